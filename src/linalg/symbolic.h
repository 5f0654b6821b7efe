// SPDX-License-Identifier: MIT
// Internal: the symbolic analysis of a sparse Cholesky factorization, and the minimum degree orders it is given.
//
// Given the pattern of a symmetric matrix A and a fill-reducing order, symbolic_analysis() computes the
// structure of the supernodal factor L of P A Pᵀ = L Lᵀ that the numeric factorization (src/linalg/supernodal.h)
// fills: the elimination tree, its postorder (composed into the order), the column counts of L, the
// fundamental supernodes, their relaxed amalgamation and the rows of each supernode, in the arrays of
// CHOLMOD's supernodal factor object (super, pi, px, s) with the same meaning, and with CHOLMOD's default
// rule and parameters (docs/solver.md, "Symbolic analysis"). amd_ordering() and camd_ordering() call libamd and
// libcamd (BSD) with the options CHOLMOD passes them by default. None of this needs CHOLMOD.
#pragma once
#include <array>
#include <cstddef>
#include <vector>

namespace trivcon::linalg {

// The patterns below: the leading n × n block of a symmetric matrix given as its upper triangle in compressed
// columns (outer, at least n + 1 entries; inner; rows ≤ column, in any order within a column). Entries below
// the diagonal are ignored, as by CHOLMOD's view of an upper triangle (stype = 1).

// AMD's order of the pattern (order[k] = row eliminated k-th): amd_order with a dense-row threshold of
// 10 √n (rows with more entries, and more than 16, are ordered last) and aggressive absorption, as cholmod_amd. Throws trivcon::Error
// naming AMD's status if it fails.
std::vector<int> amd_ordering(const std::vector<int>& outer, const std::vector<int>& inner, int n);

// CAMD's order of the pattern with each row i in the constraint set set[i] ∈ [0, n): the rows of set 0 are
// eliminated first, then those of set 1, and so on (camd_order, options as cholmod_camd). Throws
// trivcon::Error if the sets are invalid or CAMD fails.
std::vector<int> camd_ordering(const std::vector<int>& outer, const std::vector<int>& inner, int n, const std::vector<int>& set);

// A postorder of the forest `parent` (parent[j] = −1 at a root; an elimination tree has parent[j] > j):
// post[k] = node visited k-th, each
// node after its descendants, the subtrees of one node one after another. Roots are taken in increasing
// order, and the children of a node in increasing order of their index, or with `weight` in increasing
// order of weight[j] clamped to [0, n − 1] (ties by index): cholmod_postorder's order.
std::vector<int> postorder(const std::vector<int>& parent, const std::vector<int>* weight = nullptr);

// Relaxed amalgamation (docs/solver.md): two supernodes, a child and its parent that follows it directly,
// with ns columns together and a fraction z of explicit zeros in the merged supernode (those of earlier
// merges included), are merged when ns ≤ nrelax[0], or the merge adds no zeros, or ns ≤ nrelax[1] and
// z < zrelax[0], or ns ≤ nrelax[2] and z < zrelax[1], or z < zrelax[2]. The defaults are CHOLMOD's.
struct SymbolicOptions {
  bool postorder = true;   // postorder the elimination tree, weighted by the column counts (CHOLMOD's postorder = 1)
  bool amalgamate = true;  // false: the fundamental supernodes alone
  std::array<int, 3> nrelax = {4, 16, 48};
  std::array<double, 3> zrelax = {0.8, 0.1, 0.05};
};

// The supernodal symbolic factor. Factor column k is matrix row perm[k]. Supernode s holds the columns
// super[s] … super[s + 1] − 1; its rows are s[pi[s]] … s[pi[s + 1] − 1] (its own columns first, then rows of
// its ancestors, increasing); its values are a height × columns column-major block starting at entry
// px[s] of the factor's values (real or complex entries), xsize in all.
struct SymbolicFactor {
  int n = 0;
  std::vector<int> perm;
  std::vector<int> parent;        // the elimination tree of P A Pᵀ (factor columns), −1 at roots
  std::vector<int> column_count;  // entries of each column of L, its diagonal included
  int nsuper = 0;
  std::vector<int> super, pi, px, s;
  size_t nnz = 0;       // entries of L without the explicit zeros of the amalgamation: Σ column_count (CHOLMOD's lnz)
  double flops = 0;     // Σ column_count², the flop count CHOLMOD reports (Common->fl)
  size_t xsize = 0;     // px[nsuper]: entries of the supernodal blocks, explicit zeros included
  size_t maxcsize = 1;  // the largest update one supernode sends to an ancestor (rows × columns), as CHOLMOD's
  int maxesize = 1;     // the most rows of a supernode below its own columns, as CHOLMOD's
};

// The symbolic factorization of the pattern in the order `order` (order[k] = row eliminated k-th, a
// permutation of 0 … n − 1). With options.postorder the factor's perm is `order` followed by the
// weighted postorder of the elimination tree, as cholmod_analyze_p with postorder = 1; otherwise it is
// `order` itself. Throws trivcon::Error if the order is not a permutation, an index is out of range, or
// the factor would have more entries than an int can address.
SymbolicFactor symbolic_analysis(const std::vector<int>& outer, const std::vector<int>& inner, int n, const std::vector<int>& order,
                                 const SymbolicOptions& options = {});

}  // namespace trivcon::linalg
