#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Relaxation against a plain solve (issue 33's benchmark rows in BENCHMARKS.md, "Relaxation"): 20 singularities at
# random vertices (14 of +1/4, 6 of -1/4: the sum 2 of a sphere; fixed seeds) on a scan of about 100k faces
# (armadillo, from ../shared) and on its midpoint subdivision (4x the faces); `solve -s S --relax` and `solve -s S`
# timed as whole commands, interleaved (farm-bench), then one run of each that prints the relaxation's own line.
#   bench/relax_bench.sh [BUILD_DIR] [RUNS]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${1:-build}
RUNS=${2:-5}
MESHES=${MESHES:-../shared/data/meshes}
[ -f "$MESHES/armadillo.obj" ] || { echo "relax_bench: $MESHES/armadillo.obj not found (../shared)" >&2; exit 1; }
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
/usr/bin/python3 - "$MESHES/armadillo.obj" "$WORK" <<'PY'
import random, sys
import numpy as np
src, out = sys.argv[1], sys.argv[2]
V, F = [], []
for line in open(src):
    if line.startswith("v "):
        V.append([float(x) for x in line.split()[1:4]])
    elif line.startswith("f "):
        F.append([int(x.split("/")[0]) - 1 for x in line.split()[1:4]])
V, F = np.array(V), np.array(F, dtype=np.int64)

def subdivide(V, F):
    """Midpoint subdivision: every triangle into four, each edge's midpoint shared."""
    edges = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    unique, inverse = np.unique(edges, axis=0, return_inverse=True)
    mid = len(V) + inverse.reshape(3, -1).T  # midpoints of edges (0 1), (1 2), (2 0) per face
    V2 = np.vstack([V, 0.5 * (V[unique[:, 0]] + V[unique[:, 1]])])
    a, b, c = F.T
    ab, bc, ca = mid.T
    F2 = np.vstack([np.stack([a, ab, ca], 1), np.stack([ab, b, bc], 1), np.stack([ca, bc, c], 1), np.stack([ab, bc, ca], 1)])
    return V2, F2

for name, (v, f) in (("armadillo", (V, F)), ("armadillo-x4", subdivide(V, F))):
    with open(f"{out}/{name}.obj", "w") as o:
        o.write("".join(f"v {x:.9g} {y:.9g} {z:.9g}\n" for x, y, z in v))
        o.write("".join(f"f {i + 1} {j + 1} {k + 1}\n" for i, j, k in f))
    rng = random.Random(33)
    with open(f"{out}/{name}.sing", "w") as o:
        for i, vertex in enumerate(rng.sample(range(len(V)), 20)):  # input vertices: on both meshes
            o.write(f"{vertex} {'1/4' if i < 14 else '-1/4'}\n")
    print(f"{name}: {len(v)} vertices, {len(f)} faces")
PY
T=$BUILD_DIR/trivcon
for name in armadillo armadillo-x4; do
  echo "== $name: solve --relax (A) against solve (B)"
  farm-bench -n "$RUNS" --timeout 900 --vs "$T solve $WORK/$name.obj -N 4 -s $WORK/$name.sing -q" -- \
    "$T" solve "$WORK/$name.obj" -N 4 -s "$WORK/$name.sing" --relax -q
  "$T" solve "$WORK/$name.obj" -N 4 -s "$WORK/$name.sing" --relax | grep -E "^relax:|^time:"
done
