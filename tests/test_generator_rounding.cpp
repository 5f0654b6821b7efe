// SPDX-License-Identifier: MIT
// Tests of src/connection/generator_rounding.h: Babai's nearest-plane rounding, which chooses the free
// whole numbers of a solve (generator and loop indices, fixed-face path turns). nearest_lattice_point, which
// adds single steps on top of it, is tested through the solver (test_solver.cpp, test_formulation.cpp).
#include "connection/generator_rounding.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/Cholesky>

namespace trivcon::connection {
namespace {

double objective(const Eigen::MatrixXd& T, const Eigen::VectorXd& u, const Eigen::VectorXi& n) {
  return (T * (u - n.cast<double>())).squaredNorm();
}

// A diagonal metric: each coordinate rounds on its own, exact halves up (with the 1e-7 margin that makes
// routes differing by round-off agree).
TEST(GeneratorRounding, ADiagonalMetricRoundsEachCoordinate) {
  const Eigen::MatrixXd T = Eigen::Vector4d(1.0, 3.0, 0.5, 2.0).asDiagonal();
  Eigen::VectorXd u(4);
  u << 0.5, -0.5, 2.49, 0.5 - 5e-8;
  for (bool lower : {true, false}) {
    const Eigen::VectorXi n = babai_round(T, lower, u);
    EXPECT_EQ(n, Eigen::Vector4i(1, 0, 2, 1)) << "lower " << lower;
  }
}

// The nearest-plane property, for lower and upper factors: each row of T (u − n) is at most half its
// diagonal entry in magnitude (the coordinate was rounded to the nearest plane given the ones before it).
// That is not always the nearest lattice point (nearest_lattice_point's single steps finish the job), but on
// a nearly orthogonal metric (off-diagonal entries of 0.05 against a unit diagonal) it almost always is:
// checked against brute force over a box around the rounded minimiser.
TEST(GeneratorRounding, EachRowIsWithinHalfAPlaneAndNearlyOrthogonalMetricsAreMostlyExact) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> off(-0.05, 0.05), coordinate(-4.0, 4.0);
  int exact = 0;
  const int trials = 200;
  for (int trial = 0; trial < trials; ++trial) {
    Eigen::MatrixXd L = Eigen::MatrixXd::Identity(3, 3);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < i; ++j) L(i, j) = off(random);
    Eigen::VectorXd u(3);
    for (int i = 0; i < 3; ++i) u(i) = coordinate(random);
    const Eigen::MatrixXd U = Eigen::LLT<Eigen::MatrixXd>(L.transpose() * L).matrixU();  // the same metric, UᵀU
    for (const auto& [T, lower] : {std::pair<Eigen::MatrixXd, bool>{L, true}, {U, false}}) {
      const Eigen::VectorXi n = babai_round(T, lower, u);
      const Eigen::VectorXd r = T * (u - n.cast<double>());
      for (int i = 0; i < 3; ++i) EXPECT_LE(std::abs(r(i)), 0.5 * std::abs(T(i, i)) + 1e-6) << "trial " << trial << " row " << i;
    }
    const Eigen::VectorXi n = babai_round(L, true, u);
    double best = 1e300;
    for (int a = -2; a <= 2; ++a)
      for (int b = -2; b <= 2; ++b)
        for (int c = -2; c <= 2; ++c) {
          const Eigen::Vector3i m(static_cast<int>(std::lround(u(0))) + a, static_cast<int>(std::lround(u(1))) + b,
                                  static_cast<int>(std::lround(u(2))) + c);
          best = std::min(best, objective(L, u, m));
        }
    exact += objective(L, u, n) <= best + 1e-12;
  }
  EXPECT_GE(exact, trials * 9 / 10);
}

// Each coordinate is rounded given those before it: with a strong coupling the second coordinate follows the
// first one's rounding error instead of rounding on its own.
TEST(GeneratorRounding, LaterCoordinatesFollowTheErrorOfEarlierOnes) {
  Eigen::MatrixXd L(2, 2);
  L << 1.0, 0.0, 0.8, 1.0;
  Eigen::VectorXd u(2);
  u << 0.4, 0.3;  // n0 = 0 leaves v0 = 0.4; row 1: 0.8 · 0.4 + (0.3 − n1) → n1 = round(0.3 + 0.32) = 1
  EXPECT_EQ(babai_round(L, true, u), Eigen::Vector2i(0, 1));
  EXPECT_LT(objective(L, u, Eigen::Vector2i(0, 1)), objective(L, u, Eigen::Vector2i(0, 0)));
}

}  // namespace
}  // namespace trivcon::connection
