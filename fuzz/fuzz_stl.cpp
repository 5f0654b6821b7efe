// SPDX-License-Identifier: MIT
// fuzz/fuzz_stl.cpp: the STL reader (trivcon/io.h read_stl), ASCII and binary, on any bytes.
#include "fuzz_target.h"

TRIVCON_FUZZ_TARGET(stl) { trivcon::fuzz::check_mesh(trivcon::read_stl(bytes, "fuzz.stl")); }
