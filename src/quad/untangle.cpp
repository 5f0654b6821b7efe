// SPDX-License-Identifier: MIT
// The local untangling of a map (src/quad/untangle.h).
#include "quad/untangle.h"

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <tuple>
#include <vector>

#include "linalg/sparse_cholesky.h"
#include "trivcon/cancel.h"

namespace trivcon::quad {

namespace {

double chi(double D, double eps) { return 0.5 * (D + std::sqrt(eps * eps + D * D)); }
double chi_derivative(double D, double eps) { return 0.5 * (1 + D / std::sqrt(eps * eps + D * D)); }

// The energy reads each face's Jacobian as J = J0 + Σ_k z[variable_k] · (row_k ← a_k): the problem's affine
// forms times the hat gradients, merged per face by (variable, row) and stored flat, so that each evaluation (one
// per L-BFGS step and line-search trial) reads memory in order.
class Energy {
 public:
  Energy(const UntangleProblem& p, double lambda) : p_(p), lambda_(lambda) {
    const size_t n = p.area.size();
    constant_.resize(n);
    start_.assign(n + 1, 0);
    std::vector<Term> face_terms;
    for (size_t f = 0; f < n; ++f) {
      Eigen::Matrix2d J0 = Eigen::Matrix2d::Zero();
      face_terms.clear();
      for (int i = 0; i < 3; ++i)
        for (int r = 0; r < 2; ++r) {
          const AffineForm& a = p.corner[f][i][r];
          const Eigen::Vector2d& g = p.gradient[f][i];
          J0.row(r) += a.constant * g.transpose();
          for (const auto& [j, coefficient] : a.terms) face_terms.push_back({j, r, coefficient * g.x(), coefficient * g.y()});
        }
      std::sort(face_terms.begin(), face_terms.end(), [](const Term& x, const Term& y) { return std::tie(x.variable, x.row) < std::tie(y.variable, y.row); });
      for (const Term& term : face_terms) {
        if (terms_.size() > static_cast<size_t>(start_[f]) && terms_.back().variable == term.variable && terms_.back().row == term.row)
          terms_.back().a0 += term.a0, terms_.back().a1 += term.a1;
        else
          terms_.push_back(term);
      }
      constant_[f] = J0;
      start_[f + 1] = static_cast<int>(terms_.size());
    }
  }

  // The relative Jacobian of face f at z.
  Eigen::Matrix2d jacobian(int f, const Eigen::VectorXd& z) const {
    Eigen::Matrix2d J = constant_[f];
    for (int k = start_[f]; k < start_[f + 1]; ++k) {
      const Term& t = terms_[k];
      const double x = z[t.variable];
      J(t.row, 0) += x * t.a0, J(t.row, 1) += x * t.a1;
    }
    return J;
  }

  double min_determinant(const Eigen::VectorXd& z) const {
    double m = std::numeric_limits<double>::infinity();
    for (size_t f = 0; f < p_.area.size(); ++f) m = std::min(m, jacobian(static_cast<int>(f), z).determinant());
    return m;
  }

  // The energy at z with regularisation eps; its gradient into `grad` when given.
  double operator()(const Eigen::VectorXd& z, double eps, Eigen::VectorXd* grad) const {
    if (grad) grad->setZero(z.size());
    double total = 0;
    for (size_t f = 0; f < p_.area.size(); ++f) {
      const Eigen::Matrix2d J = jacobian(static_cast<int>(f), z);
      const double D = J.determinant(), T = J.squaredNorm(), c = chi(D, eps), a = p_.area[f];
      total += a * ((1 - lambda_) * T + lambda_ * (D * D + 1)) / c;
      if (!grad) continue;
      const double dc = chi_derivative(D, eps);
      Eigen::Matrix2d cofactor;
      cofactor << J(1, 1), -J(1, 0), -J(0, 1), J(0, 0);
      const Eigen::Matrix2d G = a * ((1 - lambda_) * (2 * J / c - T * dc / (c * c) * cofactor) +
                                     lambda_ * (2 * D / c - (D * D + 1) * dc / (c * c)) * cofactor);
      for (int k = start_[f]; k < start_[f + 1]; ++k) {
        const Term& t = terms_[k];
        (*grad)[t.variable] += G(t.row, 0) * t.a0 + G(t.row, 1) * t.a1;
      }
    }
    return total;
  }

 private:
  struct Term {
    int variable, row;
    double a0, a1;
  };
  const UntangleProblem& p_;
  double lambda_;
  std::vector<Eigen::Matrix2d> constant_;
  std::vector<int> start_;
  std::vector<Term> terms_;
};

// L-BFGS (Nocedal & Wright, Algorithm 7.4, memory 8) with a backtracking Armijo line search, from z, for at
// most `iterations` steps or until the gradient or the decrease is negligible. Returns the steps taken.
int minimise(const Energy& energy, double eps, Eigen::VectorXd& z, int iterations) {
  const int memory = 8;
  std::deque<Eigen::VectorXd> S, Y;
  std::deque<double> rho;
  Eigen::VectorXd g(z.size()), g_new(z.size());
  double E = energy(z, eps, &g);
  const double g0 = g.norm();
  int it = 0;
  for (; it < iterations; ++it) {
    if (!(g.norm() > 1e-10 * std::max(1.0, g0))) break;
    Eigen::VectorXd d = -g;
    std::vector<double> alpha(S.size());
    for (int k = static_cast<int>(S.size()) - 1; k >= 0; --k) {
      alpha[k] = rho[k] * S[k].dot(d);
      d -= alpha[k] * Y[k];
    }
    if (!S.empty()) d *= S.back().dot(Y.back()) / Y.back().squaredNorm();
    for (size_t k = 0; k < S.size(); ++k) d += S[k] * (alpha[k] - rho[k] * Y[k].dot(d));
    double slope = g.dot(d);
    if (!(slope < 0)) {  // not a descent direction (curvature pairs gone stale): restart from the gradient
      S.clear(), Y.clear(), rho.clear();
      d = -g;
      slope = -g.squaredNorm();
    }
    double step = 1, E_new = 0;
    Eigen::VectorXd z_new;
    bool accepted = false, have_gradient = false;
    for (int tries = 0; tries < 40; ++tries, step *= 0.5) {
      z_new = z + step * d;
      // The full step is usually taken: its gradient comes with its energy (one pass over the faces, not two).
      E_new = energy(z_new, eps, tries == 0 ? &g_new : nullptr);
      if (std::isfinite(E_new) && E_new <= E + 1e-4 * step * slope) {
        accepted = true, have_gradient = tries == 0;
        break;
      }
    }
    if (!accepted) break;
    if (!have_gradient) energy(z_new, eps, &g_new);
    const Eigen::VectorXd s = z_new - z, y = g_new - g;
    const double sy = s.dot(y);
    if (sy > 1e-12 * s.norm() * y.norm()) {
      S.push_back(s), Y.push_back(y), rho.push_back(1 / sy);
      if (static_cast<int>(S.size()) > memory) S.pop_front(), Y.pop_front(), rho.pop_front();
    }
    const double decrease = E - E_new;
    z = z_new, g = g_new, E = E_new;
    if (decrease < 1e-9 * std::abs(E)) break;
  }
  return it;
}

}  // namespace

UntangleResult untangle(const UntangleProblem& problem, Eigen::VectorXd& z, double min_determinant, double lambda, int max_outer,
                        int max_inner) {
  UntangleResult result;
  const Energy energy(problem, lambda);
  double D = energy.min_determinant(z);
  result.min_determinant = D;
  if (problem.area.empty() || z.size() == 0) {
    result.unfolded = D > min_determinant;
    return result;
  }
  // ε's rule (Garanzha et al. 2021, §3): after each minimisation with ε, σ = max(1 − E_new/E_old, 1/10) and
  // μ = (1 − σ) χ(D_min, ε); ε becomes 2√(μ(μ − D_min)) while D_min < μ (smaller as the worst face opens).
  double eps = D > 0 ? 1e-3 : std::max(1e-3, 2 * std::abs(D));
  double E_old = energy(z, eps, nullptr);
  // Stuck: the worst face no better than 4 rounds before while still folded (the held unknowns admit no
  // unfolded map here: e.g. two singularities on one integer point).
  std::vector<double> worst;
  int unfolded_rounds = 0;
  for (int outer = 0; outer < max_outer; ++outer) {
    check_cancelled();
    ++result.outer_iterations;
    result.inner_iterations += minimise(energy, eps, z, max_inner);
    const double E_new = energy(z, eps, nullptr);
    D = energy.min_determinant(z);
    result.min_determinant = D;
    // Unfolded: a few more rounds for the shape while they still lower the energy markedly.
    const bool decreasing = E_old - E_new > 1e-3 * std::abs(E_new);
    if (D > min_determinant && (!decreasing || ++unfolded_rounds > 3)) break;
    worst.push_back(D);
    if (D <= min_determinant && worst.size() > 4) {
      const double then = worst[worst.size() - 5];
      if (D <= then + std::max(1e-3 * std::abs(then), 1e-4)) break;
    }
    const double sigma = std::max(1 - E_new / E_old, 0.1);
    const double mu = (1 - sigma) * chi(D, eps);
    eps = D < mu ? std::max(2 * std::sqrt(mu * (mu - D)), 1e-12) : 1e-8;
    E_old = energy(z, eps, nullptr);
  }
  result.unfolded = result.min_determinant > min_determinant;
  return result;
}

Eigen::VectorXd least_squares_start(const UntangleProblem& problem, const Eigen::VectorXd& z) {
  // Rows: per face, the four entries of J − I, each weighted by √area; J is affine in z. The normal equations
  // get a small multiple of the identity (toward z) so that a variable no face pins keeps its value.
  const int n = problem.num_variables;
  if (n == 0) return z;
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
  double largest = 0;
  std::vector<std::pair<int, double>> row;
  for (size_t f = 0; f < problem.area.size(); ++f) {
    const double w = problem.area[f];
    for (int r = 0; r < 2; ++r)
      for (int d = 0; d < 2; ++d) {
        // Σ_i gradient_i[d] · (constant + Σ coefficient · z) − δ_rd
        row.clear();
        double constant = r == d ? -1.0 : 0.0;
        for (int i = 0; i < 3; ++i) {
          const double g = problem.gradient[f][i][d];
          const AffineForm& a = problem.corner[f][i][r];
          constant += g * a.constant;
          for (const auto& [j, c] : a.terms) row.emplace_back(j, g * c);
        }
        for (const auto& [j, cj] : row) {
          rhs[j] -= w * cj * constant;
          for (const auto& [k, ck] : row)
            if (j <= k) triplets.emplace_back(j, k, w * cj * ck);
        }
      }
  }
  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(triplets.begin(), triplets.end());
  for (int k = 0; k < A.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, k); it; ++it)
      if (it.row() == it.col()) largest = std::max(largest, it.value());
  const double ridge = 1e-9 * std::max(largest, 1e-300);
  for (int j = 0; j < n; ++j) triplets.emplace_back(j, j, ridge), rhs[j] += ridge * z[j];
  A.setFromTriplets(triplets.begin(), triplets.end());
  try {
    linalg::SparseCholesky solver(A, "the untangling's least squares");
    if (solver.factorize(A) >= 0) return z;  // not positive definite: keep the start as it was
    const Eigen::VectorXd x = solver.solve(rhs);
    return x.allFinite() ? x : z;
  } catch (const std::exception&) {
    return z;
  }
}

}  // namespace trivcon::quad
