// SPDX-License-Identifier: MIT
#include "linalg/supernodal.h"

#include <omp.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <complex>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>

#include "linalg/parallel.h"
#include "trivcon/blas.h"
#include "trivcon/cancel.h"
#include "trivcon/error.h"

// Fortran BLAS and LAPACK, the same OpenBLAS CHOLMOD calls (libblas.so.3 / liblapack.so.3).
extern "C" {
void dsyrk_(const char* uplo, const char* trans, const int* n, const int* k, const double* alpha, const double* a, const int* lda,
            const double* beta, double* c, const int* ldc);
void dgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k, const double* alpha, const double* a,
            const int* lda, const double* b, const int* ldb, const double* beta, double* c, const int* ldc);
void dtrsm_(const char* side, const char* uplo, const char* transa, const char* diag, const int* m, const int* n, const double* alpha,
            const double* a, const int* lda, double* b, const int* ldb);
void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info);
void dtrtri_(const char* uplo, const char* diag, const int* n, double* a, const int* lda, int* info);
// Complex (the smoothest-field matrix of trivcon/auto.h): std::complex<double> is layout-compatible with
// Fortran's COMPLEX*16.
void zherk_(const char* uplo, const char* trans, const int* n, const int* k, const double* alpha, const std::complex<double>* a,
            const int* lda, const double* beta, std::complex<double>* c, const int* ldc);
void zgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k, const std::complex<double>* alpha,
            const std::complex<double>* a, const int* lda, const std::complex<double>* b, const int* ldb, const std::complex<double>* beta,
            std::complex<double>* c, const int* ldc);
void ztrsm_(const char* side, const char* uplo, const char* transa, const char* diag, const int* m, const int* n,
            const std::complex<double>* alpha, const std::complex<double>* a, const int* lda, std::complex<double>* b, const int* ldb);
void zpotrf_(const char* uplo, const int* n, std::complex<double>* a, const int* lda, int* info);
}

namespace trivcon::linalg {

namespace {

// Below these sizes a block is computed by inlined loops (Eigen; our own panel factorization) instead of
// a BLAS call. Most supernodes near the leaves are a few columns wide; the thresholds (tried from all-BLAS
// to none below 10⁹ flops) moved the time by less than the machine's noise, except that without BLAS at all
// the top of the tree takes several times longer (BENCHMARKS.md, "Figures that were in code comments").
constexpr double kBlasUpdateFlops = 8192;  // ndrow2 · ndrow1 · ndcol of one descendant's update
constexpr int kBlasColumns = 24;           // columns of a supernode's own factorization

using Complex = std::complex<double>;
double conj_if_complex(double a) { return a; }
Complex conj_if_complex(Complex a) { return std::conj(a); }

// The BLAS calls of one scalar type: the real symmetric (dsyrk, dgemm "T", dpotrf, dtrsm "T") or the complex
// Hermitian ones (zherk, zgemm "C", zpotrf, ztrsm "C"), for LLᵀ and LLᴴ respectively.
void blas_rank_update(int n, int k, const double* a, int lda, double* c, int ldc) {
  const double one = 1, zero = 0;
  dsyrk_("L", "N", &n, &k, &one, a, &lda, &zero, c, &ldc);
}
void blas_rank_update(int n, int k, const Complex* a, int lda, Complex* c, int ldc) {
  const double one = 1, zero = 0;
  zherk_("L", "N", &n, &k, &one, a, &lda, &zero, c, &ldc);
}
void blas_product(int m, int n, int k, const double* a, int lda, const double* b, int ldb, double* c, int ldc) {
  const double one = 1, zero = 0;
  dgemm_("N", "T", &m, &n, &k, &one, a, &lda, b, &ldb, &zero, c, &ldc);
}
void blas_product(int m, int n, int k, const Complex* a, int lda, const Complex* b, int ldb, Complex* c, int ldc) {
  const Complex one = 1, zero = 0;
  zgemm_("N", "C", &m, &n, &k, &one, a, &lda, b, &ldb, &zero, c, &ldc);
}
void lapack_cholesky(int n, double* a, int lda, int* info) { dpotrf_("L", &n, a, &lda, info); }
void lapack_cholesky(int n, Complex* a, int lda, int* info) { zpotrf_("L", &n, a, &lda, info); }
void blas_triangular_solve(int m, int n, const double* a, int lda, double* b, int ldb) {
  const double one = 1;
  dtrsm_("R", "L", "T", "N", &m, &n, &one, a, &lda, b, &ldb);
}
void blas_triangular_solve(int m, int n, const Complex* a, int lda, Complex* b, int ldb) {
  const Complex one = 1;
  ztrsm_("R", "L", "C", "N", &m, &n, &one, a, &lda, b, &ldb);
}

// The matrix permuted to factor order, lower triangle, by columns: column k holds its rows ≥ k (for a
// Hermitian matrix, an upper entry that lands above the diagonal after the permutation is conjugated).
template <class T>
struct PermutedLower {
  std::vector<int> start, row;
  std::vector<T> value;
};

template <class T>
PermutedLower<T> permuted_lower(const std::vector<int>& outer, const std::vector<int>& inner, const T* values,
                                const std::vector<int>& position) {
  const int n = static_cast<int>(position.size());
  PermutedLower<T> A;
  A.start.assign(static_cast<size_t>(n) + 1, 0);
  for (int c = 0; c < n; ++c)
    for (int k = outer[c]; k < outer[c + 1]; ++k) ++A.start[std::min(position[inner[k]], position[c]) + 1];
  for (int c = 0; c < n; ++c) A.start[c + 1] += A.start[c];
  std::vector<int> fill(A.start.begin(), A.start.end() - 1);
  A.row.resize(A.start[n]), A.value.resize(A.start[n]);
  for (int c = 0; c < n; ++c)
    for (int k = outer[c]; k < outer[c + 1]; ++k) {
      const int i = position[inner[k]], j = position[c];
      const int q = fill[std::min(i, j)]++;
      A.row[q] = std::max(i, j), A.value[q] = i >= j ? values[k] : conj_if_complex(values[k]);
    }
  return A;
}

// Per thread: where each factor row sits in the supernode being computed, and the update buffer.
template <class T>
struct Workspace {
  std::vector<int> map, relative;
  std::unique_ptr<T[]> update;  // not initialised: every update overwrites what it reads
  size_t update_size = 0;
};

template <class T>
class Numeric {
 public:
  using Matrix = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>;
  using Block = Eigen::Map<Matrix, 0, Eigen::OuterStride<>>;
  using ConstBlock = Eigen::Map<const Matrix, 0, Eigen::OuterStride<>>;

  Numeric(const Supernodes& L, const std::vector<int>& owner, T* x, const PermutedLower<T>& A)
      : A_(A), L_(L), owner_(owner), x_(x), next_(L.count, -1), lpos_(L.count, 0) {}

  Workspace<T> workspace() const {
    Workspace<T> w;
    w.map.assign(owner_.size(), -1);
    int height = 0;
    for (int s = 0; s < L_.count; ++s) height = std::max(height, L_.height(s));
    w.relative.resize(height);
    return w;
  }

  // Computes supernode s: its entries of A minus the updates of the descendants linked to it in `head`,
  // then the Cholesky factor of its diagonal block and the triangular solve of the rows below; then
  // links s, in `head`, to the supernode of its first row below (its next update). Returns the factor
  // column where the matrix was found not positive definite, or −1.
  int compute(int s, Workspace<T>& w, std::vector<int>& head) {
    const int k1 = L_.first(s), ncol = L_.cols(s), nrow = L_.height(s);
    T* Ls = x_ + L_.px[s];
    std::fill(Ls, Ls + static_cast<size_t>(nrow) * ncol, T(0));
    for (int i = 0; i < nrow; ++i) w.map[L_.row(s, i)] = i;
    for (int k = k1; k < k1 + ncol; ++k) {
      T* column = Ls + static_cast<size_t>(k - k1) * nrow;
      for (int q = A_.start[k]; q < A_.start[k + 1]; ++q) column[w.map[A_.row[q]]] += A_.value[q];
    }
    for (int d = head[s]; d != -1;) {
      const int next = next_[d];
      update_from(d, k1 + ncol, Ls, nrow, w);
      link(d, head);
      d = next;
    }
    head[s] = -1;
    const int failed = factor_panel(Ls, nrow, ncol);
    if (failed >= 0) return k1 + failed;
    lpos_[s] = ncol;
    link(s, head);
    return -1;
  }

  // Moves the descendants linked to s in `from` to the front of its list in `to`.
  void move_list(int s, std::vector<int>& from, std::vector<int>& to) {
    for (int d = from[s]; d != -1;) {
      const int next = next_[d];
      next_[d] = to[s], to[s] = d;
      d = next;
    }
    from[s] = -1;
  }

 private:
  // Ls −= the part of descendant d's columns that falls in supernode s (columns up to k2 − 1, from the
  // row where d's last update stopped).
  void update_from(int d, int k2, T* Ls, int nrow, Workspace<T>& w) {
    const int ndcol = L_.cols(d), ndrow = L_.height(d);
    const int first = lpos_[d];
    int last = first;
    while (last < ndrow && L_.row(d, last) < k2) ++last;
    const int ndrow1 = last - first, ndrow2 = ndrow - first;
    lpos_[d] = last;
    // Grown as needed: the largest updates (L.maxcsize) go to the top of the tree, which the threads
    // below it never reach.
    const size_t size = static_cast<size_t>(ndrow2) * ndrow1;
    if (size > w.update_size) {
      w.update.reset();
      w.update.reset(new T[size]);
      w.update_size = size;
    }
    const T* Ld = x_ + L_.px[d] + first;  // rows first … ndrow − 1 of d, leading dimension ndrow
    T* C = w.update.get();                // ndrow2 × ndrow1, leading dimension ndrow2
    if (static_cast<double>(ndrow2) * ndrow1 * ndcol < kBlasUpdateFlops) {
      const ConstBlock below(Ld, ndrow2, ndcol, Eigen::OuterStride<>(ndrow));
      Block(C, ndrow2, ndrow1, Eigen::OuterStride<>(ndrow2)).noalias() = below * below.topRows(ndrow1).adjoint();
    } else {
      // The Hermitian rank update fills the lower triangle of the top ndrow1 rows (its diagonal real).
      blas_rank_update(ndrow1, ndcol, Ld, ndrow, C, ndrow2);
      const int ndrow3 = ndrow2 - ndrow1;
      if (ndrow3 > 0) blas_product(ndrow3, ndrow1, ndcol, Ld + ndrow1, ndrow, Ld, ndrow, C + ndrow1, ndrow2);
    }
    int* relative = w.relative.data();
    for (int i = 0; i < ndrow2; ++i) relative[i] = w.map[L_.row(d, first + i)];
    for (int j = 0; j < ndrow1; ++j) {
      T* column = Ls + static_cast<size_t>(relative[j]) * nrow;  // rows k1 … k2 − 1 are s's own columns
      const T* c = C + static_cast<size_t>(j) * ndrow2;
      for (int i = j; i < ndrow2; ++i) column[relative[i]] -= c[i];
    }
  }

  // Links d (computed, its next rows starting at lpos_[d]) to the supernode of that row in `head`, if any.
  void link(int d, std::vector<int>& head) {
    if (lpos_[d] >= L_.height(d)) return;
    const int target = owner_[L_.row(d, lpos_[d])];
    next_[d] = head[target];
    head[target] = d;
  }

  // Cholesky factor of the ncol × ncol diagonal block of the nrow × ncol panel, and the rows below
  // divided by it. Returns the panel column that is not positive, or −1.
  // (For a Hermitian matrix the diagonal's real part is what is tested and factored; its imaginary part is
  // zero in exact arithmetic and is dropped.)
  static int factor_panel(T* panel, int nrow, int ncol) {
    if (ncol < kBlasColumns) {
      for (int j = 0; j < ncol; ++j) {
        T* cj = panel + static_cast<size_t>(j) * nrow;
        const double pivot = std::real(cj[j]);
        if (!(pivot > 0) || !std::isfinite(pivot)) return j;
        const double d = std::sqrt(pivot);
        cj[j] = d;
        const double inv = 1 / d;
        for (int i = j + 1; i < nrow; ++i) cj[i] *= inv;
        for (int k = j + 1; k < ncol; ++k) {
          T* ck = panel + static_cast<size_t>(k) * nrow;
          const T f = conj_if_complex(cj[k]);
          for (int i = k; i < nrow; ++i) ck[i] -= cj[i] * f;
        }
      }
      return -1;
    }
    int info = 0;
    lapack_cholesky(ncol, panel, nrow, &info);
    if (info > 0) return info - 1;
    for (int j = 0; j < ncol; ++j) {
      const double d = std::real(panel[static_cast<size_t>(j) * nrow + j]);
      if (!(d > 0) || !std::isfinite(d)) return j;
    }
    const int below = nrow - ncol;
    if (below > 0) blas_triangular_solve(below, ncol, panel, nrow, panel + ncol, nrow);
    return -1;
  }

  const PermutedLower<T>& A_;
  const Supernodes& L_;
  const std::vector<int>& owner_;
  T* x_;                          // L_.x, written
  std::vector<int> next_, lpos_;  // a linked list's next, and where each supernode's next update starts
};

}  // namespace

TreeSplit split_tree(const std::vector<int>& parent, const std::vector<double>& own_work, double min_split, int parts, bool deepen) {
  if (parts < 1) parts = 1;
  const int count = static_cast<int>(parent.size());
  std::vector<double> work = own_work;  // of each subtree (a parent comes after its children)
  std::vector<std::vector<int>> children(count);
  std::vector<int> roots;
  for (int s = 0; s < count; ++s) {
    if (parent[s] >= 0)
      work[parent[s]] += work[s], children[parent[s]].push_back(s);
    else
      roots.push_back(s);
  }
  TreeSplit split;
  split.part.resize(parts);
  auto lighter = [&](int a, int b) { return work[a] < work[b]; };
  std::vector<int> open = roots;  // a max-heap of subtree roots by work
  std::make_heap(open.begin(), open.end(), lighter);
  double open_work = 0;
  for (int r : roots) open_work += work[r];
  while (parts > 1 && !open.empty() && work[open.front()] > open_work / parts && work[open.front()] > min_split) {
    std::pop_heap(open.begin(), open.end(), lighter);
    const int s = open.back();
    open.pop_back();
    split.top.push_back(s);
    open_work -= work[s];
    for (int c : children[s]) open.push_back(c), std::push_heap(open.begin(), open.end(), lighter), open_work += work[c];
  }
  if (deepen && parts > 1) {
    // Further down while that shortens top + heaviest part: each step moves the heaviest subtree's root to
    // the top; the best prefix of these steps is kept (64 steps in a row without a better one end the search).
    auto heaviest_part = [&](std::vector<int> roots) {
      std::sort(roots.begin(), roots.end(), [&](int a, int b) { return work[a] > work[b]; });
      std::vector<double> load(parts, 0.0);
      for (int r : roots) *std::min_element(load.begin(), load.end()) += work[r];
      return *std::max_element(load.begin(), load.end());
    };
    double top_work = 0;
    for (int s : split.top) top_work += own_work[s];
    double best = top_work + heaviest_part(open);
    std::vector<int> steps, best_open = open;
    size_t best_steps = 0;
    while (!open.empty() && work[open.front()] > min_split && steps.size() < best_steps + 64) {
      std::pop_heap(open.begin(), open.end(), lighter);
      const int s = open.back();
      open.pop_back();
      steps.push_back(s);
      top_work += own_work[s];
      for (int c : children[s]) open.push_back(c), std::push_heap(open.begin(), open.end(), lighter);
      if (const double cost = top_work + heaviest_part(open); cost < best) best = cost, best_steps = steps.size(), best_open = open;
    }
    split.top.insert(split.top.end(), steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(best_steps));
    open = best_open;
  }
  std::sort(open.begin(), open.end(), [&](int a, int b) { return work[a] > work[b]; });
  std::vector<double> load(parts, 0.0);
  std::vector<int> stack;
  for (int r : open) {
    const int k = static_cast<int>(std::min_element(load.begin(), load.end()) - load.begin());  // the first least loaded
    load[k] += work[r];
    for (stack.assign(1, r); !stack.empty();) {
      const int s = stack.back();
      stack.pop_back();
      split.part[k].push_back(s);
      stack.insert(stack.end(), children[s].begin(), children[s].end());
    }
  }
  std::sort(split.top.begin(), split.top.end());
  for (auto& part : split.part) std::sort(part.begin(), part.end());
  return split;
}

std::vector<int> Supernodes::owners() const {
  std::vector<int> owner(super[count]);
  for (int s = 0; s < count; ++s) std::fill(owner.begin() + first(s), owner.begin() + first(s) + cols(s), s);
  return owner;
}

std::vector<int> supernode_parents(const Supernodes& L, const std::vector<int>& owner) {
  std::vector<int> parent(L.count, -1);
  for (int s = 0; s < L.count; ++s)
    if (L.height(s) > L.cols(s)) parent[s] = owner[L.row(s, L.cols(s))];
  return parent;
}

namespace {

// The numeric factorization into the values x of the supernodal factor S, whose column k is matrix row perm[k].
// Returns the first factor column not positive definite, or n.
template <class T>
int factor_values(const Supernodes& S, const int* perm, int n, T* x, const std::vector<int>& outer, const std::vector<int>& inner,
                  const T* values) {
  std::vector<int> position(n);
  for (int k = 0; k < n; ++k) position[perm[k]] = k;
  const PermutedLower<T> A = permuted_lower(outer, inner, values, position);

  const std::vector<int> owner = S.owners();
  std::vector<double> work(S.count);  // flops of its own factorization and of the updates it sends, and a fixed cost
  for (int s = 0; s < S.count; ++s) {
    const double ncol = S.cols(s), nrow = S.height(s);
    work[s] = ncol * nrow * nrow + 64 * nrow;
  }
  const TreeSplit split = split_tree(supernode_parents(S, owner), work, 1e5, linalg::max_threads());
  const int parts = static_cast<int>(split.part.size());
  Numeric<T> numeric(S, owner, x, A);
  // Below the top, one thread per part (OpenMP's thread count): a subtree needs only its own descendants. Each thread keeps its own
  // lists of pending updates (`head`); its lists for the supernodes of the top are handed over when both
  // are done. Then the top, one supernode at a time, with OpenBLAS's threads inside the large dense
  // blocks there. (Gathering each thread's updates to the top in buffers of its own, so that they are
  // computed on both cores too, saved nothing: it took each thread as long as it saved the top;
  // BENCHMARKS.md, "Tried and dropped".) The result does not depend on the timing of the threads: each
  // part is computed in its own order and the lists are handed over in a fixed one.
  const bool several = parts > 1 && !split.part[1].empty();
  std::vector<std::vector<int>> head(parts);
  std::vector<int> failed(parts, -1);
  std::vector<std::exception_ptr> error(parts);
  const std::atomic<bool>* cancel = cancel_flag().get();  // trivcon/cancel.h: polled per supernode, on every thread
  {
    std::optional<SingleThreadedBlas> one_thread_per_call;
    if (several) one_thread_per_call.emplace();
#pragma omp parallel for schedule(static, 1) num_threads(parts) if (several)
    for (int k = 0; k < parts; ++k) {
      try {
        head[k].assign(S.count, -1);
        Workspace<T> w = numeric.workspace();
        for (int s : split.part[k]) {
          check_cancelled(cancel);
          if ((failed[k] = numeric.compute(s, w, head[k])) >= 0) break;
        }
      } catch (...) {  // an exception must not leave an OpenMP region
        error[k] = std::current_exception();
      }
    }
  }
  for (const auto& e : error)
    if (e) std::rethrow_exception(e);
  int minor = n;
  for (int f : failed)
    if (f >= 0) minor = std::min(minor, f);
  if (minor == n) {
    std::vector<int> top_head(S.count, -1);
    for (int t : split.top)
      for (auto& h : head) numeric.move_list(t, h, top_head);
    Workspace<T> w = numeric.workspace();
    for (int t : split.top) {
      check_cancelled(cancel);
      if (const int f = numeric.compute(t, w, top_head); f >= 0) {
        minor = f;
        break;
      }
    }
  }
  return minor;
}

#ifdef TRIVCON_WITH_SUITESPARSE
template <class T>
int factorize_as(cholmod_factor& L, const std::vector<int>& outer, const std::vector<int>& inner, const T* values, cholmod_common& c) {
  if (!L.is_super) throw Error("internal: the numeric factorization needs a supernodal symbolic factor");
  // The super, pi, px and s arrays are read as int (CHOLMOD's int API; src/linalg/cholmod.h checks the version).
  if (L.itype != CHOLMOD_INT) throw Error("internal: the numeric factorization needs a factor of CHOLMOD's int API");
  // Allocates the values (L.xsize entries of T, interleaved for complex) and marks L numeric LLᵀ (LLᴴ), as
  // cholmod_super_numeric does.
  const int xtype = std::is_same<T, double>::value ? CHOLMOD_REAL : CHOLMOD_COMPLEX;
  if (!cholmod_change_factor(xtype, 1, 1, 1, 1, &L, &c) || L.x == nullptr)
    throw Error("CHOLMOD could not allocate the factor (status " + std::to_string(c.status) + ")");
  const int minor =
      factor_values<T>(Supernodes(&L), static_cast<const int*>(L.Perm), static_cast<int>(L.n), static_cast<T*>(L.x), outer, inner, values);
  L.minor = static_cast<size_t>(minor);
  return minor;
}
#endif

template <class T>
int factorize_own(const SymbolicFactor& L, FactorValues<T>& x, const std::vector<int>& outer, const std::vector<int>& inner,
                  const T* values) {
  if (static_cast<int>(L.super.size()) != L.nsuper + 1 || L.pi.size() != L.super.size() || L.px.size() != L.super.size() ||
      static_cast<int>(L.perm.size()) != L.n)
    throw Error("internal: the numeric factorization was given an incomplete symbolic factor");
  x.resize(L.xsize);  // not zeroed: Numeric::compute writes each supernode's block whole
  return factor_values<T>(Supernodes(L, reinterpret_cast<const double*>(x.data())), L.perm.data(), L.n, x.data(), outer, inner, values);
}

}  // namespace

#ifdef TRIVCON_WITH_SUITESPARSE
int factorize(cholmod_factor& L, const std::vector<int>& outer, const std::vector<int>& inner, const std::vector<double>& values,
              cholmod_common& c) {
  return factorize_as<double>(L, outer, inner, values.data(), c);
}

int factorize_complex(cholmod_factor& L, const std::vector<int>& outer, const std::vector<int>& inner, const std::vector<double>& values,
                      cholmod_common& c) {
  return factorize_as<Complex>(L, outer, inner, reinterpret_cast<const Complex*>(values.data()), c);
}
#endif

int factorize(const SymbolicFactor& L, FactorValues<double>& x, const std::vector<int>& outer, const std::vector<int>& inner,
              const std::vector<double>& values) {
  return factorize_own<double>(L, x, outer, inner, values.data());
}

int factorize_complex(const SymbolicFactor& L, FactorValues<Complex>& x, const std::vector<int>& outer, const std::vector<int>& inner,
                      const std::vector<double>& values) {
  return factorize_own<Complex>(L, x, outer, inner, reinterpret_cast<const Complex*>(values.data()));
}

Eigen::MatrixXd trailing_block(const Supernodes& L, const std::vector<int>& place, int m) {
  Eigen::MatrixXd block = Eigen::MatrixXd::Zero(m, m);
  for (int s = 0; s < L.count; ++s) {
    const auto Ls = L.values(s);
    for (int c = 0; c < L.cols(s); ++c) {
      const int a = place[L.first(s) + c];
      if (a < 0) continue;
      for (int r = c; r < L.height(s); ++r) {
        const int b = place[L.row(s, r)];
        if (b < 0) throw Error("internal error: a factor row below the trailing block's columns is outside it");
        block(b, a) = Ls(r, c);
      }
    }
  }
  return block;
}

bool invert_lower_triangular(Eigen::MatrixXd& R) {
  if (R.rows() != R.cols()) throw Error("invert_lower_triangular: the matrix is not square");
  const int n = static_cast<int>(R.rows());
  if (n == 0) return true;
  int info = 0;
  dtrtri_("L", "N", &n, R.data(), &n, &info);
  return info == 0;
}

}  // namespace trivcon::linalg
