// SPDX-License-Identifier: MIT
// trivcon/quad.h: quad meshes extracted from integer-grid maps of generated meshes with known answers. Every test
// checks the quads from (V, Q) alone with the small counts below (edges, orientation, χ, boundary loops, valences,
// distance to the input), not the extraction's own report only.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <chrono>
#include <functional>
#include <cmath>
#include <map>
#include <set>

#include "trivcon/common.h"
#include "trivcon/error.h"
#include "trivcon/generate.h"
#include "trivcon/param.h"
#include "trivcon/quad.h"
#include "trivcon/request.h"
#include "quad/fill.h"
#include "quad/relax.h"
#include "support.h"

namespace trivcon {
namespace {

struct Pipeline {
  std::unique_ptr<FieldDesigner> designer;
  FieldOutcome outcome;
  Parametrization param;
  QuadMesh quads;
};

Pipeline run(const Mesh& m, FieldRequest r, ParamOptions o, bool align_sharp = false) {
  Pipeline out;
  out.designer = std::make_unique<FieldDesigner>(m.V, m.F);
  r.prescription.N = 4;
  out.outcome = solve_request(*out.designer, m.F, r);
  const Topology& t = out.designer->topology();
  if (r.align_boundary)
    for (int e = 0; e < t.num_edges; ++e)
      if (t.is_boundary_edge(e)) o.aligned_edges.push_back(e);
  if (align_sharp) o.aligned_edges.insert(o.aligned_edges.end(), out.outcome.sharp_edges.begin(), out.outcome.sharp_edges.end());
  out.param = parametrize(*out.designer, out.outcome.design, o);
  out.quads = extract_quads(*out.designer, out.param);
  return out;
}

// The 48 × 16 torus's map at 300 squares and its quads (a regular grid): the start of the tests that break one.
Pipeline torus_grid() {
  ParamOptions o;
  o.target_faces = 300;
  return run(make_torus(48, 16), {}, o);
}

// Q without the rows in `gone`.
Eigen::MatrixX4i without_quads(const Eigen::MatrixX4i& Q, const std::vector<int>& gone) {
  Eigen::MatrixX4i kept(Q.rows() - static_cast<Eigen::Index>(gone.size()), 4);
  for (int i = 0, j = 0; i < Q.rows(); ++i)
    if (std::find(gone.begin(), gone.end(), i) == gone.end()) kept.row(j++) = Q.row(i);
  return kept;
}

// What (V, Q) say on their own.
struct Counts {
  int vertices = 0, edges = 0, faces = 0, boundary_loops = 0;
  int overfull_edges = 0;               // in more than two quads
  int repeated_half_edges = 0;          // a directed side run by two quads (inconsistent orientation)
  int repeated_corners = 0;             // quads with a vertex twice
  int split_vertices = 0;               // vertices whose quads form more than one fan (linked by the edges at it)
  std::map<int, int> interior_valence;  // vertex -> number of edges, for vertices on no boundary edge
  int euler() const { return vertices - edges + faces; }
};

Counts count(const Eigen::MatrixXd& V, const Eigen::MatrixX4i& Q) {
  Counts c;
  c.faces = static_cast<int>(Q.rows());
  std::map<std::pair<int, int>, int> undirected, directed;
  std::set<int> used;
  for (int i = 0; i < Q.rows(); ++i) {
    std::set<int> distinct;
    for (int k = 0; k < 4; ++k) {
      const int a = Q(i, k), b = Q(i, (k + 1) % 4);
      EXPECT_GE(a, 0);
      EXPECT_LT(a, V.rows());
      used.insert(a), distinct.insert(a);
      ++undirected[{std::min(a, b), std::max(a, b)}];
      ++directed[{a, b}];
    }
    c.repeated_corners += distinct.size() != 4;
  }
  c.vertices = static_cast<int>(used.size());
  c.edges = static_cast<int>(undirected.size());
  for (const auto& [e, n] : undirected) c.overfull_edges += n > 2;
  for (const auto& [e, n] : directed) c.repeated_half_edges += n > 1;
  // Boundary sides: run by one quad; each boundary vertex of a manifold has one leaving it.
  std::map<int, int> next;
  std::set<int> boundary;
  for (const auto& [e, n] : directed)
    if (!directed.count({e.second, e.first})) next[e.first] = e.second, boundary.insert(e.first), boundary.insert(e.second);
  std::set<int> seen;
  for (const auto& [a, b] : next) {
    if (seen.count(a)) continue;
    ++c.boundary_loops;
    for (int v = a; !seen.count(v) && next.count(v); v = next[v]) seen.insert(v);
  }
  for (const auto& [e, n] : undirected)
    for (int v : {e.first, e.second})
      if (!boundary.count(v)) ++c.interior_valence[v];
  // Fans: at each vertex, its quads joined when they share an edge at it.
  std::map<std::pair<int, int>, std::vector<int>> edge_quads;  // (v, w) -> quads with the edge v–w
  std::map<int, std::vector<int>> vertex_quads;
  for (int i = 0; i < Q.rows(); ++i)
    for (int k = 0; k < 4; ++k) {
      vertex_quads[Q(i, k)].push_back(i);
      for (int w : {Q(i, (k + 1) % 4), Q(i, (k + 3) % 4)}) edge_quads[{Q(i, k), w}].push_back(i);
    }
  for (const auto& [v, quads] : vertex_quads) {
    std::map<int, int> parent;
    for (int q : quads) parent[q] = q;
    std::function<int(int)> root = [&](int q) { return parent[q] == q ? q : parent[q] = root(parent[q]); };
    for (auto it = edge_quads.lower_bound({v, -1}); it != edge_quads.end() && it->first.first == v; ++it)
      for (size_t j = 1; j < it->second.size(); ++j) parent[root(it->second[j])] = root(it->second[0]);
    std::set<int> roots;
    for (int q : quads) roots.insert(root(q));
    c.split_vertices += roots.size() > 1;
  }
  return c;
}

double distance_to_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  // Projection into the plane when inside, else the nearest of the three sides.
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double area2 = n.squaredNorm();
  if (area2 > 0) {
    const Eigen::Vector3d q = p - n * (p - a).dot(n) / area2;
    const double wa = (b - q).cross(c - q).dot(n), wb = (c - q).cross(a - q).dot(n), wc = (a - q).cross(b - q).dot(n);
    if (wa >= 0 && wb >= 0 && wc >= 0) return (p - q).norm();
  }
  auto segment = [&](const Eigen::Vector3d& x, const Eigen::Vector3d& y) {
    const double l = (y - x).squaredNorm();
    const double s = l > 0 ? std::clamp((p - x).dot(y - x) / l, 0.0, 1.0) : 0.0;
    return (p - (x + s * (y - x))).norm();
  };
  return std::min({segment(a, b), segment(b, c), segment(c, a)});
}

// Brute force over the input's triangles: the largest distance of a quad vertex from the surface.
double farthest_vertex(const Pipeline& r) {
  const MatrixX3d& V = r.designer->V();
  const MatrixX3i& F = r.designer->topology().F;
  double worst = 0;
  for (int i = 0; i < r.quads.V.rows(); ++i) {
    const Eigen::Vector3d p = r.quads.V.row(i).transpose();
    double best = 1e300;
    for (int f = 0; f < F.rows(); ++f) best = std::min(best, distance_to_triangle(p, V.row(F(f, 0)), V.row(F(f, 1)), V.row(F(f, 2))));
    worst = std::max(worst, best);
  }
  return worst;
}

// Each quad vertex is where its face and barycentric coordinates say.
void expect_located(const FieldDesigner& designer, const QuadMesh& q) {
  const MatrixX3d& V = designer.V();
  const MatrixX3i& F = designer.topology().F;
  for (int i = 0; i < q.V.rows(); ++i) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) p += q.vertex_barycentric(i, k) * V.row(F(q.vertex_face[i], k)).transpose();
    EXPECT_LT((p - q.V.row(i).transpose()).norm(), 1e-9) << "vertex " << i;
  }
}

// Quads whose normal points away from the input's outward normal at the nearest input face to their centre.
int inverted(const Pipeline& r) {
  const MatrixX3d& V = r.designer->V();
  const MatrixX3i& F = r.designer->topology().F;
  int n = 0;
  for (int i = 0; i < r.quads.Q.rows(); ++i) {
    Eigen::Vector3d p[4];
    for (int k = 0; k < 4; ++k) p[k] = r.quads.V.row(r.quads.Q(i, k)).transpose();
    const Eigen::Vector3d centre = (p[0] + p[1] + p[2] + p[3]) / 4;
    int nearest = 0;
    double best = 1e300;
    for (int f = 0; f < F.rows(); ++f) {
      const double d = distance_to_triangle(centre, V.row(F(f, 0)), V.row(F(f, 1)), V.row(F(f, 2)));
      if (d < best) best = d, nearest = f;
    }
    const Eigen::Vector3d a = V.row(F(nearest, 0)), b = V.row(F(nearest, 1)), c = V.row(F(nearest, 2));
    n += (p[2] - p[0]).cross(p[3] - p[1]).dot((b - a).cross(c - a)) <= 0;
  }
  return n;
}

// The guarantees every clean extraction must meet, from (V, Q).
// `brute_force`: also the checks that look at every input face for every quad (small meshes only).
void expect_clean(const Pipeline& r, const std::string& what, bool brute_force = true) {
  const QuadMesh& m = r.quads;
  const Topology& t = r.designer->topology();
  EXPECT_TRUE(m.quality.problems.empty()) << what << ": " << quad_warning(m);
  EXPECT_TRUE(m.other_faces.empty()) << what;
  ASSERT_GT(m.Q.rows(), 0) << what;
  const Counts c = count(m.V, m.Q);
  EXPECT_EQ(c.overfull_edges, 0) << what;
  EXPECT_EQ(c.repeated_half_edges, 0) << what;
  EXPECT_EQ(c.repeated_corners, 0) << what;
  EXPECT_EQ(c.split_vertices, 0) << what;
  EXPECT_EQ(c.vertices, m.V.rows()) << what << ": every vertex is in a quad";
  EXPECT_EQ(c.euler(), t.euler_characteristic()) << what;
  EXPECT_EQ(c.boundary_loops, static_cast<int>(t.boundary_loops.size())) << what;
  // Valence 4 − n at a cone of index n/4, 4 at every other interior vertex.
  std::map<int, int> cone;
  for (size_t k = 0; k < r.param.cones.size(); ++k) cone[r.param.cones[k]] = r.param.cone_index[k];
  std::set<int> cones_seen;
  for (const auto& [v, valence] : c.interior_valence) {
    const int input = m.vertex_cone[v];
    const int n = cone.count(input) ? cone[input] : 0;
    if (n != 0) cones_seen.insert(input);
    EXPECT_EQ(valence, 4 - n) << what << ": quad vertex " << v << " (input vertex " << input << ")";
  }
  EXPECT_EQ(cones_seen.size(), cone.size()) << what << ": every cone has its quad vertex";
  if (brute_force) {
    EXPECT_EQ(inverted(r), 0) << what;
  }
  // The measures of the report agree with these counts.
  EXPECT_EQ(m.quality.quads, c.faces) << what;
  EXPECT_EQ(m.quality.euler_characteristic, c.euler()) << what;
  EXPECT_EQ(m.quality.boundary_loops, c.boundary_loops) << what;
  EXPECT_TRUE(m.quality.manifold) << what;
  EXPECT_TRUE(m.quality.oriented) << what;
  EXPECT_EQ(m.quality.singular_mismatches, 0) << what;
  EXPECT_EQ(m.quality.inverted_quads, 0) << what;
  // Corners may be reflex where the map is strongly distorted (near close cones), so only the mean is bounded.
  EXPECT_GT(m.quality.mean_scaled_jacobian, 0.8) << what;
  EXPECT_LE(m.quality.min_scaled_jacobian, m.quality.mean_scaled_jacobian) << what;
  // Quads with a flat or reflex corner: the sine of some corner's angle about the quad's normal is not positive.
  int nonconvex = 0;
  for (int i = 0; i < m.Q.rows(); ++i) {
    Eigen::Vector3d p[4];
    for (int k = 0; k < 4; ++k) p[k] = m.V.row(m.Q(i, k)).transpose();
    const Eigen::Vector3d normal = (p[2] - p[0]).cross(p[3] - p[1]);
    bool flat = false;
    for (int k = 0; k < 4; ++k) flat = flat || !((p[(k + 1) % 4] - p[k]).cross(p[(k + 3) % 4] - p[k]).dot(normal) > 0);
    nonconvex += flat;
  }
  EXPECT_EQ(m.quality.nonconvex_quads, nonconvex) << what;
  EXPECT_EQ(m.quality.nonconvex_quads > 0, m.quality.min_scaled_jacobian <= 0) << what;
  // The vertices lie on the input surface.
  if (brute_force) {
    const Eigen::Vector3d extent = r.designer->V().colwise().maxCoeff() - r.designer->V().colwise().minCoeff();
    EXPECT_LT(farthest_vertex(r), 1e-9 * extent.norm()) << what;
  }
}

TEST(Quad, FlatCubeIsItsOwnGrid) {
  // A flat-sided cube of side 2 with its 8 corners +1/4 and the field along the sharp edges: at edge length 2/n
  // the quads are the n × n grid of each side.
  const Mesh m = make_cube_sphere(4, false);
  FieldRequest req;
  req.feature_degrees = 60;
  req.auto_place = true;
  for (int n : {4, 8, 3, 5}) {
    ParamOptions o;
    o.edge_length = 2.0 / n;
    const Pipeline r = run(m, req, o, true);
    const std::string what = "n = " + std::to_string(n);
    ASSERT_EQ(r.param.cones.size(), 8u);
    expect_clean(r, what);
    EXPECT_EQ(r.quads.Q.rows(), 6 * n * n) << what;
    const Counts c = count(r.quads.V, r.quads.Q);
    int three = 0, four = 0;
    for (const auto& [v, valence] : c.interior_valence) {
      three += valence == 3;
      four += valence == 4;
    }
    EXPECT_EQ(three, 8) << what;
    EXPECT_EQ(four, static_cast<int>(c.interior_valence.size()) - 8) << what;
    // Every quad is a square of side 2 / n (the sides are flat; a quad never bends over a sharp edge).
    for (int i = 0; i < r.quads.Q.rows(); ++i)
      for (int k = 0; k < 4; ++k)
        EXPECT_NEAR((r.quads.V.row(r.quads.Q(i, k)) - r.quads.V.row(r.quads.Q(i, (k + 1) % 4))).norm(), 2.0 / n, 1e-6) << what;
    EXPECT_NEAR(r.quads.quality.min_scaled_jacobian, 1.0, 1e-6) << what;
  }
}

TEST(Quad, ShearedBoxGetsAQuadCornerAtEachNarrowCorner) {
  // The sheared box's 21.8° corners between sharp edges (trivcon/features.h, narrow corners): each a quad
  // corner (valence 3) instead of a collapsed sector, the map without a flipped or degenerate triangle.
  const Mesh m = test::sheared_box(6);
  FieldRequest req;
  req.feature_degrees = 30;
  req.auto_place = true;
  for (int target : {300, 1000}) {
    ParamOptions o;
    o.target_faces = target;
    const Pipeline r = run(m, req, o, true);
    const std::string what = "target " + std::to_string(target);
    ASSERT_EQ(r.outcome.constraints.features.narrow.size(), 4u) << what;
    EXPECT_EQ(r.param.quality.flipped_faces + r.param.quality.degenerate_faces, 0) << what << ": " << param_warning(r.param);
    EXPECT_EQ(r.param.quality.unaligned_edges, 0) << what;
    expect_clean(r, what);
    for (const NarrowCorner& k : r.outcome.constraints.features.narrow) {
      const auto it = std::find(r.param.cones.begin(), r.param.cones.end(), k.vertex);
      ASSERT_NE(it, r.param.cones.end()) << what << ": corner " << k.vertex;
      EXPECT_EQ(r.param.cone_index[it - r.param.cones.begin()], 1) << what;
    }
  }
}

TEST(Quad, DegenerateFacesStayOutOfTheMeanDistortion) {
  // make_cube_sphere's sides sheared to 158.2° corners held by one triangle each: a map aligned to both sharp
  // edges there gives that triangle a straight (u, v) corner, so it is degenerate (a limit of maps on the mesh
  // as given, docs/param.md). Reported as such; the mean distortion is the rest's, not swamped by them.
  Mesh m = make_cube_sphere(6, false);
  for (int v = 0; v < m.V.rows(); ++v) m.V(v, 0) += 2.5 * m.V(v, 1);
  FieldRequest req;
  req.feature_degrees = 30;
  req.auto_place = true;
  ParamOptions o;
  o.target_faces = 300;
  const Pipeline r = run(m, req, o, true);
  const ParamQuality& q = r.param.quality;
  EXPECT_GT(q.degenerate_faces, 0);
  EXPECT_FALSE(std::isfinite(q.max_distortion));
  EXPECT_TRUE(std::isfinite(q.mean_distortion));
  EXPECT_GE(q.mean_distortion, 1.0);
  EXPECT_LT(q.mean_distortion, 3.0);
}

TEST(Quad, SingularitiesNearASharpEdgeMoveOntoIt) {
  // A capped cylinder of radius 1: --auto puts four +1/4 inside each cap. At 60 squares (a unit ≈ 0.6) they lie
  // within 1.5 units of the rims; with flat sectors allowed they move onto them (trivcon/features.h): each rim
  // vertex then turns its cap-side sector (168.75°) one step less, one quad corner of valence 3 on the rim.
  // Without, they stay inside the caps (that corner would be nearly flat), as at 400 squares.
  const Mesh m = make_capped_cylinder(6, 32, 12, 2.0);
  for (auto [target, flat] : {std::pair{60, true}, {60, false}, {400, true}}) {
    FieldRequest req;
    req.feature_degrees = 30;
    req.auto_place = true;
    req.auto_options.onto_flat_sectors = flat;
    cancel_for_map(req, FieldDesigner(m.V, m.F), 0, target);
    ParamOptions o;
    o.target_faces = target;
    const Pipeline r = run(m, req, o, true);
    const std::string what = "target " + std::to_string(target) + (flat ? ", flat sectors" : "");
    const std::vector<FeatureSnap>& moved = r.outcome.constraints.features.snapped;
    ASSERT_EQ(r.param.cones.size(), 8u) << what;
    int on_rim = 0;
    for (int v : r.param.cones) {
      const double radius = std::hypot(m.V(v, 0), m.V(v, 1));
      on_rim += std::abs(radius - 1) < 1e-9 && std::abs(std::abs(m.V(v, 2)) - 1) < 1e-9;
    }
    for (int n : r.param.cone_index) EXPECT_EQ(n, 1) << what;
    EXPECT_EQ(moved.size(), target == 60 && flat ? 8u : 0u) << what;
    EXPECT_EQ(on_rim, static_cast<int>(moved.size())) << what;
    const double unit = std::sqrt(r.designer->geometry().face_area.sum() / target);
    for (const FeatureSnap& k : moved) EXPECT_LT(k.distance, 1.5 * unit) << what;
    EXPECT_EQ(r.param.quality.flipped_faces + r.param.quality.degenerate_faces, 0) << what;
    expect_clean(r, what);
  }
}

// The round cube sphere (12 × 12 per side) with --auto's 8 cones of +1/4, mapped at 6 × 36 squares.
Pipeline cube_sphere_auto() {
  FieldRequest req;
  req.auto_place = true;
  ParamOptions o;
  o.target_faces = 6 * 36;
  return run(make_cube_sphere(12, true), req, o);
}

TEST(Quad, CubeSphereWithAutomaticCones) {
  const Pipeline r = cube_sphere_auto();
  ASSERT_EQ(r.param.cones.size(), 8u);
  for (int n : r.param.cone_index) EXPECT_EQ(n, 1);
  ASSERT_EQ(r.param.quality.flipped_faces, 0) << param_warning(r.param);
  expect_clean(r, "cube sphere");
  const Counts c = count(r.quads.V, r.quads.Q);
  int three = 0;
  for (const auto& [v, valence] : c.interior_valence) three += valence == 3;
  EXPECT_EQ(three, 8);
  EXPECT_NEAR(r.quads.Q.rows() / r.quads.quality.target_quads, 1.0, 0.3);
  EXPECT_LT(r.quads.quality.hausdorff_relative, 0.05);
}

TEST(Quad, CubeSphereWithItsCornersPrescribed) {
  // The 8 valence-3 vertices of the cube sphere as the +1/4 cones: 8 valence-3 quad vertices there, 4 elsewhere.
  const Mesh m = make_cube_sphere(8, true);
  const std::vector<int> corners = test::vertices_of_valence(m, 3);
  ASSERT_EQ(corners.size(), 8u);
  FieldRequest req;
  for (int v : corners) req.prescription.vertex[v] = 1;
  for (double h : {0.35, 0.5, 0.7}) {
    ParamOptions o;
    o.edge_length = h;
    const Pipeline r = run(m, req, o);
    const std::string what = "h = " + std::to_string(h);
    ASSERT_EQ(r.param.quality.flipped_faces, 0) << what << ": " << param_warning(r.param);
    expect_clean(r, what);
    const Counts c = count(r.quads.V, r.quads.Q);
    std::set<int> at_three;
    for (const auto& [v, valence] : c.interior_valence)
      if (valence == 3) at_three.insert(r.quads.vertex_cone[v]);
    EXPECT_EQ(at_three, std::set<int>(corners.begin(), corners.end())) << what;
  }
}

TEST(Quad, TorusIsARegularGrid) {
  const Pipeline r = torus_grid();
  ASSERT_TRUE(r.param.cones.empty());
  expect_clean(r, "torus");
  const Counts c = count(r.quads.V, r.quads.Q);
  EXPECT_EQ(c.euler(), 0);
  for (const auto& [v, valence] : c.interior_valence) EXPECT_EQ(valence, 4);
  EXPECT_EQ(static_cast<int>(c.interior_valence.size()), c.vertices);
  EXPECT_EQ(r.quads.quality.irregular_vertices, 0);
  // A regular grid on a torus: as many vertices as quads.
  EXPECT_EQ(c.vertices, c.faces);
  EXPECT_NEAR(r.quads.Q.rows() / r.quads.quality.target_quads, 1.0, 0.3);
}

TEST(Quad, GenusTwoWithAutomaticSingularities) {
  const Mesh m = make_genus_surface(2, 3);
  FieldRequest req;
  req.auto_place = true;
  ParamOptions o;
  o.target_faces = 800;
  const Pipeline r = run(m, req, o);
  ASSERT_EQ(r.param.quality.flipped_faces, 0) << param_warning(r.param);
  expect_clean(r, "genus 2");
  EXPECT_EQ(count(r.quads.V, r.quads.Q).euler(), -2);
  int irregular = 0;
  for (const auto& [v, valence] : count(r.quads.V, r.quads.Q).interior_valence) irregular += valence != 4;
  EXPECT_EQ(irregular, static_cast<int>(r.param.cones.size()));
}

TEST(Quad, DiskAndGridsEndOnTheirAlignedBoundary) {
  FieldRequest req;
  req.align_boundary = true;
  req.auto_place = true;
  {
    ParamOptions o;
    o.edge_length = 0.2;
    const Pipeline r = run(make_disk(12, 8), req, o);
    ASSERT_EQ(r.param.quality.flipped_faces, 0) << param_warning(r.param);
    expect_clean(r, "disk");
    EXPECT_EQ(count(r.quads.V, r.quads.Q).boundary_loops, 1);
  }
  {
    // The unit square with two square holes, 15 × 15 cells, at a quad edge of 2 cells: the grid itself.
    ParamOptions o;
    o.edge_length = 2.0 / 15;
    const Mesh m = make_holed_grid(15, 2);
    const Pipeline r = run(m, req, o);
    ASSERT_EQ(r.param.quality.flipped_faces, 0) << param_warning(r.param);
    expect_clean(r, "holed grid");
    const Counts c = count(r.quads.V, r.quads.Q);
    EXPECT_EQ(c.boundary_loops, 3);
    EXPECT_EQ(c.euler(), -1);
  }
  {
    ParamOptions o;
    o.target_faces = 150;
    const Pipeline r = run(make_annulus(8, 48), req, o);
    ASSERT_EQ(r.param.quality.flipped_faces, 0) << param_warning(r.param);
    expect_clean(r, "annulus");
    EXPECT_EQ(count(r.quads.V, r.quads.Q).boundary_loops, 2);
  }
}

// Singularities placed automatically, every boundary edge aligned (as `quad --auto` does).
FieldRequest aligned_boundary_auto() {
  FieldRequest req;
  req.align_boundary = true;
  req.auto_place = true;
  return req;
}

Mesh mesh_of(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3i>& faces) {
  Mesh m;
  m.V.resize(static_cast<int>(points.size()), 3);
  for (int i = 0; i < m.V.rows(); ++i) m.V.row(i) = points[i].transpose();
  m.F.resize(static_cast<int>(faces.size()), 3);
  for (int i = 0; i < m.F.rows(); ++i) m.F.row(i) = faces[i].transpose();
  return m;
}

// The (n + 1)² points (row y, column x at y (n + 1) + x) as a grid of n × n cells, each cut along its diagonal.
Mesh grid_of(int n, const std::vector<Eigen::Vector3d>& points) {
  const int stride = n + 1;
  std::vector<Eigen::Vector3i> faces;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const int p = y * stride + x;
      faces.emplace_back(p, p + 1, p + stride + 1);
      faces.emplace_back(p, p + stride + 1, p + stride);
    }
  return mesh_of(points, faces);
}

// The unit square, n × n cells (two triangles each), with a slit along x = 1/2 from the bottom side up to
// y = tip / n: the points on the slit below its tip are doubled, the cells left of it using one copy and those right of
// it the other (a seam of two patches left unwelded, as in the Utah teapot's file).
Mesh slit_square(int n, int tip) {
  const int stride = n + 1, half = n / 2;
  std::vector<Eigen::Vector3d> points;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) points.emplace_back(double(x) / n, double(y) / n, 0);
  std::map<int, int> copy;  // grid point on the slit below the tip → its copy, used by the cells right of it
  for (int y = 0; y < tip; ++y) {
    copy[y * stride + half] = static_cast<int>(points.size());
    points.push_back(points[y * stride + half]);
  }
  auto id = [&](int x, int y, bool right_of_slit) {
    const int p = y * stride + x;
    return right_of_slit && copy.count(p) ? copy[p] : p;
  };
  std::vector<Eigen::Vector3i> faces;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const bool right = x >= half;
      faces.emplace_back(id(x, y, right), id(x + 1, y, right), id(x + 1, y + 1, right));
      faces.emplace_back(id(x, y, right), id(x + 1, y + 1, right), id(x, y + 1, right));
    }
  return mesh_of(points, faces);
}

// The slit's tip is a boundary point where the aligned boundary turns back on itself: both its edges keep u
// constant, so the alignment makes only u whole there. The map makes v whole too (a turned boundary point), so the
// tip is a quad vertex and the slit's two sides end there; with v left fractional, the iso-line through the tip
// went on past it on one side only and the traces from the two sides did not meet.
TEST(Quad, SlitTipIsAQuadVertex) {
  const Mesh m = slit_square(20, 8);
  const FieldRequest req = aligned_boundary_auto();
  ParamOptions o;
  o.edge_length = 1 / 7.3;  // the tip 2/5 of the way up: about 2.9 units, not whole by itself
  const Pipeline r = run(m, req, o);
  EXPECT_EQ(r.param.quality.turned_boundary_points, 1);
  ASSERT_EQ(r.param.quality.flipped_faces, 0) << param_warning(r.param);
  EXPECT_EQ(r.quads.quality.unmatched_traces, 0);
  expect_clean(r, "slit square");
  const Counts c = count(r.quads.V, r.quads.Q);
  EXPECT_EQ(c.boundary_loops, 1);
  EXPECT_EQ(c.euler(), 1);
  // The tip (grid point (10, 8)) is a quad vertex: the map puts it on an integer point.
  const int tip = 8 * 21 + 10;
  EXPECT_EQ(std::count(r.quads.vertex_cone.data(), r.quads.vertex_cone.data() + r.quads.vertex_cone.size(), tip), 1)
      << "no quad vertex at the slit's tip";
}

// The unit square, n × n cells, without the cells [lo, hi)² (a square hole).
Mesh square_with_hole(int n, int lo, int hi) {
  const int stride = n + 1;
  std::vector<Eigen::Vector3d> points;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) points.emplace_back(double(x) / n, double(y) / n, 0);
  std::vector<Eigen::Vector3i> faces;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      if (x >= lo && x < hi && y >= lo && y < hi) continue;
      const int a = y * stride + x;
      faces.emplace_back(a, a + 1, a + stride + 1);
      faces.emplace_back(a, a + stride + 1, a + stride);
    }
  return mesh_of(points, faces);
}

// A hole about half a unit wide: rounded by itself, its sides' iso-lines could meet (the hole a point, or a slit
// whose two sides are one quad edge). Its width and height are kept at least a unit, so the quads keep the loop.
TEST(Quad, HoleSmallerThanASquareStaysOpen) {
  const Mesh m = square_with_hole(30, 14, 16);  // the hole 1/15 wide: 0.53 units at 8 units across
  const FieldRequest req = aligned_boundary_auto();
  ParamOptions o;
  o.edge_length = 1.0 / 8;
  const Pipeline r = run(m, req, o);
  ASSERT_EQ(r.param.quality.flipped_faces, 0) << param_warning(r.param);
  EXPECT_GE(r.param.quality.segments_opened, 1);
  expect_clean(r, "square with a small hole");
  const Counts c = count(r.quads.V, r.quads.Q);
  EXPECT_EQ(c.boundary_loops, 2);
  EXPECT_EQ(c.euler(), 0);
}

// The same hole at a fifth of a unit, kept a unit wide: the map's own check looks at the rings of the boundary
// vertices between aligned edges too (their angle against the turn between the edges), so a hole's corner that
// winds wrong is a winding error of the map, not only a trace of the quads that does not come back.
TEST(Quad, MapCheckSeesABoundaryRingThatWindsWrong) {
  const Mesh m = square_with_hole(30, 14, 16);
  const FieldRequest req = aligned_boundary_auto();
  for (double h : {1.0 / 8, 0.2, 0.3}) {
    ParamOptions o;
    o.edge_length = h;
    const Pipeline r = run(m, req, o);
    const QuadQuality& q = r.quads.quality;
    const ParamQuality& p = r.param.quality;
    const int map_problems = p.flipped_faces + p.degenerate_faces + p.winding_errors;
    if (q.unmatched_traces > 0 || q.failed_traces > 0) {
      EXPECT_GT(map_problems, 0) << "edge length " << h << ": the quads fail where the map says it has no problem";
    }
    if (h == 1.0 / 8) {
      EXPECT_EQ(map_problems, 0);
    }
  }
}

// A coin: a capped cylinder of radius 1 whose wall (one face tall, its rims sharp) is a quarter of a unit high at
// 100 squares. The singularities move onto the rims; the wall's faces then have every corner on a rim's iso-line
// or on a singularity's point, and each such face's extent is kept from 0 (a unit when a round makes it 0).
// Without that, the rounding left the map's mean singular-value ratio at 1.85.
TEST(Quad, CoinWallThinnerThanASquareKeepsAUnit) {
  const Mesh m = make_capped_cylinder(8, 48, 1, 0.06);
  FieldRequest req;
  req.feature_degrees = 30;
  req.auto_place = true;
  cancel_for_map(req, FieldDesigner(m.V, m.F), 0, 100);
  ParamOptions o;
  o.target_faces = 100;
  const Pipeline r = run(m, req, o, true);
  const ParamQuality& p = r.param.quality;
  ASSERT_EQ(p.flipped_faces + p.degenerate_faces, 0) << param_warning(r.param);
  EXPECT_GE(p.segments_opened, 1);
  EXPECT_LE(p.mean_distortion, 1.6);
  expect_clean(r, "coin");
  const Counts c = count(r.quads.V, r.quads.Q);
  EXPECT_EQ(c.boundary_loops, 0);
  EXPECT_EQ(c.euler(), 2);
}

// Two singularities on one feature line less than a unit apart, with no point between them whole along the line:
// the rounding put both on one integer and the faces along the line between them folded (on a plate with 27
// holes, the −1/4 moved onto its outer rim, 9 flipped faces). The line's length between them keeps its sign and a
// unit. An L-shaped sheet, its crease sharp and its boundary aligned, a unit 5 cells: a +1/4 and a −1/4 on the
// crease 2 cells apart (0.4 of a unit). Without it, the local search after the rounding pulled them apart
// again, but the map's mean singular-value ratio was 2.66.
TEST(Quad, SingularitiesOnOneFeatureLineCloserThanAUnitKeepOne) {
  const int n = 30, stride = n + 1, crease = n / 2;
  std::vector<Eigen::Vector3d> points;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x)
      points.emplace_back(double(x) / n, double(std::min(y, crease)) / n, double(std::max(y - crease, 0)) / n);
  const Mesh m = grid_of(n, points);
  FieldRequest req;
  req.align_boundary = true;
  req.feature_degrees = 30;
  const std::array<int, 2> cones{crease * stride + 14, crease * stride + 16};
  req.prescription.vertex[cones[0]] = 1;
  req.prescription.vertex[cones[1]] = -1;
  ParamOptions o;
  o.edge_length = 1.0 / 6;
  const Pipeline r = run(m, req, o, true);
  ASSERT_TRUE(r.outcome.verified);
  const ParamQuality& p = r.param.quality;
  ASSERT_EQ(p.flipped_faces + p.degenerate_faces + p.winding_errors, 0) << param_warning(r.param);
  EXPECT_EQ(p.unaligned_edges, 0);
  EXPECT_GE(p.segments_opened, 1);
  EXPECT_LE(p.mean_distortion, 1.8);
  expect_clean(r, "L-shaped sheet with two singularities on its crease");
  // Each singularity its own quad vertex (not one point for both).
  std::map<int, int> at_cone;
  for (int v = 0; v < static_cast<int>(r.quads.vertex_cone.size()); ++v)
    if (req.prescription.vertex.count(r.quads.vertex_cone[v])) ++at_cone[r.quads.vertex_cone[v]];
  EXPECT_EQ(at_cone, (std::map<int, int>{{cones[0], 1}, {cones[1], 1}}));
  // With the sectors turned for them, as `param` and `quad` make the field (FieldRequest::sectors_for_singularities,
  // turn_sectors_for_singularities): clean without opening anything.
  FieldRequest request = req;
  request.sectors_for_singularities = true;
  const Pipeline q = run(m, request, o, true);
  ASSERT_TRUE(q.outcome.verified);
  EXPECT_EQ(q.outcome.constraints.features.given_sectors.size(), 2u);
  EXPECT_EQ(q.param.quality.flipped_faces + q.param.quality.degenerate_faces + q.param.quality.winding_errors, 0) << param_warning(q.param);
  EXPECT_LE(q.param.quality.mean_distortion, 1.5);
  expect_clean(q, "L-shaped sheet, sectors turned for its singularities");
}

// A line of aligned edges and a spur of one more leaving it at a narrow corner inside one triangle keep the same
// coordinate constant there (the field runs along both within kAlignedEdgeTolerance): both edges lie on one
// iso-line through their shared corner, so the triangle is a segment in (u, v) whatever the integers (3holes
// with its sharp edges at 40° had one). The spur, whose far end is on no other aligned edge, is left free
// (counted unaligned) and the triangle keeps its shape. A flat square, 12 × 12 cells, its boundary aligned (the
// field runs along x); the line is the row y = 6, the spur the diagonal from (4, 6) to (5, 7) with (5, 7)
// lowered to y = 6.3 (a corner of 16.7°).
TEST(Quad, SpurAtANarrowCornerInOneTriangleIsLeftFree) {
  const int n = 12, stride = n + 1;
  std::vector<Eigen::Vector3d> points;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) points.emplace_back(double(x) / n, double(y) / n, 0);
  points[7 * stride + 5].y() = 6.3 / n;
  const Mesh m = grid_of(n, points);
  const Topology t = build_topology(m.F, static_cast<int>(m.V.rows()));
  ParamOptions o;
  o.edge_length = 1.0 / 6;
  for (int x = 0; x < n; ++x) o.aligned_edges.push_back(edge_between(t, 6 * stride + x, 6 * stride + x + 1));
  const int spur = edge_between(t, 6 * stride + 4, 7 * stride + 5);
  o.aligned_edges.push_back(spur);
  const Pipeline r = run(m, aligned_boundary_auto(), o);
  const ParamQuality& p = r.param.quality;
  EXPECT_EQ(p.unaligned_edges, 1);
  EXPECT_FALSE(std::binary_search(r.param.aligned_edges.begin(), r.param.aligned_edges.end(), spur));
  ASSERT_EQ(p.flipped_faces + p.degenerate_faces, 0) << param_warning(r.param);
  expect_clean(r, "square with a spur at a narrow corner");
}

// A sphere exported unwelded (unwelded_sphere): each pole a row of points at one place, the seam a boundary loop
// along both its sides. The map puts each pole row on one integer point (docs/param.md), and the quad mesh has one
// vertex there, not one per point of the row; the boundary's last direction at the seam's end beside a pole, whose
// next face is a segment in (u, v), stays with the face before it. The quads end on the seam, χ and the loop are
// the input's.
TEST(Quad, UnweldedSphereHasOneQuadVertexAtEachPole) {
  const Mesh m = test::unwelded_sphere(24, 48);
  FieldRequest req;
  req.align_boundary = true;
  req.auto_place = true;
  ParamOptions o;
  o.target_faces = 600;
  cancel_for_map(req, FieldDesigner(m.V, m.F), 0, o.target_faces);
  const Pipeline r = run(m, req, o);
  ASSERT_EQ(r.param.quality.flipped_faces + r.param.quality.degenerate_faces, 0) << param_warning(r.param);
  EXPECT_EQ(r.param.quality.collapsed_faces, 2 * 48);
  expect_clean(r, "unwelded sphere");
  EXPECT_EQ(r.quads.quality.failed_traces, 0);
  for (double z : {-1.0, 1.0}) {
    int at_pole = 0;
    for (int i = 0; i < r.quads.V.rows(); ++i) at_pole += (r.quads.V.row(i) - Eigen::RowVector3d(0, 0, z)).norm() < 1e-12;
    EXPECT_EQ(at_pole, 1) << "pole " << z;
  }
}

// A parallelogram (the unit square's grid sheared by `degrees`): at two of its corners one triangle holds both
// boundary edges, so its field follows one of them and meets the other off a right angle. Within
// kAlignedEdgeTolerance that edge is put on an iso-line too, and the corner becomes a quad corner: the quads are
// the sheared grid itself, with no trace leaving the surface.
Mesh parallelogram(int n, double degrees, bool other_diagonal = false) {
  Mesh m;
  const double shear = std::tan(degrees * 3.141592653589793 / 180);
  m.V.resize((n + 1) * (n + 1), 3);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.V.row(j * (n + 1) + i) << (i + shear * j) / n, static_cast<double>(j) / n, 0;
  m.F.resize(2 * n * n, 3);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, f = 2 * (j * n + i);
      if (other_diagonal) {
        m.F.row(f) << a, a + 1, a + n + 1;
        m.F.row(f + 1) << a + 1, a + n + 2, a + n + 1;
      } else {
        m.F.row(f) << a, a + 1, a + n + 2;
        m.F.row(f + 1) << a, a + n + 2, a + n + 1;
      }
    }
  return m;
}

TEST(Quad, ParallelogramCornersInOneTriangleBecomeQuadCorners) {
  FieldRequest req;
  req.align_boundary = true;
  req.auto_place = true;
  for (double degrees : {10.0, 20.0, 25.0}) {
    ParamOptions o;
    o.target_faces = 100;
    const Pipeline r = run(parallelogram(20, degrees), req, o);
    const std::string what = "sheared by " + std::to_string(degrees) + " degrees";
    EXPECT_EQ(r.param.quality.unaligned_edges, 0) << what;
    EXPECT_EQ(r.param.quality.flipped_faces + r.param.quality.degenerate_faces, 0) << what << ": " << param_warning(r.param);
    expect_clean(r, what);
    EXPECT_EQ(r.quads.quality.irregular_vertices, 0) << what;
    if (degrees > 20) continue;  // valid, but not the grid itself
    EXPECT_EQ(r.quads.quality.quads, 100) << what;
    // Every quad is the grid's parallelogram: its scaled Jacobian is the cosine of the shear.
    EXPECT_NEAR(r.quads.quality.min_scaled_jacobian, std::cos(degrees * 3.141592653589793 / 180), 0.02) << what;
  }
  // Past the tolerance (a corner of 45° off a right angle cannot be a quad corner) the edge is left unaligned and
  // counted; the quads say why they fail.
  ParamOptions o;
  o.target_faces = 100;
  const Pipeline r = run(parallelogram(20, 45), req, o);
  EXPECT_GT(r.param.quality.unaligned_edges, 0);
  EXPECT_FALSE(r.quads.quality.problems.empty());
  // With the other diagonal the triangles held alone are the acute corners: at 45°–60° (sheared by 30°–45°), an
  // acute corner cannot be flat, so the edge the field does not follow is aligned across the other, and the
  // corner is a quad corner.
  for (double degrees : {35.0, 40.0}) {
    const Pipeline acute = run(parallelogram(20, degrees, true), req, o);
    const std::string what = "acute corners, sheared by " + std::to_string(degrees) + " degrees";
    EXPECT_EQ(acute.param.quality.unaligned_edges, 0) << what;
    EXPECT_EQ(acute.param.quality.flipped_faces + acute.param.quality.degenerate_faces, 0) << what << ": " << param_warning(acute.param);
    expect_clean(acute, what);
  }
}

TEST(Quad, UnalignedBoundaryIsReported) {
  // Without the boundary on iso-lines the traces leave the surface there: said, not hidden.
  ParamOptions o;
  o.edge_length = 0.2;
  const Pipeline r = run(make_disk(12, 8), {}, o);
  EXPECT_GT(r.quads.quality.failed_traces, 0);
  EXPECT_FALSE(r.quads.quality.problems.empty());
  EXPECT_TRUE(test::contains(quad_warning(r.quads), "aligned")) << quad_warning(r.quads);
}

TEST(Quad, InputWithMixedOrientation) {
  // Every third face of the torus reversed: the topology orients them back, and the quads follow its orientation.
  Mesh m = make_torus(48, 16);
  for (int f = 0; f < m.F.rows(); f += 3) std::swap(m.F(f, 1), m.F(f, 2));
  ParamOptions o;
  o.target_faces = 300;
  const Pipeline r = run(m, {}, o);
  ASSERT_FALSE(r.designer->topology().flipped_faces.empty());
  expect_clean(r, "mixed orientation");
}

TEST(Quad, SeveralComponents) {
  // Apart in space, so that the nearest input face to a quad is one of its own component.
  std::vector<Mesh> parts{make_torus(36, 12), make_cube_sphere(6, true), make_holed_grid(12, 1)};
  for (size_t i = 0; i < parts.size(); ++i) parts[i].V.col(0).array() += 4.0 * static_cast<double>(i);
  const Mesh m = concatenate(parts);
  FieldRequest req;
  req.auto_place = true;
  req.align_boundary = true;
  ParamOptions o;
  o.target_faces = 600;
  const Pipeline r = run(m, req, o);
  ASSERT_EQ(r.param.quality.flipped_faces, 0) << param_warning(r.param);
  expect_clean(r, "three components");
  EXPECT_EQ(r.quads.quality.components, 3);
  EXPECT_EQ(r.quads.quality.input_components, 3);
}

// A component of a few unit squares gets 16 of its own size (docs/param.md, "Small components"): a cube sphere of
// radius 0.1 beside one of radius 1 at 200 squares (about 2 of them on the small one) gets at least 12 quads,
// and both are clean; the target's total is kept. With a fifth of the target too little to raise it, it is not.
TEST(Quad, SmallComponentGetsSquaresOfItsOwnSize) {
  std::vector<Mesh> parts{make_cube_sphere(12, true), make_cube_sphere(6, true)};
  parts[1].V *= 0.1;
  parts[1].V.col(0).array() += 3.0;
  const Mesh m = concatenate(parts);
  FieldRequest req;
  req.auto_place = true;
  ParamOptions o;
  o.target_faces = 200;
  const Pipeline r = run(m, req, o);
  EXPECT_EQ(r.param.quality.small_components, 1);
  ASSERT_EQ(r.param.quality.flipped_faces + r.param.quality.degenerate_faces, 0) << param_warning(r.param);
  expect_clean(r, "two spheres");
  int small_quads = 0;
  for (int i = 0; i < r.quads.Q.rows(); ++i) small_quads += r.quads.V(r.quads.Q(i, 0), 0) > 2.0;
  EXPECT_GE(small_quads, 12);
  EXPECT_NEAR(r.param.quality.unit_squares, 200, 0.1 * 200);
  o.target_faces = 20;  // 14 squares more than 2: more than a fifth of 20
  const Pipeline coarse = run(m, req, o);
  EXPECT_EQ(coarse.param.quality.small_components, 0);
}

// Components smaller than one unit square (debris of a scan) are counted, and the warning says that no quad
// fits in them (rather than only "a larger edge length"): a cube sphere with 30 stray triangles of 1e-6 squares.
TEST(Quad, ComponentsSmallerThanASquareAreNamed) {
  std::vector<Mesh> parts{make_cube_sphere(8, true)};
  for (int i = 0; i < 30; ++i) {
    Mesh tri;
    tri.V = (MatrixX3d(3, 3) << 0, 0, 0, 1e-4, 0, 0, 0, 1e-4, 0).finished();
    tri.V.col(0).array() += 3.0 + 0.1 * i;
    tri.F = (MatrixX3i(1, 3) << 0, 1, 2).finished();
    parts.push_back(tri);
  }
  const Mesh m = concatenate(parts);
  FieldRequest req;
  req.auto_place = true;
  req.align_boundary = true;
  ParamOptions o;
  o.target_faces = 200;
  const Pipeline r = run(m, req, o);
  const ParamQuality& q = r.param.quality;
  EXPECT_EQ(q.tiny_components + q.small_components, 30);  // the sphere is neither
  ASSERT_GT(q.tiny_components, 0);
  EXPECT_GE(q.first_tiny_face, parts[0].F.rows());
  EXPECT_LT(q.first_tiny_squares, 1e-3);
  EXPECT_LE(q.tiny_component_folds, q.flipped_faces + q.degenerate_faces);
  EXPECT_NE(param_warning(r.param).find(std::to_string(q.tiny_components) + " component(s) of the mesh are smaller than one unit square (first: the one of face " +
                                        std::to_string(q.first_tiny_face) + ", "),
            std::string::npos)
      << param_warning(r.param);
  // The stray triangles get no quads: the quad mesh's components and χ are not the input's, and the warning says why.
  EXPECT_NE(quad_warning(r.quads).find("(the input has " + std::to_string(q.tiny_components) + " component(s) smaller than one unit square"),
            std::string::npos)
      << quad_warning(r.quads);
  const Pipeline sphere = run(parts[0], req, o);
  EXPECT_EQ(sphere.param.quality.tiny_components, 0);
  EXPECT_EQ(sphere.param.quality.small_components, 0);
}

// A map with folds: the extraction ends, and says what failed instead of hiding it.
TEST(Quad, FoldsAreReportedNotHidden) {
  Pipeline r = torus_grid();
  // Push one vertex's (u, v) (every corner of it alike, so the map stays seamless off the cut) far over its ring.
  const Topology& t = r.designer->topology();
  for (int v : {100, 400}) {
    for (int j = t.vertex_face_offsets[v]; j < t.vertex_face_offsets[v + 1]; ++j) {
      const int f = t.vertex_faces[j];
      for (int k = 0; k < 3; ++k)
        if (t.F(f, k) == v) r.param.uv(3 * f + k, 0) += 2.3, r.param.uv(3 * f + k, 1) += 1.7;
    }
  }
  const QuadMesh q = extract_quads(*r.designer, r.param);
  EXPECT_FALSE(q.quality.problems.empty());
  EXPECT_FALSE(quad_warning(q).empty());
  EXPECT_GT(q.quality.failed_traces + q.quality.unmatched_traces + q.quality.dropped_points, 0);
  // The quads and the other faces together: every walk closed, and each side of an edge is run once.
  EXPECT_EQ(q.quality.open_faces, 0);
  std::map<std::pair<int, int>, int> sides;
  std::set<int> used;
  std::vector<std::vector<int>> all = q.other_faces;
  for (int i = 0; i < q.Q.rows(); ++i) all.push_back({q.Q(i, 0), q.Q(i, 1), q.Q(i, 2), q.Q(i, 3)});
  for (const auto& face : all)
    for (size_t k = 0; k < face.size(); ++k) {
      ASSERT_LT(face[k], q.V.rows());
      used.insert(face[k]);
      ++sides[{face[k], face[(k + 1) % face.size()]}];
    }
  int unpaired = 0;
  for (const auto& [side, n] : sides) {
    EXPECT_EQ(n, 1);
    unpaired += !sides.count({side.second, side.first});
  }
  EXPECT_EQ(unpaired, 0);                                                                                           // closed
  EXPECT_EQ(static_cast<int>(used.size()) - static_cast<int>(sides.size()) / 2 + static_cast<int>(all.size()), 0);  // χ of the torus
  // Garbage (u, v): random per vertex. Ends, reports, does not throw.
  Parametrization garbage = r.param;
  unsigned seed = 12345;
  std::vector<Eigen::Vector2d> at(t.num_vertices);
  for (auto& p : at) {
    seed = seed * 1103515245u + 12345u;
    const double a = (seed >> 8) % 1000 / 100.0;
    seed = seed * 1103515245u + 12345u;
    p = Eigen::Vector2d(a, (seed >> 8) % 1000 / 100.0);
  }
  garbage.cut_edges.clear();
  garbage.rotation.setZero();
  garbage.translation.setZero();
  for (int f = 0; f < t.num_faces; ++f)
    for (int k = 0; k < 3; ++k) garbage.uv.row(3 * f + k) = at[t.F(f, k)].transpose();
  const QuadMesh g = extract_quads(*r.designer, garbage);
  EXPECT_FALSE(g.quality.problems.empty());
  EXPECT_GT(g.quality.dropped_points + g.quality.failed_traces + g.quality.unmatched_traces, 0);
}

// The fill (src/quad/fill.h): the four quads around a vertex taken out leave an octagon, as the traces that
// fail around a fold leave larger faces; it is filled with four quads around one new vertex on the surface, whose
// spokes go to the corners that lost theirs (every valence right again), also when a spur (an edge into the
// face and back, to a vertex in no other face) is in the walk, and when the octagon is two faces of 5 and 7
// sides split by a path through the old vertex (merged, the path's rest a spur).
TEST(Quad, FacesLeftByFailedTracesAreFilledWithQuads) {
  const Pipeline r = torus_grid();
  ASSERT_TRUE(r.quads.quality.problems.empty()) << quad_warning(r.quads);
  const int x = r.quads.Q(0, 0);
  for (std::string shape : {"octagon", "spur", "odd pair"}) {
    QuadMesh q = r.quads;
    std::vector<int> gone;
    std::map<int, std::array<int, 2>> path;  // a → (b, c) of each quad (x, a, b, c) around x
    for (int i = 0; i < q.Q.rows(); ++i)
      for (int k = 0; k < 4; ++k)
        if (q.Q(i, k) == x) gone.push_back(i), path[q.Q(i, (k + 1) % 4)] = {q.Q(i, (k + 2) % 4), q.Q(i, (k + 3) % 4)};
    ASSERT_EQ(gone.size(), 4u);
    std::vector<int> octagon;
    for (int a = path.begin()->first; octagon.size() < 8; a = path.at(a)[1]) octagon.push_back(a), octagon.push_back(path.at(a)[0]);
    ASSERT_EQ(octagon.front(), path.begin()->first);
    q.Q = without_quads(q.Q, gone);
    q.other_faces = {octagon};
    if (shape == "spur") q.other_faces[0].insert(q.other_faces[0].begin() + 1, {x, octagon[0]});
    if (shape == "odd pair")  // octagon[0] a neighbour of x, octagon[3] a diagonal one
      q.other_faces = {{octagon[0], octagon[1], octagon[2], octagon[3], x},
                       {octagon[3], octagon[4], octagon[5], octagon[6], octagon[7], octagon[0], x}};
    const Eigen::Vector3d was = r.quads.V.row(x).transpose();
    ASSERT_EQ(quad::fill_faces(*r.designer, r.param, q), 1) << shape;
    SCOPED_TRACE(shape);
    EXPECT_TRUE(q.other_faces.empty());
    // x was in no face: it is gone, the new vertex last.
    EXPECT_EQ(q.V.rows(), r.quads.V.rows());
    EXPECT_EQ(q.Q.rows(), r.quads.Q.rows());
    EXPECT_LT((q.V.row(q.V.rows() - 1).transpose() - was).norm(), 0.1 * (r.quads.V.row(octagon[0]) - r.quads.V.row(x)).norm());
    expect_located(*r.designer, q);
    check_quads(*r.designer, r.param, q);
    EXPECT_TRUE(q.quality.problems.empty()) << quad_warning(q);
    EXPECT_EQ(q.quality.irregular_vertices, 0);
    EXPECT_EQ(q.quality.euler_characteristic, 0);
    EXPECT_GT(q.quality.min_scaled_jacobian, 0.5);
  }
}

// A hexagon (two quads beside each other taken out) is split by the diagonal that was their common edge: the two
// quads come back, no vertex is added, every valence is right.
TEST(Quad, HexagonIsSplitByADiagonal) {
  const Pipeline r = torus_grid();
  ASSERT_TRUE(r.quads.quality.problems.empty()) << quad_warning(r.quads);
  QuadMesh q = r.quads;
  const int a = q.Q(0, 1), b = q.Q(0, 2);  // quad 0's edge a → b; the quad across it runs b → a
  int other = -1, at = -1;
  for (int i = 1; i < q.Q.rows() && other < 0; ++i)
    for (int k = 0; k < 4; ++k)
      if (q.Q(i, k) == b && q.Q(i, (k + 1) % 4) == a) other = i, at = k;
  ASSERT_GE(other, 0);
  // Quad 0 from b round to a, then the other from after a round to before b.
  const std::vector<int> hexagon{b, q.Q(0, 3), q.Q(0, 0), a, q.Q(other, (at + 2) % 4), q.Q(other, (at + 3) % 4)};
  q.Q = without_quads(q.Q, {0, other});
  q.other_faces = {hexagon};
  ASSERT_EQ(quad::fill_faces(*r.designer, r.param, q), 1);
  EXPECT_TRUE(q.other_faces.empty());
  EXPECT_EQ(q.V.rows(), r.quads.V.rows());
  EXPECT_EQ(q.Q.rows(), r.quads.Q.rows());
  bool rejoined = false;
  for (int i = 0; i < q.Q.rows(); ++i)
    for (int k = 0; k < 4; ++k) rejoined = rejoined || (q.Q(i, k) == a && q.Q(i, (k + 3) % 4) == b) || (q.Q(i, k) == b && q.Q(i, (k + 3) % 4) == a);
  EXPECT_TRUE(rejoined);
  check_quads(*r.designer, r.param, q);
  EXPECT_TRUE(q.quality.problems.empty()) << quad_warning(q);
  EXPECT_EQ(q.quality.irregular_vertices, 0);
}

// check_quads on its own: a quad mesh with one quad removed has a hole the input does not have.
TEST(Quad, CheckFindsAHole) {
  const Pipeline r = torus_grid();
  QuadMesh q = r.quads;
  ASSERT_TRUE(q.quality.problems.empty()) << quad_warning(q);
  q.Q = q.Q.topRows(q.Q.rows() - 1).eval();
  q.quality = {};
  check_quads(*r.designer, r.param, q);
  EXPECT_EQ(q.quality.boundary_loops, 1);
  EXPECT_EQ(q.quality.euler_characteristic, -1);
  EXPECT_EQ(q.quality.problems.size(), 2u) << quad_warning(q);  // χ and the boundary loops
  // Reversing one quad breaks the orientation.
  QuadMesh flipped = r.quads;
  flipped.Q.row(0) = flipped.Q.row(0).reverse().eval();
  flipped.quality = {};
  check_quads(*r.designer, r.param, flipped);
  EXPECT_FALSE(flipped.quality.oriented);
  EXPECT_EQ(flipped.quality.inverted_quads, 1);
  QuadMesh bad = r.quads;
  bad.Q(0, 0) = static_cast<int>(bad.V.rows());
  EXPECT_THROW(check_quads(*r.designer, r.param, bad), Error);
}

// The relaxation (src/quad/relax.h): a vertex put onto its diagonal neighbour leaves its quads degenerate or
// turned over; relaxing moves it back out, on the surface, without touching the connectivity or the others'
// places more than around it.
TEST(Quad, RelaxationUndoesAnInvertedQuad) {
  Pipeline r = torus_grid();
  ASSERT_TRUE(r.quads.quality.problems.empty()) << quad_warning(r.quads);
  ASSERT_EQ(inverted(r), 0);
  QuadMesh& q = r.quads;
  const Eigen::MatrixX4i Q = q.Q;
  const int v = q.Q(0, 0), w = q.Q(0, 2);  // opposite corners of quad 0
  q.V.row(v) = q.V.row(w);
  q.vertex_face[v] = q.vertex_face[w];
  q.vertex_barycentric.row(v) = q.vertex_barycentric.row(w);
  q.vertex_cone[v] = -1;
  const int broken = inverted(r);
  ASSERT_GE(broken, 1);
  check_quads(*r.designer, r.param, q);
  EXPECT_GE(q.quality.nonconvex_quads, 1);
  q.quality = {};
  EXPECT_GE(quad::relax_quads(*r.designer, r.param, q), 1);
  EXPECT_EQ(inverted(r), 0);
  EXPECT_TRUE(q.Q == Q);
  EXPECT_LT(farthest_vertex(r), 1e-9);
  expect_located(*r.designer, q);
  q.quality = {};
  check_quads(*r.designer, r.param, q);
  EXPECT_TRUE(q.quality.problems.empty()) << quad_warning(q);
  EXPECT_GT(q.quality.min_scaled_jacobian, 0.2);
  EXPECT_EQ(q.quality.nonconvex_quads, 0);
}

// A quad at a cone twisted: the two edge-neighbours of a valence-3 vertex of the cube sphere trade places, so that
// the quads between them turn over or get reflex corners. The relaxation untwists them on the surface; the cone's
// vertex, which it never moves, stays where it was.
TEST(Quad, RelaxationUntwistsQuadsAtACone) {
  Pipeline r = cube_sphere_auto();
  ASSERT_TRUE(r.quads.quality.problems.empty()) << quad_warning(r.quads);
  QuadMesh& q = r.quads;
  int cone = -1;
  for (int v = 0; v < q.V.rows() && cone < 0; ++v)
    if (q.vertex_cone[v] >= 0 && std::count(r.param.cones.begin(), r.param.cones.end(), q.vertex_cone[v])) cone = v;
  ASSERT_GE(cone, 0);
  int i = 0, k = 0;
  for (; i < q.Q.rows(); ++i) {
    for (k = 0; k < 4 && q.Q(i, k) != cone; ++k) {
    }
    if (k < 4) break;
  }
  ASSERT_LT(i, q.Q.rows());
  const int a = q.Q(i, (k + 1) % 4), d = q.Q(i, (k + 3) % 4);
  const Eigen::RowVector3d cone_at = q.V.row(cone);
  const Eigen::MatrixX4i Q = q.Q;
  for (auto* rows : {&q.V, &q.vertex_barycentric}) {
    const Eigen::RowVectorXd x = rows->row(a);
    rows->row(a) = rows->row(d);
    rows->row(d) = x;
  }
  std::swap(q.vertex_face[a], q.vertex_face[d]);
  q.vertex_cone[a] = q.vertex_cone[d] = -1;
  q.quality = {};
  check_quads(*r.designer, r.param, q);
  ASSERT_GE(q.quality.nonconvex_quads + q.quality.inverted_quads, 1);
  q.quality = {};
  EXPECT_GE(quad::relax_quads(*r.designer, r.param, q), 2);
  EXPECT_EQ(inverted(r), 0);
  EXPECT_TRUE(q.Q == Q);
  EXPECT_EQ(q.V.row(cone), cone_at);
  EXPECT_LT(farthest_vertex(r), 1e-9);
  expect_located(*r.designer, q);
  check_quads(*r.designer, r.param, q);
  EXPECT_TRUE(q.quality.problems.empty()) << quad_warning(q);
  EXPECT_EQ(q.quality.nonconvex_quads, 0);
  EXPECT_GT(q.quality.min_scaled_jacobian, 0.2);
}

TEST(Quad, RefusesAMapOfAnotherMesh) {
  const Mesh m = make_torus(48, 16), other = make_torus(24, 8);
  ParamOptions o;
  o.target_faces = 300;
  const Pipeline r = run(m, {}, o);
  FieldDesigner d(other.V, other.F);
  try {
    extract_quads(d, r.param);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "quad: the map does not belong to this mesh (4608 corner rows for 384 faces)");
  }
  Parametrization far = r.param;
  far.uv(0, 0) = 1e12;
  try {
    extract_quads(*r.designer, far);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_TRUE(std::string(e.what()).find("beyond 2^30") != std::string::npos) << e.what();
  }
  Parametrization huge = r.param;
  huge.uv *= 1e4;  // still seamless off the cut, but 10⁸ times the squares
  try {
    extract_quads(*r.designer, huge);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_TRUE(test::contains(e.what(), "unit squares (at most 2^27")) << e.what();
  }
}

// A 100k-face torus at about 10k quads: the extraction is linear (the bound is loose for a loaded machine).
TEST(Quad, LargeMeshIsFast) {
  const Mesh m = make_torus(400, 125);
  ParamOptions o;
  o.target_faces = 10000;
  const Pipeline r = run(m, {}, o);
  expect_clean(r, "large torus", false);
  EXPECT_LT(r.quads.quality.seconds_extract, 2.0);
  std::printf(
      "large torus: %d faces, %d quads, extract %.3f s, check %.3f s, map %.2f s\n", static_cast<int>(m.F.rows()),
      static_cast<int>(r.quads.Q.rows()), r.quads.quality.seconds_extract, r.quads.quality.seconds_check,
      r.param.quality.seconds_cut + r.param.quality.seconds_setup + r.param.quality.seconds_rounding + r.param.quality.seconds_untangling + r.param.quality.seconds_stiffening);
}

}  // namespace
}  // namespace trivcon
