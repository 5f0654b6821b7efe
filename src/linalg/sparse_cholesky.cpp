// SPDX-License-Identifier: MIT
#include "linalg/sparse_cholesky.h"

#include <string>

#include "linalg/numeric_libraries.h"
#include "linalg/substitution.h"
#include "linalg/supernodal.h"
#include "linalg/symbolic.h"
#include "trivcon/error.h"

namespace trivcon::linalg {

struct SparseCholesky::State {
  SymbolicFactor symbolic;
  FactorValues<double> x;              // the factor's values
  std::vector<int> outer, inner;       // the upper triangle's pattern, compressed columns
  std::vector<double> values;
  std::vector<int> position;           // the factor position of each matrix row (the inverse of symbolic.perm)
  std::unique_ptr<Substitution<double>> substitution;
  std::string what;
};

namespace {

// The upper triangle of A (row ≤ column) in compressed columns, values in `values` when it is not null.
void upper_triangle(const Eigen::SparseMatrix<double>& A, std::vector<int>& outer, std::vector<int>& inner, std::vector<double>* values) {
  const int n = static_cast<int>(A.cols());
  outer.assign(n + 1, 0);
  inner.clear();
  if (values) values->clear();
  for (int j = 0; j < n; ++j) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, j); it; ++it) {
      if (it.row() > j) continue;
      inner.push_back(static_cast<int>(it.row()));
      if (values) values->push_back(it.value());
    }
    outer[j + 1] = static_cast<int>(inner.size());
  }
}

}  // namespace

SparseCholesky::SparseCholesky(const Eigen::SparseMatrix<double>& A, const char* what) : state_(std::make_unique<State>()) {
  check_numeric_libraries();
  if (A.rows() != A.cols()) throw Error(std::string(what) + ": the matrix is not square");
  n_ = static_cast<int>(A.cols());
  state_->what = what;
  upper_triangle(A, state_->outer, state_->inner, nullptr);
  // AMD, then the postordered supernodal analysis with the default amalgamation: cholmod_analyze's factor
  // with AMD and postorder = 1 (tests/test_symbolic.cpp).
  try {
    state_->symbolic = symbolic_analysis(state_->outer, state_->inner, n_, amd_ordering(state_->outer, state_->inner, n_));
  } catch (const Error& e) {
    throw Error(std::string(what) + ": " + e.what());
  }
  state_->position.resize(n_);
  for (int k = 0; k < n_; ++k) state_->position[state_->symbolic.perm[k]] = k;
}

SparseCholesky::~SparseCholesky() = default;

int SparseCholesky::factorize(const Eigen::SparseMatrix<double>& A) {
  std::vector<int> outer, inner;
  upper_triangle(A, outer, inner, &state_->values);
  if (A.cols() != n_ || outer != state_->outer || inner != state_->inner)
    throw Error(state_->what + ": the matrix's pattern changed after its analysis");
  state_->substitution.reset();
  const int minor = linalg::factorize(state_->symbolic, state_->x, state_->outer, state_->inner, state_->values);
  if (minor < n_) return state_->symbolic.perm[minor];
  state_->substitution = std::make_unique<Substitution<double>>(state_->symbolic, state_->x);
  return -1;
}

Eigen::VectorXd SparseCholesky::solve(const Eigen::VectorXd& b) const {
  if (!state_->substitution) throw Error(state_->what + ": solve without a successful factorization");
  if (b.size() != n_) throw Error(state_->what + ": the right-hand side has the wrong size");
  Eigen::VectorXd x = b;
  if (n_ > 0) state_->substitution->solve(x.data());
  return x;
}

Eigen::VectorXd SparseCholesky::solve_sparse(const std::vector<std::pair<int, double>>& entries) const {
  if (!state_->substitution) throw Error(state_->what + ": solve without a successful factorization");
  std::vector<std::pair<int, double>> in_factor_order;
  in_factor_order.reserve(entries.size());
  for (const auto& [row, value] : entries) {
    if (row < 0 || row >= n_) throw Error(state_->what + ": a right-hand side entry outside the matrix");
    in_factor_order.emplace_back(state_->position[row], value);
  }
  Eigen::VectorXd z = Eigen::VectorXd::Zero(n_), x(n_);
  state_->substitution->forward_update(in_factor_order, z.data());
  state_->substitution->backward_in_factor_order(z.data());
  for (int k = 0; k < n_; ++k) x[state_->symbolic.perm[k]] = z[k];
  return x;
}

}  // namespace trivcon::linalg
