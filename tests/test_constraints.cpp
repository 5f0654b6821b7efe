// SPDX-License-Identifier: MIT
// Fixed directions (paper Section 2.8) and boundary alignment: exact at the fixed faces, still exactly the
// prescribed singularities, optimal, and as fast to edit as without constraints.
#include <gtest/gtest.h>

#include <random>

#include <Eigen/Geometry>
#include <cmath>

#include "support.h"
#include "trivcon/constraints.h"
#include "trivcon/design.h"
#include "trivcon/error.h"
#include "trivcon/generate.h"

using namespace trivcon;

namespace {

std::vector<int> keys(const std::map<int, double>& m) {
  std::vector<int> k;
  for (auto [f, a] : m) k.push_back(f);
  return k;
}

// Constraint rows, fixed faces, index read-back.
void expect_exact(const FieldDesigner& d, const Design& r, const IndexPrescription& p, bool indices_from_field = true) {
  const double scale = std::max(1.0, r.connection.rhs_scale);
  EXPECT_LE(r.connection.max_vertex_residual, 1e-9 * scale);
  EXPECT_LE(r.connection.max_cycle_residual, 1e-9 * scale);
  EXPECT_LE(r.transport_mismatch, 1e-9 * scale);
  EXPECT_LE(r.max_fixed_error, 1e-9);
  for (auto [f, angle] : p.fixed) ASSERT_LE(std::abs(reduce_angle(r.field.angle(f) - angle, p.N)), 1e-9) << "face " << f;
  EXPECT_TRUE(r.unexplained_mismatch_vertices.empty());
  if (indices_from_field) {
    for (int v = 0; v < d.topology().num_vertices; ++v) {
      if (!d.topology().is_interior_vertex(v)) continue;
      ASSERT_EQ(r.indices.vertex[v], p.vertex.count(v) ? p.vertex.at(v) : 0) << "vertex " << v;
    }
  }
}

}  // namespace

TEST(Constraints, AlignBoundaryDiskAnnulusHoles) {
  struct Case {
    std::string name;
    Mesh mesh;
    int N;
    std::map<int, int> vertex;  // singularities for the boundary-tangent field
    WeightKind weights;
  };
  const Mesh disk = make_disk(16, 16), annulus = make_annulus(10, 60), holes = make_holed_grid(40, 2);
  std::vector<Case> cases;
  for (int N : {1, 2, 4}) {
    cases.push_back({"disk", disk, N, {{0, N}}, WeightKind::Cotan});  // a tangent field on a disk: +1 at the centre
    cases.push_back({"annulus", annulus, N, {}, WeightKind::Cotan});  // concentric: no singularity
  }
  // A square with two square holes: the tangent cross field needs no singularity.
  cases.push_back({"holes", holes, 4, {}, WeightKind::Cotan});
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name + " N=" + std::to_string(c.N));
    FieldDesigner d(c.mesh.V, c.mesh.F, SolverOptions{c.weights, SolverKind::Cholesky});
    IndexPrescription p;
    p.N = c.N;
    p.vertex = c.vertex;
    p.fixed = boundary_alignment(c.mesh.V, d.topology(), d.geometry());
    int boundary_faces = 0;
    for (int f = 0; f < d.topology().num_faces; ++f)
      for (int k = 0; k < 3; ++k)
        if (d.topology().is_boundary_edge(d.topology().face_edges(f, k))) {
          ++boundary_faces;
          break;
        }
    EXPECT_EQ(static_cast<int>(p.fixed.size()), boundary_faces);
    d.set_fixed_faces(keys(p.fixed));
    const Design r = d.design(p);
    expect_exact(d, r, p);
    EXPECT_LE(test::max_face_optimality(d, r.connection, p.fixed), 1e-9);
    // The field runs along the boundary: at a face with one boundary edge, one of its N directions is that edge.
    const Topology& t = d.topology();
    for (auto [f, angle] : p.fixed) {
      for (int k = 0; k < 3; ++k) {
        if (!t.is_boundary_edge(t.face_edges(f, k))) continue;
        const Eigen::Vector3d edge = (c.mesh.V.row(t.F(f, (k + 1) % 3)) - c.mesh.V.row(t.F(f, k))).normalized();
        const Eigen::Vector3d dir = d.geometry().direction_in_face(f, r.field.angle(f));
        const double a = std::atan2(edge.cross(dir).dot(d.geometry().normal.row(f)), edge.dot(dir));
        EXPECT_LE(std::abs(reduce_angle(a, c.N)), 1e-9) << "face " << f;
        break;
      }
    }
  }
}

// The QR route agrees, with constraints too.
#ifdef TRIVCON_WITH_SUITESPARSE
TEST(Constraints, QrRouteAgrees) {
  const Mesh m = make_annulus(8, 40);
  FieldDesigner chol(m.V, m.F), qr(m.V, m.F, SolverOptions{WeightKind::Cotan, SolverKind::QR});
  IndexPrescription p;
  p.N = 4;
  p.fixed = boundary_alignment(m.V, chol.topology(), chol.geometry());
  p.fixed[100] = 0.3;  // and one interior face
  chol.set_fixed_faces(keys(p.fixed));
  qr.set_fixed_faces(keys(p.fixed));
  const Design a = chol.design(p), b = qr.design(p);
  expect_exact(qr, b, p, false);
  EXPECT_EQ(a.connection.path_turn, b.connection.path_turn);
  EXPECT_LE((a.connection.x - b.connection.x).cwiseAbs().maxCoeff(), 1e-8 * std::max(1.0, a.connection.x.cwiseAbs().maxCoeff()));
}
#endif

// Fixing faces to the directions the unconstrained field already has changes nothing; fixing them to
// other directions never lowers the energy.
TEST(Constraints, FixingTheFieldsOwnDirectionsChangesNothing) {
  for (const Mesh& m : {make_icosphere(3), make_torus(40, 20), make_disk(12, 6)}) {
    FieldDesigner free_designer(m.V, m.F);
    IndexPrescription p;
    p.N = 4;
    if (free_designer.topology().boundary_loops.empty() && free_designer.topology().euler_characteristic() == 2)
      for (int v : {0, 1, 2, 3, 4, 5, 6, 7}) p.vertex[v] = 1;
    const Design free_design = free_designer.design(p);
    IndexPrescription q = p;
    for (int f = 0; f < free_designer.topology().num_faces; f += 37) q.fixed[f] = free_design.field.angle(f) + kPi / 2 * (f % 3);
    FieldDesigner fixed_designer(m.V, m.F);
    fixed_designer.set_fixed_faces(keys(q.fixed));
    const Design same = fixed_designer.design(q);
    expect_exact(fixed_designer, same, q, false);
    EXPECT_NEAR(same.connection.energy, free_design.connection.energy, 1e-9 * std::max(1.0, free_design.connection.energy));
    EXPECT_LE((same.connection.x - free_design.connection.x).cwiseAbs().maxCoeff(), 1e-8);
    for (auto& [f, angle] : q.fixed) angle += 0.4 * std::sin(f);
    const Design other = fixed_designer.design(q);
    expect_exact(fixed_designer, other, q, false);
    EXPECT_GE(other.connection.energy, free_design.connection.energy - 1e-9);
  }
}

// Singularities only change the right-hand side: editing them after fixing faces reuses the factorization.
TEST(Constraints, EditingSingularitiesKeepsTheSetup) {
  const Mesh m = make_icosphere(4);
  FieldDesigner d(m.V, m.F);
  IndexPrescription p;
  p.N = 1;
  for (int f = 0; f < d.topology().num_faces; f += 101) p.fixed[f] = 0.1 * f;
  d.set_fixed_faces(keys(p.fixed));
  const ConnectionSolver* solver = &d.solver();
  for (int edit = 0; edit < 5; ++edit) {
    p.vertex = {{edit * 7, 1}, {edit * 13 + 100, 1}};
    const Design r = d.design(p);
    expect_exact(d, r, p);
    EXPECT_EQ(&d.solver(), solver);
    EXPECT_LE(test::max_face_optimality(d, r.connection, p.fixed), 1e-9);
  }
}

TEST(Constraints, InvariantUnderRenumbering) {
  const Mesh m = make_annulus(8, 40);
  std::vector<int> vperm, fperm;
  const Mesh m2 = permute(m, 3, &vperm, &fperm);
  FieldDesigner d1(m.V, m.F), d2(m2.V, m2.F);
  IndexPrescription p1, p2;
  p1.N = p2.N = 2;
  p1.fixed = boundary_alignment(m.V, d1.topology(), d1.geometry());
  p2.fixed = boundary_alignment(m2.V, d2.topology(), d2.geometry());
  ASSERT_EQ(p1.fixed.size(), p2.fixed.size());
  for (auto [f, a] : p1.fixed) EXPECT_TRUE(p2.fixed.count(fperm[f]));
  d1.set_fixed_faces(keys(p1.fixed));
  d2.set_fixed_faces(keys(p2.fixed));
  const Design r1 = d1.design(p1), r2 = d2.design(p2);
  expect_exact(d2, r2, p2);
  EXPECT_NEAR(r1.connection.energy, r2.connection.energy, 1e-8 * std::max(1.0, r1.connection.energy));
  // The fixed boundary directions leave one optimum: the same x on every edge (by vertex pair, the sign
  // following the edge's i < j order) and the same field in every face, compared as world directions.
  const Eigen::VectorXd x2 = test::edge_values_on_original(d1.topology(), d2.topology(), r2.connection.x, vperm);
  const double scale = std::max(1.0, r1.connection.x.cwiseAbs().maxCoeff());
  EXPECT_LE((r1.connection.x - x2).cwiseAbs().maxCoeff(), 1e-8 * scale);
  EXPECT_GT(r1.connection.x.cwiseAbs().maxCoeff(), 1e-3) << "a connection that is zero would compare trivially";
  EXPECT_LE(test::max_field_difference(d1.geometry(), r1.field, d2.geometry(), r2.field, fperm), 1e-8);
}

TEST(Constraints, ConflictsBetweenAdjacentFixedFacesAreReported) {
  const Mesh m = make_disk(10, 6);
  FieldDesigner d(m.V, m.F);
  const Topology& t = d.topology();
  int e = 0;
  while (t.is_boundary_edge(e)) ++e;
  const int a = t.edge_faces(e, 0), b = t.edge_faces(e, 1);
  IndexPrescription p;
  p.N = 4;
  p.fixed[a] = 0.0;
  p.fixed[b] = d.geometry().rho(e) + kPi / 4;  // 45° off after transport: as far as a cross field can be
  d.set_fixed_faces(keys(p.fixed));
  const Design r = d.design(p);
  expect_exact(d, r, p, false);
  ASSERT_EQ(r.conflicts.size(), 1u);
  EXPECT_EQ(r.conflicts[0].face_a, a);
  EXPECT_EQ(r.conflicts[0].face_b, b);
  EXPECT_NEAR(std::abs(r.conflicts[0].turn), kPi / 4, 1e-9);
}

TEST(Constraints, Errors) {
  const Mesh m = make_disk(4, 6);
  FieldDesigner d(m.V, m.F);
  std::map<int, double> fixed;
  auto message = [&](const std::string& spec) {
    try {
      add_fixed_direction(spec, d.topology(), d.geometry(), fixed);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message("1000:1,0,0"), "--fix 1000:1,0,0: face 1000 out of range (mesh has " + std::to_string(m.F.rows()) + " faces)");
  EXPECT_EQ(message("3:0,0,0"), "--fix 3:0,0,0: fixed direction of face 3 is zero");
  EXPECT_EQ(message("3:0,0,1"), "--fix 3:0,0,1: fixed direction of face 3 is perpendicular to the face: nothing is left after projection");
  EXPECT_EQ(message("3:nan,0,1"), "--fix 3:nan,0,1: number 'nan' is not finite");
  EXPECT_EQ(message("3:1,0"), "--fix 3:1,0: expected 'x y z' or 'angle=A' after the face id");
  EXPECT_EQ(message("3:angle=0.5"), "no error");
  EXPECT_NEAR(fixed.at(3), 0.5, 1e-15);
  EXPECT_EQ(message("3:1,0,0"), "--fix 3:1,0,0: face 3 is fixed twice");
  // A prescription whose fixed faces differ from the set-up.
  IndexPrescription p;
  p.N = 4;
  p.fixed[5] = 0;
  try {
    d.design(p);
    FAIL();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "the fixed faces of the prescription (1) are not those the solver was set up with (0): fixing other faces changes the "
                 "matrix, set up a new solver");
  }
}

// World directions are projected onto the face.
TEST(Constraints, DirectionProjection) {
  const Mesh m = make_icosphere(2);
  FieldDesigner d(m.V, m.F);
  const Geometry& g = d.geometry();
  for (int f : {0, 17, 200}) {
    const Eigen::Vector3d in_plane = g.direction_in_face(f, 1.1);
    EXPECT_NEAR(fixed_angle_from_direction(g, f, in_plane + 5.0 * g.normal.row(f).transpose()), 1.1, 1e-12);
  }
}

// Many fixed faces: the Cholesky route keeps the path rows sparse and rounds their turns from the field
// without them (no ±1 improvement of path turns): exact, with the concentric loop indices, and within
// 1% of the energy of the dense route (QR), which also improves path turns by ±1 steps.
TEST(Constraints, ManyFixedFacesSparseRoute) {
  const Mesh m = make_annulus(12, 200);
  FieldDesigner chol(m.V, m.F);
#ifdef TRIVCON_WITH_SUITESPARSE
  FieldDesigner qr(m.V, m.F, SolverOptions{WeightKind::Cotan, SolverKind::QR});
#endif
  for (int N : {1, 4}) {
    IndexPrescription p;
    p.N = N;
    p.fixed = boundary_alignment(m.V, chol.topology(), chol.geometry());
    ASSERT_GT(p.fixed.size(), 300u);
    chol.set_fixed_faces(keys(p.fixed));
    const Design a = chol.design(p);
    expect_exact(chol, a, p);
    EXPECT_LE(test::max_face_optimality(chol, a.connection, p.fixed), 1e-9);
#ifdef TRIVCON_WITH_SUITESPARSE
    qr.set_fixed_faces(keys(p.fixed));
    const Design b = qr.design(p);
    EXPECT_GE(a.connection.energy, b.connection.energy - 1e-8 * std::max(1.0, b.connection.energy));
    EXPECT_LE(a.connection.energy, 1.01 * b.connection.energy);
    EXPECT_EQ(a.connection.loop_index, b.connection.loop_index);
#endif
    // Concentric: the boundary-tangent field turns once with each circle, so neither loop has a singular
    // turn (indices.h: 0 on both, where a constant field has +1 outside and −1 inside).
    EXPECT_EQ(a.connection.loop_index, (std::vector<int>{0, 0}));
    EXPECT_EQ(a.indices.loop, (std::vector<int>{0, 0}));
  }
}

// The sparse route's path turns (more than 256 paths, docs/solver.md "Fixed-face paths"): a one-edge path between two
// adjacent fixed faces takes the smallest turn, |x_e| ≤ π/N, whatever the sign of the difference between
// their directions (here random, within ±π/N after parallel transport).
TEST(Constraints, SparsePathsTakeTheSmallestTurnEitherWay) {
  const Mesh m = make_disk(24, 12);
  FieldDesigner d(m.V, m.F, test::sparse_path_options());
  std::mt19937 random(7);
  std::uniform_real_distribution<double> angle(-kPi, kPi);
  IndexPrescription p;
  p.N = 4;
  // Every face but those on the boundary: fixed directions all along the boundary would decide the
  // interior singularities' sum (check_aligned_index_sums), which random directions would not meet.
  for (int f = 0; f < m.F.rows(); ++f) {
    bool on_boundary = false;
    for (int k = 0; k < 3; ++k) on_boundary |= d.topology().is_boundary_edge(d.topology().face_edges(f, k));
    const double a = angle(random);
    if (!on_boundary) p.fixed[f] = a;
  }
  ASSERT_GT(p.fixed.size(), 300u);
  d.set_fixed_faces(keys(p.fixed));
  const Design r = d.design(p);
  EXPECT_TRUE(design_verified(r));
  int one_edge = 0;
  for (const FixedPath& path : d.solver().fixed_paths()) {
    if (path.path.edges.size() != 1) continue;
    ++one_edge;
    EXPECT_LE(std::abs(r.connection.x(path.path.edges[0])), kPi / 4 + 1e-9) << "edge " << path.path.edges[0];
  }
  EXPECT_GT(one_edge, 50);
}

// With a path guide (IndexPrescription::path_guide) the sparse route takes each path's whole turns from the
// guide: the connection turns along every path, relative to parallel transport, exactly as the guide does, where
// the guide turns by less than π/N across each edge and holds the fixed directions. Here the guide is a direction
// winding at 6 radians per unit across the disk, every 40th face fixed to it: paths of several edges turn by more
// than π/N, where the smallest turn per path (no guide) takes another. A guide of another size, or with a NaN,
// is refused.
TEST(Constraints, SparsePathsFollowTheirGuide) {
  const Mesh m = make_disk(24, 12);
  SolverOptions options;
  options.max_dense_paths = 0;  // always the sparse route
  FieldDesigner d(m.V, m.F, options);
  const Topology& t = d.topology();
  IndexPrescription p;
  p.N = 4;
  for (int f = 0; f < m.F.rows(); ++f) {
    const Eigen::Vector3d centre = (m.V.row(m.F(f, 0)) + m.V.row(m.F(f, 1)) + m.V.row(m.F(f, 2))).transpose() / 3;
    p.path_guide.push_back(d.geometry().angle_in_face(f, Eigen::Vector3d(std::cos(6 * centre.x()), std::sin(6 * centre.x()), 0)));
    if (f % 40 == 0) p.fixed[f] = p.path_guide.back();
  }
  d.set_fixed_faces(keys(p.fixed));
  ASSERT_TRUE(d.solver().sparse_paths());
  const double step = kPi / 2;
  auto reduced = [step](double a) { return a - step * std::floor(a / step + 0.5); };
  IndexPrescription unguided_prescription = p;
  unguided_prescription.path_guide.clear();
  const Design guided = d.design(p), unguided = d.design(unguided_prescription);
  EXPECT_TRUE(design_verified(guided));
  EXPECT_TRUE(design_verified(unguided));
  EXPECT_EQ(guided.connection.path_turns, Connection::PathTurns::FromTheGuide);
  EXPECT_EQ(unguided.connection.path_turns, Connection::PathTurns::Smallest);
  int long_turns = 0, differ = 0;
  for (const FixedPath& path : d.solver().fixed_paths()) {
    double guide_turn = 0, turn = 0, unguided_turn = 0;
    for (size_t i = 0; i < path.path.edges.size(); ++i) {
      const int e = path.path.edges[i], s = path.path.signs[i];
      const int from = t.edge_faces(e, s > 0 ? 0 : 1), to = t.edge_faces(e, s > 0 ? 1 : 0);
      const double across = p.path_guide[from] + s * d.geometry().rho(e) - p.path_guide[to];
      ASSERT_LT(std::abs(reduced(across)), step / 2 - 0.1);  // the guide is smooth
      guide_turn += reduced(across);
      turn += s * guided.connection.x(e), unguided_turn += s * unguided.connection.x(e);
    }
    EXPECT_NEAR(turn, guide_turn, 1e-9);
    long_turns += std::abs(guide_turn) > step / 2;
    differ += std::abs(unguided_turn - guide_turn) > 1;
  }
  EXPECT_GT(long_turns, 0);  // the case this test is for
  EXPECT_GT(differ, 0);
  IndexPrescription wrong = p;
  wrong.path_guide.pop_back();
  EXPECT_THROW(
      try { d.design(wrong); } catch (const Error& e) {
        EXPECT_TRUE(test::contains(e.what(), "path guide has")) << e.what();
        throw;
      },
      Error);
  wrong = p;
  wrong.path_guide[5] = std::nan("");
  EXPECT_THROW(
      try { d.design(wrong); } catch (const Error& e) {
        EXPECT_TRUE(test::contains(e.what(), "face 5 is not a number")) << e.what();
        throw;
      },
      Error);
}

// Fixed faces walled in by zero-weight edges (here: every edge unusable) are still joined to the others:
// one path per fixed face beyond the first of each component, so every direction is held. Before, the
// regions grew through usable edges only, and a fixed face whose neighbours no region reached was left out.
TEST(Constraints, FixedFacesBehindZeroWeightsAreStillJoined) {
  const Mesh m = make_icosphere(2);
  const Topology t = test::topo(m);
  const std::vector<int> fixed = {0, 57, 123, 200};
  const std::vector<char> none(t.num_edges, 0);
  const std::vector<FixedPath> paths = fixed_face_paths(t, fixed, none);
  ASSERT_EQ(paths.size(), fixed.size() - 1);
  // The paths span the fixed faces (a tree: each joins two of them, and together they connect all).
  std::vector<int> group = {0, 1, 2, 3};
  auto id = [&](int f) { return static_cast<int>(std::find(fixed.begin(), fixed.end(), f) - fixed.begin()); };
  for (const FixedPath& p : paths) {
    const int a = group[id(p.from_face)], b = group[id(p.to_face)];
    EXPECT_NE(a, b);
    for (int& g : group)
      if (g == b) g = a;
    EXPECT_FALSE(p.path.edges.empty());
  }
  EXPECT_TRUE(std::all_of(group.begin(), group.end(), [&](int g) { return g == group[0]; }));
}

// ---------------------------------------------------------------------------------------------
// Boundary alignment decides the loop indices, and with them the sum of the vertex indices.

std::vector<int> fixed_face_list(const std::map<int, double>& fixed) {
  std::vector<int> faces;
  for (const auto& entry : fixed) faces.push_back(entry.first);
  return faces;
}

// The case: a boundary-aligned disk needs interior singularities summing to 1; with none, the
// connection would be exact but turn by 2π/4 across some edges, and the field would read four +1/4.
TEST(AlignedIndexSums, ADiskAlignedWithoutSingularitiesIsRefusedNamingTheSum) {
  const Mesh m = make_disk(30, 120);
  FieldDesigner designer(m.V, m.F);
  IndexPrescription p;
  p.N = 4;
  p.fixed = boundary_alignment(designer.V(), designer.topology(), designer.geometry());
  designer.set_fixed_faces(fixed_face_list(p.fixed));
  const std::vector<AlignedLoop> loops = aligned_loop_indices(designer.topology(), designer.geometry(), p.fixed, 4);
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_EQ(loops[0].index, 0);  // the field turns with the circle: no turning left for the virtual vertex
  EXPECT_EQ(loops[0].ambiguous, 0);
  const std::string message = test::error_of([&] { designer.design(p); });
  EXPECT_EQ(message,
            "component 0 (containing face 0): its fixed boundary directions (boundary alignment) need interior singularities summing to 1 "
            "(Gauss-Bonnet with the boundary's turning, Euler characteristic 1), but the prescription's sum to 0; place singularities "
            "summing to 1 (e.g. 4 of +1/4), or let trivcon place them (--auto; Python singularities=\"auto\"; the editor's auto button)");
  // Four +1/4 at quarter turns of ring 15 (make_disk: ring k starts at vertex 1 + segments·k(k−1)/2, with
  // k·segments vertices): accepted, and the per-face field reads exactly them.
  const int first = 1 + 120 * 15 * 14 / 2;
  for (int k = 0; k < 4; ++k) p.vertex[first + k * 15 * 120 / 4] = 1;
  const Design d = designer.design(p);
  EXPECT_TRUE(design_verified(d));
  EXPECT_EQ(d.large_turn_edges, 0);
  EXPECT_TRUE(d.field_exact);
  // A loop index that Gauss-Bonnet allows but the alignment does not (a constant field's): refused too.
  IndexPrescription wrong;
  wrong.N = 4;
  wrong.fixed = p.fixed;
  wrong.loop[0] = 4;
  EXPECT_EQ(test::error_of([&] { designer.design(wrong); }),
            "boundary loop 0 is given index 1, but the fixed directions along it (boundary alignment) turn with index 0: the field would "
            "turn by 2pi/N or more across edges to reach them; give it 0 or leave it out");
}

// Where the boundary's own turning needs no interior singularity, nothing is refused: a flat annulus and a
// square with two square holes (every corner 90°: a cross turns with it), each exact with none.
TEST(AlignedIndexSums, AnnulusAndHoledSquareNeedNone) {
  for (const Mesh& m : {make_annulus(4, 40), make_holed_grid(12, 2)}) {
    FieldDesigner designer(m.V, m.F);
    IndexPrescription p;
    p.N = 4;
    p.fixed = boundary_alignment(designer.V(), designer.topology(), designer.geometry());
    designer.set_fixed_faces(fixed_face_list(p.fixed));
    const std::vector<AlignedLoop> loops = aligned_loop_indices(designer.topology(), designer.geometry(), p.fixed, 4);
    ASSERT_EQ(loops.size(), designer.topology().boundary_loops.size());
    // The circles' tangent field turns with them (0, 0); on the squares the aligned cross is constant, a
    // constant field's loop indices (+1 outside, −1 per hole). Either way nothing is left for the inside.
    int sum = 0;
    for (const AlignedLoop& a : loops) {
      sum += a.index;
      EXPECT_EQ(a.ambiguous, 0);
    }
    EXPECT_EQ(4 * designer.topology().euler_characteristic() - sum, 0);
    if (loops.size() == 3) {
      EXPECT_EQ(loops[0].index + loops[1].index + loops[2].index, -4);
    }
    if (loops.size() == 2) {
      EXPECT_EQ(loops[0].index, 0);
      EXPECT_EQ(loops[1].index, 0);
    }
    const Design d = designer.design(p);
    EXPECT_TRUE(design_verified(d));
    EXPECT_TRUE(d.field_exact);
    EXPECT_EQ(d.large_turn_edges, 0);
  }
}

// Loops not decided (a boundary face left free) decide nothing: the old behaviour, no error.
TEST(AlignedIndexSums, APartlyFixedBoundaryDecidesNothing) {
  const Mesh m = make_disk(10, 12);
  FieldDesigner designer(m.V, m.F);
  IndexPrescription p;
  p.N = 4;
  p.fixed = boundary_alignment(designer.V(), designer.topology(), designer.geometry());
  p.fixed.erase(p.fixed.begin());
  designer.set_fixed_faces(fixed_face_list(p.fixed));
  EXPECT_TRUE(aligned_loop_indices(designer.topology(), designer.geometry(), p.fixed, 4).empty());
  EXPECT_EQ(test::error_of([&] { designer.design(p); }), "<no error>");
}
