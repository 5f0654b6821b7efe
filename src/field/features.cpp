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

// Narrow corners (trivcon/features.h): at vertex v, consecutive feature edges a, b around v enclosing a sector
// of angle θ < π/N (the corners at v of the faces between them). Following both, the field would turn by θ
// through the sector, and a map that puts a and b on iso-lines would give the sector the angle 0: its faces
// collapse. Instead the sector's faces W_1..W_m (in the turning sense from a) are fixed to the direction of a
// turned by i·δ, δ = (θ − 2π/N)/(m + 1): with the faces across a and b (which follow their edges) every
// step turns by |δ| < π/N, so the closest reading turns through the sector by θ − 2π/N and the sector gets one
// step, 2π/N. Only sectors whose faces have no feature edges but a and b, and no face in two such sectors.
void narrow_corners(const Topology& t, const Geometry& g, const std::vector<int>& edges, const std::map<int, std::vector<int>>& sharp_beside,
                    int N, FeatureAlignment& out) {
  if (N < 4 || N % 2 != 0) return;  // a sense-free step of 2π/N that a quad or hexagon corner can take
  std::vector<char> sharp(t.num_edges, 0);
  std::vector<int> count(t.num_vertices, 0);
  for (int e : edges) {
    sharp[e] = 1;
    ++count[t.edge_vertices(e, 0)], ++count[t.edge_vertices(e, 1)];
  }
  std::vector<char> claimed(t.num_faces, 0);
  auto corner_at = [&](int f, int v) {
    for (int k = 0; k < 3; ++k)
      if (t.F(f, k) == v) return k;
    return -1;
  };
  for (int v = 0; v < t.num_vertices; ++v) {
    if (count[v] < 2) continue;
    // A face at v whose outgoing half-edge at v (corner k → k+1) is a feature edge: the walk starts there.
    int start = -1;
    for (int j = t.vertex_face_offsets[v]; j < t.vertex_face_offsets[v + 1] && start < 0; ++j) {
      const int f = t.vertex_faces[j];
      if (sharp[t.face_edges(f, corner_at(f, v))]) start = f;
    }
    if (start < 0) continue;
    // Walk counter-clockwise: from face f across its incoming half-edge at v (corner k+2 → k) to the next face.
    std::vector<int> sector;
    double theta = 0;
    int f = start;
    const int degree = t.vertex_face_offsets[v + 1] - t.vertex_face_offsets[v];
    for (int step = 0; step < degree; ++step) {
      const int k = corner_at(f, v);
      sector.push_back(f);
      theta += g.corner_angles(f, k);
      const int incoming = t.face_edges(f, (k + 2) % 3);
      if (sharp[incoming]) {
        const int a = t.face_edges(sector.front(), corner_at(sector.front(), v));
        bool usable = theta < kPi / N;
        for (int w : sector) {
          usable = usable && !claimed[w];
          const auto it = sharp_beside.find(w);
          if (it != sharp_beside.end())
            for (int e : it->second) usable = usable && (e == a || e == incoming);
        }
        if (usable) {
          const int m = static_cast<int>(sector.size());
          const double delta = (theta - 2 * kPi / N) / (m + 1);
          double gamma = 0;  // the angle at v from a to W_i's outgoing half-edge
          for (int i = 0; i < m; ++i) {
            const int w = sector[i], c = corner_at(w, v);
            out.fixed[w] = wrap_angle(g.half_edge_angle(w, c) - gamma + (i + 1) * delta);
            claimed[w] = 1;
            gamma += g.corner_angles(w, c);
          }
          out.narrow.push_back({v, a, incoming, theta, sector});
        }
        sector.clear();
        theta = 0;
      }
      if (t.is_boundary_edge(incoming)) break;
      f = t.edge_faces(incoming, 0) == f ? t.edge_faces(incoming, 1) : t.edge_faces(incoming, 0);
    }
  }
  if (out.narrow.empty()) return;
  // A face of a narrow corner follows neither edge on purpose: it is no conflict.
  out.conflicts.erase(std::remove_if(out.conflicts.begin(), out.conflicts.end(), [&](const FeatureConflict& k) { return claimed[k.face]; }),
                      out.conflicts.end());
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
  std::map<int, std::vector<int>> sharp_beside;  // face → its feature edges (for the narrow corners below)
  for (auto& [f, list] : beside)
    for (const Candidate& c : list) sharp_beside[f].push_back(c.edge);
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
  narrow_corners(t, g, edges, sharp_beside, N, out);
  return out;
}

}  // namespace trivcon
