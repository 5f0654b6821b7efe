// SPDX-License-Identifier: MIT
// The CHOLMOD adaptor (src/linalg/cholmod.h): workspaces and views. Compiled only with TRIVCON_WITH_SUITESPARSE.
#include "linalg/cholmod.h"

#include "trivcon/error.h"

namespace trivcon::linalg {

void require(bool ok, const std::string& what, const cholmod_common& c) {
  if (!ok) throw Error(what + " (CHOLMOD status " + std::to_string(c.status) + ")");
}

CholmodContext::CholmodContext() {
  cholmod_start(&c_);
  c_.print = 0;
  c_.supernodal = CHOLMOD_SUPERNODAL;
  c_.final_ll = 1;
}
CholmodContext::~CholmodContext() { cholmod_finish(&c_); }

CholmodLongContext::CholmodLongContext() {
  cholmod_l_start(&c_);
  c_.print = 0;
}
CholmodLongContext::~CholmodLongContext() { cholmod_l_finish(&c_); }

cholmod_sparse upper_pattern_view(const std::vector<int>& outer, const std::vector<int>& inner, int n) {
  cholmod_sparse s{};
  s.nrow = s.ncol = static_cast<size_t>(n), s.nzmax = static_cast<size_t>(outer[n]);
  s.p = const_cast<int*>(outer.data()), s.i = const_cast<int*>(inner.data());
  s.stype = 1, s.itype = CHOLMOD_INT, s.xtype = CHOLMOD_PATTERN, s.dtype = CHOLMOD_DOUBLE, s.sorted = 1, s.packed = 1;
  return s;
}

cholmod_sparse upper_view(const std::vector<int>& outer, const std::vector<int>& inner, const std::vector<double>& values, int n) {
  cholmod_sparse s = upper_pattern_view(outer, inner, n);
  s.x = const_cast<double*>(values.data()), s.xtype = CHOLMOD_REAL;
  return s;
}

cholmod_sparse upper_view_complex(const std::vector<int>& outer, const std::vector<int>& inner, const std::vector<double>& values, int n) {
  cholmod_sparse s = upper_view(outer, inner, values, n);
  s.xtype = CHOLMOD_COMPLEX;
  return s;
}

cholmod_dense dense_view_complex(const Eigen::VectorXd& b) {
  cholmod_dense B = dense_view(b);
  B.nrow = B.nzmax = B.d = static_cast<size_t>(b.size() / 2);
  B.xtype = CHOLMOD_COMPLEX;
  return B;
}

cholmod_dense dense_view(const Eigen::VectorXd& b) {
  cholmod_dense B{};
  B.nrow = static_cast<size_t>(b.size()), B.ncol = 1, B.nzmax = B.nrow, B.d = B.nrow;
  B.x = const_cast<double*>(b.data());
  B.xtype = CHOLMOD_REAL, B.dtype = CHOLMOD_DOUBLE;
  return B;
}

}  // namespace trivcon::linalg
