#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs the Python module the Python tutorial's way (docs/tutorials/python.md) into a virtual environment, build/venv (or $VENV), made from
# Debian's /usr/bin/python3 with --system-site-packages (numpy, pybind11, pytest and Dask from Debian), after
# installing those packages. Works offline: pip builds with --no-build-isolation.
#   scripts/python.sh          install (a C++ build folder $BUILD_DIR, default build, is reused when it exists:
#                              only the module is compiled into it)
#   scripts/python.sh --test   install, then run the pytest suite python/tests in that environment
# Prints how long each part took. Used by scripts/test.sh and scripts/demo.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh --python
BUILD_DIR=${BUILD_DIR:-build}
VENV=${VENV:-$BUILD_DIR/venv}
start=$(date +%s)
[ -x "$VENV/bin/python" ] || /usr/bin/python3 -m venv --system-site-packages "$VENV"
# The tutorial's install command; TRIVCON_CMAKE_BUILD_DIR lets setup.py reuse the C++ build folder.
if [ -f "$BUILD_DIR/CMakeCache.txt" ]; then export TRIVCON_CMAKE_BUILD_DIR=$BUILD_DIR; fi
"$VENV/bin/pip" install --no-build-isolation --no-cache-dir --quiet .
installed=$(date +%s)
echo "== python: trivcon $("$VENV/bin/python" -c 'import trivcon; print(trivcon.__version__)') installed into $VENV in $((installed - start)) s"
if [ "${1:-}" = "--test" ]; then
  # The suite compares with the program built beside it (skipped without one) and runs Dask on 2 local workers.
  export TRIVCON_CLI=${TRIVCON_CLI:-$PWD/$BUILD_DIR/trivcon}
  "$VENV/bin/python" -m pytest python/tests -q -p no:cacheprovider
  echo "== python: pytest suite in $(($(date +%s) - installed)) s"
fi
