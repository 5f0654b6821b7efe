// SPDX-License-Identifier: MIT
// fuzz/fuzz_gltf.cpp: the glTF reader (trivcon/io.h read_gltf), .gltf JSON and .glb, on any bytes.
#include "fuzz_target.h"

TRIVCON_FUZZ_TARGET(gltf) { trivcon::fuzz::check_mesh(trivcon::read_gltf(bytes, "fuzz.gltf")); }
