#include "trivcon/solver.h"

#include <cholmod.h>
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <SuiteSparseQR.hpp>
#include <chrono>
#include <functional>
#include <cmath>
#include <numeric>
#include <omp.h>

#include "detail/timing.h"
#include "ordering.h"
#include "supernodal.h"
#include "trivcon/error.h"
#include "trivcon/field.h"
#include <algorithm>
#include <array>
#include <map>

namespace trivcon {

namespace {
// Beyond this many fixed-face paths the Cholesky route keeps them out of the dense block.
constexpr int kMaxDensePaths = 256;
// Per-edit loops over edges or vertices run on all cores (OpenMP) above this size.
constexpr int kParallelEdits = 100000;
using SparseMatrix = Eigen::SparseMatrix<double>;
using Triplet = Eigen::Triplet<double>;
using detail::Clock;
using detail::seconds_since;
using EdgeEnds = std::vector<std::array<int, 2>>;  // per active edge, the vertex rows of its ends (−1: none)
}  // namespace

// The constraint system in the space of the system edges (system_edges: every interior edge on the
// Cholesky route, those with w_e > 0 on the QR route): Dt (m × nD) and Ct (m × nC) are the transposed
// constraint rows, so x_active = W (Dt λ + Ct μ).
struct ConnectionSolver::Engine {
  virtual ~Engine() = default;
  // Returns x on the system edges for vertex right-hand sides b_D; the cycle right-hand sides b_C are
  // asked from `choose`, given r₀: the real b_C that minimises the energy for this b_D.
  using CycleRhsChooser = std::function<Eigen::VectorXd(const Eigen::VectorXd& r0)>;
  virtual Eigen::VectorXd solve(const Eigen::VectorXd& b_D, const CycleRhsChooser& choose) const = 0;

  // P = S⁻¹ = ((A W Aᵀ)⁻¹) restricted to the cycle rows: the energy's quadratic form in their right-hand sides.
  virtual Eigen::VectorXd apply_P(const Eigen::VectorXd& v) const = 0;
  virtual Eigen::VectorXd P_column(int i) const = 0;
  virtual Eigen::MatrixXd dense_P() const = 0;
  // A triangular T with P = Tᵀ T (for rounding one index at a time, Babai's nearest plane).
  virtual const Eigen::MatrixXd& P_factor(bool& lower) const = 0;
  // The vertex right-hand side most solves differ from in only a few rows (the angle defects: no
  // singularity), so that a solve can update a stored forward substitution instead of redoing it.
  virtual void set_base_rhs(const Eigen::VectorXd& /*b_D*/) {}
  // The fill-reducing order the factorization used.
  virtual std::string ordering() const { return "SuiteSparseQR default"; }
  Eigen::VectorXd P_diagonal;
};

namespace {

// Upper triangle of the normal matrix M = A W Aᵀ, compressed columns.
struct Csc {
  std::vector<int> outer, inner;
  std::vector<double> values;
};

// The rows of A touching each system edge a (column a of A): row[start[a] … start[a + 1]) with their
// coefficients.
struct EdgeRows {
  std::vector<int> start, row;
  std::vector<double> coefficient;
};

// The leading n × n block of the upper triangle M (the vertex block for n = nD: its columns hold no
// cycle rows).
cholmod_sparse view(Csc& M, int n) {
  cholmod_sparse s{};
  s.nrow = s.ncol = static_cast<size_t>(n), s.nzmax = static_cast<size_t>(M.outer[n]);
  s.p = M.outer.data(), s.i = M.inner.data(), s.x = M.values.data();
  s.stype = 1, s.itype = CHOLMOD_INT, s.xtype = CHOLMOD_REAL, s.dtype = CHOLMOD_DOUBLE, s.sorted = 1, s.packed = 1;
  return s;
}

// Upper triangle of A W Aᵀ as a sparse product over the edges (Gustavson's algorithm): column c
// gathers, for each edge a in row c of A, the rows r ≤ c that edge a touches. The rows of A: nV vertex
// rows given per edge by the rows of its two ends (coefficient −1 for ends[a][0], +1 for ends[a][1]; an
// end without a row is −1), then the extra rows Et (m × (nD − nV)), then the cycle rows Ct (m × nC).
// Every product of two rows sharing an edge is an entry, also where w is 0 or the sum cancels: the
// pattern depends on ends, Et and Ct only (SolverAnalysis relies on it).
Csc normal_matrix(const EdgeEnds& ends, int nV, const SparseMatrix& Et, const SparseMatrix& Ct, const Eigen::VectorXd& w, EdgeRows& edges) {
  const int m = static_cast<int>(ends.size()), nD = nV + static_cast<int>(Et.cols()), nC = static_cast<int>(Ct.cols());
  const int n = nD + nC;
  // The rows of A touching each edge, by counting.
  std::vector<int>& start = edges.start;
  start.assign(static_cast<size_t>(m) + 1, 0);
  auto for_each_sparse_entry = [&](auto&& visit) {  // (row of A, edge, coefficient) of Et and Ct
    for (int c = 0; c < static_cast<int>(Et.cols()); ++c)
      for (SparseMatrix::InnerIterator it(Et, c); it; ++it) visit(nV + c, static_cast<int>(it.row()), it.value());
    for (int c = 0; c < nC; ++c)
      for (SparseMatrix::InnerIterator it(Ct, c); it; ++it) visit(nD + c, static_cast<int>(it.row()), it.value());
  };
  for (int a = 0; a < m; ++a) start[a + 1] = (ends[a][0] >= 0) + (ends[a][1] >= 0);
  for_each_sparse_entry([&](int, int a, double) { ++start[a + 1]; });
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<int>& row_of = edges.row;
  std::vector<double>& coefficient = edges.coefficient;
  row_of.resize(start[m]), coefficient.resize(start[m]);
  std::vector<int> next(start.begin(), start.end() - 1);
  for (int a = 0; a < m; ++a)
    for (int end = 0; end < 2; ++end)
      if (ends[a][end] >= 0) row_of[next[a]] = ends[a][end], coefficient[next[a]++] = end == 0 ? -1.0 : 1.0;
  for_each_sparse_entry([&](int r, int a, double v) { row_of[next[a]] = r, coefficient[next[a]++] = v; });
  // Per vertex row, its edges as (the other end's row or −1, weight): a vertex column of M holds only
  // vertex rows (the others come after it), so it is read from this list in sequence.
  std::vector<int> incident_start(static_cast<size_t>(nV) + 1, 0);
  for (int a = 0; a < m; ++a)
    for (int end = 0; end < 2; ++end)
      if (ends[a][end] >= 0) ++incident_start[ends[a][end] + 1];
  std::partial_sum(incident_start.begin(), incident_start.end(), incident_start.begin());
  std::vector<std::pair<int, double>> incident(incident_start[nV]);
  next.assign(incident_start.begin(), incident_start.end() - 1);
  for (int a = 0; a < m; ++a)
    for (int end = 0; end < 2; ++end)
      if (ends[a][end] >= 0) incident[next[ends[a][end]]++] = {ends[a][1 - end], w(a)};

  Csc M;
  M.outer.assign(static_cast<size_t>(n) + 1, 0);
  M.inner.reserve(static_cast<size_t>(start[m]) * 2 + n);
  M.values.reserve(M.inner.capacity());
  std::vector<double> sum(n, 0.0);
  std::vector<int> seen(n, -1), rows;
  auto add_edge = [&](int c, int a, double scale) {
    for (int k = start[a]; k < start[a + 1]; ++k) {
      const int r = row_of[k];
      if (r > c) continue;
      if (seen[r] != c) seen[r] = c, sum[r] = 0, rows.push_back(r);
      sum[r] += scale * coefficient[k];
    }
  };
  std::vector<std::pair<int, double>> column;
  for (int c = 0; c < n; ++c) {
    rows.clear();
    if (c < nV) {  // −w to each neighbouring row above the diagonal, Σ w on it (one edge per vertex pair)
      column.clear();
      double diagonal = 0;
      for (int k = incident_start[c]; k < incident_start[c + 1]; ++k) {
        const auto [other, weight] = incident[k];
        diagonal += weight;
        if (other >= 0 && other < c) column.emplace_back(other, -weight);
      }
      std::sort(column.begin(), column.end());
      for (const auto& [r, v] : column) M.inner.push_back(r), M.values.push_back(v);
      M.inner.push_back(c), M.values.push_back(diagonal);
      M.outer[c + 1] = static_cast<int>(M.inner.size());
      continue;
    }
    const SparseMatrix& S = c < nD ? Et : Ct;
    for (SparseMatrix::InnerIterator it(S, c < nD ? c - nV : c - nD); it; ++it)
      add_edge(c, static_cast<int>(it.row()), it.value() * w(static_cast<int>(it.row())));
    std::sort(rows.begin(), rows.end());
    for (int r : rows) M.inner.push_back(r), M.values.push_back(sum[r]);
    M.outer[c + 1] = static_cast<int>(M.inner.size());
  }
  return M;
}

void start_supernodal(cholmod_common& c) {  // supernodal LLᵀ
  cholmod_start(&c);
  c.print = 0;
  c.supernodal = CHOLMOD_SUPERNODAL;
  c.final_ll = 1;
}
void require(bool ok, const char* what, const cholmod_common& c) {
  if (!ok) throw Error(std::string(what) + " (CHOLMOD status " + std::to_string(c.status) + ")");
}

// A fill-reducing order of the nD vertex rows of M (the nC cycle rows come last). Minimum degree (AMD;
// CAMD when there are cycle rows, constrained to order them last, so that it sees how they couple the
// vertices: a quarter fewer flops on the dragon), then postordered by the vertex block's elimination
// tree so that CHOLMOD finds large supernodes without postordering the whole system (which could move
// the cycle rows). Not CHOLMOD's default choice, which tries METIS on large meshes: its analysis alone
// takes 3 s (the dragon) to 16 s (the dragon subdivided) on our 2-core machine, more than the fill it
// saves. (A nested dissection by vertex coordinates, tried as a second candidate, cut the flops by a
// third on smooth closed surfaces but not the time with AVX-512 BLAS kernels, and lost on the dragon;
// see BENCHMARKS.md.)
std::vector<int> vertex_order(Csc& M, int nD, int nC, cholmod_common& cc) {
  std::vector<int> order(nD);
  if (nD == 0) return order;
  if (nC > 0) {
    cholmod_sparse A = view(M, nD + nC);
    std::vector<int> last(nD + nC, 0), full(nD + nC);
    std::fill(last.begin() + nD, last.end(), 1);
    require(cholmod_camd(&A, nullptr, 0, last.data(), full.data(), &cc) != 0, "CHOLMOD could not order the constraint system", cc);
    std::copy(full.begin(), full.begin() + nD, order.begin());
    for (int k = 0; k < nD; ++k) require(order[k] < nD, "CHOLMOD did not order the cycle rows last", cc);
  } else {
    cholmod_sparse A = view(M, nD);
    require(cholmod_amd(&A, nullptr, 0, order.data(), &cc) != 0, "CHOLMOD could not order the vertex Laplacian", cc);
  }
  const ordering::Pattern pattern = ordering::leading_block_pattern(M.outer, M.inner, nD);
  std::vector<int> parent = ordering::elimination_tree(pattern, order), post(nD);
  require(cholmod_postorder(parent.data(), nD, nullptr, post.data(), &cc) == nD, "CHOLMOD could not postorder the elimination tree", cc);
  std::vector<int> postordered(nD);
  for (int k = 0; k < nD; ++k) postordered[k] = order[post[k]];
  return postordered;
}

// Symbolic analysis of the whole system: the vertex rows in `order`, then the cycle rows.
cholmod_factor* symbolic(Csc& M, std::vector<int> order, int nD, int nC, cholmod_common& c) {
  const int n = nD + nC;
  for (int r = nD; r < n; ++r) order.push_back(r);
  cholmod_sparse A = view(M, n);
  c.nmethods = 1;
  c.method[0].ordering = CHOLMOD_GIVEN;
  c.postorder = 0;  // keep the cycle rows last (the vertex order is postordered already)
  cholmod_factor* L = cholmod_analyze_p(&A, order.data(), nullptr, 0, &c);
  require(L != nullptr, "CHOLMOD could not analyse the constraint system", c);
  return L;
}

}  // namespace

// A symbolic factorization and the pattern it was computed for (SolverAnalysis), or just the CHOLMOD
// workspace of an engine that analyses its own.
struct SolverAnalysis::Impl {
  cholmod_common cc;
  cholmod_factor* factor = nullptr;
  int nD = 0, nC = 0;
  std::vector<int> outer, inner;
  double seconds = 0;
  Impl() { start_supernodal(cc); }
  ~Impl() {
    if (factor) cholmod_free_factor(&factor, &cc);
    cholmod_finish(&cc);
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
};

namespace {

using supernodal::Supernodes;

// One supernodal Cholesky factorization R Rᵀ = Π M Πᵀ of the whole normal matrix
//   M = A W Aᵀ = [ D W Dᵀ   D W Cᵀ ]
//                [ C W Dᵀ   C W Cᵀ ],
// with the vertex rows in a minimum-degree order (vertex_order) and the cycle rows C forced last. Then
// the trailing block R_CC of the factor is the Cholesky factor of the Schur complement S, so
// P = S⁻¹ = R_CC⁻ᵀ R_CC⁻¹ costs O(|C|³) with no extra solves, and an edit needs one forward and one
// backward substitution: the forward part of the vertex rows does not depend on b_C. The forward part is
// sparse too: with a base right-hand side set (set_base_rhs), a new b_D that differs from it in a few
// rows (a new set of singular vertices) only updates the supernodes on their paths to the root.
struct CholeskyEngine : ConnectionSolver::Engine {
  // CHOLMOD's workspace, and the symbolic factorization when one was given (see factorize). Mutable:
  // CHOLMOD's solves write to their workspace.
  mutable std::unique_ptr<SolverAnalysis::Impl> cholmod_ = std::make_unique<SolverAnalysis::Impl>();
  cholmod_common& cc() const { return cholmod_->cc; }
  cholmod_factor* factor = nullptr;
  bool analysis_adopted = false;
  Eigen::VectorXd w;
  int m = 0, nD = 0, nC = 0;
  // The constraint rows touching each system edge (column a of A); after the factorization, as
  // positions in factor order.
  EdgeRows edge_rows_;
  Eigen::MatrixXd R_CC, R_inv;  // lower triangular; P = R_invᵀ R_inv
  // Sparse forward substitution (see forward_update).
  std::vector<int> position_;     // factor position of each row of M (the inverse of factor->Perm)
  std::vector<int> super_of_col_, super_parent_;
  Eigen::VectorXd base_b_, base_z_;  // base right-hand side of the vertex rows, and L⁻¹ Π [base_b; 0]
  mutable std::vector<int> super_stamp_;
  mutable Eigen::VectorXd forward_work_;
  mutable int stamp_ = 0;
  // Backward substitution on two threads (see plan_backward): the supernodes of the top of the tree,
  // then two sets of disjoint subtrees, all in decreasing order.
  std::vector<int> backward_top_;
  std::array<std::vector<int>, 2> backward_part_;

  // The rows of A (see normal_matrix): vertex rows given per system edge by the rows of its two ends (a
  // boundary or dropped vertex has none), then the extra rows Et (fixed-face paths that are ordered with
  // the vertex rows), then the cycle rows Ct (last). `analysis`, if given, is asked for a symbolic
  // factorization once A W Aᵀ is assembled; it is used if it was made for this pattern.
  CholeskyEngine(const EdgeEnds& ends, int num_vertex_rows, const SparseMatrix& Et, const SparseMatrix& Ct, const Eigen::VectorXd& w_,
                 SetupTimings& timings, const std::function<std::unique_ptr<SolverAnalysis::Impl>()>& analysis = {})
      : w(w_) {
    m = static_cast<int>(ends.size()), nD = num_vertex_rows + static_cast<int>(Et.cols()), nC = static_cast<int>(Ct.cols());
    const int n = nD + nC;
    try {
      auto t0 = Clock::now();
      Csc M = normal_matrix(ends, num_vertex_rows, Et, Ct, w, edge_rows_);
      timings.assemble += seconds_since(t0);
      if (n == 0) return;
      if (analysis) {
        t0 = Clock::now();
        adopt(M, analysis());
        timings.analysis_wait += seconds_since(t0);
        timings.analysis_adopted = analysis_adopted;
      }
      t0 = Clock::now();
      factorize(M);
      timings.factor += seconds_since(t0);
      t0 = Clock::now();
      prepare_schur();
      timings.schur += seconds_since(t0);
    } catch (...) {  // the destructor does not run for an object whose constructor throws
      release();
      throw;
    }
  }
  ~CholeskyEngine() override { release(); }
  void release() {
    if (factor) cholmod_free_factor(&factor, &cc());
  }

  // Takes a symbolic factorization made for exactly this pattern (compared entry by entry; a different
  // one is dropped and the factorization analyses its own).
  void adopt(const Csc& M, std::unique_ptr<SolverAnalysis::Impl> given) {
    if (!given || !given->factor || given->nD != nD || given->nC != nC || given->outer != M.outer || given->inner != M.inner) return;
    factor = given->factor, given->factor = nullptr;
    cholmod_ = std::move(given);
    std::vector<int>().swap(cholmod_->outer), std::vector<int>().swap(cholmod_->inner);  // compared: not needed any more
    analysis_adopted = true;
  }

  void factorize(Csc& M) {
    const int n = nD + nC;
    if (!factor) factor = symbolic(M, vertex_order(M, nD, nC, cc()), nD, nC, cc());
    const int* perm = static_cast<const int*>(factor->Perm);
    if (supernodal::factorize(*factor, M.outer, M.inner, M.values, cc()) < n) {
      const int row = static_cast<int>(factor->minor);
      throw Error(row < n && perm[row] >= nD
                      ? "the holonomy of the generators, boundary loops or fixed-direction paths cannot be controlled independently "
                        "with these weights (the constraint system is singular); try --weights unit"
                      : "the constraint system is not positive definite with these weights; try --weights unit");
    }
    check(cc().status == CHOLMOD_OK && factor->is_super && factor->is_ll, "CHOLMOD factorization failed");
    for (int k = nD; k < n; ++k) check(perm[k] == k, "CHOLMOD did not keep the cycle rows last");
    prepare_sparse_forward();
  }

  // R_CC and its inverse: the Schur complement's factor, for choosing free cycle indices.
  void prepare_schur() {
    extract_cycle_block();
    if (nC > 0) {
      const double min_diag = R_CC.diagonal().minCoeff(), max_diag = R_CC.diagonal().maxCoeff();
      if (!(min_diag > 1e-8 * max_diag))
        throw Error("the holonomy of the generators, boundary loops or fixed-direction paths is nearly undetermined with these weights "
                    "(ill-conditioned Schur complement); try --weights unit");
      R_inv = R_CC.triangularView<Eigen::Lower>().solve(Eigen::MatrixXd::Identity(nC, nC));
      P_diagonal = R_inv.colwise().squaredNorm().transpose();
    }
  }

  std::string ordering() const override { return nC > 0 ? "CAMD" : "AMD"; }

  void check(bool ok, const char* what) const {
    if (!ok) throw Error(std::string(what) + " (CHOLMOD status " + std::to_string(cc().status) + ")");
  }

  // Supernodal elimination tree and the factor position of each row, for forward_update.
  void prepare_sparse_forward() {
    const int n = nD + nC;
    const int* perm = static_cast<const int*>(factor->Perm);
    position_.resize(n);
    for (int k = 0; k < n; ++k) position_[perm[k]] = k;
    const Supernodes L(factor);
    super_of_col_ = L.owners();
    super_parent_ = supernodal::supernode_parents(L, super_of_col_);
    super_stamp_.assign(L.count, -1);
    for (int& r : edge_rows_.row) r = position_[r];
    plan_backward();
  }

  // Splits the supernodal elimination tree for a backward substitution on two threads, balanced by
  // the factor's entries (see supernodal::split_tree), each list in decreasing order.
  void plan_backward() {
    const Supernodes L(factor);
    std::vector<double> entries(L.count);
    for (int s = 0; s < L.count; ++s) entries[s] = static_cast<double>(L.height(s)) * L.cols(s);
    supernodal::TreeSplit split = supernodal::split_tree(super_parent_, entries, 1e4);
    backward_top_.assign(split.top.rbegin(), split.top.rend());
    for (int k = 0; k < 2; ++k) backward_part_[k].assign(split.part[k].rbegin(), split.part[k].rend());
  }

  // z ← L⁻ᵀ z (in factor order): the top supernodes, then the two parts of the tree concurrently.
  // Each supernode s solves its columns given its rows below, which belong to its ancestors: done
  // before it (the top) or earlier in its own part (decreasing order).
  void backward(Eigen::VectorXd& z) const {
    const Supernodes L(factor);
    auto solve_supernodes = [&](const std::vector<int>& list) {
      Eigen::VectorXd below;
      for (int s : list) {
        const int ncol = L.cols(s), nrow = L.height(s);
        const auto Ls = L.values(s);
        auto block = z.segment(L.first(s), ncol);
        if (nrow > ncol) {
          below.resize(nrow - ncol);
          for (int i = 0; i < nrow - ncol; ++i) below(i) = z(L.row(s, ncol + i));
          block.noalias() -= Ls.bottomRows(nrow - ncol).transpose() * below;
        }
        Ls.topRows(ncol).triangularView<Eigen::Lower>().transpose().solveInPlace(block);
      }
    };
    solve_supernodes(backward_top_);
#pragma omp parallel for schedule(static, 1) num_threads(std::min(2, omp_get_max_threads())) if (!backward_part_[1].empty())
    for (int k = 0; k < 2; ++k) solve_supernodes(backward_part_[k]);
  }

  // z += L⁻¹ d for d with the few nonzeros `entries` (factor positions, values): only the supernodes on
  // the paths from those entries to the root of the elimination tree are touched, in increasing order.
  void forward_update(const std::vector<std::pair<int, double>>& entries, Eigen::VectorXd& z) const {
    const Supernodes L(factor);
    ++stamp_;
    std::vector<int> path;
    for (const auto& [k, value] : entries)
      for (int s = super_of_col_[k]; s != -1 && super_stamp_[s] != stamp_; s = super_parent_[s]) super_stamp_[s] = stamp_, path.push_back(s);
    std::sort(path.begin(), path.end());
    Eigen::VectorXd& d = forward_work_;  // zero outside a call
    if (d.size() != z.size()) d.setZero(z.size());
    for (const auto& [k, value] : entries) d(k) += value;
    Eigen::VectorXd below;
    for (int s : path) {
      const int ncol = L.cols(s), nrow = L.height(s);
      const auto Ls = L.values(s);
      auto block = d.segment(L.first(s), ncol);
      Ls.topRows(ncol).triangularView<Eigen::Lower>().solveInPlace(block);
      if (nrow == ncol) continue;
      below.noalias() = Ls.bottomRows(nrow - ncol) * block;
      for (int i = 0; i < nrow - ncol; ++i) d(L.row(s, ncol + i)) -= below(i);
    }
    // Every entry touched lies in the columns of the path's supernodes (the rows below a supernode are
    // columns of its ancestors): add them to z and zero them again.
    for (int s : path) {
      auto touched = d.segment(L.first(s), L.cols(s));
      z.segment(L.first(s), L.cols(s)) += touched;
      touched.setZero();
    }
  }

  // R_CC: the factor's entries at rows and columns ≥ nD (in factor order), read from the supernodes.
  void extract_cycle_block() {
    R_CC = Eigen::MatrixXd::Zero(nC, nC);
    if (nC == 0) return;
    const Supernodes L(factor);
    for (int s = 0; s < L.count; ++s) {
      const auto Ls = L.values(s);
      for (int c = 0; c < L.cols(s); ++c) {
        const int col = L.first(s) + c;
        if (col < nD) continue;
        for (int r = c; r < L.height(s); ++r) R_CC(L.row(s, r) - nD, col - nD) = Ls(r, c);
      }
    }
  }

  // L⁻¹ b by CHOLMOD (in factor order), for a right-hand side that is not an update of the base one.
  Eigen::VectorXd lower_solve(const Eigen::VectorXd& b) const {
    cholmod_dense B{};
    B.nrow = b.size(), B.ncol = 1, B.nzmax = b.size(), B.d = b.size();
    B.x = const_cast<double*>(b.data());
    B.xtype = CHOLMOD_REAL, B.dtype = CHOLMOD_DOUBLE;
    cholmod_dense* X = cholmod_solve(CHOLMOD_L, factor, &B, &cc());
    check(X != nullptr && cc().status == CHOLMOD_OK, "CHOLMOD solve failed");
    Eigen::VectorXd out = Eigen::Map<Eigen::VectorXd>(static_cast<double*>(X->x), b.size());
    cholmod_free_dense(&X, &cc());
    return out;
  }
  // L⁻¹ Π [b_D; 0]: the forward substitution with the cycle right-hand sides zero.
  Eigen::VectorXd forward(const Eigen::VectorXd& b_D) const {
    Eigen::VectorXd permuted = Eigen::VectorXd::Zero(nD + nC);
    for (int r = 0; r < nD; ++r) permuted(position_[r]) = b_D(r);
    return lower_solve(permuted);
  }

  void set_base_rhs(const Eigen::VectorXd& b_D) override {
    if (nD + nC == 0) return;
    base_b_ = b_D;
    base_z_ = forward(b_D);
  }

  Eigen::VectorXd apply_P(const Eigen::VectorXd& v) const override {
    const Eigen::VectorXd r = R_inv.triangularView<Eigen::Lower>() * v;
    return R_inv.triangularView<Eigen::Lower>().transpose() * r;
  }
  Eigen::VectorXd P_column(int i) const override {
    Eigen::VectorXd r = Eigen::VectorXd::Zero(nC);
    r.tail(nC - i) = R_inv.col(i).tail(nC - i);
    return R_inv.triangularView<Eigen::Lower>().transpose() * r;
  }
  Eigen::MatrixXd dense_P() const override { return R_inv.transpose() * R_inv.triangularView<Eigen::Lower>(); }
  const Eigen::MatrixXd& P_factor(bool& lower) const override {
    lower = true;
    return R_inv;
  }

  Eigen::VectorXd solve(const Eigen::VectorXd& b_D, const CycleRhsChooser& choose) const override {
    const int n = nD + nC;
    if (n == 0) return Eigen::VectorXd::Zero(m);
    // Forward substitution with b_C = 0: z_D is final; z_C = z_C0 + R_CC⁻¹ b_C for any b_C (the cycle
    // rows come last, in their own order, so positions ≥ nD of Πb are b_C). When b_D differs from the
    // base in few rows, z = base_z + L⁻¹ Π (b_D − base_b) touches only their paths in the tree.
    Eigen::VectorXd z;
    std::vector<std::pair<int, double>> changed;
    if (base_b_.size() == b_D.size()) {
      for (int r = 0; r < nD && changed.size() * 64 <= static_cast<size_t>(n); ++r)
        if (b_D(r) != base_b_(r)) changed.emplace_back(position_[r], b_D(r) - base_b_(r));
    }
    if (base_b_.size() == b_D.size() && changed.size() * 64 <= static_cast<size_t>(n)) {
      z = base_z_;
      forward_update(changed, z);
    } else {
      z = forward(b_D);
    }
    if (nC > 0) {
      const Eigen::VectorXd z_C0 = z.tail(nC);
      const Eigen::VectorXd b_C = choose(-(R_CC * z_C0));  // the energy ‖z‖² is least at b_C = −R_CC z_C0
      z.tail(nC) = z_C0 + R_CC.triangularView<Eigen::Lower>().solve(b_C);
    }
    Eigen::VectorXd& y = z;  // [λ; μ] in factor order
    backward(y);
    Eigen::VectorXd x(m);
#pragma omp parallel for schedule(static) if (m > kParallelEdits)
    for (int a = 0; a < m; ++a) {
      double sum = 0;
      for (int k = edge_rows_.start[a]; k < edge_rows_.start[a + 1]; ++k) sum += edge_rows_.coefficient[k] * y(edge_rows_.row[k]);
      x(a) = w(a) * sum;
    }
    return x;
  }
};

// SuiteSparseQR factorization of (A W^½)ᵀ; min-norm solves x = W^½ Q R⁻ᵀ Eᵀ b (as SPQR's min2norm).
struct QREngine : ConnectionSolver::Engine {
  mutable cholmod_common cc;
  SuiteSparseQR_factorization<double>* qr = nullptr;
  Eigen::VectorXd sqrt_w;
  int nD = 0, nC = 0, m = 0;
  Eigen::MatrixXd responses;  // y for each unit C right-hand side (m × nC)
  Eigen::MatrixXd P;

  Eigen::VectorXd apply_P(const Eigen::VectorXd& v) const override { return P * v; }
  Eigen::VectorXd P_column(int i) const override { return P.col(i); }
  Eigen::MatrixXd dense_P() const override { return P; }
  Eigen::MatrixXd P_lower;  // P = P_lowerᵀ P_lower
  const Eigen::MatrixXd& P_factor(bool& lower) const override {
    lower = true;
    return P_lower;
  }

  QREngine(const SparseMatrix& Dt, const SparseMatrix& Ct, const Eigen::VectorXd& w, SetupTimings& timings) {
    cholmod_l_start(&cc);
    cc.print = 0;
    try {
      set_up(Dt, Ct, w, timings);
    } catch (...) {  // the destructor does not run for an object whose constructor throws
      release();
      throw;
    }
  }
  ~QREngine() override { release(); }
  void release() {
    if (qr) SuiteSparseQR_free<double>(&qr, &cc);
    cholmod_l_finish(&cc);
  }
  void set_up(const SparseMatrix& Dt, const SparseMatrix& Ct, const Eigen::VectorXd& w, SetupTimings& timings) {
    auto t0 = Clock::now();
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
    P_diagonal = P.diagonal();
    if (nC > 0) {
      // P = Tᵀ T with T lower triangular, as the Cholesky route has it (R_CC⁻¹): the Cholesky factor of P
      // with rows and columns reversed, reversed back.
      const Eigen::MatrixXd reversed = P.reverse();
      Eigen::LLT<Eigen::MatrixXd> llt(reversed);
      if (llt.info() != Eigen::Success) throw Error("the cycle rows of the constraint system are dependent; try --weights unit");
      P_lower = Eigen::MatrixXd(llt.matrixU()).reverse();
    }
    timings.schur += seconds_since(t0);
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
  Eigen::VectorXd solve(const Eigen::VectorXd& b_D, const CycleRhsChooser& choose) const override {
    Eigen::VectorXd b = Eigen::VectorXd::Zero(nD + nC);
    b.head(nD) = b_D;
    if (nC > 0) {
      // The energy is ‖y‖²; its gradient in b_C at b_C = 0 is 2 λ_C = 2 responsesᵀ y.
      const Eigen::VectorXd gradient = responses.transpose() * min_norm_y(b);
      b.tail(nC) = choose(-P.ldlt().solve(gradient));
    }
    return sqrt_w.asDiagonal() * min_norm_y(b);
  }
};

// Rounds the real minimiser u of ‖T (u − n)‖² to integers one coordinate at a time, each given the
// ones already rounded and with the others still real (Babai's nearest plane): with T lower triangular
// from the first coordinate on, with T upper triangular from the last one back.
Eigen::VectorXi babai_round(const Eigen::MatrixXd& T, bool lower, const Eigen::VectorXd& u) {
  const int k = static_cast<int>(u.size());
  Eigen::VectorXi n(k);
  Eigen::VectorXd v(k);  // u − n of the coordinates already rounded
  // Halves round up, with a margin, so that routes whose round-off differs choose alike on exact ties.
  auto round = [](double x) { return static_cast<int>(std::floor(x + 0.5 + 1e-7)); };
  for (int step = 0; step < k; ++step) {
    const int i = lower ? step : k - 1 - step;
    const double shift = lower ? T.row(i).head(i).dot(v.head(i)) : T.row(i).tail(k - 1 - i).dot(v.tail(k - 1 - i));
    n(i) = round(u(i) + shift / T(i, i));
    v(i) = u(i) - n(i);
  }
  return n;
}

// Minimises (u − n₀ − M t)ᵀ P (u − n₀ − M t) over integer t: Babai rounding of the real minimiser, then
// single ±1 steps while they lower the value. When every cycle row is free (M = I, the usual case of
// editing singularities) this costs O(|C|²) per step through the engine's P products; otherwise P is formed.
Eigen::VectorXi nearest_lattice_point(const ConnectionSolver::Engine& engine, const Eigen::VectorXd& u, const Eigen::VectorXd& n0,
                                      const Eigen::MatrixXd& M, bool identity) {
  const int k = static_cast<int>(M.cols());
  Eigen::VectorXi t = Eigen::VectorXi::Zero(k);
  if (k == 0) return t;
  Eigen::MatrixXd Q;
  Eigen::VectorXd g, diagonal;  // g: half the gradient at t
  if (identity) {
    bool lower = true;
    const Eigen::MatrixXd& T = engine.P_factor(lower);
    t = babai_round(T, lower, u);
    g = engine.apply_P(t.cast<double>() - u);
    diagonal = engine.P_diagonal;
  } else {
    const Eigen::MatrixXd PM = engine.dense_P() * M;
    Q = M.transpose() * PM;
    const Eigen::VectorXd rhs = PM.transpose() * (u - n0);
    const Eigen::LLT<Eigen::MatrixXd> llt(Q);
    const Eigen::VectorXd real_opt = llt.solve(rhs);
    t = babai_round(llt.matrixU(), false, real_opt);
    g = Q * t.cast<double>() - rhs;
    diagonal = Q.diagonal();
  }
  const double tolerance = 1e-12 * std::max(1.0, diagonal.maxCoeff());
  for (int pass = 0; pass < 1000; ++pass) {
    bool improved = false;
    for (int i = 0; i < k; ++i) {
      for (int d : {1, -1}) {
        if (2 * d * g(i) + diagonal(i) < -tolerance) {
          t(i) += d;
          g += d * (identity ? engine.P_column(i) : Eigen::VectorXd(Q.col(i)));
          improved = true;
        }
      }
    }
    if (!improved) break;
  }
  return t;
}


// Which rows the reduced system has (see trivcon/solver.h): per component the dropped vertex (closed
// component: its largest interior vertex) or loop (with boundary: the longest loop, ties to the smallest
// id), and the row of each other interior vertex.
struct RowLayout {
  std::vector<int> vertex_row, dropped_vertex, dropped_loop;
  int num_vertex_rows = 0;
};
RowLayout row_layout(const Topology& t) {
  RowLayout r;
  r.vertex_row.assign(t.num_vertices, -1);
  r.dropped_vertex.assign(t.components.size(), -1);
  r.dropped_loop.assign(t.components.size(), -1);
  for (size_t c = 0; c < t.components.size(); ++c)
    for (int l : t.components[c].boundary_loops)
      if (r.dropped_loop[c] < 0 || t.boundary_loops[l].size() > t.boundary_loops[r.dropped_loop[c]].size()) r.dropped_loop[c] = l;
  for (int v = t.num_vertices - 1; v >= 0; --v) {
    if (!t.is_interior_vertex(v)) continue;
    const int c = t.vertex_component[v];
    if (t.components[c].boundary_loops.empty() && r.dropped_vertex[c] < 0) r.dropped_vertex[c] = v;
  }
  for (int v = 0; v < t.num_vertices; ++v)
    if (t.is_interior_vertex(v) && r.dropped_vertex[t.vertex_component[v]] != v) r.vertex_row[v] = r.num_vertex_rows++;
  return r;
}
// The boundary loops that have a row, in id order.
std::vector<int> loop_rows(const Topology& t, const std::vector<int>& dropped_loop) {
  std::vector<int> loops;
  for (size_t l = 0; l < t.boundary_loops.size(); ++l)
    if (dropped_loop[t.vertex_component[t.boundary_loops[l][0]]] != static_cast<int>(l)) loops.push_back(static_cast<int>(l));
  return loops;
}
// The edges that are columns of A, and each edge's column (−1: none). The Cholesky route takes every
// interior edge: a zero weight gives an entry of zero, which keeps A W Aᵀ's pattern that of the mesh
// whatever the geometry (SolverAnalysis relies on it); the QR route takes the edges of positive weight.
void system_edges(const Topology& t, const Eigen::VectorXd* positive_only, std::vector<int>& edges, std::vector<int>& column) {
  edges.clear();
  column.assign(t.num_edges, -1);
  for (int e = 0; e < t.num_edges; ++e)
    if (positive_only ? (*positive_only)(e) > 0 : !t.is_boundary_edge(e)) column[e] = static_cast<int>(edges.size()), edges.push_back(e);
}
EdgeEnds edge_ends(const Topology& t, const std::vector<int>& edges, const std::vector<int>& vertex_row) {
  EdgeEnds ends(edges.size());
  for (size_t a = 0; a < edges.size(); ++a)
    for (int end = 0; end < 2; ++end) ends[a][end] = vertex_row[t.edge_vertices(edges[a], end)];
  return ends;
}
// Cycles (or paths) as the sparse columns of Aᵀ (m × count); repeated edges of a cycle are summed.
SparseMatrix cycle_columns(int m, const std::vector<int>& column, int count, const std::function<const DualCycle&(int)>& cycle) {
  std::vector<Triplet> trip;
  for (int r = 0; r < count; ++r) {
    const DualCycle& c = cycle(r);
    for (size_t k = 0; k < c.edges.size(); ++k)
      if (column[c.edges[k]] >= 0) trip.emplace_back(column[c.edges[k]], r, c.signs[k]);
  }
  SparseMatrix S(m, count);
  S.setFromTriplets(trip.begin(), trip.end());
  return S;
}

}  // namespace

SolverAnalysis::SolverAnalysis(const Topology& t, const Cycles& cycles) : impl_(std::make_unique<Impl>()) {
  const auto t0 = Clock::now();
  const RowLayout layout = row_layout(t);
  std::vector<int> edges, column;
  system_edges(t, nullptr, edges, column);
  std::vector<const DualCycle*> rows;
  for (int l : loop_rows(t, layout.dropped_loop)) rows.push_back(&cycles.loops[l]);
  for (const DualCycle& g : cycles.generators) rows.push_back(&g);
  const int m = static_cast<int>(edges.size());
  const SparseMatrix Ct = cycle_columns(m, column, static_cast<int>(rows.size()), [&](int r) -> const DualCycle& { return *rows[r]; });
  EdgeRows edge_rows;
  Csc M = normal_matrix(edge_ends(t, edges, layout.vertex_row), layout.num_vertex_rows, SparseMatrix(m, 0), Ct, Eigen::VectorXd::Ones(m),
                        edge_rows);
  Impl& a = *impl_;
  a.nD = layout.num_vertex_rows, a.nC = static_cast<int>(rows.size());
  if (a.nD + a.nC > 0) a.factor = symbolic(M, vertex_order(M, a.nD, a.nC, a.cc), a.nD, a.nC, a.cc);
  a.outer = std::move(M.outer), a.inner = std::move(M.inner);
  a.seconds = seconds_since(t0);
}
SolverAnalysis::~SolverAnalysis() = default;
SolverAnalysis::SolverAnalysis(SolverAnalysis&&) noexcept = default;
SolverAnalysis& SolverAnalysis::operator=(SolverAnalysis&&) noexcept = default;
double SolverAnalysis::seconds() const { return impl_ ? impl_->seconds : 0; }

ConnectionSolver::ConnectionSolver(const Topology& topology, const Geometry& geometry, const Cycles& cycles, SolverOptions options,
                                   const std::vector<int>& fixed_faces, const std::function<SolverAnalysis()>& analysis)
    : topology_(topology), geometry_(geometry), cycles_(cycles), options_(options) {
  const Topology& t = topology;
  const int nV = t.num_vertices, nE = t.num_edges;
  auto t0 = Clock::now();
  weights_.setZero(nE);
  for (int e = 0; e < nE; ++e)
    if (!t.is_boundary_edge(e)) weights_(e) = options.weights == WeightKind::Unit ? 1.0 : geometry.cotan_weight(e);
  for (size_t l = 0; l < t.boundary_loops.size(); ++l) loop_curvature_.push_back(loop_curvature(t, geometry, static_cast<int>(l)));
  for (const DualCycle& g : cycles.generators) generator_holonomy_.push_back(levi_civita_holonomy(g, geometry));
  fixed_faces_ = fixed_faces;
  std::sort(fixed_faces_.begin(), fixed_faces_.end());
  fixed_faces_.erase(std::unique(fixed_faces_.begin(), fixed_faces_.end()), fixed_faces_.end());
  for (int f : fixed_faces_)
    if (f < 0 || f >= t.num_faces)
      throw Error("fixed face " + std::to_string(f) + " out of range (mesh has " + std::to_string(t.num_faces) + " faces)");
  if (!fixed_faces_.empty()) {
    std::vector<char> usable(nE, 0);
    for (int e = 0; e < nE; ++e) usable[e] = weights_(e) > 0;
    paths_ = fixed_face_paths(t, fixed_faces_, usable);
    for (const FixedPath& path : paths_) path_holonomy_.push_back(levi_civita_holonomy(path.path, geometry));
  }

  // A cycle or fixed-face path made only of zero-weight edges could not turn the field at all; its edges
  // get a small positive weight (1e-6 × the median positive weight), so that it turns there only when
  // nothing else can.
  double epsilon = 1e-6;
  {
    std::vector<double> positive;
    positive.reserve(nE);
    for (int e = 0; e < nE; ++e)
      if (weights_(e) > 0) positive.push_back(weights_(e));
    if (!positive.empty()) {
      std::nth_element(positive.begin(), positive.begin() + positive.size() / 2, positive.end());
      epsilon = 1e-6 * positive[positive.size() / 2];
    }
    auto regularize = [&](const DualCycle& c) {
      if (std::any_of(c.edges.begin(), c.edges.end(), [&](int e) { return weights_(e) > 0; })) return;
      for (int e : c.edges) weights_(e) = epsilon, ++regularized_edges_;
    };
    for (const DualCycle& c : cycles.loops) regularize(c);
    for (const DualCycle& c : cycles.generators) regularize(c);
    for (const FixedPath& p : paths_) regularize(p.path);
  }

  // Vertex rows (one dropped per closed component), loop rows (one dropped per component with
  // boundary), generator rows.
  RowLayout layout = row_layout(t);
  vertex_row_ = std::move(layout.vertex_row), dropped_vertex_ = std::move(layout.dropped_vertex);
  dropped_loop_ = std::move(layout.dropped_loop), num_vertex_rows_ = layout.num_vertex_rows;
  // Cycle rows, fixed-face paths first: free indices are rounded in this order (see nearest_lattice_point),
  // and a path between nearby fixed faces is well determined, while a loop or generator index is only
  // determined once the paths around it are.
  // Many fixed faces (e.g. a whole aligned boundary) would make the dense block large: then the Cholesky
  // route orders the path rows with the vertex rows (sparse, fill-reducing) and rounds their turns
  // from the field without them (see solve()).
  sparse_paths_ = options.solver == SolverKind::Cholesky && static_cast<int>(paths_.size()) > kMaxDensePaths;
  if (!sparse_paths_)
    for (int k = 0; k < static_cast<int>(paths_.size()); ++k) rows_.push_back({RowKind::Path, k});
  for (int l : loop_rows(t, dropped_loop_)) rows_.push_back({RowKind::Loop, l});
  for (int g = 0; g < num_generators(); ++g) rows_.push_back({RowKind::Generator, g});

  connect_isolated_vertices(epsilon);
  system_edges(t, options.solver == SolverKind::QR ? &weights_ : nullptr, active_edges_, edge_column_);

  const int m = static_cast<int>(active_edges_.size());
  const int nC = static_cast<int>(rows_.size());
  // The vertex rows of A as the rows of each edge's ends; the cycle and path rows as sparse columns.
  const EdgeEnds ends = edge_ends(t, active_edges_, vertex_row_);
  const SparseMatrix Ct = cycle_columns(m, edge_column_, nC, [&](int r) -> const DualCycle& { return cycle_of_row(r); });
  Eigen::VectorXd w(m);
  for (int a = 0; a < m; ++a) w(a) = weights_(active_edges_[a]);
  timings_.assemble += seconds_since(t0);
  if (options.solver == SolverKind::QR) {
    SparseMatrix Dt(m, num_vertex_rows_);
    std::vector<Triplet> trip;
    for (int a = 0; a < m; ++a)
      for (int end = 0; end < 2; ++end)
        if (ends[a][end] >= 0) trip.emplace_back(a, ends[a][end], end == 0 ? -1.0 : 1.0);
    Dt.setFromTriplets(trip.begin(), trip.end());
    engine_ = std::make_unique<QREngine>(Dt, Ct, w, timings_);
  } else if (!sparse_paths_) {
    // A symbolic factorization made beforehand fits the system without fixed faces only.
    std::function<std::unique_ptr<SolverAnalysis::Impl>()> given;
    if (analysis && paths_.empty()) given = [&analysis] { return std::move(analysis().impl_); };
    engine_ = std::make_unique<CholeskyEngine>(ends, num_vertex_rows_, SparseMatrix(m, 0), Ct, w, timings_, given);
  } else {
    // The vertex rows alone (for the field without path constraints), and vertex + path rows together.
    const SparseMatrix Et =
        cycle_columns(m, edge_column_, static_cast<int>(paths_.size()), [&](int k) -> const DualCycle& { return paths_[k].path; });
    relaxed_engine_ = std::make_unique<CholeskyEngine>(ends, num_vertex_rows_, SparseMatrix(m, 0), SparseMatrix(m, 0), w, timings_);
    engine_ = std::make_unique<CholeskyEngine>(ends, num_vertex_rows_, Et, Ct, w, timings_);
  }
  t0 = Clock::now();
  Eigen::VectorXd base(num_vertex_rows_);
  for (int v = 0; v < nV; ++v)
    if (vertex_row_[v] >= 0) base(vertex_row_[v]) = geometry.angle_defect(v);
  if (relaxed_engine_) relaxed_engine_->set_base_rhs(base);
  base.conservativeResize(num_vertex_rows_ + (sparse_paths_ ? static_cast<Eigen::Index>(paths_.size()) : 0));
  base.tail(base.size() - num_vertex_rows_).setZero();
  engine_->set_base_rhs(base);
  timings_.schur += seconds_since(t0);
}

ConnectionSolver::~ConnectionSolver() = default;

std::string ConnectionSolver::ordering() const { return engine_ ? engine_->ordering() : ""; }

const DualCycle& ConnectionSolver::cycle_of_row(int r) const {
  const Row& row = rows_[r];
  return row.kind == RowKind::Loop ? cycles_.loops[row.id] : row.kind == RowKind::Generator ? cycles_.generators[row.id] : paths_[row.id].path;
}

// Every vertex row must reach a boundary vertex or the dropped vertex of its component through edges of
// positive weight; otherwise the Laplacian is singular and the vertex's curvature has nowhere to go
// (e.g. a vertex surrounded by zero-area faces only). The zero-weight edges at such vertices get the
// small weight `epsilon`, repeatedly, until every vertex row is reached.
void ConnectionSolver::connect_isolated_vertices(double epsilon) {
  const Topology& t = topology_;
  // Through interior edges every vertex reaches the boundary or its component's dropped vertex (an edge
  // with an interior end is interior), so only zero weights can cut a vertex off.
  bool any_zero = false;
  for (int e = 0; e < t.num_edges && !any_zero; ++e) any_zero = !t.is_boundary_edge(e) && weights_(e) == 0;
  if (!any_zero) return;
  // Breadth-first search from the grounded vertices through edges of positive weight; each round gives
  // the zero-weight edges of the vertices it did not reach a small weight and carries the search on.
  std::vector<char> grounded(t.num_vertices, 0);
  std::vector<int> queue;
  for (int v = 0; v < t.num_vertices; ++v)
    if (t.is_boundary_vertex(v)) grounded[v] = 1, queue.push_back(v);
  for (int v : dropped_vertex_)
    if (v >= 0 && !grounded[v]) grounded[v] = 1, queue.push_back(v);
  size_t searched = 0;
  auto search = [&] {
    for (; searched < queue.size(); ++searched) {
      const int v = queue[searched];
      for (int a = t.vertex_edge_offsets[v]; a < t.vertex_edge_offsets[v + 1]; ++a) {
        const int e = t.vertex_edges[a];
        if (!(weights_(e) > 0)) continue;
        const int u = t.edge_vertices(e, 0) == v ? t.edge_vertices(e, 1) : t.edge_vertices(e, 0);
        if (!grounded[u]) grounded[u] = 1, queue.push_back(u);
      }
    }
  };
  search();
  std::vector<int> isolated_vertices;
  for (int v = 0; v < t.num_vertices; ++v)
    if (vertex_row_[v] >= 0 && !grounded[v]) isolated_vertices.push_back(v);
  while (!isolated_vertices.empty()) {
    int added = 0;
    for (int v : isolated_vertices) {
      for (int a = t.vertex_edge_offsets[v]; a < t.vertex_edge_offsets[v + 1]; ++a) {
        const int e = t.vertex_edges[a];
        if (t.is_boundary_edge(e) || weights_(e) != 0) continue;
        weights_(e) = epsilon, ++added;
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
    regularized_edges_ += added;
    search();
    std::vector<int> still;
    for (int v : isolated_vertices)
      if (!grounded[v]) still.push_back(v);
    isolated_vertices.swap(still);
  }
}

Connection ConnectionSolver::solve(const IndexPrescription& prescription) const {
  const Topology& t = topology_;
  validate_prescription(t, num_generators(), prescription);
  if (prescription.fixed.size() != fixed_faces_.size() ||
      !std::equal(fixed_faces_.begin(), fixed_faces_.end(), prescription.fixed.begin(), [](int f, const auto& kv) { return f == kv.first; }))
    throw Error("the fixed faces of the prescription (" + std::to_string(prescription.fixed.size()) + ") are not those the solver was set up with (" +
                std::to_string(fixed_faces_.size()) + "): fixing other faces changes the matrix, set up a new solver");
  for (auto [f, angle] : prescription.fixed)
    if (!std::isfinite(angle)) throw Error("fixed angle of face " + std::to_string(f) + " is not finite");
  const int N = prescription.N;
  const double step = 2 * kPi / N;
  auto path_holonomy = [&](int k) {  // what the x along path k must add up to, before the 2π/N turns
    const FixedPath& path = paths_[k];
    return path_holonomy_[k] - (prescription.fixed.at(path.to_face) - prescription.fixed.at(path.from_face));
  };
  Eigen::VectorXd b_D(num_vertex_rows_);
  for (int v = 0; v < t.num_vertices; ++v)
    if (vertex_row_[v] >= 0) b_D(vertex_row_[v]) = geometry_.angle_defect(v);
  for (auto [v, n] : prescription.vertex)
    if (vertex_row_[v] >= 0) b_D(vertex_row_[v]) -= step * n;

  // Cycle rows: the holonomy H they must match (their right-hand side is H − (2π/N) n), and which n are
  // free. Loops of a component must sum, with its vertex indices, to χ: the dropped loop takes the
  // remainder. If the dropped loop is prescribed, one free loop of the component ("pivot") takes it instead.
  const int nC = static_cast<int>(rows_.size());
  Eigen::VectorXd H(nC), n0 = Eigen::VectorXd::Zero(nC);
  std::vector<int> free_rows, loop_row_of(t.boundary_loops.size(), -1);
  std::vector<int> component_vertex_sum(t.components.size(), 0);
  for (auto [v, n] : prescription.vertex) component_vertex_sum[t.vertex_component[v]] += n;
  for (int r = 0; r < nC; ++r) {
    const Row& row = rows_[r];
    const std::map<int, int>* given = nullptr;
    if (row.kind == RowKind::Loop) {
      H(r) = loop_curvature_[row.id];
      loop_row_of[row.id] = r;
      given = &prescription.loop;
    } else if (row.kind == RowKind::Generator) {
      H(r) = generator_holonomy_[row.id];
      given = &prescription.generator;
    } else {  // transport from one fixed face to the next must turn γ_from onto γ_to
      H(r) = path_holonomy(row.id);
    }
    auto it = given ? given->find(row.id) : prescription.loop.end();
    if (given && it != given->end()) n0(r) = it->second;
    else free_rows.push_back(r);
  }
  std::vector<int> pivot_of_component(t.components.size(), -1);
  for (size_t c = 0; c < t.components.size(); ++c) {
    const int dl = dropped_loop_[c];
    if (dl < 0 || !prescription.loop.count(dl)) continue;
    int sum = N * t.components[c].euler_characteristic - component_vertex_sum[c] - prescription.loop.at(dl);
    for (int l : t.components[c].boundary_loops) {
      if (l == dl) continue;
      if (!prescription.loop.count(l) && pivot_of_component[c] < 0) pivot_of_component[c] = loop_row_of[l];
      else if (prescription.loop.count(l)) sum -= prescription.loop.at(l);
    }
    if (pivot_of_component[c] >= 0) n0(pivot_of_component[c]) = sum;
  }
  // Parametrisation n = n0 + M t of the free rows.
  std::vector<int> params;
  for (int r : free_rows)
    if (rows_[r].kind != RowKind::Loop || pivot_of_component[component_of_row(r)] != r) params.push_back(r);
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(nC, static_cast<Eigen::Index>(params.size()));
  for (size_t k = 0; k < params.size(); ++k) {
    const int r = params[k];
    M(r, k) = 1;
    if (rows_[r].kind == RowKind::Loop && pivot_of_component[component_of_row(r)] >= 0) M(pivot_of_component[component_of_row(r)], k) = -1;
  }
  const bool identity = static_cast<int>(params.size()) == nC;
  Eigen::VectorXd n_C = n0;
  Eigen::VectorXd n_E;  // path turns, when the path rows are sparse
  Eigen::VectorXd b_sparse = b_D;
  if (sparse_paths_) {
    // Each path's whole number of turns is rounded from the field without path constraints (and with
    // real-valued loop and generator holonomies): the vertex rows alone.
    const Eigen::VectorXd x0 = relaxed_engine_->solve(b_D, [](const Eigen::VectorXd& r0) { return r0; });
    const int nP = static_cast<int>(paths_.size());
    n_E.resize(nP);
    b_sparse.conservativeResize(num_vertex_rows_ + nP);
    for (int k = 0; k < nP; ++k) {
      const DualCycle& path = paths_[k].path;
      double along = 0;
      for (size_t i = 0; i < path.edges.size(); ++i)
        if (edge_column_[path.edges[i]] >= 0) along += path.signs[i] * x0(edge_column_[path.edges[i]]);
      const double h = path_holonomy(k);
      n_E(k) = std::floor((h - along) / step + 0.5 + 1e-7);
      b_sparse(num_vertex_rows_ + k) = h - step * n_E(k);
    }
  }
  const Eigen::VectorXd x_active = engine_->solve(b_sparse, [&](const Eigen::VectorXd& r0) {
    const Eigen::VectorXd u = (H - r0) / step;
    n_C += M * nearest_lattice_point(*engine_, u, n0, M, identity).cast<double>();
    return Eigen::VectorXd(H - step * n_C);
  });

  Connection result;
  result.N = N;
  result.x.setZero(t.num_edges);
  const int num_active = static_cast<int>(active_edges_.size());
#pragma omp parallel for schedule(static) if (num_active > kParallelEdits)
  for (int a = 0; a < num_active; ++a) result.x(active_edges_[a]) = x_active(a);
  const int nG = num_generators();
  result.generator_index.assign(nG, 0);
  result.generator_chosen.assign(nG, 0);
  result.loop_index.assign(t.boundary_loops.size(), 0);
  result.loop_chosen.assign(t.boundary_loops.size(), 0);
  result.path_turn.assign(paths_.size(), 0);
  double path_residual = 0;
  for (int k = 0; k < n_E.size(); ++k) {
    result.path_turn[k] = static_cast<int>(n_E(k));
    const DualCycle& path = paths_[k].path;
    double sum = 0;
    for (size_t i = 0; i < path.edges.size(); ++i) sum += path.signs[i] * result.x(path.edges[i]);
    path_residual = std::max(path_residual, std::abs(sum - (path_holonomy(k) - step * n_E(k))));
  }
  for (int r = 0; r < nC; ++r) {
    const Row& row = rows_[r];
    const int n = static_cast<int>(std::lround(n_C(r)));
    if (row.kind == RowKind::Loop) {
      result.loop_index[row.id] = n;
      result.loop_chosen[row.id] = !prescription.loop.count(row.id);
    } else if (row.kind == RowKind::Generator) {
      result.generator_index[row.id] = n;
      result.generator_chosen[row.id] = !prescription.generator.count(row.id);
    } else {
      result.path_turn[row.id] = n;
      const DualCycle& path = paths_[row.id].path;
      double sum = 0;
      for (size_t k = 0; k < path.edges.size(); ++k) sum += path.signs[k] * result.x(path.edges[k]);
      path_residual = std::max(path_residual, std::abs(sum - (H(r) - step * n)));
    }
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
  double energy = 0;
#pragma omp parallel for schedule(static) reduction(+ : energy) if (num_active > kParallelEdits)
  for (int a = 0; a < num_active; ++a) {
    const int e = active_edges_[a];
    if (weights_(e) > 0) energy += result.x(e) * result.x(e) / weights_(e);
  }
  result.energy = energy;

  IndexPrescription used = prescription;
  for (int g = 0; g < nG; ++g) used.generator[g] = result.generator_index[g];
  for (size_t l = 0; l < t.boundary_loops.size(); ++l) used.loop[static_cast<int>(l)] = result.loop_index[l];
  verify_connection(t, geometry_, cycles_, used, result, &loop_curvature_, &generator_holonomy_);
  result.max_cycle_residual = std::max(result.max_cycle_residual, path_residual);
  return result;
}

int ConnectionSolver::component_of_row(int r) const {
  const Row& row = rows_[r];
  if (row.kind == RowKind::Loop) return topology_.vertex_component[topology_.boundary_loops[row.id][0]];
  return row.kind == RowKind::Generator ? cycles_.generators[row.id].component : paths_[row.id].path.component;
}

void verify_connection(const Topology& t, const Geometry& geometry, const Cycles& cycles, const IndexPrescription& prescription,
                       Connection& connection, const std::vector<double>* loop_curvatures, const std::vector<double>* generator_holonomies) {
  const double step = 2 * kPi / prescription.N;
  const Eigen::VectorXd& x = connection.x;
  connection.max_vertex_residual = connection.max_cycle_residual = 0;
  connection.rhs_scale = 0;
  Eigen::VectorXd rhs_of = geometry.angle_defect;
  for (auto [v, n] : prescription.vertex)
    if (v >= 0 && v < t.num_vertices) rhs_of(v) -= step * n;
  // Per interior vertex (all of its edges are interior), Σ_e s_ve x_e against its right-hand side.
  double rhs_scale = 0, max_residual = 0;
#pragma omp parallel for schedule(static) reduction(max : rhs_scale, max_residual) if (t.num_vertices > kParallelEdits)
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
    double s = 0;
    for (size_t k = 0; k < cycle.edges.size(); ++k) s += cycle.signs[k] * x(cycle.edges[k]);
    const double rhs = holonomy - step * n;
    connection.rhs_scale = std::max(connection.rhs_scale, std::abs(rhs));
    connection.max_cycle_residual = std::max(connection.max_cycle_residual, std::abs(s - rhs));
  };
  for (size_t l = 0; l < cycles.loops.size(); ++l)
    check_cycle(cycles.loops[l], loop_curvatures ? (*loop_curvatures)[l] : loop_curvature(t, geometry, static_cast<int>(l)),
                prescription.loop.at(static_cast<int>(l)));
  for (size_t g = 0; g < cycles.generators.size(); ++g)
    check_cycle(cycles.generators[g], generator_holonomies ? (*generator_holonomies)[g] : levi_civita_holonomy(cycles.generators[g], geometry),
                prescription.generator.at(static_cast<int>(g)));
}

}  // namespace trivcon
