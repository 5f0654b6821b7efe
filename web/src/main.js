// SPDX-License-Identifier: MIT
// The page of `trivcon edit`: the mesh, the field drawn on it, and the edits that re-solve it through the
// server (src/api.js). All numerics are the server's; this file keeps the session (singularities, fixed
// directions, cycle indices), its history, and draws.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import * as api from './api.js';
import { FieldGlyphs, wantedDirections } from './glyphs.js';
import { formatIndex, parseIndex, componentBalance } from './indices.js';

const $ = (id) => document.getElementById(id);
const tLoadStart = performance.now();
// Asked for at once: creating the WebGL context (below) can take a while, the downloads go on meanwhile.
// (Without a token there is nothing to ask: start() says what is missing.)
const meshPromise = api.token ? api.getMesh() : null;
const statePromise = api.token ? api.getState() : null;
meshPromise?.catch(() => {});
statePromise?.catch(() => {});

// --- the session ---------------------------------------------------------------------------------
// n are integers meaning n/N (as in trivcon/indices.h); fixed directions are world vectors; pins are singular
// vertices that relaxation leaves where they are.
function emptySession(N) {
  return { N, sings: new Map(), gens: new Map(), loops: new Map(), fixed: new Map(), align: false, pins: new Set() };
}
function cloneSession(s) {
  return {
    N: s.N, sings: new Map(s.sings), gens: new Map(s.gens), loops: new Map(s.loops), fixed: new Map(s.fixed), align: s.align,
    pins: new Set(s.pins),
  };
}
function requestBody(s) {
  const pairs = (m) => [...m].sort((a, b) => a[0] - b[0]).map(([id, n]) => [id, formatIndex(n, s.N)]);
  return {
    N: s.N,
    singularities: pairs(s.sings),
    generators: pairs(s.gens),
    boundary: pairs(s.loops),
    fixed: [...s.fixed].sort((a, b) => a[0] - b[0]).map(([f, d]) => [f, d]),
    align_boundary: s.align,
    pins: [...s.pins].filter((v) => s.sings.has(v)).sort((a, b) => a - b),
  };
}
function sessionFromRequest(r, fallbackN) {
  const N = r.N || fallbackN;
  const s = emptySession(N);
  const fill = (map, list) => {
    for (const [id, text] of list || []) {
      const n = parseIndex(String(text), N);
      if (n === null) throw new Error(`index ${text} is not a multiple of 1/${N}`);
      map.set(id, n);
    }
  };
  fill(s.sings, r.singularities);
  fill(s.gens, r.generators);
  fill(s.loops, r.boundary);
  for (const [f, d] of r.fixed || []) s.fixed.set(f, d);
  s.align = !!r.align_boundary;
  for (const v of r.pins || []) if (s.sings.has(v)) s.pins.add(v);
  return s;
}

let session = null;
const history = []; // {label, session}
let historyIndex = -1;
let indexChoice = 1; // the palette's index, in units of 1/N
let mode = 'sing';

// --- mesh and scene ------------------------------------------------------------------------------
let mesh = null; // {info, positions, faces, component}
let isBoundaryVertex = null;
let adjacency = null; // CSR: vertex → neighbours
let meanEdge = 1;
let faceNormals = null, faceCentroids = null;
let fieldOct = null; // last drawn, octahedral-encoded (src/api.js); null: no field on screen
let fieldN = 0; // the symmetry of that field
let fieldVersion = 0;
let notice = ''; // what the last edit did that the user should know (shown until the next edit)
let lastReport = null;
let lastTimings = null;
let lastError = '';

const view = $('view');
// No colour-space conversion anywhere: colours are used as given. The per-pixel sRGB encoding costs more than
// the rest of an edit's redraw on a CPU rasterizer (SwiftShader), and a shaded grey surface needs none.
THREE.ColorManagement.enabled = false;
const renderer = new THREE.WebGLRenderer({ antialias: false });
renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
renderer.setPixelRatio(window.devicePixelRatio || 1);
view.appendChild(renderer.domElement);
// Two scenes: the surface (and its boundary loops), which only changes with the camera, and what an edit
// changes (the field, markers, arrows, highlights). The surface is rendered into a texture with its depth
// when the camera moves; an edit redraws that texture and the second scene over it, not the whole mesh
// (on a big mesh, and above all on a CPU rasterizer, the mesh is most of a frame).
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xf4f4f2);
const overlay = new THREE.Scene();
const camera = new THREE.PerspectiveCamera(35, 1, 0.001, 1000);
scene.add(camera);
scene.add(new THREE.HemisphereLight(0xffffff, 0x8888aa, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.4);
sun.position.set(0.5, 1, 1);
camera.add(sun);
overlay.add(new THREE.HemisphereLight(0xffffff, 0x8888aa, 1.6));
const overlaySun = new THREE.DirectionalLight(0xffffff, 1.4);
overlay.add(overlaySun);
const cache = {
  target: null,
  dirty: true,
  quad: new THREE.Mesh(
    new THREE.PlaneGeometry(2, 2),
    new THREE.ShaderMaterial({
      uniforms: { tColor: { value: null }, tDepth: { value: null } },
      vertexShader: 'varying vec2 vUv; void main() { vUv = uv; gl_Position = vec4(position.xy, 0.0, 1.0); }',
      fragmentShader: `uniform sampler2D tColor; uniform sampler2D tDepth; varying vec2 vUv;
        void main() { gl_FragColor = texture2D(tColor, vUv); gl_FragDepth = texture2D(tDepth, vUv).x; }`,
      depthTest: true,
      depthWrite: true,
      depthFunc: THREE.AlwaysDepth,
    })),
  quadScene: new THREE.Scene(),
  quadCamera: new THREE.OrthographicCamera(-1, 1, 1, -1, 0, 1),
};
cache.quad.frustumCulled = false;
cache.quadScene.add(cache.quad);
function resizeCache(w, h) {
  if (cache.target) cache.target.dispose();
  const dpr = renderer.getPixelRatio();
  const W = Math.max(1, Math.floor(w * dpr)), H = Math.max(1, Math.floor(h * dpr));
  cache.target = new THREE.WebGLRenderTarget(W, H, { depthTexture: new THREE.DepthTexture(W, H, THREE.UnsignedIntType) });
  cache.quad.material.uniforms.tColor.value = cache.target.texture;
  cache.quad.material.uniforms.tDepth.value = cache.target.depthTexture;
  cache.dirty = true;
}
const controls = new OrbitControls(camera, renderer.domElement);
controls.enableDamping = false;
camera.userData.target = controls.target; // the glyphs measure the viewing distance to it

let surface = null;
let glyphs = null;
const markers = new THREE.Group();
const fixedArrows = new THREE.Group();
const loopsGroup = new THREE.Group();
const highlight = new THREE.Group();
let streamlineObject = null;
let previewArrow = null;
scene.add(loopsGroup);
overlay.add(markers, fixedArrows, highlight);

let renderQueued = false;
function invalidate() {
  if (renderQueued) return;
  renderQueued = true;
  requestAnimationFrame(() => {
    renderQueued = false;
    draw();
  });
}
function draw() {
  if (glyphs) {
    glyphs.adapt(camera, renderer.domElement.clientHeight, +$('spacing').value);
    // Zoomed in past the directions received: ask for more (a re-solve of the same session).
    if (fieldOct && glyphs.count > glyphs.usable() && glyphs.received < wantedDirections(glyphs) && !inflight && !pending && !lastError)
      requestSolve();
  }
  updateMarkerSizes();
  camera.updateMatrixWorld();
  overlaySun.position.copy(camera.localToWorld(new THREE.Vector3(0.5, 1, 1)));
  if (cache.dirty) {
    renderer.setRenderTarget(cache.target);
    renderer.render(scene, camera);
    renderer.setRenderTarget(null);
    cache.dirty = false;
  }
  renderer.render(cache.quadScene, cache.quadCamera);
  renderer.autoClear = false;
  renderer.render(overlay, camera);
  renderer.autoClear = true;
}
function resize() {
  const w = view.clientWidth, h = view.clientHeight;
  renderer.setSize(w, h);
  resizeCache(w, h);
  camera.aspect = w / Math.max(1, h);
  camera.updateProjectionMatrix();
  invalidate();
}
window.addEventListener('resize', resize);
controls.addEventListener('change', () => ((cache.dirty = true), invalidate()));

function status(text) {
  $('status').textContent = text;
  $('status').title = text;
}

function buildMesh() {
  const { positions, faces, info } = mesh;
  const nV = info.vertices, nF = info.faces;
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  geometry.setIndex(new THREE.BufferAttribute(faces, 1));
  geometry.computeBoundingSphere();
  const material = new THREE.MeshLambertMaterial({
    color: 0xd9d6cf, side: THREE.DoubleSide, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
  });
  surface = new THREE.Mesh(geometry, material);
  scene.add(surface);

  // Per face: centroid, unit normal; mean edge length.
  faceNormals = new Float32Array(3 * nF);
  faceCentroids = new Float32Array(3 * nF);
  let edgeSum = 0;
  const vertexNormals = new Float32Array(3 * nV); // area-weighted sums of the face normals, then normalized
  for (let f = 0; f < nF; ++f) {
    const a = 3 * faces[3 * f], b = 3 * faces[3 * f + 1], c = 3 * faces[3 * f + 2];
    const ux = positions[b] - positions[a], uy = positions[b + 1] - positions[a + 1], uz = positions[b + 2] - positions[a + 2];
    const vx = positions[c] - positions[a], vy = positions[c + 1] - positions[a + 1], vz = positions[c + 2] - positions[a + 2];
    let nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
    for (const v of [a, b, c]) (vertexNormals[v] += nx), (vertexNormals[v + 1] += ny), (vertexNormals[v + 2] += nz);
    const len = Math.hypot(nx, ny, nz);
    if (len > 0) (nx /= len), (ny /= len), (nz /= len);
    faceNormals[3 * f] = nx, faceNormals[3 * f + 1] = ny, faceNormals[3 * f + 2] = nz;
    for (let k = 0; k < 3; ++k) faceCentroids[3 * f + k] = (positions[a + k] + positions[b + k] + positions[c + k]) / 3;
    edgeSum += Math.hypot(ux, uy, uz);
  }
  meanEdge = nF ? edgeSum / nF : 1;
  for (let v = 0; v < nV; ++v) {
    const l = Math.hypot(vertexNormals[3 * v], vertexNormals[3 * v + 1], vertexNormals[3 * v + 2]) || 1;
    for (let k = 0; k < 3; ++k) vertexNormals[3 * v + k] /= l;
  }
  geometry.setAttribute('normal', new THREE.BufferAttribute(vertexNormals, 3));

  // Vertex adjacency (CSR), for dragging a singularity from vertex to vertex.
  const degree = new Uint32Array(nV + 1);
  for (let i = 0; i < faces.length; ++i) degree[faces[i] + 1] += 2;
  for (let v = 0; v < nV; ++v) degree[v + 1] += degree[v];
  const nbr = new Uint32Array(degree[nV]);
  const fill = degree.slice(0, nV);
  for (let f = 0; f < nF; ++f)
    for (let k = 0; k < 3; ++k) {
      const a = faces[3 * f + k], b = faces[3 * f + (k + 1) % 3];
      nbr[fill[a]++] = b;
      nbr[fill[b]++] = a;
    }
  adjacency = { start: degree, nbr };

  isBoundaryVertex = new Uint8Array(nV);
  for (const loop of info.cycles.loops) for (const v of loop.vertices) isBoundaryVertex[v] = 1;
  for (const loop of info.cycles.loops) {
    const pts = loop.vertices.map((v) => new THREE.Vector3(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]));
    const line = new THREE.LineLoop(new THREE.BufferGeometry().setFromPoints(pts), new THREE.LineBasicMaterial({ color: 0xd06010 }));
    line.userData.loop = loop.id;
    loopsGroup.add(line);
  }

  glyphs = new FieldGlyphs({ positions, faces, normals: faceNormals, order: mesh.glyphOrder, times: mesh.glyphTimes, meanEdge });
  overlay.add(glyphs.object);

  const sphere = geometry.boundingSphere;
  controls.target.copy(sphere.center);
  camera.near = sphere.radius / 500;
  camera.far = sphere.radius * 50;
  // The whole bounding sphere in view, with a margin.
  camera.position.copy(sphere.center).add(new THREE.Vector3(0, 0, (1.25 * sphere.radius) / Math.sin((camera.fov * Math.PI) / 360)));
  camera.updateProjectionMatrix();
  controls.update();
}

// --- singularity markers, fixed arrows, highlights ------------------------------------------------
const sphereGeometry = new THREE.SphereGeometry(1, 16, 12);
// A pinned singularity: a cube with dark edges instead of a ball.
const pinGeometry = new THREE.BoxGeometry(1.5, 1.5, 1.5);
const pinEdges = new THREE.EdgesGeometry(pinGeometry);
const pinEdgeMaterial = new THREE.LineBasicMaterial({ color: 0x202020 });
function markerColor(n, N) {
  const t = Math.min(1, Math.abs(n) / N);
  return n > 0 ? new THREE.Color().setHSL(0.02 + 0.1 * (1 - t), 0.9, 0.5) : new THREE.Color().setHSL(0.6 - 0.1 * (1 - t), 0.85, 0.5);
}
function rebuildMarkers() {
  markers.clear();
  const p = mesh.positions;
  for (const [v, n] of session.sings) {
    const pinned = session.pins.has(v);
    const m = new THREE.Mesh(pinned ? pinGeometry : sphereGeometry, new THREE.MeshLambertMaterial({ color: markerColor(n, session.N) }));
    m.position.set(p[3 * v], p[3 * v + 1], p[3 * v + 2]);
    m.userData = { vertex: v, n, pinned };
    if (pinned) m.add(new THREE.LineSegments(pinEdges, pinEdgeMaterial));
    markers.add(m);
  }
  updateMarkerSizes();
}
// Markers keep a readable size on screen: a few pixels at any zoom, never much smaller than an edge, and
// growing with |index|.
function updateMarkerSizes() {
  if (!surface) return;
  const worldPerPixel = (2 * camera.position.distanceTo(controls.target) * Math.tan((camera.fov * Math.PI) / 360)) / Math.max(1, view.clientHeight);
  const base = Math.max(4 * worldPerPixel, 0.3 * meanEdge);
  for (const m of markers.children) m.scale.setScalar(base * (0.8 + 0.5 * Math.sqrt(Math.abs(m.userData.n) / session.N)));
}
function arrowSegments(list, length) {
  const pts = [];
  for (const [f, d] of list) {
    const c = new THREE.Vector3(faceCentroids[3 * f], faceCentroids[3 * f + 1], faceCentroids[3 * f + 2]);
    const n = new THREE.Vector3(faceNormals[3 * f], faceNormals[3 * f + 1], faceNormals[3 * f + 2]);
    const dir = new THREE.Vector3(...d);
    dir.addScaledVector(n, -dir.dot(n));
    if (dir.lengthSq() === 0) continue;
    dir.normalize().multiplyScalar(length);
    const tip = c.clone().add(dir);
    const side = new THREE.Vector3().crossVectors(n, dir).multiplyScalar(0.3);
    pts.push(c.clone().sub(dir.clone().multiplyScalar(0.3)), tip);
    pts.push(tip, tip.clone().sub(dir.clone().multiplyScalar(0.35)).add(side));
    pts.push(tip, tip.clone().sub(dir.clone().multiplyScalar(0.35)).sub(side));
  }
  return new THREE.BufferGeometry().setFromPoints(pts);
}
function rebuildFixedArrows() {
  fixedArrows.clear();
  if (session.fixed.size) {
    const lines = new THREE.LineSegments(arrowSegments([...session.fixed], 2.5 * meanEdge), new THREE.LineBasicMaterial({ color: 0x00a040 }));
    fixedArrows.add(lines);
  }
  $('fixedcount').textContent = session.fixed.size ? `${session.fixed.size} fixed face(s)` : 'none';
}
function highlightCycle(kind, id) {
  highlight.clear();
  if (kind === 'generator') {
    const g = mesh.info.cycles.generators[id];
    const pts = g.faces.map((f) => new THREE.Vector3(faceCentroids[3 * f], faceCentroids[3 * f + 1], faceCentroids[3 * f + 2]));
    highlight.add(new THREE.LineLoop(new THREE.BufferGeometry().setFromPoints(pts), new THREE.LineBasicMaterial({ color: 0xe0007a })));
  } else if (kind === 'loop') {
    const p = mesh.positions;
    const pts = mesh.info.cycles.loops[id].vertices.map((v) => new THREE.Vector3(p[3 * v], p[3 * v + 1], p[3 * v + 2]));
    highlight.add(new THREE.LineLoop(new THREE.BufferGeometry().setFromPoints(pts), new THREE.LineBasicMaterial({ color: 0xe0007a })));
    // Thick enough to see at any zoom: small spheres along the loop too.
    const r = 0.25 * meanEdge;
    for (let i = 0; i < pts.length; i += Math.max(1, Math.floor(pts.length / 200))) {
      const s = new THREE.Mesh(sphereGeometry, new THREE.MeshBasicMaterial({ color: 0xe0007a }));
      s.position.copy(pts[i]);
      s.scale.setScalar(r);
      highlight.add(s);
    }
  }
  invalidate();
}

// --- solving: at most one request in flight, only the newest pending one kept ---------------------
let inflight = false;
let pending = null;
let idleWaiters = [];
let refactorSeconds = null; // how long the last re-factoring for fixed faces took (the progress bar's estimate)
let solvedFixedKey = null; // the fixed faces the server was last set up for (a change refactors)

function fixedKey(s) {
  return (s.align ? 'A' : '') + [...s.fixed.keys()].sort((a, b) => a - b).join(',');
}
function requestSolve(tEdit = performance.now()) {
  pending = { session: cloneSession(session), tEdit };
  if (!inflight) pump();
}
async function pump() {
  const job = pending;
  pending = null;
  inflight = true;
  const refactor = fixedKey(job.session) !== solvedFixedKey;
  let timer = null;
  const t0 = performance.now();
  if (refactor) {
    // The server does not stream its progress; the bar runs against the expected time: the last
    // re-factoring's, or at first three times the set-up without fixed faces (BENCHMARKS.md measures
    // 1.8–3.4× with thousands of them), and stops short of the end until the answer arrives.
    const faces = job.session.fixed.size + (job.session.align ? ' + boundary' : '');
    const expected = refactorSeconds ?? 3 * (lastReport ? lastReport.seconds.setup + lastReport.seconds.analysis : 1);
    const bar = $('progress');
    bar.hidden = false;
    const tick = () => {
      const elapsed = (performance.now() - t0) / 1000;
      bar.value = Math.min(0.95, elapsed / Math.max(expected, 0.05));
      status(`re-factoring for ${faces} fixed face(s)… ${elapsed.toFixed(1)} s of about ${expected.toFixed(1)} s`);
    };
    tick();
    timer = setInterval(tick, 100);
  } else {
    // Shown only for a solve that takes a while: a page update per edit would be repainted (on the CPU,
    // with SwiftShader) while the server solves on the same cores.
    timer = setTimeout(() => status('solving…'), 250);
  }
  try {
    const r = await api.solve(requestBody(job.session), wantedDirections(glyphs));
    if (refactor) refactorSeconds = (performance.now() - t0) / 1000;
    solvedFixedKey = fixedKey(job.session);
    showField(r, job);
    lastError = '';
    // Whether the crosses, read face to face by the closest matching (as Directional, QuadWild or MIQ read an
    // exported field), show exactly the singularities placed (the report's field_exact).
    const read = r.report.large_turns ? r.report.large_turns.principal_matching_singularities.length : 0;
    const exact = r.report.field_exact
      ? ' · field exact'
      : ` · field NOT exact: read face to face it shows ${read} singular vertices, not those placed (edges turn by π/N or more; trivcon solve --split-large-turns refines the mesh until they do not)`;
    status(`solved: energy ${r.report.energy.toPrecision(6)}${r.report.verified ? '' : ' (verification failed: see the report)'}${exact}`);
  } catch (e) {
    // The last valid field of this symmetry stays on screen; the message says what went wrong (the CLI's text).
    lastError = e.message;
    status(fieldOct ? 'not solved: the last valid field is shown' : `not solved: no valid field for N = ${session.N} yet`);
  } finally {
    if (timer) clearInterval(timer), clearTimeout(timer);
    $('progress').hidden = true;
  }
  updateReadout();
  inflight = false;
  if (pending) pump();
  else {
    for (const w of idleWaiters) w();
    idleWaiters = [];
    if ($('streamlines').checked && !lastError) refreshStreamlines();
  }
}
function showField(r, job) {
  fieldOct = r.oct;
  fieldN = job.session.N;
  lastReport = r.report;
  glyphs.setDirections(r.oct, r.count, job.session.N);
  draw();
  const tSubmitted = performance.now();
  // Wait for the GPU to finish this frame (a 1-pixel read), so that "drawing" is the whole drawing.
  const gl = renderer.getContext();
  gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
  const tDrawn = performance.now();
  const server = r.serverSeconds * 1000;
  lastTimings = {
    server_ms: server,
    transfer_ms: Math.max(0, r.tReceived - r.tSend - server),
    draw_ms: tDrawn - r.tReceived,
    draw_submit_ms: tSubmitted - r.tReceived, // the page's own work: copying directions, issuing the frame
    total_ms: tDrawn - job.tEdit,
    solve_ms: 1000 * (r.report.seconds.solve + r.report.seconds.field + r.report.seconds.verify),
  };
  fieldVersion++;
  $('timings').textContent = `last edit → field on screen ${lastTimings.total_ms.toFixed(0)} ms: server ${server.toFixed(0)} ms ` +
    `(solve ${lastTimings.solve_ms.toFixed(0)}), transfer ${lastTimings.transfer_ms.toFixed(0)} ms, drawing ${lastTimings.draw_ms.toFixed(0)} ms`;
  updateCycleList();
}

async function refreshStreamlines() {
  if (streamlineObject) overlay.remove(streamlineObject), (streamlineObject = null);
  if (!$('streamlines').checked || lastError) return invalidate();
  try {
    const { counts, points } = await api.streamlines(requestBody(session));
    const seg = [];
    let i = 0;
    for (const c of counts) {
      for (let k = 0; k + 1 < c; ++k) seg.push(...points.subarray(3 * (i + k), 3 * (i + k) + 6));
      i += c;
    }
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(seg), 3));
    if (streamlineObject) overlay.remove(streamlineObject);
    streamlineObject = new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ color: 0x203080 }));
    overlay.add(streamlineObject);
  } catch (e) {
    status(`streamlines: ${e.message}`);
  }
  invalidate();
}

// --- readout ------------------------------------------------------------------------------------
function updateReadout() {
  const rows = componentBalance(mesh.info, mesh.component, session);
  const out = $('readout');
  out.textContent = '';
  let missing = [];
  for (const r of rows) {
    const div = document.createElement('div');
    const sum = formatIndex(r.sum, session.N);
    out.appendChild(div);
    if (r.free) {
      div.textContent = `component ${r.component}: Σ ${sum} (free boundary loops take the rest of χ ${r.chi})`;
      div.className = 'ok';
    } else if (r.missing === 0) {
      div.textContent = `component ${r.component}: Σ ${sum} = χ ${r.chi}`;
      div.className = 'ok';
    } else {
      div.textContent = `component ${r.component}: Σ ${sum}, χ ${r.chi}: add ${formatIndex(r.missing, session.N)}`;
      div.className = 'bad';
      missing.push(`add ${formatIndex(r.missing, session.N)} on component ${r.component}`);
    }
    div.title = div.textContent; // one line each, cut to the panel: the whole line on hover
  }
  $('balance').disabled = missing.length === 0;
  let text = notice;
  const shown = fieldOct ? 'The last valid field is shown.' : 'No field is shown: none has solved yet for this N.';
  if (missing.length) text += (text ? '\n' : '') + `Indices do not balance (Gauss–Bonnet): ${missing.join('; ')}. ${shown}`;
  if (lastError && !(missing.length && /Gauss-Bonnet/.test(lastError))) text += (text ? '\n' : '') + lastError;
  $('message').textContent = text;
  $('message').title = text;
}

// --- edits and history ----------------------------------------------------------------------------
// `label`: one line in the history list; `detail`: its tooltip (what a long edit did in full); `told`: what
// the user should know about the edit (the message area, until the next edit).
function commit(label, next, { detail = '', told = '', tEdit = performance.now() } = {}) {
  session = next;
  notice = told;
  history.length = historyIndex + 1;
  history.push({ label, detail, session: cloneSession(next) });
  historyIndex = history.length - 1;
  applySession(tEdit);
}
function applySession(tEdit = performance.now()) {
  // A field of another symmetry is not this session's: no crosses until one solves for this N.
  if (fieldOct && fieldN !== session.N) {
    fieldOct = null;
    lastReport = null;
    glyphs.clear();
    fieldVersion++;
  }
  requestSolve(tEdit); // first: the panel's updates below need not delay the solve
  clearQuads('quads: the field changed; make them again');
  rebuildMarkers();
  rebuildFixedArrows();
  $('N').value = session.N;
  $('align').checked = session.align;
  renderPalette();
  updateCycleList();
  updateHistory();
  updateReadout();
  invalidate();
  saveTabSoon();
}
function goTo(i) {
  if (i < 0 || i >= history.length) return;
  historyIndex = i;
  session = cloneSession(history[i].session);
  notice = '';
  applySession();
}
const undo = () => goTo(historyIndex - 1);
const redo = () => goTo(historyIndex + 1);
function updateHistory() {
  const box = $('history');
  box.textContent = '';
  history.forEach((h, i) => {
    const div = document.createElement('div');
    div.textContent = `${i}. ${h.label}`;
    div.title = h.detail || h.label;
    div.className = i === historyIndex ? 'current' : i > historyIndex ? 'future' : '';
    div.onclick = () => goTo(i);
    box.appendChild(div);
  });
  // The current entry in view, scrolling the list only (scrollIntoView would scroll the panel too).
  const cur = box.querySelector('.current');
  if (cur) {
    if (cur.offsetTop < box.scrollTop) box.scrollTop = cur.offsetTop;
    else if (cur.offsetTop + cur.offsetHeight > box.scrollTop + box.clientHeight)
      box.scrollTop = cur.offsetTop + cur.offsetHeight - box.clientHeight;
  }
  $('undo').disabled = historyIndex <= 0;
  $('redo').disabled = historyIndex >= history.length - 1;
}

function addSingularity(v) {
  if (isBoundaryVertex[v]) {
    status(`vertex ${v} is on a boundary loop: set the loop's index instead`);
    return;
  }
  if (mesh.component[v] < 0) return;
  const next = cloneSession(session);
  next.sings.set(v, indexChoice);
  commit(`add ${formatIndex(indexChoice, session.N)} at vertex ${v}`, next);
}
function removeSingularity(v) {
  const next = cloneSession(session);
  const n = next.sings.get(v);
  next.sings.delete(v);
  next.pins.delete(v);
  commit(`remove ${formatIndex(n, session.N)} at vertex ${v}`, next);
}
function togglePin(v) {
  const next = cloneSession(session);
  const pinned = next.pins.has(v);
  if (pinned) next.pins.delete(v);
  else next.pins.add(v);
  commit(`${pinned ? 'unpin' : 'pin'} ${formatIndex(next.sings.get(v), next.N)} at vertex ${v}`, next);
}
// --- relaxation (POST /api/relax) -------------------------------------------------------------------
// The server moves the singularities one edge at a time while the energy goes down (trivcon/relax.h); the page
// replays the moves on the markers, then commits the end as one step of the history (one undo).
let relaxing = false;
let lastRelax = null;
// --- quads (POST /api/quad) -----------------------------------------------------------------------------
// The quad mesh of the field on screen, drawn as its edges; an edit makes it stale (removed, the panel says so).
let quadMesh = null; // {V, Q, report}
let quadObject = null;
let quadding = false;
function clearQuads(why) {
  if (quadObject) overlay.remove(quadObject), quadObject.geometry.dispose(), (quadObject = null);
  if (quadMesh && why) $('quadinfo').textContent = why;
  quadMesh = null;
  $('dl-quads').disabled = true;
}
function drawQuads() {
  if (quadObject) overlay.remove(quadObject), quadObject.geometry.dispose(), (quadObject = null);
  if (!quadMesh || !$('showquads').checked) return invalidate();
  const { V, Q } = quadMesh;
  // Each quad's edges, lifted off the surface along the quad's normal by a tenth of a mesh edge (no z-fighting).
  const seg = new Float32Array(Q.length * 6);
  const p = (i) => new THREE.Vector3(V[3 * i], V[3 * i + 1], V[3 * i + 2]);
  const lift = 0.1 * meanEdge;
  for (let f = 0; f < Q.length / 4; ++f) {
    const c = [0, 1, 2, 3].map((k) => p(Q[4 * f + k]));
    const n = c[2].clone().sub(c[0]).cross(c[3].clone().sub(c[1]));
    const len = n.length();
    if (len > 0) n.multiplyScalar(lift / len);
    for (let k = 0; k < 4; ++k) {
      const a = c[k].clone().add(n), b = c[(k + 1) % 4].clone().add(n);
      seg.set([a.x, a.y, a.z, b.x, b.y, b.z], 24 * f + 6 * k);
    }
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(seg, 3));
  quadObject = new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ color: 0x202020 }));
  overlay.add(quadObject);
  invalidate();
}
async function makeQuads() {
  if (quadding) return;
  if (session.N !== 4) {
    status('quads: they need a cross field, N = 4');
    return;
  }
  quadding = true;
  $('quads').disabled = true;
  const target = Math.max(1, Math.round(parseFloat($('quadtarget').value) || 2000));
  status(`quads: making about ${target}…`);
  const made = session;
  try {
    const body = requestBody(session);
    body.target_faces = target;
    const r = await api.quads(body);
    if (session !== made) return; // an edit meanwhile: these quads are of an older field
    quadMesh = r;
    const q = r.report.quad;
    const irregular = q.singular_mismatches === 0 ? 'all at the singularities' : `${q.singular_mismatches} NOT at a singularity of their valence`;
    $('quadinfo').textContent = `${q.quads} quads (target ${target}), ${q.irregular_vertices} irregular vertices (${irregular}), ` +
      `chi ${q.euler_characteristic}, scaled Jacobian min ${q.min_scaled_jacobian.toFixed(3)}, mean ${q.mean_scaled_jacobian.toFixed(3)}, ` +
      `${q.nonconvex_quads} with a flat or reflex corner` +
      (r.report.map_scale !== 1 ? `; the map at the target kept problems, made at ${r.report.map_scale} times its edge length` : '') +
      (r.report.warning ? `. ${r.report.warning}` : '');
    $('dl-quads').disabled = false;
    status(r.report.warning ? 'quads: made, with problems (see Quads)' : `quads: ${q.quads} made`);
    drawQuads();
  } catch (e) {
    status(`quads: ${e.message}`);
  } finally {
    quadding = false;
    $('quads').disabled = false;
  }
}
function quadObj() {
  const { V, Q } = quadMesh;
  const lines = [`# trivcon quad mesh: ${V.length / 3} vertices, ${Q.length / 4} quads`];
  for (let i = 0; i < V.length; i += 3) lines.push(`v ${V[i]} ${V[i + 1]} ${V[i + 2]}`);
  for (let i = 0; i < Q.length; i += 4) lines.push(`f ${Q[i] + 1} ${Q[i + 1] + 1} ${Q[i + 2] + 1} ${Q[i + 3] + 1}`);
  return lines.join('\n') + '\n';
}
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));
const energyText = (e) => (Math.abs(e) >= 1e-3 && Math.abs(e) < 1e5 ? e.toFixed(4) : e.toExponential(3));
async function relax() {
  if (relaxing) return;
  if (!session.sings.size) {
    status('relax: there are no singularities to move');
    return;
  }
  relaxing = true;
  $('relax').disabled = true;
  status('relax: moving singularities downhill in the energy…');
  try {
    const body = requestBody(session);
    body.relax_cancel = Math.max(0, Math.min(1000, Math.round(parseFloat($('relaxcancel').value) || 0)));
    const r = await api.relax(body);
    lastRelax = r;
    const percent = r.energy_before > 0 ? ` (${((100 * (r.energy_after - r.energy_before)) / r.energy_before).toFixed(1)} %)` : '';
    const cancelled = r.moves.filter((m) => m.cancelled).length;
    const summary = `${r.moves.length} move${r.moves.length === 1 ? '' : 's'}${cancelled ? ` (${cancelled} cancelling a pair)` : ''}, ` +
      `energy ${energyText(r.energy_before)} → ${energyText(r.energy_after)}${percent}`;
    const why = r.out_of_time ? '; stopped after its time budget: relax again to go on' : r.converged ? '; no single move lowers it further' : '';
    $('relaxinfo').textContent = `last: ${summary}, ${r.candidates_evaluated} solves in ${r.seconds.toFixed(2)} s${why}`;
    if (!r.moves.length) {
      status(`relax: no single move lowers the energy (${energyText(r.energy_before)})`);
      return;
    }
    // The replay: each move on the markers, about 1.5 s in all (edits on the mesh and keys wait for it).
    const before = session;
    const shown = cloneSession(session);
    session = shown;
    const pause = Math.min(120, 1500 / r.moves.length);
    for (const m of r.moves) {
      shown.sings.delete(m.from);
      if (m.cancelled) shown.sings.delete(m.to);
      else shown.sings.set(m.to, parseIndex(m.index, shown.N));
      rebuildMarkers();
      invalidate();
      await sleep(pause);
      if (session !== shown) return; // undo, the history or a button chose another state meanwhile
    }
    session = before;
    const next = cloneSession(before);
    next.sings = new Map(r.singularities.map(([v, t]) => [v, parseIndex(t, before.N)]));
    for (const v of [...next.pins]) if (!next.sings.has(v)) next.pins.delete(v);
    const detail = r.moves.map((m) => `${m.index} ${m.from} → ${m.to}${m.cancelled ? ' (cancelled)' : ''}`).join('\n');
    commit(`relax: ${summary}`, next, { detail, told: `relaxed: ${summary}${why}` });
  } catch (e) {
    status(`relax: ${e.message}`);
  } finally {
    relaxing = false;
    $('relax').disabled = false;
  }
}
function setN(N) {
  if (!(N >= 1 && N <= 1000) || N === session.N) {
    if (!(N >= 1 && N <= 1000)) status(`N: ${$('N').value || 'nothing'} is not a whole number from 1 to 1000`);
    $('N').value = session.N;
    return;
  }
  // Indices carry over where they are multiples of 1/N in the new symmetry too; otherwise the set is cleared.
  const convert = (m) => {
    const out = new Map();
    for (const [id, n] of m) {
      const scaled = (n * N) / session.N;
      if (!Number.isInteger(scaled)) return null;
      out.set(id, scaled);
    }
    return out;
  };
  const next = cloneSession(session);
  next.N = N;
  const s = convert(session.sings), g = convert(session.gens), l = convert(session.loops);
  next.sings = s || new Map();
  next.gens = g || new Map();
  next.loops = l || new Map();
  indexChoice = Math.sign(indexChoice) || 1;
  const removed = [];
  const count = (n, one, many) => `${n} ${n === 1 ? one : many}`;
  if (!s && session.sings.size) removed.push(count(session.sings.size, 'singularity', 'singularities'));
  if (!g && session.gens.size) removed.push(count(session.gens.size, 'generator index', 'generator indices'));
  if (!l && session.loops.size) removed.push(count(session.loops.size, 'boundary loop index', 'boundary loop indices'));
  const told = removed.length
    ? `N = ${N}: removed ${removed.join(' and ')} (their indices are not multiples of 1/${N}); Ctrl+Z brings them back.`
    : '';
  if (told) status(told);
  commit(`N = ${N}${removed.length ? ` (removed ${removed.join(', ')})` : ''}`, next, { told });
}
function balance() {
  const rows = componentBalance(mesh.info, mesh.component, session);
  const next = cloneSession(session);
  const placed = [];
  for (const r of rows) {
    if (r.free || r.missing === 0) continue;
    const v = farthestFreeVertex(r.component, next);
    if (v < 0) continue;
    next.sings.set(v, r.missing);
    placed.push(`${formatIndex(r.missing, session.N)} at ${v}`);
  }
  // One entry however many components: its line says how many, its tooltip what went where.
  const label =
    placed.length <= 2 ? `balance: ${placed.join(', ')}` : `balance: ${placed.length} singularities on ${placed.length} components`;
  if (placed.length) commit(label, next, { detail: `balance: ${placed.join(', ')}` });
}
// The interior vertex of the component farthest from the singularities already there (a sample of the
// component's vertices on big meshes), so the balancing singularity disturbs the field least.
function farthestFreeVertex(c, s) {
  const p = mesh.positions, nV = mesh.info.vertices;
  const existing = [...s.sings.keys()].filter((v) => mesh.component[v] === c);
  const step = Math.max(1, Math.floor(nV / 20000));
  let best = -1, bestD = -1;
  for (let v = 0; v < nV; v += step) {
    if (mesh.component[v] !== c || isBoundaryVertex[v] || s.sings.has(v)) continue;
    let d = Infinity;
    for (const u of existing) d = Math.min(d, (p[3 * v] - p[3 * u]) ** 2 + (p[3 * v + 1] - p[3 * u + 1]) ** 2 + (p[3 * v + 2] - p[3 * u + 2]) ** 2);
    if (d > bestD) (bestD = d), (best = v);
  }
  if (best < 0) for (let v = 0; v < nV && best < 0; ++v) if (mesh.component[v] === c && !isBoundaryVertex[v] && !s.sings.has(v)) best = v;
  return best;
}

// --- palette, cycles list --------------------------------------------------------------------------
function renderPalette() {
  const box = $('palette');
  box.textContent = '';
  const N = session.N;
  const row = document.createElement('div');
  for (const k of [-4, -3, -2, -1, 1, 2, 3, 4]) {
    const b = document.createElement('button');
    b.textContent = (k > 0 ? '+' : '') + formatIndex(k, N);
    b.className = k === indexChoice ? 'on' : '';
    b.title = `${k > 0 ? '' : 'Shift+'}${Math.abs(k)}`;
    b.onclick = () => setIndexChoice(k);
    row.appendChild(b);
  }
  box.appendChild(row);
  $('modehint').textContent = mode === 'sing'
    ? `click a vertex: add ${formatIndex(indexChoice, N)}; click a singularity: remove; drag one: move`
    : mode === 'pin'
      ? 'click a singularity: pin it (relax leaves it where it is) or unpin it'
      : 'drag on a face: fix its direction; click a fixed face: free it';
}
function setIndexChoice(k) {
  indexChoice = k;
  renderPalette();
}
function setMode(m) {
  mode = m;
  $('mode-sing').className = m === 'sing' ? 'on' : '';
  $('mode-fix').className = m === 'fix' ? 'on' : '';
  $('mode-pin').className = m === 'pin' ? 'on' : '';
  renderPalette();
}
// The list is built once (a mesh may have hundreds of cycles); edits and solves update its fields in place.
const cycleInputs = []; // {kind, id, input}
function buildCycleList() {
  const box = $('cycles');
  const { generators, loops } = mesh.info.cycles;
  if (!generators.length && !loops.length) {
    box.textContent = 'none (every dual cycle is a vertex cycle)';
    return;
  }
  box.textContent = '';
  const add = (kind, c, label) => {
    const row = document.createElement('div');
    row.className = 'row';
    const span = document.createElement('span');
    span.className = 'label';
    span.textContent = label;
    const input = document.createElement('input');
    input.type = 'text';
    input.title = 'the index along this cycle; empty: chosen to make the field smoothest';
    input.onchange = () => {
      const text = input.value.trim();
      const next = cloneSession(session);
      const m = kind === 'generator' ? next.gens : next.loops;
      if (text === '') m.delete(c.id);
      else {
        const n = parseIndex(text, session.N);
        if (n === null) {
          status(`${label}: '${text}' is not a multiple of 1/${session.N}`);
          updateCycleList();
          return;
        }
        m.set(c.id, n);
      }
      commit(`${label}: ${text === '' ? 'smoothest' : text}`, next);
    };
    row.onmouseenter = () => (row.classList.add('hover'), highlightCycle(kind, c.id));
    row.onmouseleave = () => (row.classList.remove('hover'), highlightCycle(null));
    row.append(span, input);
    row.dataset.kind = kind;
    row.dataset.id = c.id;
    box.appendChild(row);
    cycleInputs.push({ kind, id: c.id, input });
  };
  for (const g of generators) add('generator', g, `generator ${g.id} (component ${g.component})`);
  for (const l of loops) add('loop', l, `boundary loop ${l.id} (component ${l.component}, ${l.length} vertices)`);
}
function updateCycleList() {
  for (const { kind, id, input } of cycleInputs) {
    const map = kind === 'generator' ? session.gens : session.loops;
    const list = lastReport && (kind === 'generator' ? lastReport.generators : lastReport.boundary_loops);
    const chosen = list && list[id] ? ` (${list[id].index})` : '';
    if (document.activeElement !== input) input.value = map.has(id) ? formatIndex(map.get(id), session.N) : '';
    input.placeholder = `smoothest${chosen}`;
  }
}

// --- picking and dragging --------------------------------------------------------------------------
const raycaster = new THREE.Raycaster();
function ndc(x, y) {
  const r = renderer.domElement.getBoundingClientRect();
  return new THREE.Vector2(((x - r.left) / r.width) * 2 - 1, -((y - r.top) / r.height) * 2 + 1);
}
function pickSurface(x, y) {
  raycaster.setFromCamera(ndc(x, y), camera);
  const hit = raycaster.intersectObject(surface, false)[0];
  return hit ? { face: hit.faceIndex, point: hit.point } : null;
}
function nearestCorner(face, point) {
  let best = -1, bestD = Infinity;
  for (let k = 0; k < 3; ++k) {
    const v = mesh.faces[3 * face + k];
    const d = point.distanceToSquared(new THREE.Vector3(mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]));
    if (d < bestD) (bestD = d), (best = v);
  }
  return best;
}
function pickVertex(x, y) {
  raycaster.setFromCamera(ndc(x, y), camera);
  const m = raycaster.intersectObjects(markers.children, false)[0];
  const s = pickSurface(x, y);
  if (m && (!s || m.distance <= s.point.distanceTo(camera.position) + meanEdge)) return m.object.userData.vertex;
  return s ? nearestCorner(s.face, s.point) : -1;
}
function projectVertex(v) {
  const p = new THREE.Vector3(mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]).project(camera);
  const r = renderer.domElement.getBoundingClientRect();
  return { x: r.left + ((p.x + 1) / 2) * r.width, y: r.top + ((1 - p.y) / 2) * r.height };
}
// Dragging walks the mesh from the singularity's vertex towards the pointer, one neighbour at a time: no
// ray cast per move (a cast visits every face), and the singularity stays on the surface.
function walkTowards(v, x, y) {
  const dist = (u) => {
    const q = projectVertex(u);
    return (q.x - x) ** 2 + (q.y - y) ** 2;
  };
  let cur = v, d = dist(v);
  for (let steps = 0; steps < 10000; ++steps) {
    let next = -1, nd = d;
    for (let i = adjacency.start[cur]; i < adjacency.start[cur + 1]; ++i) {
      const u = adjacency.nbr[i];
      const du = dist(u);
      if (du < nd) (nd = du), (next = u);
    }
    if (next < 0) break;
    (cur = next), (d = nd);
  }
  return cur;
}

let gesture = null; // {kind: 'orbit'|'drag-sing'|'fix', x0, y0, ...}
renderer.domElement.addEventListener('pointerdown', (e) => {
  if (!surface || e.button !== 0) return;
  if (relaxing) {  // edits wait for the relaxation's replay; the view still turns
    gesture = { kind: 'orbit', x0: e.clientX, y0: e.clientY, passive: true };
    return;
  }
  if (mode === 'pin') {
    raycaster.setFromCamera(ndc(e.clientX, e.clientY), camera);
    const m = raycaster.intersectObjects(markers.children, false)[0];
    if (m) {
      gesture = { kind: 'pin', x0: e.clientX, y0: e.clientY, vertex: m.object.userData.vertex };
      return;
    }
  } else if (mode === 'sing') {
    raycaster.setFromCamera(ndc(e.clientX, e.clientY), camera);
    const m = raycaster.intersectObjects(markers.children, false)[0];
    if (m) {
      controls.enabled = false;
      const v = m.object.userData.vertex;
      gesture = { kind: 'drag-sing', x0: e.clientX, y0: e.clientY, from: v, at: v, before: cloneSession(session) };
      renderer.domElement.setPointerCapture(e.pointerId);
      return;
    }
  } else {
    const s = pickSurface(e.clientX, e.clientY);
    if (s) {
      controls.enabled = false;
      gesture = { kind: 'fix', x0: e.clientX, y0: e.clientY, face: s.face, p0: s.point, dir: null };
      renderer.domElement.setPointerCapture(e.pointerId);
      return;
    }
  }
  gesture = { kind: 'orbit', x0: e.clientX, y0: e.clientY };
});
renderer.domElement.addEventListener('pointermove', (e) => {
  if (!gesture) return;
  if (gesture.kind === 'drag-sing') {
    const v = walkTowards(gesture.at, e.clientX, e.clientY);
    if (v === gesture.at || session.sings.has(v) || isBoundaryVertex[v] || mesh.component[v] !== mesh.component[gesture.from]) return;
    const n = session.sings.get(gesture.at);
    session.sings.delete(gesture.at);
    session.sings.set(v, n);
    if (session.pins.delete(gesture.at)) session.pins.add(v); // a pin goes where its singularity goes
    gesture.at = v;
    rebuildMarkers();
    // No frame of its own: the marker is drawn with the field solved for it (showField), so that the page
    // does not render while the server solves on the same cores, and marker and field never disagree.
    requestSolve(e.timeStamp); // the newest position replaces any pending one; timed from the pointer event
  } else if (gesture.kind === 'fix') {
    const s = pickSurface(e.clientX, e.clientY);
    if (!s) return;
    const d = s.point.clone().sub(gesture.p0);
    if (d.length() < 1e-12) return;
    gesture.dir = [d.x, d.y, d.z];
    if (previewArrow) overlay.remove(previewArrow);
    previewArrow = new THREE.LineSegments(arrowSegments([[gesture.face, gesture.dir]], Math.max(2.5 * meanEdge, d.length())),
      new THREE.LineBasicMaterial({ color: 0xff3030 }));
    overlay.add(previewArrow);
    invalidate();
  }
});
renderer.domElement.addEventListener('pointerup', (e) => {
  const g = gesture;
  gesture = null;
  controls.enabled = true;
  if (!g) return;
  const moved = Math.hypot(e.clientX - g.x0, e.clientY - g.y0) > 4;
  if (g.kind === 'drag-sing') {
    if (g.at !== g.from) {
      const next = cloneSession(session);
      session = g.before; // the history entry goes from the state before the drag to the one after
      commit(`move ${formatIndex(next.sings.get(g.at), next.N)} from vertex ${g.from} to ${g.at}`, next);
    } else if (!moved) removeSingularity(g.from);
  } else if (g.kind === 'fix') {
    if (previewArrow) overlay.remove(previewArrow), (previewArrow = null);
    if (moved && g.dir) {
      const next = cloneSession(session);
      next.fixed.set(g.face, g.dir);
      commit(`fix face ${g.face}`, next);
    } else if (!moved && session.fixed.has(g.face)) {
      const next = cloneSession(session);
      next.fixed.delete(g.face);
      commit(`free face ${g.face}`, next);
    }
    invalidate();
  } else if (g.kind === 'pin') {
    if (!moved && session.sings.has(g.vertex)) togglePin(g.vertex);
  } else if (g.kind === 'orbit' && !moved && mode === 'sing' && !g.passive) {
    const v = pickVertex(e.clientX, e.clientY);
    if (v < 0) return;
    if (session.sings.has(v)) removeSingularity(v);
    else addSingularity(v);
  }
});

// --- controls -------------------------------------------------------------------------------------
function download(blob, name) {
  const a = document.createElement('a');
  a.href = URL.createObjectURL(blob);
  a.download = name;
  document.body.appendChild(a);
  a.click();
  setTimeout(() => (URL.revokeObjectURL(a.href), a.remove()), 1000);
}
async function downloadExport(format, name) {
  try {
    download(await api.exportFile(format, requestBody(session)), name);
  } catch (e) {
    status(`download: ${e.message}`);
  }
}
// toBlob right after a render reads that frame (the drawing buffer is not preserved between frames).
function viewPng() {
  draw();
  return new Promise((ok) => renderer.domElement.toBlob(ok, 'image/png'));
}
function wireControls() {
  $('N').onchange = () => setN(parseInt($('N').value, 10));
  $('mode-sing').onclick = () => setMode('sing');
  $('mode-fix').onclick = () => setMode('fix');
  $('mode-pin').onclick = () => setMode('pin');
  $('relax').onclick = relax;
  $('quads').onclick = makeQuads;
  $('showquads').onchange = drawQuads;
  $('dl-quads').onclick = () => quadMesh && download(new Blob([quadObj()], { type: 'text/plain' }), 'quads.obj');
  $('balance').onclick = balance;
  $('undo').onclick = undo;
  $('redo').onclick = redo;
  $('align').onchange = () => {
    const next = cloneSession(session);
    next.align = $('align').checked;
    commit(next.align ? 'align to the boundary' : 'stop aligning to the boundary', next);
  };
  $('clearfixed').onclick = () => {
    if (!session.fixed.size) return;
    const next = cloneSession(session);
    next.fixed.clear();
    commit('remove all fixed directions', next);
  };
  $('auto').onclick = async () => {
    status('automatic placement: solving for the smoothest field…');
    try {
      const body = requestBody(session);
      body.cancel = Math.max(0, parseFloat($('cancel').value) || 0);
      const r = await api.autoPlace(body);
      const next = cloneSession(session);
      next.sings = new Map(r.singularities.map(([v, t]) => [v, parseIndex(t, session.N)]));
      commit(`automatic placement: ${r.singularities.length} singularities`, next);
    } catch (e) {
      status(`automatic placement: ${e.message}`);
    }
  };
  $('glyphs').onchange = () => ((glyphs.object.visible = $('glyphs').checked), invalidate());
  $('spacing').oninput = invalidate;
  $('streamlines').onchange = refreshStreamlines;
  $('save').onclick = () => {
    const body = { format: 'trivcon-edit-session', version: 1, mesh: mesh.info.file, vertices: mesh.info.vertices, faces: mesh.info.faces, ...requestBody(session) };
    download(new Blob([JSON.stringify(body, null, 1)], { type: 'application/json' }), 'session.json');
  };
  $('load').onclick = () => $('loadfile').click();
  $('loadfile').onchange = async () => {
    const file = $('loadfile').files[0];
    $('loadfile').value = '';
    if (!file) return;
    try {
      const j = JSON.parse(await file.text());
      if (j.format !== 'trivcon-edit-session') throw new Error('not a session file of trivcon edit');
      if (j.vertices !== mesh.info.vertices || j.faces !== mesh.info.faces)
        throw new Error(`it was saved on a mesh of ${j.vertices} vertices and ${j.faces} faces, this one has ${mesh.info.vertices} and ${mesh.info.faces}`);
      commit(`load session ${file.name}`, sessionFromRequest(j, session.N));
    } catch (e) {
      status(`load session: ${e.message}`);
    }
  };
  $('dl-txt').onclick = () => downloadExport('txt', 'field.txt');
  $('dl-rawfield').onclick = () => downloadExport('rawfield', 'field.rawfield');
  $('dl-sing').onclick = () => downloadExport('sing', 'singularities.txt');
  $('dl-png').onclick = async () => download(await viewPng(), 'view.png');
  // In a text or number field: Enter commits it and Escape gives it up, and either leaves the field, so that
  // the keys are shortcuts again. While a field has the focus, keys are its own.
  const typing = (t) => t instanceof HTMLInputElement && t.type !== 'checkbox' && t.type !== 'range';
  $('panel').addEventListener('keydown', (e) => {
    if (!typing(e.target)) return;
    if (e.key === 'Escape') {
      e.target.value = e.target.dataset.committed ?? e.target.defaultValue;
      e.target.blur();
    } else if (e.key === 'Enter') {
      e.target.blur(); // fires its change first
    }
  });
  $('panel').addEventListener('focusin', (e) => {
    if (typing(e.target)) e.target.dataset.committed = e.target.value;
  });
  window.addEventListener('keydown', (e) => {
    if (typing(e.target) || relaxing) return;
    const key = e.key.toLowerCase();
    if ((e.ctrlKey || e.metaKey) && key === 'z') {
      e.preventDefault();
      e.shiftKey ? redo() : undo();
    } else if ((e.ctrlKey || e.metaKey) && key === 'y') {
      e.preventDefault();
      redo();
    } else if (e.ctrlKey || e.metaKey || e.altKey) {
      return;
    } else if (/^Digit[1-9]$/.test(e.code)) {
      setIndexChoice((e.shiftKey ? -1 : 1) * parseInt(e.code.slice(5), 10));
    } else if (key === 's') setMode('sing');
    else if (key === 'f') setMode('fix');
    else if (key === 'p') setMode('pin');
    else if (key === 'r') relax();
    else if (key === 'q') makeQuads();
    else if (key === 'b') balance();
    else if (key === 'l') ($('streamlines').checked = !$('streamlines').checked), refreshStreamlines();
  });
}

// --- this tab's session, kept across reloads ------------------------------------------------------
// sessionStorage belongs to this tab and this origin: a reload restores the tab's own session and history
// (not the last request of any tab, which is what the server knows), another tab starts on its own.
const TAB_KEY = 'trivcon-tab';
let saveTimer = null;
function meshId() {
  return { file: mesh.info.file, vertices: mesh.info.vertices, faces: mesh.info.faces };
}
function saveTab() {
  clearTimeout(saveTimer);
  saveTimer = null;
  if (!mesh || historyIndex < 0) return;
  let entries = history.map((h) => ({ label: h.label, detail: h.detail, body: requestBody(h.session) }));
  let index = historyIndex;
  // Too big for the storage: the oldest entries go first (the current one stays).
  for (;;) {
    try {
      sessionStorage.setItem(TAB_KEY, JSON.stringify({ token: api.token, mesh: meshId(), index, history: entries }));
      return;
    } catch (e) {
      const drop = Math.min(index, Math.ceil(entries.length / 2));
      if (drop === 0) return;
      entries = entries.slice(drop);
      index -= drop;
    }
  }
}
function saveTabSoon() {
  if (!saveTimer) saveTimer = setTimeout(saveTab, 200);
}
window.addEventListener('pagehide', saveTab);
// The saved history of this tab for this run of the editor (its token) and this mesh, or null.
function restoreTab() {
  try {
    const saved = JSON.parse(sessionStorage.getItem(TAB_KEY) || 'null');
    if (!saved || saved.token !== api.token || JSON.stringify(saved.mesh) !== JSON.stringify(meshId())) return null;
    const entries = saved.history.map((h) => ({
      label: h.label, detail: h.detail || '', session: sessionFromRequest(h.body, mesh.info.N),
    }));
    if (!entries.length || !(saved.index >= 0 && saved.index < entries.length)) return null;
    return { entries, index: saved.index };
  } catch (e) {
    return null;
  }
}

// --- start ----------------------------------------------------------------------------------------
async function start() {
  if (!api.token) {
    $('overlay').textContent = 'This page needs its token: open the URL that trivcon edit printed (with ?token=…).';
    return;
  }
  try {
    mesh = await meshPromise;
  } catch (e) {
    $('overlay').textContent = `cannot load the mesh: ${e.message}`;
    return;
  }
  const phases = { mesh_fetched: (performance.now() - tLoadStart) / 1000 };
  const info = mesh.info;
  $('meshinfo').textContent = `${info.file}: ${info.vertices} vertices, ${info.faces} faces, χ ${info.euler_characteristic}, ` +
    `${info.components.length} component(s), ${info.cycles.generators.length} generator(s), ${info.cycles.loops.length} boundary loop(s)` +
    (info.repair ? ` (${info.repair})` : '');
  const state = await statePromise;
  buildMesh();
  buildCycleList();
  resize();
  wireControls();
  phases.built = (performance.now() - tLoadStart) / 1000;
  // The first solve is asked for before the first frame is drawn (the first frame of a big mesh is slow on
  // a CPU rasterizer): the server solves while the page draws.
  const restored = restoreTab();
  if (restored) {
    history.push(...restored.entries);
    historyIndex = restored.index;
    session = cloneSession(history[historyIndex].session);
  } else {
    // A new tab starts from the command line's session.
    try {
      session = sessionFromRequest(state.initial || state.request, info.N);
    } catch (e) {
      session = emptySession(info.N);
      status(`the starting prescription: ${e.message}`);
    }
    // Ids the mesh does not have cannot be shown: they are dropped (the server said so at start).
    for (const v of [...session.sings.keys()]) if (!(v >= 0 && v < info.vertices)) session.sings.delete(v);
    history.push({ label: 'start', detail: '', session: cloneSession(session) });
    historyIndex = 0;
  }
  applySession();
  await idle();
  $('overlay').textContent = '';
  $('overlay').style.display = 'none';
  window.__trivcon.loadSeconds = (performance.now() - tLoadStart) / 1000;
  phases.first_field = window.__trivcon.loadSeconds;
  window.__trivcon.loadPhases = phases; // seconds since the script started: mesh received, scene built, first field drawn
  window.__trivcon.ready = true;
}
function idle() {
  return inflight || pending ? new Promise((r) => idleWaiters.push(r)) : Promise.resolve();
}

// For tests and the benchmark (web/tests, bench/edit_bench.mjs): read-only views of the page's state,
// and the screen position of a vertex.
window.__trivcon = {
  ready: false,
  loadSeconds: null,
  idle,
  projectVertex,
  pickVertex,
  get fieldVersion() { return fieldVersion; },
  get faces() { return mesh ? mesh.info.faces : 0; },
  async pngSize() { return (await viewPng()).size; },
  get streamlinePoints() { return streamlineObject ? streamlineObject.geometry.getAttribute('position').count : 0; },
  // The faces of the glyphs drawn now (one entry per glyph; a large face has several).
  get glyphFaces() { return glyphs && fieldOct && glyphs.object.visible ? glyphs.drawnFaces() : []; },
  // One redraw of what an edit redraws, waited for on the GPU: milliseconds (the benchmark's "drawing" alone).
  redraw(surfaceToo = false) {
    const t0 = performance.now();
    if (surfaceToo) cache.dirty = true;
    draw();
    const gl = renderer.getContext();
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
    return performance.now() - t0;
  },
  // The last drawn field, decoded: x y z per face, NaN for faces not received (the server sends the faces
  // of the glyph order up to what the view draws, at least 20000 of those with glyphs: every face of an
  // even mesh of up to 20000 faces); null when no field is on screen.
  get directions() {
    if (!fieldOct) return null;
    const out = new Float32Array(3 * mesh.info.faces).fill(NaN);
    for (let i = 0; i < fieldOct.length / 2; ++i) api.decodeOct(fieldOct, i, out, glyphs.order[i]);
    return out;
  },
  get timings() { return lastTimings; },
  get message() { return $('message').textContent; },
  get session() { return requestBody(session); },
  get historyLength() { return history.length; },
  get historyLabels() { return history.map((h) => h.label); },
  get historyIndex() { return historyIndex; },
  // The vertices whose markers are drawn as pinned, and the last relaxation's answer (POST /api/relax).
  get pinnedMarkers() { return markers.children.filter((m) => m.userData.pinned).map((m) => m.userData.vertex).sort((a, b) => a - b); },
  get lastRelax() { return lastRelax; },
  // The quad mesh on screen (POST /api/quad's answer) and the segments drawn for it (4 per quad, or 0 when hidden).
  get quads() { return quadMesh ? { report: quadMesh.report, V: Array.from(quadMesh.V), Q: Array.from(quadMesh.Q) } : null; },
  get quadSegments() { return quadObject ? quadObject.geometry.getAttribute('position').count / 2 : 0; },
  get quadInfo() { return $('quadinfo').textContent; },
};

start();
