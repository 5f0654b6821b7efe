#!/usr/bin/env bash
# Configures and builds trivcon (Release) into build/ (or $BUILD_DIR), after installing dependencies.
# Extra arguments go to CMake's configure step, e.g. -DTRIVCON_SANITIZE=ON.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh
BUILD_DIR=${BUILD_DIR:-build}
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release "$@"
cmake --build "$BUILD_DIR" -j"$(nproc)"
