#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Configures and builds trivcon (Release) into build/ (or $BUILD_DIR), after installing dependencies, the
# editor's too (scripts/deps.sh --web: `trivcon edit` and its page are part of the program; -DTRIVCON_EDITOR=OFF
# builds without them).
# Extra arguments go to CMake's configure step, e.g. -DTRIVCON_SANITIZE=ON.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh --web
BUILD_DIR=${BUILD_DIR:-build}
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release "$@"
cmake --build "$BUILD_DIR" -j"$(nproc)"
