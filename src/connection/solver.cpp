// SPDX-License-Identifier: MIT
// The trivial connection closest to Levi-Civita (trivcon/solver.h): the constraint rows, the weights and
// their regularization, the right-hand sides of a prescription, the choice of free indices, and the
// result. The factorizations are src/connection/cholesky_engine.h and qr_engine.h, the matrices
// src/connection/assembly.h, the rounding src/connection/generator_rounding.h; verify_connection is in verify.cpp.
#include "trivcon/solver.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "connection/assembly.h"
#include "connection/cholesky_engine.h"
#include "connection/generator_rounding.h"
#include "linalg/parallel.h"
#include "connection/qr_engine.h"
#include "connection/solver_engine.h"
#include "linalg/timing.h"
#include "trivcon/error.h"

namespace trivcon {

namespace {
// Iterative refinement (see ConnectionSolver::solve): when the largest constraint residual exceeds this
// (relative to max(1, the right-hand sides' scale): a quarter of what verification accepts), up to this many
// steps. Not lower: one substitution's round-off alone grows with the mesh to the order of this limit, and
// a step costs as much as a whole edit and cannot do better (BENCHMARKS.md, "Exact on slivers").
constexpr double kRefineAbove = 2.5e-10;
constexpr int kMaxRefinements = 3;
using linalg::Clock;
using linalg::kParallelMinEditElements;
using linalg::seconds_since;
using connection::SparseMatrix;
using Triplet = Eigen::Triplet<double>;
}  // namespace

SolverAnalysis::SolverAnalysis(const Topology& t, const Cycles& cycles) : state_(std::make_unique<connection::AnalysisState>()) {
  const auto t0 = Clock::now();
  const connection::RowLayout layout = connection::row_layout(t);
  std::vector<int> edges, column;
  connection::system_edges(t, nullptr, edges, column);
  std::vector<const DualCycle*> rows;
  for (int l : connection::loop_rows(t, layout.dropped_loop)) rows.push_back(&cycles.loops[l]);
  for (const DualCycle& g : cycles.generators) rows.push_back(&g);
  const int m = static_cast<int>(edges.size());
  const SparseMatrix Ct =
      connection::cycle_columns(m, column, static_cast<int>(rows.size()), [&](int r) -> const DualCycle& { return *rows[r]; });
  connection::EdgeRows edge_rows;
  connection::Csc M = connection::normal_matrix(connection::edge_ends(t, edges, layout.vertex_row), layout.num_vertex_rows, SparseMatrix(m, 0), Ct,
                                        Eigen::VectorXd::Ones(m), edge_rows);
  connection::AnalysisState& a = *state_;
  a.nD = layout.num_vertex_rows, a.nC = static_cast<int>(rows.size());
  connection::analyse(M, a.nD, a.nC, a);
  a.outer = std::move(M.outer), a.inner = std::move(M.inner);
  a.seconds = seconds_since(t0);
}
SolverAnalysis::~SolverAnalysis() = default;
SolverAnalysis::SolverAnalysis(SolverAnalysis&&) noexcept = default;
SolverAnalysis& SolverAnalysis::operator=(SolverAnalysis&&) noexcept = default;
double SolverAnalysis::seconds() const { return state_ ? state_->seconds : 0; }

struct ConnectionSolver::Impl {
  const Topology& topology;
  const Geometry& geometry;
  const Cycles& cycles;
  SolverOptions options;
  Eigen::VectorXd weights;
  // Levi-Civita holonomy per loop / generator / fixed-face path.
  std::vector<double> loop_curvature, generator_holonomy, path_holonomy;
  SetupTimings timings;
  std::unique_ptr<connection::SolverEngine> engine;
  bool sparse_paths = false;

  // Rows of the reduced system: interior vertices (minus one per closed component), then the cycle
  // rows C: boundary loops (minus one per component with boundary), then generators.
  std::vector<int> active_edges, edge_column;  // the system edges (src/connection/assembly.h), and their column
  std::vector<int> vertex_row;                 // row of each vertex, −1 if none
  int num_vertex_rows = 0;
  std::vector<int> dropped_vertex, dropped_loop;  // per component, −1 if none
  enum class RowKind { Loop, Generator, Path };
  struct Row {
    RowKind kind;
    int id;  // loop, generator or path id
  };
  std::vector<Row> rows;  // the cycle rows C
  std::vector<int> fixed_faces;
  std::vector<FixedPath> paths;
  int regularized_edges = 0;
  int floored_edges = 0;  // edges raised to SolverOptions::weight_floor

  Impl(const Topology& t, const Geometry& g, const Cycles& c, SolverOptions o) : topology(t), geometry(g), cycles(c), options(o) {}
  int num_generators() const { return static_cast<int>(cycles.generators.size()); }
  const DualCycle& cycle_of_row(int r) const {
    const Row& row = rows[r];
    return row.kind == RowKind::Loop        ? cycles.loops[row.id]
           : row.kind == RowKind::Generator ? cycles.generators[row.id]
                                            : paths[row.id].path;
  }
  int component_of_row(int r) const {
    const Row& row = rows[r];
    if (row.kind == RowKind::Loop) return topology.vertex_component[topology.boundary_loops[row.id][0]];
    return row.kind == RowKind::Generator ? cycles.generators[row.id].component : paths[row.id].path.component;
  }

  // Set-up, in order.
  void set_weights_and_paths(const std::vector<int>& fixed);
  double regularize_rigid_cycles();
  void connect_isolated_vertices(double epsilon);
  void lay_out_rows(double epsilon);
  void factor(const std::function<SolverAnalysis()>& analysis);

  // A solve, in order.
  void check_fixed_angles(const IndexPrescription& prescription) const;
  Eigen::VectorXd vertex_rhs(const IndexPrescription& prescription) const;
  // What the x along fixed-face path k must add up to, before its whole number of 2π/N turns.
  double path_target(int k, const IndexPrescription& prescription) const {
    const FixedPath& path = paths[k];
    return path_holonomy[k] - (prescription.fixed.at(path.to_face) - prescription.fixed.at(path.from_face));
  }
  struct CycleRhs;
  CycleRhs cycle_rhs(const IndexPrescription& prescription) const;
  Eigen::VectorXd round_sparse_path_turns(const IndexPrescription& prescription, const Eigen::VectorXd& b_D, Eigen::VectorXd& n_E) const;
  struct Rhs;
  Rhs rhs_of(const IndexPrescription& prescription) const;
  // What a solve asks for the cycle rows, given r₀ (the real b_C of least energy): the cycle indices n_C moved to
  // the nearest point of their lattice, and b_C = H − step n_C (both written to `rhs`).
  connection::SolverEngine::CycleRhsChooser cycle_chooser(Rhs& rhs) const;
  Connection result(const IndexPrescription& prescription, const Eigen::VectorXd& x_active, const CycleRhs& cycle,
                    const Eigen::VectorXd& n_C, const Eigen::VectorXd& n_E) const;
};

ConnectionSolver::ConnectionSolver(const Topology& topology, const Geometry& geometry, const Cycles& cycles, SolverOptions options,
                                   const std::vector<int>& fixed_faces, const std::function<SolverAnalysis()>& analysis)
    : impl_(std::make_unique<Impl>(topology, geometry, cycles, options)) {
  Impl& s = *impl_;
  const auto t0 = Clock::now();
  s.set_weights_and_paths(fixed_faces);
  const double epsilon = s.regularize_rigid_cycles();
  s.lay_out_rows(epsilon);
  s.timings.assemble += seconds_since(t0);
  s.factor(analysis);
}

// Weights, the Levi-Civita holonomies the constraints use, and the paths between fixed faces.
void ConnectionSolver::Impl::set_weights_and_paths(const std::vector<int>& fixed) {
  const Topology& t = topology;
  const int nE = t.num_edges;
  weights.setZero(nE);
  for (int e = 0; e < nE; ++e)
    if (!t.is_boundary_edge(e)) weights(e) = options.weights == WeightKind::Unit ? 1.0 : geometry.cotan_weight(e);
#ifndef TRIVCON_WITH_SUITESPARSE
  // The reference routes need CHOLMOD or SuiteSparseQR, which a default build does not link (CMakeLists.txt).
  if (options.solver == SolverKind::QR)
    throw Error("the QR solver needs SuiteSparseQR, which this build of trivcon does not link (it is GPL-licensed); rebuild with "
                "-DTRIVCON_WITH_SUITESPARSE=ON, or use the Cholesky solver (the default)");
  if (options.factorization == Factorization::Cholmod)
    throw Error("the cholmod factorization needs CHOLMOD, which this build of trivcon does not link (Debian's CHOLMOD contains "
                "GPL-licensed modules); rebuild with -DTRIVCON_WITH_SUITESPARSE=ON, or use trivcon's own factorization (the default)");
#endif
  if (!(options.weight_floor >= 0 && options.weight_floor <= 1))
    throw Error("the weight floor must be in [0, 1] (a fraction of the median weight), not " + std::to_string(options.weight_floor));
  if (options.weights == WeightKind::Cotan && options.weight_floor > 0) {
    std::vector<double> positive;
    for (int e = 0; e < nE; ++e)
      if (weights(e) > 0) positive.push_back(weights(e));
    if (!positive.empty()) {
      std::nth_element(positive.begin(), positive.begin() + positive.size() / 2, positive.end());
      const double floor = options.weight_floor * positive[positive.size() / 2];
      for (int e = 0; e < nE; ++e)
        if (!t.is_boundary_edge(e) && weights(e) < floor) weights(e) = floor, ++floored_edges;
    }
  }
  if (!options.edge_weight_scale.empty()) {
    if (static_cast<int>(options.edge_weight_scale.size()) != nE)
      throw Error("edge_weight_scale has " + std::to_string(options.edge_weight_scale.size()) + " entries for " + std::to_string(nE) +
                  " edges");
    for (int e = 0; e < nE; ++e) {
      if (!(options.edge_weight_scale[e] > 0 && std::isfinite(options.edge_weight_scale[e])))
        throw Error("edge_weight_scale of edge " + std::to_string(e) + " must be positive and finite");
      weights(e) *= options.edge_weight_scale[e];
    }
  }
  for (size_t l = 0; l < t.boundary_loops.size(); ++l) loop_curvature.push_back(trivcon::loop_curvature(t, geometry, static_cast<int>(l)));
  for (const DualCycle& g : cycles.generators) generator_holonomy.push_back(levi_civita_holonomy(g, geometry));
  fixed_faces = fixed;
  std::sort(fixed_faces.begin(), fixed_faces.end());
  fixed_faces.erase(std::unique(fixed_faces.begin(), fixed_faces.end()), fixed_faces.end());
  for (int f : fixed_faces)
    if (f < 0 || f >= t.num_faces)
      throw Error("fixed face " + std::to_string(f) + " out of range (mesh has " + std::to_string(t.num_faces) + " faces)");
  if (fixed_faces.empty()) return;
  std::vector<char> usable(nE, 0);
  for (int e = 0; e < nE; ++e) usable[e] = weights(e) > 0;
  paths = fixed_face_paths(t, fixed_faces, usable);
  for (const FixedPath& path : paths) path_holonomy.push_back(levi_civita_holonomy(path.path, geometry));
}

// A cycle or fixed-face path made only of zero-weight edges could not turn the field at all; its edges
// get a small positive weight (1e-6 × the median positive weight, returned), so that it turns there only
// when nothing else can.
double ConnectionSolver::Impl::regularize_rigid_cycles() {
  const int nE = topology.num_edges;
  double epsilon = 1e-6;
  std::vector<double> positive;
  positive.reserve(nE);
  for (int e = 0; e < nE; ++e)
    if (weights(e) > 0) positive.push_back(weights(e));
  if (!positive.empty()) {
    std::nth_element(positive.begin(), positive.begin() + positive.size() / 2, positive.end());
    epsilon = 1e-6 * positive[positive.size() / 2];
  }
  auto regularize = [&](const DualCycle& c) {
    if (std::any_of(c.edges.begin(), c.edges.end(), [&](int e) { return weights(e) > 0; })) return;
    for (int e : c.edges) weights(e) = epsilon, ++regularized_edges;
  };
  for (const DualCycle& c : cycles.loops) regularize(c);
  for (const DualCycle& c : cycles.generators) regularize(c);
  for (const FixedPath& p : paths) regularize(p.path);
  // With fixed faces, the path rows and the vertex rows can be dependent on the edges of positive weight
  // alone: a vertex whose only weighted edges are links between adjacent fixed faces has its holonomy fixed
  // twice, and A W Aᵀ is singular. CAD meshes, with their right-angled triangles (weights of 0 or of
  // round-off size, ~1e-17) along feature lines, do this often. The rows are independent on all interior
  // edges (the paths form a forest, trivcon/constraints.h), so every edge lighter than ε then gets ε: the
  // field turns there only when nothing else can.
  if (!paths.empty())
    for (int e = 0; e < nE; ++e)
      if (!topology.is_boundary_edge(e) && weights(e) < epsilon) weights(e) = epsilon, ++regularized_edges;
  return epsilon;
}

// Vertex rows (one dropped per closed component), loop rows (one dropped per component with boundary),
// generator rows; the system edges.
void ConnectionSolver::Impl::lay_out_rows(double epsilon) {
  const Topology& t = topology;
  connection::RowLayout layout = connection::row_layout(t);
  vertex_row = std::move(layout.vertex_row), dropped_vertex = std::move(layout.dropped_vertex);
  dropped_loop = std::move(layout.dropped_loop), num_vertex_rows = layout.num_vertex_rows;
  // Cycle rows, fixed-face paths first: free indices are rounded in this order (see src/connection/generator_rounding.h),
  // and a path between nearby fixed faces is well determined, while a loop or generator index is only
  // determined once the paths around it are.
  // Many fixed faces (e.g. a whole aligned boundary) would make the dense block large: then the Cholesky
  // route orders the path rows with the vertex rows (sparse, fill-reducing) and rounds their turns
  // from the field without them (see round_sparse_path_turns).
  sparse_paths = options.solver == SolverKind::Cholesky && static_cast<int>(paths.size()) > options.max_dense_paths;
  if (!sparse_paths)
    for (int k = 0; k < static_cast<int>(paths.size()); ++k) rows.push_back({RowKind::Path, k});
  for (int l : connection::loop_rows(t, dropped_loop)) rows.push_back({RowKind::Loop, l});
  for (int g = 0; g < num_generators(); ++g) rows.push_back({RowKind::Generator, g});
  connect_isolated_vertices(epsilon);
  connection::system_edges(t, options.solver == SolverKind::QR ? &weights : nullptr, active_edges, edge_column);
}

// The factorization of the chosen route, and the stored forward substitution of the base right-hand side.
void ConnectionSolver::Impl::factor(const std::function<SolverAnalysis()>& analysis) {
  const Topology& t = topology;
  auto t0 = Clock::now();
  const int m = static_cast<int>(active_edges.size());
  const int nC = static_cast<int>(rows.size());
  // The vertex rows of A as the rows of each edge's ends; the cycle and path rows as sparse columns.
  const connection::EdgeEnds ends = connection::edge_ends(t, active_edges, vertex_row);
  const SparseMatrix Ct = connection::cycle_columns(m, edge_column, nC, [&](int r) -> const DualCycle& { return cycle_of_row(r); });
  Eigen::VectorXd w(m);
  for (int a = 0; a < m; ++a) w(a) = weights(active_edges[a]);
  timings.assemble += seconds_since(t0);
  if (options.solver == SolverKind::QR) {
#ifdef TRIVCON_WITH_SUITESPARSE
    SparseMatrix Dt(m, num_vertex_rows);
    std::vector<Triplet> trip;
    for (int a = 0; a < m; ++a)
      for (int end = 0; end < 2; ++end)
        if (ends[a][end] >= 0) trip.emplace_back(a, ends[a][end], end == 0 ? -1.0 : 1.0);
    Dt.setFromTriplets(trip.begin(), trip.end());
    engine = connection::make_qr_engine(Dt, Ct, w, timings);
#endif
  } else if (!sparse_paths) {
    // A symbolic factorization made beforehand fits the system without fixed faces only.
    std::function<std::unique_ptr<connection::AnalysisState>()> given;
    if (analysis && paths.empty()) given = [&analysis] { return std::move(analysis().state_); };
    engine = connection::make_cholesky_engine(ends, num_vertex_rows, SparseMatrix(m, 0), Ct, w, options.factorization, timings, given);
  } else {
    // The vertex and path rows together, ordered anew (CAMD). (Ordering the path rows first, or each
    // before the first of its vertices, with the vertex order of the system without them, made the
    // factorization far slower on feature lines, where many paths share edges: BENCHMARKS.md, "Fixed directions".)
    const SparseMatrix Et =
        connection::cycle_columns(m, edge_column, static_cast<int>(paths.size()), [&](int k) -> const DualCycle& { return paths[k].path; });
    engine = connection::make_cholesky_engine(ends, num_vertex_rows, Et, Ct, w, options.factorization, timings);
  }
  t0 = Clock::now();
  Eigen::VectorXd base(num_vertex_rows);
  for (int v = 0; v < t.num_vertices; ++v)
    if (vertex_row[v] >= 0) base(vertex_row[v]) = geometry.angle_defect(v);
  base.conservativeResize(num_vertex_rows + (sparse_paths ? static_cast<Eigen::Index>(paths.size()) : 0));
  base.tail(base.size() - num_vertex_rows).setZero();
  engine->set_base_rhs(base);
  timings.schur += seconds_since(t0);
}

ConnectionSolver::~ConnectionSolver() = default;

Eigen::VectorXd ConnectionSolver::vertex_duals(const Connection& connection) const {
  const Impl& s = *impl_;
  if (connection.x.size() != s.topology.num_edges)
    throw Error("vertex_duals: the connection has " + std::to_string(connection.x.size()) + " edge values for " +
                std::to_string(s.topology.num_edges) + " edges");
  const int m = static_cast<int>(s.active_edges.size());
  Eigen::VectorXd x_active(m);
  for (int a = 0; a < m; ++a) x_active(a) = connection.x(s.active_edges[a]);
  const Eigen::VectorXd y = s.engine->multipliers(x_active);
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(s.topology.num_vertices);
  for (int v = 0; v < s.topology.num_vertices; ++v)
    if (s.vertex_row[v] >= 0) lambda(v) = y(s.vertex_row[v]);
  return lambda;
}

const Eigen::VectorXd& ConnectionSolver::weights() const { return impl_->weights; }
const SetupTimings& ConnectionSolver::timings() const { return impl_->timings; }
std::string ConnectionSolver::ordering() const { return impl_->engine ? impl_->engine->ordering() : ""; }
int ConnectionSolver::num_generators() const { return impl_->num_generators(); }
const std::vector<double>& ConnectionSolver::loop_curvatures() const { return impl_->loop_curvature; }
const std::vector<double>& ConnectionSolver::generator_holonomies() const { return impl_->generator_holonomy; }
const std::vector<int>& ConnectionSolver::fixed_faces() const { return impl_->fixed_faces; }
int ConnectionSolver::regularized_edges() const { return impl_->regularized_edges; }
int ConnectionSolver::floored_edges() const { return impl_->floored_edges; }
const std::vector<FixedPath>& ConnectionSolver::fixed_paths() const { return impl_->paths; }
bool ConnectionSolver::sparse_paths() const { return impl_->sparse_paths; }

// Every vertex row must reach a boundary vertex or the dropped vertex of its component through edges of
// positive weight; otherwise the Laplacian is singular and the vertex's curvature has nowhere to go
// (e.g. a vertex surrounded by zero-area faces only). The zero-weight edges at such vertices get the
// small weight `epsilon`, repeatedly, until every vertex row is reached.
void ConnectionSolver::Impl::connect_isolated_vertices(double epsilon) {
  const Topology& t = topology;
  // Through interior edges every vertex reaches the boundary or its component's dropped vertex (an edge
  // with an interior end is interior), so only zero weights can cut a vertex off.
  bool any_zero = false;
  for (int e = 0; e < t.num_edges && !any_zero; ++e) any_zero = !t.is_boundary_edge(e) && weights(e) == 0;
  if (!any_zero) return;
  // Breadth-first search from the grounded vertices through edges of positive weight; each round gives
  // the zero-weight edges of the vertices it did not reach a small weight and carries the search on.
  std::vector<char> grounded(t.num_vertices, 0);
  std::vector<int> queue;
  for (int v = 0; v < t.num_vertices; ++v)
    if (t.is_boundary_vertex(v)) grounded[v] = 1, queue.push_back(v);
  for (int v : dropped_vertex)
    if (v >= 0 && !grounded[v]) grounded[v] = 1, queue.push_back(v);
  size_t searched = 0;
  auto search = [&] {
    for (; searched < queue.size(); ++searched) {
      const int v = queue[searched];
      for (int a = t.vertex_edge_offsets[v]; a < t.vertex_edge_offsets[v + 1]; ++a) {
        const int e = t.vertex_edges[a];
        if (!(weights(e) > 0)) continue;
        const int u = t.edge_vertices(e, 0) == v ? t.edge_vertices(e, 1) : t.edge_vertices(e, 0);
        if (!grounded[u]) grounded[u] = 1, queue.push_back(u);
      }
    }
  };
  search();
  std::vector<int> isolated_vertices;
  for (int v = 0; v < t.num_vertices; ++v)
    if (vertex_row[v] >= 0 && !grounded[v]) isolated_vertices.push_back(v);
  while (!isolated_vertices.empty()) {
    int added = 0;
    for (int v : isolated_vertices) {
      for (int a = t.vertex_edge_offsets[v]; a < t.vertex_edge_offsets[v + 1]; ++a) {
        const int e = t.vertex_edges[a];
        if (t.is_boundary_edge(e) || weights(e) != 0) continue;
        weights(e) = epsilon, ++added;
        // The search goes on from the grounded end of a newly weighted edge.
        for (int end = 0; end < 2; ++end) {
          const int u = t.edge_vertices(e, end), other = t.edge_vertices(e, 1 - end);
          if (grounded[u] && !grounded[other]) grounded[other] = 1, queue.push_back(other);
        }
      }
    }
    if (added == 0)  // cannot happen on a connected component; kept as a guard against an endless loop
      throw Error("interior vertex " + std::to_string(isolated_vertices[0]) + " cannot be joined to the rest of component " +
                  std::to_string(t.vertex_component[isolated_vertices[0]]) + " through weighted edges; use --weights unit");
    regularized_edges += added;
    search();
    std::vector<int> still;
    for (int v : isolated_vertices)
      if (!grounded[v]) still.push_back(v);
    isolated_vertices.swap(still);
  }
}

// The cycle rows' holonomy H (their right-hand side is H − (2π/N) n), the prescribed n₀, and the free
// ones as n = n₀ + M t.
struct ConnectionSolver::Impl::CycleRhs {
  Eigen::VectorXd H, n0;
  Eigen::MatrixXd M;
  bool identity = false;                  // M = I: every cycle row free
  std::vector<int> component_vertex_sum;  // Σ n of the prescribed vertices, per component
};

// A prescription's right-hand sides: the vertex rows' b (with the sparse route's path rows, their turns n_E),
// the cycle rows' holonomy, and the cycle indices and right-hand sides a solve fills in (n_C, b_C).
struct ConnectionSolver::Impl::Rhs {
  double step = 0;
  CycleRhs cycle;
  Eigen::VectorXd b, n_C, n_E, b_C;
};

// Checked against the mesh and the fixed faces first.
ConnectionSolver::Impl::Rhs ConnectionSolver::Impl::rhs_of(const IndexPrescription& prescription) const {
  validate_prescription(topology, num_generators(), prescription);
  check_fixed_angles(prescription);
  Rhs r;
  r.step = 2 * kPi / prescription.N;
  const Eigen::VectorXd b_D = vertex_rhs(prescription);
  r.cycle = cycle_rhs(prescription);
  r.n_C = r.cycle.n0;
  r.b = sparse_paths ? round_sparse_path_turns(prescription, b_D, r.n_E) : b_D;
  return r;
}

connection::SolverEngine::CycleRhsChooser ConnectionSolver::Impl::cycle_chooser(Rhs& rhs) const {
  return [this, &rhs](const Eigen::VectorXd& r0) {
    const CycleRhs& cycle = rhs.cycle;
    const Eigen::VectorXd u = (cycle.H - r0) / rhs.step;
    rhs.n_C += cycle.M * connection::nearest_lattice_point(*engine, u, cycle.n0, cycle.M, cycle.identity).cast<double>();
    rhs.b_C = cycle.H - rhs.step * rhs.n_C;
    return rhs.b_C;
  };
}

void ConnectionSolver::Impl::check_fixed_angles(const IndexPrescription& prescription) const {
  if (prescription.fixed.size() != fixed_faces.size() ||
      !std::equal(fixed_faces.begin(), fixed_faces.end(), prescription.fixed.begin(), [](int f, const auto& kv) { return f == kv.first; }))
    throw Error("the fixed faces of the prescription (" + std::to_string(prescription.fixed.size()) +
                ") are not those the solver was set up with (" + std::to_string(fixed_faces.size()) +
                "): fixing other faces changes the matrix, set up a new solver");
  for (auto [f, angle] : prescription.fixed)
    if (!std::isfinite(angle)) throw Error("fixed angle of face " + std::to_string(f) + " is not finite");
}

// K_v − (2π/N) n_v per vertex row.
Eigen::VectorXd ConnectionSolver::Impl::vertex_rhs(const IndexPrescription& prescription) const {
  const double step = 2 * kPi / prescription.N;
  Eigen::VectorXd b_D(num_vertex_rows);
  for (int v = 0; v < topology.num_vertices; ++v)
    if (vertex_row[v] >= 0) b_D(vertex_row[v]) = geometry.angle_defect(v);
  for (auto [v, n] : prescription.vertex)
    if (vertex_row[v] >= 0) b_D(vertex_row[v]) -= step * n;
  return b_D;
}

// Loops of a component must sum, with its vertex indices, to χ: the dropped loop takes the remainder. If
// the dropped loop is prescribed, one free loop of the component ("pivot") takes it instead.
ConnectionSolver::Impl::CycleRhs ConnectionSolver::Impl::cycle_rhs(const IndexPrescription& prescription) const {
  const Topology& t = topology;
  const int nC = static_cast<int>(rows.size());
  CycleRhs c;
  c.H.resize(nC);
  c.n0 = Eigen::VectorXd::Zero(nC);
  std::vector<int> free_rows, loop_row_of(t.boundary_loops.size(), -1);
  c.component_vertex_sum.assign(t.components.size(), 0);
  for (auto [v, n] : prescription.vertex) c.component_vertex_sum[t.vertex_component[v]] += n;
  for (int r = 0; r < nC; ++r) {
    const Row& row = rows[r];
    const std::map<int, int>* given = nullptr;
    if (row.kind == RowKind::Loop) {
      c.H(r) = loop_curvature[row.id];
      loop_row_of[row.id] = r;
      given = &prescription.loop;
    } else if (row.kind == RowKind::Generator) {
      c.H(r) = generator_holonomy[row.id];
      given = &prescription.generator;
    } else {  // transport from one fixed face to the next must turn γ_from onto γ_to
      c.H(r) = path_target(row.id, prescription);
    }
    auto it = given ? given->find(row.id) : prescription.loop.end();
    if (given && it != given->end())
      c.n0(r) = it->second;
    else
      free_rows.push_back(r);
  }
  std::vector<int> pivot_of_component(t.components.size(), -1);
  for (size_t k = 0; k < t.components.size(); ++k) {
    const int dl = dropped_loop[k];
    if (dl < 0 || !prescription.loop.count(dl)) continue;
    int sum = prescription.N * t.components[k].euler_characteristic - c.component_vertex_sum[k] - prescription.loop.at(dl);
    for (int l : t.components[k].boundary_loops) {
      if (l == dl) continue;
      if (!prescription.loop.count(l) && pivot_of_component[k] < 0)
        pivot_of_component[k] = loop_row_of[l];
      else if (prescription.loop.count(l))
        sum -= prescription.loop.at(l);
    }
    if (pivot_of_component[k] >= 0) c.n0(pivot_of_component[k]) = sum;
  }
  // Parametrisation n = n0 + M t of the free rows.
  std::vector<int> params;
  for (int r : free_rows)
    if (rows[r].kind != RowKind::Loop || pivot_of_component[component_of_row(r)] != r) params.push_back(r);
  c.M = Eigen::MatrixXd::Zero(nC, static_cast<Eigen::Index>(params.size()));
  for (size_t k = 0; k < params.size(); ++k) {
    const int r = params[k];
    c.M(r, k) = 1;
    if (rows[r].kind == RowKind::Loop && pivot_of_component[component_of_row(r)] >= 0) c.M(pivot_of_component[component_of_row(r)], k) = -1;
  }
  c.identity = static_cast<int>(params.size()) == nC;
  return c;
}

// With the path rows sparse, each path's whole number of turns n_E is read from a field: the path's row asks
// Σ s_e x_e = h − (2π/N) n_E along it (h = path_target), and a field β turns along the path, relative to parallel
// transport, by T = Σ s_e x_e with s_e x_e = β_cur + s_e ρ_e − β_next reduced to (−π/N, π/N] at each step
// (trivcon/field.h's convention, β_R = β_L + ρ_e − x_e); n_E = round((h − T)/(2π/N)). With the prescription's
// path_guide (the smoothest field, which the fixed directions hold) that is the guide's own turn; without one,
// T = 0: the smallest turn, which for a path of one edge (two adjacent fixed faces, most of them on feature
// lines and boundaries) is the principal matching of the two directions. (Rounding instead the turn of the
// field without path constraints, which knows nothing of the fixed directions, gave a CAD mesh many times the
// energy of the dense route's choice, and needed a second factorization, BENCHMARKS.md "Fixed directions".)
// Returns the right-hand side of the vertex and path rows.
Eigen::VectorXd ConnectionSolver::Impl::round_sparse_path_turns(const IndexPrescription& prescription, const Eigen::VectorXd& b_D,
                                                                Eigen::VectorXd& n_E) const {
  const double step = 2 * kPi / prescription.N;
  const int nP = static_cast<int>(paths.size());
  const std::vector<double>& guide = prescription.path_guide;
  auto reduced = [step](double a) { return a - step * std::floor(a / step + 0.5); };
  n_E.resize(nP);
  Eigen::VectorXd b = b_D;
  b.conservativeResize(num_vertex_rows + nP);
  for (int k = 0; k < nP; ++k) {
    const double h = path_target(k, prescription);
    double turn = 0;
    if (!guide.empty()) {
      const DualCycle& path = paths[k].path;
      for (size_t i = 0; i < path.edges.size(); ++i) {
        const int e = path.edges[i], s = path.signs[i];
        const int from = topology.edge_faces(e, s > 0 ? 0 : 1), to = topology.edge_faces(e, s > 0 ? 1 : 0);
        turn += reduced(guide[from] + s * geometry.rho(e) - guide[to]);
      }
    }
    n_E(k) = std::floor((h - turn) / step + 0.5 + 1e-7);
    b(num_vertex_rows + k) = h - step * n_E(k);
  }
  return b;
}

Connection ConnectionSolver::solve(const IndexPrescription& prescription) const {
  const Impl& s = *impl_;
  Impl::Rhs r = s.rhs_of(prescription);
  const Eigen::VectorXd& b = r.b;
  Eigen::VectorXd x_active = s.engine->solve(b, s.cycle_chooser(r));
  const Eigen::VectorXd &n_C = r.n_C, &n_E = r.n_E, &b_C = r.b_C;
  const Impl::CycleRhs& cycle = r.cycle;
  Connection connection = s.result(prescription, x_active, cycle, n_C, n_E);
  // Iterative refinement, only when the residual asks for it: on meshes whose weights span many orders
  // of magnitude (slivers, needles) one substitution with A W Aᵀ can leave a residual far above round-off.
  // Each step costs one forward and one backward substitution with the factor at hand; a step is kept
  // only when it lowers the residual.
  auto residual_of = [](const Connection& c) { return std::max(c.max_vertex_residual, c.max_cycle_residual); };
  Eigen::VectorXd b_full(b.size() + b_C.size());
  b_full << b, b_C;
  for (int step_count = 0; step_count < kMaxRefinements && residual_of(connection) > kRefineAbove * std::max(1.0, connection.rhs_scale);
       ++step_count) {
    Eigen::VectorXd refined = x_active;
    if (!s.engine->refine(b_full, refined)) break;
    Connection better = s.result(prescription, refined, cycle, n_C, n_E);
    if (!(residual_of(better) < residual_of(connection))) break;
    better.refinements = step_count + 1;
    connection = std::move(better), x_active = std::move(refined);
  }
  return connection;
}

double ConnectionSolver::energy(const IndexPrescription& prescription) const {
  const Impl& s = *impl_;
  Impl::Rhs r = s.rhs_of(prescription);
  const double e = s.engine->energy(r.b, s.cycle_chooser(r));
  return e >= 0 ? e : solve(prescription).energy;
}

// x on every edge, the indices used (the dropped loop's from Gauss–Bonnet), the energy, and the
// verification against every constraint.
Connection ConnectionSolver::Impl::result(const IndexPrescription& prescription, const Eigen::VectorXd& x_active, const CycleRhs& cycle,
                                          const Eigen::VectorXd& n_C, const Eigen::VectorXd& n_E) const {
  const Topology& t = topology;
  const int N = prescription.N;
  const double step = 2 * kPi / N;
  Connection result;
  result.N = N;
  result.x.setZero(t.num_edges);
  const int num_active = static_cast<int>(active_edges.size());
#pragma omp parallel for schedule(static) if (num_active > kParallelMinEditElements)
  for (int a = 0; a < num_active; ++a) result.x(active_edges[a]) = x_active(a);
  const int nG = num_generators();
  result.generator_index.assign(nG, 0);
  result.generator_chosen.assign(nG, 0);
  result.loop_index.assign(t.boundary_loops.size(), 0);
  result.loop_chosen.assign(t.boundary_loops.size(), 0);
  result.path_turn.assign(paths.size(), 0);
  if (sparse_paths) result.path_turns = prescription.path_guide.empty() ? Connection::PathTurns::Smallest : Connection::PathTurns::FromTheGuide;
  double path_residual = 0;
  for (int k = 0; k < n_E.size(); ++k) {
    result.path_turn[k] = static_cast<int>(n_E(k));
    path_residual = std::max(path_residual, std::abs(cycle_sum(paths[k].path, result.x) - (path_target(k, prescription) - step * n_E(k))));
  }
  for (int r = 0; r < static_cast<int>(rows.size()); ++r) {
    const Row& row = rows[r];
    const int n = static_cast<int>(std::lround(n_C(r)));
    if (row.kind == RowKind::Loop) {
      result.loop_index[row.id] = n;
      result.loop_chosen[row.id] = !prescription.loop.count(row.id);
    } else if (row.kind == RowKind::Generator) {
      result.generator_index[row.id] = n;
      result.generator_chosen[row.id] = !prescription.generator.count(row.id);
    } else {
      result.path_turn[row.id] = n;
      path_residual = std::max(path_residual, std::abs(cycle_sum(paths[row.id].path, result.x) - (cycle.H(r) - step * n)));
    }
  }
  for (size_t c = 0; c < t.components.size(); ++c) {
    const int dl = dropped_loop[c];
    if (dl < 0) continue;
    int rest = N * t.components[c].euler_characteristic - cycle.component_vertex_sum[c];
    for (int l : t.components[c].boundary_loops)
      if (l != dl) rest -= result.loop_index[l];
    result.loop_index[dl] = rest;
    result.loop_chosen[dl] = !prescription.loop.count(dl);
  }
  double energy = 0;
#pragma omp parallel for schedule(static) reduction(+ : energy) if (num_active > kParallelMinEditElements)
  for (int a = 0; a < num_active; ++a) {
    const int e = active_edges[a];
    if (weights(e) > 0) energy += result.x(e) * result.x(e) / weights(e);
  }
  result.energy = energy;

  IndexPrescription used = prescription;
  for (int g = 0; g < nG; ++g) used.generator[g] = result.generator_index[g];
  for (size_t l = 0; l < t.boundary_loops.size(); ++l) used.loop[static_cast<int>(l)] = result.loop_index[l];
  verify_connection(t, geometry, cycles, used, result, &loop_curvature, &generator_holonomy);
  result.max_cycle_residual = std::max(result.max_cycle_residual, path_residual);
  return result;
}

}  // namespace trivcon
