// SPDX-License-Identifier: MIT
// src/linalg/sparse_cholesky.h (internal): a sparse symmetric positive definite solve, A x = b, for the
// layers that need one without the trivial-connection solver's structure (the integer-grid map of
// src/quad/). The order (AMD, through libamd), the symbolic analysis, the numeric factorization and the
// substitutions are trivcon's (src/linalg/symbolic.h, supernodal.h, substitution.h), as for the connection and
// the smoothest field; no CHOLMOD.
//
// The pattern is analysed once; factorize() may be called again with new values on the same pattern (a
// row and column replaced by the identity to fix an unknown keeps the pattern).
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
  SparseCholesky(const Eigen::SparseMatrix<double>& A, const char* what);
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
  int size() const { return n_; }

 private:
  struct State;
  std::unique_ptr<State> state_;
  int n_ = 0;
};

}  // namespace trivcon::linalg
