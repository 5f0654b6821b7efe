// SPDX-License-Identifier: MIT
// src/linalg/sparse_cholesky.h (internal): a sparse symmetric positive definite solve, A x = b, for the
// layers that need one without the trivial-connection solver's structure (the integer-grid map of
// src/quad/). The order (AMD through libamd, or CAMD through libcamd with rows constrained last), the
// symbolic analysis, the numeric factorization and the substitutions are trivcon's (src/linalg/symbolic.h,
// supernodal.h, substitution.h), as for the connection and the smoothest field; no CHOLMOD.
//
// The pattern is analysed once; factorize() may be called again with new values on the same pattern (a
// row and column replaced by the identity to fix an unknown keeps the pattern).
//
// Rows given as `last` are eliminated after all the others (CAMD, libcamd, with them constrained last), so that
// the factor's rows and columns of them, L_ll, are the Cholesky factor of their Schur complement
// S = A_ll − A_lr A_rr⁻¹ A_rl (r: the other rows): schur_complement() reads it from the factor, without a solve.
#pragma once
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>
#include <utility>
#include <vector>

namespace trivcon::linalg {

class SparseCholesky {
 public:
  // `A`: a symmetric matrix; only its upper triangle (row ≤ column) is read. Throws trivcon::Error naming
  // `what` if it is not square or cannot be ordered and analysed.
  // `last`: rows to eliminate after all others (distinct, within the matrix), for schur_complement().
  SparseCholesky(const Eigen::SparseMatrix<double>& A, const char* what, const std::vector<int>& last = {});
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;
  // Factors the values of a matrix with the pattern given to the constructor (entries outside it are an
  // error). Returns −1 on success, otherwise the first column (matrix numbering) found not positive definite.
  int factorize(const Eigen::SparseMatrix<double>& A);
  // x ← A⁻¹ b with the last factorization.
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  // The same for b with the few nonzeros `entries` (matrix row, value; a row may repeat, its values add up):
  // the forward half visits only the supernodes on their paths to the root of the elimination tree.
  Eigen::VectorXd solve_sparse(const std::vector<std::pair<int, double>>& entries) const;
  // S = L_ll L_llᵀ for the rows `last` given to the constructor, in that order, from the last factorization.
  Eigen::MatrixXd schur_complement() const;
  // x_r = A_rr⁻¹ b_r for the other rows r, with L_rr alone (b's rows of `last` are ignored, x's are 0): the
  // solution with the rows of `last` held at 0. For b with the few nonzeros `entries` as in solve_sparse.
  Eigen::VectorXd solve_rest(const Eigen::VectorXd& b) const;
  Eigen::VectorXd solve_rest_sparse(const std::vector<std::pair<int, double>>& entries) const;
  // The factor's flop count (Σ column count²): the cost of a factorization, for choosing between routes.
  double factor_flops() const;
  int size() const { return n_; }

 private:
  std::vector<std::pair<int, double>> in_factor_order(const std::vector<std::pair<int, double>>& entries, bool skip_last) const;
  struct State;
  std::unique_ptr<State> state_;
  int n_ = 0;
};

}  // namespace trivcon::linalg
