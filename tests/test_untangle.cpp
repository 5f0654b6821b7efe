// SPDX-License-Identifier: MIT
// src/quad/untangle.h: the local untangling opens folded maps with the held unknowns held, and leaves an
// unfolded map unfolded; checked on the determinants computed here from the corners, not on its own report.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <random>

#include "quad/untangle.h"

namespace trivcon::quad {
namespace {

// An n × n grid of unit squares split into triangles, the ideal map the identity: the boundary vertices held
// (constants), the interior ones variables (u, v) = (z[2i], z[2i + 1]).
struct Grid {
  int n;
  std::vector<int> variable;  // per vertex: its index i, or −1 on the boundary
  std::vector<std::array<int, 3>> faces;
  int num_interior = 0;
  explicit Grid(int n_) : n(n_), variable((n + 1) * (n + 1), -1) {
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i)
        if (i > 0 && j > 0 && i < n && j < n) variable[j * (n + 1) + i] = num_interior++;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
        faces.push_back({a, b, d});
        faces.push_back({a, d, c});
      }
  }
  Eigen::Vector2d rest(int v) const { return Eigen::Vector2d(v % (n + 1), v / (n + 1)); }
  UntangleProblem problem() const {
    UntangleProblem p;
    p.num_variables = 2 * num_interior;
    for (const auto& f : faces) {
      // Hat gradients of the rest triangle (the ideal Jacobian is the identity).
      const Eigen::Vector2d x0 = rest(f[0]), x1 = rest(f[1]), x2 = rest(f[2]);
      const double area2 = (x1 - x0).x() * (x2 - x0).y() - (x1 - x0).y() * (x2 - x0).x();
      std::array<Eigen::Vector2d, 3> g;
      for (int i = 0; i < 3; ++i) {
        const Eigen::Vector2d e = rest(f[(i + 2) % 3]) - rest(f[(i + 1) % 3]);
        g[i] = Eigen::Vector2d(-e.y(), e.x()) / area2;
      }
      std::array<std::array<AffineForm, 2>, 3> corner;
      for (int i = 0; i < 3; ++i)
        for (int r = 0; r < 2; ++r) {
          if (variable[f[i]] >= 0) corner[i][r].terms = {{2 * variable[f[i]] + r, 1.0}};
          else corner[i][r].constant = rest(f[i])[r];
        }
      p.area.push_back(area2 / 2);
      p.gradient.push_back(g);
      p.corner.push_back(corner);
    }
    return p;
  }
  Eigen::Vector2d at(int v, const Eigen::VectorXd& z) const {
    return variable[v] >= 0 ? Eigen::Vector2d(z[2 * variable[v]], z[2 * variable[v] + 1]) : rest(v);
  }
  double min_signed_area(const Eigen::VectorXd& z) const {
    double m = 1e300;
    for (const auto& f : faces) {
      const Eigen::Vector2d a = at(f[0], z), b = at(f[1], z), c = at(f[2], z);
      m = std::min(m, 0.5 * ((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x()));
    }
    return m;
  }
};

TEST(Untangle, OpensAGridWhoseInteriorIsScrambled) {
  for (int seed : {1, 2, 3}) {
    SCOPED_TRACE(seed);
    const Grid grid(6);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> inside(0.5, 5.5);
    Eigen::VectorXd z(2 * grid.num_interior);
    for (int k = 0; k < z.size(); ++k) z[k] = inside(rng);  // every interior vertex anywhere: many folds
    ASSERT_LT(grid.min_signed_area(z), 0);
    const UntangleResult r = untangle(grid.problem(), z);
    EXPECT_TRUE(r.unfolded);
    EXPECT_GT(grid.min_signed_area(z), 0.5 * 1e-3);  // det J > 1e-3 on triangles of area 1/2
    EXPECT_NEAR(r.min_determinant, 2 * grid.min_signed_area(z), 1e-9);
  }
}

TEST(Untangle, OneVertexPushedThroughItsRing) {
  const Grid grid(4);
  Eigen::VectorXd z(2 * grid.num_interior);
  for (int v = 0; v < (grid.n + 1) * (grid.n + 1); ++v)
    if (grid.variable[v] >= 0) z.segment<2>(2 * grid.variable[v]) = grid.rest(v);
  const int centre = 2 * (grid.n + 1) + 2;
  z.segment<2>(2 * grid.variable[centre]) = Eigen::Vector2d(3.6, 2.9);  // beyond its neighbour at (3, 2)
  ASSERT_LT(grid.min_signed_area(z), 0);
  EXPECT_TRUE(untangle(grid.problem(), z).unfolded);
  EXPECT_GT(grid.min_signed_area(z), 0);
}

TEST(Untangle, LeavesTheIdealMapWhereItIs) {
  const Grid grid(4);
  Eigen::VectorXd z(2 * grid.num_interior);
  for (int v = 0; v < (grid.n + 1) * (grid.n + 1); ++v)
    if (grid.variable[v] >= 0) z.segment<2>(2 * grid.variable[v]) = grid.rest(v);
  const Eigen::VectorXd z0 = z;
  const UntangleResult r = untangle(grid.problem(), z);
  EXPECT_TRUE(r.unfolded);
  EXPECT_LT((z - z0).lpNorm<Eigen::Infinity>(), 1e-6);
}

// Impossible: a held vertex inside out (the boundary's own orientation reversed) cannot be opened; the result says so.
TEST(Untangle, SaysWhenItCannot) {
  Grid grid(3);
  UntangleProblem p = grid.problem();
  // Mirror the boundary: every held constant's u negated, so that no map of the interior is unfolded.
  for (auto& corner : p.corner)
    for (auto& c : corner)
      if (c[0].terms.empty()) c[0].constant = -c[0].constant;
  Eigen::VectorXd z = Eigen::VectorXd::Constant(p.num_variables, 1.5);
  EXPECT_FALSE(untangle(p, z).unfolded);
  EXPECT_TRUE(z.allFinite());
}

// The least-squares start: on the grid, whose ideal map is reachable, it is the ideal map whatever the start.
TEST(Untangle, LeastSquaresStartIsTheIdealMapWhenOneExists) {
  const Grid grid(6);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> inside(0.5, 5.5);
  Eigen::VectorXd z(2 * grid.num_interior);
  for (int k = 0; k < z.size(); ++k) z[k] = inside(rng);
  const Eigen::VectorXd start = least_squares_start(grid.problem(), z);
  ASSERT_EQ(start.size(), z.size());
  for (int v = 0; v < (grid.n + 1) * (grid.n + 1); ++v)
    if (grid.variable[v] >= 0) {
      EXPECT_LT((start.segment<2>(2 * grid.variable[v]) - grid.rest(v)).norm(), 1e-6) << v;
    }
  EXPECT_GT(grid.min_signed_area(start), 0.49);
}

}  // namespace
}  // namespace trivcon::quad
