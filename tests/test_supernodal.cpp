// SPDX-License-Identifier: MIT
// The numeric supernodal factorization (src/linalg/supernodal.h, internal) against CHOLMOD's own, on the same
// symbolic factorization; the split of the elimination tree it and the backward substitution use; and the
// parallel substitution (src/linalg/substitution.h) against CHOLMOD's solve.
#include <cholmod.h>
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <map>
#include <random>
#include <set>
#include <type_traits>

#include "linalg/cholmod.h"
#include "linalg/substitution.h"
#include "linalg/supernodal.h"
#include "trivcon/error.h"
#include "trivcon/generate.h"

using namespace trivcon;

namespace {

// Upper triangle (compressed columns) of the graph Laplacian of a mesh's edges plus `shift` on the
// diagonal, with random positive edge weights.
struct Upper {
  int n = 0;
  std::vector<int> outer, inner;
  std::vector<double> values;
};

Upper shifted_laplacian(const Mesh& mesh, double shift, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> weight(0.1, 2.0);
  const int n = static_cast<int>(mesh.V.rows());
  std::vector<std::map<int, double>> columns(n);
  for (int v = 0; v < n; ++v) columns[v][v] = shift;
  for (int f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = std::min(mesh.F(f, k), mesh.F(f, (k + 1) % 3)), b = std::max(mesh.F(f, k), mesh.F(f, (k + 1) % 3));
      if (columns[b].count(a)) continue;  // each edge once (the second face sees it again)
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

cholmod_sparse view(const Upper& M) { return linalg::upper_view(M.outer, M.inner, M.values, M.n); }

// The library's CHOLMOD workspace (src/linalg/cholmod.h), as the solver sets it up.
struct Cholmod {
  linalg::CholmodContext context;
  cholmod_common& c = *context;
};

// Factors M with CHOLMOD and with linalg::factorize from one symbolic analysis; returns the largest
// difference of the factors' values relative to the largest value, and each one's `minor`.
struct Comparison {
  double difference = 0;
  size_t ours_minor = 0, cholmod_minor = 0;
  size_t supernodes = 0;
};
Comparison compare(Upper& M) {
  Cholmod cm;
  cholmod_sparse A = view(M);
  cholmod_factor* theirs = cholmod_analyze(&A, &cm.c);
  EXPECT_NE(theirs, nullptr);
  cholmod_factor* ours = cholmod_copy_factor(theirs, &cm.c);
  cholmod_factorize(&A, theirs, &cm.c);
  Comparison r;
  r.ours_minor = static_cast<size_t>(linalg::factorize(*ours, M.outer, M.inner, M.values, cm.c));
  EXPECT_EQ(r.ours_minor, ours->minor);
  r.cholmod_minor = theirs->minor;
  r.supernodes = ours->nsuper;
  EXPECT_TRUE(ours->is_super && ours->is_ll && ours->xtype == CHOLMOD_REAL);
  if (r.ours_minor == static_cast<size_t>(M.n) && r.cholmod_minor == static_cast<size_t>(M.n)) {
    EXPECT_EQ(ours->xsize, theirs->xsize);
    const double* a = static_cast<const double*>(ours->x);
    const double* b = static_cast<const double*>(theirs->x);
    double largest = 0;
    for (size_t k = 0; k < theirs->xsize; ++k) largest = std::max(largest, std::abs(b[k]));
    for (size_t k = 0; k < theirs->xsize; ++k) r.difference = std::max(r.difference, std::abs(a[k] - b[k]) / largest);
  }
  cholmod_free_factor(&ours, &cm.c);
  cholmod_free_factor(&theirs, &cm.c);
  return r;
}

}  // namespace

// A Hermitian positive definite matrix: the shifted Laplacian above with each off-diagonal entry turned by a
// random phase (a connection Laplacian, as trivcon/auto.h factors), values as (real, imaginary) pairs.
Upper hermitian_laplacian(const Mesh& mesh, double shift, unsigned seed) {
  Upper M = shifted_laplacian(mesh, shift, seed);
  std::mt19937 rng(seed + 1);
  std::uniform_real_distribution<double> angle(-3.14159, 3.14159);
  std::vector<double> values;
  for (int c = 0; c < M.n; ++c)
    for (int k = M.outer[c]; k < M.outer[c + 1]; ++k) {
      const double a = M.inner[k] == c ? 0.0 : angle(rng);
      values.push_back(M.values[k] * std::cos(a)), values.push_back(M.values[k] * std::sin(a));
    }
  M.values = values;
  return M;
}

// The complex (LLᴴ) factorization against CHOLMOD's, from one supernodal analysis: the same factor values, and a
// CHOLMOD solve with ours gives a small residual.
TEST(Supernodal, SameComplexFactorAsCholmod) {
  for (const auto& [name, mesh] : std::vector<std::pair<std::string, Mesh>>{{"icosphere-3", make_icosphere(3)},
                                                                            {"cube sphere 40", make_cube_sphere(40, true)},
                                                                            {"torus 90x36", make_torus(90, 36)}}) {
    SCOPED_TRACE(name);
    Upper M = hermitian_laplacian(mesh, 1e-3, 7);
    Cholmod cm;
    cm.c.supernodal = CHOLMOD_SUPERNODAL;
    cholmod_sparse A = linalg::upper_view_complex(M.outer, M.inner, M.values, M.n);
    cholmod_factor* theirs = cholmod_analyze(&A, &cm.c);
    ASSERT_NE(theirs, nullptr);
    cholmod_factor* ours = cholmod_copy_factor(theirs, &cm.c);
    ASSERT_TRUE(cholmod_factorize(&A, theirs, &cm.c));
    ASSERT_EQ(linalg::factorize_complex(*ours, M.outer, M.inner, M.values, cm.c), M.n);
    EXPECT_TRUE(ours->is_super && ours->is_ll && ours->xtype == CHOLMOD_COMPLEX);
    ASSERT_EQ(ours->xsize, theirs->xsize);
    const double* a = static_cast<const double*>(ours->x);
    const double* b = static_cast<const double*>(theirs->x);
    double largest = 0, difference = 0;
    for (size_t k = 0; k < 2 * theirs->xsize; ++k) largest = std::max(largest, std::abs(b[k]));
    for (size_t k = 0; k < 2 * theirs->xsize; ++k) difference = std::max(difference, std::abs(a[k] - b[k]) / largest);
    EXPECT_LT(difference, 1e-11);
    // Solve A x = b with our factor; the residual computed from the upper triangle directly.
    std::vector<double> rhs(2 * M.n);
    for (int i = 0; i < 2 * M.n; ++i) rhs[i] = std::sin(0.37 * i + 1);
    Eigen::VectorXd bv = Eigen::Map<Eigen::VectorXd>(rhs.data(), 2 * M.n);
    cholmod_dense B = linalg::dense_view_complex(bv);
    cholmod_dense* X = cholmod_solve(CHOLMOD_A, ours, &B, &cm.c);
    ASSERT_NE(X, nullptr);
    const std::complex<double>* x = static_cast<const std::complex<double>*>(X->x);
    std::vector<std::complex<double>> r(M.n);
    for (int i = 0; i < M.n; ++i) r[i] = {rhs[2 * i], rhs[2 * i + 1]};
    for (int c = 0; c < M.n; ++c)
      for (int k = M.outer[c]; k < M.outer[c + 1]; ++k) {
        const int i = M.inner[k];
        const std::complex<double> v(M.values[2 * k], M.values[2 * k + 1]);  // A(i, c), i <= c
        r[i] -= v * x[c];
        if (i != c) r[c] -= std::conj(v) * x[i];
      }
    double worst = 0;
    for (const auto& z : r) worst = std::max(worst, std::abs(z));
    EXPECT_LT(worst, 1e-9);
    cholmod_free_dense(&X, &cm.c);
    cholmod_free_factor(&ours, &cm.c);
    cholmod_free_factor(&theirs, &cm.c);
  }
}

TEST(Supernodal, SameFactorAsCholmod) {
  for (const auto& [name, mesh] : std::vector<std::pair<std::string, Mesh>>{{"icosphere-2", make_icosphere(2)},
                                                                            {"cube sphere 60", make_cube_sphere(60, true)},
                                                                            {"torus 120x48", make_torus(120, 48)},
                                                                            {"holed grid", make_holed_grid(80, 5)}}) {
    Upper M = shifted_laplacian(mesh, 1e-3, 7);
    const Comparison r = compare(M);
    EXPECT_EQ(r.ours_minor, static_cast<size_t>(M.n)) << name;
    EXPECT_EQ(r.cholmod_minor, static_cast<size_t>(M.n)) << name;
    EXPECT_LT(r.difference, 1e-12) << name << " (" << r.supernodes << " supernodes)";
  }
}

// The Laplacian of a small mesh with `extra` rows that couple with each other and with every tenth vertex:
// the top of the elimination tree is then a large dense block that both threads' subtrees update.
Upper with_dense_block(const Mesh& mesh, int extra) {
  Upper M = shifted_laplacian(mesh, 1e-3, 13);
  const int n = M.n;
  for (int c = n; c < n + extra; ++c) {
    for (int r = 0; r < n; r += 10) M.inner.push_back(r), M.values.push_back(-0.01);
    for (int r = n; r < c; ++r) M.inner.push_back(r), M.values.push_back(-0.001);
    M.inner.push_back(c), M.values.push_back(10.0 + 0.01 * n / 10);
    M.outer.push_back(static_cast<int>(M.inner.size()));
  }
  for (int r = 0; r < n; r += 10)  // keep the vertex rows diagonally dominant
    for (int k = M.outer[r]; k < M.outer[r + 1]; ++k)
      if (M.inner[k] == r) M.values[k] += 0.01 * extra;
  M.n = n + extra;
  return M;
}

TEST(Supernodal, SameFactorWithALargeTop) {
  Upper M = with_dense_block(make_cube_sphere(30, true), 700);
  const Comparison r = compare(M);
  EXPECT_EQ(r.ours_minor, static_cast<size_t>(M.n));
  EXPECT_LT(r.difference, 1e-12);
}

TEST(Supernodal, SameFactorOnOneThreeAndFourThreads) {
  // The subtrees are split into one part per OpenMP thread (more threads than cores is fine here).
  const int threads = omp_get_max_threads();
  for (int n : {1, 3, 4}) {
    SCOPED_TRACE(std::to_string(n) + " threads");
    omp_set_num_threads(n);
    Upper M = shifted_laplacian(make_cube_sphere(50, true), 1e-3, 11);
    const Comparison r = compare(M);
    EXPECT_EQ(r.ours_minor, static_cast<size_t>(M.n));
    EXPECT_LT(r.difference, 1e-12);
  }
  omp_set_num_threads(threads);
}

TEST(Supernodal, SameBitsEveryTime) {
  // The two threads' parts are computed in their own order and handed over in a fixed one.
  Upper M = shifted_laplacian(make_torus(160, 64), 1e-3, 17);
  Cholmod cm;
  cholmod_sparse A = view(M);
  cholmod_factor* symbolic = cholmod_analyze(&A, &cm.c);
  std::vector<double> first;
  for (int run = 0; run < 4; ++run) {
    cholmod_factor* L = cholmod_copy_factor(symbolic, &cm.c);
    ASSERT_EQ(linalg::factorize(*L, M.outer, M.inner, M.values, cm.c), M.n);
    const double* x = static_cast<const double*>(L->x);
    if (run == 0)
      first.assign(x, x + L->xsize);
    else
      EXPECT_TRUE(std::equal(first.begin(), first.end(), x)) << "run " << run;
    cholmod_free_factor(&L, &cm.c);
  }
  cholmod_free_factor(&symbolic, &cm.c);
}

// A x for the Hermitian (or symmetric) matrix given by its upper triangle, T = double or complex.
template <class T>
std::vector<T> multiply(const Upper& M, const std::vector<T>& x) {
  std::vector<T> y(M.n, T(0));
  const T* v = reinterpret_cast<const T*>(M.values.data());
  for (int c = 0; c < M.n; ++c)
    for (int k = M.outer[c]; k < M.outer[c + 1]; ++k) {
      const int i = M.inner[k];
      y[i] += v[k] * x[c];
      if (i != c) {
        if constexpr (std::is_same<T, double>::value)
          y[c] += v[k] * x[i];
        else
          y[c] += std::conj(v[k]) * x[i];
      }
    }
  return y;
}

// The parallel substitution against CHOLMOD's solve with the same factor, and by its own residual, on 1 to 4
// threads (a split per thread), real and complex, with a small and a large top of the tree.
template <class T>
void check_substitution(const Upper& M, const std::string& name) {
  constexpr bool complex = !std::is_same<T, double>::value;
  Cholmod cm;
  cm.c.supernodal = CHOLMOD_SUPERNODAL;
  cholmod_sparse A = complex ? linalg::upper_view_complex(M.outer, M.inner, M.values, M.n) : view(M);
  cholmod_factor* L = cholmod_analyze(&A, &cm.c);
  ASSERT_NE(L, nullptr);
  ASSERT_EQ(complex ? linalg::factorize_complex(*L, M.outer, M.inner, M.values, cm.c)
                    : linalg::factorize(*L, M.outer, M.inner, M.values, cm.c),
            M.n);
  std::vector<T> b(M.n);
  for (int i = 0; i < M.n; ++i) {
    if constexpr (complex)
      b[i] = T(std::sin(0.37 * i + 1), std::cos(0.11 * i));
    else
      b[i] = std::sin(0.37 * i + 1);
  }
  Eigen::VectorXd flat = Eigen::Map<const Eigen::VectorXd>(reinterpret_cast<const double*>(b.data()), (complex ? 2 : 1) * M.n);
  cholmod_dense B = complex ? linalg::dense_view_complex(flat) : linalg::dense_view(flat);
  cholmod_dense* X = cholmod_solve(CHOLMOD_A, L, &B, &cm.c);
  ASSERT_NE(X, nullptr);
  const T* theirs = static_cast<const T*>(X->x);
  double scale = 0;
  for (int i = 0; i < M.n; ++i) scale = std::max(scale, std::abs(theirs[i]));
  const int threads = omp_get_max_threads();
  std::vector<T> first;
  for (int n : {1, 2, 3, 4}) {
    SCOPED_TRACE(name + ", " + std::to_string(n) + " threads");
    omp_set_num_threads(n);
    const linalg::Substitution<T> solver(*L);
    EXPECT_EQ(solver.size(), M.n);
    for (int run = 0; run < 2; ++run) {
      std::vector<T> x = b;
      solver.solve(x.data());
      double difference = 0;
      for (int i = 0; i < M.n; ++i) difference = std::max(difference, std::abs(x[i] - theirs[i]) / scale);
      EXPECT_LT(difference, 1e-12);
      const std::vector<T> Ax = multiply(M, x);
      double residual = 0, bmax = 0;
      for (int i = 0; i < M.n; ++i) residual = std::max(residual, std::abs(Ax[i] - b[i])), bmax = std::max(bmax, std::abs(b[i]));
      EXPECT_LT(residual, 1e-9 * bmax);
      if (n == 2 && run == 0) first = x;
      if (n == 2 && run == 1) {
        EXPECT_TRUE(first == x) << "two runs on the same threads differ";
      }
    }
  }
  omp_set_num_threads(threads);
  cholmod_free_dense(&X, &cm.c);
  cholmod_free_factor(&L, &cm.c);
}

TEST(Substitution, SameSolutionAsCholmodRealAndComplex) {
  check_substitution<double>(shifted_laplacian(make_cube_sphere(50, true), 1e-3, 11), "real cube sphere 50");
  check_substitution<double>(with_dense_block(make_cube_sphere(30, true), 700), "real, large top");
  check_substitution<std::complex<double>>(hermitian_laplacian(make_torus(120, 48), 1e-3, 5), "complex torus 120x48");
  check_substitution<std::complex<double>>(hermitian_laplacian(make_holed_grid(60, 4), 1e-3, 9), "complex holed grid");
}

TEST(Substitution, RefusesAFactorOfTheOtherType) {
  Upper M = shifted_laplacian(make_icosphere(2), 1e-3, 3);
  Cholmod cm;
  cm.c.supernodal = CHOLMOD_SUPERNODAL;
  cholmod_sparse A = view(M);
  cholmod_factor* L = cholmod_analyze(&A, &cm.c);
  ASSERT_EQ(linalg::factorize(*L, M.outer, M.inner, M.values, cm.c), M.n);
  EXPECT_THROW(linalg::Substitution<std::complex<double>>{*L}, Error);
  cholmod_free_factor(&L, &cm.c);
}

TEST(Supernodal, ReportsTheColumnThatIsNotPositiveDefinite) {
  // A diagonally dominant matrix stays so as columns are eliminated: only the row made negative fails,
  // at its own factor column, wherever the ordering put it.
  for (int bad : {0, 777, 5000}) {
    Upper M = shifted_laplacian(make_cube_sphere(40, true), 1.0, 3);
    for (int k = M.outer[bad]; k < M.outer[bad + 1]; ++k)
      if (M.inner[k] == bad) M.values[k] = -50.0;
    Cholmod cm;
    cholmod_sparse A = view(M);
    cholmod_factor* L = cholmod_analyze(&A, &cm.c);
    const int* perm = static_cast<const int*>(L->Perm);
    const int column = static_cast<int>(std::find(perm, perm + M.n, bad) - perm);
    EXPECT_EQ(linalg::factorize(*L, M.outer, M.inner, M.values, cm.c), column) << "row " << bad;
    cholmod_free_factor(&L, &cm.c);
    const Comparison r = compare(M);
    EXPECT_EQ(r.ours_minor, r.cholmod_minor) << "row " << bad;
  }
}

// Checks a split against split_tree's contract (src/linalg/supernodal.h) and returns what it left below
// the top: the loads of the parts (the sum of `work` over each) and the subtree roots there.
struct BelowTop {
  std::vector<double> load;
  std::vector<int> roots;
  double heaviest = 0;  // the largest subtree below the top
};
BelowTop expect_valid_split(const std::vector<int>& parent, const std::vector<double>& work, double min_split,
                            const linalg::TreeSplit& split, int parts = 2) {
  const int count = static_cast<int>(parent.size());
  EXPECT_EQ(static_cast<int>(split.part.size()), parts);
  std::vector<int> where(count, -2);  // −1: top, k ≥ 0: part k
  for (int s : split.top) {
    EXPECT_EQ(where[s], -2);
    where[s] = -1;
  }
  EXPECT_TRUE(std::is_sorted(split.top.begin(), split.top.end()));
  for (int k = 0; k < static_cast<int>(split.part.size()); ++k) {
    EXPECT_TRUE(std::is_sorted(split.part[k].begin(), split.part[k].end()));
    for (int s : split.part[k]) {
      EXPECT_EQ(where[s], -2);
      where[s] = k;
    }
  }
  std::vector<double> subtree = work;  // a parent comes after its children
  for (int s = 0; s < count; ++s)
    if (parent[s] >= 0) subtree[parent[s]] += subtree[s];
  BelowTop below;
  below.load.assign(split.part.size(), 0.0);
  for (int s = 0; s < count; ++s) {
    EXPECT_NE(where[s], -2) << "supernode " << s << " in no list";
    if (where[s] == -2) continue;
    // The top is closed upwards, and a part's supernode has its ancestors in its part or the top: the
    // parts are whole subtrees and do not depend on each other.
    if (parent[s] >= 0) {
      EXPECT_TRUE(where[s] == -1 ? where[parent[s]] == -1 : where[parent[s]] == where[s] || where[parent[s]] == -1) << "supernode " << s;
    }
    if (where[s] == -1) {
      EXPECT_GT(subtree[s], min_split) << "supernode " << s << " is in the top, but its subtree is too small to split";
    } else {
      below.load[where[s]] += work[s];
      if (parent[s] < 0 || where[parent[s]] == -1) below.roots.push_back(s), below.heaviest = std::max(below.heaviest, subtree[s]);
    }
  }
  // Splitting stopped where it should: the largest subtree left holds at most 1/parts of the work below the
  // top, or no more than min_split (with one part nothing is split).
  double total = 0;
  for (double l : below.load) total += l;
  if (parts > 1) {
    EXPECT_FALSE(below.heaviest > total / parts && below.heaviest > min_split)
        << "the largest subtree below the top should have been split";
  } else {
    EXPECT_TRUE(split.top.empty());
  }
  // Every part gets work whenever there are as many subtrees as parts; balanced by the work measure: the
  // heaviest and lightest parts differ by at most the largest subtree (each subtree goes whole to the
  // lightest part, largest first).
  if (static_cast<int>(below.roots.size()) >= parts) {
    for (const auto& part : split.part) EXPECT_FALSE(part.empty()) << below.roots.size() << " subtrees below the top, a part empty";
  }
  if (!below.load.empty()) {
    const auto [lightest, heaviest] = std::minmax_element(below.load.begin(), below.load.end());
    EXPECT_LE(*heaviest - *lightest, below.heaviest + 1e-9);
  }
  return below;
}

// A random forest of up to 400 supernodes (a parent after its children, one root in 20 on average) with
// random work.
void random_forest(std::mt19937& rng, std::vector<int>& parent, std::vector<double>& work) {
  const int count = 1 + static_cast<int>(rng() % 400);
  parent.assign(count, -1);
  work.resize(count);
  for (int s = 0; s < count; ++s) {
    work[s] = 1 + rng() % 1000;
    if (s + 1 < count && rng() % 20 != 0) parent[s] = s + 1 + static_cast<int>(rng() % std::min(5, count - s - 1));
  }
}

TEST(Supernodal, TreeSplitIsIndependentAndBalanced) {
  using linalg::split_tree;
  {  // Two equal leaves under a heavy root: the root is the top, one leaf per part.
    const linalg::TreeSplit s = split_tree({2, 2, -1}, {10, 10, 1}, 5);
    expect_valid_split({2, 2, -1}, {10, 10, 1}, 5, s);
    EXPECT_EQ(s.top, std::vector<int>{2});
    EXPECT_EQ(s.part[0].size() + s.part[1].size(), 2u);
    EXPECT_FALSE(s.part[0].empty() || s.part[1].empty());
  }
  {  // Two trees of equal work: nothing to split, one each.
    const linalg::TreeSplit s = split_tree({1, -1, 3, -1}, {5, 5, 5, 5}, 1);
    expect_valid_split({1, -1, 3, -1}, {5, 5, 5, 5}, 1, s);
    EXPECT_TRUE(s.top.empty());
    EXPECT_EQ(s.part[0].size(), 2u);
    EXPECT_EQ(s.part[1].size(), 2u);
  }
  {  // A chain allows no two independent parts: below min_split it stays whole, above it all goes to the top.
    const linalg::TreeSplit small = split_tree({1, 2, -1}, {10, 10, 10}, 100), large = split_tree({1, 2, -1}, {10, 10, 10}, 1);
    expect_valid_split({1, 2, -1}, {10, 10, 10}, 100, small);
    expect_valid_split({1, 2, -1}, {10, 10, 10}, 1, large);
    EXPECT_TRUE(small.top.empty());
    EXPECT_EQ(small.part[0].size() + small.part[1].size(), 3u);
    EXPECT_EQ(large.top, (std::vector<int>{0, 1, 2}));
  }
  std::mt19937 rng(5);
  int split_in_two = 0;
  for (int trial = 0; trial < 50; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    std::vector<int> parent;
    std::vector<double> work;
    random_forest(rng, parent, work);
    const linalg::TreeSplit split = split_tree(parent, work, 100);
    split_in_two += expect_valid_split(parent, work, 100, split).roots.size() >= 2;
  }
  EXPECT_GE(split_in_two, 40) << "most random forests leave several subtrees below the top";
}

// The same contract for 1, 3 and 4 parts (threads): split_tree takes OpenMP's thread count.
TEST(Supernodal, TreeSplitIntoAnyNumberOfParts) {
  using linalg::split_tree;
  {  // Four equal leaves under a root: with 4 parts one leaf each, with 1 part nothing split.
    const std::vector<int> parent{4, 4, 4, 4, -1};
    const std::vector<double> work{10, 10, 10, 10, 1};
    const linalg::TreeSplit four = split_tree(parent, work, 5, 4), one = split_tree(parent, work, 5, 1);
    expect_valid_split(parent, work, 5, four, 4);
    expect_valid_split(parent, work, 5, one, 1);
    EXPECT_EQ(four.top, std::vector<int>{4});
    for (const auto& part : four.part) EXPECT_EQ(part.size(), 1u);
    EXPECT_EQ(one.part[0].size(), 5u);
  }
  std::mt19937 rng(11);
  for (int parts : {1, 3, 4}) {
    int all_used = 0;
    for (int trial = 0; trial < 40; ++trial) {
      SCOPED_TRACE("parts " + std::to_string(parts) + ", trial " + std::to_string(trial));
      std::vector<int> parent;
      std::vector<double> work;
      random_forest(rng, parent, work);
      const linalg::TreeSplit split = split_tree(parent, work, 100, parts);
      all_used += static_cast<int>(expect_valid_split(parent, work, 100, split, parts).roots.size()) >= parts;
    }
    EXPECT_GE(all_used, 30) << "most random forests leave a subtree for every part";
  }
}

// With `deepen` (the parallel substitution's split): the same contract of independent, balanced parts, and a
// critical path (the top's work, done on one thread, plus the heaviest part's) never longer than without.
TEST(Supernodal, RefinedTreeSplitShortensTheCriticalPath) {
  using linalg::split_tree;
  auto critical_path = [](const std::vector<double>& work, const linalg::TreeSplit& s, const BelowTop& below) {
    double top = 0;
    for (int t : s.top) top += work[t];
    return top + *std::max_element(below.load.begin(), below.load.end());
  };
  std::mt19937 rng(23);
  int shorter = 0;
  for (int trial = 0; trial < 60; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    std::vector<int> parent;
    std::vector<double> work;
    random_forest(rng, parent, work);
    for (int parts : {2, 3}) {
      const linalg::TreeSplit plain = split_tree(parent, work, 100, parts), deepened = split_tree(parent, work, 100, parts, true);
      const BelowTop below_plain = expect_valid_split(parent, work, 100, plain, parts);
      const BelowTop below_deepened = expect_valid_split(parent, work, 100, deepened, parts);
      const double a = critical_path(work, plain, below_plain), b = critical_path(work, deepened, below_deepened);
      EXPECT_LE(b, a + 1e-9);
      shorter += b < a - 1e-9;
    }
  }
  EXPECT_GE(shorter, 1) << "refining should help on some random forests";
  // A root over three subtrees of 40, 35 and 25: none holds half, so the plain split stops at the root and
  // two of them share a thread (critical path 1 + 60); going down the 40 (2 over two 19s) gives 3 + 54.
  const std::vector<int> parent{2, 2, 5, 5, 5, -1};
  const std::vector<double> work{19, 19, 2, 35, 25, 1};
  const linalg::TreeSplit plain = split_tree(parent, work, 1, 2), deepened = split_tree(parent, work, 1, 2, true);
  const BelowTop a = expect_valid_split(parent, work, 1, plain), b = expect_valid_split(parent, work, 1, deepened);
  EXPECT_EQ(plain.top, (std::vector<int>{5}));
  EXPECT_DOUBLE_EQ(critical_path(work, plain, a), 61);
  EXPECT_EQ(deepened.top, (std::vector<int>{2, 5}));
  EXPECT_DOUBLE_EQ(critical_path(work, deepened, b), 57);
}

// The elimination trees of mesh Laplacians, with the work measure and threshold linalg::factorize
// uses (per supernode cols · height² + 64 · height, split above 1e5): two non-empty parts, balanced.
TEST(Supernodal, TreeSplitOfMeshFactorsWithTheFactorizationsWorkMeasure) {
  for (const auto& [name, mesh] : std::vector<std::pair<std::string, Mesh>>{{"cube sphere 40", make_cube_sphere(40, true)},
                                                                            {"torus 120x48", make_torus(120, 48)},
                                                                            {"holed grid", make_holed_grid(120, 3)}}) {
    SCOPED_TRACE(name);
    Upper M = shifted_laplacian(mesh, 1e-3, 7);
    Cholmod cm;
    cholmod_sparse A = view(M);
    cholmod_factor* L = cholmod_analyze(&A, &cm.c);
    ASSERT_NE(L, nullptr);
    ASSERT_TRUE(L->is_super);
    const linalg::Supernodes S(L);
    const std::vector<int> parent = linalg::supernode_parents(S, S.owners());
    std::vector<double> work(S.count);
    for (int s = 0; s < S.count; ++s) {
      const double ncol = S.cols(s), nrow = S.height(s);
      work[s] = ncol * nrow * nrow + 64 * nrow;
    }
    const linalg::TreeSplit split = linalg::split_tree(parent, work, 1e5);
    const BelowTop below = expect_valid_split(parent, work, 1e5, split);
    EXPECT_FALSE(split.part[0].empty() || split.part[1].empty());
    EXPECT_GE(below.roots.size(), 2u);
    const double total = below.load[0] + below.load[1];
    // The contract bounds the difference by the largest subtree (up to half the work); on these trees the
    // parts are within 6% of each other.
    EXPECT_LE(std::abs(below.load[0] - below.load[1]), 0.2 * total) << below.load[0] << " vs " << below.load[1];
    cholmod_free_factor(&L, &cm.c);
  }
}
