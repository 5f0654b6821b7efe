// SPDX-License-Identifier: MIT
// trivcon/request.h: one request, the same meaning in every front end (the CLI, the editor and Python are
// tested against it through their own files; here the layer itself).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <tuple>
#include <vector>

#include "trivcon/common.h"
#include "trivcon/error.h"
#include "trivcon/generate.h"
#include "trivcon/request.h"
#include "support.h"

namespace trivcon {
namespace {

// Fixed faces in the order in which later ones win: the boundary, the sharp edges, the explicit directions.
TEST(Request, ExplicitDirectionsWinOverFeaturesOverTheBoundary) {
  const Mesh m = make_capped_cylinder(6, 24, 8);  // a flat cap meets the side at a sharp rim
  FieldDesigner d(m.V, m.F);
  FieldRequest r;
  r.prescription.N = 4;
  r.feature_degrees = 60;
  const RequestConstraints features = request_constraints(d, r);
  ASSERT_FALSE(features.sharp_edges.empty());
  EXPECT_EQ(features.fixed, features.features.fixed);
  const int face = features.fixed.begin()->first;
  r.prescription.fixed[face] = features.fixed.at(face) + 0.3;
  const RequestConstraints c = request_constraints(d, r);
  EXPECT_EQ(c.fixed.at(face), features.fixed.at(face) + 0.3);
  EXPECT_EQ(c.fixed.size(), features.fixed.size());
  std::vector<int> keys;
  for (auto [f, angle] : c.fixed) keys.push_back(f);
  EXPECT_EQ(c.fixed_faces, keys);
  r.feature_edges = {-1};
  EXPECT_THROW(request_constraints(d, r), Error);
}

TEST(Request, ExplicitDirectionsWinOverTheBoundary) {
  const Mesh m = make_annulus(4, 24);
  FieldDesigner d(m.V, m.F);
  FieldRequest r;
  r.prescription.N = 4;
  r.align_boundary = true;
  const std::map<int, double> boundary = boundary_alignment(d.V(), d.topology(), d.geometry());
  EXPECT_EQ(request_constraints(d, r).fixed, boundary);
  const int face = boundary.begin()->first;
  r.prescription.fixed[face] = 0.25;
  EXPECT_EQ(request_constraints(d, r).fixed.at(face), 0.25);
}

// Auto: the singularities used are the smoothest field's, the design verified, and the designer set up for
// the request's fixed faces once (a second request with the same faces does not set it up again).
TEST(Request, AutoOnACubeAndOneSetUp) {
  const Mesh m = make_cube_sphere(4, false);
  FieldDesigner d(m.V, m.F);
  FieldRequest r;
  r.prescription.N = 4;
  r.auto_place = true;
  r.feature_degrees = 30;
  const FieldOutcome out = solve_request(d, m.F, r);
  ASSERT_TRUE(out.auto_result);
  EXPECT_EQ(out.prescription.vertex, out.auto_result->vertex);
  EXPECT_EQ(out.prescription.vertex.size(), 8u);
  EXPECT_TRUE(out.verified);
  EXPECT_TRUE(out.design.field_exact);
  EXPECT_EQ(d.fixed_faces(), out.constraints.fixed_faces);
  const ConnectionSolver* solver = &d.solver();
  r.auto_place = false;
  r.prescription.vertex = out.prescription.vertex;
  const FieldOutcome again = solve_request(d, m.F, r);
  EXPECT_EQ(&d.solver(), solver);
  double worst = 0;
  for (int f = 0; f < m.F.rows(); ++f)
    worst = std::max(worst, std::abs(reduce_angle(again.design.field.angle(f) - out.design.field.angle(f), 4)));
  EXPECT_LT(worst, 1e-9);  // every face of the cube is on a fixed component: the same field
}

// Auto without fixed faces: each component takes its rotation from the smoothest field (turn_toward), and a
// root keeps a component where it was put.
TEST(Request, AutoTurnsTowardTheSmoothestFieldUnlessRooted) {
  Mesh m = make_icosphere(3);
  for (int v = 0; v < m.V.rows(); ++v) m.V.row(v) = Eigen::RowVector3d(2.0 * m.V(v, 0), m.V(v, 1), 0.6 * m.V(v, 2));
  FieldDesigner d(m.V, m.F);
  FieldRequest r;
  r.prescription.N = 4;
  r.auto_place = true;
  const FieldOutcome out = solve_request(d, m.F, r);
  auto mean_difference = [&](const Field& field) {
    double sum = 0, area = 0;
    for (int f = 0; f < m.F.rows(); ++f) {
      sum += d.geometry().face_area(f) * std::abs(reduce_angle(field.angle(f) - out.auto_result->field.angle(f), 4));
      area += d.geometry().face_area(f);
    }
    return sum / area;
  };
  EXPECT_LT(mean_difference(out.design.field), 0.03);
  r.roots = {{0, 0.0}};
  const FieldOutcome rooted = solve_request(d, m.F, r);
  EXPECT_NEAR(rooted.design.field.angle(0), 0.0, 1e-12);
  EXPECT_GT(mean_difference(rooted.design.field), 0.1);
}

// The sparse path route (more fixed-face paths than SolverOptions::max_dense_paths): the request gives the solver
// the smoothest field as the paths' guide, with --auto or singularities given, and the field is the one the dense
// route makes. A plate with
// 27 round holes, its boundary aligned (2,111 paths): the smallest turn per path gave 7 times the energy.
TEST(Request, AutoOnTheSparsePathRouteMatchesTheDenseRoute) {
  const Mesh m = test::perforated_plate(9, 3, 16, 4, 0.3);
  FieldRequest r;
  r.prescription.N = 4;
  r.auto_place = true;
  r.align_boundary = true;
  SolverOptions dense_options;
  dense_options.max_dense_paths = 1 << 20;
  FieldDesigner dense(m.V, m.F, dense_options), sparse(m.V, m.F);
  const FieldOutcome a = solve_request(dense, m.F, r), b = solve_request(sparse, m.F, r);
  ASSERT_FALSE(dense.solver().sparse_paths());
  ASSERT_TRUE(sparse.solver().sparse_paths());  // the default limit, 2,048
  EXPECT_TRUE(a.prescription.path_guide.empty());
  EXPECT_EQ(b.prescription.path_guide.size(), static_cast<size_t>(m.F.rows()));
  ASSERT_TRUE(a.verified && b.verified);
  EXPECT_EQ(a.prescription.vertex, b.prescription.vertex);
  EXPECT_NEAR(b.design.connection.energy, a.design.connection.energy, 1e-8 * a.design.connection.energy);
  IndexPrescription unguided = b.prescription;
  unguided.path_guide.clear();
  EXPECT_GT(sparse.design(unguided).connection.energy, 5 * a.design.connection.energy);
  // The same singularities given (no auto_place): the request makes the smoothest field for the guide all the same.
  FieldRequest given = r;
  given.auto_place = false;
  given.prescription.vertex = b.prescription.vertex;
  const FieldOutcome c = solve_request(sparse, m.F, given);
  EXPECT_FALSE(c.auto_result.has_value());
  EXPECT_EQ(c.prescription.path_guide.size(), static_cast<size_t>(m.F.rows()));
  ASSERT_TRUE(c.verified);
  EXPECT_NEAR(c.design.connection.energy, a.design.connection.energy, 1e-8 * a.design.connection.energy);
}

// The placement search screens maps without their near-miss retries; where the kept map's retries leave problems,
// the next screened maps' follow (kMapRetryCandidates in all), and the map kept is the best after them. Genus 4
// at 80 squares: the three maps made keep problems, so all three are retried; at 100 the kept one is mended by
// its own and the search stops there.
TEST(Request, MapSearchRetriesTheRunnersUpWhenTheKeptMapKeepsProblems) {
  const Mesh m = make_genus_surface(4, 3);
  auto search = [&](double target) {
    FieldDesigner d(m.V, m.F);
    FieldRequest r;
    r.prescription.N = 4;
    r.auto_place = true;
    MapOutcome o = map_request(d, m.F, r, 0, target, true);
    const ParamQuality& q = o.param.quality;
    const int problems = q.flipped_faces + q.degenerate_faces + q.winding_errors + static_cast<int>(o.quads->quality.problems.size());
    return std::make_tuple(o.placements, o.retried_maps, problems, r.auto_options.cancel_distance);
  };
  const auto [placements, retried, problems, cancel] = search(80);
  (void)cancel;
  ASSERT_GT(problems, 0);  // the case this test is for
  EXPECT_EQ(placements, 3);
  EXPECT_EQ(retried, std::min(placements, kMapRetryCandidates));
  const auto [placements_100, retried_100, problems_100, cancel_100] = search(100);
  EXPECT_EQ(problems_100, 0);
  EXPECT_EQ(retried_100, 1);
  EXPECT_GT(cancel_100, 0);
}

// The search's steps (MapSearch::progress) and its bound (max_maps). Genus 4 at 80 squares keeps problems through
// the whole search; bounded at 12 maps: one line per step, their map counts running from 1 to MapOutcome::maps
// without a gap, the last step's best so far the map kept, then the stop; bounded at one map, the search stops
// after the first placement's maps (with the singularities given, the first step is named for them). A torus whose
// first map is clean says nothing.
TEST(Request, MapSearchReportsEachStepAndStopsAtItsBound) {
  const Mesh m = make_genus_surface(4, 3);
  auto search = [&](const Mesh& mesh, double target, int max_maps, std::vector<std::string>& lines) {
    FieldDesigner d(mesh.V, mesh.F);
    FieldRequest r;
    r.prescription.N = 4;
    r.auto_place = true;
    MapSearch s;
    s.max_maps = max_maps;
    s.progress = [&](const std::string& line) { lines.push_back(line); };
    return map_request(d, mesh.F, r, 0, target, true, s);
  };
  std::vector<std::string> lines;
  const MapOutcome o = search(m, 80, 12, lines);
  EXPECT_TRUE(o.stopped);
  EXPECT_GE(o.maps, 12);
  ASSERT_GE(lines.size(), 3u);
  EXPECT_EQ(lines.back(), "search: stopped after " + std::to_string(o.maps) + " maps (the bound given); the best of them kept");
  lines.pop_back();
  int next = 1;
  for (const std::string& line : lines) {
    ASSERT_EQ(line.rfind("search: map", 0), 0u) << line;
    int first = 0, last = 0;
    if (std::sscanf(line.c_str(), "search: maps %d-%d", &first, &last) != 2) {
      ASSERT_EQ(std::sscanf(line.c_str(), "search: map %d", &first), 1) << line;
      last = first;
    }
    EXPECT_EQ(first, next) << line;
    EXPECT_GE(last, first) << line;
    next = last + 1;
  }
  EXPECT_EQ(next - 1, o.maps);
  EXPECT_NE(lines.front().find("(placement the first): "), std::string::npos) << lines.front();
  // The last line's best so far is the map kept.
  const int kept = map_problems(o.param, o.quads);
  EXPECT_NE(lines.back().find("; best so far " + std::to_string(kept) + ", "), std::string::npos) << lines.back();

  std::vector<std::string> bounded_lines;
  const MapOutcome b = search(m, 80, 1, bounded_lines);
  EXPECT_TRUE(b.stopped);
  EXPECT_EQ(b.placements, 1);
  EXPECT_LT(b.maps, 12);
  ASSERT_EQ(bounded_lines.size(), 2u);
  EXPECT_EQ(bounded_lines[0].rfind("search: map", 0), 0u);
  EXPECT_EQ(bounded_lines[1], "search: stopped after " + std::to_string(b.maps) + (b.maps == 1 ? " map" : " maps") +
                                  " (the bound given); the best of them kept");

  // With the singularities given, the first step is theirs.
  {
    FieldDesigner d(m.V, m.F);
    FieldRequest r;
    r.prescription.N = 4;
    r.prescription.vertex = b.field.prescription.vertex;
    std::vector<std::string> given_lines;
    MapSearch s;
    s.max_maps = 1;
    s.progress = [&](const std::string& line) { given_lines.push_back(line); };
    const MapOutcome g = map_request(d, m.F, r, 0, 80, true, s);
    ASSERT_GT(map_problems(g.param, g.quads), 0);  // the first placement's, retried: still with problems
    ASSERT_EQ(given_lines.size(), 2u);
    EXPECT_NE(given_lines[0].find(" (the singularities given): "), std::string::npos) << given_lines[0];
  }
  std::vector<std::string> clean_lines;
  const MapOutcome c = search(make_torus(48, 16), 500, 0, clean_lines);
  EXPECT_EQ(map_problems(c.param, c.quads), 0);
  EXPECT_TRUE(clean_lines.empty());
  EXPECT_FALSE(c.stopped);
  EXPECT_GE(c.maps, 1);
}

// A boundary vertex given an index is a corner of the aligned boundary (solve_request turns its fan): refused by
// name where its fan cannot take the turn (three faces of a straight side, a quarter turn), and without the
// boundary aligned.
TEST(Request, BoundaryVertexGivenAnIndexIsACornerOrRefusedByName) {
  const Mesh m = test::lattice_plate(1, 1, 0.25, 0.08);
  FieldDesigner d(m.V, m.F);
  const Topology& t = d.topology();
  const int straight = test::boundary_vertex_with_fan(t, 3);
  ASSERT_GE(straight, 0);
  FieldRequest r;
  r.prescription.N = 4;
  r.prescription.vertex = {{straight, -1}};
  r.align_boundary = true;
  const std::string loop = std::to_string(t.vertex_boundary_loop[straight]);
  auto message = [&]() -> std::string {
    try {
      solve_request(d, m.F, r);
    } catch (const Error& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_EQ(message(), "singular vertex " + std::to_string(straight) + " on boundary loop " + loop +
                           " cannot be a corner of index -1/4: its fan of 3 faces cannot turn by that much in steps the field reads "
                           "unambiguously (or it has a corner already, or faces beside other aligned edges)");
  r.align_boundary = false;
  EXPECT_EQ(message(), "singular vertex " + std::to_string(straight) + " is on boundary loop " + loop +
                           ": a boundary vertex has no dual cycle (set the loop's index with --boundary instead, or align the "
                           "boundary, --align-boundary, to make the vertex a corner of it)");
}

// With moves onto feature lines, the split's gathering comes after them. A plate 0.3 thick with 3 × 2 round holes
// of radius 0.3 at 200 squares: each hole's eight −1/4 lie on its two rims (none gathered into a −2/4 in the strip
// between two holes, as the gathering before the moves made it), the eight +1/4 at the plate's corners, and the
// map and the quads have no problems.
TEST(Request, MapMovesSingularitiesOntoFeatureLinesBeforeGathering) {
  const Mesh m = test::extruded(test::perforated_plate(3, 2, 8, 3, 0.3), 0.3);
  FieldDesigner d(m.V, m.F);
  FieldRequest r;
  r.prescription.N = 4;
  r.auto_place = true;
  r.feature_degrees = 30;
  const MapOutcome o = map_request(d, m.F, r, 0, 200, true);
  ASSERT_TRUE(o.field.verified);
  int negative = 0, positive = 0;
  for (auto [v, n] : o.field.prescription.vertex) {
    ASSERT_LT(v, m.V.rows());  // an input vertex
    ASSERT_EQ(std::abs(n), 1) << "vertex " << v;
    const Eigen::RowVector3d p = m.V.row(v);
    const bool top_or_bottom = std::abs(p.z()) < 1e-9 || std::abs(p.z() + 0.3) < 1e-9;
    EXPECT_TRUE(top_or_bottom) << "vertex " << v;
    if (n < 0) {
      ++negative;
      const double radius = std::hypot(p.x() - std::floor(p.x()) - 0.5, p.y() - std::floor(p.y()) - 0.5);
      EXPECT_NEAR(radius, 0.3, 1e-6) << "vertex " << v << " is not on a rim";
    } else {
      ++positive;
      EXPECT_TRUE((p.x() == 0 || p.x() == 3) && (p.y() == 0 || p.y() == 2)) << "vertex " << v << " is not a corner";
    }
  }
  EXPECT_EQ(negative, 48);
  EXPECT_EQ(positive, 8);
  const ParamQuality& q = o.param.quality;
  EXPECT_EQ(q.flipped_faces + q.degenerate_faces + q.winding_errors, 0);
  ASSERT_TRUE(o.quads.has_value());
  EXPECT_TRUE(o.quads->quality.problems.empty());
  EXPECT_EQ(o.quads->quality.irregular_vertices, 56);
}

TEST(Request, SplittingRefusesWhatItCannotCarry) {
  const Mesh m = make_cube_sphere(3, false);
  FieldDesigner d(m.V, m.F);
  FieldRequest r;
  r.prescription.N = 4;
  r.split_large_turns = true;
  r.feature_edges = {0};
  try {
    solve_request(d, m.F, r);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "splitting large turns splits edges, which a list of feature edges names: use a feature angle instead");
  }
}

}  // namespace
}  // namespace trivcon
