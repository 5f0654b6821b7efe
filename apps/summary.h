// JSON descriptions shared by `info` and the `solve` report (documented in README.md, "trivcon info --json").
#pragma once
#include <nlohmann/json.hpp>
#include <string>

#include "trivcon/cycles.h"
#include "trivcon/geometry.h"
#include "trivcon/io.h"
#include "trivcon/topology.h"

namespace trivcon::cli {

nlohmann::ordered_json mesh_summary(const std::string& path, const MeshData& mesh, const Topology& topology, const Geometry& geometry);
nlohmann::ordered_json cycles_summary(const Topology& topology, const Geometry& geometry, const Cycles& cycles);

}  // namespace trivcon::cli
