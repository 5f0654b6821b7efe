// SPDX-License-Identifier: MIT
// fuzz/fuzz_obj.cpp: the OBJ reader (trivcon/io.h read_obj) on any bytes.
#include "fuzz_target.h"

TRIVCON_FUZZ_TARGET(obj) { trivcon::fuzz::check_mesh(trivcon::read_obj(bytes, "fuzz.obj")); }
