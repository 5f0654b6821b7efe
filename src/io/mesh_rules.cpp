// SPDX-License-Identifier: MIT
// src/io/mesh_rules.cpp: the checks and messages the mesh readers and writers share; see src/io/mesh_rules.h.
#include "io/mesh_rules.h"

#include <algorithm>
#include <cmath>

namespace trivcon::io {

std::string out_of_range_message(long long index, long long vertex_count) {
  return "face index " + std::to_string(index) + " out of range (file has " + std::to_string(vertex_count) + " vertices)";
}

std::string non_finite_message(long long vertex, double value) {
  return "non-finite coordinate in vertex " + std::to_string(vertex) + " (" +
         (std::isnan(value) ? "nan"
          : value > 0       ? "inf"
                            : "-inf") +
         ")";
}

std::string polygon_problem(const std::vector<int>& corners, long long face, bool allow_repeated) {
  const std::size_t k = corners.size();
  if (k < 3) {
    return "face " + std::to_string(face) + " has " + std::to_string(k) + " corner" + (k == 1 ? "" : "s") + " (at least 3 needed)";
  }
  return allow_repeated ? std::string() : repeated_vertex_problem(corners, face);
}

std::string repeated_vertex_problem(const std::vector<int>& corners, long long face) {
  const std::size_t k = corners.size();
  bool repeated = false;
  if (k <= 16) {  // the common case: no allocation
    for (std::size_t i = 1; i < k && !repeated; ++i) {
      for (std::size_t j = 0; j < i && !repeated; ++j) repeated = corners[i] == corners[j];
    }
  } else {
    std::vector<int> sorted = corners;
    std::sort(sorted.begin(), sorted.end());
    repeated = std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end();
  }
  if (!repeated) return {};
  constexpr std::size_t kMaxListed = 12;
  std::string list;
  for (std::size_t i = 0; i < std::min(k, kMaxListed); ++i) list += (i ? ", " : "") + std::to_string(corners[i]);
  if (k > kMaxListed) list += ", ...";
  return "face " + std::to_string(face) + " has a repeated vertex (" + list + ")";
}

}  // namespace trivcon::io
