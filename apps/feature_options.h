// SPDX-License-Identifier: MIT
// The options that choose feature (sharp) edges (--align-features DEG, --features FILE), shared by `solve`
// and `render` (trivcon/features.h).
#pragma once
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "trivcon/geometry.h"
#include "trivcon/topology.h"

namespace trivcon::cli {

struct FeatureOptions {
  double degrees = 0;
  std::string file;
  CLI::Option* degrees_option = nullptr;
  CLI::Option* file_option = nullptr;
  bool given() const { return degrees_option->count() > 0 || file_option->count() > 0; }
  // Adds the two options to `cmd`; `what` ends their help text ("the field follows them", "drawn").
  void add_to(CLI::App* cmd, const std::string& what);
  // The feature edges (increasing edge ids): those sharper than --align-features and those --features lists,
  // both when both are given; none when neither is. Throws trivcon::Error for a bad file.
  std::vector<int> edges(const MatrixX3d& V, const Topology& topology, const Geometry& geometry) const;
};

}  // namespace trivcon::cli
