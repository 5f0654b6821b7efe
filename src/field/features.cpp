// SPDX-License-Identifier: MIT
#include "trivcon/features.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "trivcon/error.h"
#include "trivcon/field.h"

namespace trivcon {

namespace {

// Corner k of face f such that the face's half-edge k → k+1 is edge e (in the oriented Topology::F).
int corner_of(const Topology& t, int f, int e) {
  for (int k = 0; k < 3; ++k)
    if (t.face_edges(f, k) == e) return k;
  return -1;
}

}  // namespace

double dihedral_angle(const Topology& t, const Geometry& g, int e) {
  if (t.is_boundary_edge(e)) return 0;
  const Eigen::Vector3d nL = g.normal.row(t.edge_faces(e, 0)), nR = g.normal.row(t.edge_faces(e, 1));
  return std::atan2(nL.cross(nR).norm(), nL.dot(nR));
}

bool is_convex_edge(const MatrixX3d& V, const Topology& t, const Geometry& g, int e) {
  if (t.is_boundary_edge(e)) return false;
  const Eigen::Vector3d nL = g.normal.row(t.edge_faces(e, 0)), nR = g.normal.row(t.edge_faces(e, 1));
  const Eigen::Vector3d d = V.row(t.edge_vertices(e, 1)) - V.row(t.edge_vertices(e, 0));
  return nL.cross(nR).dot(d) > 0;
}

std::vector<int> sharp_edges(const MatrixX3d& V, const Topology& t, const Geometry& g, double degrees) {
  (void)V;  // the normals come from the geometry; V is taken as by the other feature functions
  if (!(degrees >= 0 && degrees <= 180)) {
    std::ostringstream s;
    s << degrees;
    throw Error("feature angle " + s.str() + " out of range: expected degrees in [0, 180]");
  }
  const double limit = degrees * kPi / 180;
  std::vector<int> out;
  for (int e = 0; e < t.num_edges; ++e)
    if (!t.is_boundary_edge(e) && dihedral_angle(t, g, e) > limit) out.push_back(e);
  return out;
}

FeatureAlignment feature_alignment(const MatrixX3d& V, const Topology& t, const Geometry& g, const std::vector<int>& edges, int N) {
  if (N < 1) throw Error("feature_alignment: N = " + std::to_string(N) + " (need N >= 1)");
  // Per face, its feature edges with their direction (p_j − p_i, i < j, in the face's frame) and length.
  struct Candidate {
    int edge;
    double angle, length;
  };
  std::map<int, std::vector<Candidate>> beside;
  for (int e : edges) {
    if (e < 0 || e >= t.num_edges || t.is_boundary_edge(e))
      throw Error("feature_alignment: edge " + std::to_string(e) + " is not an interior edge of the mesh");
    const double length = (V.row(t.edge_vertices(e, 1)) - V.row(t.edge_vertices(e, 0))).norm();
    for (int side = 0; side < 2; ++side) {
      const int f = t.edge_faces(e, side);
      // L holds i → j, R holds j → i: R's half-edge is turned by π to give the same sense.
      const double angle = wrap_angle(g.half_edge_angle(f, corner_of(t, f, e)) + (side == 1 ? kPi : 0.0));
      beside[f].push_back({e, angle, length});
    }
  }
  FeatureAlignment out;
  for (auto& [f, list] : beside) {
    // The longest edge is followed; ties go to the smaller edge id, so the choice is deterministic.
    std::sort(list.begin(), list.end(),
              [](const Candidate& a, const Candidate& b) { return a.length != b.length ? a.length > b.length : a.edge < b.edge; });
    out.fixed[f] = list[0].angle;
    if (list.size() > 1) ++out.corner_faces;
    for (size_t k = 1; k < list.size(); ++k) {
      const double difference = std::abs(reduce_angle(list[k].angle - list[0].angle, N));
      if (difference > kFeatureAngleTolerance) out.conflicts.push_back({f, list[0].edge, list[k].edge, difference});
    }
  }
  return out;
}

}  // namespace trivcon
