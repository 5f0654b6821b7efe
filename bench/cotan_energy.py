# SPDX-License-Identifier: MIT
"""The energy Σ x_e² / w_e of a connection in the mesh's own clamped cotangent weights
w_e = ½ (max(cot α, 0) + max(cot β, 0)), computed here from the positions (independently of trivcon's
geometry), for comparing fields solved with other weights (BENCHMARKS.md "Weights that spread turning").

    /usr/bin/python3 bench/cotan_energy.py MESH CONNECTION        (CONNECTION: solve --connection-out)

Prints the energy over the edges of positive weight and how many edges of weight 0 carry a turn.
Reads the mesh with the trivcon module (installed as docs/tutorials/python.md says).
"""
import sys

import numpy as np
import trivcon

V, F = trivcon.read_mesh(sys.argv[1])[:2]
V, F = np.asarray(V, float), np.asarray(F, int)
w = {}
for f in F:
    for k in range(3):
        i, j, o = f[k], f[(k + 1) % 3], f[(k + 2) % 3]
        a, b = V[i] - V[o], V[j] - V[o]
        cot = np.dot(a, b) / np.linalg.norm(np.cross(a, b))
        key = (min(i, j), max(i, j))
        w[key] = w.get(key, 0.0) + 0.5 * max(cot, 0.0)
energy, turning_on_zero = 0.0, 0
for line in open(sys.argv[2]):
    if line.startswith('#') or not line.strip():
        continue
    i, j, x = line.split()
    we, x = w[(int(i), int(j))], float(x)
    if we > 0:
        energy += x * x / we
    elif abs(x) > 1e-12:
        turning_on_zero += 1
print('%.6g' % energy, 'edges of weight 0 that turn:', turning_on_zero)
