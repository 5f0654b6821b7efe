# SPDX-License-Identifier: MIT
# A flat grid of m x m squares with a fin on every interior edge: about 3m^2 edges with three faces, for
# timing repair (BENCHMARKS.md "Repair"). Usage: python3 bench/make_fins.py 183 fins.obj
import sys
m = int(sys.argv[1]); out = sys.argv[2]
V = []; F = []
idx = lambda i, j: i * (m + 1) + j
for i in range(m + 1):
    for j in range(m + 1): V.append((i, j, 0))
for i in range(m):
    for j in range(m):
        a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
        F += [(a, b, c), (a, c, d)]
from collections import Counter
cnt = Counter()
for f in F:
    for k in range(3): cnt[(min(f[k], f[(k+1)%3]), max(f[k], f[(k+1)%3]))] += 1
fins = 0
for (a, b), n in sorted(cnt.items()):
    if n == 2:
        pa, pb = V[a], V[b]
        V.append(((pa[0] + pb[0]) / 2, (pa[1] + pb[1]) / 2, 0.7)); F.append((a, b, len(V) - 1)); fins += 1
with open(out, "w") as f:
    f.write("".join("v %g %g %g\n" % v for v in V)); f.write("".join("f %d %d %d\n" % (a + 1, b + 1, c + 1) for a, b, c in F))
print(fins, "fins,", len(F), "faces", file=sys.stderr)
