// The CHOLMOD adaptor (src/linalg/cholmod.h): workspaces, views, and the check of the numeric libraries.
#include "linalg/cholmod.h"

#include <cstdint>
#include <cstring>
#include <mutex>

#include "trivcon/error.h"

// Fortran BLAS, as CHOLMOD and src/linalg/supernodal.cpp call it: 32-bit integers (LP64) assumed, checked below.
extern "C" int idamax_(const int* n, const double* x, const int* incx);

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

namespace {

std::string library_problem() {
  int version[3] = {0, 0, 0};
  cholmod_version(version);
  if (version[0] != CHOLMOD_MAIN_VERSION || version[1] != CHOLMOD_SUB_VERSION)
    return "the CHOLMOD library loaded is version " + std::to_string(version[0]) + "." + std::to_string(version[1]) + "." +
           std::to_string(version[2]) + ", but trivcon was built against " + std::to_string(CHOLMOD_MAIN_VERSION) + "." +
           std::to_string(CHOLMOD_SUB_VERSION) + "." + std::to_string(CHOLMOD_SUBSUB_VERSION) + "; rebuild trivcon";
  // The BLAS integer width: n is passed as 8 bytes whose first 4 (little-endian: the low half) say 2 and
  // whose high half is all ones. A BLAS with 32-bit integers reads n = 2 and finds the largest of {1, 5}
  // at 2; one with 64-bit integers reads a negative n and returns 0.
  const std::uint16_t probe = 1;
  unsigned char first = 0;
  std::memcpy(&first, &probe, 1);
  if (first == 1) {
    const std::int64_t n = static_cast<std::int64_t>(0xFFFFFFFF00000002ULL), incx = 1;
    const double x[2] = {1.0, 5.0};
    const int found = idamax_(reinterpret_cast<const int*>(&n), x, reinterpret_cast<const int*>(&incx));
    if (found != 2)
      return "the BLAS library loaded does not take 32-bit integers (idamax gave " + std::to_string(found) +
             "); trivcon and CHOLMOD need an LP64 BLAS such as Debian's OpenBLAS";
  }
  return "";
}

}  // namespace

void check_numeric_libraries() {
  static std::once_flag once;
  static std::string problem;
  std::call_once(once, [] { problem = library_problem(); });
  if (!problem.empty()) throw Error(problem);
}

}  // namespace trivcon::linalg
