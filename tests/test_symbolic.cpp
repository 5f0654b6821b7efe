// SPDX-License-Identifier: MIT
// trivcon's own symbolic analysis (src/linalg/symbolic.h, internal) against a brute-force symbolic Cholesky
// factorization and against CHOLMOD's (cholmod_analyze_p with the same order), its AMD and CAMD orders against
// CHOLMOD's, and the numeric factorization of src/linalg/supernodal.h on its structure. The comparisons with
// CHOLMOD are compiled only in a build with TRIVCON_WITH_SUITESPARSE; the brute force and the solves always.
#ifdef TRIVCON_WITH_SUITESPARSE
#include <cholmod.h>
#endif
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdio>
#include <functional>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#ifdef TRIVCON_WITH_SUITESPARSE
#include "linalg/cholmod.h"
#endif
#include "linalg/ordering.h"
#include "linalg/sparse_cholesky.h"
#include "linalg/substitution.h"
#include "linalg/supernodal.h"
#include "linalg/symbolic.h"
#include "support.h"
#include "trivcon/error.h"
#include "trivcon/generate.h"
#include "trivcon/io.h"
#include "trivcon/topology.h"

using namespace trivcon;
using linalg::SymbolicFactor;
using linalg::SymbolicOptions;

namespace {

// A symmetric positive definite matrix by its upper triangle (compressed columns, rows sorted, diagonal included).
struct Upper {
  int n = 0;
  std::vector<int> outer, inner;
  std::vector<double> values;
};

// From the off-diagonal pairs: −w per pair (w random in [0.1, 2)), the diagonal the sum of its row's weights
// plus `shift` (a shifted weighted graph Laplacian).
Upper from_pairs(int n, const std::vector<std::pair<int, int>>& pairs, double shift, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> weight(0.1, 2.0);
  std::vector<std::map<int, double>> columns(n);
  for (int v = 0; v < n; ++v) columns[v][v] = shift;
  for (auto [p, q] : pairs) {
    const int a = std::min(p, q), b = std::max(p, q);
    if (a == b || columns[b].count(a)) continue;
    const double w = weight(rng);
    columns[b][a] = -w, columns[a][a] += w, columns[b][b] += w;
  }
  Upper M;
  M.n = n;
  M.outer.push_back(0);
  for (int c = 0; c < n; ++c) {
    for (const auto& [r, value] : columns[c]) M.inner.push_back(r), M.values.push_back(value);
    M.outer.push_back(static_cast<int>(M.inner.size()));
  }
  return M;
}

// The vertex Laplacian of a mesh (its edges).
Upper vertex_laplacian(const Mesh& mesh, double shift = 1e-2, unsigned seed = 7) {
  std::vector<std::pair<int, int>> pairs;
  for (int f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) pairs.emplace_back(mesh.F(f, k), mesh.F(f, (k + 1) % 3));
  return from_pairs(static_cast<int>(mesh.V.rows()), pairs, shift, seed);
}

// The face Laplacian of a mesh (its interior edges between faces): the pattern of the smoothest field's matrix.
Upper face_laplacian(const Mesh& mesh, double shift = 1e-2, unsigned seed = 7) {
  const Topology t = build_topology(mesh.F, static_cast<int>(mesh.V.rows()));
  std::vector<std::pair<int, int>> pairs;
  for (int e = 0; e < t.num_edges; ++e)
    if (!t.is_boundary_edge(e)) pairs.emplace_back(t.edge_faces(e, 0), t.edge_faces(e, 1));
  return from_pairs(t.num_faces, pairs, shift, seed);
}

// A random sparse pattern: each row coupled to `per_row` others chosen at random, plus a few dense rows
// (coupled to a fifth of all rows) when `dense` is set.
Upper random_spd(int n, int per_row, unsigned seed, int dense = 0) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> any(0, n - 1);
  std::vector<std::pair<int, int>> pairs;
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < per_row; ++k) pairs.emplace_back(i, any(rng));
  for (int d = 0; d < dense; ++d) {
    const int row = any(rng);
    for (int k = 0; k < n / 5; ++k) pairs.emplace_back(row, any(rng));
  }
  return from_pairs(n, pairs, 1.0, seed + 1);
}

std::vector<int> shuffled(int n, unsigned seed) {
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(seed));
  return order;
}

// The symbolic Cholesky factorization by brute force, in dense booleans: the pattern of L for P A Pᵀ (row
// perm[k] of A eliminated k-th), column j's rows ≥ j.
std::vector<std::vector<char>> brute_force_pattern(const Upper& A, const std::vector<int>& perm) {
  const int n = A.n;
  std::vector<int> position(n);
  for (int k = 0; k < n; ++k) position[perm[k]] = k;
  std::vector<std::vector<char>> L(n, std::vector<char>(n, 0));  // L[j][i]: entry (i, j), i ≥ j
  for (int c = 0; c < n; ++c)
    for (int q = A.outer[c]; q < A.outer[c + 1]; ++q) {
      const int a = position[A.inner[q]], b = position[c];
      L[std::min(a, b)][std::max(a, b)] = 1;
    }
  for (int j = 0; j < n; ++j) {
    L[j][j] = 1;
    for (int i = j + 1; i < n; ++i)
      if (L[j][i])
        for (int k = i; k < n; ++k)
          if (L[j][k]) L[i][k] = 1;  // eliminating j couples every pair of its rows below it
  }
  return L;
}

// The factor's structure against the brute-force pattern: its elimination tree, column counts, nnz, and the rows of
// every supernode (its own columns, then the union of its columns' patterns below them).
void expect_matches_brute_force(const Upper& A, const SymbolicFactor& F, const std::string& what) {
  SCOPED_TRACE(what);
  const int n = A.n;
  const auto L = brute_force_pattern(A, F.perm);
  size_t nnz = 0;
  for (int j = 0; j < n; ++j) {
    int parent = -1, count = 0;
    for (int i = n - 1; i > j; --i)
      if (L[j][i]) parent = i;
    for (int i = j; i < n; ++i) count += L[j][i];
    nnz += count;
    ASSERT_EQ(F.parent[j], parent) << "column " << j;
    ASSERT_EQ(F.column_count[j], count) << "column " << j;
  }
  EXPECT_EQ(F.nnz, nnz);
  ASSERT_EQ(F.super.front(), 0);
  ASSERT_EQ(F.super.back(), n);
  for (int s = 0; s < F.nsuper; ++s) {
    const int first = F.super[s], last = F.super[s + 1];
    std::vector<int> expected;
    for (int k = first; k < last; ++k) expected.push_back(k);
    for (int i = last; i < n; ++i) {
      bool any = false;
      for (int j = first; j < last; ++j) any = any || L[j][i];
      if (any) expected.push_back(i);
    }
    const std::vector<int> rows(F.s.begin() + F.pi[s], F.s.begin() + F.pi[s + 1]);
    ASSERT_EQ(rows, expected) << "supernode " << s;
    EXPECT_EQ(F.px[s + 1] - F.px[s], static_cast<int>(rows.size()) * (last - first)) << "supernode " << s;
  }
}

// The pattern of every test matrix: small ones, for the brute force.
struct Case {
  std::string name;
  Upper A;
};
std::vector<Case> small_cases() {
  return {{"icosphere-1", vertex_laplacian(make_icosphere(1))},
          {"torus 9x7", vertex_laplacian(make_torus(9, 7))},
          {"genus-2 surface", vertex_laplacian(make_genus_surface(2, 1))},
          {"disk 5x6", vertex_laplacian(make_disk(5, 6))},
          {"faces of icosphere-1", face_laplacian(make_icosphere(1))},
          {"random 150 x3", random_spd(150, 3, 11)},
          {"random 200 x1 with dense rows", random_spd(200, 1, 12, 3)},
          {"one row", from_pairs(1, {}, 1.0, 1)}};
}

std::vector<Case> mesh_cases() {
  return {{"icosphere-4", vertex_laplacian(make_icosphere(4))},
          {"torus 80x50", vertex_laplacian(make_torus(80, 50))},
          {"genus-3 surface", vertex_laplacian(make_genus_surface(3, 4))},
          {"disk 40x8", vertex_laplacian(make_disk(40, 8))},
          {"holed grid", vertex_laplacian(make_holed_grid(70, 3))},
          {"faces of a cube sphere", face_laplacian(make_cube_sphere(25, true))},
          {"random 3000 x2", random_spd(3000, 2, 21)},
          {"random 2000 x4 with dense rows", random_spd(2000, 4, 22, 5)}};
}

#ifdef TRIVCON_WITH_SUITESPARSE
// CHOLMOD's supernodal symbolic factor for a given order (cholmod_analyze_p), with CHOLMOD's parameters set
// to `o`'s.
struct CholmodSymbolic {
  linalg::CholmodContext context;
  cholmod_factor* L = nullptr;
  CholmodSymbolic(const Upper& A, std::vector<int> order, const SymbolicOptions& o) {
    cholmod_common& c = *context;
    c.nmethods = 1;
    c.method[0].ordering = CHOLMOD_GIVEN;
    c.postorder = o.postorder;
    c.supernodal = CHOLMOD_SUPERNODAL;
    for (int k = 0; k < 3; ++k) c.nrelax[k] = static_cast<size_t>(o.nrelax[k]), c.zrelax[k] = o.zrelax[k];
    cholmod_sparse view = linalg::upper_pattern_view(A.outer, A.inner, A.n);
    L = cholmod_analyze_p(&view, order.data(), nullptr, 0, &c);
    EXPECT_NE(L, nullptr);
    EXPECT_TRUE(L && L->is_super);
  }
  ~CholmodSymbolic() { cholmod_free_factor(&L, context.get()); }
  const cholmod_common& common() const { return context.common(); }
  std::vector<int> array(void* p, size_t size) const { return std::vector<int>(static_cast<int*>(p), static_cast<int*>(p) + size); }
};

// Ours and CHOLMOD's are the same factor: order, column counts, counts of entries and flops, and every supernodal array.
void expect_same_as_cholmod(const Upper& A, const std::vector<int>& order, const SymbolicOptions& o, const std::string& what) {
  SCOPED_TRACE(what);
  const SymbolicFactor ours = linalg::symbolic_analysis(A.outer, A.inner, A.n, order, o);
  const CholmodSymbolic theirs(A, order, o);
  ASSERT_NE(theirs.L, nullptr);
  const cholmod_factor& L = *theirs.L;
  const size_t ns = L.nsuper;
  EXPECT_EQ(ours.perm, theirs.array(L.Perm, A.n));
  EXPECT_EQ(ours.column_count, theirs.array(L.ColCount, A.n));
  EXPECT_EQ(static_cast<double>(ours.nnz), theirs.common().lnz);
  EXPECT_EQ(ours.flops, theirs.common().fl);
  ASSERT_EQ(static_cast<size_t>(ours.nsuper), ns);
  EXPECT_EQ(ours.super, theirs.array(L.super, ns + 1));
  EXPECT_EQ(ours.pi, theirs.array(L.pi, ns + 1));
  EXPECT_EQ(ours.px, theirs.array(L.px, ns + 1));
  EXPECT_EQ(ours.s, theirs.array(L.s, ours.s.size()));
  EXPECT_EQ(ours.xsize, L.xsize);
  EXPECT_EQ(ours.maxcsize, L.maxcsize);
  EXPECT_EQ(static_cast<size_t>(ours.maxesize), L.maxesize);
}
#endif

// x ← (L Lᴴ)⁻¹ x for a factor of ours (values `x` of the scalar T), b and the result in the matrix's order: the
// supernodal forward and backward substitutions, written out.
template <class T>
std::vector<T> solve_with(const SymbolicFactor& F, const linalg::FactorValues<T>& values, const std::vector<T>& b) {
  using Matrix = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>;
  using Vector = Eigen::Matrix<T, Eigen::Dynamic, 1>;
  Vector y(F.n);
  for (int k = 0; k < F.n; ++k) y(k) = b[F.perm[k]];
  auto block = [&](int s) {
    const int cols = F.super[s + 1] - F.super[s], height = F.pi[s + 1] - F.pi[s];
    return Eigen::Map<const Matrix>(values.data() + F.px[s], height, cols);
  };
  for (int s = 0; s < F.nsuper; ++s) {
    const auto Ls = block(s);
    const int first = F.super[s], cols = static_cast<int>(Ls.cols()), below = static_cast<int>(Ls.rows()) - cols;
    Ls.topRows(cols).template triangularView<Eigen::Lower>().solveInPlace(y.segment(first, cols));
    const Vector update = Ls.bottomRows(below) * y.segment(first, cols);
    for (int i = 0; i < below; ++i) y(F.s[F.pi[s] + cols + i]) -= update(i);
  }
  for (int s = F.nsuper - 1; s >= 0; --s) {
    const auto Ls = block(s);
    const int first = F.super[s], cols = static_cast<int>(Ls.cols()), below = static_cast<int>(Ls.rows()) - cols;
    Vector rows(below);
    for (int i = 0; i < below; ++i) rows(i) = y(F.s[F.pi[s] + cols + i]);
    y.segment(first, cols) -= Ls.bottomRows(below).adjoint() * rows;
    Ls.topRows(cols).template triangularView<Eigen::Lower>().adjoint().solveInPlace(y.segment(first, cols));
  }
  std::vector<T> x(F.n);
  for (int k = 0; k < F.n; ++k) x[F.perm[k]] = y(k);
  return x;
}

double conjugate(double a) { return a; }
std::complex<double> conjugate(std::complex<double> a) { return std::conj(a); }

// ‖b − A x‖ / ‖b‖ for the matrix given by its upper triangle (Hermitian: the lower entries are the conjugates).
template <class T>
double relative_residual(const Upper& A, const std::vector<T>& entries, const std::vector<T>& x, const std::vector<T>& b) {
  std::vector<T> r = b;
  for (int c = 0; c < A.n; ++c)
    for (int q = A.outer[c]; q < A.outer[c + 1]; ++q) {
      const int i = A.inner[q];
      r[i] -= entries[q] * x[c];
      if (i != c) r[c] -= conjugate(entries[q]) * x[i];
    }
  double rr = 0, bb = 0;
  for (int i = 0; i < A.n; ++i) rr += std::norm(r[i]), bb += std::norm(b[i]);
  return std::sqrt(rr / bb);
}

#ifdef TRIVCON_WITH_SUITESPARSE
double seconds_of(const std::function<void()>& f, int repeats = 3) {
  double best = 1e300;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

// Prints the times of ours and of cholmod_analyze_p (best of 3 each) for AMD's order of the matrix, and
// checks that both found the same factor size. Not asserted: the times of a shared machine are no test.
void print_times(const Case& c) {
  const Upper& A = c.A;
  const std::vector<int> order = linalg::amd_ordering(A.outer, A.inner, A.n);
  SymbolicFactor ours;
  const double t_ours = seconds_of([&] { ours = linalg::symbolic_analysis(A.outer, A.inner, A.n, order); });
  size_t their_xsize = 0;
  const double t_theirs = seconds_of([&] {
    linalg::CholmodContext context;
    cholmod_common& cc = *context;
    cc.nmethods = 1, cc.method[0].ordering = CHOLMOD_GIVEN, cc.postorder = 1;
    cholmod_sparse view = linalg::upper_pattern_view(A.outer, A.inner, A.n);
    std::vector<int> p = order;
    cholmod_factor* L = cholmod_analyze_p(&view, p.data(), nullptr, 0, &cc);
    ASSERT_NE(L, nullptr);
    their_xsize = L->xsize;
    cholmod_free_factor(&L, &cc);
  });
  const double t_amd = seconds_of([&] { linalg::amd_ordering(A.outer, A.inner, A.n); }, 1);
  EXPECT_EQ(ours.xsize, their_xsize);
  std::printf("%s: n %d, nnz(L) %zu, %d supernodes; symbolic analysis %.1f ms, cholmod_analyze_p %.1f ms (AMD itself %.1f ms)\n",
              c.name.c_str(), A.n, ours.nnz, ours.nsuper, 1e3 * t_ours, 1e3 * t_theirs, 1e3 * t_amd);
}
#endif

}  // namespace

// The elimination tree and column counts against the brute force, in random orders, AMD's order and the natural one,
// with and without the postorder; and the rows of every supernode, fundamental and relaxed.
TEST(Symbolic, MatchesABruteForceSymbolicFactorization) {
  for (const Case& c : small_cases()) {
    std::vector<int> natural(c.A.n);
    std::iota(natural.begin(), natural.end(), 0);
    const std::vector<std::pair<std::string, std::vector<int>>> orders = {
        {"random", shuffled(c.A.n, 3)}, {"AMD", linalg::amd_ordering(c.A.outer, c.A.inner, c.A.n)}, {"natural", natural}};
    for (const auto& [order_name, order] : orders)
      for (bool postorder : {false, true})
        for (bool amalgamate : {false, true}) {
          SymbolicOptions o;
          o.postorder = postorder, o.amalgamate = amalgamate;
          const SymbolicFactor F = linalg::symbolic_analysis(c.A.outer, c.A.inner, c.A.n, order, o);
          if (!postorder) {
            EXPECT_EQ(F.perm, order);
          }
          expect_matches_brute_force(
              c.A, F, c.name + ", " + order_name + (postorder ? ", postordered" : "") + (amalgamate ? ", relaxed" : ", fundamental"));
        }
  }
}

// Postordered, every subtree of the elimination tree is a contiguous range ending at its root; and the fundamental
// supernodes are the maximal chains j − 1 → j where j has one child and L's column j − 1 is column j's plus row j.
TEST(Symbolic, PostorderAndFundamentalSupernodes) {
  for (const Case& c : mesh_cases()) {
    SCOPED_TRACE(c.name);
    SymbolicOptions o;
    o.amalgamate = false;
    const SymbolicFactor F = linalg::symbolic_analysis(c.A.outer, c.A.inner, c.A.n, linalg::amd_ordering(c.A.outer, c.A.inner, c.A.n), o);
    const int n = c.A.n;
    std::vector<int> size(n, 1), children(n, 0);
    for (int j = 0; j < n; ++j) {
      ASSERT_TRUE(F.parent[j] == -1 || F.parent[j] > j);
      if (F.parent[j] != -1) size[F.parent[j]] += size[j], ++children[F.parent[j]];
    }
    for (int j = 0; j < n; ++j) {
      if (F.parent[j] != -1) {
        ASSERT_GE(j, F.parent[j] - size[F.parent[j]] + 1) << "column " << j << " lies outside its parent's range";
      }
    }
    std::set<int> starts(F.super.begin(), F.super.end());
    for (int j = 1; j < n; ++j) {
      const bool continues = F.parent[j - 1] == j && children[j] == 1 && F.column_count[j - 1] == F.column_count[j] + 1;
      EXPECT_EQ(starts.count(j) == 0, continues) << "column " << j;
    }
    // No explicit zeros but the upper triangles of the diagonal blocks.
    size_t triangles = 0;
    for (int s = 0; s < F.nsuper; ++s) {
      const size_t cols = F.super[s + 1] - F.super[s];
      triangles += cols * (cols - 1) / 2;
    }
    EXPECT_EQ(F.xsize, F.nnz + triangles);
  }
}

#ifdef TRIVCON_WITH_SUITESPARSE
// The same factor as cholmod_analyze_p given the same order, array for array: postordered or not, with CHOLMOD's
// default amalgamation, with the smoothest field's (trivcon/auto.h), and with none (nrelax and zrelax 0, where
// CHOLMOD still merges a child into its parent when that adds no zeros). The rule and the order in which pairs are
// considered are CHOLMOD's (docs/solver.md), zeros counted as CHOLMOD counts them, so the relaxed partitions are
// the same too, not only similar.
TEST(Symbolic, SameFactorAsCholmodAnalyzeP) {
  SymbolicOptions defaults, smoothest, none, not_postordered;
  smoothest.zrelax = {0.4, 0.05, 0.02};
  none.nrelax = {0, 0, 0}, none.zrelax = {0, 0, 0};
  not_postordered.postorder = false;
  {
    linalg::CholmodContext context;  // the defaults are CHOLMOD's
    for (int k = 0; k < 3; ++k) EXPECT_EQ(context.common().nrelax[k], static_cast<size_t>(defaults.nrelax[k]));
    for (int k = 0; k < 3; ++k) EXPECT_EQ(context.common().zrelax[k], defaults.zrelax[k]);
  }
  std::vector<Case> cases = mesh_cases();
  for (Case& c : small_cases()) cases.push_back(std::move(c));
  for (const Case& c : cases) {
    const std::vector<int> amd = linalg::amd_ordering(c.A.outer, c.A.inner, c.A.n);
    for (const auto& [name, o] : std::vector<std::pair<std::string, SymbolicOptions>>{
             {"default", defaults}, {"smoothest field's", smoothest}, {"no relaxation", none}, {"not postordered", not_postordered}})
      expect_same_as_cholmod(c.A, amd, o, c.name + ", AMD, " + name);
    expect_same_as_cholmod(c.A, shuffled(c.A.n, 5), defaults, c.name + ", random order");
  }
}

// Without amalgamation the supernodes are fundamental: each of CHOLMOD's with no relaxation is a run of ours
// (CHOLMOD merges a child into its parent also when that adds no zero), with the same entries.
TEST(Symbolic, FundamentalSupernodesRefineCholmods) {
  for (const Case& c : mesh_cases()) {
    SCOPED_TRACE(c.name);
    const std::vector<int> amd = linalg::amd_ordering(c.A.outer, c.A.inner, c.A.n);
    SymbolicOptions fundamental, none;
    fundamental.amalgamate = false;
    none.nrelax = {0, 0, 0}, none.zrelax = {0, 0, 0};
    const SymbolicFactor ours = linalg::symbolic_analysis(c.A.outer, c.A.inner, c.A.n, amd, fundamental);
    const CholmodSymbolic theirs(c.A, amd, none);
    const std::vector<int> their_super = theirs.array(theirs.L->super, theirs.L->nsuper + 1);
    EXPECT_TRUE(std::includes(ours.super.begin(), ours.super.end(), their_super.begin(), their_super.end()));
    EXPECT_LE(their_super.size(), ours.super.size());
    EXPECT_EQ(static_cast<double>(ours.nnz), theirs.common().lnz);
  }
}

// amd_ordering and camd_ordering call libamd and libcamd with CHOLMOD's options: the same orders as cholmod_amd
// and cholmod_camd (the connection's vertex order with its cycle rows constrained last).
TEST(Symbolic, SameOrdersAsCholmod) {
  for (const Case& c : mesh_cases()) {
    SCOPED_TRACE(c.name);
    linalg::CholmodContext context;
    cholmod_sparse view = linalg::upper_pattern_view(c.A.outer, c.A.inner, c.A.n);
    std::vector<int> theirs(c.A.n);
    ASSERT_TRUE(cholmod_amd(&view, nullptr, 0, theirs.data(), context.get()));
    EXPECT_EQ(linalg::amd_ordering(c.A.outer, c.A.inner, c.A.n), theirs);
    // The last 20 rows (or a tenth) constrained last, as the connection's cycle rows.
    const int last = std::min(20, c.A.n / 10);
    std::vector<int> set(c.A.n, 0);
    std::fill(set.end() - last, set.end(), 1);
    ASSERT_TRUE(cholmod_camd(&view, nullptr, 0, set.data(), theirs.data(), context.get()));
    const std::vector<int> ours = linalg::camd_ordering(c.A.outer, c.A.inner, c.A.n, set);
    EXPECT_EQ(ours, theirs);
    for (int k = 0; k < c.A.n; ++k) ASSERT_EQ(set[ours[k]], k >= c.A.n - last ? 1 : 0) << "position " << k;
  }
}

// The connection's pipeline (src/connection/cholesky_engine.cpp) without CHOLMOD gives CHOLMOD's factor: the vertex
// rows by CAMD with the cycle rows constrained last, postordered by the vertex block's elimination tree, then the
// whole system analysed in that order with the cycle rows last and no postorder of its own.
TEST(Symbolic, TheConnectionsPipelineGivesCholmodsFactor) {
  for (const auto& [name, mesh, cycles] :
       std::vector<std::tuple<std::string, Mesh, int>>{{"genus-3 surface, 6 generators", make_genus_surface(3, 3), 6},
                                                       {"torus, 2 generators", make_torus(60, 40), 2},
                                                       {"icosphere-4, none", make_icosphere(4), 0}}) {
    SCOPED_TRACE(name);
    // The vertex Laplacian, then `cycles` rows, each coupled to the vertices of a band around the mesh and to
    // the cycle rows before it (as generators couple the vertices along them).
    const Upper L = vertex_laplacian(mesh);
    const int nD = L.n, n = nD + cycles;
    std::vector<std::pair<int, int>> pairs;
    for (int c = 0; c < nD; ++c)
      for (int q = L.outer[c]; q < L.outer[c + 1]; ++q) pairs.emplace_back(L.inner[q], c);
    for (int g = 0; g < cycles; ++g) {
      for (int v = g * 7; v < nD; v += 97) pairs.emplace_back(v, nD + g);
      for (int h = 0; h < g; ++h) pairs.emplace_back(nD + h, nD + g);
    }
    const Upper M = from_pairs(n, pairs, 1.0, 3);

    // CHOLMOD's way, as cholesky_engine.cpp does it today.
    linalg::CholmodContext context;
    cholmod_common& cc = *context;
    cholmod_sparse view = linalg::upper_pattern_view(M.outer, M.inner, n);
    std::vector<int> full(n), order(nD);
    if (cycles > 0) {
      std::vector<int> last(n, 0);
      std::fill(last.begin() + nD, last.end(), 1);
      ASSERT_TRUE(cholmod_camd(&view, nullptr, 0, last.data(), full.data(), &cc));
      std::copy(full.begin(), full.begin() + nD, order.begin());
    } else {
      cholmod_sparse block = linalg::upper_pattern_view(M.outer, M.inner, nD);
      ASSERT_TRUE(cholmod_amd(&block, nullptr, 0, order.data(), &cc));
    }
    std::vector<int> parent = linalg::elimination_tree(linalg::leading_block_pattern(M.outer, M.inner, nD), order), post(nD);
    ASSERT_EQ(cholmod_postorder(parent.data(), nD, nullptr, post.data(), &cc), nD);
    std::vector<int> given(n);
    for (int k = 0; k < nD; ++k) given[k] = order[post[k]];
    std::iota(given.begin() + nD, given.end(), nD);

    // Ours: libcamd / libamd and linalg::postorder give the same order.
    std::vector<int> ours_order;
    if (cycles > 0) {
      std::vector<int> set(n, 0);
      std::fill(set.begin() + nD, set.end(), 1);
      ours_order = linalg::camd_ordering(M.outer, M.inner, n, set);
      ours_order.resize(nD);
    } else {
      ours_order = linalg::amd_ordering(M.outer, M.inner, nD);
    }
    const std::vector<int> ours_post =
        linalg::postorder(linalg::elimination_tree(linalg::leading_block_pattern(M.outer, M.inner, nD), ours_order));
    std::vector<int> ours_given(n);
    for (int k = 0; k < nD; ++k) ours_given[k] = ours_order[ours_post[k]];
    std::iota(ours_given.begin() + nD, ours_given.end(), nD);
    EXPECT_EQ(ours_given, given);

    SymbolicOptions o;
    o.postorder = false;  // keeps the cycle rows last
    expect_same_as_cholmod(M, ours_given, o, "the whole system");
    const SymbolicFactor F = linalg::symbolic_analysis(M.outer, M.inner, n, ours_given, o);
    for (int k = nD; k < n; ++k) EXPECT_EQ(F.perm[k], k);
  }
}

// The smoothest field's (src/field/smoothest_field.cpp) and SparseCholesky's (src/linalg/sparse_cholesky.cpp)
// analyses without CHOLMOD give CHOLMOD's factor: cholmod_analyze with AMD and postorder = 1 is amd_ordering then
// symbolic_analysis, with the smoothest field's zrelax and with the defaults.
TEST(Symbolic, CholmodAnalyzeWithAmdIsAmdOrderingThenSymbolicAnalysis) {
  for (const Case& c : mesh_cases()) {
    SCOPED_TRACE(c.name);
    for (const std::array<double, 3>& zrelax : {std::array<double, 3>{0.8, 0.1, 0.05}, std::array<double, 3>{0.4, 0.05, 0.02}}) {
      linalg::CholmodContext context;
      cholmod_common& cc = *context;
      cc.nmethods = 1, cc.method[0].ordering = CHOLMOD_AMD, cc.postorder = 1;
      for (int k = 0; k < 3; ++k) cc.zrelax[k] = zrelax[k];
      cholmod_sparse view = linalg::upper_pattern_view(c.A.outer, c.A.inner, c.A.n);
      cholmod_factor* L = cholmod_analyze(&view, &cc);
      ASSERT_NE(L, nullptr);
      SymbolicOptions o;
      o.zrelax = zrelax;
      const SymbolicFactor F = linalg::symbolic_analysis(c.A.outer, c.A.inner, c.A.n, linalg::amd_ordering(c.A.outer, c.A.inner, c.A.n), o);
      EXPECT_EQ(F.perm, std::vector<int>(static_cast<int*>(L->Perm), static_cast<int*>(L->Perm) + c.A.n));
      EXPECT_EQ(F.super, std::vector<int>(static_cast<int*>(L->super), static_cast<int*>(L->super) + L->nsuper + 1));
      EXPECT_EQ(F.s, std::vector<int>(static_cast<int*>(L->s), static_cast<int*>(L->s) + F.s.size()));
      EXPECT_EQ(F.flops, cc.fl);
      cholmod_free_factor(&L, &cc);
    }
  }
}

// Scanned meshes of the shared folder (genus 0, 133 handles, a boundary): the same orders and factor as CHOLMOD's.
TEST(Symbolic, SameAsCholmodOnRealMeshes) {
  TRIVCON_REQUIRE_SHARED();
  for (const std::string name : {"armadillo.obj", "cheese.off", "Input_wheel.off", "camelhead.off"}) {
    const MeshData mesh = read_mesh(test::shared_mesh(name));
    for (const Case& c : {Case{name + ", vertices", vertex_laplacian(mesh)}, Case{name + ", faces", face_laplacian(mesh)}}) {
      SCOPED_TRACE(c.name);
      linalg::CholmodContext context;
      cholmod_sparse view = linalg::upper_pattern_view(c.A.outer, c.A.inner, c.A.n);
      std::vector<int> theirs(c.A.n);
      ASSERT_TRUE(cholmod_amd(&view, nullptr, 0, theirs.data(), context.get()));
      const std::vector<int> amd = linalg::amd_ordering(c.A.outer, c.A.inner, c.A.n);
      EXPECT_EQ(amd, theirs);
      expect_same_as_cholmod(c.A, amd, SymbolicOptions{}, "AMD");
    }
  }
}

// The leading block of a larger pattern: only its columns are read, as CHOLMOD's view of the block
// (the connection orders its vertex rows alone this way).
TEST(Symbolic, OrdersAndAnalysesALeadingBlock) {
  const Upper A = vertex_laplacian(make_torus(30, 20));
  const int n = A.n - 50;
  linalg::CholmodContext context;
  cholmod_sparse view = linalg::upper_pattern_view(A.outer, A.inner, n);
  std::vector<int> theirs(n);
  ASSERT_TRUE(cholmod_amd(&view, nullptr, 0, theirs.data(), context.get()));
  const std::vector<int> order = linalg::amd_ordering(A.outer, A.inner, n);
  EXPECT_EQ(order, theirs);
  Upper block = A;
  block.n = n, block.outer.resize(n + 1), block.inner.resize(block.outer[n]), block.values.resize(block.outer[n]);
  const SymbolicFactor F = linalg::symbolic_analysis(A.outer, A.inner, n, order);
  const SymbolicFactor G = linalg::symbolic_analysis(block.outer, block.inner, n, order);
  EXPECT_EQ(F.super, G.super);
  EXPECT_EQ(F.s, G.s);
  expect_same_as_cholmod(block, order, SymbolicOptions{}, "leading block");
}

#endif

// A numeric factorization by src/linalg/supernodal.cpp's code on our structure solves A x = b, real (L Lᵀ) and
// complex Hermitian (L Lᴴ, a connection Laplacian as the smoothest field's), and its values are CHOLMOD's symbolic
// factor's filled by the same code.
TEST(Symbolic, NumericFactorizationOnItSolves) {
  for (const Case& c : mesh_cases()) {
    SCOPED_TRACE(c.name);
    const Upper& A = c.A;
    const SymbolicFactor F = linalg::symbolic_analysis(A.outer, A.inner, A.n, linalg::amd_ordering(A.outer, A.inner, A.n));
    linalg::FactorValues<double> x;
    ASSERT_EQ(linalg::factorize(F, x, A.outer, A.inner, A.values), A.n);
    ASSERT_EQ(x.size(), F.xsize);
    std::vector<double> b(A.n);
    for (int i = 0; i < A.n; ++i) b[i] = std::sin(0.37 * i + 1);
    EXPECT_LT(relative_residual(A, A.values, solve_with(F, x, b), b), 1e-10);

#ifdef TRIVCON_WITH_SUITESPARSE
    // The same values as the factor CHOLMOD's analysis gives the same code (the structures are the same).
    CholmodSymbolic theirs(A, linalg::amd_ordering(A.outer, A.inner, A.n), SymbolicOptions{});
    ASSERT_EQ(linalg::factorize(*theirs.L, A.outer, A.inner, A.values, *theirs.context), A.n);
    ASSERT_EQ(theirs.L->xsize, x.size());
    const double* y = static_cast<const double*>(theirs.L->x);
    double largest = 0, difference = 0;
    for (size_t k = 0; k < x.size(); ++k)
      largest = std::max(largest, std::abs(y[k])), difference = std::max(difference, std::abs(x[k] - y[k]));
    EXPECT_LE(difference, 1e-14 * largest);
#endif

    // Hermitian: each off-diagonal entry turned by a random phase.
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> angle(-3.14159, 3.14159);
    std::vector<std::complex<double>> entries(A.inner.size());
    std::vector<double> interleaved;
    for (int col = 0; col < A.n; ++col)
      for (int q = A.outer[col]; q < A.outer[col + 1]; ++q) {
        entries[q] = A.inner[q] == col ? A.values[q] : std::polar(A.values[q], angle(rng));
        interleaved.push_back(entries[q].real()), interleaved.push_back(entries[q].imag());
      }
    linalg::FactorValues<std::complex<double>> z;
    std::vector<std::complex<double>> bz(A.n);
    ASSERT_EQ(linalg::factorize_complex(F, z, A.outer, A.inner, interleaved), A.n);
    for (int i = 0; i < A.n; ++i) bz[i] = {std::sin(0.37 * i + 1), std::cos(0.11 * i)};
    EXPECT_LT(relative_residual(A, entries, solve_with(F, z, bz), bz), 1e-10);
  }
}

// The whole symmetric matrix of an upper triangle.
Eigen::SparseMatrix<double> full_matrix(const Upper& A) {
  std::vector<Eigen::Triplet<double>> t;
  for (int col = 0; col < A.n; ++col)
    for (int q = A.outer[col]; q < A.outer[col + 1]; ++q) {
      t.emplace_back(A.inner[q], col, A.values[q]);
      if (A.inner[q] != col) t.emplace_back(col, A.inner[q], A.values[q]);
    }
  Eigen::SparseMatrix<double> M(A.n, A.n);
  M.setFromTriplets(t.begin(), t.end());
  return M;
}

// A right-hand side with few nonzeros (the map's responses to one fixed integer, the connection's changed rows):
// the forward half visits only the supernodes on their paths to the root (Substitution::forward_update), and
// gives the dense solve's answer, real through SparseCholesky::solve_sparse and complex through the
// substitution itself, with repeated rows adding up.
TEST(Symbolic, SparseRightHandSidesGiveTheDenseSolvesAnswer) {
  for (const Case& c : mesh_cases()) {
    SCOPED_TRACE(c.name);
    const Upper& A = c.A;
    const Eigen::SparseMatrix<double> M = full_matrix(A);
    linalg::SparseCholesky solver(M, "test");
    EXPECT_THROW(solver.solve_sparse({{0, 1.0}}), Error);  // before a factorization
    ASSERT_EQ(solver.factorize(M), -1);
    const std::vector<std::vector<std::pair<int, double>>> sets{
        {{0, 1.0}}, {{A.n - 1, -2.5}}, {{A.n / 2, 1.0}, {A.n / 3, -0.5}, {A.n / 2, 0.25}, {7, 3.0}}};
    for (const auto& entries : sets) {
      Eigen::VectorXd b = Eigen::VectorXd::Zero(A.n);
      for (const auto& [row, value] : entries) b[row] += value;
      const Eigen::VectorXd dense = solver.solve(b), sparse = solver.solve_sparse(entries);
      EXPECT_LE((sparse - dense).lpNorm<Eigen::Infinity>(), 1e-12 * dense.lpNorm<Eigen::Infinity>());
      EXPECT_LE((M * sparse - b).lpNorm<Eigen::Infinity>(), 1e-10 * b.lpNorm<Eigen::Infinity>());
    }
    EXPECT_THROW(solver.solve_sparse({{A.n, 1.0}}), Error);

    // Complex: z += L⁻¹ d against the full forward pass, in the factor's order, twice on one object (its work
    // vector is left zero between calls).
    const SymbolicFactor F = linalg::symbolic_analysis(A.outer, A.inner, A.n, linalg::amd_ordering(A.outer, A.inner, A.n));
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> angle(-3.14159, 3.14159);
    std::vector<double> interleaved;  // Hermitian: each off-diagonal entry turned by a random phase
    for (int col = 0; col < A.n; ++col)
      for (int q = A.outer[col]; q < A.outer[col + 1]; ++q) {
        const std::complex<double> entry = A.inner[q] == col ? A.values[q] : std::polar(A.values[q], angle(rng));
        interleaved.push_back(entry.real()), interleaved.push_back(entry.imag());
      }
    linalg::FactorValues<std::complex<double>> z;
    ASSERT_EQ(linalg::factorize_complex(F, z, A.outer, A.inner, interleaved), A.n);
    const linalg::Substitution<std::complex<double>> substitution(F, z);
    for (int run = 0; run < 2; ++run) {
      const std::vector<std::pair<int, std::complex<double>>> entries{{A.n / 4, {1.0, -0.5}}, {A.n - 1 - run, {0.0, 2.0}}};
      std::vector<std::complex<double>> full(A.n), updated(A.n, {1.0, 1.0});
      for (const auto& [k, value] : entries) full[k] += value;
      substitution.forward_in_factor_order(full.data());
      substitution.forward_update(entries, updated.data());
      double largest = 0, difference = 0;
      for (int k = 0; k < A.n; ++k)
        largest = std::max(largest, std::abs(full[k])), difference = std::max(difference, std::abs(updated[k] - std::complex<double>(1.0, 1.0) - full[k]));
      EXPECT_LE(difference, 1e-12 * largest);
    }
  }
}

// Rows ordered last: the factor's block of them is the Cholesky factor of their Schur complement, against
// S = A_ll − A_lr A_rr⁻¹ A_rl computed with Eigen's own sparse factorization of A_rr.
TEST(Symbolic, RowsOrderedLastGiveTheirSchurComplement) {
  for (const Case& c : mesh_cases()) {
    SCOPED_TRACE(c.name);
    const Upper& A = c.A;
    const Eigen::SparseMatrix<double> M = full_matrix(A);
    std::vector<int> last{A.n - 1, 0};  // scattered, not sorted
    for (int row = 97; row < A.n - 1; row += 97) last.push_back(row);
    const int m = static_cast<int>(last.size());
    linalg::SparseCholesky solver(M, "test", last);
    EXPECT_THROW(solver.schur_complement(), Error);  // before a factorization
    ASSERT_EQ(solver.factorize(M), -1);
    const Eigen::MatrixXd S = solver.schur_complement();
    ASSERT_EQ(S.rows(), m);

    std::vector<int> place(A.n, -1), rest;
    for (int a = 0; a < m; ++a) place[last[a]] = a;
    for (int row = 0; row < A.n; ++row)
      if (place[row] < 0) place[row] = static_cast<int>(rest.size()), rest.push_back(row);
    std::vector<Eigen::Triplet<double>> rr;
    Eigen::MatrixXd rl = Eigen::MatrixXd::Zero(static_cast<int>(rest.size()), m), ll = Eigen::MatrixXd::Zero(m, m);
    std::vector<char> is_last(A.n, 0);
    for (int row : last) is_last[row] = 1;
    for (int col = 0; col < A.n; ++col)
      for (Eigen::SparseMatrix<double>::InnerIterator it(M, col); it; ++it) {
        const int row = static_cast<int>(it.row());
        if (!is_last[row] && !is_last[col]) rr.emplace_back(place[row], place[col], it.value());
        else if (!is_last[row]) rl(place[row], place[col]) = it.value();
        else if (is_last[col]) ll(place[row], place[col]) = it.value();
      }
    Eigen::SparseMatrix<double> Arr(static_cast<int>(rest.size()), static_cast<int>(rest.size()));
    Arr.setFromTriplets(rr.begin(), rr.end());
    const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(Arr);
    ASSERT_EQ(ldlt.info(), Eigen::Success);
    const Eigen::MatrixXd expected = ll - rl.transpose() * ldlt.solve(rl);
    EXPECT_LE((S - expected).lpNorm<Eigen::Infinity>(), 1e-10 * expected.lpNorm<Eigen::Infinity>());
    EXPECT_LE((S - S.transpose()).lpNorm<Eigen::Infinity>(), 0.0);
    // The other rows' system alone, A_rr x_r = b_r (b's rows of `last` ignored, x's 0), dense and sparse.
    Eigen::VectorXd b(A.n), b_rest(static_cast<int>(rest.size()));
    for (int row = 0; row < A.n; ++row) b[row] = std::sin(0.37 * row) + (is_last[row] ? 5.0 : 0.0);
    for (size_t k = 0; k < rest.size(); ++k) b_rest[static_cast<int>(k)] = b[rest[k]];
    const Eigen::VectorXd x_rest = ldlt.solve(b_rest), x = solver.solve_rest(b);
    std::vector<std::pair<int, double>> entries{{rest[3], 1.0}, {last[1], 7.0}, {rest[rest.size() / 2], -2.0}};
    Eigen::VectorXd unit = Eigen::VectorXd::Zero(static_cast<int>(rest.size()));
    unit[3] += 1.0, unit[static_cast<int>(rest.size() / 2)] -= 2.0;
    const Eigen::VectorXd x_unit = ldlt.solve(unit), x_sparse = solver.solve_rest_sparse(entries);
    for (int row = 0; row < A.n; ++row) {
      EXPECT_NEAR(x[row], is_last[row] ? 0.0 : x_rest[place[row]], 1e-10 * x_rest.lpNorm<Eigen::Infinity>());
      EXPECT_NEAR(x_sparse[row], is_last[row] ? 0.0 : x_unit[place[row]], 1e-10 * x_unit.lpNorm<Eigen::Infinity>());
    }
  }
  const Upper A = vertex_laplacian(make_icosphere(2));
  const Eigen::SparseMatrix<double> M = full_matrix(A);
  EXPECT_THROW(linalg::SparseCholesky(M, "test", {3, 5, 3}), Error);  // a row twice
  EXPECT_THROW(linalg::SparseCholesky(M, "test", {A.n}), Error);     // outside the matrix
}

// An indefinite matrix: the first column found not positive definite, as with CHOLMOD's factor.
TEST(Symbolic, NumericFactorizationReportsTheColumnNotPositiveDefinite) {
  Upper A = vertex_laplacian(make_icosphere(3));
  A.values[A.outer[100 + 1] - 1] = -1.0;  // the diagonal of row 100
  const std::vector<int> order = linalg::amd_ordering(A.outer, A.inner, A.n);
  const SymbolicFactor F = linalg::symbolic_analysis(A.outer, A.inner, A.n, order);
  linalg::FactorValues<double> x;
  const int minor = linalg::factorize(F, x, A.outer, A.inner, A.values);
#ifdef TRIVCON_WITH_SUITESPARSE
  CholmodSymbolic theirs(A, order, SymbolicOptions{});
  EXPECT_EQ(minor, linalg::factorize(*theirs.L, A.outer, A.inner, A.values, *theirs.context));
#endif
  EXPECT_LT(minor, A.n);
}

TEST(Symbolic, EmptyAndOneByOne) {
  const Upper empty{0, {0}, {}, {}};
  const SymbolicFactor F = linalg::symbolic_analysis(empty.outer, empty.inner, 0, {});
  EXPECT_EQ(F.nsuper, 0);
  EXPECT_EQ(F.super, std::vector<int>{0});
  EXPECT_EQ(F.xsize, 0u);
  EXPECT_TRUE(linalg::amd_ordering(empty.outer, empty.inner, 0).empty());
  EXPECT_TRUE(linalg::camd_ordering(empty.outer, empty.inner, 0, {}).empty());
  const Upper one = from_pairs(1, {}, 4.0, 1);
  const SymbolicFactor G = linalg::symbolic_analysis(one.outer, one.inner, 1, {0});
  EXPECT_EQ(G.super, (std::vector<int>{0, 1}));
  EXPECT_EQ(G.s, std::vector<int>{0});
  linalg::FactorValues<double> x;
  ASSERT_EQ(linalg::factorize(G, x, one.outer, one.inner, one.values), 1);
  EXPECT_DOUBLE_EQ(x[0], 2.0);
}

#ifdef TRIVCON_WITH_SUITESPARSE
// cholmod_postorder's order, weighted and not, on a forest.
TEST(Symbolic, PostorderAsCholmods) {
  std::mt19937 rng(4);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 1 + trial * 37;
    std::vector<int> parent(n), weight(n);
    for (int j = 0; j < n; ++j) {
      parent[j] = j + 1 < n && rng() % 7 != 0 ? j + 1 + static_cast<int>(rng() % std::min(5, n - j - 1)) : -1;
      weight[j] = static_cast<int>(rng() % (n + 3)) - 1;  // some out of [0, n − 1]: clamped
    }
    linalg::CholmodContext context;
    for (const std::vector<int>* w : std::vector<const std::vector<int>*>{nullptr, &weight}) {
      std::vector<int> theirs(n);
      ASSERT_EQ(cholmod_postorder(parent.data(), n, w ? const_cast<int*>(w->data()) : nullptr, theirs.data(), context.get()), n);
      EXPECT_EQ(linalg::postorder(parent, w), theirs) << "n " << n << (w ? ", weighted" : "");
    }
  }
}

#endif

TEST(Symbolic, RejectsBadInputWithSpecificMessages) {
  const Upper A = vertex_laplacian(make_icosphere(1));
  auto message = [](const std::function<void()>& f) {
    try {
      f();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  std::vector<int> order(A.n);
  std::iota(order.begin(), order.end(), 0);
  std::vector<int> repeated = order;
  repeated[3] = repeated[4];
  EXPECT_NE(message([&] { linalg::symbolic_analysis(A.outer, A.inner, A.n, repeated); }).find("not a permutation"), std::string::npos);
  EXPECT_NE(message([&] { linalg::symbolic_analysis(A.outer, A.inner, A.n, std::vector<int>(3)); }).find("the order has 3 entries"),
            std::string::npos);
  std::vector<int> bad_inner = A.inner;
  bad_inner[5] = -2;
  EXPECT_NE(message([&] { linalg::amd_ordering(A.outer, bad_inner, A.n); }).find("negative row index"), std::string::npos);
  std::vector<int> bad_outer = A.outer;
  std::swap(bad_outer[4], bad_outer[5]);
  EXPECT_NE(message([&] { linalg::symbolic_analysis(bad_outer, A.inner, A.n, order); }).find("column offsets decrease"), std::string::npos);
  EXPECT_NE(message([&] { linalg::amd_ordering(A.outer, A.inner, A.n + 5); }).find("fewer than n + 1"), std::string::npos);
  std::vector<int> set(A.n, 0);
  set[7] = A.n;
  EXPECT_NE(message([&] { linalg::camd_ordering(A.outer, A.inner, A.n, set); }).find("row 7 is in constraint set"), std::string::npos);
  EXPECT_NE(message([&] { linalg::camd_ordering(A.outer, A.inner, A.n, std::vector<int>(2)); }).find("2 constraint sets"),
            std::string::npos);
  EXPECT_NE(message([&] { linalg::postorder({1, 0}); }).find("has a cycle"), std::string::npos);
  EXPECT_NE(message([&] { linalg::postorder({5, -1}); }).find("node 0 has an invalid parent"), std::string::npos);
}

#ifdef TRIVCON_WITH_SUITESPARSE
// Ours against cholmod_analyze_p on meshes of 330k to 400k faces (vertex and face Laplacians), printed.
TEST(Symbolic, TimeAgainstCholmod) {
  for (const Case& c : {Case{"vertex Laplacian, torus 500x400 (400k faces)", vertex_laplacian(make_torus(500, 400))},
                        Case{"face Laplacian, torus 500x400 (400k faces)", face_laplacian(make_torus(500, 400))},
                        Case{"vertex Laplacian, icosphere-7 (328k faces)", vertex_laplacian(make_icosphere(7))}})
    print_times(c);
}

// The same on a scanned mesh of 871k faces, when the shared folder is there.
TEST(Symbolic, TimeAgainstCholmodOnAScan) {
  TRIVCON_REQUIRE_SHARED();
  const MeshData dragon = read_mesh(test::shared_mesh("dragon_vrip.ply"));
  print_times({"vertex Laplacian, dragon_vrip (871k faces)", vertex_laplacian(dragon)});
  print_times({"face Laplacian, dragon_vrip (871k faces)", face_laplacian(dragon)});
}
#endif

// The cycle block's inverse (src/connection/cholesky_engine.cpp): R⁻¹ R = I for a lower triangular R of a
// size where dtrtri blocks, its strict upper triangle untouched; a zero on the diagonal is reported.
TEST(Symbolic, LowerTriangularInverse) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> entry(-1.0, 1.0);
  const int n = 300;
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(n, n);
  for (int j = 0; j < n; ++j) {
    R(j, j) = 2.0 + entry(rng);
    for (int i = j + 1; i < n; ++i) R(i, j) = entry(rng) / n;
  }
  Eigen::MatrixXd inverse = R;
  ASSERT_TRUE(linalg::invert_lower_triangular(inverse));
  EXPECT_LT((inverse * R - Eigen::MatrixXd::Identity(n, n)).lpNorm<Eigen::Infinity>(), 1e-12);
  for (int j = 1; j < n; ++j)
    for (int i = 0; i < j; ++i) ASSERT_EQ(inverse(i, j), 0.0);
  Eigen::MatrixXd singular = R;
  singular(n / 2, n / 2) = 0;
  EXPECT_FALSE(linalg::invert_lower_triangular(singular));
}
