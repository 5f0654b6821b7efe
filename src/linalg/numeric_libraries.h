// SPDX-License-Identifier: MIT
// src/linalg/numeric_libraries.h (internal): the run-time check of the numeric libraries.
//
// The hand-written numeric factorization and substitutions (src/linalg/supernodal.h, src/linalg/substitution.h)
// call Fortran BLAS and LAPACK with 32-bit integers. check_numeric_libraries() verifies that the BLAS loaded
// takes them (LP64, as Debian's OpenBLAS), and, in a build with SuiteSparse (TRIVCON_WITH_SUITESPARSE), that the
// CHOLMOD loaded is the one compiled against (src/linalg/cholmod.h), throwing trivcon::Error otherwise.
#pragma once

namespace trivcon::linalg {

// See the top of this file. Cheap after the first call (the result is remembered).
void check_numeric_libraries();

}  // namespace trivcon::linalg
