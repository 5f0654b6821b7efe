#include "trivcon/design.h"

#include <chrono>
#include <cmath>

namespace trivcon {

namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
}  // namespace

FieldDesigner::FieldDesigner(const MatrixX3d& V, const MatrixX3i& F, SolverOptions options) : V_(V) {
  auto t0 = Clock::now();
  check_finite(V_);
  topology_ = build_topology(F, static_cast<int>(V_.rows()));
  timings_.topology = seconds_since(t0);
  t0 = Clock::now();
  geometry_ = compute_geometry(V_, topology_);
  timings_.geometry = seconds_since(t0);
  t0 = Clock::now();
  cycles_ = compute_cycles(topology_);
  timings_.cycles = seconds_since(t0);
  t0 = Clock::now();
  solver_ = std::make_unique<ConnectionSolver>(topology_, geometry_, cycles_, options);
  timings_.setup = seconds_since(t0);
}

Design FieldDesigner::design(const IndexPrescription& prescription, const std::vector<std::pair<int, double>>& roots) const {
  Design d;
  auto t0 = Clock::now();
  d.connection = solver_->solve(prescription);
  d.solve_seconds = seconds_since(t0);
  t0 = Clock::now();
  d.field = propagate_field(topology_, geometry_, d.connection.x, prescription.N, roots);
  d.field_seconds = seconds_since(t0);
  t0 = Clock::now();
  d.indices = field_indices(topology_, geometry_, cycles_, d.field);
  d.transport_mismatch = max_transport_mismatch(topology_, geometry_, d.connection.x, d.field);
  for (int v = 0; v < topology_.num_vertices; ++v) {
    if (!topology_.is_interior_vertex(v)) continue;
    auto it = prescription.vertex.find(v);
    if (d.indices.vertex[v] != (it == prescription.vertex.end() ? 0 : it->second)) d.index_mismatch_vertices.push_back(v);
  }
  const double half_period = 3.14159265358979323846 / prescription.N;
  for (int e = 0; e < topology_.num_edges; ++e) d.large_turn_edges += std::abs(d.connection.x(e)) >= half_period;
  d.verify_seconds = seconds_since(t0);
  return d;
}

}  // namespace trivcon
