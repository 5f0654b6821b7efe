#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs the Debian 12 packages trivcon builds and tests with (as root; uses sudo otherwise). The base set
# includes python3 (the build generates the man page and bash completion with scripts/cli_help.py), dpkg-dev
# (dpkg-shlibdeps: `cpack -G DEB` computes the package's Depends) and groff-base (the man page's test).
# Shared by scripts/demo.sh, scripts/test.sh and scripts/bench.sh.
#   scripts/deps.sh            the C++ build (library, program, tests, benchmark)
#   scripts/deps.sh --fuzz     also clang's libFuzzer and sanitizer runtimes (scripts/fuzz.sh)
#   scripts/deps.sh --python   also the Python module's: pybind11, numpy, pytest, Dask (distributed), pip, venv,
#                              setuptools and wheel, all from Debian (scripts/python.sh; no other package index)
#   scripts/deps.sh --web      also the editor's (`trivcon edit`): cpp-httplib, Chromium for the browser tests, node and
#                              npm (Debian's, unless a node is already installed), then `npm ci` in web/ (three, esbuild,
#                              puppeteer-core, at the versions of web/package-lock.json) when web/node_modules is not current
#   scripts/deps.sh --docs     also the documentation site's (scripts/docs.sh): Sphinx, furo, breathe, doxygen, myst-parser
set -euo pipefail
packages=(build-essential cmake pkg-config zlib1g-dev libeigen3-dev libsuitesparse-dev libopenblas-dev libmetis-dev
          libcli11-dev nlohmann-json3-dev libtinygltf-dev libgtest-dev libgmock-dev libbenchmark-dev libstb-dev
          python3 dpkg-dev groff-base)
web=0
for extra in "$@"; do
  case "$extra" in
    --python) packages+=(python3 python3-dev python3-venv python3-pip python3-setuptools python3-wheel python3-numpy pybind11-dev
                         python3-pybind11 python3-pytest python3-distributed) ;;
    --fuzz) packages+=(clang libclang-rt-14-dev libomp-14-dev) ;;  # libFuzzer, its sanitizer runtimes, OpenMP for clang
    --docs) packages+=(python3-sphinx furo python3-breathe doxygen python3-myst-parser) ;;
    --web) web=1
           packages+=(libcpp-httplib-dev chromium)
           command -v npm >/dev/null 2>&1 || packages+=(nodejs npm) ;;
    *) echo "deps.sh: unknown option $extra (known: --python, --fuzz, --web, --docs)" >&2; exit 2 ;;
  esac
done
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "== installing: ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
if [ "$web" = 1 ]; then
  # npm ci when node_modules is missing or older than the lock file (npm writes node_modules/.package-lock.json).
  if [ ! -f web/node_modules/.package-lock.json ] || [ web/package-lock.json -nt web/node_modules/.package-lock.json ]; then
    echo "== npm ci in web/"
    (cd web && npm ci --no-audit --no-fund --loglevel=error)
  fi
fi
