// SPDX-License-Identifier: MIT
// The shape of one quad (p0, p1, p2, p3), as the check, the relaxation and the fill measure it
// (src/quad/quad_check.cpp, relax.cpp, fill.cpp), and the valence a quad vertex should have.
#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <vector>

#include "trivcon/param.h"

namespace trivcon::quad {

// The quad's own normal: the cross product of its diagonals, (p2 − p0) × (p3 − p1) (not normalized).
inline Eigen::Vector3d quad_normal(const std::array<Eigen::Vector3d, 4>& p) { return (p[2] - p[0]).cross(p[3] - p[1]); }

// The scaled Jacobian of corner k about the unit normal n: the sine of its angle, negative at a reflex corner,
// −1 when one of its edges has length 0.
inline double corner_sine(const std::array<Eigen::Vector3d, 4>& p, int k, const Eigen::Vector3d& n) {
  const Eigen::Vector3d a = p[(k + 1) % 4] - p[k], b = p[(k + 3) % 4] - p[k];
  const double lengths = a.norm() * b.norm();
  return lengths > 0 ? a.cross(b).dot(n) / lengths : -1.0;
}

// Per input vertex, n of its singularity's index n/4 in the map (0 off the singularities): a quad vertex on
// input vertex v should have valence 4 − n there, 4 elsewhere.
inline std::vector<int> cone_quarters(const Parametrization& param, int num_input_vertices) {
  std::vector<int> n(num_input_vertices, 0);
  for (size_t k = 0; k < param.cones.size() && k < param.cone_index.size(); ++k)
    if (param.cones[k] >= 0 && param.cones[k] < num_input_vertices) n[param.cones[k]] = param.cone_index[k];
  return n;
}

}  // namespace trivcon::quad
