// SPDX-License-Identifier: MIT
// The benchmark's edit generator (bench/edits.h) produces valid, changing prescriptions that the solver
// realises. No timing is measured or asserted here.
#include <gtest/gtest.h>

#include <random>
#include <set>

#include "../bench/edits.h"
#include "trivcon/cycles.h"
#include "trivcon/field.h"
#include "trivcon/generate.h"
#include "trivcon/geometry.h"
#include "trivcon/solver.h"
#include "trivcon/topology.h"

namespace trivcon {
namespace {

struct Prepared {
  Mesh mesh;
  Topology topology;
  Geometry geometry;
  Cycles cycles;
  explicit Prepared(Mesh m) : mesh(std::move(m)) {
    topology = build_topology(mesh.F, static_cast<int>(mesh.V.rows()));
    geometry = compute_geometry(mesh.V, topology);
    cycles = compute_cycles(topology);
  }
};

// Every edit: valid for the mesh, singularities at interior vertices, the stated count, and different from the previous one.
void check_edits(const Prepared& p, int N, int count, int expected_singularities, int expected_sum_on_target) {
  const bench::EditGenerator gen(p.topology, N, count);
  EXPECT_EQ(gen.singularities(), expected_singularities);
  std::set<std::map<int, int>> seen;
  for (int i = 0; i < 6; ++i) {
    std::mt19937_64 rng(bench::edit_seed("smoke", i));
    const IndexPrescription e = gen.next(rng);
    EXPECT_EQ(e.N, N);
    EXPECT_EQ(static_cast<int>(e.vertex.size()), expected_singularities);
    int sum_on_target = 0;
    for (auto [v, n] : e.vertex) {
      EXPECT_TRUE(p.topology.is_interior_vertex(v)) << "vertex " << v;
      EXPECT_TRUE(n == 1 || n == -1);
      if (p.topology.vertex_component[v] == gen.target_component()) sum_on_target += n;
    }
    EXPECT_EQ(sum_on_target, expected_sum_on_target);
    EXPECT_NO_THROW(validate_prescription(p.topology, static_cast<int>(p.cycles.generators.size()), e));
    seen.insert(e.vertex);
    // Same seed, same edit.
    std::mt19937_64 again(bench::edit_seed("smoke", i));
    EXPECT_EQ(gen.next(again).vertex, e.vertex);
  }
  EXPECT_EQ(seen.size(), 6u) << "the singularities must move from one edit to the next";
}

TEST(BenchEdits, SphereGetsTheEightQuarterSingularitiesOfACrossField) {
  const Prepared p(make_cube_sphere(6, true));
  check_edits(p, 4, 8, 8, 8);
}

TEST(BenchEdits, TorusGetsBalancedPairs) {
  const Prepared p(make_torus(24, 10));
  check_edits(p, 4, 8, 8, 0);
}

TEST(BenchEdits, GenusTwoSurfaceGetsNegativeIndices) {
  const Prepared p(make_genus_surface(2, 1));
  check_edits(p, 4, 8, 8, -8);
}

TEST(BenchEdits, OddCountIsAdjustedToTheParityOfGaussBonnet) {
  const Prepared p(make_cube_sphere(4, true));
  check_edits(p, 1, 3, 4, 2);  // three +1 and one −1
}

TEST(BenchEdits, BoundaryMeshHasNoSumConstraint) {
  const Prepared p(make_holed_grid(20, 2));
  check_edits(p, 4, 8, 8, 8);
}

TEST(BenchEdits, OtherClosedComponentsGetTheirGaussBonnetShare) {
  // Largest component: the torus (the target); the small sphere needs 2N, the disk nothing.
  const Prepared p(concatenate({make_cube_sphere(2, true), make_torus(30, 12), make_disk(3, 6)}));
  const bench::EditGenerator gen(p.topology, 4, 8);
  EXPECT_EQ(gen.target_component(), 1);
  check_edits(p, 4, 8, 16, 0);
}

TEST(BenchEdits, SolverRealisesTheEdits) {
  const Prepared p(make_torus(40, 16));
  const ConnectionSolver solver(p.topology, p.geometry, p.cycles);
  const bench::EditGenerator gen(p.topology, 4, 8);
  for (int i = 0; i < 3; ++i) {
    std::mt19937_64 rng(bench::edit_seed("smoke-solve", i));
    const IndexPrescription e = gen.next(rng);
    const Connection c = solver.solve(e);
    EXPECT_LT(c.max_vertex_residual, 1e-9);
    EXPECT_LT(c.max_cycle_residual, 1e-9);
    const Field f = propagate_field(p.topology, p.geometry, c.x, e.N);
    const FieldIndices idx = field_indices(p.topology, p.geometry, p.cycles, f);
    for (int v = 0; v < p.topology.num_vertices; ++v) {
      auto it = e.vertex.find(v);
      EXPECT_EQ(idx.vertex[v], it == e.vertex.end() ? 0 : it->second) << "vertex " << v;
    }
  }
}

TEST(BenchEdits, SingularitiesAreNeverNeighbours) {
  const Prepared p(make_torus(40, 16));
  const bench::EditGenerator gen(p.topology, 4, 8);
  for (int i = 0; i < 50; ++i) {
    std::mt19937_64 rng(bench::edit_seed("smoke-apart", i));
    const IndexPrescription e = gen.next(rng);
    for (int edge = 0; edge < p.topology.num_edges; ++edge)
      EXPECT_FALSE(e.vertex.count(p.topology.edge_vertices(edge, 0)) && e.vertex.count(p.topology.edge_vertices(edge, 1)))
          << "edit " << i << ": singularities at both ends of edge " << edge;
  }
}

TEST(BenchEdits, RejectsImpossibleRequests) {
  const Prepared p(make_cube_sphere(1, true));  // 8 vertices: no room for 20 singularities
  EXPECT_THROW(bench::EditGenerator(p.topology, 4, 20), std::invalid_argument);
  EXPECT_THROW(bench::EditGenerator(p.topology, 0, 8), std::invalid_argument);
}

}  // namespace
}  // namespace trivcon
