// SPDX-License-Identifier: MIT
// Sharp feature edges (trivcon/features.h): detection, the fixed faces that make a field follow them (with
// --auto's placement and with singularities given by hand), conflicts at corners, and the .sharp / .rosy
// files QuadWild reads.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <set>

#include "support.h"
#include "trivcon/angles.h"
#include "trivcon/auto.h"
#include "trivcon/constraints.h"
#include "trivcon/error.h"
#include "trivcon/features.h"
#include "trivcon/field_io.h"
#include "trivcon/generate.h"
#include "trivcon/io.h"

namespace trivcon {
namespace {

using test::error_of;
using test::temp_file;
using test::write_text;

// A fandisk-like block: the flat-faced cube with its top (y = 1) bulged into a curved roof,
// y += 0.3 (1 − x²)(y + 1)/2. The sides x = ±1, z = ±1 and the bottom stay flat; the top edges along x are
// curves that meet the vertical edges at non-right angles (about 59°, since dy/dx = ∓0.6 there), so the
// faces at those four corners cannot follow both edges with a cross.
Mesh bulged_block(int n) {
  Mesh m = make_cube_sphere(n, false);
  for (int v = 0; v < m.V.rows(); ++v) m.V(v, 1) += 0.3 * (1 - m.V(v, 0) * m.V(v, 0)) * (m.V(v, 1) + 1) / 2;
  return m;
}

// The oriented faces' unit normal, from the vertex positions alone.
Eigen::Vector3d unit_normal(const MatrixX3d& V, const Topology& t, int f) {
  const Eigen::Vector3d p0 = V.row(t.F(f, 0)), p1 = V.row(t.F(f, 1)), p2 = V.row(t.F(f, 2));
  return (p1 - p0).cross(p2 - p0).normalized();
}

// How far (radians, in [0, π/4]) the world direction `d` in face f is from edge e's direction modulo π/2,
// measured in the face's plane from the positions (not through trivcon's frames).
double off_edge(const MatrixX3d& V, const Topology& t, int f, int e, const Eigen::Vector3d& d) {
  const Eigen::Vector3d n = unit_normal(V, t, f);
  const Eigen::Vector3d edge = V.row(t.edge_vertices(e, 1)) - V.row(t.edge_vertices(e, 0));
  const double a = std::atan2(d.cross(edge).dot(n), d.dot(edge));
  const double q = kPi / 2;
  const double r = a - q * std::round(a / q);
  return std::abs(r);
}

// Per face, its sharp edges.
std::map<int, std::vector<int>> faces_beside(const Topology& t, const std::vector<int>& edges) {
  std::map<int, std::vector<int>> out;
  for (int e : edges) out[t.edge_faces(e, 0)].push_back(e), out[t.edge_faces(e, 1)].push_back(e);
  return out;
}

struct Solved {
  std::vector<int> edges;
  FeatureAlignment alignment;
  std::map<int, int> singularities;
  Design design;
};

// The exact solve of s.singularities with s.alignment's faces fixed, into s.design.
void design_aligned(FieldDesigner& designer, Solved& s) {
  std::vector<int> faces;
  for (auto [f, a] : s.alignment.fixed) faces.push_back(f);
  designer.set_fixed_faces(faces);
  IndexPrescription p;
  p.N = 4;
  p.fixed = s.alignment.fixed;
  p.vertex = s.singularities;
  s.design = designer.design(p);
}

// The CLI's route: sharp edges at `degrees`, faces fixed to them, then --auto's placement (honouring the
// same fixed faces) or the given singularities, then the exact solve.
Solved solve_with_features(FieldDesigner& designer, double degrees, const std::map<int, int>* given = nullptr) {
  Solved s;
  s.edges = sharp_edges(designer.V(), designer.topology(), designer.geometry(), degrees);
  s.alignment = feature_alignment(designer.V(), designer.topology(), designer.geometry(), s.edges, 4);
  if (given) {
    s.singularities = *given;
  } else {
    AutoOptions ao;
    ao.N = 4;
    ao.fixed = s.alignment.fixed;
    s.singularities = auto_singularities(designer, ao).vertex;
  }
  design_aligned(designer, s);
  return s;
}

// Exact, no singularity beyond the prescription, and every face beside a sharp edge along it (modulo π/2)
// except the reported conflicts, where the face is along the edge it follows.
void expect_exact_and_aligned(const FieldDesigner& designer, const Solved& s) {
  const Design& d = s.design;
  EXPECT_TRUE(design_verified(d));
  EXPECT_LE(std::max(d.connection.max_vertex_residual, d.connection.max_cycle_residual), 1e-9);
  EXPECT_LE(d.max_fixed_error, 1e-9);
  EXPECT_TRUE(d.index_mismatch_vertices.empty()) << d.index_mismatch_vertices.size() << " vertices read back another index";
  std::map<int, int> read;
  for (int v = 0; v < designer.topology().num_vertices; ++v)
    if (d.indices.vertex[v] != 0) read[v] = d.indices.vertex[v];
  EXPECT_EQ(read, s.singularities);
  std::set<std::pair<int, int>> conflicting;  // (face, edge it does not follow)
  for (const FeatureConflict& c : s.alignment.conflicts) conflicting.insert({c.face, c.other});
  std::set<int> narrow;  // faces of narrow corners follow neither edge, by design
  for (const NarrowCorner& k : s.alignment.narrow) narrow.insert(k.faces.begin(), k.faces.end());
  int checked = 0;
  for (const auto& [f, edges] : faces_beside(designer.topology(), s.edges))
    for (int e : edges) {
      if (conflicting.count({f, e}) || narrow.count(f)) continue;
      const Eigen::Vector3d dir = designer.geometry().direction_in_face(f, d.field.angle(f));
      EXPECT_LE(off_edge(designer.V(), designer.topology(), f, e, dir), 1e-9) << "face " << f << " edge " << e;
      ++checked;
    }
  EXPECT_GT(checked, 0);
}

TEST(SharpEdges, CubeHasItsTwelveEdgesConvexAtNinetyDegrees) {
  const Mesh m = make_cube_sphere(6, false);
  FieldDesigner designer(m.V, m.F);
  const Topology& t = designer.topology();
  const std::vector<int> edges = sharp_edges(m.V, t, designer.geometry(), 30);
  ASSERT_EQ(edges.size(), 12u * 6);
  for (int e : edges) {
    EXPECT_NEAR(dihedral_angle(t, designer.geometry(), e), kPi / 2, 1e-12);
    EXPECT_TRUE(is_convex_edge(m.V, t, designer.geometry(), e));
    // On the cube's edges two coordinates are ±1 at both ends.
    for (int end = 0; end < 2; ++end) {
      const Eigen::Vector3d p = m.V.row(t.edge_vertices(e, end));
      EXPECT_EQ((p.array().abs() == 1.0).count() >= 2, true);
    }
  }
  EXPECT_EQ(sharp_edges(m.V, t, designer.geometry(), 91).size(), 0u);
  EXPECT_EQ(sharp_edges(m.V, t, designer.geometry(), 0).size(), 12u * 6);
}

TEST(SharpEdges, ConcaveEdgesOfAHoledPlate) {
  const Mesh m = make_genus_surface(1, 2);
  FieldDesigner designer(m.V, m.F);
  const std::vector<int> edges = sharp_edges(m.V, designer.topology(), designer.geometry(), 30);
  int convex = 0;
  for (int e : edges) convex += is_convex_edge(m.V, designer.topology(), designer.geometry(), e);
  // The hole's four vertical edges are concave (valleys seen from outside); everything else is convex.
  EXPECT_GT(convex, 0);
  EXPECT_EQ(static_cast<int>(edges.size()) - convex, 4 * 2 * 2);  // 4 edges, 2 voxels tall, resolution 2
}

TEST(SharpEdges, BadAnglesAreRejected) {
  const Mesh m = make_cube_sphere(2, false);
  FieldDesigner designer(m.V, m.F);
  for (double bad : {-1.0, 200.0, std::nan("")})
    EXPECT_NE(error_of([&] { sharp_edges(m.V, designer.topology(), designer.geometry(), bad); }).find("out of range"), std::string::npos);
}

TEST(SharpEdges, CylinderRimsOnly) {
  const Mesh m = make_capped_cylinder(4, 8, 6);
  FieldDesigner designer(m.V, m.F);
  EXPECT_EQ(designer.topology().euler_characteristic(), 2);
  const std::vector<int> edges = sharp_edges(m.V, designer.topology(), designer.geometry(), 30);
  EXPECT_EQ(edges.size(), 2u * 4 * 8);  // the two rims of rings · segments edges
  for (int e : edges) {
    EXPECT_NEAR(std::abs(m.V(designer.topology().edge_vertices(e, 0), 2)), 1.0, 1e-15);
    EXPECT_TRUE(is_convex_edge(m.V, designer.topology(), designer.geometry(), e));  // outward normals
  }
  // make_capped_cylinder's sizes: two make_disk(4, 8) caps (1 + 8·4·5/2 = 81 vertices, 8·16 faces) and
  // 6 rows of 32 quads, 5 inner rows of vertices.
  EXPECT_EQ(m.V.rows(), 2 * 81 + 5 * 32);
  EXPECT_EQ(m.F.rows(), 2 * 128 + 2 * 6 * 32);
  EXPECT_TRUE(designer.topology().flipped_faces.empty());
  EXPECT_NE(error_of([] { make_capped_cylinder(4, 8, 0); }).find("make_capped_cylinder: invalid stacks = 0"), std::string::npos);
  EXPECT_NE(error_of([] { make_capped_cylinder(4, 8, 2, -1); }).find("height"), std::string::npos);
}

// Edges drawn on a flat 20 × 20 grid of the unit square (cells of h = 0.05) by grid steps, with a minimum length
// of 0.25 (five cells): what stays and what goes is known from the drawing alone.
TEST(SharpEdges, ShortLooseEndsAndSmallPiecesAreDropped) {
  const int n = 20;
  const double h = 1.0 / n;
  const Mesh m = make_holed_grid(n, 0);
  FieldDesigner designer(m.V, m.F);
  const Topology& t = designer.topology();
  auto vertex = [&](int i, int j) {
    for (int v = 0; v < m.V.rows(); ++v)
      if (std::abs(m.V(v, 0) - i * h) < 1e-12 && std::abs(m.V(v, 1) - j * h) < 1e-12) return v;
    ADD_FAILURE() << "no grid vertex (" << i << ", " << j << ")";
    return -1;
  };
  auto edge = [&](int a, int b) {
    for (int q = t.vertex_edge_offsets[a]; q < t.vertex_edge_offsets[a + 1]; ++q) {
      const int e = t.vertex_edges[q];
      if (t.edge_vertices(e, 0) == b || t.edge_vertices(e, 1) == b) return e;
    }
    ADD_FAILURE() << "no edge (" << a << ", " << b << ")";
    return -1;
  };
  // The path of grid steps through the points given (each pair on one row or column).
  auto path = [&](std::vector<std::pair<int, int>> points) {
    std::vector<int> out;
    for (size_t k = 0; k + 1 < points.size(); ++k) {
      auto [i, j] = points[k];
      const auto [i1, j1] = points[k + 1];
      while (i != i1 || j != j1) {
        const int a = vertex(i, j);
        i += (i1 > i) - (i1 < i), j += (j1 > j) - (j1 < j);
        out.push_back(edge(a, vertex(i, j)));
      }
    }
    return out;
  };
  // A line of 18 cells whose loose ends are 6 cells long (from x = 1 and x = 19 to the junctions at x = 7, 13): stays.
  const std::vector<int> line = path({{1, 10}, {19, 10}});
  const std::vector<int> long_spur = path({{7, 10}, {7, 4}});       // 6 cells from the line: stays
  const std::vector<int> short_spur = path({{11, 10}, {11, 13}});   // 3 cells: goes
  const std::vector<int> dash = path({{2, 2}, {4, 2}});             // 2 cells on its own: goes
  const std::vector<int> ring = path({{2, 16}, {3, 16}, {3, 17}, {2, 17}, {2, 16}});  // 1 × 1 loop: goes
  const std::vector<int> square = path({{12, 12}, {18, 12}, {18, 18}, {12, 18}, {12, 12}});  // 6 × 6 loop: stays
  // A 2-cell chain off the line that ends in two 2-cell spurs: the spurs go, then the chain is loose and goes.
  const std::vector<int> fork = path({{13, 10}, {13, 8}});
  const std::vector<int> tines = path({{11, 8}, {15, 8}});
  std::vector<int> edges;
  for (const auto* part : {&line, &long_spur, &short_spur, &dash, &ring, &square, &fork, &tines})
    edges.insert(edges.end(), part->begin(), part->end());
  std::sort(edges.begin(), edges.end());
  std::vector<int> stays = line;
  stays.insert(stays.end(), long_spur.begin(), long_spur.end());
  stays.insert(stays.end(), square.begin(), square.end());
  std::sort(stays.begin(), stays.end());
  std::vector<int> goes;
  std::set_difference(edges.begin(), edges.end(), stays.begin(), stays.end(), std::back_inserter(goes));
  std::vector<int> dropped;
  EXPECT_EQ(without_short_feature_ends(m.V, t, edges, 5 * h + 1e-9, &dropped), stays);
  EXPECT_EQ(dropped, goes);
  // Nothing goes without a length. With 0.4 the line's loose ends go, then what is left of it (6 cells between
  // them), and the spurs; the square (0.42 across) stays.
  EXPECT_EQ(without_short_feature_ends(m.V, t, edges, 0), edges);
  std::vector<int> sorted_square = square;
  std::sort(sorted_square.begin(), sorted_square.end());
  EXPECT_EQ(without_short_feature_ends(m.V, t, edges, 0.4), sorted_square);
}

// On an icosahedron with one vertex pulled out, most edges are sharp at 30° and most faces have three: each face
// that still has three loses its least sharp one, so none is left with three, and each edge dropped was the least
// sharp of a face whose other two stayed sharp up to then.
TEST(SharpEdges, FacesSharpOnAllThreeEdgesLoseTheLeastSharp) {
  Mesh m = make_icosphere(0);
  m.V.row(0) *= 1.4;
  FieldDesigner designer(m.V, m.F);
  const Topology& t = designer.topology();
  const std::vector<int> edges = sharp_edges(m.V, t, designer.geometry(), 30);
  const std::set<int> sharp(edges.begin(), edges.end());
  int closed = 0;
  for (int f = 0; f < t.num_faces; ++f) closed += sharp.count(t.face_edges(f, 0)) + sharp.count(t.face_edges(f, 1)) + sharp.count(t.face_edges(f, 2)) == 3;
  ASSERT_GT(closed, 5);
  std::vector<int> dropped;
  const std::vector<int> kept = without_closed_faces(t, designer.geometry(), edges, &dropped);
  EXPECT_EQ(kept.size() + dropped.size(), edges.size());
  EXPECT_LE(dropped.size(), 20u);
  const std::set<int> alive(kept.begin(), kept.end());
  for (int f = 0; f < t.num_faces; ++f) EXPECT_LT(alive.count(t.face_edges(f, 0)) + alive.count(t.face_edges(f, 1)) + alive.count(t.face_edges(f, 2)), 3u) << f;
  for (int e : dropped) {
    bool least_somewhere = false;
    for (int side = 0; side < 2; ++side) {
      const int f = t.edge_faces(e, side);
      bool least = true;
      for (int k = 0; k < 3; ++k) least &= dihedral_angle(t, designer.geometry(), t.face_edges(f, k)) >= dihedral_angle(t, designer.geometry(), e);
      least_somewhere |= least;
    }
    EXPECT_TRUE(least_somewhere) << e;
  }
  // The cube's faces have at most two: nothing goes.
  const Mesh cube = make_cube_sphere(4, false);
  FieldDesigner cd(cube.V, cube.F);
  const std::vector<int> cube_edges = sharp_edges(cube.V, cd.topology(), cd.geometry(), 30);
  EXPECT_EQ(without_closed_faces(cd.topology(), cd.geometry(), cube_edges), cube_edges);
}

// A clean CAD-like part loses nothing: the cube's twelve edges end at junctions, and the block is wider than the
// length.
TEST(SharpEdges, ACubesEdgesAllStay) {
  const Mesh m = make_cube_sphere(6, false);
  FieldDesigner designer(m.V, m.F);
  const std::vector<int> edges = sharp_edges(m.V, designer.topology(), designer.geometry(), 30);
  std::vector<int> dropped;
  EXPECT_EQ(without_short_feature_ends(m.V, designer.topology(), edges, 1.9, &dropped), edges);
  EXPECT_TRUE(dropped.empty());
  // Wider than the cube's diagonal (2√3): the whole piece is smaller than the length.
  EXPECT_TRUE(without_short_feature_ends(m.V, designer.topology(), edges, 3.5).empty());
}

TEST(ReadFeatureEdges, ReadsPairsAndNamesTheLineOfEachError) {
  const Mesh m = make_cube_sphere(2, false);
  const Topology t = test::topo(m);
  const std::string path = temp_file("edges.txt");
  const int a = t.edge_vertices(3, 0), b = t.edge_vertices(3, 1), c = t.edge_vertices(7, 0), d = t.edge_vertices(7, 1);
  write_text(path,
             "# features\n" + std::to_string(b) + " " + std::to_string(a) + "\n\n" + std::to_string(c) + " " + std::to_string(d) + "\n");
  EXPECT_EQ(read_feature_edges(path, t), (std::vector<int>{3, 7}));
  auto error = [&](const std::string& text) {
    write_text(path, text);
    return error_of([&] { read_feature_edges(path, t); });
  };
  const std::string pair = std::to_string(a) + " " + std::to_string(b) + "\n";
  EXPECT_NE(error(pair + pair).find(path + ":2: edge"), std::string::npos);
  EXPECT_NE(error(pair + pair).find("listed twice (first at line 1)"), std::string::npos);
  EXPECT_NE(error("0 1000\n").find(path + ":1: vertex id '1000' is not a whole number"), std::string::npos);
  EXPECT_NE(error("0 x\n").find(path + ":1:"), std::string::npos);
  EXPECT_NE(error("1 2 3\n").find(path + ":1: expected two vertex ids"), std::string::npos);
  EXPECT_NE(error("4 4\n").find(path + ":1: (4, 4) is not an edge"), std::string::npos);
  // A pair that is not an edge: two opposite corners of the cube.
  int far = 0;
  for (int v = 1; v < m.V.rows(); ++v)
    if ((m.V.row(v) + m.V.row(0)).norm() < 1e-12) far = v;
  EXPECT_NE(error("0 " + std::to_string(far) + "\n").find("is not an edge of the mesh"), std::string::npos);
  EXPECT_NE(error_of([&] { read_feature_edges(temp_file("missing.txt"), t); }).find("missing.txt"), std::string::npos);
  // Boundary edges are not features.
  const Mesh disk = make_disk(2, 6);
  const Topology td = test::topo(disk);
  const int last = static_cast<int>(disk.V.rows()) - 1;  // rim vertices are the last ring
  write_text(path, std::to_string(last - 1) + " " + std::to_string(last) + "\n");
  EXPECT_NE(error_of([&] { read_feature_edges(path, td); }).find("is a boundary edge"), std::string::npos);
}

TEST(FeatureAlignment, CubeCornersAreCompatibleForCrossesNotForLines) {
  const Mesh m = make_cube_sphere(4, false);
  FieldDesigner designer(m.V, m.F);
  const std::vector<int> edges = sharp_edges(m.V, designer.topology(), designer.geometry(), 30);
  const FeatureAlignment crosses = feature_alignment(m.V, designer.topology(), designer.geometry(), edges, 4);
  EXPECT_EQ(crosses.fixed.size(), faces_beside(designer.topology(), edges).size());
  EXPECT_EQ(crosses.corner_faces, 24);  // one triangle of each corner quad holds both of its sharp edges
  EXPECT_TRUE(crosses.conflicts.empty());
  const FeatureAlignment lines = feature_alignment(m.V, designer.topology(), designer.geometry(), edges, 2);
  ASSERT_EQ(lines.conflicts.size(), 24u);
  for (const FeatureConflict& c : lines.conflicts) EXPECT_NEAR(c.difference, kPi / 2, 1e-12);
}

TEST(FeatureAlignment, CubeWithAutoGetsItsEightCorners) {
  const Mesh m = make_cube_sphere(8, false);
  FieldDesigner designer(m.V, m.F);
  const Solved s = solve_with_features(designer, 30);
  EXPECT_EQ(s.edges.size(), 12u * 8);
  EXPECT_TRUE(s.alignment.conflicts.empty());
  std::map<int, int> corners;
  for (int v : test::vertices_of_valence(m, 3)) corners[v] = 1;
  ASSERT_EQ(corners.size(), 8u);
  EXPECT_EQ(s.singularities, corners);
  expect_exact_and_aligned(designer, s);
}

TEST(FeatureAlignment, NarrowCornersTurnByOneStep) {
  // At the four 21.8° corners a field following both sharp edges would give the corner's sector no turn
  // (a map would collapse it, and each such box corner would be a +1/2); the sector's faces take a step less
  // instead, and --auto finds the box's eight corners at +1/4 each, like a cube's.
  const Mesh m = test::sheared_box(6);
  FieldDesigner designer(m.V, m.F);
  const Solved s = solve_with_features(designer, 30);
  ASSERT_EQ(s.alignment.narrow.size(), 4u);
  const Topology& t = designer.topology();
  for (const NarrowCorner& k : s.alignment.narrow) {
    EXPECT_NEAR(k.angle, std::atan(1 / 2.5), 1e-9);
    EXPECT_EQ(k.faces.size(), 2u);
    // The two edges are sharp and meet at the corner, one of the box's eight.
    for (int e : {k.first, k.second}) {
      EXPECT_TRUE(std::count(s.edges.begin(), s.edges.end(), e));
      EXPECT_TRUE(t.edge_vertices(e, 0) == k.vertex || t.edge_vertices(e, 1) == k.vertex);
    }
  }
  // Eight +1/4 singularities: the four narrow corners, and one inside each side near each 158.2° corner (a
  // side's quad corners are then 90°, 180°, 90°, 180°: two quarter turns short of a disk's four, made up inside).
  ASSERT_EQ(s.singularities.size(), 8u);
  for (auto [v, n] : s.singularities) EXPECT_EQ(n, 1) << "vertex " << v;
  for (const NarrowCorner& k : s.alignment.narrow) EXPECT_EQ(s.singularities.count(k.vertex), 1u) << "corner " << k.vertex;
  expect_exact_and_aligned(designer, s);
  EXPECT_TRUE(design_verified(s.design));
  // For N = 2 (lines), no corner is narrow: a line field has no quad corner to give.
  const FeatureAlignment lines = feature_alignment(m.V, t, designer.geometry(), s.edges, 2);
  EXPECT_TRUE(lines.narrow.empty());
}

// The vertex at (x / n, y / n) of an n × n grid (make_holed_grid).
int grid_vertex(const Mesh& m, int n, int x, int y) {
  for (int v = 0; v < m.V.rows(); ++v)
    if (std::abs(m.V(v, 0) * n - x) < 1e-9 && std::abs(m.V(v, 1) * n - y) < 1e-9) return v;
  ADD_FAILURE() << "no vertex at " << x << ", " << y;
  return -1;
}

// The edges of an n × n grid (make_holed_grid) on the line y = 1/2, without the two at the grid's sides: a straight
// feature line across it whose ends are inside.
std::vector<int> middle_line(const Mesh& m, const Topology& t, int n) {
  std::vector<int> edges;
  for (int e = 0; e < t.num_edges; ++e) {
    const Eigen::Vector3d a = m.V.row(t.edge_vertices(e, 0)), b = m.V.row(t.edge_vertices(e, 1));
    if (std::abs(a.y() - 0.5) < 1e-12 && std::abs(b.y() - 0.5) < 1e-12 && std::min(a.x(), b.x()) > 0.5 / n &&
        std::max(a.x(), b.x()) < 1 - 0.5 / n)
      edges.push_back(e);
  }
  return edges;
}

TEST(FeatureAlignment, SingularityBesideAJunctionMovesOntoIt) {
  // A flat 12×12 grid with a feature line across it at y = 1/2 and another from its middle up to y = 11/12:
  // a T-junction of three sharp edges at (1/2, 1/2). A +1/4 one edge below the junction is moved onto it
  // (move_singularities_onto_features) when flat sectors are allowed: the half-plane below the line turns one
  // step fewer, and the junction reads +1/4 in the exact field while every face beside the lines still follows
  // them. Without, it stays: the half-plane would be one quad's corner of π.
  const int n = 12;
  const Mesh m = make_holed_grid(n, 0);
  FieldDesigner designer(m.V, m.F);
  const Topology& t = designer.topology();
  auto at = [&](int x, int y) { return grid_vertex(m, n, x, y); };
  auto edge_between = [&](int a, int b) {
    for (int e = 0; e < t.num_edges; ++e)
      if ((t.edge_vertices(e, 0) == a && t.edge_vertices(e, 1) == b) || (t.edge_vertices(e, 0) == b && t.edge_vertices(e, 1) == a)) return e;
    ADD_FAILURE() << "no edge " << a << "-" << b;
    return -1;
  };
  Solved s;
  for (int x = 1; x + 2 < n; ++x) s.edges.push_back(edge_between(at(x, n / 2), at(x + 1, n / 2)));
  for (int y = n / 2; y + 2 < n; ++y) s.edges.push_back(edge_between(at(n / 2, y), at(n / 2, y + 1)));
  const int junction = at(n / 2, n / 2), below = at(n / 2, n / 2 - 1);
  s.alignment = feature_alignment(m.V, t, designer.geometry(), s.edges, 4);
  EXPECT_TRUE(s.alignment.narrow.empty());
  std::map<int, int> vertex{{below, 1}};
  FeatureAlignment strict = s.alignment;
  move_singularities_onto_features(m.V, t, designer.geometry(), s.edges, 4, 1.5 / n, false, vertex, strict);
  EXPECT_EQ(vertex, (std::map<int, int>{{below, 1}}));
  EXPECT_TRUE(strict.snapped.empty());
  move_singularities_onto_features(m.V, t, designer.geometry(), s.edges, 4, 1.5 / n, true, vertex, s.alignment);
  EXPECT_EQ(vertex, (std::map<int, int>{{junction, 1}}));
  ASSERT_EQ(s.alignment.snapped.size(), 1u);
  const FeatureSnap& snap = s.alignment.snapped[0];
  EXPECT_EQ(snap.from, below);
  EXPECT_EQ(snap.to, junction);
  EXPECT_NEAR(snap.distance, 1.0 / n, 1e-12);
  // The sector turned is the half-plane below the line: every face of the junction's star there.
  int star_below = 0;
  for (int f = 0; f < t.num_faces; ++f) {
    bool touches = false;
    double cy = 0;
    for (int k = 0; k < 3; ++k) touches = touches || t.F(f, k) == junction, cy += m.V(t.F(f, k), 1) / 3;
    if (touches && cy < 0.5) ++star_below;
  }
  ASSERT_EQ(static_cast<int>(snap.faces.size()), star_below);
  for (int f : snap.faces) {
    double cy = 0;
    for (int k = 0; k < 3; ++k) cy += m.V(t.F(f, k), 1) / 3;
    EXPECT_LT(cy, 0.5) << "face " << f;
  }
  s.singularities = vertex;
  design_aligned(designer, s);
  // The turned sector's inner faces follow neither line by design, like a narrow corner's.
  s.alignment.narrow.push_back({junction, -1, -1, kPi, snap.faces});
  expect_exact_and_aligned(designer, s);
  // Beside a degree-2 vertex of the line only (the vertical line removed), a −1/4 moves without flat sectors
  // allowed: the half-plane gets three quad corners of π/3.
  Solved line;
  for (int x = 1; x + 2 < n; ++x) line.edges.push_back(edge_between(at(x, n / 2), at(x + 1, n / 2)));
  line.alignment = feature_alignment(m.V, t, designer.geometry(), line.edges, 4);
  std::map<int, int> alone{{below, -1}};
  move_singularities_onto_features(m.V, t, designer.geometry(), line.edges, 4, 1.5 / n, false, alone, line.alignment);
  EXPECT_EQ(alone, (std::map<int, int>{{junction, -1}}));
}

TEST(FeatureAlignment, SingularityGivenOnALineGetsItsSector) {
  // A flat 12×12 grid with a straight feature line at y = 1/2 and a −1/4 given at a vertex w of the line (as
  // `quad --auto --sing-out` writes a singularity it moved onto the line). Following the line, each half-plane
  // turns by π less two quarter turns, so w reads 0 with no turn of its own, and the exact field makes up the
  // −1/4 with a turn of π/2 across one edge: a field that is not what it reads. turn_sectors_for_singularities
  // turns one half-plane through with one step more, and the field is exact and follows the line, as after the
  // move onto it (move_singularities_onto_features) from one edge below.
  const int n = 12;
  const Mesh m = make_holed_grid(n, 0);
  FieldDesigner designer(m.V, m.F);
  const Topology& t = designer.topology();
  auto at = [&](int x, int y) { return grid_vertex(m, n, x, y); };
  const std::vector<int> edges = middle_line(m, t, n);
  const int w = at(n / 2, n / 2), below = at(n / 2, n / 2 - 1);
  Solved plain;
  plain.edges = edges;
  plain.alignment = feature_alignment(m.V, t, designer.geometry(), edges, 4);
  plain.singularities = {{w, -1}};
  design_aligned(designer, plain);
  EXPECT_GE(plain.design.large_turn_edges, 1);
  EXPECT_FALSE(plain.design.field_exact);

  Solved turned = plain;
  turn_sectors_for_singularities(t, designer.geometry(), edges, 4, turned.singularities, turned.alignment);
  ASSERT_EQ(turned.alignment.given_sectors.size(), 1u);
  const FeatureSnap& sector = turned.alignment.given_sectors[0];
  EXPECT_EQ(sector.from, w);
  EXPECT_EQ(sector.to, w);
  // The sector is a half-plane: every face of w's star on one side of the line.
  int above = 0, under = 0;
  for (int f : sector.faces) {
    double cy = 0;
    for (int k = 0; k < 3; ++k) cy += m.V(t.F(f, k), 1) / 3;
    (cy > 0.5 ? above : under) += 1;
  }
  EXPECT_TRUE(above == 0 || under == 0);
  EXPECT_EQ(static_cast<int>(sector.faces.size()), above + under);
  design_aligned(designer, turned);
  EXPECT_EQ(turned.design.large_turn_edges, 0);
  EXPECT_TRUE(turned.design.field_exact);
  turned.alignment.narrow.push_back({w, -1, -1, kPi, sector.faces});  // its inner faces follow neither side, by design
  expect_exact_and_aligned(designer, turned);
  // The move onto the line from below turns the lower half-plane; where the given one turned it too, the
  // fields are the same.
  Solved moved = plain;
  moved.singularities = {{below, -1}};
  move_singularities_onto_features(m.V, t, designer.geometry(), edges, 4, 1.5 / n, false, moved.singularities, moved.alignment);
  ASSERT_EQ(moved.singularities, (std::map<int, int>{{w, -1}}));
  design_aligned(designer, moved);
  if (under > 0) {
    EXPECT_EQ(moved.alignment.snapped[0].faces, sector.faces);
    EXPECT_NEAR(moved.design.connection.energy, turned.design.connection.energy, 1e-9 * turned.design.connection.energy);
  }
  // Given where the sectors make it already (a vertex off the line; the index the line gives), nothing turns.
  FeatureAlignment untouched = plain.alignment;
  turn_sectors_for_singularities(t, designer.geometry(), edges, 4, {{below, -1}}, untouched);
  EXPECT_TRUE(untouched.given_sectors.empty());
  // And a singularity a move turned a sector for already is not turned again.
  turn_sectors_for_singularities(t, designer.geometry(), edges, 4, moved.singularities, moved.alignment);
  EXPECT_TRUE(moved.alignment.given_sectors.empty());
}

TEST(FeatureAlignment, SingularitiesBesideTheAlignedBoundaryBecomeCornersOfIt) {
  // A unit square with a round hole of radius 1/4, meshed on a triangle lattice, its boundary aligned: the smoothest
  // field puts four −1/4 beside the hole's rim. With the boundary as a line, each within 3 lattice spacings moves onto
  // a rim vertex w whose fan (from one boundary edge to the other, the two end faces following them exactly) turns
  // through with one step more, so the field turns a quarter less than the rim there, and no vertex carries the
  // −1/4 (boundary vertices have no index): the interior singularities sum to what the turned boundary needs and
  // the field is exact, every boundary face along its edge. A fan of three faces cannot take the turn in steps
  // read unambiguously (two of π/4): the next rim vertex is tried.
  const double h = 0.08;
  const Mesh m = test::lattice_plate(1, 1, 0.25, h);
  FieldDesigner designer(m.V, m.F);
  const Topology& t = designer.topology();
  const Geometry& g = designer.geometry();
  Solved s;
  s.alignment.fixed = boundary_alignment(m.V, t, g);
  AutoOptions ao;
  ao.N = 4;
  ao.fixed = s.alignment.fixed;
  s.singularities = auto_singularities(designer, ao).vertex;
  const std::map<int, double> plain = s.alignment.fixed;
  const std::map<int, int> found = s.singularities;

  // Not without the boundary as a line (there are no sharp edges).
  Solved kept = s;
  move_singularities_onto_features(m.V, t, g, {}, 4, 3 * h, false, kept.singularities, kept.alignment, 0, false);
  EXPECT_EQ(kept.singularities, found);

  move_singularities_onto_features(m.V, t, g, {}, 4, 3 * h, false, s.singularities, s.alignment, 0, true);
  ASSERT_FALSE(s.alignment.snapped.empty());
  EXPECT_EQ(s.alignment.snapped.size(), 4u);
  EXPECT_TRUE(s.singularities.empty());
  for (const FeatureSnap& snap : s.alignment.snapped) {
    EXPECT_EQ(found.at(snap.from), -1);
    EXPECT_FALSE(s.singularities.count(snap.from));
    EXPECT_TRUE(t.is_boundary_vertex(snap.to));
    std::vector<int> fan;
    vertex_fan(t, snap.to, fan);
    EXPECT_EQ(snap.faces, fan);
    EXPECT_GE(fan.size(), 4u);
    // The fan's end faces still follow their boundary edges; the ones between turn.
    EXPECT_NEAR(reduce_angle(s.alignment.fixed.at(fan.front()) - plain.at(fan.front()), 4), 0, 1e-12);
    EXPECT_NEAR(reduce_angle(s.alignment.fixed.at(fan.back()) - plain.at(fan.back()), 4), 0, 1e-12);
  }
  design_aligned(designer, s);
  const Design& d = s.design;
  EXPECT_TRUE(design_verified(d));
  EXPECT_TRUE(d.field_exact);
  EXPECT_EQ(d.large_turn_edges, 0);
  EXPECT_LE(d.max_fixed_error, 1e-9);
  std::map<int, int> read;
  for (int v = 0; v < t.num_vertices; ++v)
    if (d.indices.vertex[v] != 0) read[v] = d.indices.vertex[v];
  EXPECT_EQ(read, s.singularities);
  for (int e = 0; e < t.num_edges; ++e) {
    if (!t.is_boundary_edge(e)) continue;
    const int f = t.edge_faces(e, 0) >= 0 ? t.edge_faces(e, 0) : t.edge_faces(e, 1);
    EXPECT_LE(off_edge(m.V, t, f, e, g.direction_in_face(f, d.field.angle(f))), 1e-9) << "face " << f;
  }
  // Without the fans turned, the −1/4 left out are missing from the sum the boundary needs.
  Solved bare;
  bare.alignment.fixed = plain;
  bare.singularities = s.singularities;
  EXPECT_THROW(design_aligned(designer, bare), Error);

  // The corners are listed with their index; given as boundary vertices to turn_sectors_for_singularities with
  // the boundary as a line, they turn the same fans the same way (a singularity file given back), and a corner
  // there already is not turned again.
  ASSERT_EQ(s.alignment.corners.size(), 4u);
  for (const FeatureSnap& snap : s.alignment.snapped) EXPECT_EQ(s.alignment.corners.at(snap.to), -1);
  FeatureAlignment given;
  given.fixed = plain;
  turn_sectors_for_singularities(t, g, {}, 4, s.alignment.corners, given, false);
  EXPECT_EQ(given.fixed, plain);  // boundary vertices alone without `boundary`
  EXPECT_TRUE(given.corners.empty());
  turn_sectors_for_singularities(t, g, {}, 4, s.alignment.corners, given, true);
  EXPECT_EQ(given.corners, s.alignment.corners);
  EXPECT_EQ(given.given_sectors.size(), 4u);
  ASSERT_EQ(given.fixed.size(), s.alignment.fixed.size());
  for (auto [f, angle] : s.alignment.fixed) EXPECT_NEAR(given.fixed.at(f), angle, 1e-12) << "face " << f;
  turn_sectors_for_singularities(t, g, {}, 4, s.alignment.corners, given, true);
  EXPECT_EQ(given.given_sectors.size(), 4u);
  // A fan of three faces (a lattice vertex on the square's straight side) cannot take a quarter turn.
  const int straight = test::boundary_vertex_with_fan(t, 3);
  ASSERT_GE(straight, 0);
  FeatureAlignment three;
  three.fixed = plain;
  turn_sectors_for_singularities(t, g, {}, 4, {{straight, -1}}, three, true);
  EXPECT_TRUE(three.corners.empty());
  EXPECT_EQ(three.fixed, plain);
}

TEST(FeatureAlignment, SingularitiesMovedOntoALineKeepTheirSeparation) {
  // Two −1/4 three edges apart, one edge below a straight feature line (a 12×12 grid, the line at y = 1/2): each
  // moves onto the line vertex above it, three edges from the other. With a separation of 3.5 edges the second
  // goes to a line vertex at least that far from the first, or stays: two singularities a fraction of a unit
  // apart on one line are rounded onto one integer point.
  const int n = 12;
  const Mesh m = make_holed_grid(n, 0);
  FieldDesigner designer(m.V, m.F);
  const Topology& t = designer.topology();
  auto at = [&](int x, int y) { return grid_vertex(m, n, x, y); };
  const std::vector<int> edges = middle_line(m, t, n);
  ASSERT_EQ(edges.size(), static_cast<size_t>(n - 2));
  const int a = at(3, n / 2 - 1), b = at(6, n / 2 - 1);
  const std::map<int, int> given{{a, -1}, {b, -1}};
  auto on_line = [&](int v) { return std::abs(m.V(v, 1) - 0.5) < 1e-12; };
  // Without a separation: both onto the line, three edges apart.
  std::map<int, int> close = given;
  FeatureAlignment near = feature_alignment(m.V, t, designer.geometry(), edges, 4);
  move_singularities_onto_features(m.V, t, designer.geometry(), edges, 4, 3.0 / n, false, close, near);
  ASSERT_EQ(close.size(), 2u);
  ASSERT_EQ(near.snapped.size(), 2u);
  EXPECT_NEAR((m.V.row(close.begin()->first) - m.V.row(std::next(close.begin())->first)).norm(), 3.0 / n, 1e-12);
  // With it: the first moves as before; the second keeps 3.5 edges from it along the line, or stays.
  std::map<int, int> apart = given;
  FeatureAlignment far = feature_alignment(m.V, t, designer.geometry(), edges, 4);
  move_singularities_onto_features(m.V, t, designer.geometry(), edges, 4, 3.0 / n, false, apart, far, 3.5 / n);
  ASSERT_EQ(apart.size(), 2u);
  ASSERT_GE(far.snapped.size(), 1u);
  EXPECT_EQ(far.snapped[0].to, near.snapped[0].to);
  for (auto [v, k] : apart) EXPECT_EQ(k, -1);
  const int p = apart.begin()->first, q = std::next(apart.begin())->first;
  if (on_line(p) && on_line(q)) {
    EXPECT_GE((m.V.row(p) - m.V.row(q)).norm(), 3.5 / n - 1e-12);
  } else {
    EXPECT_EQ(far.snapped.size(), 1u);
    EXPECT_TRUE(apart.count(a) || apart.count(b));  // the one not moved is where it was
  }
}

TEST(FeatureAlignment, CubeWithSingularitiesByHand) {
  // The corners, and also a +1/4 −1/4 pair inside a cube face: exact and aligned all the same.
  const Mesh m = make_cube_sphere(8, false);
  FieldDesigner designer(m.V, m.F);
  std::map<int, int> given;
  for (int v : test::vertices_of_valence(m, 3)) given[v] = 1;
  int inside_a = -1, inside_b = -1;
  for (int v = 0; v < m.V.rows(); ++v) {  // two vertices of the face z = 1, away from its edges
    const Eigen::Vector3d p = m.V.row(v);
    if (p.z() == 1 && std::abs(p.x() + 0.25) < 1e-12 && std::abs(p.y()) < 1e-12) inside_a = v;
    if (p.z() == 1 && std::abs(p.x() - 0.25) < 1e-12 && std::abs(p.y()) < 1e-12) inside_b = v;
  }
  ASSERT_GE(inside_a, 0);
  ASSERT_GE(inside_b, 0);
  given[inside_a] = 1, given[inside_b] = -1;
  const Solved s = solve_with_features(designer, 30, &given);
  expect_exact_and_aligned(designer, s);
}

TEST(FeatureAlignment, CappedCylinderWithAuto) {
  const Mesh m = make_capped_cylinder(6, 8, 12);
  FieldDesigner designer(m.V, m.F);
  const Solved s = solve_with_features(designer, 30);
  EXPECT_TRUE(s.alignment.conflicts.empty());
  int sum = 0;
  for (auto [v, n] : s.singularities) sum += n;
  EXPECT_EQ(sum, 4 * 2);  // Poincaré–Hopf: Σ n = N χ
  // The side is a developable band whose rims the field follows: nothing singular on it.
  for (auto [v, n] : s.singularities) EXPECT_GT(std::abs(m.V(v, 2)), 1 - 1e-12) << "vertex " << v << " is on the side";
  expect_exact_and_aligned(designer, s);
}

// With more than 256 fixed-face paths (the sparse route, docs/solver.md "Fixed-face paths") a path of one edge between two
// adjacent fixed faces takes the smallest turn: |x_e| ≤ π/N. On a capped cylinder's rims the fixed
// directions of neighbouring faces differ by a little (the rim turns), so any other whole number would
// make that edge turn by nearly π/2.
TEST(FeatureAlignment, SparsePathsTakeTheSmallestTurn) {
  // The cylinder and its mirror image (the rims then turn the other way in the faces' frames, so the
  // targets of the paths change sign: both roundings, up and down, are exercised).
  Mesh mirrored = make_capped_cylinder(6, 96, 12);
  mirrored.V.col(0) *= -1;
  mirrored.F.col(1).swap(mirrored.F.col(2));
  for (const Mesh& m : {make_capped_cylinder(6, 96, 12), mirrored}) {
  FieldDesigner designer(m.V, m.F, test::sparse_path_options());
  const Solved s = solve_with_features(designer, 30);
  const std::vector<FixedPath>& paths = designer.solver().fixed_paths();
  ASSERT_GT(paths.size(), 256u) << "the dense route would be taken";
  int one_edge = 0;
  for (const FixedPath& p : paths) {
    if (p.path.edges.size() != 1) continue;
    ++one_edge;
    EXPECT_LE(std::abs(s.design.connection.x(p.path.edges[0])), kPi / 4 + 1e-9) << "edge " << p.path.edges[0];
  }
  EXPECT_GT(one_edge, 100);
  expect_exact_and_aligned(designer, s);
  }
}

TEST(FeatureAlignment, FandiskLikeBlockReportsItsNonRightCorners) {
  const Mesh m = bulged_block(10);
  FieldDesigner designer(m.V, m.F);
  const Solved s = solve_with_features(designer, 30);
  EXPECT_EQ(s.edges.size(), 12u * 10);  // the roof's own folds are far below 30°
  // Conflicts are exactly the faces beside two sharp edges whose directions differ modulo π/2, found here
  // from the positions.
  std::set<int> expected;
  for (const auto& [f, edges] : faces_beside(designer.topology(), s.edges)) {
    if (edges.size() < 2) continue;
    const Eigen::Vector3d a =
        m.V.row(designer.topology().edge_vertices(edges[0], 1)) - m.V.row(designer.topology().edge_vertices(edges[0], 0));
    if (off_edge(m.V, designer.topology(), f, edges[1], a.normalized()) > 1e-9) expected.insert(f);
  }
  std::set<int> reported;
  for (const FeatureConflict& c : s.alignment.conflicts) reported.insert(c.face);
  EXPECT_EQ(reported, expected);
  EXPECT_EQ(reported.size(), 4u);  // the roof's four corners, one triangle each
  int sum = 0;
  for (auto [v, n] : s.singularities) sum += n;
  EXPECT_EQ(sum, 8);
  expect_exact_and_aligned(designer, s);
}

TEST(QuadWildFiles, RosyRoundTrip) {
  const Mesh m = make_cube_sphere(4, false);
  FieldDesigner designer(m.V, m.F);
  const Solved s = solve_with_features(designer, 30);
  const std::string path = temp_file("m.rosy");
  write_field(path, m.V, m.F, designer.geometry(), s.design.field);
  const std::vector<std::string> lines = test::lines_of(test::slurp(path));
  ASSERT_EQ(lines.size(), 2 + static_cast<size_t>(m.F.rows()));
  EXPECT_EQ(lines[0], std::to_string(m.F.rows()));
  EXPECT_EQ(lines[1], "4");
  int N = 0;
  const MatrixX3d d = read_field(path, static_cast<int>(m.F.rows()), &N);
  EXPECT_EQ(N, 4);
  for (int f = 0; f < m.F.rows(); ++f)
    EXPECT_LE((d.row(f).transpose() - designer.geometry().direction_in_face(f, s.design.field.angle(f))).norm(), 1e-15);
  // Only crosses: QuadWild would misread another N.
  Field lines2 = s.design.field;
  lines2.N = 2;
  EXPECT_NE(error_of([&] { write_field(temp_file("l.rosy"), m.V, m.F, designer.geometry(), lines2); }).find("N = 2"), std::string::npos);
  write_text(path, "3\n4\n1 0 0\n");
  EXPECT_NE(error_of([&] { read_field(path, static_cast<int>(m.F.rows())); }).find(path + ":1: the field has 3 faces"), std::string::npos);
}

TEST(QuadWildFiles, SharpRoundTripInTheFilesFaceOrder) {
  // Some faces given with the other orientation: the topology flips them back, the file keeps them.
  Mesh m = make_cube_sphere(3, false);
  for (int f = 0; f < 5; ++f) std::swap(m.F(f, 1), m.F(f, 2));
  const Topology t = test::topo(m);
  ASSERT_EQ(t.flipped_faces.size(), 5u);
  const Geometry g = compute_geometry(m.V, t);
  const std::vector<int> edges = sharp_edges(m.V, t, g, 45);
  std::vector<char> convex;
  for (int e : edges) convex.push_back(is_convex_edge(m.V, t, g, e));
  const std::string path = temp_file("m.sharp");
  write_sharp(path, m.F, t, edges, convex);
  EXPECT_EQ(test::lines_of(test::slurp(path))[0], std::to_string(2 * edges.size()));
  const std::vector<SharpFaceEdge> read = read_sharp(path, static_cast<int>(m.F.rows()));
  ASSERT_EQ(read.size(), 2 * edges.size());
  std::set<std::pair<int, int>> got, want;  // (min vertex, max vertex) of each line's edge, per face
  for (const SharpFaceEdge& r : read) {
    EXPECT_EQ(r.convex, 1);
    const int i = m.F(r.face, r.edge), j = m.F(r.face, (r.edge + 1) % 3);
    got.insert({r.face, std::min(i, j) * 100000 + std::max(i, j)});
  }
  for (int e : edges)
    for (int side = 0; side < 2; ++side) want.insert({t.edge_faces(e, side), t.edge_vertices(e, 0) * 100000 + t.edge_vertices(e, 1)});
  EXPECT_EQ(got, want);
  write_text(path, "2\n1,0,0\n");
  EXPECT_NE(error_of([&] { read_sharp(path, 10); }).find("ends after 1 of the 2"), std::string::npos);
  write_text(path, "1\n1,0,3\n");
  EXPECT_NE(error_of([&] { read_sharp(path, 10); }).find(path + ":2: edge '3'"), std::string::npos);
  write_text(path, "1\n2,0,1\n");
  EXPECT_NE(error_of([&] { read_sharp(path, 10); }).find("convexity"), std::string::npos);
}

}  // namespace
}  // namespace trivcon
