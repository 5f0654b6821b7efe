// SPDX-License-Identifier: MIT
#include "quad/relax.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "quad/quad_shape.h"
#include "quad/surface_grid.h"

namespace trivcon::quad {

namespace {
// Directions in the tangent plane a vertex of a bad quad tries, besides its neighbours' mean and the
// parallelograms' corners.
constexpr int kRelaxDirections = 8;
}  // namespace

int relax_quads(const FieldDesigner& designer, const Parametrization& param, QuadMesh& quads, double threshold, int sweeps) {
  const Topology& t = designer.topology();
  const MatrixX3d& Vin = designer.V();
  const MatrixX3d& normal = designer.geometry().normal;
  const int nV = static_cast<int>(quads.V.rows()), nQ = static_cast<int>(quads.Q.rows());
  if (nQ == 0 || quads.vertex_face.size() != nV || quads.vertex_barycentric.rows() != nV) return 0;
  for (int v = 0; v < nV; ++v)
    if (quads.vertex_face[v] < 0 || quads.vertex_face[v] >= t.num_faces) return 0;  // not located: nothing to move on

  // Which vertices stay.
  std::vector<char> pinned(nV, 0), is_cone(t.num_vertices, 0), aligned_edge(t.num_edges, 0), near_aligned(t.num_vertices, 0);
  for (int c : param.cones)
    if (c >= 0 && c < t.num_vertices) is_cone[c] = 1;
  for (int e : param.aligned_edges)
    if (e >= 0 && e < t.num_edges) aligned_edge[e] = 1, near_aligned[t.edge_vertices(e, 0)] = near_aligned[t.edge_vertices(e, 1)] = 1;
  for (int v = 0; v < nV; ++v) {
    if (const int c = quads.vertex_cone[v]; c >= 0) {
      pinned[v] = is_cone[c] || near_aligned[c] || !t.is_interior_vertex(c);
      continue;
    }
    const int f = quads.vertex_face[v];
    for (int k = 0; k < 3; ++k)  // inside the edge opposite corner k
      if (quads.vertex_barycentric(v, k) == 0) {
        const int e = edge_between(t, t.F(f, (k + 1) % 3), t.F(f, (k + 2) % 3));
        if (e < 0 || t.is_boundary_edge(e) || aligned_edge[e]) pinned[v] = 1;
      }
  }
  for (const auto& face : quads.other_faces)
    for (int v : face)
      if (v >= 0 && v < nV) pinned[v] = 1;
  // Quads around each vertex, neighbours along quad edges, boundary edges of the quad mesh.
  std::vector<int> quad_start(nV + 1, 0), quad_list(4 * static_cast<size_t>(nQ));
  for (int i = 0; i < nQ; ++i)
    for (int k = 0; k < 4; ++k) ++quad_start[quads.Q(i, k) + 1];
  for (int v = 0; v < nV; ++v) quad_start[v + 1] += quad_start[v];
  {
    std::vector<int> next(quad_start.begin(), quad_start.end() - 1);
    for (int i = 0; i < nQ; ++i)
      for (int k = 0; k < 4; ++k) quad_list[next[quads.Q(i, k)]++] = i;
  }
  // A quad edge used by one quad: its ends are on the boundary (or beside a face that is not a quad).
  for (int v = 0; v < nV; ++v) {
    std::vector<std::pair<int, int>> ends;  // (neighbour, +1 outgoing / −1 incoming)
    for (int j = quad_start[v]; j < quad_start[v + 1]; ++j) {
      const int i = quad_list[j];
      for (int k = 0; k < 4; ++k)
        if (quads.Q(i, k) == v) ends.emplace_back(quads.Q(i, (k + 1) % 4), 1), ends.emplace_back(quads.Q(i, (k + 3) % 4), -1);
    }
    std::sort(ends.begin(), ends.end());
    for (size_t a = 0; a < ends.size() && !pinned[v]; ++a) {
      int sum = 0;
      size_t b = a;
      for (; b < ends.size() && ends[b].first == ends[a].first; ++b) sum += ends[b].second;
      if (sum != 0 || b - a != 2) pinned[v] = 1;  // not one quad on each side
      a = b - 1;
    }
  }

  // The nearest point of the surface to `target` (of the component of `face`, which holds a point no further
  // than `limit`): its face and barycentric coordinates. The same grid as check_quads.
  SurfaceGrid grid(Vin, t.F, 1000LL * (nQ + t.num_faces) + 10000000);
  auto onto_surface = [&](const Eigen::Vector3d& target, int face, double limit, Eigen::Vector3d& bary) {
    const int found = grid.nearest(target, limit, t.face_component[face], t.face_component).first;
    if (found < 0) return std::pair<Eigen::Vector3d, int>(Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()), -1);
    const Eigen::Vector3d q = closest_on_triangle(target, Vin.row(t.F(found, 0)), Vin.row(t.F(found, 1)), Vin.row(t.F(found, 2)), &bary);
    return std::pair<Eigen::Vector3d, int>(q, found);
  };
  // How well quad i sits, with vertex `moved` at (p, face) instead of where it is, as check_quads measures it: the
  // least of its corners' sines about its own normal (p2 − p0) × (p3 − p1) and of the cosine between that normal
  // and the normal of the input face nearest to its centre; below −1 when that cosine is not positive (inverted).
  auto worst_corner = [&](int i, int moved, const Eigen::Vector3d& p, int face) {
    std::array<Eigen::Vector3d, 4> x;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) {
      const int v = quads.Q(i, k);
      x[k] = v == moved ? p : Eigen::Vector3d(quads.V.row(v).transpose());
      centre += x[k] / 4;
    }
    const Eigen::Vector3d own = quad_normal(x);
    if (!(own.norm() > 0)) return -1.0;
    const Eigen::Vector3d n = own.normalized();
    double to_corner = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 4; ++k) to_corner = std::min(to_corner, (centre - x[k]).norm());
    const int v0 = quads.Q(i, 0);
    const int f0 = v0 == moved ? face : quads.vertex_face[v0];
    const int nearest = grid.nearest(centre, to_corner, t.face_component[f0], t.face_component).first;
    const double facing = normal.row(nearest >= 0 ? nearest : f0).dot(n);
    if (!(facing > 0)) return facing - 2;  // inverted: worse than any quad that is not
    double worst = facing;
    for (int k = 0; k < 4; ++k) worst = std::min(worst, corner_sine(x, k, n));
    return worst;
  };
  // Of the quads around v with v at (p, face): the worst corner, and Σ (threshold − worst)² over the quads below
  // the threshold (a move is kept when the worst does not get worse and the sum gets smaller).
  struct Score {
    double worst = std::numeric_limits<double>::infinity(), penalty = 0;
    bool better_than(const Score& o) const { return worst >= o.worst - 1e-12 && penalty < o.penalty - 1e-12; }
  };
  auto score_around = [&](int v, const Eigen::Vector3d& p, int face) {
    Score s;
    for (int j = quad_start[v]; j < quad_start[v + 1]; ++j) {
      const double w = worst_corner(quad_list[j], v, p, face);
      s.worst = std::min(s.worst, w);
      if (w < threshold) s.penalty += (threshold - w) * (threshold - w);
    }
    return s;
  };
  // Sweeps: the free vertices of the quads below the threshold try to move; the next sweep looks only at the
  // quads around the vertices that moved (nothing else changed).
  int moved_vertices = 0;
  std::vector<char> moved(nV, 0), active(nV, 0), suspect(nQ, 1);
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    std::fill(active.begin(), active.end(), 0);
    bool any = false;
    for (int i = 0; i < nQ; ++i)
      if (suspect[i] && worst_corner(i, -1, Eigen::Vector3d::Zero(), -1) < threshold)
        for (int k = 0; k < 4; ++k)
          if (!pinned[quads.Q(i, k)]) active[quads.Q(i, k)] = 1, any = true;
    if (!any) break;
    std::fill(suspect.begin(), suspect.end(), 0);
    bool improved = false;
    for (int v = 0; v < nV; ++v) {
      if (!active[v]) continue;
      const Eigen::Vector3d p = quads.V.row(v).transpose();
      // Where to try: the mean of the neighbours, and for each quad around v the corner that completes the
      // parallelogram of its other three vertices; the whole step, half and a quarter; the best kept.
      Eigen::Vector3d centre = Eigen::Vector3d::Zero();
      std::vector<Eigen::Vector3d> targets(1);
      for (int j = quad_start[v]; j < quad_start[v + 1]; ++j) {
        const int i = quad_list[j];
        for (int k = 0; k < 4; ++k)
          if (quads.Q(i, k) == v) {
            const Eigen::Vector3d next = quads.V.row(quads.Q(i, (k + 1) % 4)).transpose(), previous = quads.V.row(quads.Q(i, (k + 3) % 4)).transpose();
            centre += next + previous;
            targets.push_back(next + previous - quads.V.row(quads.Q(i, (k + 2) % 4)).transpose());
          }
      }
      if (targets.size() == 1) continue;
      targets[0] = centre / (2.0 * static_cast<double>(targets.size() - 1));
      // Where a quad around v has a flat or reflex corner: also points around v in the surface's tangent plane, in
      // kRelaxDirections directions at a quarter, half and whole of its mean quad edge (a twisted quad beside a
      // cone, two of its corners reflex, is not mended by moves toward the neighbours, each of which makes one of
      // its corners worse). Not for quads that are only tilted against the surface: there such moves trade
      // their corners for the tilt.
      bool reflex = false;
      double reach = 0;
      for (int j = quad_start[v]; j < quad_start[v + 1]; ++j) {
        const int i = quad_list[j];
        std::array<Eigen::Vector3d, 4> x;
        for (int k = 0; k < 4; ++k) x[k] = quads.V.row(quads.Q(i, k)).transpose();
        const Eigen::Vector3d own = quad_normal(x);
        for (int k = 0; k < 4; ++k) {
          reflex = reflex || !(own.norm() > 0) || corner_sine(x, k, own.normalized()) <= 0;
          if (quads.Q(i, k) == v) reach += (x[(k + 1) % 4] - p).norm();
        }
      }
      if (reflex) {
        reach /= static_cast<double>(quad_start[v + 1] - quad_start[v]);
        const Eigen::Vector3d n = normal.row(quads.vertex_face[v]).transpose();
        const Eigen::Vector3d t1 = n.unitOrthogonal(), t2 = n.cross(t1);
        for (int d = 0; d < kRelaxDirections; ++d) {
          const double angle = 2 * M_PI * d / kRelaxDirections;
          targets.push_back(p + reach * (std::cos(angle) * t1 + std::sin(angle) * t2));
        }
      }
      Score best = score_around(v, p, quads.vertex_face[v]);
      const double best_before = best.penalty;
      Eigen::Vector3d best_point = p, best_bary = quads.vertex_barycentric.row(v).transpose();
      int best_face = quads.vertex_face[v];
      for (const Eigen::Vector3d& target : targets)
        for (double step : {1.0, 0.5, 0.25}) {
          Eigen::Vector3d bary;
          const Eigen::Vector3d aim = p + step * (target - p);
          const auto [q, face] = onto_surface(aim, quads.vertex_face[v], (aim - p).norm(), bary);
          if (face < 0) continue;
          if (const Score s = score_around(v, q, face); s.better_than(best)) best = s, best_point = q, best_face = face, best_bary = bary;
        }
      if (best.penalty < best_before) {
        quads.V.row(v) = best_point.transpose();
        quads.vertex_face[v] = best_face;
        quads.vertex_barycentric.row(v) = best_bary.transpose();
        quads.vertex_cone[v] = -1;  // no longer on an input vertex (cones do not move)
        if (!moved[v]) moved[v] = 1, ++moved_vertices;
        for (int j = quad_start[v]; j < quad_start[v + 1]; ++j) suspect[quad_list[j]] = 1;
        improved = true;
      }
    }
    if (!improved) break;
  }
  return moved_vertices;
}

}  // namespace trivcon::quad
