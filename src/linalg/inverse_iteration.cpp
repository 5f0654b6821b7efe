// SPDX-License-Identifier: MIT
#include "linalg/inverse_iteration.h"

#include <cmath>
#include <complex>

#include "trivcon/cancel.h"
#include "trivcon/error.h"

namespace trivcon::linalg {

namespace {

double squared(double v) { return v * v; }
double squared(const std::complex<double>& v) { return std::norm(v); }

template <class T>
T load(const std::vector<double>& x, int j) {
  if constexpr (std::is_same_v<T, double>) {
    return x[j];
  } else {
    return T(x[2 * j], x[2 * j + 1]);
  }
}

template <class T>
void store(std::vector<double>& x, int j, const T& v) {
  if constexpr (std::is_same_v<T, double>) {
    x[j] = v;
  } else {
    x[2 * j] = v.real(), x[2 * j + 1] = v.imag();
  }
}

}  // namespace

template <class T>
void inverse_iteration(const Substitution<T>& factor, const InverseIterationProblem& p, std::vector<double>& x) {
  const int n = factor.size();
  const int groups = static_cast<int>(p.normalised.size());
  // In the factor's order (no permutation per solve; mass, group and affine values permuted once). The scale of
  // each iteration is applied with the next mass product (and at the end) instead of a pass of its own.
  const std::vector<int>& perm = factor.permutation();
  std::vector<T> xf(n), bf(n), df(n);
  std::vector<double> mf(n), scale(groups, 1.0), norm(groups);
  std::vector<int> gf(n);
  for (int q = 0; q < n; ++q) {
    const int j = perm[q], group = p.group[j];
    xf[q] = load<T>(x, j), df[q] = p.affine.empty() ? T(0) : load<T>(p.affine, j);
    gf[q] = group, mf[q] = p.normalised[group] ? p.mass[j] : 0.0;
  }
  for (int it = 0; it < std::max(1, p.iterations); ++it) {
    check_cancelled();
    for (int q = 0; q < n; ++q) bf[q] = (mf[q] * scale[gf[q]]) * xf[q] + df[q];
    factor.solve_in_factor_order(bf.data());
    xf.swap(bf);
    std::fill(norm.begin(), norm.end(), 0.0);
    for (int q = 0; q < n; ++q) norm[gf[q]] += mf[q] * squared(xf[q]);
    for (int group = 0; group < groups; ++group) {
      if (!p.normalised[group]) continue;
      if (!(norm[group] > 0) || !std::isfinite(norm[group]))
        throw Error(p.what + ": the inverse iteration lost the field on component " + std::to_string(group) + " (norm " +
                    std::to_string(norm[group]) + ")");
      scale[group] = 1 / std::sqrt(norm[group]);
    }
  }
  for (int q = 0; q < n; ++q) store<T>(x, perm[q], xf[q] * scale[gf[q]]);
}

template void inverse_iteration<double>(const Substitution<double>&, const InverseIterationProblem&, std::vector<double>&);
template void inverse_iteration<std::complex<double>>(const Substitution<std::complex<double>>&, const InverseIterationProblem&,
                                                      std::vector<double>&);

}  // namespace trivcon::linalg
