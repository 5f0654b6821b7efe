#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds everything and runs all tests: the C++ suite (GoogleTest through CTest), then the Python module,
# installed the Python tutorial's way (docs/tutorials/python.md) into build/venv, and its pytest suite
# (scripts/python.sh --test), then the editor's browser tests (scripts/web.sh --test: `trivcon edit` driven in headless Chromium), then builds the documentation
# site with warnings as errors (scripts/docs.sh; its examples run in the pytest suite). Tests on the real
# meshes in ../shared/data/meshes run when that folder exists and are skipped with a message otherwise.
#   scripts/test.sh             Release build in build/, all tests
#   scripts/test.sh --sanitize  the C++ tests under AddressSanitizer + UndefinedBehaviorSanitizer, in build-asan/
#                               (not the Python suite: an ASan library cannot be loaded into python3)
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
(cd "$BUILD_DIR" && ctest --output-on-failure -j"$(nproc)")
if [ "$BUILD_DIR" = build ]; then
  bash scripts/python.sh --test
else
  echo "== python: the pytest suite runs without --sanitize only"
fi
if [ "$BUILD_DIR" = build ]; then
  bash scripts/web.sh --test
else
  echo "== web: the browser tests run without --sanitize only"
fi
if [ "$BUILD_DIR" = build ]; then
  bash scripts/docs.sh
else
  echo "== docs: the documentation site is built without --sanitize only"
fi
