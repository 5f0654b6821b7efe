// SPDX-License-Identifier: MIT
// Internal: the numeric supernodal Cholesky factorization behind ConnectionSolver, on several threads.
//
// trivcon's own symbolic analysis (src/linalg/symbolic.h, docs/solver.md) gives the supernodal structure; this
// computes the factor's values in it, which the substitutions (src/linalg/substitution.h) and the solver's
// sparse forward update read. In a build with TRIVCON_WITH_SUITESPARSE it can fill CHOLMOD's own supernodal
// factor object the same way (the arrays mean the same; the tests compare). Why not cholmod_factorize: CHOLMOD 3
// (Debian 12) visits the supernodes one after another and uses the second core only inside BLAS calls on
// large supernodes, while on a mesh most of the time goes to the many small supernodes near the leaves of
// the elimination tree. Here independent subtrees are factored on OpenMP's threads (one set of subtrees per thread), then the top of the
// tree with multithreaded BLAS. Same algorithm as CHOLMOD's (left-looking supernodal: each supernode gathers the updates of its
// descendants, then a dense Cholesky of its diagonal block and a triangular solve of the rows below), same storage.
#pragma once
#ifdef TRIVCON_WITH_SUITESPARSE
#include <cholmod.h>
#endif

#include <Eigen/Core>

#include <array>
#include <complex>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

#include "linalg/symbolic.h"

namespace trivcon::linalg {

// The supernodal elimination tree of a factor, split for `parts` threads: `top` (the supernodes above
// the split, done one at a time) and `parts` sets of whole subtrees below it that do not depend on each
// other, balanced by `work` (per supernode; a subtree's work is the sum over it): the largest remaining
// subtree is split at its root while it holds more than 1/parts of the work below the top and more than
// `min_split`, then the subtrees go, largest first, to the part with the least work so far. Each list is
// in increasing supernode order (descendants first). parts ≥ 1; with 1 everything is in part[0].
// With `deepen`, the splitting then goes further down while that shortens the critical path, the work of the
// top plus that of the heaviest part (for a top done on one thread: the parallel substitution of
// src/linalg/substitution.h); the largest subtree left is then smaller still.
struct TreeSplit {
  std::vector<int> top;
  std::vector<std::vector<int>> part;
};
TreeSplit split_tree(const std::vector<int>& parent, const std::vector<double>& work, double min_split, int parts = 2, bool deepen = false);

// The values of a factor of trivcon's own (below): a std::vector whose new entries are left unwritten.
// The numeric factorization writes every entry, supernode by supernode on the thread that computes it; a
// plain std::vector would first zero them all on one thread, which on a large mesh costs more than the
// factorization's own first touch of that memory (the kernel's page clearing, then, spread over the threads).
template <class T>
struct UninitializedAllocator : std::allocator<T> {
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);
  template <class U>
  struct rebind {
    using other = UninitializedAllocator<U>;
  };
  UninitializedAllocator() = default;
  template <class U>
  UninitializedAllocator(const UninitializedAllocator<U>&) noexcept {}
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    if constexpr (sizeof...(Args) > 0) ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
template <class T>
using FactorValues = std::vector<T, UninitializedAllocator<T>>;

// A supernodal factor, read in place (CHOLMOD's, or one of src/linalg/symbolic.h, whose arrays mean the same):
// supernode s holds the columns first(s) … first(s) + cols(s) − 1; its rows (its own columns first, then rows
// of its ancestors) are row(s, 0 … height(s) − 1), its entries the height(s) × cols(s) column-major block
// values(s), starting at x + px[s].
struct Supernodes {
  const int *super, *pi, *px, *rows;
  const double* x;
  int count;
#ifdef TRIVCON_WITH_SUITESPARSE
  explicit Supernodes(const cholmod_factor* L)
      : super(static_cast<const int*>(L->super)),
        pi(static_cast<const int*>(L->pi)),
        px(static_cast<const int*>(L->px)),
        rows(static_cast<const int*>(L->s)),
        x(static_cast<const double*>(L->x)),
        count(static_cast<int>(L->nsuper)) {}
#endif
  // `x`: the factor's values (L.xsize entries; for a complex factor, the (real, imaginary) pairs), or null
  // where only the structure is read.
  Supernodes(const SymbolicFactor& L, const double* x)
      : super(L.super.data()), pi(L.pi.data()), px(L.px.data()), rows(L.s.data()), x(x), count(L.nsuper) {}
  int first(int s) const { return super[s]; }
  int cols(int s) const { return super[s + 1] - super[s]; }
  int height(int s) const { return pi[s + 1] - pi[s]; }
  int row(int s, int i) const { return rows[pi[s] + i]; }
  Eigen::Map<const Eigen::MatrixXd> values(int s) const { return {x + px[s], height(s), cols(s)}; }
  // The supernode of each column.
  std::vector<int> owners() const;
};

// Parent of each supernode in the supernodal elimination tree (−1 at a root), given owners().
std::vector<int> supernode_parents(const Supernodes& L, const std::vector<int>& owner);

// The factor's block at the columns k with place[k] ≥ 0 (factor positions; m of them) and the same rows, dense:
// block(place[i], place[j]) = L(i, j). Every row below such a column must be one of them (they are the top of
// the elimination tree, as an order with them constrained last leaves them; a trivcon::Error otherwise).
Eigen::MatrixXd trailing_block(const Supernodes& L, const std::vector<int>& place, int m);

#ifdef TRIVCON_WITH_SUITESPARSE
// Computes the numeric LLᵀ factor in L (a supernodal symbolic factor from cholmod_analyze_p, with its
// permutation L.Perm) of the symmetric n × n matrix whose upper triangle is given in compressed columns
// (outer, inner, values; rows ≤ column, in the matrix's own numbering). Returns n on success, or the
// first factor column found not positive definite (as CHOLMOD's L->minor); throws trivcon::Error if
// CHOLMOD cannot allocate the factor.
int factorize(cholmod_factor& L, const std::vector<int>& outer, const std::vector<int>& inner, const std::vector<double>& values,
              cholmod_common& c);
// The same for a Hermitian matrix (LLᴴ): `values` holds (real, imaginary) pairs, entry k at 2k, 2k + 1, as
// CHOLMOD's complex (interleaved) storage; the factor becomes CHOLMOD_COMPLEX, so cholmod_solve reads it.
// Used by the smoothest field of trivcon/auto.h.
int factorize_complex(cholmod_factor& L, const std::vector<int>& outer, const std::vector<int>& inner, const std::vector<double>& values,
                      cholmod_common& c);
#endif

// The same two into a factor of trivcon's own symbolic analysis (src/linalg/symbolic.h, permutation L.perm):
// `x` becomes its values, L.xsize entries. Returns n on success, or the first factor column found not
// positive definite.
int factorize(const SymbolicFactor& L, FactorValues<double>& x, const std::vector<int>& outer, const std::vector<int>& inner,
              const std::vector<double>& values);
int factorize_complex(const SymbolicFactor& L, FactorValues<std::complex<double>>& x, const std::vector<int>& outer,
                      const std::vector<int>& inner, const std::vector<double>& values);

// R ← R⁻¹ for a square lower triangular R (its strict upper triangle is neither read nor written): LAPACK's
// dtrtri, blocked, on OpenBLAS's threads. Returns false, R partly overwritten, if a diagonal entry is 0.
bool invert_lower_triangular(Eigen::MatrixXd& R);

}  // namespace trivcon::linalg
