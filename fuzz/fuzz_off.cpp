// SPDX-License-Identifier: MIT
// fuzz/fuzz_off.cpp: the OFF reader (trivcon/io.h read_off) on any bytes.
#include "fuzz_target.h"

TRIVCON_FUZZ_TARGET(off) { trivcon::fuzz::check_mesh(trivcon::read_off(bytes, "fuzz.off")); }
