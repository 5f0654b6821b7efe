// SPDX-License-Identifier: MIT
// The Cholesky route of ConnectionSolver (src/connection/cholesky_engine.h).
#include "connection/cholesky_engine.h"

#include <Eigen/Dense>
#include <algorithm>
#include <memory>
#include <string>

#ifdef TRIVCON_WITH_SUITESPARSE
#include "linalg/cholmod.h"
#endif
#include "linalg/numeric_libraries.h"
#include "linalg/ordering.h"
#include "linalg/parallel.h"
#include "linalg/substitution.h"
#include "linalg/supernodal.h"
#include "linalg/symbolic.h"
#include "linalg/timing.h"
#include "trivcon/cancel.h"
#include "trivcon/error.h"

namespace trivcon::connection {

namespace {

// A fill-reducing order of the nD vertex rows of M (the nC cycle rows come last). Minimum degree (AMD;
// CAMD when there are cycle rows, constrained to order them last, so that it sees how they couple the
// vertices: fewer flops on meshes with many cycles), then postordered by the vertex block's elimination
// tree so that the analysis finds large supernodes without postordering the whole system (which could move
// the cycle rows). Not CHOLMOD's default choice, which tries METIS on large meshes: its analysis alone
// takes longer than the fill it saves. (A nested dissection by vertex coordinates, tried as a second
// candidate, cut the flops on smooth closed surfaces but not the time with AVX-512 BLAS kernels, and lost
// on scanned meshes.) The figures: BENCHMARKS.md, "What changed since the first measurement" and "Tried
// and dropped". libamd / libcamd with CHOLMOD's options give cholmod_amd's and cholmod_camd's orders
// (tests/test_symbolic.cpp).
std::vector<int> vertex_order(const Csc& M, int nD, int nC) {
  std::vector<int> order;
  if (nD == 0) return order;
  if (nC > 0) {
    std::vector<int> set(nD + nC, 0);
    std::fill(set.begin() + nD, set.end(), 1);
    order = linalg::camd_ordering(M.outer, M.inner, nD + nC, set);
    order.resize(nD);
    for (int k = 0; k < nD; ++k)
      if (order[k] >= nD) throw Error("internal: CAMD did not order the cycle rows last");
  } else {
    order = linalg::amd_ordering(M.outer, M.inner, nD);
  }
  const std::vector<int> post = linalg::postorder(linalg::elimination_tree(linalg::leading_block_pattern(M.outer, M.inner, nD), order));
  std::vector<int> postordered(nD);
  for (int k = 0; k < nD; ++k) postordered[k] = order[post[k]];
  return postordered;
}

// Symbolic analysis of the whole system: the vertex rows in `order`, then the cycle rows, not postordered
// again (that keeps the cycle rows last; the vertex order is postordered already).
linalg::SymbolicFactor symbolic(const Csc& M, std::vector<int> order, int nD, int nC) {
  const int n = nD + nC;
  for (int r = nD; r < n; ++r) order.push_back(r);
  linalg::SymbolicOptions options;
  options.postorder = false;
  return linalg::symbolic_analysis(M.outer, M.inner, n, order, options);
}

}  // namespace

void analyse(const Csc& M, int nD, int nC, AnalysisState& state) {
  if (nD + nC == 0) return;
  std::vector<int> order = vertex_order(M, nD, nC);
  check_cancelled();  // trivcon/cancel.h
  state.symbolic = symbolic(M, std::move(order), nD, nC);
  state.analysed = true;
}

namespace {

using linalg::Supernodes;

// See src/connection/cholesky_engine.h.
class CholeskyEngine : public SolverEngine {
 public:
  // The symbolic factorization (given, see adopt, or the engine's own) and the factor's values in its
  // supernodal blocks.
  std::unique_ptr<AnalysisState> analysis_ = std::make_unique<AnalysisState>();
  linalg::FactorValues<double> values_;
  const linalg::SymbolicFactor& symbolic_factor() const { return analysis_->symbolic; }
  Supernodes supernodes() const { return Supernodes(analysis_->symbolic, values_.data()); }
  Factorization factorization_;
  const char* numeric_by_ = "";  // who computed the factor's values (SetupTimings::numeric_factorization)
  bool analysis_adopted = false;
  Eigen::VectorXd w;
  int m = 0, nD = 0, nC = 0;
  // The constraint rows touching each system edge (column a of A); after the factorization, as
  // positions in factor order.
  EdgeRows edge_rows_;
  Eigen::MatrixXd R_CC, R_inv;  // lower triangular; P = R_invᵀ R_inv
  // Sparse forward substitution (see forward_update).
  std::vector<int> position_;  // factor position of each row of M (the inverse of the factor's perm)
  Eigen::VectorXd base_b_, base_z_;  // base right-hand side of the vertex rows, and L⁻¹ Π [base_b; 0]
  // Backward substitution on OpenMP's threads (src/linalg/substitution.h), planned once the factor has its values.
  std::unique_ptr<linalg::Substitution<double>> substitution_;

  // The rows of A (see normal_matrix): vertex rows given per system edge by the rows of its two ends (a
  // boundary or dropped vertex has none), then the extra rows Et (fixed-face paths that are ordered with
  // the vertex rows), then the cycle rows Ct (last). `analysis`, if given, is asked for a symbolic
  // factorization once A W Aᵀ is assembled; it is used if it was made for this pattern.
  CholeskyEngine(const EdgeEnds& ends, int num_vertex_rows, const SparseMatrix& Et, const SparseMatrix& Ct, const Eigen::VectorXd& w_,
                 Factorization factorization, SetupTimings& timings, const std::function<std::unique_ptr<AnalysisState>()>& analysis)
      : factorization_(factorization), w(w_) {
    linalg::check_numeric_libraries();
    m = static_cast<int>(ends.size()), nD = num_vertex_rows + static_cast<int>(Et.cols()), nC = static_cast<int>(Ct.cols());
    const int n = nD + nC;
    auto t0 = linalg::Clock::now();
    Csc M = normal_matrix(ends, num_vertex_rows, Et, Ct, w, edge_rows_);
    timings.assemble += linalg::seconds_since(t0);
    if (n == 0) return;
    check_cancelled();
    if (analysis) {
      t0 = linalg::Clock::now();
      adopt(M, analysis());
      timings.analysis_wait += linalg::seconds_since(t0);
      timings.analysis_adopted = analysis_adopted;
      check_cancelled();
    }
    t0 = linalg::Clock::now();
    factorize(M);
    timings.factor += linalg::seconds_since(t0);
    timings.numeric_factorization = numeric_by_;
    check_cancelled();
    t0 = linalg::Clock::now();
    prepare_schur();
    timings.schur += linalg::seconds_since(t0);
  }

  // Takes a symbolic factorization made for exactly this pattern (compared entry by entry; a different
  // one is dropped and the factorization analyses its own).
  void adopt(const Csc& M, std::unique_ptr<AnalysisState> given) {
    if (!given || !given->analysed || given->nD != nD || given->nC != nC || given->outer != M.outer || given->inner != M.inner) return;
    analysis_ = std::move(given);
    std::vector<int>().swap(analysis_->outer), std::vector<int>().swap(analysis_->inner);  // compared: not needed any more
    analysis_adopted = true;
  }

  // The numeric factorization into the symbolic factor: ours (OpenMP's threads) or CHOLMOD's own. Returns
  // the first column not positive definite, or n.
  int numeric(const Csc& M) {
    if (factorization_ == Factorization::Parallel) {
      numeric_by_ = "trivcon";
      return linalg::factorize(symbolic_factor(), values_, M.outer, M.inner, M.values);
    }
#ifdef TRIVCON_WITH_SUITESPARSE
    numeric_by_ = "cholmod";
    return cholmod_numeric(M);
#else
    throw Error("the cholmod factorization needs CHOLMOD, which this build of trivcon does not link (Debian's CHOLMOD contains "
                "GPL-licensed modules); rebuild with -DTRIVCON_WITH_SUITESPARSE=ON");
#endif
  }

#ifdef TRIVCON_WITH_SUITESPARSE
  // Factorization::Cholmod: cholmod_factorize into CHOLMOD's own factor, analysed by cholmod_analyze_p in the
  // same order without a postorder, which gives the same supernodal structure (tests/test_symbolic.cpp;
  // checked here array for array), then its values copied into values_.
  int cholmod_numeric(const Csc& M) {
    const linalg::SymbolicFactor& S = symbolic_factor();
    const int n = nD + nC;
    linalg::CholmodContext context;
    cholmod_common& c = *context;
    c.nmethods = 1;
    c.method[0].ordering = CHOLMOD_GIVEN;
    c.postorder = 0;
    cholmod_sparse A = linalg::upper_view(M.outer, M.inner, M.values, n);
    cholmod_factor* L = cholmod_analyze_p(&A, const_cast<int*>(S.perm.data()), nullptr, 0, &c);
    linalg::require(L != nullptr, "CHOLMOD could not analyse the constraint system", c);
    struct Free {
      cholmod_factor*& L;
      cholmod_common& c;
      ~Free() { cholmod_free_factor(&L, &c); }
    } free_factor{L, c};
    auto same = [](const std::vector<int>& ours, const void* theirs) {
      return std::equal(ours.begin(), ours.end(), static_cast<const int*>(theirs));
    };
    if (static_cast<int>(L->nsuper) != S.nsuper || L->xsize != S.xsize || !same(S.perm, L->Perm) || !same(S.super, L->super) ||
        !same(S.pi, L->pi) || !same(S.px, L->px) || !same(S.s, L->s))
      throw Error("internal: CHOLMOD's symbolic factor of the constraint system differs from trivcon's");
    const int ok = cholmod_factorize(&A, L, &c);
    linalg::require(ok && (c.status == CHOLMOD_OK || c.status == CHOLMOD_NOT_POSDEF), "CHOLMOD factorization failed", c);
    if (c.status == CHOLMOD_NOT_POSDEF) return static_cast<int>(L->minor);
    linalg::require(L->is_super && L->is_ll && L->x != nullptr, "CHOLMOD factorization failed", c);
    const double* x = static_cast<const double*>(L->x);
    values_.assign(x, x + S.xsize);
    return n;
  }
#endif

  void factorize(const Csc& M) {
    const int n = nD + nC;
    if (!analysis_->analysed) analyse(M, nD, nC, *analysis_);
    const std::vector<int>& perm = symbolic_factor().perm;
    if (const int row = numeric(M); row < n) {
      throw Error(perm[row] >= nD
                      ? "the holonomy of the generators, boundary loops or fixed-direction paths cannot be controlled independently "
                        "with these weights (the constraint system is singular); try --weights unit"
                      : "the constraint system is not positive definite with these weights; try --weights unit");
    }
    for (int k = nD; k < n; ++k)
      if (perm[k] != k) throw Error("internal: the symbolic analysis did not keep the cycle rows last");
    prepare_sparse_forward();
  }

  // R_CC and its inverse: the Schur complement's factor, for choosing free cycle indices.
  void prepare_schur() {
    extract_cycle_block();
    if (nC > 0) {
      const double min_diag = R_CC.diagonal().minCoeff(), max_diag = R_CC.diagonal().maxCoeff();
      if (!(min_diag > 1e-8 * max_diag))
        throw Error(
            "the holonomy of the generators, boundary loops or fixed-direction paths is nearly undetermined with these weights "
            "(ill-conditioned Schur complement); try --weights unit");
      R_inv = R_CC;  // its upper triangle is 0 (extract_cycle_block), and stays so
      if (!linalg::invert_lower_triangular(R_inv)) throw Error("internal error: the cycle block's factor has a zero diagonal entry");
      P_diagonal_ = R_inv.colwise().squaredNorm().transpose();
    }
  }

  std::string ordering() const override { return nC > 0 ? "CAMD" : "AMD"; }

  // The factor position of each row, for forward_update.
  void prepare_sparse_forward() {
    const int n = nD + nC;
    const std::vector<int>& perm = symbolic_factor().perm;
    position_.resize(n);
    for (int k = 0; k < n; ++k) position_[perm[k]] = k;
    for (int& r : edge_rows_.row) r = position_[r];
    substitution_ = std::make_unique<linalg::Substitution<double>>(symbolic_factor(), values_);
  }

  // z ← L⁻ᵀ z (in factor order), on OpenMP's threads: the top of the tree, then one set of disjoint subtrees
  // per thread (src/linalg/substitution.h).
  void backward(Eigen::VectorXd& z) const { substitution_->backward_in_factor_order(z.data()); }

  // z += L⁻¹ d for d with the few nonzeros `entries` (factor positions, values): only the supernodes on the
  // paths from those entries to the root of the elimination tree are touched.
  void forward_update(const std::vector<std::pair<int, double>>& entries, Eigen::VectorXd& z) const {
    substitution_->forward_update(entries, z.data());
  }

  // R_CC: the factor's entries at rows and columns ≥ nD (in factor order), read from the supernodes.
  void extract_cycle_block() {
    if (nC == 0) {
      R_CC.resize(0, 0);
      return;
    }
    std::vector<int> place(nD + nC, -1);
    for (int k = nD; k < nD + nC; ++k) place[k] = k - nD;
    R_CC = linalg::trailing_block(supernodes(), place, nC);
  }

  // L⁻¹ b (in factor order), for a right-hand side that is not an update of the base one: the forward half of
  // the parallel substitution (src/linalg/substitution.h).
  Eigen::VectorXd lower_solve(const Eigen::VectorXd& b) const {
    Eigen::VectorXd out = b;
    substitution_->forward_in_factor_order(out.data());
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
    Eigen::VectorXd y = forward_with_cycles(b_D, choose);  // [λ; μ] in factor order, after the backward half
    backward(y);
    return edge_values(y);
  }

  // Σ x²/w = yᵀ L Lᵀ y = ‖Lᵀ y‖² = ‖z‖² for z = L⁻¹ Π b, the forward half's result.
  double energy(const Eigen::VectorXd& b_D, const CycleRhsChooser& choose) const override {
    if (nD + nC == 0) return 0;
    return forward_with_cycles(b_D, choose).squaredNorm();
  }

  // z = L⁻¹ Π [b_D; b_C] with b_C from `choose`.
  Eigen::VectorXd forward_with_cycles(const Eigen::VectorXd& b_D, const CycleRhsChooser& choose) const {
    const int n = nD + nC;
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
    return z;
  }

  bool refine(const Eigen::VectorXd& b, Eigen::VectorXd& x) const override {
    const int n = nD + nC;
    if (n == 0) return false;
    // r = Π (b − A x), in factor order.
    Eigen::VectorXd r(n);
    for (int row = 0; row < n; ++row) r(position_[row]) = b(row);
    for (int a = 0; a < m; ++a)
      for (int k = edge_rows_.start[a]; k < edge_rows_.start[a + 1]; ++k) r(edge_rows_.row[k]) -= edge_rows_.coefficient[k] * x(a);
    Eigen::VectorXd y = lower_solve(r);
    backward(y);
    x += edge_values(y);
    return true;
  }

  Eigen::VectorXd multipliers(const Eigen::VectorXd& x) const override {
    const int n = nD + nC;
    if (n == 0) return Eigen::VectorXd();
    Eigen::VectorXd y = Eigen::VectorXd::Zero(n);  // Π A x, in factor order
    for (int a = 0; a < m; ++a)
      for (int k = edge_rows_.start[a]; k < edge_rows_.start[a + 1]; ++k) y(edge_rows_.row[k]) += edge_rows_.coefficient[k] * x(a);
    y = lower_solve(y);
    backward(y);
    Eigen::VectorXd out(n);
    for (int row = 0; row < n; ++row) out(row) = y(position_[row]);
    return out;
  }

 private:
  // x = W Aᵀ y for y in factor order.
  Eigen::VectorXd edge_values(const Eigen::VectorXd& y) const {
    Eigen::VectorXd x(m);
#pragma omp parallel for schedule(static) if (m > linalg::kParallelMinEditElements)
    for (int a = 0; a < m; ++a) {
      double sum = 0;
      for (int k = edge_rows_.start[a]; k < edge_rows_.start[a + 1]; ++k) sum += edge_rows_.coefficient[k] * y(edge_rows_.row[k]);
      x(a) = w(a) * sum;
    }
    return x;
  }
};

}  // namespace

std::unique_ptr<SolverEngine> make_cholesky_engine(const EdgeEnds& ends, int num_vertex_rows, const SparseMatrix& Et,
                                                   const SparseMatrix& Ct, const Eigen::VectorXd& w, Factorization factorization,
                                                   SetupTimings& timings, const std::function<std::unique_ptr<AnalysisState>()>& analysis) {
  return std::make_unique<CholeskyEngine>(ends, num_vertex_rows, Et, Ct, w, factorization, timings, analysis);
}

}  // namespace trivcon::connection
