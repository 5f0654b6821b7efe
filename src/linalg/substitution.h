// SPDX-License-Identifier: MIT
// Internal: solves with a numeric supernodal Cholesky factor (L Lᴴ x = b) on several threads.
//
// Why not cholmod_solve: CHOLMOD 3 (Debian 12) visits the supernodes one after another, on one core, with a
// BLAS call per supernode even where a supernode is a few columns wide (most of them, on a mesh). The inverse
// iterations of the smoothest field (trivcon/auto.h) are a chain of such solves, which took as long as the
// factorization itself on large meshes. Here, as for the factorization (src/linalg/supernodal.h), the
// supernodal elimination tree is split into a top and disjoint subtrees, one set per thread:
// - forward, L y = P b: each thread its subtrees (descendants first); what a subtree sends to rows of the
//   top goes to a buffer of that thread's own and is added afterwards, so the result does not depend on
//   the timing of the threads; then the top, one supernode at a time;
// - backward, Lᴴ z = y: the top, then each thread its subtrees (ancestors first; a subtree reads only
//   rows of its own ancestors, done before it);
// - x = Pᵀ z.
// A solve reads each entry of the factor once, so it is bound by memory, not flops: each supernode's
// columns are read as a stream (forward: first to last; backward: last to first, so that the whole
// backward pass is one descending stream the processor prefetches), with plain loops (BLAS's per-call cost
// is more than most supernodes' work). The split is balanced by entries and goes down the tree while that
// shortens top + heaviest part (split_tree's `deepen`). It is several times faster than cholmod_solve
// (BENCHMARKS.md, "Figures that were in code comments").
// solve, solve_in_factor_order and forward_in_factor_order are not for concurrent calls on one object (their work vectors are shared).
#pragma once
#ifdef TRIVCON_WITH_SUITESPARSE
#include <cholmod.h>
#endif

#include <complex>
#include <utility>
#include <vector>

#include "linalg/supernodal.h"

namespace trivcon::linalg {

// T is double for a real (LLᵀ) factor, std::complex<double> for a complex (LLᴴ) one; the factor must be
// supernodal and numeric with that type (linalg::factorize / factorize_complex): trivcon's own symbolic factor
// (src/linalg/symbolic.h) with its values, or, in a build with SuiteSparse, CHOLMOD's factor object. The plan
// (tree split, permutation) is made once; the factor's values are read at each solve, so a refactorization
// with the same symbolic factor (the curvature alignment of trivcon/auto.h) needs no new plan. The factor
// (and `values`) must outlive the object.
template <class T>
class Substitution {
 public:
  // `values`: the factor's entries (L.xsize), as factorize / factorize_complex fill them; read at each solve.
  Substitution(const SymbolicFactor& L, const FactorValues<T>& values);
#ifdef TRIVCON_WITH_SUITESPARSE
  explicit Substitution(const cholmod_factor& L);
#endif
  // x ← A⁻¹ x for A = Pᵀ L Lᴴ P, x in the matrix's own order (as cholmod_solve(CHOLMOD_A, …)); x has n entries.
  void solve(T* x) const;
  // The same in the factor's order: z ← (L Lᴴ)⁻¹ z, z[k] the entry of matrix row permutation()[k].
  void solve_in_factor_order(T* z) const;
  // Its first half alone: z ← L⁻¹ z in the factor's order (the trivial-connection solver's full forward
  // substitution, before its own choice of the cycle rows' right-hand side).
  void forward_in_factor_order(T* z) const;
  // Its second half alone: z ← L⁻ᴴ z in the factor's order (the trivial-connection solver's backward
  // substitution, after its own sparse forward update). Uses no member work vector.
  void backward_in_factor_order(T* z) const;
  // z += L⁻¹ d in the factor's order, for d with the few nonzeros `entries` (factor position, value): only the
  // supernodes on the paths from those entries to the root of the elimination tree are visited, in increasing
  // order, on one thread (a right-hand side with few nonzeros touches a small part of the factor).
  void forward_update(const std::vector<std::pair<int, T>>& entries, T* z) const;
  const std::vector<int>& permutation() const { return perm_; }
  int size() const { return n_; }

 private:
  void plan();
  const T* values() const;
  Supernodes S_;                              // the structure (stable); values through values()
#ifdef TRIVCON_WITH_SUITESPARSE
  const cholmod_factor* cholmod_ = nullptr;   // CHOLMOD's factor, whose x may be reallocated by a refactorization
#endif
  const FactorValues<T>* values_ = nullptr;    // the values of trivcon's own factor
  int n_ = 0;
  std::vector<int> perm_;                     // factor position k holds matrix row perm_[k]
  std::vector<int> top_;                      // supernodes above the split, increasing
  std::vector<std::vector<int>> part_;        // per thread: whole subtrees, increasing
  std::vector<int> top_slot_;                 // per column: its slot in a thread's top buffer, or −1 below the top
  int top_columns_ = 0;
  std::vector<int> owner_, parent_;           // per column its supernode; per supernode its parent (−1: a root)
  mutable std::vector<T> work_;               // z in factor order
  mutable std::vector<T> update_;             // forward_update's d, zero outside a call
  mutable std::vector<int> stamp_;            // per supernode: the forward_update call that last visited it
  mutable int calls_ = 0;
  mutable std::vector<std::vector<T>> send_;  // per thread: what its subtrees send to the top's columns
};

extern template class Substitution<double>;
extern template class Substitution<std::complex<double>>;

}  // namespace trivcon::linalg
