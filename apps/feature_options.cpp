// SPDX-License-Identifier: MIT
#include "feature_options.h"

#include <algorithm>
#include <cmath>

#include "trivcon/features.h"

namespace trivcon::cli {

void FeatureOptions::add_to(CLI::App* cmd, const std::string& what) {
  // CLI::Range lets NaN through (every comparison with it is false), so the range is checked here.
  auto check_degrees = [](const std::string& text) -> std::string {
    size_t used = 0;
    double v = 0;
    try {
      v = std::stod(text, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != text.size() || !(v >= 0 && v <= 180)) return "expected an angle in degrees in [0, 180], not '" + text + "'";
    return "";
  };
  degrees_option =
      cmd->add_option("--align-features", degrees,
                      "Sharp edges: interior edges whose dihedral angle (between the face normals) exceeds DEG degrees; " + what)
          ->check(CLI::Validator(check_degrees, "DEG"));
  file_option = cmd->add_option("--features", file, "Sharp edges from a file: one 'i j' (vertex ids) per line, '#' comments; " + what);
}

std::vector<int> FeatureOptions::edges(const MatrixX3d& V, const Topology& t, const Geometry& g) const {
  std::vector<int> out;
  if (degrees_option->count() > 0) out = sharp_edges(V, t, g, degrees);
  if (file_option->count() > 0) {
    const std::vector<int> listed = read_feature_edges(file, t);
    out.insert(out.end(), listed.begin(), listed.end());
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }
  return out;
}

}  // namespace trivcon::cli
