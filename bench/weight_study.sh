#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The weight-policy study of BENCHMARKS.md "Weights that spread turning": for each mesh, the singularities
# of `--auto` and 94 random vertices (±1/4 balanced to the mesh's χ; a mesh with boundary or unused
# vertices usually gets no random set: the solve refuses it, and the line says FAILED), solved (N = 4)
# with each weight policy; prints the large-turn edges and the vertices a principal matching misreads
# (from the report), the energy in the policy's own weights and the floored edges.
#
#   bench/weight_study.sh [--trivcon PATH] MESH...        (default: build/trivcon)
#
# The energies in the mesh's own clamped cotangent weights (the second table) come from
# bench/cotan_energy.py on `--connection-out`.
set -euo pipefail
T=build/trivcon
if [ "${1:-}" = "--trivcon" ]; then T=$2; shift 2; fi
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
for M in "$@"; do
  name=$(basename "$M")
  "$T" solve "$M" -N 4 --auto --sing-out "$WORK/auto.sing" --quiet 2>/dev/null || { echo "$name: --auto failed"; continue; }
  /usr/bin/python3 - "$T" "$M" "$WORK/auto.sing" "$WORK/rand.sing" <<'PY'
import json, random, subprocess, sys
from fractions import Fraction
trivcon, mesh, auto, out = sys.argv[1:]
info = json.loads(subprocess.run([trivcon, 'info', mesh, '--json'], capture_output=True, text=True, check=True).stdout)
chi = sum(Fraction(line.split()[1]) for line in open(auto) if line.strip() and not line.startswith('#'))
k = 94
positive = (k + int(chi * 4)) // 2
random.seed(1)
with open(out, 'w') as f:
    for n, v in enumerate(random.sample(range(info['vertices']), 3 * k)[:k]):  # (the study's draw)
        f.write('%d %s\n' % (v, '1/4' if n < positive else '-1/4'))
PY
  for pres in auto rand; do
    for pol in "--weights cotan" "--weight-floor 0.05" "--weight-floor 0.2" "--weight-floor 0.3" "--weight-floor 0.5" "--weight-floor 1" "--weights unit"; do
      # shellcheck disable=SC2086
      if "$T" solve "$M" -N 4 -s "$WORK/$pres.sing" $pol --quiet --report "$WORK/r.json" 2>"$WORK/err.txt"; then
        /usr/bin/python3 - "$WORK/r.json" "$name" "$pres" "$pol" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
prescribed = {s['vertex'] for s in r['singularities']}
misread = sum(1 for c in r['large_turns']['principal_matching_singularities'] if c['vertex'] not in prescribed)
print(sys.argv[2], sys.argv[3], len(prescribed), sys.argv[4].replace('--', ''), 'large', r['indices']['large_turn_edges'],
      'misread', misread, 'energy %.6g' % r['energy'], 'floored', r['weight_policy']['floored_edges'], 'verified', r['verified'])
PY
      else echo "$name $pres $pol FAILED: $(head -c 150 "$WORK/err.txt")"; fi
    done
  done
done
