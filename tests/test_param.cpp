// SPDX-License-Identifier: MIT
// trivcon/param.h: the integer-grid map on generated meshes with known answers. Every test checks what the
// map promises from the (u, v) alone (transitions, cones, iso-lines, flips), not the solver's own report only.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <set>
#include <string>

#include "support.h"
#include "trivcon/common.h"
#include "trivcon/error.h"
#include "trivcon/generate.h"
#include "trivcon/io.h"
#include "trivcon/param.h"
#include "trivcon/render.h"
#include "trivcon/request.h"

namespace trivcon {
namespace {

constexpr double kHalfPi = 1.5707963267948966;

struct MapRun {
  std::unique_ptr<FieldDesigner> designer;
  FieldOutcome outcome;
  Parametrization param;
};

MapRun run(const Mesh& m, FieldRequest r, ParamOptions o, bool align_sharp = false) {
  MapRun out;
  out.designer = std::make_unique<FieldDesigner>(m.V, m.F);
  r.prescription.N = 4;
  cancel_for_map(r, *out.designer, o.edge_length, o.target_faces);  // as the CLI: --auto's ± pairs closer than a unit cancelled
  out.outcome = solve_request(*out.designer, m.F, r);
  const Topology& t = out.designer->topology();
  if (r.align_boundary)
    for (int e = 0; e < t.num_edges; ++e)
      if (t.is_boundary_edge(e)) o.aligned_edges.push_back(e);
  if (align_sharp) o.aligned_edges.insert(o.aligned_edges.end(), out.outcome.sharp_edges.begin(), out.outcome.sharp_edges.end());
  out.param = parametrize(*out.designer, out.outcome.design, o);
  return out;
}

double whole_offset(double x) { return std::abs(x - std::round(x)); }

// Independent of the solver's report: across every interior edge, the two faces' (u, v) at both ends differ by
// one rotation by a multiple of π/2 and one whole translation (off the cut: the identity).
void expect_seamless(const MapRun& r) {
  const Topology& t = r.designer->topology();
  const Eigen::MatrixXd& uv = r.param.uv;
  auto at = [&](int f, int v) {
    for (int k = 0; k < 3; ++k)
      if (t.F(f, k) == v) return Eigen::Vector2d(uv(3 * f + k, 0), uv(3 * f + k, 1));
    ADD_FAILURE() << "vertex not in face";
    return Eigen::Vector2d(0, 0);
  };
  std::set<int> cut(r.param.cut_edges.begin(), r.param.cut_edges.end());
  double worst = 0;
  for (int e = 0; e < t.num_edges; ++e) {
    if (t.is_boundary_edge(e)) continue;
    const int L = t.edge_faces(e, 0), R = t.edge_faces(e, 1), a = t.edge_vertices(e, 0), b = t.edge_vertices(e, 1);
    const Eigen::Vector2d la = at(L, a), lb = at(L, b), ra = at(R, a), rb = at(R, b);
    // The rotation that carries L's edge vector to R's.
    double best = 1e300;
    for (int q = 0; q < 4; ++q) {
      const double c = std::cos(q * kHalfPi), s = std::sin(q * kHalfPi);
      const Eigen::Matrix2d J = (Eigen::Matrix2d() << std::round(c), -std::round(s), std::round(s), std::round(c)).finished();
      const Eigen::Vector2d ta = ra - J * la, tb = rb - J * lb;
      const double residual = std::max({(ta - tb).lpNorm<Eigen::Infinity>(), whole_offset(ta.x()), whole_offset(ta.y())});
      if (!cut.count(e) && q != 0) continue;
      if (!cut.count(e)) {
        EXPECT_LT(ta.lpNorm<Eigen::Infinity>(), 1e-9) << "edge " << e << " is off the cut but its sides differ";
      }
      best = std::min(best, residual);
    }
    worst = std::max(worst, best);
  }
  EXPECT_LT(worst, 1e-7);
  EXPECT_TRUE(r.param.quality.seamless) << param_warning(r.param);
  EXPECT_LT(r.param.quality.max_transition_residual, 1e-7);
}

void expect_cones_on_integer_points(const MapRun& r) {
  const Topology& t = r.designer->topology();
  for (int v : r.param.cones)
    for (int j = t.vertex_face_offsets[v]; j < t.vertex_face_offsets[v + 1]; ++j) {
      const int f = t.vertex_faces[j];
      for (int k = 0; k < 3; ++k)
        if (t.F(f, k) == v) {
          EXPECT_LT(whole_offset(r.param.uv(3 * f + k, 0)), 1e-7) << "cone " << v;
          EXPECT_LT(whole_offset(r.param.uv(3 * f + k, 1)), 1e-7) << "cone " << v;
        }
    }
  EXPECT_LT(r.param.quality.max_cone_angle_error, 1e-7);
}

TEST(Param, CubeGridOnTheCube) {
  // A flat-sided cube, 4 × 4 cells a side, with its 8 corners +1/4 and the field along the sharp edges: the map
  // is the cube's own grid, one unit per cell at edge length 0.5.
  const Mesh m = make_cube_sphere(4, false);
  FieldRequest req;
  req.feature_degrees = 60;
  req.auto_place = true;
  ParamOptions o;
  o.edge_length = 0.5;
  const MapRun r = run(m, req, o, true);
  EXPECT_EQ(r.param.cones.size(), 8u);
  for (int n : r.param.cone_index) EXPECT_EQ(n, 1);
  expect_seamless(r);
  expect_cones_on_integer_points(r);
  EXPECT_EQ(r.param.quality.flipped_faces, 0);
  EXPECT_EQ(r.param.quality.degenerate_faces, 0);
  EXPECT_LT(r.param.quality.max_alignment_error, 1e-7);
  EXPECT_NEAR(r.param.quality.unit_squares, 6 * 16, 1e-6);  // 6 sides of 2 × 2 length, 0.5 per unit
  EXPECT_NEAR(r.param.quality.mean_distortion, 1.0, 1e-6);
  // Every vertex of the 4 × 4 grid of each side sits on an integer point.
  for (int c = 0; c < r.param.uv.rows(); ++c) {
    EXPECT_LT(whole_offset(r.param.uv(c, 0)), 1e-7);
    EXPECT_LT(whole_offset(r.param.uv(c, 1)), 1e-7);
  }
}

TEST(Param, TorusWrapsWithoutCones) {
  const Mesh m = make_torus(48, 16);
  ParamOptions o;
  o.target_faces = 300;
  const MapRun r = run(m, {}, o);
  EXPECT_TRUE(r.param.cones.empty());
  EXPECT_FALSE(r.param.cut_edges.empty());  // the two loops of the handle
  expect_seamless(r);
  EXPECT_EQ(r.param.quality.flipped_faces, 0);
  EXPECT_NEAR(r.param.quality.unit_squares / r.param.quality.target_squares, 1.0, 0.3);
}

TEST(Param, DiskWithAlignedBoundary) {
  const Mesh m = make_disk(12, 8);
  FieldRequest req;
  req.align_boundary = true;
  req.auto_place = true;
  ParamOptions o;
  o.edge_length = 0.2;
  const MapRun r = run(m, req, o);
  expect_seamless(r);
  expect_cones_on_integer_points(r);
  EXPECT_GT(r.param.quality.aligned_edges, 0);
  EXPECT_LT(r.param.quality.max_alignment_error, 1e-7);
  EXPECT_EQ(r.param.quality.flipped_faces, 0);
}

TEST(Param, GenusTwoWithAutomaticSingularities) {
  const Mesh m = make_genus_surface(2, 3);
  FieldRequest req;
  req.auto_place = true;
  ParamOptions o;
  o.target_faces = 800;
  const MapRun r = run(m, req, o);
  expect_seamless(r);
  expect_cones_on_integer_points(r);
  int total = 0;
  for (int n : r.param.cone_index) total += n;
  EXPECT_EQ(total, 4 * (2 - 2 * 2));
  EXPECT_LE(r.param.quality.flipped_faces, 0);
}


// Strips narrower than a unit between two parallel aligned lines, meshed four triangles across: a 6 × 4 plate with
// a 4 × 3.2 slot leaves strips 0.4 high below and above it, at an edge length of 1. No face has its three corners
// on the two lines, so only the strip's own width (found by walking the real-valued map across from each line)
// keeps the rounding from putting both lines on one integer, where the strip's faces would collapse and fold (the
// first rounding, without the strips, leaves 52 problems). Each strip keeps a unit across: its faces beside the
// slot cover at least 4 squares.
// A 6 × 4 plate with a 4 × 3.2 slot, leaving strips `gap` wide above and below it, each four triangles across.
Mesh slotted_plate(double gap) {
  std::vector<double> xs, ys{0, gap / 4, gap / 2, 3 * gap / 4, gap, 1.2, 2.0, 2.8, 4 - gap, 4 - 3 * gap / 4, 4 - gap / 2, 4 - gap / 4, 4};
  for (int i = 0; i <= 12; ++i) xs.push_back(0.5 * i);
  const int nx = static_cast<int>(xs.size()), ny = static_cast<int>(ys.size());
  Mesh m;
  m.V.resize(nx * ny, 3);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) m.V.row(j * nx + i) << xs[i], ys[j], 0;
  std::vector<std::array<int, 3>> faces;
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const double cx = 0.5 * (xs[i] + xs[i + 1]), cy = 0.5 * (ys[j] + ys[j + 1]);
      if (cx > 1 && cx < 5 && cy > gap && cy < 4 - gap) continue;  // the slot
      const int a = j * nx + i, b = a + 1, c = a + nx + 1, d = a + nx;
      if ((i + j) % 2) faces.push_back({a, b, c}), faces.push_back({a, c, d});
      else faces.push_back({a, b, d}), faces.push_back({b, c, d});
    }
  m.F = test::faces(faces);
  return m;
}

// The area-weighted mean of σ_max/σ_min of each face's map from its own plane to (u, v), from the corners alone.
double mean_singular_value_ratio(const Mesh& m, const Eigen::MatrixXd& uv) {
  double sum = 0, area = 0;
  for (int f = 0; f < m.F.rows(); ++f) {
    const Eigen::Vector3d p0 = m.V.row(m.F(f, 0)), e1 = m.V.row(m.F(f, 1)) - p0.transpose(), e2 = m.V.row(m.F(f, 2)) - p0.transpose();
    const Eigen::Vector3d x = e1.normalized(), y = (e2 - e2.dot(x) * x).normalized();
    Eigen::Matrix2d E, U;  // columns: the edges in the face's plane and in (u, v)
    E << e1.dot(x), e2.dot(x), 0, e2.dot(y);
    U.col(0) = (uv.row(3 * f + 1) - uv.row(3 * f)).transpose();
    U.col(1) = (uv.row(3 * f + 2) - uv.row(3 * f)).transpose();
    const Eigen::Vector2d s = Eigen::JacobiSVD<Eigen::Matrix2d>(U * E.inverse()).singularValues();
    const double a = 0.5 * e1.cross(e2).norm();
    sum += a * s[0] / s[1], area += a;
  }
  return sum / area;
}

TEST(Param, NarrowStripsBetweenAlignedLinesKeepAUnit) {
  constexpr double gap = 0.4;
  const Mesh m = slotted_plate(gap);
  FieldRequest req;
  req.auto_place = true;
  req.align_boundary = true;
  ParamOptions o;
  o.edge_length = 1;
  const MapRun r = run(m, req, o);
  expect_seamless(r);
  const ParamQuality& q = r.param.quality;
  EXPECT_EQ(q.flipped_faces + q.degenerate_faces + q.winding_errors, 0) << param_warning(r.param);
  EXPECT_GT(q.strip_widths, 0);  // the second rounding's map
  double below = 0, above = 0;  // the (u, v) area of the strips' faces beside the slot
  for (int f = 0; f < m.F.rows(); ++f) {
    const Eigen::Vector3d c = (m.V.row(m.F(f, 0)) + m.V.row(m.F(f, 1)) + m.V.row(m.F(f, 2))).transpose() / 3;
    if (c.x() < 1 || c.x() > 5) continue;
    const Eigen::Vector2d p0 = r.param.uv.row(3 * f), p1 = r.param.uv.row(3 * f + 1), p2 = r.param.uv.row(3 * f + 2);
    const double area = 0.5 * std::abs((p1 - p0).x() * (p2 - p0).y() - (p1 - p0).y() * (p2 - p0).x());
    if (c.y() < gap) below += area;
    if (c.y() > 4 - gap) above += area;
  }
  // A unit wide along the slot's 4 units (collapsed: 0); the shape pass may move the strip's ends across x = 1
  // and x = 5 a little.
  EXPECT_GE(below, 3.9);
  EXPECT_GE(above, 3.9);
}

// The shape pass: a closed plate 0.5 thick with 3 round holes, its sharp edges aligned, at 100 squares. Its walls
// must be a whole unit high and the rims ring the holes on integer lines; the least squares' map stretches past the
// goal. With the pass the stretched faces and their neighbours take less of it, every relation still exact and
// nothing folded, and the mean ratio read from the corners falls below the goal. At 150 squares the map is within
// the goal and the pass leaves it as it is.
TEST(Param, ShapePassLowersTheStretch) {
  const Mesh m = test::extruded(test::perforated_plate(3, 1, 6, 3, 0.3), 0.5);
  FieldRequest req;
  req.auto_place = true;
  req.feature_degrees = 30;
  ParamOptions o;
  o.target_faces = 100;
  o.shape = false;
  const MapRun plain = run(m, req, o, true);
  o.shape = true;
  const MapRun shaped = run(m, req, o, true);
  o.target_faces = 150;
  const MapRun within = run(m, req, o, true);
  for (const MapRun* r : {&plain, &shaped, &within}) {
    expect_seamless(*r);
    expect_cones_on_integer_points(*r);
    const ParamQuality& q = r->param.quality;
    EXPECT_EQ(q.flipped_faces + q.degenerate_faces + q.winding_errors, 0) << param_warning(r->param);
    EXPECT_GT(q.aligned_edges, 0);
    EXPECT_LT(q.max_alignment_error, 1e-7);
    EXPECT_NEAR(mean_singular_value_ratio(m, r->param.uv), q.mean_distortion, 1e-6);
  }
  EXPECT_EQ(plain.param.quality.shaped_faces, 0);
  EXPECT_GT(shaped.param.quality.shaped_faces, 0);
  const double before = plain.param.quality.mean_distortion, after = shaped.param.quality.mean_distortion;
  EXPECT_GT(before, kMapDistortionGoal);
  EXPECT_LT(after, before - 0.04) << before << " -> " << after;
  EXPECT_LT(after, kMapDistortionGoal);
  EXPECT_LT(within.param.quality.mean_distortion, kMapDistortionGoal);
  EXPECT_EQ(within.param.quality.shaped_faces, 0);
}
// Relief: a plate with 27 round holes of radius 0.3, its boundary aligned, at 900 squares (about three units
// between neighbouring holes). Its map keeps no fold, but where the rounding left a singularity's corner opened to
// about π a face is nearly flat (σ_max/σ_min in the thousands: alone it would lift the area-weighted mean by a
// whole unit); the relief opens those regions, so that no face is stretched past a small ratio and the mean is
// within the goal, the map still exactly seamless.
TEST(Param, NearlyFlatFacesAreRelieved) {
  const Mesh m = test::perforated_plate(9, 3, 8, 4, 0.3);
  FieldRequest req;
  req.auto_place = true;
  req.align_boundary = true;
  ParamOptions o;
  o.target_faces = 900;
  const MapRun r = run(m, req, o);
  expect_seamless(r);
  expect_cones_on_integer_points(r);
  const ParamQuality& q = r.param.quality;
  EXPECT_EQ(q.flipped_faces + q.degenerate_faces + q.winding_errors, 0) << param_warning(r.param);
  EXPECT_GT(q.relieved_regions, 0);
  EXPECT_LT(q.max_distortion, 20);
  EXPECT_LT(q.mean_distortion, 1.5);
}

// Sizing: an annulus with both boundaries aligned is ringed by iso-lines whose spacing along the circles cannot be
// the same at both radii (r from 0.5 to 1), so the field's unit size everywhere stretches one direction against
// the other (1,600 squares). With the sizing the map's scale follows r as the conformal map's (log r) does and the mean
// singular-value ratio falls, the map still exactly seamless, without folds and near its target: following the
// real-valued map (two rounds) part of the way, and by the connection's own conformal factor (the field rotates
// along the circles exactly as the Levi-Civita connection of e^{2φ} g with φ = −log r would) nearly to 1.
TEST(Param, SizingLowersTheStretchAroundAnAnnulus) {
  const Mesh m = make_annulus(12, 96, 0.5, 1.0);
  FieldRequest req;
  req.auto_place = true;
  req.align_boundary = true;
  ParamOptions o;
  o.target_faces = 1600;
  o.sizing = Sizing::uniform;
  const MapRun unit = run(m, req, o);
  o.sizing = Sizing::map;
  const MapRun map_sized = run(m, req, o);
  o.sizing = Sizing::connection;
  const MapRun sized = run(m, req, o);
  for (const MapRun* r : {&unit, &map_sized, &sized}) {
    expect_seamless(*r);
    EXPECT_EQ(r->param.quality.flipped_faces + r->param.quality.degenerate_faces, 0) << param_warning(r->param);
    EXPECT_NEAR(r->param.quality.unit_squares, 1600, 480);
  }
  EXPECT_EQ(unit.param.quality.sizing, Sizing::uniform);
  EXPECT_EQ(unit.param.quality.sizing_rounds, 0);
  EXPECT_EQ(map_sized.param.quality.sizing, Sizing::map);
  EXPECT_EQ(map_sized.param.quality.sizing_rounds, 2);
  EXPECT_EQ(sized.param.quality.sizing, Sizing::connection);
  EXPECT_EQ(sized.param.quality.sizing_rounds, 0);
  const double ratio[3] = {unit.param.quality.mean_distortion, map_sized.param.quality.mean_distortion, sized.param.quality.mean_distortion};
  EXPECT_LT(ratio[1], ratio[0] - 0.05) << ratio[0] << " -> " << ratio[1];
  EXPECT_LT(ratio[2], ratio[1] - 0.01) << ratio[1] << " -> " << ratio[2];
  EXPECT_LT(ratio[2], 1.05);
}

// A scan where the rounding leaves folds around clustered singularities (armadillo, --auto, 10,000 squares):
// the local untangling (and moving a singularity to a neighbouring integer point where its ring cannot open)
// leaves none, with the map still exactly seamless.
TEST(Param, ArmadilloFoldsAreUntangled) {
  TRIVCON_REQUIRE_SHARED();
  const Mesh m = read_mesh(test::shared_mesh("armadillo.obj"));
  FieldRequest req;
  req.auto_place = true;
  ParamOptions o;
  o.target_faces = 10000;
  o.sizing = Sizing::uniform;  // the field's unit size: the rounding leaves folds (with the sizing it leaves none)
  const MapRun r = run(m, req, o);
  expect_seamless(r);
  expect_cones_on_integer_points(r);
  EXPECT_GT(r.param.quality.folds_rounded, 0);  // the case this test is for
  EXPECT_GT(r.param.quality.untangled_faces, 0);
  EXPECT_EQ(r.param.quality.flipped_faces + r.param.quality.degenerate_faces, 0) << param_warning(r.param);
  // Independent of the report: every (u, v) triangle positively oriented.
  for (int f = 0; f < m.F.rows(); ++f) {
    const Eigen::Vector2d a = r.param.uv.row(3 * f).transpose(), b = r.param.uv.row(3 * f + 1).transpose(), c = r.param.uv.row(3 * f + 2).transpose();
    ASSERT_GT((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x(), 0) << "face " << f;
  }
}

// The greedy rounding fixes each integer before the later ones; the descent after it moves integers by whole
// units to lower energy. Genus 4 at 150 squares (no retries): the rounding's own integers leave folds and a mean
// singular-value ratio above the goal; descended, the map is valid and within it.
TEST(Param, DescentOnTheIntegersMendsTheRoundedMap) {
  const Mesh m = make_genus_surface(4, 3);
  FieldRequest req;
  req.auto_place = true;
  ParamOptions o;
  o.target_faces = 150;
  o.retries = 0;
  o.shape = false;  // the rounding's maps as they are (the shape pass would lower both ratios)
  ParamOptions greedy = o;
  greedy.descend_integers = false;
  const MapRun a = run(m, req, o), b = run(m, req, greedy);
  const ParamQuality &qa = a.param.quality, &qb = b.param.quality;
  EXPECT_EQ(qb.integers_descended, 0);
  ASSERT_GT(qb.flipped_faces + qb.degenerate_faces + qb.winding_errors, 0);  // the case this test is for
  EXPECT_GT(qb.mean_distortion, kMapDistortionGoal);
  EXPECT_GT(qa.integers_descended, 0);
  EXPECT_EQ(qa.flipped_faces + qa.degenerate_faces + qa.winding_errors, 0) << param_warning(a.param);
  EXPECT_LT(qa.mean_distortion, kMapDistortionGoal);
  EXPECT_EQ(a.param.cones, b.param.cones);
  expect_seamless(a);
  expect_cones_on_integer_points(a);
}

// The near-miss retries resumed from a map made without them (what a search that screens many maps does) give
// the map parametrize gives with them, without making the screened maps again. Genus 4 at 125 squares: the first
// map and its map-sized and unit-size variants keep folds, a retry at another edge length has none.
TEST(Param, RetriesResumeFromTheScreenedMap) {
  const Mesh m = make_genus_surface(4, 3);
  FieldRequest req;
  req.auto_place = true;
  ParamOptions o;
  o.target_faces = 125;
  const MapRun whole = run(m, req, o);
  ParamOptions screening = o;
  screening.retries = 0;
  const MapRun screened = run(m, req, screening);
  const ParamQuality& s = screened.param.quality;
  ASSERT_GT(s.flipped_faces + s.degenerate_faces + s.winding_errors, 0);  // the case this test is for
  EXPECT_EQ(s.attempts, 3);
  EXPECT_GT(s.first_factorizations, 0);
  const Parametrization resumed = parametrize_retries(*screened.designer, screened.outcome.design, o, screened.param);
  EXPECT_GT(resumed.quality.attempts, 3);
  EXPECT_EQ(resumed.quality.attempts, whole.param.quality.attempts);
  EXPECT_EQ(resumed.quality.flipped_faces + resumed.quality.degenerate_faces + resumed.quality.winding_errors, 0) << param_warning(resumed);
  EXPECT_TRUE(resumed.uv == whole.param.uv);
  EXPECT_EQ(resumed.cut_edges, whole.param.cut_edges);
  EXPECT_TRUE(resumed.translation == whole.param.translation);
  EXPECT_EQ(resumed.edge_length, whole.param.edge_length);
  // A map that parametrize did not make (no first factorizations recorded) is refused.
  Parametrization foreign = screened.param;
  foreign.quality.first_factorizations = 0;
  EXPECT_THROW(parametrize_retries(*screened.designer, screened.outcome.design, o, foreign), Error);
}

// A sphere as modelling tools export it (unwelded_sphere: each pole a row of points at one place, joined by edges of
// length 0; the seam two coincident columns; a disk with one boundary loop). With the boundary aligned,
// an edge of length 0 has no direction (no face is fixed to it) and is a point on both iso-lines: the pole rows map
// to one integer point each, their faces collapse to segments (counted as such, not as folds) and nothing folds.
TEST(Param, UnweldedSphereWithItsBoundaryAligned) {
  const int rings = 24, segments = 48;
  const Mesh m = test::unwelded_sphere(rings, segments);
  FieldDesigner probe(m.V, m.F);
  ASSERT_EQ(probe.topology().boundary_loops.size(), 1u);
  // No face is fixed to a pole row's edge: the faces beside only such edges are free (the last one also has a seam
  // edge, which it follows), every other face follows its boundary edge.
  const std::map<int, double> fixed = boundary_alignment(probe.V(), probe.topology(), probe.geometry());
  for (int j = 0; j + 1 < segments; ++j) EXPECT_EQ(fixed.count(2 * j), 0u) << "pole face " << 2 * j;
  EXPECT_EQ(fixed.size(), 2u * (rings - 1) + 2);  // beside the seam: one face per ring on each side, and the two pole faces there
  for (auto [f, angle] : fixed) EXPECT_TRUE(std::isfinite(angle));
  FieldRequest req;
  req.auto_place = true;
  req.align_boundary = true;
  ParamOptions o;
  o.target_faces = 600;
  const MapRun r = run(m, req, o);
  const ParamQuality& q = r.param.quality;
  EXPECT_EQ(q.flipped_faces, 0) << param_warning(r.param);
  EXPECT_EQ(q.degenerate_faces, 0);
  EXPECT_EQ(q.collapsed_faces, 2 * segments);  // one triangle per segment at each pole
  EXPECT_EQ(q.unaligned_edges, 0);
  EXPECT_TRUE(q.seamless);
  expect_seamless(r);
  // Each pole corner on an integer point, and a face's two corners at a pole at the same (u, v): its pole edge maps
  // to a point (the charts across the cut differ by their transitions, checked above).
  const Topology& t = r.designer->topology();
  auto pole = [&](int v) { return v / (segments + 1) == 0 || v / (segments + 1) == rings; };
  int pole_edges = 0;
  for (int f = 0; f < t.num_faces; ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = t.F(f, k), b = t.F(f, (k + 1) % 3);
      if (!pole(a)) continue;
      EXPECT_EQ(whole_offset(r.param.uv(3 * f + k, 0)) + whole_offset(r.param.uv(3 * f + k, 1)), 0.0) << "face " << f;
      if (pole(b) && a / (segments + 1) == b / (segments + 1)) {
        ++pole_edges;
        EXPECT_EQ(r.param.uv.row(3 * f + k), r.param.uv.row(3 * f + (k + 1) % 3)) << "face " << f;
      }
    }
  EXPECT_EQ(pole_edges, 2 * segments);
}

TEST(Param, SeveralComponents) {
  const Mesh m = concatenate({make_torus(36, 12), make_cube_sphere(4, true), make_disk(6, 8)});
  FieldRequest req;
  req.auto_place = true;
  ParamOptions o;
  o.target_faces = 600;
  const MapRun r = run(m, req, o);
  expect_seamless(r);
  expect_cones_on_integer_points(r);
}

// The renderer's checkerboard of the map: about half of the surface's pixels take the checker colour (told
// apart from the front colour by their red/blue ratio, which shading does not change).
TEST(Param, CheckerboardPicture) {
  const Mesh m = make_torus(48, 16);
  ParamOptions o;
  o.target_faces = 200;
  const MapRun r = run(m, {}, o);
  RenderOptions ro;
  ro.width = 400, ro.height = 300, ro.legend = false, ro.draw_field = false;
  ro.corner_uv.resize(m.F.rows(), 6);
  for (int f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) ro.corner_uv(f, 2 * k) = r.param.uv(3 * f + k, 0), ro.corner_uv(f, 2 * k + 1) = r.param.uv(3 * f + k, 1);
  const Image image = render_design(*r.designer, r.outcome.design, ro);
  int surface = 0, checker = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const Rgb p = image.pixel(x, y);
      if (p == ro.palette.background || p[2] == 0) continue;
      ++surface;
      checker += static_cast<double>(p[0]) / p[2] < 0.78;
    }
  ASSERT_GT(surface, 10000);
  EXPECT_NEAR(static_cast<double>(checker) / surface, 0.5, 0.15);
  ro.corner_uv.resize(3, 6);
  EXPECT_THROW(render_design(*r.designer, r.outcome.design, ro), Error);
}

// Where the connection turns by π or more across an edge the per-face field turns by 2π less: the map, which
// follows it, reads a +1 and a −1 at that edge's ends that were not prescribed. Counted (half_turn_edges), said
// in the warning, and nowhere else: +3 (twelve quarters) at one vertex of a coarse icosphere, −1 at another, the
// first vertex's five dual edges turning by about 6π/5 each; the cube sphere's eight +1/4 turn far less.
TEST(Param, ConnectionTurningByHalfARevolutionIsReported) {
  const Mesh m = make_icosphere(1);
  FieldDesigner d(m.V, m.F);
  IndexPrescription p;
  p.N = 4;
  int far = 0;
  for (int v = 0; v < m.V.rows(); ++v)
    if (m.V.row(v).dot(m.V.row(0)) < m.V.row(far).dot(m.V.row(0))) far = v;
  p.vertex = {{0, 12}, {far, -4}};
  const Design design = d.design(p);
  ParamOptions o;
  o.target_faces = 60;
  const Parametrization param = parametrize(d, design, o);
  int half_turns = 0;
  for (int e = 0; e < d.topology().num_edges; ++e) half_turns += std::abs(design.connection.x[e]) >= kPi;
  ASSERT_GT(half_turns, 0);
  EXPECT_EQ(param.quality.half_turn_edges, half_turns);
  EXPECT_NE(param_warning(param).find("the connection turns by pi or more across " + std::to_string(half_turns) + " edge(s)"), std::string::npos)
      << param_warning(param);
  std::map<int, int> cones;
  for (size_t k = 0; k < param.cones.size(); ++k) cones[param.cones[k]] = param.cone_index[k];
  EXPECT_NE(cones, p.vertex);  // the map's cones are the per-face field's, not the prescription
  FieldRequest req;
  req.auto_place = true;
  ParamOptions unit;
  unit.edge_length = 0.5;
  EXPECT_EQ(run(make_cube_sphere(4, true), req, unit).param.quality.half_turn_edges, 0);
}

TEST(Param, RefusesWhatItCannotMap) {
  const Mesh m = make_torus(12, 6);
  FieldDesigner d(m.V, m.F);
  // parametrize's error message ("no error" when it maps).
  auto message = [&](const Design& design, const ParamOptions& options) -> std::string {
    try {
      parametrize(d, design, options);
    } catch (const Error& e) {
      return e.what();
    }
    return "no error";
  };
  IndexPrescription p;
  p.N = 6;
  const Design six = d.design(p);
  ParamOptions o;
  o.edge_length = 0.1;
  EXPECT_EQ(message(six, o), "param: a seamless parametrization needs a cross field (N = 4), got N = 6");
  p.N = 4;
  const Design four = d.design(p);
  EXPECT_EQ(message(four, {}), "param: give a positive edge length or target face count (--edge-length H or --target-faces K)");
  o.aligned_edges = {d.topology().num_edges};
  EXPECT_THROW(parametrize(d, four, o), Error);
  o.aligned_edges.clear();
  for (double share : {0.0, -0.5, 1.5, std::nan("")}) {
    o.untangle_share = share;
    EXPECT_THROW(parametrize(d, four, o), Error) << share;
  }
  o.untangle_share = 1.5;
  EXPECT_EQ(message(four, o), "param: untangle_share must be in (0, 1], got 1.5");
  o.untangle_share = kUntangleShareFollowed;
  EXPECT_TRUE(parametrize(d, four, o).quality.seamless);
}

}  // namespace
}  // namespace trivcon
