// SPDX-License-Identifier: MIT
#include "linalg/sparse_cholesky.h"

#include <Eigen/Dense>

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
  std::vector<int> last;               // the rows ordered last (schur_complement, solve_rest)
  std::vector<int> last_positions;     // their factor positions
  std::vector<char> is_last;           // per matrix row
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

SparseCholesky::SparseCholesky(const Eigen::SparseMatrix<double>& A, const char* what, const std::vector<int>& last)
    : state_(std::make_unique<State>()) {
  check_numeric_libraries();
  if (A.rows() != A.cols()) throw Error(std::string(what) + ": the matrix is not square");
  n_ = static_cast<int>(A.cols());
  state_->what = what;
  state_->last = last;
  upper_triangle(A, state_->outer, state_->inner, nullptr);
  // AMD (or CAMD with `last` constrained last), then the postordered supernodal analysis with the default
  // amalgamation: cholmod_analyze's factor with AMD and postorder = 1 (tests/test_symbolic.cpp).
  try {
    std::vector<int> order;
    if (last.empty()) {
      order = amd_ordering(state_->outer, state_->inner, n_);
    } else {
      std::vector<int> set(n_, 0);
      for (int row : last) {
        if (row < 0 || row >= n_ || set[row]) throw Error("a row to order last is outside the matrix or repeated");
        set[row] = 1;
      }
      order = camd_ordering(state_->outer, state_->inner, n_, set);
    }
    state_->symbolic = symbolic_analysis(state_->outer, state_->inner, n_, order);
  } catch (const Error& e) {
    throw Error(std::string(what) + ": " + e.what());
  }
  state_->position.resize(n_);
  for (int k = 0; k < n_; ++k) state_->position[state_->symbolic.perm[k]] = k;
  // The postorder keeps the rows of `last` above all others in the elimination tree (an ancestor of one of them
  // is one of them): then L_rr is the factor of A_rr alone and L_ll that of the Schur complement.
  state_->is_last.assign(n_, 0);
  for (int row : last) state_->is_last[row] = 1, state_->last_positions.push_back(state_->position[row]);
  for (int k = 0; k < n_; ++k) {
    const int parent = state_->symbolic.parent[k];
    if (parent >= 0 && state_->is_last[state_->symbolic.perm[k]] && !state_->is_last[state_->symbolic.perm[parent]])
      throw Error(std::string(what) + ": internal error: a row ordered last has an ancestor that is not");
  }
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

// The entries of a sparse right-hand side at their factor positions (those in rows of `last` left out with
// `skip_last`), each row checked.
std::vector<std::pair<int, double>> SparseCholesky::in_factor_order(const std::vector<std::pair<int, double>>& entries, bool skip_last) const {
  if (!state_->substitution) throw Error(state_->what + ": solve without a successful factorization");
  std::vector<std::pair<int, double>> out;
  out.reserve(entries.size());
  for (const auto& [row, value] : entries) {
    if (row < 0 || row >= n_) throw Error(state_->what + ": a right-hand side entry outside the matrix");
    if (!skip_last || !state_->is_last[row]) out.emplace_back(state_->position[row], value);
  }
  return out;
}

Eigen::VectorXd SparseCholesky::solve_sparse(const std::vector<std::pair<int, double>>& entries) const {
  const std::vector<std::pair<int, double>> in_factor = in_factor_order(entries, false);
  Eigen::VectorXd z = Eigen::VectorXd::Zero(n_), x(n_);
  state_->substitution->forward_update(in_factor, z.data());
  state_->substitution->backward_in_factor_order(z.data());
  for (int k = 0; k < n_; ++k) x[state_->symbolic.perm[k]] = z[k];
  return x;
}

Eigen::MatrixXd SparseCholesky::schur_complement() const {
  if (!state_->substitution) throw Error(state_->what + ": Schur complement without a successful factorization");
  const int m = static_cast<int>(state_->last.size());
  std::vector<int> place(n_, -1);  // per factor position, its place in `last`
  for (int a = 0; a < m; ++a) place[state_->last_positions[a]] = a;
  // L_ll: below a column of `last` every row is one of them (the analysis checked).
  const Eigen::MatrixXd Lll = trailing_block(Supernodes(state_->symbolic, state_->x.data()), place, m);
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(m, m);
  S.selfadjointView<Eigen::Lower>().rankUpdate(Lll);
  return S.selfadjointView<Eigen::Lower>();
}

// Forward and backward substitution in the factor's order with the rows of `last` zeroed between them: their
// columns have only rows of `last` below them, so the forward pass gives L_rr⁻¹ b_r in the other rows whatever
// it leaves in theirs, and with z_l = 0 the backward pass gives x_l = 0 and x_r = L_rr⁻ᵀ z_r.
namespace {
Eigen::VectorXd solve_rest_in_factor_order(const Substitution<double>& substitution, const std::vector<int>& last_positions,
                                           const std::vector<int>& perm, Eigen::VectorXd& z) {
  for (int k : last_positions) z[k] = 0;
  substitution.backward_in_factor_order(z.data());
  Eigen::VectorXd x(z.size());
  for (int k = 0; k < static_cast<int>(z.size()); ++k) x[perm[k]] = z[k];
  for (int k : last_positions) x[perm[k]] = 0;
  return x;
}
}  // namespace

Eigen::VectorXd SparseCholesky::solve_rest(const Eigen::VectorXd& b) const {
  if (!state_->substitution) throw Error(state_->what + ": solve without a successful factorization");
  if (b.size() != n_) throw Error(state_->what + ": the right-hand side has the wrong size");
  Eigen::VectorXd z(n_);
  for (int k = 0; k < n_; ++k) z[k] = b[state_->symbolic.perm[k]];
  for (int k : state_->last_positions) z[k] = 0;
  if (n_ > 0) state_->substitution->forward_in_factor_order(z.data());
  return solve_rest_in_factor_order(*state_->substitution, state_->last_positions, state_->symbolic.perm, z);
}

Eigen::VectorXd SparseCholesky::solve_rest_sparse(const std::vector<std::pair<int, double>>& entries) const {
  const std::vector<std::pair<int, double>> in_factor = in_factor_order(entries, true);
  Eigen::VectorXd z = Eigen::VectorXd::Zero(n_);
  state_->substitution->forward_update(in_factor, z.data());
  return solve_rest_in_factor_order(*state_->substitution, state_->last_positions, state_->symbolic.perm, z);
}

double SparseCholesky::factor_flops() const { return state_->symbolic.flops; }

}  // namespace trivcon::linalg
