// The field drawn as short crosses at the faces' centroids: for even N, N/2 lines through the centroid;
// for odd N, N rays out of it. The vertex shader turns each face's first direction about its normal into
// the others, so a new field costs one copy of the drawn faces' directions and their upload.
//
// Not instanced: on a CPU rasterizer (SwiftShader, what headless Chromium has here) each instance of an
// instanced draw costs as much as a small draw of its own, so the attributes are repeated per vertex.
//
// Density adapts to the screen: faces are drawn in a fixed spread-out order, as many as make one glyph per
// `spacing` pixels over the surface's projected area, each as long as that spacing allows.
import * as THREE from 'three';
import { decodeOct } from './api.js';

const MAX_GLYPHS = 150000; // beyond this the glyphs would be denser than any screen shows

export class FieldGlyphs {
  constructor(centroids, normals, area, meanEdge) {
    const nF = centroids.length / 3;
    this.nF = nF;
    this.area = area;
    this.meanEdge = meanEdge;
    this.centroids = centroids;
    this.normals = normals;
    // The faces in the order i · stride mod F, stride coprime with F near F / φ: consecutive glyphs land
    // far apart in the id order, which on most meshes means far apart on the surface. The server sends the
    // directions in this order (api.solve), only as many as are drawn.
    let stride = Math.max(1, Math.round(nF * 0.6180339887));
    const gcd = (a, b) => (b ? gcd(b, a % b) : a);
    while (gcd(stride, nF) !== 1) ++stride;
    this.stride = nF > 1 ? stride : 1;
    const order = new Uint32Array(nF);
    for (let i = 0; i < nF; ++i) order[i] = (i * this.stride) % nF;
    this.order = order;
    this.cap = Math.min(nF, MAX_GLYPHS);
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
        attribute vec3 iC;
        attribute vec3 iN;
        attribute vec3 iD;
        uniform float uLength, uN, uLift;
        varying float vT;
        void main() {
          float a = 6.28318530718 * aK / uN;
          vec3 d = cos(a) * iD + sin(a) * cross(iN, iD);
          vec3 p = iC + iN * uLift + d * uLength * aT;
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
  // −1 → +1 through the centroid for even N, 0 → 1 for odd N).
  setN(N) {
    if (N === this.N) return;
    this.N = N;
    const even = N % 2 === 0, segments = even ? N / 2 : N, per = 2 * segments;
    this.per = per;
    const cap = this.cap;
    const k = new Float32Array(cap * per), t = new Float32Array(cap * per);
    const c = new Float32Array(3 * cap * per), n = new Float32Array(3 * cap * per);
    for (let g = 0; g < cap; ++g) {
      const f = this.order[g];
      for (let v = 0; v < per; ++v) {
        const i = g * per + v;
        k[i] = v >> 1;
        t[i] = v & 1 ? 1 : even ? -1 : 0;
        for (let x = 0; x < 3; ++x) (c[3 * i + x] = this.centroids[3 * f + x]), (n[3 * i + x] = this.normals[3 * f + x]);
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
    this.material.uniforms.uN.value = N;
    this.filled = 0;
    this.fill(this.count);
  }

  // `oct`: the server's octahedral encoding of the directions of the first `received` faces of the order
  // (src/api.js), decoded for drawn faces only.
  setDirections(oct, received, N) {
    this.source = oct;
    this.received = received;
    this.filled = 0;
    this.setN(N);
    this.fill(Math.max(this.count, 1));
  }

  // Copies the current field's directions into the first `count` glyphs and uploads just those.
  fill(count) {
    if (!this.source || count <= this.filled) return;
    const { dir, source, per } = this;
    const d = new Float32Array(3);
    count = Math.min(count, this.received);
    if (count <= this.filled) return;
    for (let g = this.filled; g < count; ++g) {
      decodeOct(source, g, d, 0);
      for (let v = 0, i = 3 * g * per; v < per; ++v, i += 3) (dir[i] = d[0]), (dir[i + 1] = d[1]), (dir[i + 2] = d[2]);
    }
    this.iD.clearUpdateRanges();
    this.iD.addUpdateRange(3 * per * this.filled, 3 * per * (count - this.filled));
    this.iD.needsUpdate = true;
    this.filled = count;
  }

  // Chooses how many glyphs to draw for this camera and viewport height (CSS pixels).
  adapt(camera, heightPx, spacingPx) {
    const distance = camera.position.distanceTo(camera.userData.target || new THREE.Vector3());
    const worldPerPixel = (2 * distance * Math.tan((camera.fov * Math.PI) / 360)) / Math.max(1, heightPx);
    const spacing = spacingPx * worldPerPixel;
    // Half the surface faces the camera, at about half its area on average.
    const wanted = Math.ceil(this.area / (spacing * spacing) / 2);
    const count = Math.max(1, Math.min(this.cap, wanted));
    this.count = count;
    this.fill(count);
    this.geometry.setDrawRange(0, this.source ? Math.min(count, this.received) * this.per : 0);
    // Each glyph as long as its share of the surface allows, never much longer than a few faces.
    const share = Math.sqrt(this.area / Math.min(count, this.nF));
    this.material.uniforms.uLength.value = Math.min(0.42 * share, 6 * this.meanEdge);
  }
}

// How many directions to ask the server for: what the view draws, with room to zoom in a little.
export function wantedDirections(glyphs) {
  return Math.min(glyphs.cap, Math.max(2 * glyphs.count, 20000));
}
