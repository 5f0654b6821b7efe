// SPDX-License-Identifier: MIT
// fuzz/fuzz_ply_binary.cpp: the PLY reader (trivcon/io.h read_ply) on any bytes, from binary PLY seeds of
// both byte orders, every scalar type, extra properties and lists (fuzz_ply_ascii.cpp: ASCII seeds).
#include "fuzz_target.h"

TRIVCON_FUZZ_TARGET(ply_binary) { trivcon::fuzz::check_mesh(trivcon::read_ply(bytes, "fuzz.ply")); }
