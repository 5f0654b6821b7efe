// SPDX-License-Identifier: MIT
// Choosing free indices by lattice rounding (src/connection/generator_rounding.h).
#include "connection/generator_rounding.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace trivcon::connection {

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

Eigen::VectorXi nearest_lattice_point(const SolverEngine& engine, const Eigen::VectorXd& u, const Eigen::VectorXd& n0,
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
    diagonal = engine.P_diagonal();
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

}  // namespace trivcon::connection
