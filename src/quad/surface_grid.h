// SPDX-License-Identifier: MIT
// Nearest points of the input surface, for the quad mesh's check and relaxation (src/quad/quad_check.cpp,
// src/quad/relax.cpp).
#pragma once
#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>
#include <vector>

#include "trivcon/common.h"

namespace trivcon::quad {

// The point of triangle (a, b, c) nearest to p, with its barycentric coordinates when `bary` is given (Ericson,
// Real-Time Collision Detection, §5.1.5: the Voronoi regions of the vertices, then of the edges, then the inside).
inline Eigen::Vector3d closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                           const Eigen::Vector3d& c, Eigen::Vector3d* bary = nullptr) {
  Eigen::Vector3d unused;
  Eigen::Vector3d& w = bary ? *bary : unused;
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return w = Eigen::Vector3d(1, 0, 0), a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return w = Eigen::Vector3d(0, 1, 0), b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double s = d1 / (d1 - d3);
    return w = Eigen::Vector3d(1 - s, s, 0), a + ab * s;
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return w = Eigen::Vector3d(0, 0, 1), c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double s = d2 / (d2 - d6);
    return w = Eigen::Vector3d(1 - s, 0, s), a + ac * s;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double s = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return w = Eigen::Vector3d(0, 1 - s, s), b + (c - b) * s;
  }
  const double denominator = va + vb + vc;
  if (!(std::abs(denominator) > 0)) return w = Eigen::Vector3d(1, 0, 0), a;  // a degenerate triangle: its first corner will do
  const double v = vb / denominator, u = vc / denominator;
  return w = Eigen::Vector3d(1 - v - u, v, u), a + ab * v + ac * u;
}

// The input's triangles in a uniform grid of cells about two mean edge lengths wide: nearest-triangle queries
// look at rings of cells around the query point until no triangle further out can be nearer.
class SurfaceGrid {
 public:
  SurfaceGrid(const MatrixX3d& V, const MatrixX3i& F, long long budget) : V_(V), F_(F), stamp_(F.rows(), -1), budget_(budget) {
    lo_ = V.colwise().minCoeff().transpose(), hi_ = V.colwise().maxCoeff().transpose();
    double mean = 0;
    for (int f = 0; f < F.rows(); ++f)
      for (int k = 0; k < 3; ++k) mean += (V.row(F(f, k)) - V.row(F(f, (k + 1) % 3))).norm();
    mean /= std::max<Eigen::Index>(1, 3 * F.rows());
    const Eigen::Vector3d extent = hi_ - lo_;
    cell_ = std::max({2 * mean, extent.maxCoeff() * 1e-6, std::numeric_limits<double>::min()});
    // No more cells than about 8 per triangle: a mesh of long thin triangles gets larger cells.
    for (;;) {
      for (int a = 0; a < 3; ++a) n_[a] = std::max(1, static_cast<int>(std::ceil(extent[a] / cell_)));
      if (static_cast<double>(n_[0]) * n_[1] * n_[2] <= 8.0 * F.rows() + 64) break;
      cell_ *= 1.5;
    }
    std::vector<int> count(static_cast<size_t>(n_[0]) * n_[1] * n_[2] + 1, 0);
    auto each_cell = [&](int f, auto&& visit) {
      Eigen::Vector3d a = V.row(F(f, 0)).transpose(), b = a;
      for (int k = 1; k < 3; ++k) a = a.cwiseMin(V.row(F(f, k)).transpose()), b = b.cwiseMax(V.row(F(f, k)).transpose());
      const std::array<int, 3> i0 = cell_of(a), i1 = cell_of(b);
      for (int x = i0[0]; x <= i1[0]; ++x)
        for (int y = i0[1]; y <= i1[1]; ++y)
          for (int z = i0[2]; z <= i1[2]; ++z) visit(index({x, y, z}));
    };
    for (int f = 0; f < F.rows(); ++f) each_cell(f, [&](int c) { ++count[c + 1]; });
    std::partial_sum(count.begin(), count.end(), count.begin());
    offsets_ = count;
    faces_.resize(offsets_.back());
    for (int f = 0; f < F.rows(); ++f) each_cell(f, [&](int c) { faces_[count[c]++] = f; });
  }

  // The nearest triangle to p and its distance, known to be at most `limit` (a point of the surface is that near);
  // with `component` ≥ 0, among that component's triangles only. Returns face −1 when the work budget given at
  // construction (cells and triangles looked at, over all queries) ran out.
  std::pair<int, double> nearest(const Eigen::Vector3d& p, double limit, int component, const std::vector<int>& face_component) {
    ++query_;
    const std::array<int, 3> c = cell_of(p);
    double best = limit * (1 + 1e-9) + std::numeric_limits<double>::min();
    int best_face = -1;
    const int rings = std::max({n_[0], n_[1], n_[2]});
    for (int r = 0; r <= rings; ++r) {
      if (work_ > budget_) return {-1, limit};
      for (int x = c[0] - r; x <= c[0] + r; ++x)
        for (int y = c[1] - r; y <= c[1] + r; ++y)
          for (int z = c[2] - r; z <= c[2] + r; ++z) {
            if (std::max({std::abs(x - c[0]), std::abs(y - c[1]), std::abs(z - c[2])}) != r) continue;
            if (x < 0 || y < 0 || z < 0 || x >= n_[0] || y >= n_[1] || z >= n_[2]) continue;
            const int cell = index({x, y, z});
            work_ += 1 + offsets_[cell + 1] - offsets_[cell];
            for (int j = offsets_[cell]; j < offsets_[cell + 1]; ++j) {
              const int f = faces_[j];
              if (stamp_[f] == query_ || (component >= 0 && face_component[f] != component)) continue;
              stamp_[f] = query_;
              const double d = (p - closest_on_triangle(p, V_.row(F_(f, 0)), V_.row(F_(f, 1)), V_.row(F_(f, 2)))).norm();
              if (d < best) best = d, best_face = f;
            }
          }
      // Cells not looked at lie beyond a wall of the block of rings 0..r (where the grid goes on): stop when
      // the nearest such wall is no nearer than the best triangle.
      double unexplored = std::numeric_limits<double>::infinity();
      for (int a = 0; a < 3; ++a) {
        if (c[a] - r > 0) unexplored = std::min(unexplored, p[a] - (lo_[a] + (c[a] - r) * cell_));
        if (c[a] + r < n_[a] - 1) unexplored = std::min(unexplored, lo_[a] + (c[a] + r + 1) * cell_ - p[a]);
      }
      if (best <= unexplored) break;
    }
    return {best_face, best};
  }

 private:
  std::array<int, 3> cell_of(const Eigen::Vector3d& p) const {
    std::array<int, 3> c{};
    for (int a = 0; a < 3; ++a) c[a] = std::clamp(static_cast<int>(std::floor((p[a] - lo_[a]) / cell_)), 0, n_[a] - 1);
    return c;
  }
  int index(const std::array<int, 3>& c) const { return (c[2] * n_[1] + c[1]) * n_[0] + c[0]; }

  const MatrixX3d& V_;
  const MatrixX3i& F_;
  Eigen::Vector3d lo_, hi_;
  double cell_ = 1;
  std::array<int, 3> n_{1, 1, 1};
  std::vector<int> offsets_, faces_, stamp_;
  int query_ = 0;
  long long work_ = 0, budget_ = 0;
};


}  // namespace trivcon::quad
