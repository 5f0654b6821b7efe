// SPDX-License-Identifier: MIT
#include "trivcon/design.h"

#include <iomanip>

#include <sstream>

#include <chrono>
#include <algorithm>
#include <cmath>
#include <omp.h>

#include "linalg/parallel.h"
#include "linalg/timing.h"
#include "trivcon/cancel.h"
#include "trivcon/error.h"

namespace trivcon {

using linalg::Clock;
using linalg::seconds_since;

FieldDesigner::FieldDesigner(const MatrixX3d& V, const MatrixX3i& F, SolverOptions options) : V_(V), options_(options) {
  const auto start = Clock::now();
  auto timed = [](double& seconds, auto&& step) {
    const auto t0 = Clock::now();
    step();
    seconds = seconds_since(t0);
  };
  timed(timings_.topology, [&] {
    check_finite(V_);
    topology_ = build_topology(F, static_cast<int>(V_.rows()));
    check_coordinate_range(V_, topology_);
  });
  const CancelFlag cancel = cancel_flag();  // trivcon/cancel.h: polled between the stages, shared with the analysis
  check_cancelled(cancel.get());
  // The cycles and the solver's symbolic analysis depend on the connectivity only: on the Cholesky
  // route a second thread computes them while this one computes the geometry and the plan (design.h).
  const bool concurrent = options_.solver == SolverKind::Cholesky;
  std::promise<void> cycles_done;
  std::future<void> cycles_ready = cycles_done.get_future();
  if (concurrent)
    analysis_ = std::async(std::launch::async, [this, timed, cancel, done = std::move(cycles_done)]() mutable {
      try {
        timed(timings_.cycles, [&] { cycles_ = compute_cycles(topology_); });
      } catch (...) {
        done.set_exception(std::current_exception());
        throw;
      }
      done.set_value();
      const CancelScope scope(cancel);  // the caller's flag, polled in the analysis too
      check_cancelled();
      return SolverAnalysis(topology_, cycles_);
    });
  // With the analysis running, the geometry leaves it a core: on two cores, OpenMP's two threads and the
  // analysis would share them, and the analysis, the longer of the two, would finish later.
  const int threads = concurrent ? std::max(1, linalg::max_threads() - 1) : 0;
  timed(timings_.geometry, [&] { geometry_ = compute_geometry(V_, topology_, threads); });
  check_cancelled(cancel.get());
  if (!concurrent) timed(timings_.cycles, [&] { cycles_ = compute_cycles(topology_); });
  timed(timings_.plan, [&] { plan_ = plan_propagation(topology_); });
  check_cancelled(cancel.get());
  if (concurrent) cycles_ready.get();  // rethrows the thread's error
  construct_seconds_ = seconds_since(start);
  timings_.prepare = construct_seconds_;
}

void FieldDesigner::set_solver_options(const SolverOptions& options) {
  options_ = options;
  solver_.reset();
  solver();
}

void FieldDesigner::set_fixed_faces(const std::vector<int>& faces) {
  fixed_faces_ = faces;
  solver_.reset();
  solver();
}

const ConnectionSolver& FieldDesigner::solver() const {
  if (!solver_) {
    const auto t0 = Clock::now();
    std::function<SolverAnalysis()> analysis;
    if (analysis_.valid() && fixed_faces_.empty())
      analysis = [this] {
        SolverAnalysis a = analysis_.get();
        timings_.analysis = a.seconds();
        return a;
      };
    solver_ = std::make_unique<ConnectionSolver>(topology_, geometry_, cycles_, options_, fixed_faces_, analysis);
    timings_.setup = seconds_since(t0);
    timings_.prepare = construct_seconds_ + timings_.setup;
  }
  return *solver_;
}

Design FieldDesigner::design(const IndexPrescription& prescription, const std::vector<std::pair<int, double>>& roots) const {
  // Fixed boundary directions that need other singularities than those given: refused before the solve
  // (the connection would be exact, the per-face field would read singularities nobody placed).
  check_aligned_index_sums(topology_, geometry_, prescription);
  Design d;
  auto t0 = Clock::now();
  d.connection = solver().solve(prescription);
  d.solve_seconds = seconds_since(t0);
  t0 = Clock::now();
  // Components with fixed faces start at their smallest fixed face, with its direction.
  std::vector<std::pair<int, double>> starts = roots;
  std::vector<char> rooted(topology_.components.size(), 0);
  for (auto [f, angle] : roots)
    if (f >= 0 && f < topology_.num_faces) rooted[topology_.face_component[f]] = 1;
  for (auto [f, angle] : prescription.fixed) {
    const int c = topology_.face_component[f];
    if (rooted[c] == 1)
      throw Error("component " + std::to_string(c) + " has fixed faces: its field starts at fixed face " + std::to_string(f) +
                  ", so it takes no root face");
    if (rooted[c] == 0) starts.emplace_back(f, angle), rooted[c] = 2;
  }
  d.field = propagate_field(topology_, geometry_, plan_, d.connection.x, prescription.N, starts);
  d.field_seconds = seconds_since(t0);
  t0 = Clock::now();
  d.indices = field_indices(topology_, geometry_, cycles_, d.field);
  d.transport_mismatch = max_transport_mismatch(topology_, geometry_, d.connection.x, d.field);
  for (int v = 0; v < topology_.num_vertices; ++v) {
    if (!topology_.is_interior_vertex(v)) continue;
    auto it = prescription.vertex.find(v);
    if (d.indices.vertex[v] != (it == prescription.vertex.end() ? 0 : it->second)) d.index_mismatch_vertices.push_back(v);
  }
  d.field_exact = d.index_mismatch_vertices.empty() && d.indices.generator == d.connection.generator_index &&
                  d.indices.loop == d.connection.loop_index;
  // A turn of exactly ±π/N is ambiguous for the field (both give the same N-direction), hence the margin.
  const double half_period = kPi / prescription.N - 1e-9;
  auto large = [&](int e) { return std::abs(d.connection.x(e)) >= half_period; };
  for (int e = 0; e < topology_.num_edges; ++e) d.large_turn_edges += large(e);
  for (int v : d.index_mismatch_vertices) {
    bool explained = false;
    for (int a = topology_.vertex_edge_offsets[v]; a < topology_.vertex_edge_offsets[v + 1]; ++a)
      explained |= large(topology_.vertex_edges[a]);
    if (!explained) d.unexplained_mismatch_vertices.push_back(v);
  }
  for (auto [f, angle] : prescription.fixed)
    d.max_fixed_error = std::max(d.max_fixed_error, std::abs(reduce_angle(d.field.angle(f) - angle, prescription.N)));
  d.conflicts = fixed_conflicts(topology_, geometry_, prescription.fixed, prescription.N);
  d.verify_seconds = seconds_since(t0);
  return d;
}

bool design_verified(const Design& d, double tolerance) {
  const Connection& c = d.connection;
  const double limit = tolerance * std::max(1.0, c.rhs_scale);
  const double residual = std::max(c.max_vertex_residual, c.max_cycle_residual);
  return residual <= limit && d.transport_mismatch <= limit && d.max_fixed_error <= limit && d.unexplained_mismatch_vertices.empty();
}

std::string verification_failure(const FieldDesigner& designer, const Design& d, double tolerance) {
  if (design_verified(d, tolerance)) return "";
  const Connection& c = d.connection;
  const double limit = tolerance * std::max(1.0, c.rhs_scale);
  const double residual = std::max(c.max_vertex_residual, c.max_cycle_residual);
  std::ostringstream out;
  out << std::setprecision(3);
  std::vector<std::string> parts;
  if (residual > limit) {
    const Geometry& g = designer.geometry();
    std::ostringstream p;
    p << std::setprecision(3) << "the holonomy constraints are met only to " << residual << " (the limit is " << limit << " = " << tolerance
      << " x max(1, right-hand sides " << c.rhs_scale << ")) after " << c.refinements
      << " steps of iterative refinement: the normal equations A W A^T are too ill-conditioned on this mesh (weights from "
      << designer.solver().weights().minCoeff() << " to " << designer.solver().weights().maxCoeff() << "; " << g.mollified_faces
      << " faces mollified, " << g.zero_weight_edges << " edges of zero weight, " << designer.solver().regularized_edges()
#ifdef TRIVCON_WITH_SUITESPARSE
      << " regularized); try --solver qr, which solves the constraints without the normal equations, or --weights unit";
#else  // no QR route in this build (CMakeLists.txt, TRIVCON_WITH_SUITESPARSE)
      << " regularized); try --weights unit";
#endif
    parts.push_back(p.str());
  }
  if (d.transport_mismatch > limit) {
    std::ostringstream p;
    p << std::setprecision(3) << "the field departs from the connection's transport by " << d.transport_mismatch << " rad (limit " << limit
      << ")";
    parts.push_back(p.str());
  }
  if (d.max_fixed_error > limit) {
    std::ostringstream p;
    p << std::setprecision(3) << "a fixed face is off its direction by " << d.max_fixed_error << " rad (limit " << limit << ")";
    parts.push_back(p.str());
  }
  if (!d.unexplained_mismatch_vertices.empty())
    parts.push_back(std::to_string(d.unexplained_mismatch_vertices.size()) + " vertices (first " +
                    std::to_string(d.unexplained_mismatch_vertices[0]) +
                    ") read back an index other than the prescription with no turn of pi/N or more beside them");
  for (size_t k = 0; k < parts.size(); ++k) out << (k ? "; " : "") << parts[k];
  return out.str();
}

}  // namespace trivcon
