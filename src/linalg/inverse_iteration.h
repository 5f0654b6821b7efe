// SPDX-License-Identifier: MIT
// src/linalg/inverse_iteration.h (internal): the smallest eigenvector of A x = λ M x (A Hermitian positive
// definite, factored; M diagonal, non-negative) by inverse power iteration, for several independent groups of
// unknowns at once (a mesh's components: A has no entries between groups), with an affine term d (Dirichlet
// values): x ← s (A⁻¹ (M x + d)), s = 1 / ‖·‖_M per group. A group with `normalised` 0 is not scaled and has no
// mass (its unknowns solve A x = d: the Dirichlet problem). Used by the smoothest field (trivcon/auto.h,
// docs/auto.md "The eigen-solve").
#pragma once
#include <string>
#include <vector>

#include "linalg/substitution.h"

namespace trivcon::linalg {

struct InverseIterationProblem {
  std::vector<double> mass;       // per unknown (matrix order)
  std::vector<int> group;         // per unknown: its group, in [0, groups)
  std::vector<char> normalised;   // per group: 1 to scale to ‖x‖_M = 1, 0 to leave as solved
  std::vector<double> affine;     // per unknown, 2 numbers for a complex T (real, imaginary), or empty
  int iterations = 1;
  std::string what;               // names the caller in errors ("automatic singularities")
};

// `x` (matrix order; for a complex T, (real, imaginary) pairs) holds the start and receives the result, each
// normalised group with ‖x‖_M = 1. Calls check_cancelled() (trivcon/cancel.h) before each iteration. Throws
// trivcon::Error naming the group when its norm vanishes or is not finite.
template <class T>
void inverse_iteration(const Substitution<T>& factor, const InverseIterationProblem& problem, std::vector<double>& x);

}  // namespace trivcon::linalg
