// SPDX-License-Identifier: MIT
// Verification of a connection against every holonomy constraint (trivcon/solver.h verify_connection).
#include <algorithm>
#include <cmath>

#include "linalg/parallel.h"
#include "trivcon/solver.h"

namespace trivcon {

using linalg::kParallelMinEditElements;

void verify_connection(const Topology& t, const Geometry& geometry, const Cycles& cycles, const IndexPrescription& prescription,
                       Connection& connection, const std::vector<double>* loop_curvatures,
                       const std::vector<double>* generator_holonomies) {
  const double step = 2 * kPi / prescription.N;
  const Eigen::VectorXd& x = connection.x;
  connection.max_vertex_residual = connection.max_cycle_residual = 0;
  connection.rhs_scale = 0;
  Eigen::VectorXd rhs_of = geometry.angle_defect;
  for (auto [v, n] : prescription.vertex)
    if (v >= 0 && v < t.num_vertices) rhs_of(v) -= step * n;
  // Per interior vertex (all of its edges are interior), Σ_e s_ve x_e against its right-hand side.
  double rhs_scale = 0, max_residual = 0;
#pragma omp parallel for schedule(static) reduction(max : rhs_scale, max_residual) if (t.num_vertices > kParallelMinEditElements)
  for (int v = 0; v < t.num_vertices; ++v) {
    if (!t.is_interior_vertex(v)) continue;
    double sum = 0;
    for (int k = t.vertex_edge_offsets[v]; k < t.vertex_edge_offsets[v + 1]; ++k) {
      const int e = t.vertex_edges[k];
      sum += t.edge_vertices(e, 1) == v ? x(e) : -x(e);
    }
    const double rhs = rhs_of(v);
    rhs_scale = std::max(rhs_scale, std::abs(rhs));
    max_residual = std::max(max_residual, std::abs(sum - rhs));
  }
  connection.rhs_scale = rhs_scale, connection.max_vertex_residual = max_residual;
  auto check_cycle = [&](const DualCycle& cycle, double holonomy, int n) {
    const double s = cycle_sum(cycle, x);
    const double rhs = holonomy - step * n;
    connection.rhs_scale = std::max(connection.rhs_scale, std::abs(rhs));
    connection.max_cycle_residual = std::max(connection.max_cycle_residual, std::abs(s - rhs));
  };
  for (size_t l = 0; l < cycles.loops.size(); ++l)
    check_cycle(cycles.loops[l], loop_curvatures ? (*loop_curvatures)[l] : loop_curvature(t, geometry, static_cast<int>(l)),
                prescription.loop.at(static_cast<int>(l)));
  for (size_t g = 0; g < cycles.generators.size(); ++g)
    check_cycle(cycles.generators[g],
                generator_holonomies ? (*generator_holonomies)[g] : levi_civita_holonomy(cycles.generators[g], geometry),
                prescription.generator.at(static_cast<int>(g)));
}

}  // namespace trivcon
