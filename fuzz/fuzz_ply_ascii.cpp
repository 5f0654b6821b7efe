// SPDX-License-Identifier: MIT
// fuzz/fuzz_ply_ascii.cpp: the PLY reader (trivcon/io.h read_ply) on any bytes, from ASCII PLY seeds
// (fuzz_ply_binary.cpp runs the same reader from binary seeds).
#include "fuzz_target.h"

TRIVCON_FUZZ_TARGET(ply_ascii) { trivcon::fuzz::check_mesh(trivcon::read_ply(bytes, "fuzz.ply")); }
