#!/usr/bin/env bash
# Builds everything and runs all tests (GoogleTest through CTest). Tests on the real meshes in
# ../shared/data/meshes run when that folder exists and are skipped with a message otherwise.
#   scripts/test.sh             Release build in build/, all tests
#   scripts/test.sh --sanitize  the same under AddressSanitizer + UndefinedBehaviorSanitizer, in build-asan/
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "${1:-}" = "--sanitize" ]; then
  export BUILD_DIR=build-asan
  bash scripts/build.sh -DTRIVCON_SANITIZE=ON -DTRIVCON_BUILD_BENCH=OFF
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
else
  export BUILD_DIR=build
  bash scripts/build.sh
fi
cd "$BUILD_DIR"
ctest --output-on-failure -j"$(nproc)"
