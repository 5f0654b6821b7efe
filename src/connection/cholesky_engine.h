// SPDX-License-Identifier: MIT
// src/connection/cholesky_engine.h (internal): the default route of ConnectionSolver (trivcon/solver.h).
//
// One supernodal Cholesky factorization R Rᵀ = Π M Πᵀ of the whole normal matrix
//   M = A W Aᵀ = [ D W Dᵀ   D W Cᵀ ]
//                [ C W Dᵀ   C W Cᵀ ],
// with the vertex rows in a minimum-degree order (vertex_order) and the cycle rows C forced last. Then
// the trailing block R_CC of the factor is the Cholesky factor of the Schur complement S, so
// P = S⁻¹ = R_CC⁻ᵀ R_CC⁻¹ costs O(|C|³) with no extra solves, and an edit needs one forward and one
// backward substitution: the forward part of the vertex rows does not depend on b_C. The forward part is
// sparse too: with a base right-hand side set (set_base_rhs), a new b_D that differs from it in a few
// rows (a new set of singular vertices) only updates the supernodes on their paths to the root.
//
// libamd / libcamd order (see vertex_order) and trivcon's own symbolic analysis (src/linalg/symbolic.h) gives
// the supernodal structure; the numeric factorization is ours on OpenMP's threads (src/linalg/supernodal.h)
// or, with Factorization::Cholmod in a build with TRIVCON_WITH_SUITESPARSE, cholmod_factorize into a factor
// of the same structure, whose values are copied. The substitutions read the values in that structure.
#pragma once
#include <functional>
#include <memory>
#include <vector>

#include "connection/assembly.h"
#include "connection/solver_engine.h"
#include "linalg/symbolic.h"
#include "trivcon/solver.h"

namespace trivcon::connection {

// A symbolic factorization and the pattern it was computed for (behind trivcon::SolverAnalysis).
struct AnalysisState {
  linalg::SymbolicFactor symbolic;
  bool analysed = false;  // `symbolic` holds an analysis (false for an empty system)
  int nD = 0, nC = 0;
  std::vector<int> outer, inner;
  double seconds = 0;
};

// Orders and analyses M (nD vertex rows, then nC cycle rows kept last) into `state`.
void analyse(const Csc& M, int nD, int nC, AnalysisState& state);

// The rows of A (see normal_matrix): vertex rows given per system edge by the rows of its two ends (a
// boundary or dropped vertex has none), then the extra rows Et (fixed-face paths that are ordered with
// the vertex rows), then the cycle rows Ct (last). `analysis`, if given, is asked for a symbolic
// factorization once A W Aᵀ is assembled; it is used if it was made for this pattern.
// Throws trivcon::Error when the system is not positive definite (naming the cycle rows when they are
// the cause) or the Schur complement is too ill-conditioned to choose free indices.
std::unique_ptr<SolverEngine> make_cholesky_engine(const EdgeEnds& ends, int num_vertex_rows, const SparseMatrix& Et,
                                                   const SparseMatrix& Ct, const Eigen::VectorXd& w, Factorization factorization,
                                                   SetupTimings& timings,
                                                   const std::function<std::unique_ptr<AnalysisState>()>& analysis = {});

}  // namespace trivcon::connection
