// SPDX-License-Identifier: MIT
// JSON descriptions shared by `info` and the `solve` report (documented in docs/reference/report.md, "info --json"),
// and the clock of the report's timings.
#pragma once
#include <chrono>
#include <nlohmann/json.hpp>
#include <string>

#include "trivcon/cycles.h"
#include "trivcon/geometry.h"
#include "trivcon/io.h"
#include "trivcon/relax.h"
#include "trivcon/repair.h"
#include "trivcon/topology.h"

namespace trivcon::cli {

nlohmann::ordered_json mesh_summary(const std::string& path, const MeshData& mesh, const Topology& topology, const Geometry& geometry);
nlohmann::ordered_json cycles_summary(const Topology& topology, const Geometry& geometry, const Cycles& cycles);
// The "repair" entry (trivcon/repair.h), all ids the input's: what was dropped, cut and split, and the vertices
// appended (each with the input vertex it copies); ids at or above the input's vertex count in other entries
// are those copies.
nlohmann::ordered_json repair_summary_json(const RepairedMesh& repaired);
// The "relax" entry of a report (trivcon/relax.h): energies, every move (vertex ids of the mesh solved on),
// candidate solves, time; and its one-line summary.
nlohmann::ordered_json relax_summary_json(const RelaxResult& relax);
std::string relax_summary_line(const RelaxResult& relax);
// The line saying how many sharp edges were left out for a map (FieldRequest::feature_min_length).
std::string loose_edges_line(size_t edges, double min_length);

using Clock = std::chrono::steady_clock;
inline double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

}  // namespace trivcon::cli
