// SPDX-License-Identifier: MIT
#include "trivcon/geometry.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include "linalg/parallel.h"
#include "trivcon/cancel.h"
#include "trivcon/error.h"

namespace trivcon {

namespace {
constexpr double kDegenerateArea = 1e-14;  // relative to the longest edge squared
constexpr double kMollifyFactor = 1e-5;    // δ of the mollification, relative to the component's mean edge length
constexpr double kMollifyReach = 1e3;      // faces with a margin below this many δ take the mollified cotangents
using linalg::kParallelMinElements;

// Cotangents of the three corner angles of a triangle with edge lengths l[k] (edge k: corner k → k+1,
// opposite corner k+2), all positive and satisfying the triangle inequality strictly: cot at corner j is
// (b² + c² − a²) / 4A with a the opposite edge, and A by Kahan's form of Heron's formula, which keeps its
// accuracy on needles and slivers ("Miscalculating Area and Angles of a Needle-like Triangle", 2014).
// The lengths are divided by the longest first (cotangents do not depend on the size), so that the
// product of four lengths can neither overflow nor underflow.
// Area of the triangle with edge lengths l[k] / longest (Kahan's Heron on the sorted lengths).
double scaled_area(const double l[3]) {
  double s[3] = {l[0], l[1], l[2]};
  std::sort(s, s + 3, [](double a, double b) { return a > b; });
  const double a = s[0], b = s[1], c = s[2];
  return 0.25 * std::sqrt((a + (b + c)) * (c - (a - b)) * (c + (a - b)) * (a + (b - c)));
}

// The area of the triangle with edge lengths l_in (satisfying the triangle inequality strictly).
double area_from_lengths(const double l_in[3]) {
  const double longest = std::max({l_in[0], l_in[1], l_in[2]});
  const double l[3] = {l_in[0] / longest, l_in[1] / longest, l_in[2] / longest};
  return scaled_area(l) * longest * longest;
}

Eigen::Vector3d cotangents_from_lengths(const double l_in[3]) {
  const double longest = std::max({l_in[0], l_in[1], l_in[2]});
  const double l[3] = {l_in[0] / longest, l_in[1] / longest, l_in[2] / longest};
  const double area = scaled_area(l);
  Eigen::Vector3d cot;
  for (int j = 0; j < 3; ++j) {
    const double opposite = l[(j + 1) % 3], u = l[j], w = l[(j + 2) % 3];
    cot(j) = (u * u + w * w - opposite * opposite) / (4 * area);
  }
  return cot;
}

// Intrinsic corner angles with the documented conventions for degenerate triangles.
Eigen::Vector3d corner_angles_of(const Eigen::Vector3d p[3]) {
  const Eigen::Vector3d e[3] = {p[1] - p[0], p[2] - p[1], p[0] - p[2]};  // e[k]: corner k → k+1
  const double len2[3] = {e[0].squaredNorm(), e[1].squaredNorm(), e[2].squaredNorm()};
  const int zero_edges = (len2[0] == 0) + (len2[1] == 0) + (len2[2] == 0);
  if (zero_edges >= 2) return Eigen::Vector3d::Constant(kPi / 3);
  if (zero_edges == 1) {
    Eigen::Vector3d a = Eigen::Vector3d::Constant(kPi / 2);
    for (int k = 0; k < 3; ++k)
      if (len2[k] == 0) a((k + 2) % 3) = 0;  // edge k is opposite corner k+2
    return a;
  }
  Eigen::Vector3d a;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d u = e[k], w = -e[(k + 2) % 3];  // the two edges leaving corner k
    a(k) = std::atan2(u.cross(w).norm(), u.dot(w));
  }
  return a;
}
}  // namespace


double Geometry::angle_in_face(int f, const Eigen::Vector3d& d) const { return std::atan2(d.dot(frame_y.row(f)), d.dot(frame_x.row(f))); }

Eigen::Vector3d Geometry::direction_in_face(int f, double beta) const {
  return std::cos(beta) * frame_x.row(f).transpose() + std::sin(beta) * frame_y.row(f).transpose();
}

Geometry compute_geometry(const MatrixX3d& V, const Topology& t, int threads) {
  const int nF = t.num_faces, nE = t.num_edges, nV = t.num_vertices;
  const int team = threads > 0 ? threads : linalg::max_threads();
  Geometry g;
  g.corner_angles.resize(nF, 3);
  g.half_edge_angle.resize(nF, 3);
  g.face_area.resize(nF);
  g.degenerate_face.assign(nF, 0);
  g.frame_x.resize(nF, 3);
  g.frame_y.resize(nF, 3);
  g.normal.resize(nF, 3);
  MatrixX3d cot(nF, 3);  // cotangent of each corner angle: 0 for degenerate faces until mollified below
  std::vector<Eigen::Vector3d> raw_normal(nF);
  int degenerate_faces = 0, zero_area_faces = 0;
  // Faces, then edges, are independent of one another: both loops run on all cores (OpenMP).
#pragma omp parallel for schedule(static) reduction(+ : degenerate_faces, zero_area_faces) num_threads(team) if (nF > kParallelMinElements)
  for (int f = 0; f < nF; ++f) {
    const Eigen::Vector3d p[3] = {V.row(t.F(f, 0)), V.row(t.F(f, 1)), V.row(t.F(f, 2))};
    const Eigen::Vector3d a = corner_angles_of(p);
    g.corner_angles.row(f) = a;
    g.half_edge_angle.row(f) << 0.0, kPi - a(1), kPi + a(0);
    const Eigen::Vector3d n = (p[1] - p[0]).cross(p[2] - p[0]);
    raw_normal[f] = n;
    const double longest2 = std::max({(p[1] - p[0]).squaredNorm(), (p[2] - p[1]).squaredNorm(), (p[0] - p[2]).squaredNorm()});
    const double area = 0.5 * n.norm();
    const bool degenerate = !(area > kDegenerateArea * longest2) || (p[1] - p[0]).squaredNorm() == 0 || (p[2] - p[1]).squaredNorm() == 0 ||
                            (p[0] - p[2]).squaredNorm() == 0;
    g.degenerate_face[f] = degenerate;
    degenerate_faces += degenerate;
    zero_area_faces += n.squaredNorm() == 0;
    g.face_area(f) = degenerate ? 0.0 : area;
    for (int k = 0; k < 3; ++k) {
      if (degenerate) {
        cot(f, k) = 0;
        continue;
      }
      const Eigen::Vector3d u = p[(k + 1) % 3] - p[k], w = p[(k + 2) % 3] - p[k];
      cot(f, k) = u.dot(w) / u.cross(w).norm();
    }
  }
  g.degenerate_faces = degenerate_faces, g.zero_area_faces = zero_area_faces;
  check_cancelled();  // trivcon/cancel.h: between the passes
  // Frames. A degenerate face borrows the summed normal of its edge neighbours (any unit vector
  // perpendicular to its first edge as a last resort), so every output stays finite.
#pragma omp parallel for schedule(static) num_threads(team) if (nF > kParallelMinElements)
  for (int f = 0; f < nF; ++f) {
    Eigen::Vector3d n = raw_normal[f];
    if (g.degenerate_face[f]) {
      n.setZero();
      for (int k = 0; k < 3; ++k) {
        const int e = t.face_edges(f, k);
        for (int s = 0; s < 2; ++s) {
          const int h = t.edge_faces(e, s);
          if (h >= 0 && h != f && !g.degenerate_face[h]) n += raw_normal[h];
        }
      }
    }
    Eigen::Vector3d x = V.row(t.F(f, 1)) - V.row(t.F(f, 0));
    if (x.squaredNorm() == 0) {
      // A zero-length first edge: its corner angles are (π/2, π/2, 0), so half_edge_angle puts edge 1 → 2
      // at π/2; the x axis is a quarter turn clockwise from that edge.
      const Eigen::Vector3d d = V.row(t.F(f, 2)) - V.row(t.F(f, 1));
      x = n.squaredNorm() > 0 ? Eigen::Vector3d(d.cross(n)) : d;
    }
    if (x.squaredNorm() == 0) x = Eigen::Vector3d::UnitX();
    x.normalize();
    n -= n.dot(x) * x;
    if (!(n.squaredNorm() > 0)) {
      n = x.cross(Eigen::Vector3d::UnitX());
      if (n.squaredNorm() < 1e-6) n = x.cross(Eigen::Vector3d::UnitY());
    }
    n.normalize();
    g.frame_x.row(f) = x;
    g.normal.row(f) = n;
    g.frame_y.row(f) = n.cross(x);
  }

  g.angle_defect.setZero(nV);
  for (int v = 0; v < nV; ++v) {
    if (t.vertex_component[v] < 0) continue;
    g.angle_defect(v) = t.is_boundary_vertex(v) ? kPi : 2 * kPi;
  }
  for (int f = 0; f < nF; ++f)
    for (int k = 0; k < 3; ++k) g.angle_defect(t.F(f, k)) -= g.corner_angles(f, k);

  // Intrinsic mollification (Sharp & Crane 2020, "A Laplacian for Nonmanifold Triangle Meshes", Sec. 4.5)
  // for the cotangent weights only, per connected component (so that components of very different sizes
  // do not share one tolerance): when some face's edge lengths miss the triangle inequality by less than
  // δ = kMollifyFactor × the component's mean edge length (slivers, needles, zero-area faces, zero-length
  // edges), the smallest ε that gives every face of the component a margin of δ is added to every edge
  // length of the component, and the cotangents of its faces whose margin is below 1000 δ are taken from
  // those lengths (the others would change by less than about 1e-3 relative and keep their own). Every face then has a
  // defined shape and bounded cotangents (|cot| ≲ longest edge / δ), no vertex moves, and the angles,
  // holonomies and frames above stay those of the mesh as given. Components whose faces all have the
  // margin keep their cotangents unchanged (ε = 0).
  std::vector<double> length(nE);
  check_cancelled();
#pragma omp parallel for schedule(static) num_threads(team) if (nE > kParallelMinElements)
  for (int e = 0; e < nE; ++e) length[e] = (V.row(t.edge_vertices(e, 1)) - V.row(t.edge_vertices(e, 0))).norm();
  const size_t nC = t.components.size();
  std::vector<double> component_length(nC, 0), component_epsilon(nC, 0);
  std::vector<int> component_edges(nC, 0);
  for (int e = 0; e < nE; ++e) {
    const int c = t.face_component[t.edge_faces(e, 0) >= 0 ? t.edge_faces(e, 0) : t.edge_faces(e, 1)];  // a boundary edge may have no L
    component_length[c] += length[e], ++component_edges[c];
  }
  // Each face's shortfall from the margin (in parallel), then the largest per component.
  std::vector<double> shortfall(nF);
  int mollified_faces = 0;
#pragma omp parallel for schedule(static) reduction(+ : mollified_faces) num_threads(team) if (nF > kParallelMinElements)
  for (int f = 0; f < nF; ++f) {
    const int c = t.face_component[f];
    const double delta = kMollifyFactor * component_length[c] / component_edges[c];
    const double l0 = length[t.face_edges(f, 0)], l1 = length[t.face_edges(f, 1)], l2 = length[t.face_edges(f, 2)];
    shortfall[f] = delta - std::min({l0 + l1 - l2, l1 + l2 - l0, l2 + l0 - l1});
    mollified_faces += shortfall[f] > 0;
  }
  for (int f = 0; f < nF; ++f)
    if (shortfall[f] > 0) component_epsilon[t.face_component[f]] = std::max(component_epsilon[t.face_component[f]], shortfall[f]);
  g.mollified_faces = mollified_faces;
  g.mollify_epsilon = nC > 0 ? *std::max_element(component_epsilon.begin(), component_epsilon.end()) : 0.0;
  g.component_epsilon = component_epsilon;
  g.mollified_area = g.face_area;
  if (g.mollify_epsilon > 0) {
#pragma omp parallel for schedule(static) num_threads(team) if (nF > kParallelMinElements)
    for (int f = 0; f < nF; ++f) {
      const int c = t.face_component[f];
      const double epsilon = component_epsilon[c];
      // A face whose margin is at least kMollifyReach δ keeps its own cotangents: adding ε ≤ δ to its lengths
      // would change them by less than about 1/kMollifyReach relative (and recomputing every face of a large
      // component made the geometry measurably slower: BENCHMARKS.md, "Exact on slivers").
      if (epsilon == 0 || shortfall[f] < -(kMollifyReach - 1) * kMollifyFactor * component_length[c] / component_edges[c]) continue;
      const double l[3] = {length[t.face_edges(f, 0)] + epsilon, length[t.face_edges(f, 1)] + epsilon,
                           length[t.face_edges(f, 2)] + epsilon};
      cot.row(f) = cotangents_from_lengths(l);
      g.mollified_area(f) = area_from_lengths(l);
    }
  }

  g.rho.setZero(nE);
  g.cotan_weight.setZero(nE);
  int negative_cotan_edges = 0, clamped_cotangents = 0, zero_weight_edges = 0;
  check_cancelled();
#pragma omp parallel for schedule(static) reduction(+ : negative_cotan_edges, clamped_cotangents, zero_weight_edges) num_threads(team) \
    if (nE > kParallelMinElements)
  for (int e = 0; e < nE; ++e) {
    if (t.is_boundary_edge(e)) continue;
    const int L = t.edge_faces(e, 0), R = t.edge_faces(e, 1);
    int kL = 0, kR = 0;
    while (t.face_edges(L, kL) != e) ++kL;
    while (t.face_edges(R, kR) != e) ++kR;
    g.rho(e) = wrap_angle(g.half_edge_angle(R, kR) + kPi - g.half_edge_angle(L, kL));
    // The corner opposite edge k of a face is corner k+2.
    const double cl = cot(L, (kL + 2) % 3), cr = cot(R, (kR + 2) % 3);
    if (cl + cr < 0) ++negative_cotan_edges;
    clamped_cotangents += (cl < 0) + (cr < 0);
    g.cotan_weight(e) = 0.5 * (std::max(cl, 0.0) + std::max(cr, 0.0));
    zero_weight_edges += g.cotan_weight(e) == 0;
  }
  g.negative_cotan_edges = negative_cotan_edges, g.clamped_cotangents = clamped_cotangents, g.zero_weight_edges = zero_weight_edges;
  return g;
}

double mean_edge_length(const MatrixX3d& V, const Topology& t) {
  if (t.num_edges == 0) return 0;
  double sum = 0;
  for (int e = 0; e < t.num_edges; ++e) sum += (V.row(t.edge_vertices(e, 1)) - V.row(t.edge_vertices(e, 0))).norm();
  return sum / t.num_edges;
}

double fixed_angle_from_direction(const Geometry& g, int face, const Eigen::Vector3d& d) {
  if (!d.allFinite()) throw Error("fixed direction of face " + std::to_string(face) + " is not finite");
  if (d.squaredNorm() == 0) throw Error("fixed direction of face " + std::to_string(face) + " is zero");
  const double along = std::hypot(d.dot(g.frame_x.row(face)), d.dot(g.frame_y.row(face)));
  if (!(along > 1e-9 * d.norm()))
    throw Error("fixed direction of face " + std::to_string(face) + " is perpendicular to the face: nothing is left after projection");
  return g.angle_in_face(face, d);
}

}  // namespace trivcon
