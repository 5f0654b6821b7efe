// SPDX-License-Identifier: MIT
// The tests' own reading of a per-face field (test_matching, test_split_large_turns): indices from world
// directions and dihedral rotations alone, with the principal matching or a given one; and the coarse
// icosphere whose connection turns by more than π/N across edges.
#pragma once
#include <Eigen/Geometry>
#include <cmath>
#include <map>

#include "trivcon/common.h"
#include "trivcon/generate.h"
#include "trivcon/indices.h"

namespace trivcon::reference {

inline double wrap(double a) { return a - 2 * kPi * std::floor((a + kPi) / (2 * kPi)); }

// The test's own mesh data: per face its unit normal; per interior edge (i < j) its two faces, L holding
// the half-edge i → j.
struct Edges {
  std::map<std::pair<int, int>, std::pair<int, int>> faces;  // (i, j) → (L, R)
};
inline Edges edges_of(const MatrixX3i& F) {
  Edges out;
  std::map<std::pair<int, int>, int> half;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) half[{F(f, k), F(f, (k + 1) % 3)}] = f;
  for (auto [h, f] : half)
    if (h.first < h.second && half.count({h.second, h.first})) out.faces[h] = {f, half.at({h.second, h.first})};
  return out;
}
inline Eigen::Vector3d normal_of(const MatrixX3d& V, const MatrixX3i& F, int f) {
  const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
  return (b - a).cross(c - a).normalized();
}
// The world direction d of face L, rotated about the shared edge into R's plane (the discrete
// Levi-Civita transport), then its signed angle to R's direction e about R's normal.
inline double transported_angle(const MatrixX3d& V, const MatrixX3i& F, int i, int j, int L, int R, const Eigen::Vector3d& d,
                         const Eigen::Vector3d& e) {
  const Eigen::Vector3d nL = normal_of(V, F, L), nR = normal_of(V, F, R);
  const Eigen::Vector3d axis = (Eigen::Vector3d(V.row(j)) - Eigen::Vector3d(V.row(i))).normalized();
  const double dihedral = std::atan2(nL.cross(nR).dot(axis), nL.dot(nR));
  const Eigen::Vector3d moved = Eigen::AngleAxisd(dihedral, axis) * d;
  return std::atan2(moved.cross(e).dot(nR), moved.dot(e));  // angle from moved to e, counter-clockwise about nR
}

// Independent indices from world directions: with `given` a matching per edge ((i, j) → m), else the
// principal one. Index of interior vertex v: (K_v + Σ over its edges of ± the jump) / 2π, K_v = 2π − Σ angles.
inline std::map<int, int> independent_indices(const MatrixX3d& V, const MatrixX3i& F, const MatrixX3d& dirs, int N,
                                       const std::map<std::pair<int, int>, int>* given) {
  const Edges edges = edges_of(F);
  std::map<int, double> defect, sum;
  std::map<int, int> boundary;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int v = F(f, k);
      const Eigen::Vector3d u = V.row(F(f, (k + 1) % 3)) - V.row(v), w = V.row(F(f, (k + 2) % 3)) - V.row(v);
      defect[v] += std::atan2(u.cross(w).norm(), u.dot(w));
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      if (!edges.faces.count({std::min(a, b), std::max(a, b)})) boundary[a] = boundary[b] = 1;
    }
  for (auto [e, lr] : edges.faces) {
    const auto [L, R] = lr;
    // β_R + 2πm/N − (β_L + ρ): the angle from L's transported direction to R's direction m.
    double jump;
    const double base = transported_angle(V, F, e.first, e.second, L, R, dirs.row(L).transpose(), dirs.row(R).transpose());
    if (given) {
      jump = wrap(base + 2 * kPi * given->at(e) / N);
    } else {
      jump = base - (2 * kPi / N) * std::round(base / (2 * kPi / N));
    }
    sum[e.second] += jump, sum[e.first] -= jump;
  }
  std::map<int, int> out;
  for (auto [v, angles] : defect) {
    if (boundary.count(v)) continue;
    const int n = static_cast<int>(std::lround((2 * kPi - angles + sum[v]) / (2 * kPi) * N));
    if (n != 0) out[v] = n;
  }
  return out;
}

// A coarse icosphere with a large index at one vertex: the connection must turn by more than π/N across
// its edges.
struct LargeTurnCase {
  Mesh mesh = make_icosphere(1);
  IndexPrescription p;
  LargeTurnCase() {
    p.N = 4;
    p.vertex[0] = 6;  // +3/2
    p.vertex[1] = 1;
    p.vertex[2] = 1;
  }
};

}  // namespace trivcon::reference
