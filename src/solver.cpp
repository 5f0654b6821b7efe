#include "trivcon/solver.h"

#include <Eigen/CholmodSupport>
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <SuiteSparseQR.hpp>
#include <chrono>
#include <cmath>
#include <numeric>

#include "trivcon/error.h"

namespace trivcon {

namespace {
constexpr double kPi = 3.14159265358979323846;
using SparseMatrix = Eigen::SparseMatrix<double>;
using Triplet = Eigen::Triplet<double>;
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Dense Y = L⁻¹ B is kept between edits (saving one sparse solve per edit) only up to this size.
constexpr double kMaxStoredSchurBytes = 512.0 * 1024 * 1024;
constexpr int kSchurBlock = 64;  // right-hand sides per CHOLMOD solve when forming the Schur complement
}  // namespace

// The constraint system in "active edge" space (interior edges with w_e > 0): Dt (m × nD) and
// Ct (m × nC) are the transposed constraint rows, so x_active = W (Dt λ + Ct μ).
struct ConnectionSolver::Engine {
  virtual ~Engine() = default;
  // r₀: the values of the C rows' right-hand sides that minimise the energy for these vertex rows.
  virtual Eigen::VectorXd optimal_cycle_rhs(const Eigen::VectorXd& b_D) const = 0;
  virtual Eigen::VectorXd solve(const Eigen::VectorXd& b_D, const Eigen::VectorXd& b_C) const = 0;  // x on active edges
  Eigen::MatrixXd P;  // ((A W Aᵀ)⁻¹) restricted to the C rows = S⁻¹
};

namespace {

// Cholesky of the interior-vertex Laplacian + dense Schur complement for the cycle rows.
struct CholeskyEngine : ConnectionSolver::Engine {
  Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> chol;
  SparseMatrix Dt, Ct, B;  // B = D W Cᵀ (nD × nC)
  Eigen::VectorXd w;
  Eigen::MatrixXd Y;       // L⁻¹ B, when small enough to keep
  bool keep_Y = false;

  CholeskyEngine(const SparseMatrix& Dt_, const SparseMatrix& Ct_, const Eigen::VectorXd& w_, SetupTimings& timings)
      : Dt(Dt_), Ct(Ct_), w(w_) {
    auto t0 = Clock::now();
    const SparseMatrix WDt = w.asDiagonal() * Dt;
    const SparseMatrix L = SparseMatrix(Dt.transpose()) * WDt;
    B = SparseMatrix(WDt.transpose()) * Ct;
    const Eigen::MatrixXd G = Eigen::MatrixXd(SparseMatrix(Ct.transpose()) * (w.asDiagonal() * Ct));
    timings.assemble += seconds_since(t0);

    t0 = Clock::now();
    if (L.rows() > 0) {
      chol.compute(L);
      if (chol.info() != Eigen::Success)
        throw Error("CHOLMOD could not factor the Laplacian of the interior vertices (" + std::to_string(L.rows()) +
                    " rows): it is not positive definite");
    }
    timings.factor += seconds_since(t0);

    t0 = Clock::now();
    const int nD = static_cast<int>(L.rows()), nC = static_cast<int>(Ct.cols());
    keep_Y = static_cast<double>(nD) * nC * 8.0 <= kMaxStoredSchurBytes;
    if (keep_Y) Y.resize(nD, nC);
    Eigen::MatrixXd S = G;
    for (int c0 = 0; c0 < nC && nD > 0; c0 += kSchurBlock) {
      const int k = std::min(kSchurBlock, nC - c0);
      const Eigen::MatrixXd Bk = Eigen::MatrixXd(B.middleCols(c0, k));
      const Eigen::MatrixXd Yk = chol.solve(Bk);
      if (chol.info() != Eigen::Success) throw Error("CHOLMOD solve failed while forming the Schur complement");
      S.middleCols(c0, k) -= SparseMatrix(B.transpose()) * Yk;
      if (keep_Y) Y.middleCols(c0, k) = Yk;
    }
    if (nC > 0) {
      S = 0.5 * (S + S.transpose());
      Eigen::LDLT<Eigen::MatrixXd> ldlt(S);
      const Eigen::VectorXd d = ldlt.vectorD();
      const double scale = S.diagonal().cwiseAbs().maxCoeff();
      if (ldlt.info() != Eigen::Success || !(d.minCoeff() > 1e-13 * scale))
        throw Error("the holonomy of the generators and boundary loops cannot be controlled independently with these "
                    "weights (singular Schur complement); try --weights unit");
      P = ldlt.solve(Eigen::MatrixXd::Identity(nC, nC));
      P = 0.5 * (P + P.transpose());
    }
    timings.schur += seconds_since(t0);
  }

  Eigen::VectorXd solve_L(const Eigen::VectorXd& b) const {
    if (b.size() == 0) return b;
    Eigen::VectorXd y = chol.solve(b);
    if (chol.info() != Eigen::Success) throw Error("CHOLMOD solve failed");
    return y;
  }
  Eigen::VectorXd optimal_cycle_rhs(const Eigen::VectorXd& b_D) const override {
    return B.transpose() * solve_L(b_D);
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& b_D, const Eigen::VectorXd& b_C) const override {
    const Eigen::VectorXd lambda0 = solve_L(b_D);
    const Eigen::VectorXd mu = P * (b_C - B.transpose() * lambda0);
    const Eigen::VectorXd lambda = keep_Y ? Eigen::VectorXd(lambda0 - Y * mu) : solve_L(b_D - B * mu);
    return w.asDiagonal() * (Dt * lambda + Ct * mu);
  }
};

// SuiteSparseQR factorization of (A W^½)ᵀ; min-norm solves x = W^½ Q R⁻ᵀ Eᵀ b (as SPQR's min2norm).
struct QREngine : ConnectionSolver::Engine {
  mutable cholmod_common cc;
  SuiteSparseQR_factorization<double>* qr = nullptr;
  Eigen::VectorXd sqrt_w;
  int nD = 0, nC = 0, m = 0;
  Eigen::MatrixXd responses;  // y for each unit C right-hand side (m × nC)

  QREngine(const SparseMatrix& Dt, const SparseMatrix& Ct, const Eigen::VectorXd& w, SetupTimings& timings) {
    auto t0 = Clock::now();
    cholmod_l_start(&cc);
    cc.print = 0;
    sqrt_w = w.cwiseSqrt();
    nD = static_cast<int>(Dt.cols()), nC = static_cast<int>(Ct.cols()), m = static_cast<int>(Dt.rows());
    Eigen::SparseMatrix<double, Eigen::ColMajor, SuiteSparse_long> At(m, nD + nC);  // (A W^½)ᵀ
    {
      std::vector<Eigen::Triplet<double, SuiteSparse_long>> trip;
      for (int k = 0; k < Dt.outerSize(); ++k)
        for (SparseMatrix::InnerIterator it(Dt, k); it; ++it) trip.emplace_back(it.row(), k, it.value() * sqrt_w(it.row()));
      for (int k = 0; k < Ct.outerSize(); ++k)
        for (SparseMatrix::InnerIterator it(Ct, k); it; ++it) trip.emplace_back(it.row(), nD + k, it.value() * sqrt_w(it.row()));
      At.setFromTriplets(trip.begin(), trip.end());
      At.makeCompressed();
    }
    timings.assemble += seconds_since(t0);
    t0 = Clock::now();
    cholmod_sparse A = viewAsCholmod(At);
    qr = SuiteSparseQR_factorize<double>(SPQR_ORDERING_DEFAULT, SPQR_DEFAULT_TOL, &A, &cc);
    if (!qr || cc.status != CHOLMOD_OK) throw Error("SuiteSparseQR could not factor the constraint matrix");
    if (cc.SPQR_istat[4] < nD + nC)
      throw Error("the constraint matrix is rank deficient (rank " + std::to_string(cc.SPQR_istat[4]) + " of " +
                  std::to_string(nD + nC) + "); try --weights unit");
    timings.factor += seconds_since(t0);
    t0 = Clock::now();
    responses.resize(m, nC);
    for (int c = 0; c < nC; ++c) {
      Eigen::VectorXd b = Eigen::VectorXd::Zero(nD + nC);
      b(nD + c) = 1;
      responses.col(c) = min_norm_y(b);
    }
    P = responses.transpose() * responses;
    timings.schur += seconds_since(t0);
  }
  ~QREngine() override {
    if (qr) SuiteSparseQR_free<double>(&qr, &cc);
    cholmod_l_finish(&cc);
  }
  static cholmod_sparse viewAsCholmod(Eigen::SparseMatrix<double, Eigen::ColMajor, SuiteSparse_long>& M) {
    cholmod_sparse s{};
    s.nrow = M.rows(), s.ncol = M.cols(), s.nzmax = M.nonZeros();
    s.p = M.outerIndexPtr(), s.i = M.innerIndexPtr(), s.x = M.valuePtr();
    s.stype = 0, s.itype = CHOLMOD_LONG, s.xtype = CHOLMOD_REAL, s.dtype = CHOLMOD_DOUBLE, s.sorted = 1, s.packed = 1;
    return s;
  }
  Eigen::VectorXd min_norm_y(const Eigen::VectorXd& b) const {
    cholmod_dense* B = cholmod_l_allocate_dense(b.size(), 1, b.size(), CHOLMOD_REAL, &cc);
    std::copy(b.data(), b.data() + b.size(), static_cast<double*>(B->x));
    cholmod_dense* Z = SuiteSparseQR_solve<double>(SPQR_RTX_EQUALS_ETB, qr, B, &cc);
    cholmod_dense* X = Z ? SuiteSparseQR_qmult<double>(SPQR_QX, qr, Z, &cc) : nullptr;
    if (!X) throw Error("SuiteSparseQR solve failed");
    Eigen::VectorXd y = Eigen::Map<Eigen::VectorXd>(static_cast<double*>(X->x), m);
    cholmod_l_free_dense(&B, &cc), cholmod_l_free_dense(&Z, &cc), cholmod_l_free_dense(&X, &cc);
    return y;
  }
  Eigen::VectorXd optimal_cycle_rhs(const Eigen::VectorXd& b_D) const override {
    if (nC == 0) return Eigen::VectorXd();
    Eigen::VectorXd b = Eigen::VectorXd::Zero(nD + nC);
    b.head(nD) = b_D;
    const Eigen::VectorXd gradient = responses.transpose() * min_norm_y(b);  // λ_C at b_C = 0
    return -P.ldlt().solve(gradient);
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& b_D, const Eigen::VectorXd& b_C) const override {
    Eigen::VectorXd b(nD + nC);
    b << b_D, b_C;
    return sqrt_w.asDiagonal() * min_norm_y(b);
  }
};

// Minimises (u − n₀ − M t)ᵀ P (u − n₀ − M t) over integer t: round the real minimiser, then take
// single ±1 steps while they lower the value.
Eigen::VectorXi nearest_lattice_point(const Eigen::MatrixXd& P, const Eigen::VectorXd& u, const Eigen::VectorXd& n0,
                                      const Eigen::MatrixXd& M) {
  const int k = static_cast<int>(M.cols());
  Eigen::VectorXi t = Eigen::VectorXi::Zero(k);
  if (k == 0) return t;
  const Eigen::MatrixXd Q = M.transpose() * P * M;
  const Eigen::VectorXd real_opt = Q.ldlt().solve(M.transpose() * P * (u - n0));
  for (int i = 0; i < k; ++i) t(i) = static_cast<int>(std::lround(real_opt(i)));
  Eigen::VectorXd g = Q * t.cast<double>() - M.transpose() * P * (u - n0);  // ½ gradient
  const double tolerance = 1e-12 * std::max(1.0, Q.diagonal().maxCoeff());
  for (int pass = 0; pass < 1000; ++pass) {
    bool improved = false;
    for (int i = 0; i < k; ++i) {
      for (int d : {1, -1}) {
        if (2 * d * g(i) + Q(i, i) < -tolerance) {
          t(i) += d;
          g += d * Q.col(i);
          improved = true;
        }
      }
    }
    if (!improved) break;
  }
  return t;
}

}  // namespace

ConnectionSolver::ConnectionSolver(const Topology& topology, const Geometry& geometry, const Cycles& cycles, SolverOptions options)
    : topology_(topology), geometry_(geometry), cycles_(cycles), options_(options) {
  const Topology& t = topology;
  const int nV = t.num_vertices, nE = t.num_edges;
  auto t0 = Clock::now();
  weights_.setZero(nE);
  for (int e = 0; e < nE; ++e)
    if (!t.is_boundary_edge(e)) weights_(e) = options.weights == WeightKind::Unit ? 1.0 : geometry.cotan_weight(e);
  for (size_t l = 0; l < t.boundary_loops.size(); ++l) loop_curvature_.push_back(loop_curvature(t, geometry, static_cast<int>(l)));
  for (const DualCycle& g : cycles.generators) generator_holonomy_.push_back(levi_civita_holonomy(g, geometry));

  // Active edges, vertex rows (one dropped per closed component), loop rows (one dropped per component
  // with boundary: the longest loop, ties to the smallest id), generator rows.
  active_edges_.clear();
  edge_column_.assign(nE, -1);
  for (int e = 0; e < nE; ++e)
    if (weights_(e) > 0) edge_column_[e] = static_cast<int>(active_edges_.size()), active_edges_.push_back(e);
  vertex_row_.assign(nV, -1);
  dropped_vertex_.assign(t.components.size(), -1);
  dropped_loop_.assign(t.components.size(), -1);
  for (size_t c = 0; c < t.components.size(); ++c) {
    for (int l : t.components[c].boundary_loops)
      if (dropped_loop_[c] < 0 || t.boundary_loops[l].size() > t.boundary_loops[dropped_loop_[c]].size()) dropped_loop_[c] = l;
  }
  for (int v = nV - 1; v >= 0; --v) {
    if (!t.is_interior_vertex(v)) continue;
    const int c = t.vertex_component[v];
    if (t.components[c].boundary_loops.empty() && dropped_vertex_[c] < 0) dropped_vertex_[c] = v;
  }
  for (int v = 0; v < nV; ++v)
    if (t.is_interior_vertex(v) && dropped_vertex_[t.vertex_component[v]] != v) vertex_row_[v] = num_vertex_rows_++;
  for (size_t l = 0; l < t.boundary_loops.size(); ++l)
    if (dropped_loop_[t.vertex_component[t.boundary_loops[l][0]]] != static_cast<int>(l)) loop_rows_.push_back(static_cast<int>(l));

  check_weight_connectivity();

  const int m = static_cast<int>(active_edges_.size());
  const int nC = static_cast<int>(loop_rows_.size() + cycles.generators.size());
  SparseMatrix Dt(m, num_vertex_rows_), Ct(m, nC);
  {
    std::vector<Triplet> trip;
    for (int a = 0; a < m; ++a) {
      const int e = active_edges_[a];
      const int i = t.edge_vertices(e, 0), j = t.edge_vertices(e, 1);
      if (vertex_row_[i] >= 0) trip.emplace_back(a, vertex_row_[i], -1.0);
      if (vertex_row_[j] >= 0) trip.emplace_back(a, vertex_row_[j], 1.0);
    }
    Dt.setFromTriplets(trip.begin(), trip.end());
    trip.clear();
    for (int r = 0; r < nC; ++r) {
      const DualCycle& cycle = cycle_of_row(r);
      for (size_t k = 0; k < cycle.edges.size(); ++k)
        if (edge_column_[cycle.edges[k]] >= 0) trip.emplace_back(edge_column_[cycle.edges[k]], r, cycle.signs[k]);
    }
    Ct.setFromTriplets(trip.begin(), trip.end());  // sums repeated edges of a cycle
  }
  Eigen::VectorXd w(m);
  for (int a = 0; a < m; ++a) w(a) = weights_(active_edges_[a]);
  timings_.assemble += seconds_since(t0);
  if (options.solver == SolverKind::QR)
    engine_ = std::make_unique<QREngine>(Dt, Ct, w, timings_);
  else
    engine_ = std::make_unique<CholeskyEngine>(Dt, Ct, w, timings_);
}

ConnectionSolver::~ConnectionSolver() = default;

const DualCycle& ConnectionSolver::cycle_of_row(int r) const {
  const int nL = static_cast<int>(loop_rows_.size());
  return r < nL ? cycles_.loops[loop_rows_[r]] : cycles_.generators[r - nL];
}

// Every vertex row must reach a boundary vertex or the dropped vertex of its component through edges of
// positive weight; otherwise the Laplacian is singular and the vertex's curvature has nowhere to go.
void ConnectionSolver::check_weight_connectivity() const {
  const Topology& t = topology_;
  std::vector<int> parent(t.num_vertices);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  for (int e : active_edges_) parent[find(t.edge_vertices(e, 0))] = find(t.edge_vertices(e, 1));
  std::vector<char> grounded(t.num_vertices, 0);
  for (int v = 0; v < t.num_vertices; ++v)
    if (t.is_boundary_vertex(v)) grounded[find(v)] = 1;
  for (int v : dropped_vertex_)
    if (v >= 0) grounded[find(v)] = 1;
  for (int v = 0; v < t.num_vertices; ++v) {
    if (vertex_row_[v] < 0 || grounded[find(v)]) continue;
    int others = 0;
    for (int u = 0; u < t.num_vertices; ++u) others += (u != v && vertex_row_[u] >= 0 && find(u) == find(v));
    throw Error("the cotangent weights are zero on every edge joining interior vertex " + std::to_string(v) +
                (others ? " (and " + std::to_string(others) + " other vertices)" : std::string()) + " to the rest of component " +
                std::to_string(t.vertex_component[v]) + ", so its curvature cannot be balanced; use --weights unit");
  }
}

Connection ConnectionSolver::solve(const IndexPrescription& prescription) const {
  const Topology& t = topology_;
  validate_prescription(t, num_generators(), prescription);
  const int N = prescription.N;
  const double step = 2 * kPi / N;
  auto vertex_n = [&](int v) {
    auto it = prescription.vertex.find(v);
    return it == prescription.vertex.end() ? 0 : it->second;
  };
  Eigen::VectorXd b_D(num_vertex_rows_);
  for (int v = 0; v < t.num_vertices; ++v)
    if (vertex_row_[v] >= 0) b_D(vertex_row_[v]) = geometry_.angle_defect(v) - step * vertex_n(v);

  // Cycle rows: holonomy H, and which indices are free. Loops of a component must sum, with its
  // vertex indices, to χ: the dropped loop takes the remainder. If the dropped loop is prescribed, one
  // free loop of the component ("pivot") takes the remainder instead.
  const int nL = static_cast<int>(loop_rows_.size()), nG = num_generators(), nC = nL + nG;
  Eigen::VectorXd H(nC), n0 = Eigen::VectorXd::Zero(nC);
  std::vector<int> free_rows;
  std::vector<int> loop_row_of(t.boundary_loops.size(), -1);
  for (int r = 0; r < nL; ++r) loop_row_of[loop_rows_[r]] = r;
  std::vector<int> component_vertex_sum(t.components.size(), 0);
  for (auto [v, n] : prescription.vertex) component_vertex_sum[t.vertex_component[v]] += n;
  for (int r = 0; r < nC; ++r) {
    if (r < nL) {
      const int l = loop_rows_[r];
      H(r) = loop_curvature_[l];
      auto it = prescription.loop.find(l);
      if (it != prescription.loop.end()) n0(r) = it->second; else free_rows.push_back(r);
    } else {
      const int g = r - nL;
      H(r) = generator_holonomy_[g];
      auto it = prescription.generator.find(g);
      if (it != prescription.generator.end()) n0(r) = it->second; else free_rows.push_back(r);
    }
  }
  // Parametrisation n = n0 + M t over the free rows.
  std::vector<int> pivot_of_component(t.components.size(), -1);
  for (size_t c = 0; c < t.components.size(); ++c) {
    const int dl = dropped_loop_[c];
    if (dl < 0 || !prescription.loop.count(dl)) continue;
    // The dropped loop is prescribed: the first free loop of the component becomes the pivot.
    int sum = N * t.components[c].euler_characteristic - component_vertex_sum[c] - prescription.loop.at(dl);
    for (int l : t.components[c].boundary_loops) {
      if (l == dl) continue;
      if (!prescription.loop.count(l) && pivot_of_component[c] < 0) pivot_of_component[c] = loop_row_of[l];
      else if (prescription.loop.count(l)) sum -= prescription.loop.at(l);
    }
    if (pivot_of_component[c] >= 0) n0(pivot_of_component[c]) = sum;
  }
  std::vector<int> params;
  for (int r : free_rows) {
    const int c = r < nL ? t.vertex_component[t.boundary_loops[loop_rows_[r]][0]] : cycles_.generators[r - nL].component;
    if (r < nL && pivot_of_component[c] == r) continue;
    params.push_back(r);
  }
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(nC, static_cast<Eigen::Index>(params.size()));
  for (size_t k = 0; k < params.size(); ++k) {
    const int r = params[k];
    M(r, k) = 1;
    if (r < nL) {
      const int c = t.vertex_component[t.boundary_loops[loop_rows_[r]][0]];
      if (pivot_of_component[c] >= 0) M(pivot_of_component[c], k) = -1;
    }
  }
  Eigen::VectorXd n_C = n0;
  if (nC > 0) {
    const Eigen::VectorXd r0 = engine_->optimal_cycle_rhs(b_D);
    const Eigen::VectorXd u = (H - r0) / step;
    n_C += M * nearest_lattice_point(engine_->P, u, n0, M).cast<double>();
  }
  const Eigen::VectorXd b_C = H - step * n_C;
  const Eigen::VectorXd x_active = engine_->solve(b_D, b_C);

  Connection result;
  result.N = N;
  result.x.setZero(t.num_edges);
  for (size_t a = 0; a < active_edges_.size(); ++a) result.x(active_edges_[a]) = x_active(a);
  result.generator_index.resize(nG);
  result.generator_chosen.resize(nG);
  for (int g = 0; g < nG; ++g) {
    result.generator_index[g] = static_cast<int>(std::lround(n_C(nL + g)));
    result.generator_chosen[g] = !prescription.generator.count(g);
  }
  result.loop_index.assign(t.boundary_loops.size(), 0);
  result.loop_chosen.assign(t.boundary_loops.size(), 0);
  for (int r = 0; r < nL; ++r) {
    result.loop_index[loop_rows_[r]] = static_cast<int>(std::lround(n_C(r)));
    result.loop_chosen[loop_rows_[r]] = !prescription.loop.count(loop_rows_[r]);
  }
  for (size_t c = 0; c < t.components.size(); ++c) {
    const int dl = dropped_loop_[c];
    if (dl < 0) continue;
    int rest = N * t.components[c].euler_characteristic - component_vertex_sum[c];
    for (int l : t.components[c].boundary_loops)
      if (l != dl) rest -= result.loop_index[l];
    result.loop_index[dl] = rest;
    result.loop_chosen[dl] = !prescription.loop.count(dl);
  }
  for (int e : active_edges_) result.energy += result.x(e) * result.x(e) / weights_(e);

  IndexPrescription used = prescription;
  for (int g = 0; g < nG; ++g) used.generator[g] = result.generator_index[g];
  for (size_t l = 0; l < t.boundary_loops.size(); ++l) used.loop[static_cast<int>(l)] = result.loop_index[l];
  verify_connection(t, geometry_, cycles_, used, result);
  return result;
}

void verify_connection(const Topology& t, const Geometry& geometry, const Cycles& cycles, const IndexPrescription& prescription,
                       Connection& connection) {
  const double step = 2 * kPi / prescription.N;
  const Eigen::VectorXd& x = connection.x;
  connection.max_vertex_residual = connection.max_cycle_residual = 0;
  connection.rhs_scale = 0;
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(t.num_vertices);
  for (int e = 0; e < t.num_edges; ++e) {
    if (t.is_boundary_edge(e)) continue;
    sum(t.edge_vertices(e, 1)) += x(e);
    sum(t.edge_vertices(e, 0)) -= x(e);
  }
  for (int v = 0; v < t.num_vertices; ++v) {
    if (!t.is_interior_vertex(v)) continue;
    auto it = prescription.vertex.find(v);
    const double rhs = geometry.angle_defect(v) - step * (it == prescription.vertex.end() ? 0 : it->second);
    connection.rhs_scale = std::max(connection.rhs_scale, std::abs(rhs));
    connection.max_vertex_residual = std::max(connection.max_vertex_residual, std::abs(sum(v) - rhs));
  }
  auto check_cycle = [&](const DualCycle& cycle, double holonomy, int n) {
    double s = 0;
    for (size_t k = 0; k < cycle.edges.size(); ++k) s += cycle.signs[k] * x(cycle.edges[k]);
    const double rhs = holonomy - step * n;
    connection.rhs_scale = std::max(connection.rhs_scale, std::abs(rhs));
    connection.max_cycle_residual = std::max(connection.max_cycle_residual, std::abs(s - rhs));
  };
  for (size_t l = 0; l < cycles.loops.size(); ++l)
    check_cycle(cycles.loops[l], loop_curvature(t, geometry, static_cast<int>(l)), prescription.loop.at(static_cast<int>(l)));
  for (size_t g = 0; g < cycles.generators.size(); ++g)
    check_cycle(cycles.generators[g], levi_civita_holonomy(cycles.generators[g], geometry), prescription.generator.at(static_cast<int>(g)));
}

}  // namespace trivcon
