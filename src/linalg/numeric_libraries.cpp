// SPDX-License-Identifier: MIT
// The check of the numeric libraries (src/linalg/numeric_libraries.h), beside src/linalg/blas.cpp.
#include "linalg/numeric_libraries.h"

#include <cstdint>
#include <cstring>
#include <mutex>
#include <string>

#ifdef TRIVCON_WITH_SUITESPARSE
#include <cholmod.h>
#endif

#include "trivcon/error.h"

// Fortran BLAS, as src/linalg/supernodal.cpp calls it: 32-bit integers (LP64) assumed, checked below.
extern "C" int idamax_(const int* n, const double* x, const int* incx);

namespace trivcon::linalg {

namespace {

std::string library_problem() {
#ifdef TRIVCON_WITH_SUITESPARSE
  int version[3] = {0, 0, 0};
  cholmod_version(version);
  if (version[0] != CHOLMOD_MAIN_VERSION || version[1] != CHOLMOD_SUB_VERSION)
    return "the CHOLMOD library loaded is version " + std::to_string(version[0]) + "." + std::to_string(version[1]) + "." +
           std::to_string(version[2]) + ", but trivcon was built against " + std::to_string(CHOLMOD_MAIN_VERSION) + "." +
           std::to_string(CHOLMOD_SUB_VERSION) + "." + std::to_string(CHOLMOD_SUBSUB_VERSION) + "; rebuild trivcon";
#endif
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
             "); trivcon needs an LP64 BLAS such as Debian's OpenBLAS";
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
