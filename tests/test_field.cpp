// SPDX-License-Identifier: MIT
// Tests of trivcon/field.h: propagation reproduces the connection it is given, the indices read off a
// field (solved or made by hand) are the expected ones and do not see the N-fold symmetry, and the
// conversions between angles and world directions.
#include "trivcon/field.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "support.h"
#include "trivcon/design.h"
#include "trivcon/generate.h"

namespace trivcon {
namespace {

using test::error_of;

struct Case {
  std::string name;
  Mesh mesh;
  IndexPrescription prescription;
};

IndexPrescription with_vertices(int N, const std::map<int, int>& vertex) {
  IndexPrescription p;
  p.N = N;
  p.vertex = vertex;
  return p;
}

// Meshes of every kind of cycle: vertices only, generators, loops, several components.
std::vector<Case> solved_cases() {
  const Mesh cube = make_cube_sphere(6, true);
  std::map<int, int> corners;
  for (int v : test::vertices_of_valence(cube, 3)) corners[v] = 1;
  const Mesh sphere = make_icosphere(3);
  return {{"sphere, two poles", sphere, with_vertices(1, {{0, 1}, {3, 1}})},
          {"cube, eight corners", cube, with_vertices(4, corners)},
          {"torus, a pair", make_torus(30, 14), with_vertices(4, {{40, 1}, {200, -1}})},
          {"annulus", make_annulus(6, 30), with_vertices(2, {})},
          {"grid with holes", make_holed_grid(20, 2), with_vertices(4, {{150, 1}})},
          {"sphere, disk and torus", concatenate({sphere, make_disk(6, 6), make_torus(20, 10)}),
           with_vertices(2, {{0, 2}, {3, 2}, {sphere.V.rows(), 1}})}};
}

// Runs `check` on every solved case with its designer and the solved connection.
void for_each_solved(const std::function<void(const Case&, const FieldDesigner&, const Connection&)>& check) {
  for (const Case& c : solved_cases()) {
    SCOPED_TRACE(c.name);
    const FieldDesigner d(c.mesh.V, c.mesh.F);
    check(c, d, d.solver().solve(c.prescription));
  }
}

TEST(Field, ReduceAngle) {
  for (int N : {1, 2, 4, 6}) {
    const double period = kTwoPi / N;
    EXPECT_NEAR(reduce_angle(kPi / N, N), kPi / N, 1e-15);
    EXPECT_NEAR(reduce_angle(-kPi / N, N), kPi / N, 1e-15);
    EXPECT_NEAR(reduce_angle(3 * period + 0.1, N), 0.1, 1e-12);
    std::mt19937 rng(N);
    std::uniform_real_distribution<double> any(-50, 50);
    int bad = 0;
    for (int i = 0; i < 2000; ++i) {
      const double a = any(rng), r = reduce_angle(a, N), turns = (a - r) / period;
      bad += !(r > -kPi / N && r <= kPi / N) || std::abs(turns - std::round(turns)) > 1e-9;
    }
    EXPECT_EQ(bad, 0) << "N = " << N;
  }
}

TEST(Field, PlanIsABreadthFirstSpanningTreePerComponent) {
  const Mesh m = concatenate({make_icosphere(2), make_annulus(3, 9), make_torus(6, 5)});
  const FieldDesigner d(m.V, m.F);
  const Topology& t = d.topology();
  const PropagationPlan plan = plan_propagation(t);
  ASSERT_EQ(static_cast<int>(plan.order.size()), t.num_faces);
  ASSERT_EQ(plan.component_begin.size(), t.components.size() + 1);
  std::vector<int> seen(t.num_faces, 0);
  int bad = 0;
  for (size_t c = 0; c < t.components.size(); ++c) {
    const int begin = plan.component_begin[c], end = plan.component_begin[c + 1];
    EXPECT_EQ(end - begin, t.components[c].faces);
    EXPECT_EQ(plan.order[begin], t.components[c].first_face);
    EXPECT_EQ(plan.parent[begin], -1);
    EXPECT_EQ(plan.edge[begin], -1);
    for (int q = begin; q < end; ++q) {
      const int f = plan.order[q];
      ++seen[f];
      bad += t.face_component[f] != static_cast<int>(c);
      if (q == begin) continue;
      const int p = plan.parent[q], e = plan.edge[q];
      bad += !(p >= begin && p < q);              // reached from a face earlier in the same component
      const int side = plan.sign[q] > 0 ? 0 : 1;  // the parent's side of the edge: L when crossing L → R
      bad += t.edge_faces(e, side) != plan.order[p] || t.edge_faces(e, 1 - side) != f;
    }
  }
  EXPECT_EQ(bad, 0);
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), t.num_faces) << "every face exactly once";
}

// β_R = β_L + ρ − x across every interior edge (not only the tree's), whichever overload, and roots
// only rotate their own component.
TEST(Field, PropagationReproducesTheConnection) {
  for_each_solved([](const Case& c, const FieldDesigner& d, const Connection& conn) {
    const Topology& t = d.topology();
    const Geometry& g = d.geometry();
    const int N = c.prescription.N;
    const Eigen::VectorXd& x = conn.x;
    const Field f = propagate_field(t, g, x, N);
    EXPECT_EQ(f.N, N);
    ASSERT_EQ(f.angle.size(), t.num_faces);
    EXPECT_TRUE((f.angle.array() >= 0).all() && (f.angle.array() < kTwoPi).all());
    EXPECT_LE(max_transport_mismatch(t, g, x, f), 1e-9);
    EXPECT_TRUE(propagate_field(t, g, d.plan(), x, N).angle == f.angle) << "the plan overload differs";
    for (size_t k = 0; k < t.components.size(); ++k) EXPECT_EQ(f.angle(t.components[k].first_face), 0.0) << "component " << k;

    // Another connection is another field: one edge turned by 0.3 shows up as a mismatch.
    Eigen::VectorXd y = x;
    int e = 0;
    while (t.is_boundary_edge(e)) ++e;
    y(e) += 0.3;
    EXPECT_GT(max_transport_mismatch(t, g, y, propagate_field(t, g, y, N)), 1e-3);

    // A root in the last component: its angle there, the component rotated rigidly, the others unchanged.
    const int last = static_cast<int>(t.components.size()) - 1, root = t.components[last].first_face + 7;
    const Field r = propagate_field(t, g, x, N, {{root, 1.25}});
    EXPECT_NEAR(r.angle(root), 1.25, 1e-12);
    EXPECT_LE(max_transport_mismatch(t, g, x, r), 1e-9);
    const double rotation = r.angle(root) - f.angle(root);
    double worst = 0;
    for (int h = 0; h < t.num_faces; ++h)
      worst = std::max(worst, std::abs(wrap_angle(r.angle(h) - f.angle(h) - (t.face_component[h] == last ? rotation : 0.0))));
    EXPECT_LE(worst, 1e-9);
  });
}

// The indices read off the propagated field alone are the prescription at every interior vertex (0 where
// none is prescribed), and the connection's generator and loop indices.
TEST(Field, IndicesOfASolvedFieldAreThePrescription) {
  for_each_solved([](const Case& c, const FieldDesigner& d, const Connection& conn) {
    const Topology& t = d.topology();
    const FieldIndices fi = field_indices(t, d.geometry(), d.cycles(), propagate_field(t, d.geometry(), conn.x, c.prescription.N));
    ASSERT_EQ(static_cast<int>(fi.vertex.size()), t.num_vertices);
    std::vector<int> want(t.num_vertices, 0);
    for (auto [v, n] : c.prescription.vertex) want[v] = n;
    EXPECT_EQ(fi.vertex, want);
    EXPECT_EQ(fi.generator, conn.generator_index);
    EXPECT_EQ(fi.loop, conn.loop_index);
    EXPECT_LE(fi.max_rounding, 1e-6);
  });
}

// Fields given as world directions, no solver: a constant field on a flat disk has no singular vertex and
// loop index +1; on a flat annulus +1 outside and −1 inside; a radial field on the disk has +1 at the
// centre and loop index 0; a concentric field on the annulus has 0 on both loops (indices.h).
TEST(Field, IndicesOfFieldsMadeByHand) {
  auto indices_of = [](const FieldDesigner& d, int N, const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& direction) {
    MatrixX3d dirs(d.topology().num_faces, 3);
    for (int f = 0; f < d.topology().num_faces; ++f) {
      Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
      for (int k = 0; k < 3; ++k) centroid += d.V().row(d.topology().F(f, k)).transpose() / 3;
      dirs.row(f) = direction(centroid);
    }
    return field_indices(d.topology(), d.geometry(), d.cycles(), field_from_directions(d.geometry(), dirs, N));
  };
  auto constant = [](const Eigen::Vector3d&) { return Eigen::Vector3d(0.6, 0.8, 0); };
  auto radial = [](const Eigen::Vector3d& p) { return Eigen::Vector3d(p.x(), p.y(), 0); };
  auto concentric = [](const Eigen::Vector3d& p) { return Eigen::Vector3d(-p.y(), p.x(), 0); };
  const Mesh disk = make_disk(6, 16), annulus = make_annulus(4, 24);  // neighbours' radial directions differ by < π/4
  const FieldDesigner dd(disk.V, disk.F), da(annulus.V, annulus.F);
  const int outer = annulus.V.row(da.topology().boundary_loops[0][0]).norm() > 0.75 ? 0 : 1;  // radii 0.5 and 1
  for (int N : {1, 2, 4}) {
    SCOPED_TRACE("N = " + std::to_string(N));
    const std::vector<int> none(disk.V.rows(), 0);
    std::vector<int> centre = none;
    centre[0] = N;
    FieldIndices fi = indices_of(dd, N, constant);
    EXPECT_EQ(fi.vertex, none);
    EXPECT_EQ(fi.loop, std::vector<int>{N});
    fi = indices_of(dd, N, radial);
    EXPECT_EQ(fi.vertex, centre);
    EXPECT_EQ(fi.loop, std::vector<int>{0});
    fi = indices_of(da, N, constant);
    EXPECT_EQ(fi.vertex, std::vector<int>(annulus.V.rows(), 0));
    ASSERT_EQ(fi.loop.size(), 2u);
    EXPECT_EQ(fi.loop[outer], N);
    EXPECT_EQ(fi.loop[1 - outer], -N);
    EXPECT_EQ(indices_of(da, N, concentric).loop, (std::vector<int>{0, 0}));
  }
}

// Turning any face's directions by a multiple of 2π/N gives the same N-direction field: nothing changes.
// Turning every face by the same angle is another root angle: the connection's field still, same indices;
// turning one face by less than π/N is not.
TEST(Field, InvariantUnderTheNFoldSymmetry) {
  for_each_solved([](const Case& c, const FieldDesigner& d, const Connection& conn) {
    const Topology& t = d.topology();
    const Geometry& g = d.geometry();
    const int N = c.prescription.N;
    if (N == 1) return;  // every turn is a multiple of 2π/1
    const Eigen::VectorXd& x = conn.x;
    const Field f = propagate_field(t, g, x, N);
    const FieldIndices base = field_indices(t, g, d.cycles(), f);
    std::mt19937 rng(4);
    Field once = f, random = f, shifted = f, one_face = f;
    for (int h = 0; h < t.num_faces; ++h) {
      once.angle(h) += kTwoPi / N;
      random.angle(h) += kTwoPi / N * static_cast<int>(rng() % (2 * N) - N);
      shifted.angle(h) += 0.37;
    }
    one_face.angle(t.num_faces / 2) += 0.3;
    for (const Field* other : {&once, &random, &shifted}) {
      const FieldIndices fi = field_indices(t, g, d.cycles(), *other);
      EXPECT_EQ(fi.vertex, base.vertex);
      EXPECT_EQ(fi.generator, base.generator);
      EXPECT_EQ(fi.loop, base.loop);
    }
    for (const Field* other : {&once, &random, &shifted}) EXPECT_LE(max_transport_mismatch(t, g, x, *other), 1e-9);
    EXPECT_NEAR(max_transport_mismatch(t, g, x, one_face), 0.3, 1e-9);
  });
}

TEST(Field, WorldDirectionsRoundTrip) {
  const Mesh m = make_torus(12, 7);
  const FieldDesigner d(m.V, m.F);
  const Geometry& g = d.geometry();
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> any(0, kTwoPi);
  Field f;
  f.N = 4;
  f.angle.resize(d.topology().num_faces);
  for (int h = 0; h < f.angle.size(); ++h) f.angle(h) = any(rng);
  const MatrixX3d dirs = field_directions(g, f);
  ASSERT_EQ(dirs.rows(), f.angle.size());
  // Unit and tangent; read back from the vectors, also when scaled and lifted off the face.
  EXPECT_LE((dirs.rowwise().norm().array() - 1).abs().maxCoeff(), 1e-12);
  EXPECT_LE(dirs.cwiseProduct(g.normal).rowwise().sum().cwiseAbs().maxCoeff(), 1e-12);
  const MatrixX3d lifted = 2.5 * dirs + 0.7 * g.normal;
  const Field back = field_from_directions(g, lifted, 4);
  EXPECT_EQ(back.N, 4);
  double worst = 0;
  for (int h = 0; h < f.angle.size(); ++h) worst = std::max(worst, std::abs(wrap_angle(back.angle(h) - f.angle(h))));
  EXPECT_LE(worst, 1e-12);
  EXPECT_TRUE((back.angle.array() >= 0).all() && (back.angle.array() < kTwoPi).all());
  MatrixX3d bad = dirs;
  bad.row(3) = g.normal.row(3);
  EXPECT_EQ(error_of([&] { field_from_directions(g, bad, 4); }), "the direction of face 3 has no component in the face's plane");
  bad.row(3).setZero();
  EXPECT_EQ(error_of([&] { field_from_directions(g, bad, 4); }), "the direction of face 3 has no component in the face's plane");
  bad.row(3) << 1, std::nan(""), 0;
  EXPECT_EQ(error_of([&] { field_from_directions(g, bad, 4); }), "the direction of face 3 is not finite");
}

TEST(Field, PropagationErrors) {
  const Mesh m = concatenate({make_icosphere(1), make_icosphere(1)});  // 80 + 80 faces
  const FieldDesigner d(m.V, m.F);
  const Topology& t = d.topology();
  const Eigen::VectorXd x = Eigen::VectorXd::Zero(t.num_edges);
  EXPECT_EQ(error_of([&] { propagate_field(t, d.geometry(), x, 1, {{160, 0.0}}); }), "root face 160 out of range (mesh has 160 faces)");
  EXPECT_EQ(error_of([&] { propagate_field(t, d.geometry(), x, 1, {{-1, 0.0}}); }), "root face -1 out of range (mesh has 160 faces)");
  EXPECT_EQ(error_of([&] { propagate_field(t, d.geometry(), x, 1, {{2, INFINITY}}); }), "root angle of face 2 is not finite");
  EXPECT_EQ(error_of([&] { propagate_field(t, d.geometry(), x, 1, {{100, 0.0}, {90, 1.0}}); }), "two root faces given for component 1");
  EXPECT_EQ(error_of([&] { propagate_field(t, d.geometry(), x, 1, {{3, 0.0}, {100, 1.0}}); }), "<no error>");
  const Mesh other = make_icosphere(1);
  const PropagationPlan wrong = plan_propagation(test::topo(other));
  EXPECT_EQ(error_of([&] { propagate_field(t, d.geometry(), wrong, x, 1); }), "the propagation plan was made for another mesh");
}

}  // namespace
}  // namespace trivcon
