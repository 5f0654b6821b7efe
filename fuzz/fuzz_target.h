// SPDX-License-Identifier: MIT
// fuzz/fuzz_target.h: what the fuzz targets (fuzz/fuzz_*.cpp, one per reader a user can reach) share.
//
// Each target is written once, as
//   TRIVCON_FUZZ_TARGET(obj) { ... read `bytes` ... }
// and compiled two ways:
// - with TRIVCON_LIBFUZZER (fuzz/CMakeLists.txt, clang -fsanitize=fuzzer): the body becomes
//   LLVMFuzzerTestOneInput. A trivcon::Error is the expected outcome of bad input and is swallowed; any
//   other exception (std::bad_alloc, std::out_of_range, ...) escapes and libFuzzer reports it as a crash,
//   like a sanitizer finding, a leak or a timeout.
// - without it (tests/test_fuzz_regressions.cpp, the normal g++ build): the body is registered by name,
//   and the test replays the seed corpus (fuzz/corpus/<name>/) and every input a fuzzer ever found a bug
//   with (tests/fuzz_regressions/<name>/): each must read or throw trivcon::Error, nothing else.
// TRIVCON_FUZZ_CHECK states what a successful read guarantees; a broken one is a bug (an abort under
// libFuzzer, a std::logic_error in the replay).
#pragma once
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>

#include "trivcon/cycles.h"
#include "trivcon/error.h"
#include "trivcon/geometry.h"
#include "trivcon/io.h"
#include "trivcon/topology.h"

namespace trivcon::fuzz {

using Target = void (*)(const std::string& bytes);

// Every target of the replay build, by name (empty under libFuzzer, where a program holds one target).
std::map<std::string, Target>& targets();
bool register_target(const char* name, Target target);

[[noreturn]] void invariant_failed(const char* condition, const char* file, int line);

// The mesh that singularity, fixed-direction and field files are read against (built once, in code): a
// torus of 4 × 3 quads (vertices 0-11, faces 0-23, 2 generators) and an annulus of 4 × 1 quads (vertices
// 12-19, all on its 2 boundary loops; faces 24-31), 20 vertices and 32 faces in all. Its OBJ is
// fuzz/corpus/obj/fixed_mesh.obj.
struct FixedMesh {
  Mesh mesh;
  Topology topology;
  Geometry geometry;
  Cycles cycles;
};
const FixedMesh& fixed_mesh();

// What every mesh reader guarantees when it returns: ids in range, one source polygon per triangle in
// file order, finite coordinates.
void check_mesh(const MeshData& mesh);

}  // namespace trivcon::fuzz

#define TRIVCON_FUZZ_CHECK(condition) \
  ((condition) ? static_cast<void>(0) : ::trivcon::fuzz::invariant_failed(#condition, __FILE__, __LINE__))

#ifdef TRIVCON_LIBFUZZER
#define TRIVCON_FUZZ_TARGET(name)                                                     \
  static void trivcon_fuzz_target(const std::string& bytes);                          \
  extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) { \
    try {                                                                             \
      trivcon_fuzz_target(std::string(reinterpret_cast<const char*>(data), size));    \
    } catch (const ::trivcon::Error&) {                                               \
    }                                                                                 \
    return 0;                                                                         \
  }                                                                                   \
  static void trivcon_fuzz_target(const std::string& bytes)
#else
#define TRIVCON_FUZZ_TARGET(name)                                                                                            \
  static void trivcon_fuzz_target(const std::string& bytes);                                                                 \
  [[maybe_unused]] static const bool trivcon_fuzz_registered = ::trivcon::fuzz::register_target(#name, trivcon_fuzz_target); \
  static void trivcon_fuzz_target(const std::string& bytes)
#endif
