// SPDX-License-Identifier: MIT
#include "linalg/symbolic.h"

#include <amd.h>
#include <camd.h>

#include <algorithm>
#include <climits>
#include <cstdint>
#include <string>

#include "trivcon/error.h"

namespace trivcon::linalg {

namespace {

// Checks the pattern's arrays: outer has n + 1 nondecreasing offsets from 0 into inner, and every row of
// the leading block's upper triangle is at least 0.
void check_pattern(const std::vector<int>& outer, const std::vector<int>& inner, int n, const char* what) {
  const std::string where = std::string(what) + ": ";
  if (n < 0) throw Error(where + "negative matrix size " + std::to_string(n));
  if (outer.size() < static_cast<size_t>(n) + 1) throw Error(where + "the column offsets have fewer than n + 1 entries");
  if (outer[0] != 0) throw Error(where + "the first column offset is not 0");
  for (int c = 0; c < n; ++c)
    if (outer[c + 1] < outer[c]) throw Error(where + "the column offsets decrease at column " + std::to_string(c));
  if (static_cast<size_t>(outer[n]) > inner.size()) throw Error(where + "the column offsets point past the row indices");
  for (int c = 0; c < n; ++c)
    for (int q = outer[c]; q < outer[c + 1]; ++q)
      if (inner[q] < 0) throw Error(where + "negative row index " + std::to_string(inner[q]) + " in column " + std::to_string(c));
}

// AMD's and CAMD's failure statuses (the two share their values), for a message.
std::string ordering_status(int status) {
  static_assert(AMD_OUT_OF_MEMORY == CAMD_OUT_OF_MEMORY && AMD_INVALID == CAMD_INVALID, "AMD and CAMD share their statuses");
  if (status == AMD_OUT_OF_MEMORY) return "out of memory";
  if (status == AMD_INVALID) return "it found the matrix invalid";
  return "status " + std::to_string(status);
}

// The leading n × n block's upper triangle as AMD and CAMD take it: (outer, inner) themselves when no entry
// lies below the diagonal, otherwise a copy without those (AMD would order them as entries of A + Aᵀ;
// CHOLMOD's upper view ignores them). Points `p` and `i` at the arrays to pass.
struct UpperOnly {
  std::vector<int> outer, inner;
  const int *p = nullptr, *i = nullptr;
  UpperOnly(const std::vector<int>& o, const std::vector<int>& in, int n) : p(o.data()), i(in.data()) {
    bool below = false;
    for (int c = 0; c < n && !below; ++c)
      for (int q = o[c]; q < o[c + 1]; ++q) below = below || in[q] > c;
    if (!below) return;
    outer.assign(static_cast<size_t>(n) + 1, 0);
    for (int c = 0; c < n; ++c) {
      for (int q = o[c]; q < o[c + 1]; ++q)
        if (in[q] <= c) inner.push_back(in[q]);
      outer[c + 1] = static_cast<int>(inner.size());
    }
    p = outer.data(), i = inner.data();
  }
};

// The strictly upper triangle of P A Pᵀ (positions in the order), by columns: column k holds the rows i < k
// with an entry (i, k), each once per entry of A (duplicates are harmless to every use below).
struct Columns {
  std::vector<int> start, row;
};

// The same entries by rows: row i holds the columns k > i.
using Rows = Columns;

// position[r] = where matrix row r is eliminated. Fills the columns, and the rows when `rows` is given.
void permuted_upper(const std::vector<int>& outer, const std::vector<int>& inner, const std::vector<int>& position, Columns& cols,
                    Rows* rows) {
  const int n = static_cast<int>(position.size());
  cols.start.assign(static_cast<size_t>(n) + 1, 0);
  if (rows) rows->start.assign(static_cast<size_t>(n) + 1, 0);
  for (int c = 0; c < n; ++c)
    for (int q = outer[c]; q < outer[c + 1]; ++q) {
      const int r = inner[q];
      if (r >= c) continue;  // the diagonal, or below it
      const int a = position[r], b = position[c];
      ++cols.start[std::max(a, b) + 1];
      if (rows) ++rows->start[std::min(a, b) + 1];
    }
  for (int k = 0; k < n; ++k) cols.start[k + 1] += cols.start[k];
  std::vector<int> col_fill(cols.start.begin(), cols.start.end() - 1), row_fill;
  cols.row.resize(cols.start[n]);
  if (rows) {
    for (int k = 0; k < n; ++k) rows->start[k + 1] += rows->start[k];
    row_fill.assign(rows->start.begin(), rows->start.end() - 1);
    rows->row.resize(rows->start[n]);
  }
  for (int c = 0; c < n; ++c)
    for (int q = outer[c]; q < outer[c + 1]; ++q) {
      const int r = inner[q];
      if (r >= c) continue;
      const int a = position[r], b = position[c], lo = std::min(a, b), hi = std::max(a, b);
      cols.row[col_fill[hi]++] = lo;
      if (rows) rows->row[row_fill[lo]++] = hi;
    }
}

// Liu's algorithm: the parent of column i is the first column k > i whose row k of L has an entry in
// column i. Row k's entries are the columns on the paths up the tree from the rows of A's column k, so
// each entry (i, k) climbs from i to the root of what is built so far, making k that root's parent; the
// climbed path is compressed to point at k (a virtual forest, `ancestor`), giving O(nnz(A) α) time.
std::vector<int> elimination_tree(const Columns& cols, int n) {
  std::vector<int> parent(n, -1), ancestor(n, -1);
  for (int k = 0; k < n; ++k)
    for (int q = cols.start[k]; q < cols.start[k + 1]; ++q)
      for (int i = cols.row[q]; i != -1 && i < k;) {
        const int next = ancestor[i];
        ancestor[i] = k;
        if (next == -1) parent[i] = k;
        i = next;
      }
  return parent;
}

// Gilbert, Ng and Peyton's column counts. Column j of L holds the rows k whose row subtree (the subtree of
// the elimination tree spanned by the columns of row k of L, rooted at k) contains j, so its count is the
// number of row subtrees through j. With the tree postordered, j is a leaf of row subtree k when no earlier
// entry of row k of A lies in j's subtree. Each row subtree is then added at each of its leaves and taken
// away at the least common ancestor of each pair of consecutive leaves (where their paths join); a leaf of
// the tree also starts with 1 (its own row), and a node loses 1 per child (the child's own row ends there).
// The count of j is the sum of these `delta` over j's subtree. The least common ancestors are found with a
// union-find over the nodes done so far (path compression), so the time is O(nnz(A) α).
// `rows`: for column j, the rows k > j with an entry (j, k) of A (the row subtrees j may be a leaf of).
std::vector<int> column_counts(const Rows& rows, const std::vector<int>& parent, const std::vector<int>& post) {
  const int n = static_cast<int>(parent.size());
  std::vector<int> delta(n, 0), first(n, -1), max_first(n, -1), prev_leaf(n, -1), ancestor(n);
  // first[j]: the postorder position of the first descendant of j; leaves start with a count of 1.
  for (int k = 0; k < n; ++k) {
    int j = post[k];
    delta[j] = first[j] == -1 ? 1 : 0;
    for (; j != -1 && first[j] == -1; j = parent[j]) first[j] = k;
  }
  for (int j = 0; j < n; ++j) ancestor[j] = j;
  for (int k = 0; k < n; ++k) {
    const int j = post[k];
    if (parent[j] != -1) --delta[parent[j]];
    for (int q = rows.start[j]; q < rows.start[j + 1]; ++q) {
      const int i = rows.row[q];
      if (first[j] <= max_first[i]) continue;  // j's subtree already holds an entry of row i: not a leaf of its subtree
      max_first[i] = first[j];
      const int previous = prev_leaf[i];
      prev_leaf[i] = j;
      ++delta[j];
      if (previous == -1) continue;  // the first leaf of row subtree i
      int root = previous;
      while (root != ancestor[root]) root = ancestor[root];
      for (int v = previous; v != root;) {
        const int next = ancestor[v];
        ancestor[v] = root;
        v = next;
      }
      --delta[root];  // the least common ancestor of the previous leaf and j
    }
    if (parent[j] != -1) ancestor[j] = parent[j];
  }
  for (int j = 0; j < n; ++j)
    if (parent[j] != -1) delta[parent[j]] += delta[j];
  return delta;
}

// The fundamental supernodes, CHOLMOD's way: column j continues the supernode of j − 1 when j is the parent
// of j − 1, its only child, and L's column j − 1 is column j's pattern plus row j. Returns the first column
// of each supernode and n at the end.
std::vector<int> fundamental_supernodes(const std::vector<int>& parent, const std::vector<int>& count) {
  const int n = static_cast<int>(parent.size());
  std::vector<int> children(n, 0), first;
  for (int j = 0; j < n; ++j)
    if (parent[j] != -1) ++children[parent[j]];
  for (int j = 0; j < n; ++j)
    if (j == 0 || parent[j - 1] != j || count[j - 1] != count[j] + 1 || children[j] > 1) first.push_back(j);
  first.push_back(n);
  return first;
}

// Relaxed amalgamation of the supernodes starting at `first` (docs/solver.md): from the last but one to the
// first, supernode s is merged with s + 1 when s + 1 is its parent now (s + 1 may have absorbed s's
// original parent) and the rule of SymbolicOptions allows it. The merged supernode's leading column has
// the rows of s + 1's plus s's columns. The zeros are counted as CHOLMOD counts them, so that the
// partition is CHOLMOD's: a merge of at most nrelax[0] columns adds none to the count. Returns the first
// column of each supernode kept, then n, and each one's height in `height`.
std::vector<int> amalgamate(const std::vector<int>& first, const std::vector<int>& parent, const std::vector<int>& count,
                            const SymbolicOptions& o, std::vector<int>& height) {
  const int nf = static_cast<int>(first.size()) - 1, n = first.back();
  std::vector<int> owner(n), sparent(nf), cols(nf), merged_into(nf, -1);
  std::vector<std::int64_t> zeros(nf, 0);
  height.resize(nf);
  for (int s = 0; s < nf; ++s) {
    std::fill(owner.begin() + first[s], owner.begin() + first[s + 1], s);
    cols[s] = first[s + 1] - first[s];
    height[s] = count[first[s]];
  }
  for (int s = 0; s < nf; ++s) {
    const int p = parent[first[s + 1] - 1];
    sparent[s] = p == -1 ? -1 : owner[p];
  }
  // Keeps any merge's block within what an int offset (px) can address, in doubles (CHOLMOD's bound).
  const double largest_block = static_cast<double>(INT_MAX) / sizeof(double);
  for (int s = nf - 2; s >= 0 && o.amalgamate; --s) {
    if (sparent[s] == -1) continue;
    int p = sparent[s];
    while (merged_into[p] != -1) p = merged_into[p];
    for (int q = sparent[s]; merged_into[q] != -1;) {  // path compression
      const int next = merged_into[q];
      merged_into[q] = p;
      q = next;
    }
    if (p != s + 1) continue;
    const int ns = cols[s] + cols[s + 1];
    std::int64_t total_zeros = zeros[s + 1];
    bool merge = ns <= o.nrelax[0];
    if (!merge) {
      const std::int64_t new_zeros = static_cast<std::int64_t>(cols[s]) * (height[s + 1] + cols[s] - height[s]);
      total_zeros += new_zeros;
      if (new_zeros == 0) {
        merge = true;
      } else {
        const double x = ns, size = x * (x + 1) / 2 + x * (static_cast<double>(height[s + 1]) - cols[s + 1]);
        const double z = static_cast<double>(total_zeros) / size;
        merge =
            ((ns <= o.nrelax[1] && z < o.zrelax[0]) || (ns <= o.nrelax[2] && z < o.zrelax[1]) || z < o.zrelax[2]) && size < largest_block;
      }
    }
    if (merge) {
      zeros[s] = total_zeros;
      merged_into[s + 1] = s;
      height[s] = cols[s] + height[s + 1];
      cols[s] += cols[s + 1];
    }
  }
  std::vector<int> relaxed;
  int kept = 0;
  for (int s = 0; s < nf; ++s)
    if (merged_into[s] == -1) relaxed.push_back(first[s]), height[kept++] = height[s];
  relaxed.push_back(n);
  height.resize(kept);
  return relaxed;
}

}  // namespace

std::vector<int> amd_ordering(const std::vector<int>& outer, const std::vector<int>& inner, int n) {
  check_pattern(outer, inner, n, "AMD ordering");
  std::vector<int> order(n);
  if (n == 0) return order;
  double control[AMD_CONTROL], info[AMD_INFO];
  amd_defaults(control);
  control[AMD_DENSE] = 10.0;    // CHOLMOD's prune_dense: rows with more than 10 √n entries (and 16) are ordered last
  control[AMD_AGGRESSIVE] = 1;  // CHOLMOD's aggressive absorption
  const UpperOnly A(outer, inner, n);
  const int status = amd_order(n, A.p, A.i, order.data(), control, info);
  if (status != AMD_OK && status != AMD_OK_BUT_JUMBLED) throw Error("AMD could not order the matrix (" + ordering_status(status) + ")");
  return order;
}

std::vector<int> camd_ordering(const std::vector<int>& outer, const std::vector<int>& inner, int n, const std::vector<int>& set) {
  check_pattern(outer, inner, n, "CAMD ordering");
  if (set.size() != static_cast<size_t>(n))
    throw Error("CAMD ordering: " + std::to_string(set.size()) + " constraint sets given for " + std::to_string(n) + " rows");
  for (int i = 0; i < n; ++i)
    if (set[i] < 0 || set[i] >= n)
      throw Error("CAMD ordering: row " + std::to_string(i) + " is in constraint set " + std::to_string(set[i]) + ", outside [0, " +
                  std::to_string(n) + ")");
  std::vector<int> order(n);
  if (n == 0) return order;
  double control[CAMD_CONTROL], info[CAMD_INFO];
  camd_defaults(control);
  control[CAMD_DENSE] = 10.0;    // as cholmod_camd: CHOLMOD's prune_dense
  control[CAMD_AGGRESSIVE] = 1;  // and aggressive absorption
  const UpperOnly A(outer, inner, n);
  const int status = camd_order(n, A.p, A.i, order.data(), control, info, set.data());
  if (status != CAMD_OK && status != CAMD_OK_BUT_JUMBLED) throw Error("CAMD could not order the matrix (" + ordering_status(status) + ")");
  return order;
}

std::vector<int> postorder(const std::vector<int>& parent, const std::vector<int>* weight) {
  const int n = static_cast<int>(parent.size());
  for (int j = 0; j < n; ++j)
    if (parent[j] < -1 || parent[j] >= n || parent[j] == j) throw Error("postorder: node " + std::to_string(j) + " has an invalid parent");
  if (weight && weight->size() != static_cast<size_t>(n)) throw Error("postorder: the weights do not match the tree");
  // The nodes in the order their parents list them: by index, or by clamped weight then index (a counting sort).
  std::vector<int> sorted(n);
  if (!weight) {
    for (int j = 0; j < n; ++j) sorted[j] = j;
  } else {
    std::vector<int> bucket(static_cast<size_t>(n) + 1, 0);
    auto clamped = [&](int j) { return std::min(std::max((*weight)[j], 0), n - 1); };
    for (int j = 0; j < n; ++j) ++bucket[clamped(j) + 1];
    for (int w = 0; w < n; ++w) bucket[w + 1] += bucket[w];
    for (int j = 0; j < n; ++j) sorted[bucket[clamped(j)]++] = j;
  }
  std::vector<int> child_start(static_cast<size_t>(n) + 1, 0), child(n);
  for (int j = 0; j < n; ++j)
    if (parent[j] >= 0) ++child_start[parent[j] + 1];
  for (int j = 0; j < n; ++j) child_start[j + 1] += child_start[j];
  std::vector<int> fill(child_start.begin(), child_start.end() - 1);
  for (int j : sorted)
    if (parent[j] >= 0) child[fill[parent[j]]++] = j;
  // Depth first from each root; next[v]: the next child of v to visit.
  std::vector<int> post, stack, next(child_start.begin(), child_start.end() - 1);
  post.reserve(n);
  for (int root = 0; root < n; ++root) {
    if (parent[root] != -1) continue;
    stack.push_back(root);
    while (!stack.empty()) {
      const int v = stack.back();
      if (next[v] < child_start[v + 1]) {
        stack.push_back(child[next[v]++]);
      } else {
        stack.pop_back();
        post.push_back(v);
      }
    }
  }
  if (static_cast<int>(post.size()) != n) throw Error("postorder: the parent array is not a forest (it has a cycle)");
  return post;
}

SymbolicFactor symbolic_analysis(const std::vector<int>& outer, const std::vector<int>& inner, int n, const std::vector<int>& order,
                                 const SymbolicOptions& options) {
  check_pattern(outer, inner, n, "symbolic analysis");
  if (order.size() != static_cast<size_t>(n))
    throw Error("symbolic analysis: the order has " + std::to_string(order.size()) + " entries for " + std::to_string(n) + " rows");
  std::vector<int> position(n, -1);
  for (int k = 0; k < n; ++k) {
    const int r = order[k];
    if (r < 0 || r >= n || position[r] != -1)
      throw Error("symbolic analysis: the order is not a permutation (entry " + std::to_string(k) + ")");
    position[r] = k;
  }
  SymbolicFactor L;
  L.n = n;
  L.perm = order;
  Columns cols;
  Rows rows;
  permuted_upper(outer, inner, position, cols, &rows);
  L.parent = elimination_tree(cols, n);
  L.column_count = column_counts(rows, L.parent, postorder(L.parent));
  if (options.postorder) {
    // Renumber the columns in the postorder weighted by the column counts (each node's children by
    // increasing count), as CHOLMOD does: a node's last child, the heaviest, then comes right before it
    // and can be merged with it.
    const std::vector<int> post = postorder(L.parent, &L.column_count);
    std::vector<int> renumbered(n);
    for (int k = 0; k < n; ++k) renumbered[post[k]] = k;
    std::vector<int> perm(n), parent(n), count(n);
    for (int k = 0; k < n; ++k) {
      const int old = post[k];
      perm[k] = L.perm[old];
      count[k] = L.column_count[old];
      parent[k] = L.parent[old] == -1 ? -1 : renumbered[L.parent[old]];
    }
    L.perm = std::move(perm), L.parent = std::move(parent), L.column_count = std::move(count);
    for (int k = 0; k < n; ++k) position[L.perm[k]] = k;
    permuted_upper(outer, inner, position, cols, nullptr);
  }
  for (int c : L.column_count) L.nnz += static_cast<size_t>(c), L.flops += static_cast<double>(c) * c;

  std::vector<int> height;
  L.super = amalgamate(fundamental_supernodes(L.parent, L.column_count), L.parent, L.column_count, options, height);
  L.nsuper = static_cast<int>(L.super.size()) - 1;
  const int ns = L.nsuper;
  std::vector<int> owner(n), sparent(ns);
  for (int s = 0; s < ns; ++s) std::fill(owner.begin() + L.super[s], owner.begin() + L.super[s + 1], s);
  for (int s = 0; s < ns; ++s) {
    const int p = L.parent[L.super[s + 1] - 1];
    sparent[s] = p == -1 ? -1 : owner[p];
  }
  L.pi.assign(static_cast<size_t>(ns) + 1, 0);
  L.px.assign(static_cast<size_t>(ns) + 1, 0);
  size_t rows_total = 0, entries = 0;
  for (int s = 0; s < ns; ++s) {
    rows_total += static_cast<size_t>(height[s]);
    entries += static_cast<size_t>(height[s]) * static_cast<size_t>(L.super[s + 1] - L.super[s]);
    if (rows_total > static_cast<size_t>(INT_MAX) || entries > static_cast<size_t>(INT_MAX))
      throw Error("symbolic analysis: the factor of this " + std::to_string(n) + " × " + std::to_string(n) +
                  " matrix would have more entries than an int can address");
    L.pi[s + 1] = static_cast<int>(rows_total), L.px[s + 1] = static_cast<int>(entries);
  }
  L.xsize = entries;

  // The rows of each supernode: row k of L holds the columns of row k's subtree, found by climbing the
  // supernodal tree from each entry (i, k) of A, i before the supernode of k, up to a supernode already
  // marked for k. Going through k in increasing order appends each supernode's rows in increasing order.
  L.s.assign(rows_total, 0);
  std::vector<int> fill(L.pi.begin(), L.pi.end() - 1), mark(ns, -1);
  for (int s = 0; s < ns; ++s) {
    const int k1 = L.super[s], k2 = L.super[s + 1];
    for (int k = k1; k < k2; ++k) L.s[fill[s]++] = k;
    for (int k = k1; k < k2; ++k) {
      mark[s] = k;
      for (int q = cols.start[k]; q < cols.start[k + 1]; ++q) {
        const int i = cols.row[q];
        if (i >= k1) continue;  // within the supernode's own columns
        for (int t = owner[i]; t != -1 && mark[t] != k; t = sparent[t]) {
          if (fill[t] == L.pi[t + 1]) throw Error("internal: a supernode's rows outgrew its column count");
          L.s[fill[t]++] = k;
          mark[t] = k;
        }
      }
    }
  }
  for (int s = 0; s < ns; ++s)
    if (fill[s] != L.pi[s + 1]) throw Error("internal: a supernode's rows fell short of its column count");

  // The largest update (rows of one ancestor's columns × the rows from there down) and the most rows below
  // a supernode's own columns.
  for (int d = 0; d < ns; ++d) {
    const int end = L.pi[d + 1];
    int p = L.pi[d] + (L.super[d + 1] - L.super[d]);
    L.maxesize = std::max(L.maxesize, end - p);
    while (p < end) {
      const int target = owner[L.s[p]];
      int q = p;
      while (q < end && owner[L.s[q]] == target) ++q;
      L.maxcsize = std::max(L.maxcsize, static_cast<size_t>(q - p) * static_cast<size_t>(end - p));
      p = q;
    }
  }
  return L;
}

}  // namespace trivcon::linalg
