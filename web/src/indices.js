// SPDX-License-Identifier: MIT
// Index texts and the Gauss–Bonnet readout, as trivcon/indices.h defines them: an index is n/N, written
// as a reduced fraction ("1/4", "-1/2") or an integer; on every component the vertex indices plus the
// boundary-loop indices sum to χ (a component with a loop left free balances through it).

function gcd(a, b) {
  a = Math.abs(a), b = Math.abs(b);
  while (b) [a, b] = [b, a % b];
  return a;
}

export function formatIndex(n, N) {
  const g = gcd(n, N) || 1;
  const p = n / g, q = N / g;
  return q === 1 ? String(p) : `${p}/${q}`;
}

// Units of 1/N, or null when the text is not a number p or p/q (q > 0) or not a multiple of 1/N.
export function parseIndex(text, N) {
  const m = /^\s*([+-]?\d+)(?:\s*\/\s*(\d+))?\s*$/.exec(text);
  if (!m) return null;
  const p = parseInt(m[1], 10), q = m[2] === undefined ? 1 : parseInt(m[2], 10);
  if (!(q > 0) || Math.abs(p) > 1e6 || q > 1e6) return null;
  const n = (p * N) / q;
  return Number.isInteger(n) ? n : null;
}

// Per component: {component, chi, sum, missing, free}; sum and missing in units of 1/N.
export function componentBalance(info, vertexComponent, session) {
  const rows = info.components.map((c) => ({
    component: c.id, chi: c.euler_characteristic, sum: 0, loops: c.boundary_loops.length, prescribedLoops: 0,
  }));
  for (const [v, n] of session.sings) {
    const c = vertexComponent[v];
    if (c >= 0 && rows[c]) rows[c].sum += n;
  }
  for (const [l, n] of session.loops) {
    const loop = info.cycles.loops[l];
    if (!loop) continue;
    rows[loop.component].sum += n;
    rows[loop.component].prescribedLoops++;
  }
  return rows.map((r) => ({
    component: r.component, chi: r.chi, sum: r.sum, free: r.loops > 0 && r.prescribedLoops < r.loops,
    missing: session.N * r.chi - r.sum,
  }));
}
