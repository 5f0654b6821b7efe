// SPDX-License-Identifier: MIT
// The trivial-connection solve: exact constraints, no spurious singularities, optimality, agreement of
// the Cholesky and QR routes, invariance under renumbering, and the defects of other implementations
// listed in ../shared/notes/peers.md.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <map>
#include <numeric>
#include <random>

#include "support.h"
#include "trivcon/design.h"
#include "trivcon/error.h"
#include "trivcon/generate.h"
#include "trivcon/io.h"

using namespace trivcon;
using test::vertices_of_valence;

namespace {

// Interior vertices spread over the mesh, deterministic.
std::vector<int> spread_interior_vertices(const Topology& t, int count, int component = -1) {
  std::vector<int> candidates;
  for (int v = 0; v < t.num_vertices; ++v)
    if (t.is_interior_vertex(v) && (component < 0 || t.vertex_component[v] == component)) candidates.push_back(v);
  std::vector<int> out;
  for (int i = 0; i < count; ++i)
    out.push_back(candidates[(static_cast<size_t>(i) * candidates.size()) / count + candidates.size() / (2 * count)]);
  return out;
}

// Singularities of index `n`/N at `count` spread vertices of each closed component so that indices sum to
// N·χ (n = ±1, count = N|χ|).
IndexPrescription gauss_bonnet_prescription(const Topology& t, int N) {
  IndexPrescription p;
  p.N = N;
  for (size_t c = 0; c < t.components.size(); ++c) {
    if (!t.components[c].boundary_loops.empty()) continue;
    const int total = N * t.components[c].euler_characteristic;
    if (total == 0) continue;
    for (int v : spread_interior_vertices(t, std::abs(total), static_cast<int>(c))) p.vertex[v] = total > 0 ? 1 : -1;
  }
  return p;
}

double max_abs(const Eigen::VectorXd& x) { return x.size() ? x.cwiseAbs().maxCoeff() : 0.0; }

// The checks every design must pass.
void expect_exact(const FieldDesigner& d, const Design& r, const IndexPrescription& p, bool expect_field_indices = true) {
  const double scale = std::max(1.0, r.connection.rhs_scale);
  EXPECT_LE(r.connection.max_vertex_residual, 1e-9 * scale);
  EXPECT_LE(r.connection.max_cycle_residual, 1e-9 * scale);
  EXPECT_LE(r.transport_mismatch, 1e-9 * scale);
  EXPECT_LE(r.indices.max_rounding, 1e-6);
  EXPECT_TRUE(r.connection.x.allFinite());
  EXPECT_TRUE(r.field.angle.allFinite());
  EXPECT_TRUE(std::isfinite(r.connection.energy));
  if (expect_field_indices) {
    EXPECT_EQ(r.large_turn_edges, 0) << "the test mesh is too coarse for reading indices from the field";
    EXPECT_TRUE(r.index_mismatch_vertices.empty()) << r.index_mismatch_vertices.size() << " vertices, first "
                                                   << (r.index_mismatch_vertices.empty() ? -1 : r.index_mismatch_vertices[0]);
    // Nonzero indices read from the field: exactly the prescription (no spurious singularity).
    for (int v = 0; v < d.topology().num_vertices; ++v) {
      const int want = p.vertex.count(v) ? p.vertex.at(v) : 0;
      if (d.topology().is_interior_vertex(v)) {
        ASSERT_EQ(r.indices.vertex[v], want) << "vertex " << v;
      }
    }
    for (size_t g = 0; g < r.indices.generator.size(); ++g) EXPECT_EQ(r.indices.generator[g], r.connection.generator_index[g]);
    for (size_t l = 0; l < r.indices.loop.size(); ++l) EXPECT_EQ(r.indices.loop[l], r.connection.loop_index[l]);
  }
}

struct Case {
  std::string name;
  Mesh mesh;
  IndexPrescription prescription;
};

std::vector<Case> generated_cases() {
  std::vector<Case> cases;
  {
    Mesh m = make_icosphere(4);
    IndexPrescription p;  // two +1 poles, N = 1
    p.N = 1;
    p.vertex[0] = 1, p.vertex[3] = 1;
    cases.push_back({"sphere_N1_two_poles", m, p});
    IndexPrescription q;  // N = 6: +1/6 at the 12 valence-5 vertices
    q.N = 6;
    for (int v : vertices_of_valence(m, 5)) q.vertex[v] = 1;
    cases.push_back({"icosphere_N6_twelve", m, q});
    IndexPrescription r;  // N = 3: six +1/3
    r.N = 3;
    for (int v : std::vector<int>{0, 1, 2, 3, 4, 5}) r.vertex[v] = 1;
    cases.push_back({"icosphere_N3_six", m, r});
    IndexPrescription s;  // N = 2: a +1 (two +1/2 merged) and two +1/2
    s.N = 2;
    s.vertex[0] = 2, s.vertex[6] = 1, s.vertex[9] = 1;
    cases.push_back({"icosphere_N2", m, s});
  }
  {
    Mesh m = make_cube_sphere(12, true);
    IndexPrescription p;  // the cube's cross field: +1/4 at the eight corners
    p.N = 4;
    for (int v : vertices_of_valence(m, 3)) p.vertex[v] = 1;
    cases.push_back({"cube_sphere_N4_eight", m, p});
  }
  {
    Mesh m = make_torus(60, 30);
    IndexPrescription p;
    p.N = 4;
    cases.push_back({"torus_N4_none", m, p});
    IndexPrescription q;
    q.N = 1;
    q.vertex[100] = 1, q.vertex[1000] = -1;
    cases.push_back({"torus_N1_pair", m, q});
  }
  {
    Mesh m = subdivide_midpoint(subdivide_midpoint(make_genus_surface(2, 2)));
    FieldDesigner d(m.V, m.F);
    cases.push_back({"genus2_N4", m, gauss_bonnet_prescription(d.topology(), 4)});
  }
  {
    Mesh m = make_disk(16, 6);
    IndexPrescription p;
    p.N = 4;
    cases.push_back({"disk_N4_none", m, p});
    IndexPrescription q;
    q.N = 4;
    q.vertex[0] = 1;  // centre
    cases.push_back({"disk_N4_centre", m, q});
  }
  {
    Mesh m = make_annulus(8, 48);
    IndexPrescription p;
    p.N = 2;
    cases.push_back({"annulus_N2", m, p});
  }
  {
    Mesh m = make_holed_grid(40, 3);
    IndexPrescription p;
    p.N = 4;
    p.vertex[200] = -1;
    cases.push_back({"holed_grid_N4", m, p});
  }
  {
    Mesh m = concatenate({make_icosphere(3), make_torus(40, 20), make_disk(10, 6)});
    FieldDesigner d(m.V, m.F);
    cases.push_back({"three_components_N4", m, gauss_bonnet_prescription(d.topology(), 4)});
  }
  return cases;
}

}  // namespace

TEST(Solver, GeneratedMeshesAreExactAndOptimal) {
  for (const Case& c : generated_cases()) {
    SCOPED_TRACE(c.name);
    FieldDesigner d(c.mesh.V, c.mesh.F);
    for (size_t k = 0; k < d.topology().components.size(); ++k)
      EXPECT_EQ(std::count_if(d.cycles().generators.begin(), d.cycles().generators.end(),
                              [&](const DualCycle& g) { return g.component == static_cast<int>(k); }),
                2 * d.topology().components[k].genus);
    const Design r = d.design(c.prescription);
    expect_exact(d, r, c.prescription);
    EXPECT_LE(test::max_face_optimality(d, r.connection), 1e-9);
  }
}

#ifdef TRIVCON_WITH_SUITESPARSE
TEST(Solver, QrRouteAgreesWithCholesky) {
  for (const Case& c : generated_cases()) {
    SCOPED_TRACE(c.name);
    FieldDesigner chol(c.mesh.V, c.mesh.F);
    FieldDesigner qr(c.mesh.V, c.mesh.F, SolverOptions{WeightKind::Cotan, SolverKind::QR});
    const Design a = chol.design(c.prescription), b = qr.design(c.prescription);
    EXPECT_EQ(a.connection.generator_index, b.connection.generator_index);
    EXPECT_EQ(a.connection.loop_index, b.connection.loop_index);
    EXPECT_LE(max_abs(a.connection.x - b.connection.x), 1e-8 * std::max(1.0, max_abs(a.connection.x)));
    EXPECT_NEAR(a.connection.energy, b.connection.energy, 1e-8 * std::max(1.0, a.connection.energy));
    expect_exact(qr, b, c.prescription);
  }
}
#endif

// The paper's problem (min Σ x_e² / w_e subject to the holonomy rows A x = b) solved from scratch, dense,
// with Eigen's complete orthogonal decomposition (the minimum-norm solution of A W^½ z = b, x = W^½ z):
// an independent check of the Cholesky route that every build runs (the QR route above needs
// SuiteSparse). A is built here from the topology alone (a row per interior vertex: its edges with a sign
// that is consistent around the vertex; a row per generator and per boundary loop: their dual cycles),
// and b = A x of the solver's own x, whose rows expect_exact checks; so a wrong x cannot pass by a wrong
// right-hand side, and the rows' overall signs, and dependent rows (a component's last loop), do not matter.
TEST(Solver, DenseMinimumNormSolutionAgrees) {
  struct Small {
    std::string name;
    Mesh mesh;
    int N;
  };
  const std::vector<Small> meshes = {{"cube_sphere", make_cube_sphere(5, true), 4},
                                     {"torus", make_torus(18, 9), 4},
                                     {"genus2", make_genus_surface(2, 2), 4},
                                     {"grid_two_holes", make_holed_grid(14, 2), 4},
                                     {"annulus_N1", make_annulus(4, 24), 1}};
  for (const Small& m : meshes) {
    SCOPED_TRACE(m.name);
    FieldDesigner d(m.mesh.V, m.mesh.F);
    const Topology& t = d.topology();
    IndexPrescription p = gauss_bonnet_prescription(t, m.N);
    int placed = 0;
    for (int v : spread_interior_vertices(t, 12))
      if (!p.vertex.count(v) && placed < 4) p.vertex[v] = placed++ % 2 ? -1 : 1;
    const Design r = d.design(p);
    expect_exact(d, r, p, /*expect_field_indices=*/false);  // coarse meshes: a few edges turn by π/N or more
    const Eigen::VectorXd& w = d.solver().weights();
    std::vector<int> column(t.num_edges, -1), edge;
    for (int e = 0; e < t.num_edges; ++e)
      if (!t.is_boundary_edge(e) && w(e) > 0) column[e] = static_cast<int>(edge.size()), edge.push_back(e);
    std::vector<std::vector<std::pair<int, double>>> rows;
    for (int v = 0; v < t.num_vertices; ++v) {
      if (!t.is_interior_vertex(v)) continue;
      std::vector<std::pair<int, double>> row;
      for (int k = t.vertex_edge_offsets[v]; k < t.vertex_edge_offsets[v + 1]; ++k) {
        const int e = t.vertex_edges[k];
        if (column[e] >= 0) row.push_back({column[e], t.edge_vertices(e, 0) == v ? -1.0 : 1.0});
      }
      rows.push_back(row);
    }
    for (const auto* cycles : {&d.cycles().generators, &d.cycles().loops})
      for (const DualCycle& c : *cycles) {
        std::vector<std::pair<int, double>> row;
        for (size_t k = 0; k < c.edges.size(); ++k)
          if (column[c.edges[k]] >= 0) row.push_back({column[c.edges[k]], static_cast<double>(c.signs[k])});
        rows.push_back(row);
      }
    const int n = static_cast<int>(edge.size());
    Eigen::MatrixXd AW = Eigen::MatrixXd::Zero(static_cast<int>(rows.size()), n);
    Eigen::VectorXd b = Eigen::VectorXd::Zero(static_cast<int>(rows.size()));
    for (size_t i = 0; i < rows.size(); ++i)
      for (const auto& [j, sign] : rows[i]) {
        AW(static_cast<int>(i), j) += sign * std::sqrt(w(edge[j]));
        b(static_cast<int>(i)) += sign * r.connection.x(edge[j]);
      }
    const Eigen::VectorXd z = Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(AW).solve(b);
    double worst = 0, scale = 1;
    for (int j = 0; j < n; ++j) {
      worst = std::max(worst, std::abs(std::sqrt(w(edge[j])) * z(j) - r.connection.x(edge[j])));
      scale = std::max(scale, std::abs(r.connection.x(edge[j])));
    }
    EXPECT_LE(worst, 1e-9 * scale) << rows.size() << " rows, " << n << " edges";
    EXPECT_LE((AW * z - b).norm(), 1e-9 * std::max(1.0, b.norm()));
  }
}

// An edit that moves a few singularities updates the stored forward substitution along the elimination
// tree only (CholeskyEngine::forward_update); one that changes many rows redoes it. Both must give the
// paper-literal QR solution, with and without cycle rows (sphere; torus: generators; holed grid: loops).
TEST(Solver, SparseAndFullForwardSubstitutionsAgreeWithQr) {
  struct Mesh_ {
    std::string name;
    Mesh mesh;
  };
  const std::vector<Mesh_> meshes = {
      {"cube_sphere", make_cube_sphere(24, true)}, {"torus", make_torus(96, 40)}, {"grid_two_holes", make_holed_grid(60, 2)}};
  for (const Mesh_& m : meshes) {
    SCOPED_TRACE(m.name);
    FieldDesigner chol(m.mesh.V, m.mesh.F);
#ifdef TRIVCON_WITH_SUITESPARSE
    FieldDesigner qr(m.mesh.V, m.mesh.F, SolverOptions{WeightKind::Cotan, SolverKind::QR});
#endif
    const Topology& t = chol.topology();
    int interior = 0;
    for (int v = 0; v < t.num_vertices; ++v) interior += t.is_interior_vertex(v);
    ASSERT_GE(interior, 64 * 8);                // so that 8 singularities take the sparse route, interior / 50 the full one
    for (int count : {1, 4, interior / 100}) {  // the last one changes too many rows: full substitution
      SCOPED_TRACE(count);
      IndexPrescription p = gauss_bonnet_prescription(t, 4);  // the sphere's eight +1/4
      int placed = 0;
      for (int v : spread_interior_vertices(t, 2 * count + 16))
        if (placed < 2 * count && !p.vertex.count(v)) p.vertex[v] = placed++ % 2 ? -1 : 1;
      ASSERT_EQ(placed, 2 * count);
      const Design a = chol.design(p);
      expect_exact(chol, a, p);
      // Without the QR route in the build: the optimality conditions, checked without the factor.
      EXPECT_LE(test::max_face_optimality(chol, a.connection), 1e-9);
#ifdef TRIVCON_WITH_SUITESPARSE
      const Design b = qr.design(p);
      EXPECT_EQ(a.connection.generator_index, b.connection.generator_index);
      EXPECT_EQ(a.connection.loop_index, b.connection.loop_index);
      EXPECT_LE(max_abs(a.connection.x - b.connection.x), 1e-8 * std::max(1.0, max_abs(a.connection.x)));
#endif
    }
  }
}

// FieldDesigner orders and analyses A W Aᵀ on a second thread, from the connectivity and cycles alone
// (SolverAnalysis); the solver adopts that analysis only for the pattern it was made for, and the result
// is the one of a solver that analysed its own system.
TEST(Solver, ConcurrentAnalysisIsAdoptedAndChangesNothing) {
  std::vector<Case> cases = generated_cases();
  {
    // Zero weights (a zero-area face): those edges are explicit zeros of the analysed pattern.
    Mesh m = make_disk(8, 6);
    m.V.row(m.F(5, 2)) = 0.5 * (m.V.row(m.F(5, 0)) + m.V.row(m.F(5, 1)));  // corner 2 of face 5 onto its opposite edge
    IndexPrescription p;
    p.N = 4;
    cases.push_back({"flattened_face", m, p});
  }
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    FieldDesigner d(c.mesh.V, c.mesh.F);
    const Design a = d.design(c.prescription);
    EXPECT_TRUE(d.solver().timings().analysis_adopted);
    EXPECT_GT(d.timings().analysis, 0.0);
    EXPECT_GT(d.timings().prepare, 0.0);
    const ConnectionSolver own(d.topology(), d.geometry(), d.cycles());
    EXPECT_FALSE(own.timings().analysis_adopted);
    if (c.name == "flattened_face") {
      int zero = 0;
      for (int e = 0; e < d.topology().num_edges; ++e) zero += !d.topology().is_boundary_edge(e) && own.weights()(e) == 0;
      EXPECT_GT(zero, 0);
    }
    const Connection b = own.solve(c.prescription);
    EXPECT_EQ(a.connection.generator_index, b.generator_index);
    EXPECT_EQ(a.connection.loop_index, b.loop_index);
    EXPECT_LE(max_abs(a.connection.x - b.x), 1e-10 * std::max(1.0, max_abs(b.x)));
    EXPECT_NEAR(a.connection.energy, b.energy, 1e-10 * std::max(1.0, b.energy));
    expect_exact(d, a, c.prescription, c.name != "flattened_face");
  }
}

TEST(Solver, AnalysisOfAnotherPatternIsNotAdopted) {
  const Mesh m = make_torus(30, 14), other = make_torus(30, 15);
  FieldDesigner d(m.V, m.F);  // topology, geometry, cycles only
  FieldDesigner o(other.V, other.F);
  int calls = 0;
  const ConnectionSolver s(d.topology(), d.geometry(), d.cycles(), {}, {}, [&] {
    ++calls;
    return SolverAnalysis(o.topology(), o.cycles());
  });
  EXPECT_EQ(calls, 1);
  EXPECT_FALSE(s.timings().analysis_adopted);
  IndexPrescription p;
  p.N = 4;
  p.vertex[10] = 1, p.vertex[200] = -1;
  const Connection a = s.solve(p), b = ConnectionSolver(d.topology(), d.geometry(), d.cycles()).solve(p);
  EXPECT_LE(max_abs(a.x - b.x), 1e-12 * std::max(1.0, max_abs(b.x)));
  EXPECT_LE(a.max_vertex_residual, 1e-9);
  // With fixed faces the system has path rows: the analysis is not asked for.
  calls = 0;
  const ConnectionSolver f(d.topology(), d.geometry(), d.cycles(), {}, {3, 300}, [&] {
    ++calls;
    return SolverAnalysis(d.topology(), d.cycles());
  });
  EXPECT_EQ(calls, 0);
  EXPECT_FALSE(f.timings().analysis_adopted);
}

TEST(Solver, UnitWeightsAreExact) {
  for (const Case& c : generated_cases()) {
    SCOPED_TRACE(c.name);
    FieldDesigner d(c.mesh.V, c.mesh.F, SolverOptions{WeightKind::Unit, SolverKind::Cholesky});
    const Design r = d.design(c.prescription);
    expect_exact(d, r, c.prescription, false);
    EXPECT_NEAR(r.connection.energy, r.connection.x.squaredNorm(), 1e-9 * std::max(1.0, r.connection.energy));
    EXPECT_LE(test::max_face_optimality(d, r.connection), 1e-9);
  }
}

// SolverOptions::weight_floor: every interior edge gets at least floor × the median positive cotan weight,
// the others keep theirs, the solve stays exact and optimal for those weights; a well-shaped mesh (no
// weight below the floor) is not changed at all.
TEST(Solver, WeightFloorRaisesOnlyTheLightEdges) {
  for (const Case& c : generated_cases()) {
    SCOPED_TRACE(c.name);
    FieldDesigner plain(c.mesh.V, c.mesh.F);
    const double floor = 0.2;
    FieldDesigner floored(c.mesh.V, c.mesh.F, SolverOptions{WeightKind::Cotan, SolverKind::Cholesky, Factorization::Parallel, floor});
    const Eigen::VectorXd& w0 = plain.solver().weights();
    const Eigen::VectorXd& w1 = floored.solver().weights();
    std::vector<double> positive;
    for (int e = 0; e < w0.size(); ++e)
      if (w0(e) > 0) positive.push_back(w0(e));
    std::sort(positive.begin(), positive.end());
    const double least = floor * positive[positive.size() / 2];
    int raised = 0;
    for (int e = 0; e < w0.size(); ++e) {
      if (plain.topology().is_boundary_edge(e)) {
        EXPECT_EQ(w1(e), 0.0);
        continue;
      }
      if (w0(e) < least) {
        EXPECT_DOUBLE_EQ(w1(e), least) << e;
        ++raised;
      } else {
        EXPECT_EQ(w1(e), w0(e)) << e;
      }
    }
    EXPECT_EQ(floored.solver().floored_edges(), raised);
    const Design r = floored.design(c.prescription);
    expect_exact(floored, r, c.prescription, false);
    EXPECT_LE(test::max_face_optimality(floored, r.connection), 1e-9);
    if (raised == 0) {
      EXPECT_NEAR(r.connection.energy, plain.design(c.prescription).connection.energy, 1e-12 * std::max(1.0, r.connection.energy));
    }
  }
  const Mesh m = make_icosphere(3);
  EXPECT_THROW(FieldDesigner(m.V, m.F, SolverOptions{WeightKind::Cotan, SolverKind::Cholesky, Factorization::Parallel, 1.5}).solver(), Error);
}

// The index n (units of 1/N) connection x gives a cycle of Levi-Civita holonomy z: Σ c x = z − 2π n/N.
double cycle_index(const DualCycle& c, const Eigen::VectorXd& x, double holonomy, int N) {
  double sum = 0;
  for (size_t k = 0; k < c.edges.size(); ++k) sum += c.signs[k] * x(c.edges[k]);
  return (holonomy - sum) * N / (2 * kPi);
}

// peers.md 1: results must not depend on vertex or face order. Generators follow the ids, so the two runs
// choose indices on different cycles; the renumbered run's connection, carried back to the original
// edges, is measured on the original's cycles. Where it has the indices the original run chose, the
// optimum is unique and the connections agree on every edge. Elsewhere the optimum is a tie between
// lattice points (here only torus_N1_pair, a ± pair on a torus): the same energy, and the original mesh
// solved with those indices prescribed gives the renumbered run's connection.
TEST(Solver, InvariantUnderRenumbering) {
  int ties = 0;
  for (const Case& c : generated_cases()) {
    SCOPED_TRACE(c.name);
    std::vector<int> vperm, fperm;
    const Mesh m2 = permute(c.mesh, 7, &vperm, &fperm);
    IndexPrescription p2 = c.prescription;
    p2.vertex.clear();
    for (auto [v, n] : c.prescription.vertex) p2.vertex[vperm[v]] = n;
    FieldDesigner d1(c.mesh.V, c.mesh.F), d2(m2.V, m2.F);
    const Design r1 = d1.design(c.prescription), r2 = d2.design(p2);
    expect_exact(d2, r2, p2);
    EXPECT_NEAR(r1.connection.energy, r2.connection.energy, 1e-8 * std::max(1.0, r1.connection.energy));
    const Eigen::VectorXd x2 = test::edge_values_on_original(d1.topology(), d2.topology(), r2.connection.x, vperm);
    const int N = c.prescription.N;
    IndexPrescription same = c.prescription;  // the original's prescription with x2's cycle indices
    bool tie = false;
    for (size_t g = 0; g < d1.cycles().generators.size(); ++g) {
      const double n = cycle_index(d1.cycles().generators[g], x2, d1.solver().generator_holonomies()[g], N);
      ASSERT_NEAR(n, std::round(n), 1e-6) << "generator " << g;
      same.generator[static_cast<int>(g)] = static_cast<int>(std::round(n));
      tie |= same.generator[static_cast<int>(g)] != r1.connection.generator_index[g];
    }
    for (size_t l = 0; l < d1.cycles().loops.size(); ++l) {
      const double n = cycle_index(d1.cycles().loops[l], x2, d1.solver().loop_curvatures()[l], N);
      ASSERT_NEAR(n, std::round(n), 1e-6) << "loop " << l;
      same.loop[static_cast<int>(l)] = static_cast<int>(std::round(n));
      tie |= same.loop[static_cast<int>(l)] != r1.connection.loop_index[l];
    }
    Connection reference = r1.connection;
    if (tie) {
      ++ties;
      reference = d1.design(same).connection;
      EXPECT_NEAR(reference.energy, r1.connection.energy, 1e-8 * std::max(1.0, r1.connection.energy)) << "not a tie";
    }
    EXPECT_LE(max_abs(reference.x - x2), 1e-8 * std::max(1.0, max_abs(reference.x))) << (tie ? "tie" : "unique optimum");
  }
  RecordProperty("ties", ties);
  EXPECT_LE(ties, 1) << "the cases with generators and loops should mostly have a unique optimum";
}

// The chosen generator indices are a local optimum on the lattice: moving any one by ±1/N costs energy.
TEST(Solver, ChosenCycleIndicesAreLocallyOptimal) {
  const Mesh m = subdivide_midpoint(make_genus_surface(2, 2));
  FieldDesigner d(m.V, m.F);
  const IndexPrescription p = gauss_bonnet_prescription(d.topology(), 4);
  const Design best = d.design(p);
  ASSERT_EQ(best.connection.generator_index.size(), 4u);
  for (int g = 0; g < 4; ++g) {
    for (int step : {-1, 1}) {
      IndexPrescription q = p;
      for (int h = 0; h < 4; ++h) q.generator[h] = best.connection.generator_index[h];
      q.generator[g] += step;
      const Design other = d.design(q);
      expect_exact(d, other, q, false);
      EXPECT_GT(other.connection.energy, best.connection.energy - 1e-9);
      EXPECT_EQ(other.connection.generator_index[g], q.generator[g]);
    }
  }
}

// The energy alone (ConnectionSolver::energy, the forward half of a solve) equals the solve's energy: with
// generators chosen and prescribed, with fixed-face paths in the dense block and among the vertex rows (the
// sparse route), and on a sphere with a singularity of large index.
TEST(Solver, EnergyAloneEqualsTheSolvesEnergy) {
  auto expect_same = [](const FieldDesigner& d, const IndexPrescription& p) {
    const double solved = d.solver().solve(p).energy, alone = d.solver().energy(p);
    EXPECT_NEAR(alone, solved, 1e-10 * std::max(1.0, solved));
  };
  {  // genus 2: generator indices chosen, then one prescribed
    const Mesh m = subdivide_midpoint(make_genus_surface(2, 2));
    FieldDesigner d(m.V, m.F);
    IndexPrescription p = gauss_bonnet_prescription(d.topology(), 4);
    expect_same(d, p);
    p.generator[1] = 3;
    expect_same(d, p);
  }
  {  // a sphere: +1 and a +1/4 spread
    const Mesh m = make_icosphere(3);
    FieldDesigner d(m.V, m.F);
    IndexPrescription p;
    p.N = 4;
    const std::vector<int> v = spread_interior_vertices(d.topology(), 5);
    p.vertex = {{v[0], 4}, {v[1], 1}, {v[2], 1}, {v[3], 1}, {v[4], 1}};
    expect_same(d, p);
  }
  for (bool sparse : {false, true}) {  // an aligned disk: fixed-face paths, dense and among the vertex rows
    const Mesh m = make_disk(50, 6);
    FieldDesigner d(m.V, m.F, sparse ? test::sparse_path_options() : SolverOptions{});
    IndexPrescription p = test::aligned_cross_field(d, m);
    p.vertex = {{0, 1}, {100, 1}, {500, 1}, {2000, 1}};
    expect_same(d, p);
    p.vertex = {{0, 1}, {101, 1}, {500, 1}, {2000, 1}, {300, 1}, {800, -1}};
    expect_same(d, p);
  }
}

// Prescribed generator turning: the field spins k times along the generator.
TEST(Solver, PrescribedGeneratorIndexIsRealised) {
  const Mesh m = make_torus(80, 40);
  FieldDesigner d(m.V, m.F);
  for (int k : {0, 1, 2, -1}) {
    IndexPrescription p;
    p.N = 4;
    p.generator[0] = 4 * k;
    p.generator[1] = 1;
    const Design r = d.design(p);
    expect_exact(d, r, p, false);
    EXPECT_EQ(r.connection.generator_index[0], 4 * k);
    EXPECT_EQ(r.connection.generator_index[1], 1);
    EXPECT_EQ(r.indices.generator[0], 4 * k);
    EXPECT_EQ(r.indices.generator[1], 1);
    EXPECT_FALSE(r.connection.generator_chosen[0]);
  }
}

// Boundary loops: a prescribed loop index is realised; the dropped loop takes the remainder.
TEST(Solver, PrescribedLoopIndices) {
  const Mesh m = make_holed_grid(40, 2);
  FieldDesigner d(m.V, m.F);
  const int loops = static_cast<int>(d.topology().boundary_loops.size());
  ASSERT_EQ(loops, 3);
  for (int l = 0; l < loops; ++l) {
    IndexPrescription p;
    p.N = 4;
    p.loop[l] = 2;  // +1/2
    const Design r = d.design(p);
    expect_exact(d, r, p, false);
    EXPECT_EQ(r.connection.loop_index[l], 2);
    EXPECT_EQ(r.indices.loop[l], 2);
    EXPECT_EQ(std::accumulate(r.connection.loop_index.begin(), r.connection.loop_index.end(), 0), 4 * d.topology().euler_characteristic());
  }
  IndexPrescription all;  // all loops prescribed consistently
  all.N = 1;
  all.loop[0] = 1, all.loop[1] = -1, all.loop[2] = -1;
  expect_exact(d, d.design(all), all, false);
  all.loop[2] = 0;  // inconsistent
  try {
    d.design(all);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "the indices on component 0 (vertices and boundary loops) sum to 0, but Gauss-Bonnet needs its Euler characteristic -1");
  }
}

// Figure 20 of the paper: index +20 on a coarse sphere. The connection carries it exactly; a field
// sampled once per face cannot show turns above π/N across an edge, and the design says so.
TEST(Solver, LargeIndexOnCoarseSphere) {
  const Mesh m = make_icosphere(1);
  FieldDesigner d(m.V, m.F);
  IndexPrescription p;
  p.N = 1;
  p.vertex[0] = 20, p.vertex[11] = -18;
  const Design r = d.design(p);
  expect_exact(d, r, p, false);
  const Topology& t = d.topology();
  for (int v : {0, 11}) {  // the connection's own index: (K_v − Σ s x) / 2π
    double sum = 0;
    for (int a = t.vertex_edge_offsets[v]; a < t.vertex_edge_offsets[v + 1]; ++a) {
      const int e = t.vertex_edges[a];
      sum += (t.edge_vertices(e, 1) == v ? 1 : -1) * r.connection.x(e);
    }
    EXPECT_NEAR((d.geometry().angle_defect(v) - sum) / (2 * kPi), p.vertex[v], 1e-9);
  }
  EXPECT_GT(r.large_turn_edges, 0);
  for (int v : r.index_mismatch_vertices) {
    bool large = false;
    for (int a = t.vertex_edge_offsets[v]; a < t.vertex_edge_offsets[v + 1]; ++a)
      large |= std::abs(r.connection.x(t.vertex_edges[a])) >= kPi;
    EXPECT_TRUE(large) << "vertex " << v;
  }
}

// peers.md 3: boundary loops whose triangles have all three corners on the boundary ("ears").
TEST(Solver, EarTrianglesOnCurvedBoundary) {
  // A spherical cap (non-flat, so curvature matters) whose rim has ear triangles: the first ring of a
  // disk is cut away at every other spoke.
  Mesh m = make_disk(6, 5);
  for (int v = 0; v < m.V.rows(); ++v) {
    const double r2 = m.V.row(v).head<2>().squaredNorm();
    m.V(v, 2) = std::sqrt(std::max(0.0, 2.0 - r2));  // on the sphere of radius √2
  }
  // Add an ear on every boundary edge: a new vertex outside, a triangle with three boundary corners
  // after the next ear is added? Instead: cut off corner triangles by adding an outer triangle fan whose
  // triangles each have all corners on the new boundary.
  FieldDesigner base(m.V, m.F);
  const std::vector<int> loop = base.topology().boundary_loops[0];
  std::vector<Eigen::Vector3d> extra;
  std::vector<Eigen::Vector3i> faces;
  for (size_t i = 0; i + 1 < loop.size(); i += 2) {
    // New vertex beyond the boundary edge (loop[i], loop[i+1]); triangle (loop[i], new, loop[i+1])
    // follows the loop direction reversed so that orientation agrees with the mesh.
    const Eigen::Vector3d a = m.V.row(loop[i]), b = m.V.row(loop[i + 1]);
    Eigen::Vector3d mid = 0.5 * (a + b);
    mid = mid * 1.08;
    extra.push_back(mid);
    faces.emplace_back(loop[i + 1], loop[i], static_cast<int>(m.V.rows() + extra.size() - 1));
  }
  Mesh ears;
  ears.V.resize(m.V.rows() + static_cast<int>(extra.size()), 3);
  ears.V.topRows(m.V.rows()) = m.V;
  for (size_t i = 0; i < extra.size(); ++i) ears.V.row(m.V.rows() + i) = extra[i];
  ears.F.resize(m.F.rows() + static_cast<int>(faces.size()), 3);
  ears.F.topRows(m.F.rows()) = m.F;
  for (size_t i = 0; i < faces.size(); ++i) ears.F.row(m.F.rows() + i) = faces[i];
  FieldDesigner d(ears.V, ears.F);
  ASSERT_EQ(d.topology().flipped_faces.size(), 0u) << "test mesh orientation";
  ASSERT_EQ(d.topology().boundary_loops.size(), 1u);
  int ear_count = 0;
  for (int f = 0; f < d.topology().num_faces; ++f)
    ear_count += d.topology().is_boundary_vertex(d.topology().F(f, 0)) && d.topology().is_boundary_vertex(d.topology().F(f, 1)) &&
                 d.topology().is_boundary_vertex(d.topology().F(f, 2));
  EXPECT_GE(ear_count, static_cast<int>(faces.size()));
  // Gauss–Bonnet with the loop's curvature, ears included.
  double total = loop_curvature(d.topology(), d.geometry(), 0);
  for (int v = 0; v < d.topology().num_vertices; ++v)
    if (d.topology().is_interior_vertex(v)) total += d.geometry().angle_defect(v);
  EXPECT_NEAR(total, 2 * kPi, 1e-9);
  IndexPrescription p;
  p.N = 4;
  p.vertex[0] = 1;
  const Design r = d.design(p);
  expect_exact(d, r, p);
  EXPECT_EQ(r.connection.loop_index[0], 3);  // χ = 1: 4/4 − 1/4
}

// peers.md 9: zero-area faces give no NaN or infinite weight, and the solve stays exact.
TEST(Solver, ZeroAreaFace) {
  Mesh m = make_disk(8, 6);
  FieldDesigner base(m.V, m.F);
  const Topology& t = base.topology();
  // An interior edge (b, c) with faces (a, b, c) and (c, b, e): split (c, b, e) into a zero-area face
  // (c, b, d), d the midpoint of bc, and the faces (d, b, e), (c, d, e).
  int edge = -1;
  for (int e = 0; e < t.num_edges && edge < 0; ++e)
    if (!t.is_boundary_edge(e) && t.is_interior_vertex(t.edge_vertices(e, 0)) && t.is_interior_vertex(t.edge_vertices(e, 1))) edge = e;
  ASSERT_GE(edge, 0);
  const int R = t.edge_faces(edge, 1);
  int k = 0;
  while (t.face_edges(R, k) != edge) ++k;
  const int c = t.F(R, k), b = t.F(R, (k + 1) % 3), e_ = t.F(R, (k + 2) % 3);
  Mesh z;
  z.V.resize(m.V.rows() + 1, 3);
  z.V.topRows(m.V.rows()) = m.V;
  const int d_id = static_cast<int>(m.V.rows());
  z.V.row(d_id) = 0.5 * (m.V.row(b) + m.V.row(c));
  z.F.resize(m.F.rows() + 2, 3);
  z.F.topRows(m.F.rows()) = t.F;
  z.F.row(R) << c, b, d_id;
  z.F.row(m.F.rows()) << d_id, b, e_;
  z.F.row(m.F.rows() + 1) << c, d_id, e_;
  FieldDesigner d(z.V, z.F);
  EXPECT_EQ(d.geometry().zero_area_faces, 1);
  EXPECT_TRUE(d.geometry().cotan_weight.allFinite());
  EXPECT_TRUE(d.geometry().rho.allFinite());
  EXPECT_NEAR(d.geometry().angle_defect(d_id), 0.0, 1e-12);
  IndexPrescription p;
  p.N = 4;
  p.vertex[d_id] = 1;
  const Design r = d.design(p);
  expect_exact(d, r, p, false);
  EXPECT_TRUE(field_directions(d.geometry(), r.field).allFinite());
}

// peers.md 7: every component is solved and anchored, with its own root.
TEST(Solver, EveryComponentSolvedAndAnchored) {
  const Mesh m = concatenate({make_icosphere(3), make_icosphere(3), make_torus(30, 15)});
  FieldDesigner d(m.V, m.F);
  ASSERT_EQ(d.topology().components.size(), 3u);
  IndexPrescription p = gauss_bonnet_prescription(d.topology(), 1);
  const int root1 = d.topology().components[1].first_face + 5;
  const Design r = d.design(p, {{root1, 0.7}});
  expect_exact(d, r, p);
  EXPECT_NEAR(r.field.angle(root1), 0.7, 1e-12);
  EXPECT_NEAR(r.field.angle(d.topology().components[0].first_face), 0.0, 1e-12);
  EXPECT_NEAR(r.field.angle(d.topology().components[2].first_face), 0.0, 1e-12);
  // Gauss–Bonnet is checked per closed component.
  p.vertex.erase(p.vertex.begin());
  p.vertex[spread_interior_vertices(d.topology(), 1, 1)[0] + 1] = 1;  // moves one unit to component 1
  EXPECT_THROW(d.design(p), Error);
}

TEST(Solver, PrescriptionErrors) {
  const Mesh disk = make_disk(6, 6);
  FieldDesigner d(disk.V, disk.F);
  auto message = [&](const IndexPrescription& p) {
    try {
      d.design(p);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  IndexPrescription p;
  p.N = 4;
  p.vertex[d.topology().boundary_loops[0][0]] = 1;
  EXPECT_EQ(message(p), "singular vertex " + std::to_string(d.topology().boundary_loops[0][0]) +
                            " is on boundary loop 0: a boundary vertex has no dual cycle (set the loop's index with --boundary instead)");
  p.vertex.clear();
  p.vertex[100000] = 1;
  EXPECT_EQ(message(p), "singular vertex 100000 out of range (mesh has " + std::to_string(disk.V.rows()) + " vertices)");
  p.vertex.clear();
  p.generator[0] = 1;
  EXPECT_EQ(message(p), "generator 0 out of range (the mesh has 0 generators)");
  const Mesh sphere = make_icosphere(2);
  FieldDesigner s(sphere.V, sphere.F);
  IndexPrescription q;
  q.N = 4;
  q.vertex[0] = 1;
  try {
    s.design(q);
    FAIL();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "the indices on component 0 sum to 1/4, but Gauss-Bonnet needs its Euler characteristic 2");
  }
}

// Every valid shared mesh: N = 4 with singularities summing to χ on closed components.
TEST(Solver, SharedMeshes) {
  TRIVCON_REQUIRE_SHARED();
  for (const std::string name :
       {"spot.obj",      "bunny_closed.obj", "torus.obj",  "kitten.off",          "bob_small.ply", "rocker-arm.obj", "eight.off",
        "fertility.off", "Input_wheel.off",  "cheese.off", "bun_zipper.ply",      "face.obj",      "camelhead.off",  "half-torus.obj",
        "circle.obj",    "capsule.obj",      "bones.off",  "blobby-shuffled.off", "armadillo.obj", "dragon_vrip.ply"}) {
    SCOPED_TRACE(name);
    const MeshData mesh = read_mesh(test::shared_mesh(name));
    FieldDesigner d(mesh.V, mesh.F);
    const IndexPrescription p = gauss_bonnet_prescription(d.topology(), 4);
    const Design r = d.design(p);
    expect_exact(d, r, p, false);
    EXPECT_LE(test::max_face_optimality(d, r.connection), 1e-8);
    // Index mismatches only where the connection turns by π/N or more next to the vertex.
    EXPECT_TRUE(r.unexplained_mismatch_vertices.empty());
#ifdef TRIVCON_WITH_SUITESPARSE
    if (mesh.F.rows() <= 25000) {
      FieldDesigner qr(mesh.V, mesh.F, SolverOptions{WeightKind::Cotan, SolverKind::QR});
      const Design b = qr.design(p);
      EXPECT_LE(max_abs(r.connection.x - b.connection.x), 1e-8 * std::max(1.0, max_abs(r.connection.x)));
    }
#endif
  }
}

// A vertex surrounded only by zero-area faces (as midpoint subdivision makes of the dragon's coincident
// vertices): the mollified lengths (trivcon/geometry.h) give its edges positive weights, so nothing needs
// the small regularization weight, and the solve stays exact.
TEST(Solver, VertexSurroundedByZeroAreaFaces) {
  Mesh m = make_disk(8, 6);
  FieldDesigner base(m.V, m.F);
  int face = 0;  // an interior face whose corners are all interior vertices
  while (!(base.topology().is_interior_vertex(m.F(face, 0)) && base.topology().is_interior_vertex(m.F(face, 1)) &&
           base.topology().is_interior_vertex(m.F(face, 2))))
    ++face;
  for (int k = 1; k < 3; ++k) m.V.row(m.F(face, k)) = m.V.row(m.F(face, 0));  // collapse it to a point
  const Mesh sub = subdivide_midpoint(m);
  FieldDesigner d(sub.V, sub.F);
  EXPECT_GT(d.geometry().zero_area_faces, 0);
  IndexPrescription p;
  p.N = 4;
  p.vertex[0] = 1;
  const Design r = d.design(p);
  EXPECT_GT(d.geometry().mollified_faces, 0);
  EXPECT_EQ(d.solver().regularized_edges(), 0);
  const double scale = std::max(1.0, r.connection.rhs_scale);
  EXPECT_LE(r.connection.max_vertex_residual, 1e-9 * scale);
  EXPECT_LE(r.transport_mismatch, 1e-9 * scale);
  EXPECT_TRUE(r.connection.x.allFinite());
  EXPECT_TRUE(field_directions(d.geometry(), r.field).allFinite());
}
