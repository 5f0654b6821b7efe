// SPDX-License-Identifier: MIT
// Internal: removes the folds a map keeps, locally, with the map's exact relations held (used by
// src/quad/param.cpp after the rounding; the mathematics: docs/param.md, "Untangling").
//
// The map on a set of faces is affine in a few real variables z: each corner's u and v is a constant plus a
// sparse combination of z (the seamless map's substitution x = P y with every other unknown held, so that
// transitions, cones on integer points and aligned iso-lines stay exact whatever z is). The untangling
// minimises, over z, the regularised barrier energy of Garanzha, Kaporin, Kudryavtseva, Protais, Ray and
// Sokolov, "Foldover-free maps in 50 lines of code" (SIGGRAPH 2021): per face, of the Jacobian J relative to
// the ideal one (the field's frame at the target scale, so that J = I is a perfect unit square),
//   area · ((1 − λ) |J|² / χ(det J, ε) + λ (det² J + 1) / χ(det J, ε)),   χ(D, ε) = (D + √(ε² + D²)) / 2,
// with ε lowered by their rule as the smallest determinant grows, until every face has det J > 0. χ > 0 for
// every D, so the energy is finite on folded maps and pushes them open; as ε → 0 on an unfolded map it
// becomes a barrier that keeps them so. The minimisation is L-BFGS with a backtracking line search (our own:
// the problems are small, a few hundred variables, and the method is a few dozen lines).
#pragma once
#include <Eigen/Core>

#include <array>
#include <utility>
#include <vector>

namespace trivcon::quad {

// c + Σ coefficient · z[variable]
struct AffineForm {
  double constant = 0;
  std::vector<std::pair<int, double>> terms;
};

struct UntangleProblem {
  int num_variables = 0;
  // Per face: the area weight, and the gradients of its three hat functions already multiplied by the inverse
  // of the ideal Jacobian (so that J = Σ_i (u_i, v_i)ᵀ gradient[i]ᵀ is the relative Jacobian).
  std::vector<double> area;
  std::vector<std::array<Eigen::Vector2d, 3>> gradient;
  // Per face and corner: u and v.
  std::vector<std::array<std::array<AffineForm, 2>, 3>> corner;
};

struct UntangleResult {
  bool unfolded = false;     // every face has det J > min_determinant at the end
  double min_determinant = 0;  // the smallest det J at the end (relative: 1 is the ideal area)
  int outer_iterations = 0, inner_iterations = 0;
};

// Minimises from z (which it updates) until every face of the problem has det J > min_determinant, or the
// iteration budgets are spent. `lambda` weighs the area term against the shape term.
UntangleResult untangle(const UntangleProblem& problem, Eigen::VectorXd& z, double min_determinant = 1e-3, double lambda = 0.5,
                        int max_outer = 30, int max_inner = 100);

// The z minimising Σ area · |J − I|² (the map's own least squares on these faces, folds allowed), a start for
// `untangle` that winds around each vertex as the field does: a map the barrier untangled can keep a ring that
// winds once too often beside one that winds once too few (a cone's turn passed to its neighbour), which no
// fold-free path leaves. Returns z unchanged when the system cannot be factored.
Eigen::VectorXd least_squares_start(const UntangleProblem& problem, const Eigen::VectorXd& z);

}  // namespace trivcon::quad
