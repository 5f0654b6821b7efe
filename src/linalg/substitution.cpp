// SPDX-License-Identifier: MIT
#include "linalg/substitution.h"

#include <algorithm>
#include <exception>
#include <type_traits>

#include "linalg/parallel.h"
#include "trivcon/error.h"

namespace trivcon::linalg {

template <class T>
Substitution<T>::Substitution(const SymbolicFactor& L, const FactorValues<T>& values) : S_(L, nullptr), values_(&values) {
  if (values.size() != L.xsize || static_cast<int>(L.perm.size()) != L.n)
    throw Error("internal: the parallel substitution needs a numeric supernodal LL' factor of the right type");
  n_ = L.n;
  perm_ = L.perm;
  plan();
}

#ifdef TRIVCON_WITH_SUITESPARSE
template <class T>
Substitution<T>::Substitution(const cholmod_factor& L) : S_(&L), cholmod_(&L) {
  const int xtype = std::is_same<T, double>::value ? CHOLMOD_REAL : CHOLMOD_COMPLEX;
  if (!L.is_super || !L.is_ll || L.xtype != xtype || L.x == nullptr || L.itype != CHOLMOD_INT)
    throw Error("internal: the parallel substitution needs a numeric supernodal LL' factor of the right type");
  n_ = static_cast<int>(L.n);
  const int* perm = static_cast<const int*>(L.Perm);
  perm_.assign(perm, perm + n_);
  plan();
}
#endif

template <class T>
const T* Substitution<T>::values() const {
#ifdef TRIVCON_WITH_SUITESPARSE
  if (cholmod_) return static_cast<const T*>(cholmod_->x);
#endif
  return values_->data();
}

template <class T>
void Substitution<T>::plan() {
  const Supernodes& S = S_;
  owner_ = S.owners();
  parent_ = supernode_parents(S, owner_);
  stamp_.assign(S.count, -1);
  // Balanced by the entries each supernode holds: a solve reads each once.
  std::vector<double> entries(S.count);
  for (int s = 0; s < S.count; ++s) entries[s] = static_cast<double>(S.height(s)) * S.cols(s);
  TreeSplit split = split_tree(parent_, entries, 1e4, linalg::max_threads(), true);
  top_ = std::move(split.top), part_ = std::move(split.part);
  top_slot_.assign(n_, -1);
  for (int s : top_)
    for (int k = S.first(s); k < S.first(s) + S.cols(s); ++k) top_slot_[k] = top_columns_++;
  work_.resize(n_);
  send_.resize(part_.size());
}

namespace {

// The two products a substitution needs, written out for complex numbers: std::complex's operator* checks
// for infinities and NaNs through a library call (__muldc3) unless -ffast-math, which costs more than the
// memory traffic here. For real T they are the plain product.
inline double times(double a, double b) { return a * b; }
inline std::complex<double> times(std::complex<double> a, std::complex<double> b) {
  return {a.real() * b.real() - a.imag() * b.imag(), a.real() * b.imag() + a.imag() * b.real()};
}
inline double conj_times(double a, double b) { return a * b; }
inline std::complex<double> conj_times(std::complex<double> a, std::complex<double> b) {  // conj(a) b
  return {a.real() * b.real() + a.imag() * b.imag(), a.real() * b.imag() - a.imag() * b.real()};
}

// Σ_i conj(a_i) b_i over n entries, from the last down, vectorised (OpenMP simd: partial sums in a fixed
// order, so the result depends on the data and the build only; a single running sum would wait on each
// addition).
double conj_dot_down(const double* a, const double* b, int n) {
  double s = 0;
#pragma omp simd reduction(+ : s)
  for (int i = n - 1; i >= 0; --i) s += a[i] * b[i];
  return s;
}
std::complex<double> conj_dot_down(const std::complex<double>* a, const std::complex<double>* b, int n) {
  const double* x = reinterpret_cast<const double*>(a);
  const double* y = reinterpret_cast<const double*>(b);
  double re = 0, im = 0;
#pragma omp simd reduction(+ : re, im)
  for (int i = n - 1; i >= 0; --i) {
    const double xr = x[2 * i], xi = x[2 * i + 1], yr = y[2 * i], yi = y[2 * i + 1];
    re += xr * yr + xi * yi, im += xr * yi - xi * yr;
  }
  return {re, im};
}

}  // namespace

template <class T>
void Substitution<T>::solve(T* x) const {
  if (n_ == 0) return;
  for (int k = 0; k < n_; ++k) work_[k] = x[perm_[k]];
  solve_in_factor_order(work_.data());
  for (int k = 0; k < n_; ++k) x[perm_[k]] = work_[k];
}

template <class T>
void Substitution<T>::solve_in_factor_order(T* z) const {
  forward_in_factor_order(z);
  backward_in_factor_order(z);
}

template <class T>
void Substitution<T>::forward_in_factor_order(T* z) const {
  if (n_ == 0) return;
  const Supernodes& S = S_;
  const T* values = this->values();

  // Forward: L y = z. Supernode s solves its own columns (its diagonal block is lower triangular with a
  // real positive diagonal), accumulating L_below · y_s in `sent`, then sends it to its rows below; what
  // goes to the top's columns from below the split goes to `to_top` (null: into z directly).
  auto forward = [&](int s, std::vector<T>& sent, T* to_top) {
    const int ncol = S.cols(s), nrow = S.height(s), below = nrow - ncol;
    const T* panel = values + S.px[s];
    T* y = z + S.first(s);
    sent.assign(below, T(0));
    T* out = sent.data();
    for (int c = 0; c < ncol; ++c) {
      const T* column = panel + static_cast<size_t>(c) * nrow;
      const T v = y[c] * (1 / std::real(column[c]));
      y[c] = v;
      for (int i = c + 1; i < ncol; ++i) y[i] -= times(column[i], v);
      const T* lower = column + ncol;
      for (int i = 0; i < below; ++i) out[i] += times(lower[i], v);
    }
    const int* rows = S.rows + S.pi[s] + ncol;
    for (int i = 0; i < below; ++i) {
      const int r = rows[i], slot = top_slot_[r];
      if (to_top && slot >= 0)
        to_top[slot] += out[i];
      else
        z[r] -= out[i];
    }
  };
  const int parts = static_cast<int>(part_.size());
  const bool several = parts > 1 && !part_[1].empty();
  std::vector<std::exception_ptr> error(parts);
#pragma omp parallel for schedule(static, 1) num_threads(parts) if (several)
  for (int k = 0; k < parts; ++k) {
    try {
      std::vector<T> sent;
      send_[k].assign(top_columns_, T(0));
      for (int s : part_[k]) forward(s, sent, send_[k].data());
    } catch (...) {  // an exception must not leave an OpenMP region
      error[k] = std::current_exception();
    }
  }
  for (const auto& e : error)
    if (e) std::rethrow_exception(e);
  for (int k = 0; k < parts; ++k)  // in a fixed order
    for (int s : top_)
      for (int c = S.first(s); c < S.first(s) + S.cols(s); ++c) z[c] -= send_[k][top_slot_[c]];
  std::vector<T> scratch;
  for (int s : top_) forward(s, scratch, nullptr);
}

template <class T>
void Substitution<T>::backward_in_factor_order(T* z) const {
  if (n_ == 0) return;
  const Supernodes& S = S_;
  const T* values = this->values();
  // Backward: Lᴴ z = y. Supernode s gathers its rows below (its ancestors', done) after a copy of its own
  // entries (v: its rows, in its row order), then solves its columns last to first, each column read from
  // its last row up: the supernodes come in decreasing order, so the whole pass reads the factor as one
  // descending stream, which the processor prefetches (read in ascending order per supernode, the pass
  // took much longer than the forward one).
  auto backward = [&](int s, std::vector<T>& v) {
    const int ncol = S.cols(s), nrow = S.height(s);
    const T* panel = values + S.px[s];
    T* y = z + S.first(s);
    const int* rows = S.rows + S.pi[s];
    v.resize(nrow);
    std::copy(y, y + ncol, v.begin());
    for (int i = ncol; i < nrow; ++i) v[i] = z[rows[i]];
    for (int c = ncol - 1; c >= 0; --c) {
      const T* column = panel + static_cast<size_t>(c) * nrow;
      v[c] = (v[c] - conj_dot_down(column + c + 1, v.data() + c + 1, nrow - c - 1)) * (1 / std::real(column[c]));
    }
    std::copy(v.begin(), v.begin() + ncol, y);
  };

  const int parts = static_cast<int>(part_.size());
  const bool several = parts > 1 && !part_[1].empty();
  std::vector<T> scratch;
  for (auto s = top_.rbegin(); s != top_.rend(); ++s) backward(*s, scratch);
  std::vector<std::exception_ptr> error(parts);
#pragma omp parallel for schedule(static, 1) num_threads(parts) if (several)
  for (int k = 0; k < parts; ++k) {
    try {
      std::vector<T> gathered;
      for (auto s = part_[k].rbegin(); s != part_[k].rend(); ++s) backward(*s, gathered);
    } catch (...) {  // an exception must not leave an OpenMP region
      error[k] = std::current_exception();
    }
  }
  for (const auto& e : error)
    if (e) std::rethrow_exception(e);
}

template <class T>
void Substitution<T>::forward_update(const std::vector<std::pair<int, T>>& entries, T* z) const {
  if (n_ == 0 || entries.empty()) return;
  const Supernodes& S = S_;
  const T* values = this->values();
  ++calls_;
  std::vector<int> path;
  for (const auto& [k, value] : entries)
    for (int s = owner_[k]; s != -1 && stamp_[s] != calls_; s = parent_[s]) stamp_[s] = calls_, path.push_back(s);
  std::sort(path.begin(), path.end());
  std::vector<T>& d = update_;
  if (static_cast<int>(d.size()) != n_) d.assign(n_, T(0));
  for (const auto& [k, value] : entries) d[k] += value;
  for (int s : path) {  // as the full forward pass, the rows below sent at once
    const int ncol = S.cols(s), nrow = S.height(s);
    const T* panel = values + S.px[s];
    T* y = d.data() + S.first(s);
    const int* rows = S.rows + S.pi[s];
    for (int c = 0; c < ncol; ++c) {
      const T* column = panel + static_cast<size_t>(c) * nrow;
      const T v = y[c] * (1 / std::real(column[c]));
      y[c] = v;
      for (int i = c + 1; i < nrow; ++i) d[rows[i]] -= times(column[i], v);
    }
  }
  // Every entry touched lies in the columns of the path's supernodes (the rows below a supernode are columns of
  // its ancestors): added to z, then zeroed again.
  for (int s : path)
    for (int k = S.first(s); k < S.first(s) + S.cols(s); ++k) z[k] += d[k], d[k] = T(0);
}

template class Substitution<double>;
template class Substitution<std::complex<double>>;

}  // namespace trivcon::linalg
