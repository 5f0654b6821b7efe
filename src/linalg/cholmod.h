// SPDX-License-Identifier: MIT
// src/linalg/cholmod.h (internal): the one adaptor between trivcon and CHOLMOD / SuiteSparseQR, in a build with
// TRIVCON_WITH_SUITESPARSE only (CHOLMOD's Debian build contains GPL modules, SuiteSparseQR is GPL: the default
// build links neither; docs/solver.md).
//
// - CholmodContext: a CHOLMOD workspace (cholmod_common) for the int API, started and finished with the
//   object, set up for a supernodal LLᵀ factorization (the Cholesky route); CholmodLongContext the same
//   for the SuiteSparse_long API that SuiteSparseQR uses.
// - Views: cholmod_sparse / cholmod_dense headers over memory the caller owns (no copy; CHOLMOD only
//   reads them). An upper-triangle view (stype = 1) of compressed columns with int indices, and a general
//   view (stype = 0) of an Eigen column-major sparse matrix with int or SuiteSparse_long indices.
// - The library check: the hand-written numeric factorization (src/linalg/supernodal.h) can write into
//   CHOLMOD's supernodal factor object with int indices. The build refuses a CHOLMOD whose major version
//   differs from the one that layout was written against; check_numeric_libraries()
//   (src/linalg/numeric_libraries.h) verifies at run time that the CHOLMOD loaded is the one compiled against.
#pragma once
#include <cholmod.h>

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <string>
#include <vector>

#include "linalg/numeric_libraries.h"

#ifndef TRIVCON_WITH_SUITESPARSE
#error "src/linalg/cholmod.h is for a build with TRIVCON_WITH_SUITESPARSE only"
#endif

// CHOLMOD 3 (SuiteSparse 5, Debian 12) is what src/linalg/supernodal.cpp's use of the factor object (super, pi, px,
// s, x as int / double arrays, cholmod_change_factor to allocate values) was written and tested against.
static_assert(CHOLMOD_MAIN_VERSION == 3, "trivcon's numeric factorization was written for CHOLMOD 3 (SuiteSparse 5)");

namespace trivcon::linalg {

// Throws trivcon::Error naming `what` and CHOLMOD's status unless `ok`.
void require(bool ok, const std::string& what, const cholmod_common& c);

class CholmodContext {
 public:
  CholmodContext();  // cholmod_start, then supernodal LLᵀ, no printing
  ~CholmodContext();
  CholmodContext(const CholmodContext&) = delete;
  CholmodContext& operator=(const CholmodContext&) = delete;
  cholmod_common& operator*() { return c_; }
  cholmod_common* get() { return &c_; }
  const cholmod_common& common() const { return c_; }

 private:
  cholmod_common c_;
};

class CholmodLongContext {
 public:
  CholmodLongContext();  // cholmod_l_start, no printing
  ~CholmodLongContext();
  CholmodLongContext(const CholmodLongContext&) = delete;
  CholmodLongContext& operator=(const CholmodLongContext&) = delete;
  cholmod_common& operator*() { return c_; }
  cholmod_common* get() { return &c_; }

 private:
  cholmod_common c_;
};

// The leading n × n block of a symmetric matrix given by its upper triangle in compressed columns (rows ≤
// column, sorted): outer has at least n + 1 entries.
cholmod_sparse upper_view(const std::vector<int>& outer, const std::vector<int>& inner, const std::vector<double>& values, int n);

// The pattern alone (CHOLMOD_PATTERN: no values), for a symbolic analysis that need not copy them.
cholmod_sparse upper_pattern_view(const std::vector<int>& outer, const std::vector<int>& inner, int n);

// The same for a complex Hermitian matrix (CHOLMOD_COMPLEX): `values` holds (real, imaginary) per entry,
// 2 × outer[n] numbers; CHOLMOD takes the lower triangle as the conjugate of the upper.
cholmod_sparse upper_view_complex(const std::vector<int>& outer, const std::vector<int>& inner, const std::vector<double>& values, int n);

// A general (unsymmetric) view of a compressed Eigen matrix.
template <class Index>
cholmod_sparse sparse_view(const Eigen::SparseMatrix<double, Eigen::ColMajor, Index>& M) {
  static_assert(sizeof(Index) == sizeof(int) || sizeof(Index) == sizeof(SuiteSparse_long), "CHOLMOD takes int or SuiteSparse_long");
  cholmod_sparse s{};
  s.nrow = static_cast<size_t>(M.rows()), s.ncol = static_cast<size_t>(M.cols()), s.nzmax = static_cast<size_t>(M.nonZeros());
  s.p = const_cast<Index*>(M.outerIndexPtr()), s.i = const_cast<Index*>(M.innerIndexPtr()), s.x = const_cast<double*>(M.valuePtr());
  s.stype = 0, s.itype = sizeof(Index) == sizeof(int) ? CHOLMOD_INT : CHOLMOD_LONG;
  s.xtype = CHOLMOD_REAL, s.dtype = CHOLMOD_DOUBLE, s.sorted = 1, s.packed = 1;
  return s;
}

// A single dense column over b's memory.
cholmod_dense dense_view(const Eigen::VectorXd& b);
// A single dense complex column over b's memory: (real, imaginary) per row, b.size() / 2 rows.
cholmod_dense dense_view_complex(const Eigen::VectorXd& b);

}  // namespace trivcon::linalg
