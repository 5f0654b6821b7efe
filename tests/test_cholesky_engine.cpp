// SPDX-License-Identifier: MIT
// The Cholesky route's two numeric factorizations (SolverOptions::factorization): trivcon's own on
// several threads (src/linalg/supernodal.h) and CHOLMOD's cholmod_factorize give the same connection,
// the same chosen indices and the same energy, on every kind of system (vertex rows only, with cycle
// rows, with fixed-face paths dense and sparse), and fail alike (in a build with TRIVCON_WITH_SUITESPARSE; without
// it, asking for CHOLMOD's is an error, and trivcon's own is checked by the residuals alone); the numeric libraries
// pass the start-up check (src/linalg/numeric_libraries.h).
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "support.h"
#ifdef TRIVCON_WITH_SUITESPARSE
#include "linalg/cholmod.h"
#endif
#include "linalg/numeric_libraries.h"
#include "trivcon/constraints.h"
#include "trivcon/design.h"
#include "trivcon/error.h"
#include "trivcon/generate.h"

using namespace trivcon;

namespace {

struct Case {
  const char* name;
  Mesh mesh;
  int N;
  std::map<int, int> vertex;  // n per vertex (index n/N)
  bool align_boundary;
};

std::vector<Case> cases() {
  std::vector<Case> out;
  out.push_back({"icosphere", make_icosphere(4), 1, {{0, 1}, {5, 1}}, false});
  out.push_back({"cube sphere", make_cube_sphere(8, true), 4, {}, false});
  out.push_back({"genus 3", make_genus_surface(3, 2), 4, {}, false});
  out.push_back({"torus", make_torus(40, 20), 6, {{10, 1}, {400, -1}}, false});
  out.push_back({"holed grid, aligned (dense paths)", make_holed_grid(12, 2), 4, {}, true});
  // The aligned disk needs interior singularities summing to 1 (trivcon/constraints.h): +1 at its centre.
  out.push_back({"disk, aligned (sparse paths)", make_disk(24, 12), 4, {{0, 4}}, true});
  out.push_back({"two components", concatenate({make_icosphere(2), make_annulus(4, 30)}), 2, {}, false});
  return out;
}

// Sings that balance Gauss–Bonnet on closed components (n = N·χ spread as +1s at the first vertices).
void balance(const Topology& t, IndexPrescription& p) {
  for (size_t c = 0; c < t.components.size(); ++c) {
    if (!t.components[c].boundary_loops.empty()) continue;
    int missing = p.N * t.components[c].euler_characteristic;
    for (auto [v, n] : p.vertex)
      if (t.vertex_component[v] == static_cast<int>(c)) missing -= n;
    for (int v = 0; v < t.num_vertices && missing != 0; v += 7) {
      if (t.vertex_component[v] != static_cast<int>(c) || p.vertex.count(v)) continue;
      const int step = missing > 0 ? 1 : -1;
      p.vertex[v] = step, missing -= step;
    }
  }
}

Design solve(const Case& c, Factorization factorization, std::vector<int>* fixed_used = nullptr) {
  SolverOptions options = test::sparse_path_options();  // the aligned disk's paths: the sparse route, tested here too
  options.factorization = factorization;
  FieldDesigner designer(c.mesh.V, c.mesh.F, options);
  IndexPrescription p;
  p.N = c.N;
  p.vertex = c.vertex;
  balance(designer.topology(), p);
  if (c.align_boundary) {
    const std::map<int, double> fixed = boundary_alignment(c.mesh.V, designer.topology(), designer.geometry());
    std::vector<int> faces;
    for (auto [f, angle] : fixed) faces.push_back(f), p.fixed[f] = angle;
    designer.set_fixed_faces(faces);
    if (fixed_used) *fixed_used = faces;
  }
  // The route asked for is the one that ran.
  EXPECT_EQ(designer.solver().timings().numeric_factorization, factorization == Factorization::Cholmod ? "cholmod" : "trivcon");
  return designer.design(p);
}

#ifdef TRIVCON_WITH_SUITESPARSE
TEST(CholeskyEngine, CholmodFactorizationGivesTheSameResults) {
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    std::vector<int> fixed;
    const Design ours = solve(c, Factorization::Parallel, &fixed);
    const Design theirs = solve(c, Factorization::Cholmod);
    if (c.align_boundary) {
      EXPECT_GT(fixed.size(), 0u);
    }
    const double scale = std::max(1.0, ours.connection.x.cwiseAbs().maxCoeff());
    EXPECT_LE((ours.connection.x - theirs.connection.x).cwiseAbs().maxCoeff(), 1e-10 * scale);
    EXPECT_NEAR(ours.connection.energy, theirs.connection.energy, 1e-10 * std::max(1.0, ours.connection.energy));
    EXPECT_EQ(ours.connection.generator_index, theirs.connection.generator_index);
    EXPECT_EQ(ours.connection.loop_index, theirs.connection.loop_index);
    EXPECT_EQ(ours.connection.path_turn, theirs.connection.path_turn);
    EXPECT_EQ(ours.indices.vertex, theirs.indices.vertex);
    for (const Design* d : {&ours, &theirs}) {
      EXPECT_LE(d->connection.max_vertex_residual, 1e-9 * std::max(1.0, d->connection.rhs_scale));
      EXPECT_LE(d->connection.max_cycle_residual, 1e-9 * std::max(1.0, d->connection.rhs_scale));
      EXPECT_TRUE(d->unexplained_mismatch_vertices.empty());
    }
  }
}

#else
// Without CHOLMOD: the route asked for is refused with the reason, and trivcon's own factorization solves every
// kind of system to the verification's accuracy.
TEST(CholeskyEngine, CholmodFactorizationNeedsABuildWithSuiteSparse) {
  const Mesh m = make_icosphere(1);
  SolverOptions options;
  options.factorization = Factorization::Cholmod;
  try {
    FieldDesigner designer(m.V, m.F, options);
    IndexPrescription p;
    p.N = 4;
    designer.design(p);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("-DTRIVCON_WITH_SUITESPARSE=ON"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("GPL"), std::string::npos) << e.what();
  }
}

TEST(CholeskyEngine, OwnFactorizationSolvesEveryKindOfSystem) {
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    const Design d = solve(c, Factorization::Parallel);
    EXPECT_LE(d.connection.max_vertex_residual, 1e-9 * std::max(1.0, d.connection.rhs_scale));
    EXPECT_LE(d.connection.max_cycle_residual, 1e-9 * std::max(1.0, d.connection.rhs_scale));
    EXPECT_TRUE(d.unexplained_mismatch_vertices.empty());
  }
}
#endif

TEST(CholeskyEngine, SparsePathRouteIsTakenOnTheAlignedDisk) {
  // More than max_dense_paths (256 here) fixed-face paths: the route that orders the path rows with the vertex rows.
  const Case c = cases()[5];
  std::vector<int> fixed;
  const Design d = solve(c, Factorization::Parallel, &fixed);
  EXPECT_GT(fixed.size(), 257u);
  EXPECT_EQ(d.connection.path_turn.size(), fixed.size() - 1);
}

#ifdef TRIVCON_WITH_SUITESPARSE
TEST(CholeskyEngine, BothFactorizationsSolveABadlyScaledSystemAlike) {
  // An annulus collapsed onto a line: every triangle has zero area, so every cotangent weight comes from
  // the mollified lengths (trivcon/geometry.h), from about 1/δ on the faces' short sides to 0 where
  // clamped. The factor is then badly scaled; both factorizations must still agree and be exact.
  Mesh flat = make_annulus(2, 12);
  for (int v = 0; v < flat.V.rows(); ++v) flat.V(v, 1) = 0;
  Eigen::VectorXd x[2];
  int k = 0;
  for (Factorization f : {Factorization::Parallel, Factorization::Cholmod}) {
    SolverOptions options;
    options.factorization = f;
    FieldDesigner designer(flat.V, flat.F, options);
    EXPECT_EQ(designer.geometry().mollified_faces, flat.F.rows());
    IndexPrescription p;
    p.N = 4;
    const Design d = designer.design(p);
    EXPECT_LE(d.connection.max_vertex_residual, 1e-9 * std::max(1.0, d.connection.rhs_scale));
    EXPECT_LE(d.connection.max_cycle_residual, 1e-9 * std::max(1.0, d.connection.rhs_scale));
    x[k++] = d.connection.x;
  }
  EXPECT_LE((x[0] - x[1]).cwiseAbs().maxCoeff(), 1e-9 * std::max(1.0, x[0].cwiseAbs().maxCoeff()));
}

#endif

TEST(CholeskyEngine, NumericLibrariesPassTheStartUpCheck) {
  EXPECT_NO_THROW(linalg::check_numeric_libraries());
#ifdef TRIVCON_WITH_SUITESPARSE
  int version[3] = {0, 0, 0};
  cholmod_version(version);
  EXPECT_EQ(version[0], CHOLMOD_MAIN_VERSION);
#endif
}

}  // namespace
