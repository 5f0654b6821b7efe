// SPDX-License-Identifier: MIT
// Tests of trivcon/geometry.h: the documented conventions (frames, half-edge angles, ρ, cotan weights),
// Gauss–Bonnet, degenerate faces, and wrap_angle. Expected values are recomputed from the positions.
#include "trivcon/geometry.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "support.h"
#include "trivcon/generate.h"
#include "trivcon/topology.h"

namespace trivcon {
namespace {

using Eigen::Vector3d;
using test::expect_consistent;
using test::expect_geometry_sane;
using test::faces;
using test::topo;

Vector3d corner(const MatrixX3d& V, const Topology& t, int f, int k) { return V.row(t.F(f, k)); }

struct Prepared {
  Topology t;
  Geometry g;
};
Prepared prepare(const Mesh& m) {
  Topology t = topo(m);
  Geometry g = compute_geometry(m.V, t);
  return {std::move(t), std::move(g)};
}

// A copy with every vertex moved by up to `amount` in each coordinate (in the xy plane only when `flat`).
Mesh jittered(Mesh m, double amount, unsigned seed, bool flat = false) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-amount, amount);
  for (int v = 0; v < m.V.rows(); ++v)
    for (int k = 0; k < (flat ? 2 : 3); ++k) m.V(v, k) += jitter(rng);
  return m;
}

// ----------------------------------------------------------------------------------------------
// The conventions of geometry.h

TEST(Geometry, WrapAngleIntoMinusPiPi) {
  EXPECT_EQ(wrap_angle(0.5), 0.5);  // inside: unchanged, exactly
  EXPECT_EQ(wrap_angle(kPi), kPi);
  EXPECT_NEAR(wrap_angle(-kPi), kPi, 1e-15);
  EXPECT_NEAR(wrap_angle(3 * kPi), kPi, 1e-15);
  EXPECT_NEAR(wrap_angle(-1.5 * kPi), 0.5 * kPi, 1e-15);
  EXPECT_NEAR(wrap_angle(7.0), 7.0 - kTwoPi, 1e-15);
  EXPECT_NEAR(wrap_angle(-100.0), -100.0 + 32 * kPi, 1e-13);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> any(-1e3, 1e3);
  int bad = 0;
  for (int i = 0; i < 10000; ++i) {
    const double a = any(rng), w = wrap_angle(a);
    const double turns = (a - w) / kTwoPi;
    bad += !(w > -kPi && w <= kPi) || std::abs(turns - std::round(turns)) > 1e-12;
  }
  EXPECT_EQ(bad, 0) << "results outside (−π, π] or not a whole number of turns from the input";
}

// Frame, normal, half-edge angles, corner angles and areas recomputed from the positions, and the two
// conversions between angles and world vectors.
TEST(Geometry, FramesHalfEdgeAnglesAndConversions) {
  for (const auto& [name, m] : std::vector<std::pair<std::string, Mesh>>{{"icosphere", jittered(make_icosphere(2), 0.03, 1)},
                                                                         {"torus", jittered(make_torus(9, 7), 0.03, 2)},
                                                                         {"disk", make_disk(3, 5)}}) {
    SCOPED_TRACE(name);
    const auto [t, g] = prepare(m);
    double worst = 0;
    for (int f = 0; f < t.num_faces; ++f) {
      const Vector3d p0 = corner(m.V, t, f, 0), p1 = corner(m.V, t, f, 1), p2 = corner(m.V, t, f, 2);
      const Vector3d x = g.frame_x.row(f), y = g.frame_y.row(f), n = g.normal.row(f);
      const Vector3d raw_normal = (p1 - p0).cross(p2 - p0);
      worst = std::max({worst, (x - (p1 - p0).normalized()).norm(), (n - raw_normal.normalized()).norm(), (y - n.cross(x)).norm(),
                        std::abs(g.face_area(f) - 0.5 * raw_normal.norm())});
      const Vector3d p[3] = {p0, p1, p2};
      for (int k = 0; k < 3; ++k) {
        const Vector3d u = p[(k + 1) % 3] - p[k], w = p[(k + 2) % 3] - p[k];
        worst = std::max(worst, std::abs(g.corner_angles(f, k) - std::acos(u.normalized().dot(w.normalized()))));
        // The half-edge from corner k to k+1 points at half_edge_angle(f, k) in the face's frame.
        worst = std::max(worst, (g.direction_in_face(f, g.half_edge_angle(f, k)) - u.normalized()).norm());
      }
      for (double beta : {-2.0, 0.0, 0.7, 3.0, 10.0}) {
        const Vector3d d = g.direction_in_face(f, beta);
        worst = std::max({worst, std::abs(d.norm() - 1), std::abs(d.dot(n)), (d - (std::cos(beta) * x + std::sin(beta) * y)).norm()});
        // angle_in_face inverts direction_in_face, whatever the length or the normal component.
        worst = std::max(worst, std::abs(wrap_angle(g.angle_in_face(f, 3.0 * d - 2.0 * n) - beta)));
      }
    }
    EXPECT_LE(worst, 1e-9);
  }
}

// ρ(e) is the angle of p_j − p_i in R's frame minus its angle in L's frame; it transports directions
// keeping their angle with the shared edge (on a flat mesh: the same world vector), and summed around an
// interior vertex it is the angle defect, modulo 2π.
TEST(Geometry, RhoIsTheLeviCivitaRotation) {
  for (const auto& [name, m, flat] :
       std::vector<std::tuple<std::string, Mesh, bool>>{{"flat holed grid", jittered(make_holed_grid(9, 2), 0.01, 3, true), true},
                                                        {"flat annulus", make_annulus(3, 12), true},
                                                        {"icosphere", jittered(make_icosphere(2), 0.03, 4), false},
                                                        {"genus 2", jittered(make_genus_surface(2, 1), 0.02, 5), false}}) {
    SCOPED_TRACE(name);
    const auto [t, g] = prepare(m);
    double worst = 0;
    for (int e = 0; e < t.num_edges; ++e) {
      if (t.is_boundary_edge(e)) continue;
      const int L = t.edge_faces(e, 0), R = t.edge_faces(e, 1);
      const Vector3d edge = m.V.row(t.edge_vertices(e, 1)) - m.V.row(t.edge_vertices(e, 0));
      worst = std::max(worst, std::abs(wrap_angle(g.angle_in_face(R, edge) - g.angle_in_face(L, edge) - g.rho(e))));
      for (double beta : {0.3, 2.0, -1.2}) {
        const Vector3d dl = g.direction_in_face(L, beta), dr = g.direction_in_face(R, beta + g.rho(e));
        const Vector3d nl = g.normal.row(L), nr = g.normal.row(R);
        const double to_edge_l = std::atan2(dl.cross(edge).dot(nl), dl.dot(edge));
        const double to_edge_r = std::atan2(dr.cross(edge).dot(nr), dr.dot(edge));
        worst = std::max(worst, std::abs(wrap_angle(to_edge_l - to_edge_r)));
        if (flat) worst = std::max(worst, (dl - dr).norm());
      }
    }
    EXPECT_LE(worst, 1e-9);
    Eigen::VectorXd holonomy = Eigen::VectorXd::Zero(t.num_vertices);  // Σ s_ve ρ_e, s = +1 where v is the larger id
    for (int e = 0; e < t.num_edges; ++e) {
      holonomy(t.edge_vertices(e, 1)) += g.rho(e);
      holonomy(t.edge_vertices(e, 0)) -= g.rho(e);
    }
    double worst_vertex = 0;
    for (int v = 0; v < t.num_vertices; ++v)
      if (t.is_interior_vertex(v)) worst_vertex = std::max(worst_vertex, std::abs(wrap_angle(holonomy(v) - g.angle_defect(v))));
    EXPECT_LE(worst_vertex, 1e-9);
  }
}

// cotan_weight = ½ (max(cot α, 0) + max(cot β, 0)) over the angles opposite each interior edge.
TEST(Geometry, CotanWeightsFromTheOppositeAngles) {
  {
    // Right isosceles triangles with axis-aligned legs: cot 45° = 1 on both sides of an axis-aligned
    // edge, cot 90° = 0 opposite each diagonal.
    const Mesh m = make_holed_grid(10, 2);
    const auto [t, g] = prepare(m);
    int bad = 0;
    for (int e = 0; e < t.num_edges; ++e) {
      const Vector3d d = m.V.row(t.edge_vertices(e, 1)) - m.V.row(t.edge_vertices(e, 0));
      const bool diagonal = std::abs(d.x()) > 1e-12 && std::abs(d.y()) > 1e-12;
      const double expected = t.is_boundary_edge(e) || diagonal ? 0.0 : 1.0;
      bad += std::abs(g.cotan_weight(e) - expected) > 1e-12;
    }
    EXPECT_EQ(bad, 0);
    EXPECT_EQ(g.negative_cotan_edges, 0);
  }
  const Mesh m = jittered(make_torus(8, 6), 0.15, 6);  // rough enough for some negative sums
  const auto [t, g] = prepare(m);
  auto cot_opposite = [&m, &t = t](int f, int e) {  // (a structured binding is captured through a reference)
    int k = 0;
    while (t.face_edges(f, k) != e) ++k;
    const Vector3d apex = corner(m.V, t, f, (k + 2) % 3), u = corner(m.V, t, f, k) - apex, w = corner(m.V, t, f, (k + 1) % 3) - apex;
    return u.dot(w) / u.cross(w).norm();
  };
  int negative = 0;
  double worst = 0;
  for (int e = 0; e < t.num_edges; ++e) {
    const double a = cot_opposite(t.edge_faces(e, 0), e), b = cot_opposite(t.edge_faces(e, 1), e);
    negative += a + b < 0;
    worst = std::max(worst, std::abs(g.cotan_weight(e) - 0.5 * (std::max(a, 0.0) + std::max(b, 0.0))));
  }
  EXPECT_LE(worst, 1e-12);
  EXPECT_GT(negative, 0) << "the jitter should make some edges' cotangent sums negative";
  EXPECT_EQ(g.negative_cotan_edges, negative);
}

TEST(Geometry, AreasAddUp) {
  const int n = 14, holes = 2, w = n / (2 * holes + 1);
  EXPECT_NEAR(prepare(make_holed_grid(n, holes)).g.face_area.sum(),
              1.0 - holes * (static_cast<double>(w) / n) * (static_cast<double>(w) / n), 1e-12);
  const Mesh sphere = make_icosphere(4);  // inscribed in the unit sphere
  const double area = prepare(sphere).g.face_area.sum();
  EXPECT_LT(area, 4 * kPi);
  EXPECT_GT(area, 0.99 * 4 * kPi);
}

// Above 50k faces the loops run on several threads: the same numbers, bit for bit.
TEST(Geometry, ThreadCountDoesNotChangeTheResult) {
  const Mesh m = jittered(make_icosphere(6), 0.001, 7);  // 81,920 faces
  const Topology t = topo(m);
  const Geometry a = compute_geometry(m.V, t, 1), b = compute_geometry(m.V, t, 2);
  EXPECT_TRUE(a.corner_angles == b.corner_angles);
  EXPECT_TRUE(a.half_edge_angle == b.half_edge_angle);
  EXPECT_TRUE(a.face_area == b.face_area);
  EXPECT_TRUE(a.frame_x == b.frame_x && a.frame_y == b.frame_y && a.normal == b.normal);
  EXPECT_TRUE(a.angle_defect == b.angle_defect);
  EXPECT_TRUE(a.rho == b.rho);
  EXPECT_TRUE(a.cotan_weight == b.cotan_weight);
  EXPECT_EQ(a.negative_cotan_edges, b.negative_cotan_edges);
  EXPECT_EQ(a.degenerate_faces, b.degenerate_faces);
}

// ----------------------------------------------------------------------------------------------
// Gauss–Bonnet, degenerate faces, finiteness (moved from test_topology.cpp, suite TopologyGeometry)

TEST(Geometry, GaussBonnetOnGeneratedMeshes) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.02, 0.02);
  std::vector<std::pair<std::string, Mesh>> meshes = {
      {"icosphere", make_icosphere(3)},
      {"uv sphere", make_uv_sphere(10, 16)},
      {"torus", make_torus(16, 9)},
      {"genus 3", make_genus_surface(3, 2)},
      {"disk", make_disk(5, 6)},
      {"annulus", make_annulus(3, 12)},
      {"holed grid", make_holed_grid(12, 3)},
      {"concatenation", concatenate({make_icosphere(1), make_torus(5, 5), make_disk(2, 4), make_holed_grid(5, 2)})},
  };
  for (auto& [name, m] : meshes) {
    expect_geometry_sane(m.V, topo(m), name);
    Mesh j = m;  // jittered in 3D: no longer flat, some negative cotangents
    for (int v = 0; v < j.V.rows(); ++v)
      for (int k = 0; k < 3; ++k) j.V(v, k) += jitter(rng);
    expect_geometry_sane(j.V, topo(j), name + " jittered");
    const Mesh p = permute(j, 11);
    expect_geometry_sane(p.V, topo(p), name + " jittered, permuted");
  }
}

TEST(Geometry, FlatDiskHasZeroInteriorCurvature) {
  const Mesh m = make_disk(4, 5);
  const Topology t = topo(m);
  const Geometry g = compute_geometry(m.V, t);
  double boundary = 0;
  for (int v = 0; v < t.num_vertices; ++v) {
    if (t.is_interior_vertex(v)) {
      EXPECT_NEAR(g.angle_defect(v), 0, 1e-12) << "vertex " << v;
    } else
      boundary += g.angle_defect(v);
  }
  EXPECT_NEAR(boundary, 2 * kPi, 1e-9);
}

// Flat mesh with one face of three collinear points (face 2 = (0, 2, 1), vertex 1 between 0 and 2).
Mesh collinear_face_mesh() {
  Mesh m;
  m.V.resize(5, 3);
  m.V << 0, 0, 0,  //
      1, 0, 0,     // between 0 and 2
      2, 0, 0,     //
      1, 1, 0,     //
      1, -1, 0;
  m.F = faces({{0, 1, 3}, {1, 2, 3}, {0, 2, 1}, {0, 4, 2}});
  return m;
}

TEST(Geometry, CollinearFace) {
  const Mesh m = collinear_face_mesh();
  const Topology t = topo(m);
  expect_consistent(t, m.F, 5, "collinear");
  EXPECT_EQ(t.euler_characteristic(), 1);
  EXPECT_EQ(t.boundary_loops.size(), 1u);
  EXPECT_TRUE(t.is_interior_vertex(1));
  expect_geometry_sane(m.V, t, "collinear", 1e-12);
  const Geometry g = compute_geometry(m.V, t);
  EXPECT_EQ(g.zero_area_faces, 1);
  EXPECT_EQ(g.degenerate_faces, 1);
  EXPECT_TRUE(g.degenerate_face[2]);
  EXPECT_EQ(g.face_area(2), 0.0);
  // Corners (0, 2, 1): the middle point 1 is corner 2 and gets π.
  EXPECT_NEAR(g.corner_angles(2, 0), 0, 1e-15);
  EXPECT_NEAR(g.corner_angles(2, 1), 0, 1e-15);
  EXPECT_NEAR(g.corner_angles(2, 2), kPi, 1e-15);
  EXPECT_NEAR(g.angle_defect(1), 0, 1e-12);  // π/2 + π/2 + π around vertex 1
  // The degenerate face borrows its neighbours' normal (+z).
  EXPECT_NEAR(g.normal(2, 2), 1.0, 1e-12);
}

TEST(Geometry, CoincidentVertices) {
  // Two coincident vertices: the faces on that edge get (0 opposite, π/2, π/2).
  {
    Mesh m = make_icosphere(2);
    const int a = m.F(0, 0), b = m.F(0, 1);
    m.V.row(b) = m.V.row(a);
    const Topology t = topo(m);
    expect_geometry_sane(m.V, t, "two coincident vertices");
    const Geometry g = compute_geometry(m.V, t);
    EXPECT_GE(g.degenerate_faces, 2);
    EXPECT_EQ(g.zero_area_faces, 2);
    EXPECT_NEAR(g.corner_angles(0, 2), 0, 1e-15);
    EXPECT_NEAR(g.corner_angles(0, 0), kPi / 2, 1e-15);
    EXPECT_NEAR(g.corner_angles(0, 1), kPi / 2, 1e-15);
  }
  // A whole face collapsed to one point: π/3 at each corner.
  {
    Mesh m = make_icosphere(2);
    const int a = m.F(5, 0), b = m.F(5, 1), c = m.F(5, 2);
    m.V.row(b) = m.V.row(a);
    m.V.row(c) = m.V.row(a);
    const Topology t = topo(m);
    expect_geometry_sane(m.V, t, "collapsed face");
    const Geometry g = compute_geometry(m.V, t);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(g.corner_angles(5, k), kPi / 3, 1e-15);
    EXPECT_GE(g.zero_area_faces, 4);  // the face and its three edge neighbours
  }
  // The same on a surface with boundary and on a torus.
  {
    Mesh m = make_disk(3, 5);
    m.V.row(m.F(3, 1)) = m.V.row(m.F(3, 0));
    expect_geometry_sane(m.V, topo(m), "disk with coincident vertices");
    Mesh tor = make_torus(8, 6);
    tor.V.row(tor.F(10, 2)) = tor.V.row(tor.F(10, 1));
    expect_geometry_sane(tor.V, topo(tor), "torus with coincident vertices");
  }
}

TEST(Geometry, AllVerticesAtOnePoint) {
  Mesh m = make_icosphere(1);
  m.V.setZero();
  const Topology t = topo(m);
  expect_geometry_sane(m.V, t, "all at the origin");
  const Geometry g = compute_geometry(m.V, t);
  EXPECT_EQ(g.zero_area_faces, t.num_faces);
  EXPECT_EQ(g.degenerate_faces, t.num_faces);
}

}  // namespace
}  // namespace trivcon
