// SPDX-License-Identifier: MIT
// The field drawn as short crosses on the surface: for even N, N/2 lines through a point; for odd N, N rays
// out of it. The vertex shader turns each face's first direction about its normal into the others, so a new
// field costs one copy of the drawn glyphs' directions and their upload.
//
// Not instanced: on a CPU rasterizer (SwiftShader, what headless Chromium has here) each instance of an
// instanced draw costs as much as a small draw of its own, so the attributes are repeated per vertex.
//
// Where the glyphs go: in proportion to area, so that a mesh of a few large faces beside a finely tessellated
// part shows the field on both (one glyph per face, or a choice by face number, leaves large faces bare).
// The server gives every face a first "time" u_f / area_f (the glyph order, server/editor_server.cpp); the
// face's j-th glyph comes at (u_f + j) / area_f, its first at the centroid and the others spread over the
// face (a low-discrepancy sequence). All glyphs sorted by time, the first ones up to time t hold about
// area_f · t glyphs of each face: t is the density, glyphs per unit area. The view draws the prefix that
// makes one glyph per `spacing` pixels, each as long as that spacing allows; the server sends the
// directions of the faces in the glyph order up to the time drawn (api.solve), so the faces of every drawn
// glyph are among them.
import * as THREE from 'three';
import { decodeOct } from './api.js';

const MAX_GLYPHS = 150000; // beyond this the glyphs would be denser than any screen shows
const MIN_DIRECTIONS = 20000; // asked for at least (room to zoom in without a new request)

// Roberts' R2 sequence: well-spread points in the unit square, folded into the triangle.
const R2_A = 1 / 1.32471795724474602596, R2_B = R2_A * R2_A;

function upperBound(sorted, value, end = sorted.length) {
  let lo = 0, hi = end;
  while (lo < hi) {
    const mid = (lo + hi) >>> 1;
    if (sorted[mid] <= value) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

export class FieldGlyphs {
  // positions/faces: the mesh; normals: per face; order/times: the server's glyph order (api.getMesh).
  constructor({ positions, faces, normals, order, times, meanEdge }) {
    const nF = faces.length / 3;
    this.nF = nF;
    this.meanEdge = meanEdge;
    this.order = order;
    this.times = times;
    const faceArea = new Float64Array(nF);
    let area = 0;
    for (let f = 0; f < nF; ++f) {
      const a = 3 * faces[3 * f], b = 3 * faces[3 * f + 1], c = 3 * faces[3 * f + 2];
      const ux = positions[b] - positions[a], uy = positions[b + 1] - positions[a + 1], uz = positions[b + 2] - positions[a + 2];
      const vx = positions[c] - positions[a], vy = positions[c + 1] - positions[a + 1], vz = positions[c + 2] - positions[a + 2];
      faceArea[f] = Math.hypot(uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx) / 2;
      area += faceArea[f];
    }
    this.area = area;
    // The glyphs up to the time of `budget` glyphs (about as many faces on an even mesh: one or two each when
    // zoomed in all the way).
    const budget = Math.min(MAX_GLYPHS, Math.max(2 * nF, MIN_DIRECTIONS));
    const tMax = area > 0 ? budget / area : 0;
    this.ranked = upperBound(times, tMax); // faces with at least one glyph
    // First glyphs come in rank order, already sorted by time; the further ones (faces larger than the
    // spacing at tMax: few, unless the mesh has large faces) are sorted apart, and the two lists merged.
    const extraTime = [], extraRank = [], extraJ = [];
    for (let r = 0; r < this.ranked; ++r) {
      const a = faceArea[order[r]];
      for (let j = 1, t = times[r] + 1 / a; t <= tMax && extraTime.length < budget; ++j, t = times[r] + j / a)
        extraTime.push(t), extraRank.push(r), extraJ.push(j);
    }
    const extra = new Uint32Array(extraTime.length);
    for (let i = 0; i < extra.length; ++i) extra[i] = i;
    extra.sort((p, q) => extraTime[p] - extraTime[q] || extraRank[p] - extraRank[q]);
    const n = this.ranked + extra.length;
    this.cap = n;
    this.time = new Float64Array(n); // ascending
    this.rank = new Uint32Array(n); // the face's place in the glyph order (where its direction is in a solve's answer)
    this.point = new Float32Array(3 * n);
    this.reach = new Uint32Array(n); // 1 + the largest rank among glyphs 0..i: glyph i is drawable once that many faces arrived
    this.maxLength = new Float32Array(n); // a glyph crosses at most a few faces of its size
    let reach = 0;
    for (let i = 0, r = 0, e = 0; i < n; ++i) {
      // The next glyph: face r's first, or the next further one, whichever comes first.
      const first = e >= extra.length || (r < this.ranked && times[r] <= extraTime[extra[e]]);
      const rank = first ? r++ : extraRank[extra[e]];
      const j = first ? 0 : extraJ[extra[e++]];
      const f = order[rank];
      this.time[i] = first ? times[rank] : extraTime[extra[e - 1]];
      this.rank[i] = rank;
      // The first at the centroid, the others spread over the face.
      let x = 1 / 3, y = 1 / 3;
      if (j > 0) {
        (x = (0.5 + j * R2_A) % 1), (y = (0.5 + j * R2_B) % 1);
        if (x + y > 1) (x = 1 - x), (y = 1 - y);
      }
      const A = 3 * faces[3 * f], B = 3 * faces[3 * f + 1], C = 3 * faces[3 * f + 2];
      for (let k = 0; k < 3; ++k)
        this.point[3 * i + k] = positions[A + k] + x * (positions[B + k] - positions[A + k]) + y * (positions[C + k] - positions[A + k]);
      reach = Math.max(reach, rank + 1);
      this.reach[i] = reach;
      this.maxLength[i] = 9 * Math.sqrt(faceArea[f]);
    }
    this.normals = normals;
    this.filled = 0; // glyphs whose direction is copied from the current field
    this.source = null;
    this.received = 0;
    this.count = 0;
    this.N = 0;
    this.material = new THREE.ShaderMaterial({
      uniforms: { uLength: { value: meanEdge * 0.4 }, uN: { value: 4 }, uLift: { value: meanEdge * 0.02 } },
      vertexShader: `
        attribute float aK;
        attribute float aT;
        attribute float aMax;
        attribute vec3 iC;
        attribute vec3 iN;
        attribute vec3 iD;
        uniform float uLength, uN, uLift;
        varying float vT;
        void main() {
          float a = 6.28318530718 * aK / uN;
          vec3 d = cos(a) * iD + sin(a) * cross(iN, iD);
          vec3 p = iC + iN * uLift + d * min(uLength, aMax) * aT;
          vT = abs(aT);
          gl_Position = projectionMatrix * modelViewMatrix * vec4(p, 1.0);
        }`,
      fragmentShader: `
        varying float vT;
        void main() { gl_FragColor = vec4(mix(vec3(0.05, 0.1, 0.35), vec3(0.15, 0.35, 0.8), vT), 1.0); }`,
    });
    this.geometry = new THREE.BufferGeometry();
    this.object = new THREE.LineSegments(this.geometry, this.material);
    this.object.frustumCulled = false;
    this.setN(4);
  }

  // Lays out the vertices for symmetry N: per glyph, `segments` segments (aK: which direction, aT: along it,
  // −1 → +1 through the point for even N, 0 → 1 for odd N).
  setN(N) {
    if (N === this.N) return;
    this.N = N;
    const even = N % 2 === 0, segments = even ? N / 2 : N, per = 2 * segments;
    this.per = per;
    const cap = this.cap;
    const k = new Float32Array(cap * per), t = new Float32Array(cap * per), m = new Float32Array(cap * per);
    const c = new Float32Array(3 * cap * per), n = new Float32Array(3 * cap * per);
    for (let g = 0; g < cap; ++g) {
      const f = this.order[this.rank[g]];
      for (let v = 0; v < per; ++v) {
        const i = g * per + v;
        k[i] = v >> 1;
        t[i] = v & 1 ? 1 : even ? -1 : 0;
        m[i] = this.maxLength[g];
        for (let x = 0; x < 3; ++x) (c[3 * i + x] = this.point[3 * g + x]), (n[3 * i + x] = this.normals[3 * f + x]);
      }
    }
    this.dir = new Float32Array(3 * cap * per);
    this.iD = new THREE.BufferAttribute(this.dir, 3);
    this.iD.setUsage(THREE.DynamicDrawUsage);
    this.geometry.setAttribute('position', new THREE.BufferAttribute(c, 3)); // three wants one; the shader uses iC
    this.geometry.setAttribute('iC', this.geometry.getAttribute('position'));
    this.geometry.setAttribute('iN', new THREE.BufferAttribute(n, 3));
    this.geometry.setAttribute('iD', this.iD);
    this.geometry.setAttribute('aK', new THREE.BufferAttribute(k, 1));
    this.geometry.setAttribute('aT', new THREE.BufferAttribute(t, 1));
    this.geometry.setAttribute('aMax', new THREE.BufferAttribute(m, 1));
    this.material.uniforms.uN.value = N;
    this.filled = 0;
    this.fill(this.count);
  }

  // `oct`: the server's octahedral encoding of the directions of the first `received` faces of the glyph
  // order (src/api.js), decoded for drawn glyphs only.
  setDirections(oct, received, N) {
    this.source = oct;
    this.received = received;
    this.filled = 0;
    this.setN(N);
    this.fill(Math.max(this.count, 1));
    this.geometry.setDrawRange(0, this.drawn() * this.per);
  }

  // No field (none solved yet for this symmetry): nothing drawn.
  clear() {
    this.source = null;
    this.received = 0;
    this.filled = 0;
    this.geometry.setDrawRange(0, 0);
  }

  // How many of the first glyphs have their face's direction.
  usable() {
    return this.source ? upperBound(this.reach, this.received) : 0;
  }
  drawn() {
    return Math.min(this.count, this.usable());
  }

  // Copies the current field's directions into the first `count` glyphs and uploads just those.
  fill(count) {
    if (!this.source) return;
    count = Math.min(count, this.usable());
    if (count <= this.filled) return;
    const { dir, source, per, rank } = this;
    const d = new Float32Array(3);
    for (let g = this.filled; g < count; ++g) {
      decodeOct(source, rank[g], d, 0);
      for (let v = 0, i = 3 * g * per; v < per; ++v, i += 3) (dir[i] = d[0]), (dir[i + 1] = d[1]), (dir[i + 2] = d[2]);
    }
    this.iD.clearUpdateRanges();
    this.iD.addUpdateRange(3 * per * this.filled, 3 * per * (count - this.filled));
    this.iD.needsUpdate = true;
    this.filled = count;
  }

  // The density (glyphs per unit area) of one glyph per `spacingPx` pixels, for this camera and viewport
  // height (CSS pixels): half the surface faces the camera, at about half its area on average.
  density(camera, heightPx, spacingPx) {
    const distance = camera.position.distanceTo(camera.userData.target || new THREE.Vector3());
    const worldPerPixel = (2 * distance * Math.tan((camera.fov * Math.PI) / 360)) / Math.max(1, heightPx);
    const spacing = spacingPx * worldPerPixel;
    return 1 / (2 * spacing * spacing);
  }

  // Chooses how many glyphs to draw for this camera and viewport.
  adapt(camera, heightPx, spacingPx) {
    const t = this.density(camera, heightPx, spacingPx);
    this.t = t;
    this.count = Math.max(1, upperBound(this.time, t));
    this.fill(this.count);
    this.geometry.setDrawRange(0, this.drawn() * this.per);
    // Each glyph as long as its share of the surface allows (and at most a few times its face's size).
    this.material.uniforms.uLength.value = 0.42 / Math.sqrt(Math.max(t, 1 / Math.max(this.area, 1e-300)));
  }

  // The faces of the glyphs drawn now (for tests).
  drawnFaces() {
    const out = [];
    for (let g = 0; g < this.drawn(); ++g) out.push(this.order[this.rank[g]]);
    return out;
  }
}

// How many directions to ask the server for: the faces of the glyphs the view draws at twice its density
// (room to zoom in a little), at least MIN_DIRECTIONS.
export function wantedDirections(glyphs) {
  const t = glyphs.t ?? 0;
  const faces = glyphs.ranked;
  return Math.min(faces, Math.max(upperBound(glyphs.times, 2 * t, faces), Math.min(faces, MIN_DIRECTIONS)));
}
