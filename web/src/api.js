// SPDX-License-Identifier: MIT
// The server's API (docs/reference/editor-api.md): every call sends the token as the X-Trivcon-Token header.

// The token comes in the page's address (?token=…, as `trivcon edit` prints it). It is kept in this tab's
// sessionStorage (per origin, so no other port of this host sees it, unlike a cookie) and removed from the
// address bar and the history; a reload of the tab finds it there.
const TOKEN_KEY = 'trivcon-token';
function takeToken() {
  const url = new URL(location.href);
  const given = url.searchParams.get('token');
  let stored = '';
  try {
    stored = sessionStorage.getItem(TOKEN_KEY) || '';
    if (given) sessionStorage.setItem(TOKEN_KEY, given);
  } catch (e) {
    // storage refused (a private mode): the token lives as long as the page
  }
  if (given !== null) {
    url.searchParams.delete('token');
    history.replaceState(history.state, '', url.pathname + url.search + url.hash);
  }
  return given || stored;
}
export const token = takeToken();

function headers(extra = {}) {
  return { 'X-Trivcon-Token': token, ...extra };
}

async function fail(res) {
  let message = `HTTP ${res.status}`;
  try {
    const j = await res.json();
    if (j && j.error) message = j.error;
  } catch (e) {
    // not JSON: keep the status line
  }
  const err = new Error(message);
  err.status = res.status;
  throw err;
}

// The binary container of the server: uint32 LE length, JSON header (padded to 4 bytes), then raw arrays.
export function unpack(buffer) {
  const n = new DataView(buffer).getUint32(0, true);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 4, n)));
  return { header, offset: 4 + n };
}

export async function getMesh() {
  const res = await fetch('/api/mesh?format=binary', { headers: headers() });
  if (!res.ok) await fail(res);
  const buffer = await res.arrayBuffer();
  const { header, offset } = unpack(buffer);
  const nV = header.vertices, nF = header.faces;
  const positions = new Float32Array(buffer, offset, 3 * nV);
  const faces = new Uint32Array(buffer, offset + 12 * nV, 3 * nF);
  const component = new Int32Array(buffer, offset + 12 * nV + 12 * nF, nV);
  // The glyphs' order (server/editor_server.cpp, GlyphOrder): faces, and their first times.
  const glyphOrder = new Uint32Array(buffer, offset + 16 * nV + 12 * nF, nF);
  const glyphTimes = new Float32Array(buffer, offset + 16 * nV + 16 * nF, nF);
  return { info: header, positions, faces, component, glyphOrder, glyphTimes };
}

export async function getState() {
  const res = await fetch('/api/state', { headers: headers() });
  if (!res.ok) await fail(res);
  return res.json();
}

function post(path, body) {
  return fetch(path, { method: 'POST', headers: headers({ 'Content-Type': 'application/json' }), body: JSON.stringify(body) });
}

// Decodes face f of the octahedral encoding (format=oct16: 2 × int16 per unit vector) into out[3 * o ...].
export function decodeOct(oct, f, out, o) {
  let x = oct[2 * f] / 32767, y = oct[2 * f + 1] / 32767;
  const z = 1 - Math.abs(x) - Math.abs(y);
  if (z < 0) {
    const x0 = x;
    x = (1 - Math.abs(y)) * (x0 >= 0 ? 1 : -1);
    y = (1 - Math.abs(x0)) * (y >= 0 ? 1 : -1);
  }
  const l = Math.hypot(x, y, z);
  out[3 * o] = x / l, out[3 * o + 1] = y / l, out[3 * o + 2] = z / l;
}

// One solve: the directions of the first `count` faces of the glyph order, octahedral-encoded, the report,
// and the server's own time.
export async function solve(body, count) {
  const tSend = performance.now();
  const res = await post(`/api/solve?format=oct16&order=area&count=${count}`, body);
  if (!res.ok) await fail(res);
  const buffer = await res.arrayBuffer();
  const tReceived = performance.now();
  const { header, offset } = unpack(buffer);
  const oct = new Int16Array(buffer, offset, (buffer.byteLength - offset) / 2);
  const serverSeconds = parseFloat(res.headers.get('X-Trivcon-Server-Seconds') || '0');
  return { report: header.report, oct, count: oct.length / 2, serverSeconds, tSend, tReceived };
}

export async function autoPlace(body) {
  const res = await post('/api/auto', body);
  if (!res.ok) await fail(res);
  return res.json();
}

// Relaxation: {singularities, moves: [{from, to, index, energy, cancelled}], energy_before, energy_after, ...}.
export async function relax(body) {
  const res = await post('/api/relax', body);
  if (!res.ok) await fail(res);
  return res.json();
}

// The quad mesh of the body's field (body.target_faces quads): {report: {quad, param, warning}, V (x y z per vertex), Q (4 per quad)}.
export async function quads(body) {
  const res = await post('/api/quad', body);
  if (!res.ok) await fail(res);
  const buffer = await res.arrayBuffer();
  const { header, offset } = unpack(buffer);
  const n = header.quad.vertices, m = header.quad.quads;
  return { report: header, V: new Float32Array(buffer, offset, 3 * n), Q: new Uint32Array(buffer, offset + 12 * n, 4 * m) };
}

export async function streamlines(body) {
  const res = await post('/api/streamlines', body);
  if (!res.ok) await fail(res);
  const buffer = await res.arrayBuffer();
  const { header, offset } = unpack(buffer);
  return { counts: header.counts, points: new Float32Array(buffer, offset, (buffer.byteLength - offset) / 4) };
}

export async function exportFile(format, body) {
  const res = await post(`/api/export?format=${encodeURIComponent(format)}`, body);
  if (!res.ok) await fail(res);
  return res.blob();
}
