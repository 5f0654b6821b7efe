// SPDX-License-Identifier: MIT
// Principal curvature directions per face (trivcon/curvature.h).
#include "trivcon/curvature.h"

#include <Eigen/Geometry>
#include <cmath>

namespace trivcon {

std::vector<std::complex<double>> curvature_tensors(const MatrixX3d& V, const Topology& t, const Geometry& g) {
  std::vector<std::complex<double>> z(t.num_faces, std::complex<double>(0, 0));
  for (int e = 0; e < t.num_edges; ++e) {
    if (t.is_boundary_edge(e)) continue;
    const int L = t.edge_faces(e, 0), R = t.edge_faces(e, 1);
    const Eigen::Vector3d d = V.row(t.edge_vertices(e, 1)) - V.row(t.edge_vertices(e, 0));
    const double length = d.norm();
    if (!(length > 0)) continue;
    const Eigen::Vector3d nL = g.normal.row(L).transpose(), nR = g.normal.row(R).transpose();
    const double beta = std::atan2(nL.cross(nR).dot(d / length), nL.dot(nR));
    for (const int f : {L, R}) {
      int k = 0;
      while (t.face_edges(f, k) != e) ++k;
      z[f] += std::polar(0.5 * beta * length, 2 * g.half_edge_angle(f, k));
    }
  }
  return z;
}

}  // namespace trivcon
