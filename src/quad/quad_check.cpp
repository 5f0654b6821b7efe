// SPDX-License-Identifier: MIT
// What a quad mesh promises, measured on (V, Q) against the input surface and the map's cones (trivcon/quad.h,
// check_quads), and the one-sentence warning.
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>

#include "linalg/timing.h"
#include "quad/quad_shape.h"
#include "quad/surface_grid.h"
#include "trivcon/error.h"
#include "trivcon/quad.h"

namespace trivcon {

namespace {

int find_root(std::vector<int>& parent, int a) {
  while (parent[a] != a) a = parent[a] = parent[parent[a]];
  return a;
}
void unite(std::vector<int>& parent, int a, int b) {
  a = find_root(parent, a), b = find_root(parent, b);
  if (a != b) parent[std::max(a, b)] = std::min(a, b);
}

}  // namespace

using quad::corner_sine;
using quad::quad_normal;
using quad::SurfaceGrid;

void check_quads(const FieldDesigner& designer, const Parametrization& param, QuadMesh& quads) {
  const auto t0 = linalg::Clock::now();
  const Topology& t = designer.topology();
  const Geometry& g = designer.geometry();
  const Eigen::MatrixXd& V = quads.V;
  const Eigen::MatrixX4i& Q = quads.Q;
  const int nV = static_cast<int>(V.rows()), nQ = static_cast<int>(Q.rows());
  QuadQuality& q = quads.quality;
  for (int i = 0; i < nQ; ++i)
    for (int k = 0; k < 4; ++k)
      if (Q(i, k) < 0 || Q(i, k) >= nV)
        throw Error("quad: quad " + std::to_string(i) + " refers to vertex " + std::to_string(Q(i, k)) + " (the mesh has " +
                    std::to_string(nV) + ")");
  if (quads.vertex_cone.size() != nV)
    throw Error("quad: vertex_cone has " + std::to_string(quads.vertex_cone.size()) + " entries for " + std::to_string(nV) + " vertices");
  q.quads = nQ;
  q.input_euler_characteristic = t.euler_characteristic();
  q.input_boundary_loops = static_cast<int>(t.boundary_loops.size());
  q.input_components = static_cast<int>(t.components.size());

  // Edges: every quad side as (smaller, larger, quad, forward), sorted, so that each edge's sides are adjacent.
  struct Side {
    int a, b, quad, corner;  // a < b; the quad's side from its corner `corner` to the next
    bool forward;            // the quad runs a → b
  };
  std::vector<Side> sides;
  sides.reserve(4 * static_cast<size_t>(nQ));
  int degenerate = 0;
  for (int i = 0; i < nQ; ++i) {
    bool repeated = false;
    for (int k = 0; k < 4; ++k) {
      const int a = Q(i, k), b = Q(i, (k + 1) % 4);
      for (int j = k + 1; j < 4; ++j) repeated |= Q(i, j) == a;
      if (a != b) sides.push_back({std::min(a, b), std::max(a, b), i, k, a < b});
    }
    degenerate += repeated;
  }
  std::sort(sides.begin(), sides.end(),
            [](const Side& x, const Side& y) { return x.a != y.a ? x.a < y.a : (x.b != y.b ? x.b < y.b : x.quad < y.quad); });
  std::vector<int> valence(nV, 0), referenced(nV, 0);
  std::vector<char> on_boundary(nV, 0);
  std::vector<int> corner_parent(4 * static_cast<size_t>(nQ)), quad_parent(nQ);
  std::iota(corner_parent.begin(), corner_parent.end(), 0);
  std::iota(quad_parent.begin(), quad_parent.end(), 0);
  std::vector<std::pair<int, int>> boundary_half_edges;  // (from, to) as the quad runs them
  int edges = 0, non_manifold_edges = 0, misoriented = 0;
  for (size_t i = 0; i < sides.size();) {
    size_t j = i;
    while (j < sides.size() && sides[j].a == sides[i].a && sides[j].b == sides[i].b) ++j;
    const int n = static_cast<int>(j - i);
    ++edges;
    ++valence[sides[i].a], ++valence[sides[i].b];
    if (n > 2) ++non_manifold_edges;
    if (n == 1) {
      const Side& s = sides[i];
      on_boundary[s.a] = on_boundary[s.b] = 1;
      boundary_half_edges.emplace_back(s.forward ? s.a : s.b, s.forward ? s.b : s.a);
    }
    if (n == 2) {
      const Side &s = sides[i], &r = sides[i + 1];
      if (s.forward == r.forward) ++misoriented;
      unite(quad_parent, s.quad, r.quad);
      // The two quads' corners at each end of the edge are in one fan there.
      for (int end : {s.a, s.b}) {
        auto corner_at = [&](const Side& x) { return 4 * x.quad + (Q(x.quad, x.corner) == end ? x.corner : (x.corner + 1) % 4); };
        unite(corner_parent, corner_at(s), corner_at(r));
      }
    }
    i = j;
  }
  for (int i = 0; i < nQ; ++i)
    for (int k = 0; k < 4; ++k) referenced[Q(i, k)] = 1;
  // Fans per vertex: the distinct roots among its corners.
  std::vector<int> fans(nV, 0);
  {
    std::vector<std::pair<int, int>> roots;  // (vertex, root)
    for (int i = 0; i < nQ; ++i)
      for (int k = 0; k < 4; ++k) roots.emplace_back(Q(i, k), find_root(corner_parent, 4 * i + k));
    std::sort(roots.begin(), roots.end());
    roots.erase(std::unique(roots.begin(), roots.end()), roots.end());
    for (const auto& r : roots) ++fans[r.first];
  }
  int non_manifold_vertices = 0;
  for (int v = 0; v < nV; ++v) non_manifold_vertices += fans[v] > 1;
  // Boundary loops: each boundary half-edge continues with the one leaving its end.
  std::vector<int> leaving(nV, -1), leaving_count(nV, 0);
  for (int i = 0; i < static_cast<int>(boundary_half_edges.size()); ++i) {
    leaving[boundary_half_edges[i].first] = i;
    ++leaving_count[boundary_half_edges[i].first];
  }
  int loops = 0;
  {
    std::vector<char> seen(boundary_half_edges.size(), 0);
    for (int i = 0; i < static_cast<int>(boundary_half_edges.size()); ++i) {
      if (seen[i]) continue;
      ++loops;
      for (int h = i; h >= 0 && !seen[h]; h = leaving[boundary_half_edges[h].second]) seen[h] = 1;
    }
  }
  for (int v = 0; v < nV; ++v) non_manifold_vertices += leaving_count[v] > 1 && fans[v] <= 1;
  int vertices = 0;
  for (int v = 0; v < nV; ++v) vertices += referenced[v];
  std::vector<char> component_seen(nQ, 0);
  int components = 0;
  for (int i = 0; i < nQ; ++i)
    if (!component_seen[find_root(quad_parent, i)]) component_seen[find_root(quad_parent, i)] = 1, ++components;
  q.vertices = vertices;
  q.edges = edges;
  q.euler_characteristic = vertices - edges + nQ;
  q.boundary_loops = loops;
  q.components = components;
  q.non_manifold_edges = non_manifold_edges;
  q.non_manifold_vertices = non_manifold_vertices;
  q.manifold = non_manifold_edges == 0 && non_manifold_vertices == 0 && degenerate == 0;
  q.oriented = misoriented == 0;

  // Valences against the cones.
  const std::vector<int> cone_of = quad::cone_quarters(param, t.num_vertices);  // n of index n/4 at each input vertex
  std::vector<char> cone_found(t.num_vertices, 0);
  int irregular = 0, mismatches = 0;
  for (int v = 0; v < nV; ++v) {
    if (!referenced[v] || on_boundary[v]) continue;
    const int input = quads.vertex_cone[v];
    const int n = input >= 0 && input < t.num_vertices ? cone_of[input] : 0;
    if (input >= 0 && input < t.num_vertices && n != 0) cone_found[input] = 1;
    if (valence[v] != 4) ++irregular;
    if (valence[v] != 4 - n) ++mismatches;
  }
  for (size_t k = 0; k < param.cones.size(); ++k)
    if (param.cone_index[k] != 0 && !cone_found[param.cones[k]]) ++mismatches;
  q.irregular_vertices = irregular;
  q.singular_mismatches = mismatches;

  // Geometry: orientation against the surface's normal, scaled Jacobians, distances.
  // Quads far larger than the grid's cells (a broken map) could make the distances quadratic: the grid's work is
  // bounded, and the quads left when it runs out are not measured (and said so).
  SurfaceGrid grid(designer.V(), t.F, 1000LL * (nQ + t.num_faces) + 10000000);
  const Eigen::Vector3d extent = designer.V().colwise().maxCoeff() - designer.V().colwise().minCoeff();
  const double diagonal = extent.norm();
  bool located = quads.vertex_face.size() == nV;
  for (int v = 0; v < nV && located; ++v) located = quads.vertex_face[v] >= 0 && quads.vertex_face[v] < t.num_faces;
  int inverted = 0, unmeasured = 0, nonconvex = 0;
  double min_sj = nQ > 0 ? std::numeric_limits<double>::infinity() : 0, sum_sj = 0, farthest = 0;
  for (int i = 0; i < nQ; ++i) {
    std::array<Eigen::Vector3d, 4> p;
    for (int k = 0; k < 4; ++k) p[k] = V.row(Q(i, k)).transpose();
    const Eigen::Vector3d centre = (p[0] + p[1] + p[2] + p[3]) / 4;
    // Distances and the surface's normal (of the nearest face to the centre) from the faces of the component the
    // quad's first corner lies in, when vertex_face says (another component passing through is not its surface).
    const int component = located ? t.face_component[quads.vertex_face[Q(i, 0)]] : -1;
    // The corners lie on the surface: the centre is no further from it than from the nearest corner, an edge's
    // midpoint no further than half the edge.
    double to_corner = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 4; ++k) to_corner = std::min(to_corner, (centre - p[k]).norm());
    const auto [face, distance] = grid.nearest(centre, to_corner, component, t.face_component);
    const Eigen::Vector3d own = quad_normal(p);
    if (face < 0) {
      ++unmeasured;
    } else {
      farthest = std::max(farthest, distance);
      for (int k = 0; k < 4; ++k)
        farthest = std::max(
            farthest, grid.nearest((p[k] + p[(k + 1) % 4]) / 2, (p[(k + 1) % 4] - p[k]).norm() / 2, component, t.face_component).second);
      if (!(own.dot(g.normal.row(face).transpose()) > 0)) ++inverted;
    }
    // The scaled Jacobian of each corner against the quad's own normal (the diagonals' cross product): the sine
    // of the corner's angle, negative at a reflex corner.
    const Eigen::Vector3d unit_own = own.norm() > 0 ? Eigen::Vector3d(own.normalized()) : own;
    double worst = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 4; ++k) {
      const double sj = corner_sine(p, k, unit_own);
      worst = std::min(worst, sj);
      sum_sj += sj;
    }
    min_sj = std::min(min_sj, worst);
    nonconvex += !(worst > 0);
  }
  q.inverted_quads = inverted;
  q.nonconvex_quads = nonconvex;
  q.min_scaled_jacobian = min_sj;
  q.mean_scaled_jacobian = nQ > 0 ? sum_sj / (4.0 * nQ) : 0;
  q.hausdorff_relative = diagonal > 0 ? farthest / diagonal : 0;

  auto say = [&](const std::string& s) { q.problems.push_back(s); };
  if (nQ == 0) say("the quad mesh has no quads");
  if (degenerate > 0) say(std::to_string(degenerate) + " quads repeat a vertex");
  if (non_manifold_edges > 0) say(std::to_string(non_manifold_edges) + " quad edges are shared by more than two quads");
  if (non_manifold_vertices > 0)
    say(std::to_string(non_manifold_vertices) + " quad vertices are not manifold (their quads form several fans)");
  if (misoriented > 0)
    say(std::to_string(misoriented) + " quad edges are run in the same direction by both their quads (orientation not consistent)");
  if (nQ > 0 && q.euler_characteristic != q.input_euler_characteristic)
    say("the quad mesh's Euler characteristic is " + std::to_string(q.euler_characteristic) + ", the input's " +
        std::to_string(q.input_euler_characteristic));
  if (nQ > 0 && q.boundary_loops != q.input_boundary_loops)
    say("the quad mesh has " + std::to_string(q.boundary_loops) + " boundary loops, the input " + std::to_string(q.input_boundary_loops));
  if (nQ > 0 && q.components != q.input_components)
    say("the quad mesh has " + std::to_string(q.components) + " components, the input " + std::to_string(q.input_components));
  if (mismatches > 0)
    say(std::to_string(mismatches) +
        " singular mismatches: irregular vertices away from the cones, or cones without a quad vertex of valence 4 - n");
  if (inverted > 0) say(std::to_string(inverted) + " quads are inverted against the surface's normal");
  if (unmeasured > 0)
    say(std::to_string(unmeasured) +
        " quads were not measured against the surface (orientation, distance): they are so much larger "
        "than the input's triangles that measuring all would take more than linear time");
  q.seconds_check = linalg::seconds_since(t0);
}

std::string quad_warning(const QuadMesh& quads) {
  const QuadQuality& q = quads.quality;
  if (q.problems.empty()) return "";
  std::ostringstream s;
  s << "the quad mesh (" << q.quads << " quads) has problems: ";
  for (size_t i = 0; i < q.problems.size(); ++i) s << (i ? "; " : "") << q.problems[i];
  if (q.map_tiny_components > 0)
    s << " (the input has " << q.map_tiny_components << " component(s) smaller than one unit square, where no quad fits: see param_warning)";
  if (q.map_folds > 0)
    s << " (the map has " << q.map_folds << " folded or degenerate faces, the usual cause: see param_warning)";
  else if (q.failed_traces > 0 && q.input_boundary_loops > 0)
    s << " (is the boundary aligned, its edges in ParamOptions::aligned_edges?)";
  return s.str();
}

}  // namespace trivcon
