// SPDX-License-Identifier: MIT
// Browser tests of `trivcon edit`: the real program serving the real page, driven in headless Chromium
// (puppeteer-core, Debian's /usr/bin/chromium, WebGL through SwiftShader: see ../../../shared/notes/browser.md).
//   node web/tests/run.mjs [--trivcon PATH] [--mesh PATH --sing PATH]
// Every check asserts a property of the page or of the server's state; nothing depends on timing.
import { spawn } from 'node:child_process';
import { once } from 'node:events';
import { dirname, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import assert from 'node:assert/strict';
import { readFileSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import puppeteer from 'puppeteer-core';

const here = dirname(fileURLToPath(import.meta.url));
const root = resolve(here, '../..');
const args = process.argv.slice(2);
const opt = (name, fallback) => (args.includes(name) ? args[args.indexOf(name) + 1] : fallback);
const trivcon = opt('--trivcon', resolve(root, 'build/trivcon'));
const meshPath = opt('--mesh', resolve(root, 'data/cube_sphere.obj'));
const singPath = opt('--sing', resolve(root, 'data/cube_sphere.sing'));

// A mesh of two flat squares side by side: one of two triangles, one of 2 n² (a CAD part's large faces next
// to a finely tessellated region).
function writeUnevenMesh(path, n = 100) {
  const v = [[-1.2, 0, 0], [-0.2, 0, 0], [-0.2, 1, 0], [-1.2, 1, 0]], f = [[1, 2, 3], [1, 3, 4]];
  const id = (i, j) => 5 + j * (n + 1) + i;
  for (let j = 0; j <= n; ++j) for (let i = 0; i <= n; ++i) v.push([i / n, j / n, 0]);
  for (let j = 0; j < n; ++j)
    for (let i = 0; i < n; ++i) f.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)], [id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
  writeFileSync(path, v.map((p) => `v ${p.join(' ')}\n`).join('') + f.map((t) => `f ${t.join(' ')}\n`).join(''));
}

// Pixels of the field's colour (blue) in a screenshot, within the clip.
async function fieldPixels(page, clip) {
  const shot = await page.screenshot({ clip, encoding: 'base64' });
  return page.evaluate(async (b64) => {
    const img = new Image();
    img.src = `data:image/png;base64,${b64}`;
    await img.decode();
    const c = document.createElement('canvas');
    c.width = img.width, c.height = img.height;
    const g = c.getContext('2d');
    g.drawImage(img, 0, 0);
    const d = g.getImageData(0, 0, c.width, c.height).data;
    let field = 0;
    for (let i = 0; i < d.length; i += 4) field += d[i + 2] > d[i] + 40 && d[i + 2] > d[i + 1] + 30; // not the green fixed arrows
    return field;
  }, shot);
}

// Starts `trivcon edit` on a free port; resolves with the printed URL.
export async function startEditor(program, extra) {
  const child = spawn(program, ['edit', ...extra, '--port', '0'], { stdio: ['ignore', 'pipe', 'pipe'] });
  let out = '', err = '';
  child.stderr.on('data', (d) => (err += d));
  const url = await new Promise((ok, fail) => {
    child.stdout.on('data', (d) => {
      out += d;
      const m = /(http:\/\/\S+\?token=[0-9a-f]+)/.exec(out);
      if (m) ok(m[1]);
    });
    child.on('exit', (code) => fail(new Error(`trivcon edit exited (${code}) before printing its URL: ${err}`)));
  });
  return { child, url, token: new URL(url).searchParams.get('token'), stderr: () => err };
}

export async function launchBrowser() {
  return puppeteer.launch({
    executablePath: '/usr/bin/chromium',
    headless: true,
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--window-size=1200,800'],
  });
}

const results = [];
async function check(name, fn) {
  try {
    await fn();
    results.push([name, true]);
    console.log(`ok   ${name}`);
  } catch (e) {
    results.push([name, false]);
    console.log(`FAIL ${name}\n     ${e.stack.split('\n').slice(0, 3).join('\n     ')}`);
  }
}

async function main() {
  const editor = await startEditor(trivcon, [meshPath, '-N', '4', '-s', singPath]);
  const api = async (path) => {
    const res = await fetch(new URL(path, editor.url), { headers: { 'X-Trivcon-Token': editor.token } });
    assert.equal(res.status, 200, `${path}: HTTP ${res.status}`);
    return res.json();
  };
  const browser = await launchBrowser();
  const page = await browser.newPage();
  await page.setViewport({ width: 1200, height: 800 });
  const pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(e.message));
  try {
    await page.goto(editor.url);
    await page.waitForFunction(() => window.__trivcon && window.__trivcon.ready, { timeout: 120000 });
    const T = (expr) => page.evaluate(expr);
    const idle = () => page.evaluate(() => window.__trivcon.idle());
    const directions = () => page.evaluate(() => Array.from(window.__trivcon.directions));
    const singularities = () => page.evaluate(() => window.__trivcon.session.singularities);
    const view = await page.evaluate(() => {
      const r = document.getElementById('view').getBoundingClientRect();
      return { x: r.left, y: r.top, w: r.width, h: r.height };
    });
    const mesh = await api('/api/mesh');

    await check('the token is kept out of the address bar, the history and cookies', async () => {
      assert.equal(new URL(page.url()).search, '');
      assert.equal(await T(() => location.href.includes('token')), false);
      assert.equal(await T(() => document.cookie), '');
      assert.equal(await T(() => sessionStorage.getItem('trivcon-token')), editor.token);
      // A page without it (another tab, no token in its address) says what it needs and calls nothing.
      const context = await browser.createBrowserContext();
      const bare = await context.newPage();
      const calls = [];
      bare.on('request', (r) => r.url().includes('/api/') && calls.push(r.url()));
      await bare.goto(new URL('/', editor.url).href);
      await bare.waitForFunction(() => /needs its token/.test(document.getElementById('overlay').textContent), { timeout: 30000 });
      assert.deepEqual(calls, []);
      await context.close();
    });

    let start = null;
    await check('the page loads the mesh and draws a field of unit vectors, one per face', async () => {
      assert.equal(await T(() => window.__trivcon.message), '');
      assert.ok((await T(() => window.__trivcon.fieldVersion)) >= 1);
      start = await directions();
      assert.equal(start.length, 3 * mesh.faces.length);
      for (let f = 0; f < mesh.faces.length; ++f) assert.ok(Math.abs(Math.hypot(start[3 * f], start[3 * f + 1], start[3 * f + 2]) - 1) < 1e-5);
      // The session starts with the singularities of -s.
      const file = readFileSync(singPath, 'utf8').split('\n').filter((l) => l.trim() && !l.startsWith('#')).map((l) => l.trim().split(/\s+/));
      assert.deepEqual(await singularities(), file.map(([v, i]) => [+v, i]).sort((a, b) => a[0] - b[0]));
    });

    await check('a screenshot is not blank: the surface and the crosses are drawn', async () => {
      const shot = await page.screenshot({ clip: { x: view.x, y: view.y, width: view.w, height: view.h }, encoding: 'base64' });
      const counts = await page.evaluate(async (b64) => {
        const img = new Image();
        img.src = `data:image/png;base64,${b64}`;
        await img.decode();
        const c = document.createElement('canvas');
        c.width = img.width, c.height = img.height;
        const g = c.getContext('2d');
        g.drawImage(img, 0, 0);
        const d = g.getImageData(0, 0, c.width, c.height).data;
        let surface = 0, field = 0;
        for (let i = 0; i < d.length; i += 4) {
          const [r, gr, b] = [d[i], d[i + 1], d[i + 2]];
          if (Math.abs(r - 0xf4) + Math.abs(gr - 0xf4) + Math.abs(b - 0xf2) > 30) surface++;
          if (b > r + 40) field++;
        }
        return { surface, field, total: d.length / 4 };
      }, shot);
      assert.ok(counts.surface > counts.total * 0.1, `only ${counts.surface} non-background pixels`);
      assert.ok(counts.field > 500, `only ${counts.field} field-coloured pixels`);
    });

    // Two vertices near the middle of the view, away from the starting singularities.
    const at = async (fx, fy) => page.evaluate((x, y) => window.__trivcon.pickVertex(x, y), view.x + fx * view.w, view.y + fy * view.h);
    const A = await at(0.42, 0.45), B = await at(0.58, 0.55);
    const pos = (v) => page.evaluate((u) => window.__trivcon.projectVertex(u), v);

    let afterB = null;
    // Where the panel's sections are (in the panel's own scrolled content): an edit must not move them.
    const layout = () => page.evaluate(() => {
      const panel = document.getElementById('panel');
      return [...panel.querySelectorAll('h2, button')].map((e) => Math.round(e.getBoundingClientRect().top + panel.scrollTop));
    });
    await check('an unbalanced set shows what to add and keeps the last field', async () => {
      assert.notEqual(A, B);
      const version = await T(() => window.__trivcon.fieldVersion);
      const before = await layout();
      await page.keyboard.down('Shift');
      await page.keyboard.press('Digit1'); // palette: −1/4
      await page.keyboard.up('Shift');
      const p = await pos(A);
      await page.mouse.click(p.x, p.y);
      await idle();
      assert.deepEqual((await singularities()).find((s) => s[0] === A), [A, '-1/4']);
      const message = await T(() => window.__trivcon.message);
      assert.match(message, /add 1\/4 on component 0/);
      assert.match(message, /The last valid field is shown\./);
      assert.deepEqual(await layout(), before, 'the panel moved');
      assert.equal(await T(() => window.__trivcon.fieldVersion), version);
      assert.deepEqual(await directions(), start);
      const state = await api('/api/state');
      assert.equal(state.solved, false);
      assert.match(state.error, /Gauss-Bonnet/);
    });

    await check('a click at the screen position of a vertex adds a singularity there; the server has it and the field changes', async () => {
      await page.keyboard.press('Digit1'); // palette: +1/4
      const p = await pos(B);
      await page.mouse.click(p.x, p.y);
      await idle();
      // Σ = 2 − 1/4 + 1/4 = 2: balanced again.
      assert.deepEqual((await singularities()).find((s) => s[0] === B), [B, '1/4']);
      assert.equal(await T(() => window.__trivcon.message), '');
      const state = await api('/api/state');
      assert.equal(state.solved, true);
      assert.ok(state.last_solved.singularities.some(([v, i]) => v === B && i === '1/4'));
      assert.ok(state.last_solved.singularities.some(([v, i]) => v === A && i === '-1/4'));
      afterB = await directions();
      let changed = 0;
      for (let i = 0; i < afterB.length; ++i) changed += Math.abs(afterB[i] - start[i]) > 1e-3;
      assert.ok(changed > 30, `only ${changed} direction components changed`);
    });

    let movedTo = -1;
    await check('dragging a singularity moves it, re-solving as it goes', async () => {
      const p = await pos(B);
      const before = await T(() => window.__trivcon.fieldVersion);
      await page.mouse.move(p.x, p.y);
      await page.mouse.down();
      for (let k = 1; k <= 10; ++k) await page.mouse.move(p.x + 8 * k, p.y - 5 * k);
      await page.mouse.up();
      await idle();
      const sing = await singularities();
      assert.ok(!sing.some(([v]) => v === B), 'the singularity left its vertex');
      const moved = sing.filter(([v, i]) => i === '1/4' && v !== B && ![0, 16].includes(v));
      const target = await page.evaluate((x, y) => window.__trivcon.pickVertex(x, y), p.x + 80, p.y - 50);
      movedTo = sing.find(([v]) => v === target) ? target : -1;
      assert.ok(movedTo >= 0, `no singularity at the vertex under the pointer (${target}); have ${JSON.stringify(moved)}`);
      assert.ok((await T(() => window.__trivcon.fieldVersion)) > before);
      const state = await api('/api/state');
      assert.ok(state.last_solved.singularities.some(([v]) => v === movedTo));
      assert.ok(!state.last_solved.singularities.some(([v]) => v === B));
      assert.equal(await T(() => window.__trivcon.historyIndex), 3); // start, add A, add B, one entry for the whole drag
    });

    await check('undo restores the previous field, redo the moved one', async () => {
      const moved = await directions();
      await page.keyboard.down('Control');
      await page.keyboard.press('KeyZ');
      await page.keyboard.up('Control');
      await idle();
      assert.ok((await singularities()).some(([v]) => v === B));
      const back = await directions();
      for (let i = 0; i < back.length; ++i) assert.ok(Math.abs(back[i] - afterB[i]) < 1e-5, `direction ${i} differs after undo`);
      await page.keyboard.down('Control');
      await page.keyboard.down('Shift');
      await page.keyboard.press('KeyZ');
      await page.keyboard.up('Shift');
      await page.keyboard.up('Control');
      await idle();
      assert.ok((await singularities()).some(([v]) => v === movedTo));
      const again = await directions();
      for (let i = 0; i < again.length; ++i) assert.ok(Math.abs(again[i] - moved[i]) < 1e-5);
    });

    await check('clicking a singularity removes it', async () => {
      const p = await pos(A);
      await page.mouse.click(p.x, p.y);
      await idle();
      assert.ok(!(await singularities()).some(([v]) => v === A));
      assert.match(await T(() => window.__trivcon.message), /add -1\/4 on component 0/);
    });

    await check('balance places the missing index', async () => {
      await page.click('#balance');
      await idle();
      assert.equal(await T(() => window.__trivcon.message), '');
      // 8 corners and the moved +1/4: Σ 9/4, so balance adds −1/4.
      const sing = await singularities();
      assert.equal(sing.length, 10);
      assert.equal(sing.filter(([, i]) => i === '-1/4').length, 1);
      assert.equal((await api('/api/state')).solved, true);
    });

    await check('a pinned singularity is drawn as such; relax moves the others downhill, the pinned one stays, undo is one step', async () => {
      const before = await singularities();
      await page.keyboard.press('KeyP');
      const p = await pos(movedTo);
      await page.mouse.click(p.x, p.y);
      await idle();
      assert.deepEqual((await T(() => window.__trivcon.session)).pins, [movedTo]);
      assert.deepEqual(await T(() => window.__trivcon.pinnedMarkers), [movedTo]);
      const entries = await T(() => window.__trivcon.historyLength);
      await page.click('#relax');
      await page.waitForFunction((n) => window.__trivcon.historyLength > n, { timeout: 60000 }, entries);
      await idle();
      const r = await T(() => window.__trivcon.lastRelax);
      assert.ok(r.moves.length >= 1, 'nothing moved');
      assert.ok(r.converged);
      assert.ok(r.energy_after < r.energy_before);
      for (let k = 1; k < r.moves.length; ++k) assert.ok(r.moves[k].energy < r.moves[k - 1].energy);
      assert.ok(r.moves.every((m) => m.from !== movedTo && m.to !== movedTo));
      const after = await singularities();
      assert.deepEqual(after, r.singularities);
      assert.ok(after.some(([v, i]) => v === movedTo && i === '1/4'), 'the pinned singularity moved');
      const indices = (list) => list.map(([, i]) => i).sort();
      assert.deepEqual(indices(after), indices(before));
      assert.deepEqual(await T(() => window.__trivcon.pinnedMarkers), [movedTo]);
      const labels = await T(() => window.__trivcon.historyLabels);
      assert.match(labels[labels.length - 1], /^relax: \d+ moves?, energy /);
      assert.equal(await T(() => window.__trivcon.historyLength), entries + 1);
      const state = await api('/api/state');
      assert.equal(state.solved, true);
      assert.deepEqual(state.last_solved.singularities, r.singularities);
      // One undo gives the set before the relaxation back.
      await page.keyboard.down('Control');
      await page.keyboard.press('KeyZ');
      await page.keyboard.up('Control');
      await idle();
      assert.deepEqual(await singularities(), before);
      await page.keyboard.down('Control');
      await page.keyboard.down('Shift');
      await page.keyboard.press('KeyZ');
      await page.keyboard.up('Shift');
      await page.keyboard.up('Control');
      await idle();
      assert.deepEqual(await singularities(), r.singularities);
      await page.keyboard.press('KeyS');
    });

    await check('POST /api/relax names what is wrong with a body', async () => {
      const before8 = () => readFileSync(singPath, 'utf8').split('\n').filter((l) => l.trim() && !l.startsWith('#'))
        .map((l) => l.trim().split(/\s+/)).map(([v, i]) => [+v, i]);
      const post = (body) => fetch(new URL('/api/relax', editor.url), {
        method: 'POST', headers: { 'X-Trivcon-Token': editor.token, 'Content-Type': 'application/json' }, body: JSON.stringify(body),
      });
      const bad = await post({ N: 4, singularities: before8(), pins: [-1] });
      assert.equal(bad.status, 400);
      assert.match((await bad.json()).error, /pins\[0\]: expected a vertex id from 0 to \d+, got -1/);
      const unbalanced = await post({ N: 4, singularities: [[0, '1/4']] });
      assert.equal(unbalanced.status, 400);
      assert.match((await unbalanced.json()).error, /Gauss-Bonnet/);
      const ok = await post({ N: 4, singularities: before8(), max_moves: 0 });
      assert.equal(ok.status, 200);
      const j = await ok.json();
      assert.deepEqual(j.moves, []);
      assert.equal(j.converged, false);
    });

    await check('automatic placement gives a balanced set the server solves', async () => {
      const entries = await T(() => window.__trivcon.historyLength);
      await page.click('#auto');
      await page.waitForFunction((n) => window.__trivcon.historyLength > n, { timeout: 60000 }, entries);
      await idle();
      assert.equal(await T(() => window.__trivcon.message), '');
      assert.equal((await api('/api/state')).solved, true);
    });

    await check('quads: the quad mesh of the field is drawn with its numbers, its irregular vertices exactly the singularities', async () => {
      const sing = await singularities();
      await page.click('#quads');
      await page.waitForFunction(() => window.__trivcon.quads !== null, { timeout: 60000 });
      const q = await T(() => window.__trivcon.quads);
      const r = q.report.quad;
      assert.deepEqual(r.problems, []);
      assert.equal(r.singular_mismatches, 0);
      assert.equal(r.irregular_vertices, sing.length);
      assert.equal(q.Q.length, 4 * r.quads);
      assert.equal(q.V.length, 3 * r.vertices);
      assert.ok(r.quads > 1000 && r.quads < 3000, `${r.quads} quads for a target of 2000`);
      // From the quads alone: only quads of 4 distinct vertices, each edge in two quads, chi 2 (a sphere).
      const edges = new Map();
      for (let f = 0; f < r.quads; ++f) {
        const c = q.Q.slice(4 * f, 4 * f + 4);
        assert.equal(new Set(c).size, 4);
        for (let k = 0; k < 4; ++k) {
          const a = Math.min(c[k], c[(k + 1) % 4]), b = Math.max(c[k], c[(k + 1) % 4]);
          edges.set(`${a},${b}`, (edges.get(`${a},${b}`) || 0) + 1);
        }
      }
      assert.ok([...edges.values()].every((n) => n === 2));
      assert.equal(r.vertices - edges.size + r.quads, 2);
      assert.equal(await T(() => window.__trivcon.quadSegments), 4 * r.quads);
      assert.match(await T(() => window.__trivcon.quadInfo), new RegExp(`^${r.quads} quads \\(target 2000\\), ${sing.length} irregular vertices \\(all at the singularities\\)`));
      // The worst corners: how many quads have a flat or reflex one (the report's count).
      assert.ok(Number.isInteger(r.nonconvex_quads));
      assert.match(await T(() => window.__trivcon.quadInfo), new RegExp(`, ${r.nonconvex_quads} with a flat or reflex corner`));
      // Clean at the target: made at the edge length asked for (map_field tries others only when it keeps problems).
      assert.equal(q.report.map_scale, 1);
      assert.doesNotMatch(await T(() => window.__trivcon.quadInfo), /made at/);
      assert.equal(await T(() => document.getElementById('dl-quads').disabled), false);
      await page.click('#showquads');
      assert.equal(await T(() => window.__trivcon.quadSegments), 0);
      await page.click('#showquads');
      assert.equal(await T(() => window.__trivcon.quadSegments), 4 * r.quads);
      // The API refuses what it cannot do, with a message.
      const post = (body) => fetch(new URL('/api/quad', editor.url), {
        method: 'POST', headers: { 'X-Trivcon-Token': editor.token, 'Content-Type': 'application/json' }, body: JSON.stringify(body),
      });
      const six = await post({ N: 6, singularities: [], target_faces: 100 });
      assert.equal(six.status, 400);
      assert.match((await six.json()).error, /quads need a cross field \(N = 4\), not N = 6/);
      const none = await post({ N: 4, singularities: sing });
      assert.equal(none.status, 400);
      assert.match((await none.json()).error, /target_faces: expected the number of quads wanted, from 1 to \d+, got nothing/);
    });

    await check('a fixed direction dragged on a face is held by the field', async () => {
      await page.keyboard.press('KeyF');
      const c = { x: view.x + 0.5 * view.w, y: view.y + 0.5 * view.h };
      await page.mouse.move(c.x, c.y);
      await page.mouse.down();
      for (let k = 1; k <= 5; ++k) await page.mouse.move(c.x + 6 * k, c.y);
      // The re-factoring shows its progress: a bar and a status line, both gone when the field arrives.
      await page.evaluate(() => {
        window.__progressSeen = [];
        new MutationObserver(() => {
          const bar = document.getElementById('progress');
          if (!bar.hidden) window.__progressSeen.push(document.getElementById('status').textContent);
        }).observe(document.getElementById('panel'), { subtree: true, childList: true, attributes: true, characterData: true });
      });
      await page.mouse.up();
      await idle();
      const seen = await page.evaluate(() => window.__progressSeen);
      assert.equal(await T(() => window.__trivcon.quads), null, 'an edit leaves no stale quads on screen');
      assert.match(await T(() => window.__trivcon.quadInfo), /the field changed; make them again/);
      assert.ok(seen.some((t) => /^re-factoring for 1 fixed face\(s\)… \d+\.\d s of about \d+\.\d s$/.test(t)), JSON.stringify(seen));
      assert.equal(await page.evaluate(() => document.getElementById('progress').hidden), true);
      assert.match(await page.evaluate(() => document.getElementById('status').textContent), /^solved: energy \S+ · field exact$/);
      const fixed = await page.evaluate(() => window.__trivcon.session.fixed);
      assert.equal(fixed.length, 1);
      const state = await api('/api/state');
      assert.equal(state.solved, true);
      assert.equal(state.last_solved.fixed.length, 1);
      const [f, want] = state.last_solved.fixed[0];
      const d = await directions();
      // Equal modulo quarter turns: |cos| of the angle is 1 or 0.
      const dot = (d[3 * f] * want[0] + d[3 * f + 1] * want[1] + d[3 * f + 2] * want[2]) / Math.hypot(...want);
      assert.ok(Math.abs(Math.abs(dot) - 1) < 1e-4 || Math.abs(dot) < 1e-2, `fixed face ${f}: cos ${dot}`);
      await page.keyboard.press('KeyS');
    });

    await check('streamlines are drawn on request (L)', async () => {
      const answer = page.waitForResponse((r) => r.url().includes('/api/streamlines'));
      await page.keyboard.press('KeyL');
      assert.equal((await answer).status(), 200);
      await page.waitForFunction(() => window.__trivcon.streamlinePoints > 0, { timeout: 60000 });
      await page.keyboard.press('KeyL');
      await page.waitForFunction(() => window.__trivcon.streamlinePoints === 0, { timeout: 60000 });
    });

    await check('the downloads are the server\'s files of the current session', async () => {
      const session = await page.evaluate(() => window.__trivcon.session);
      // The page asks the server for each file (puppeteer does not keep a download's body: it is fetched again below).
      for (const [button, name] of [['#dl-txt', 'field.txt'], ['#dl-rawfield', 'field.rawfield'], ['#dl-sing', 'singularities.txt']]) {
        const answer = page.waitForResponse((r) => r.url().includes('/api/export'));
        await page.click(button);
        const res = await answer;
        assert.equal(res.status(), 200, button);
        assert.match(res.headers()['content-disposition'], new RegExp(name.replace('.', '\\.')), button);
      }
      const file = async (format) => (await fetch(new URL(`/api/export?format=${format}`, editor.url), {
        method: 'POST', headers: { 'X-Trivcon-Token': editor.token, 'Content-Type': 'application/json' }, body: JSON.stringify(session),
      })).text();
      const txt = await file('txt');
      assert.match(txt, /^# trivcon field.*\n# N 4\n# faces 3072\n/);
      assert.equal(txt.trim().split('\n').filter((l) => !l.startsWith('#')).length, 3072);
      assert.match(await file('rawfield'), /^4 3072\n/);
      const sing = await file('sing');
      assert.equal(sing.split('\n').filter((l) => l && !l.startsWith('#')).length, session.singularities.length);
    });

    await check('a saved session loads back (singularities, fixed directions, N)', async () => {
      const saved = await page.evaluate(() => window.__trivcon.session);
      const entries = await T(() => window.__trivcon.historyLength);
      // The file the page's "save session" writes, made from the same state, then loaded through the file dialog.
      const file = resolve(tmpdir(), `trivcon-session-${process.pid}.json`);
      writeFileSync(file, JSON.stringify({ format: 'trivcon-edit-session', version: 1, vertices: mesh.vertices.length, faces: mesh.faces.length, ...saved,
        singularities: saved.singularities.slice(0, 8).map(([v]) => [v, '1/4']) }));
      const chooser = page.waitForFileChooser();
      await page.click('#load');
      await (await chooser).accept([file]);
      await page.waitForFunction((n) => window.__trivcon.historyLength > n, { timeout: 60000 }, entries);
      await idle();
      const loaded = await page.evaluate(() => window.__trivcon.session);
      assert.deepEqual(loaded.singularities, saved.singularities.slice(0, 8).map(([v]) => [v, '1/4']).sort((a, b) => a[0] - b[0]));
      assert.deepEqual(loaded.fixed.map(([f]) => f), saved.fixed.map(([f]) => f));
      assert.equal((await api('/api/state')).solved, true);
    });

    await check('a reload of the tab restores its singularities and its undo history (and needs no token in the address)', async () => {
      await idle();
      const session = () => page.evaluate(() => window.__trivcon.session);
      const key = async (k) => {
        await page.keyboard.down('Control');
        await page.keyboard.press(k);
        await page.keyboard.up('Control');
        await idle();
      };
      await key('KeyZ');
      const previous = await session();
      await key('KeyY');
      const saved = await session();
      const labels = await T(() => window.__trivcon.historyLabels);
      const index = await T(() => window.__trivcon.historyIndex);
      assert.ok(labels.length > 5);
      await page.reload();
      await page.waitForFunction(() => window.__trivcon && window.__trivcon.ready, { timeout: 120000 });
      assert.equal(new URL(page.url()).search, '');
      assert.deepEqual(await page.evaluate(() => window.__trivcon.session), saved);
      assert.deepEqual(await T(() => window.__trivcon.historyLabels), labels);
      assert.equal(await T(() => window.__trivcon.historyIndex), index);
      assert.equal(await T(() => window.__trivcon.message), '');
      // Undo and redo go through this tab's own history.
      await key('KeyZ');
      assert.equal(await T(() => window.__trivcon.historyIndex), index - 1);
      assert.deepEqual(await session(), previous);
      await key('KeyY');
      assert.deepEqual(await session(), saved);
    });

    const typeIn = async (selector, text) => {
      await page.click(selector, { clickCount: 3 });
      await page.keyboard.type(text);
      await page.keyboard.press('Enter');
    };
    await check('after typing in the N box (Enter), the keys are shortcuts again', async () => {
      await typeIn('#N', '4'); // the same N: no edit
      assert.equal(await T(() => document.activeElement === document.getElementById('N')), false);
      await page.keyboard.press('KeyF');
      assert.equal(await T(() => document.getElementById('mode-fix').className), 'on');
      await page.keyboard.press('KeyS');
      assert.equal(await T(() => document.getElementById('mode-sing').className), 'on');
      // Escape gives up what was typed and leaves the box too.
      await page.click('#N', { clickCount: 3 });
      await page.keyboard.type('7');
      await page.keyboard.press('Escape');
      assert.equal(await T(() => document.getElementById('N').value), '4');
      await page.keyboard.press('KeyF');
      assert.equal(await T(() => document.getElementById('mode-fix').className), 'on');
      await page.keyboard.press('KeyS');
    });

    await check('changing N when the singularities cannot follow says so and clears the crosses; undo brings them back', async () => {
      const saved = await page.evaluate(() => window.__trivcon.session);
      const count = saved.singularities.length;
      assert.ok(count > 0 && (await T(() => window.__trivcon.glyphFaces.length)) > 0);
      const clip = { x: view.x, y: view.y, width: view.w, height: view.h };
      assert.ok((await fieldPixels(page, clip)) > 500);
      await typeIn('#N', '3');
      await idle();
      const message = await T(() => window.__trivcon.message);
      assert.match(message, new RegExp(`^N = 3: removed ${count} singularities \\(their indices are not multiples of 1/3\\); Ctrl\\+Z brings them back\\.`));
      assert.match(message, /No field is shown: none has solved yet for this N\./);
      assert.doesNotMatch(message, /last valid field/);
      assert.deepEqual(await singularities(), []);
      assert.equal(await T(() => window.__trivcon.directions), null);
      assert.equal(await T(() => window.__trivcon.glyphFaces.length), 0);
      assert.ok((await fieldPixels(page, clip)) < 50, 'crosses still on screen');
      assert.match(await T(() => document.getElementById('status').textContent), /^not solved: no valid field for N = 3 yet$/);
      await page.keyboard.down('Control');
      await page.keyboard.press('KeyZ');
      await page.keyboard.up('Control');
      await idle();
      assert.deepEqual(await page.evaluate(() => window.__trivcon.session), saved);
      assert.equal(await T(() => window.__trivcon.message), '');
      assert.ok((await fieldPixels(page, clip)) > 500);
    });

    await check('a PNG of the view can be saved; its button is whole on screen', async () => {
      const png = await page.evaluate(() => window.__trivcon.pngSize());
      assert.ok(png > 10000, `PNG of ${png} bytes`);
      const box = await page.evaluate(() => {
        const b = document.getElementById('dl-png');
        b.scrollIntoView({ block: 'nearest' });
        const r = b.getBoundingClientRect(), p = document.getElementById('panel').getBoundingClientRect();
        return { r: r.toJSON(), p: p.toJSON(), w: innerWidth, h: innerHeight };
      });
      assert.ok(box.r.left >= box.p.left && box.r.right <= box.p.right && box.r.right <= box.w, JSON.stringify(box));
      assert.ok(box.r.top >= 0 && box.r.bottom <= box.h + 0.5, JSON.stringify(box));
      assert.equal(await page.evaluate(() => document.getElementById('panel').scrollWidth <= document.getElementById('panel').clientWidth), true);
      await page.click('#dl-png');
    });

    await check('a mesh that is not manifold is repaired: the page says how, a downloaded field has a row per face of the file', async () => {
      // Two closed boxes touching at one corner (vertex 7 of the first is vertex 0 of the second).
      const v = [], f = [];
      for (const o of [0, 1]) {
        const b = v.length;
        for (let i = 0; i < 8; i++) v.push([o + ((i >> 2) & 1), o + ((i >> 1) & 1), o + (i & 1)]);
        for (const [a, c, d, e] of [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]])
          f.push([b + a, b + c, b + d], [b + a, b + d, b + e]);
      }
      v.splice(8, 1);
      const faces = f.map((t) => t.map((i) => (i === 8 ? 7 : i > 8 ? i - 1 : i) + 1));
      const path = resolve(tmpdir(), `trivcon-boxes-${process.pid}.obj`);
      writeFileSync(path, v.map((p) => `v ${p.join(' ')}\n`).join('') + faces.map((t) => `f ${t.join(' ')}\n`).join(''));
      const other = await startEditor(trivcon, [path, '-N', '4']);
      const tab = await browser.newPage();
      tab.on('pageerror', (e) => pageErrors.push(e.message));
      try {
        await tab.goto(other.url);
        await tab.waitForFunction(() => window.__trivcon && window.__trivcon.ready, { timeout: 120000 });
        const info = await tab.evaluate(() => document.getElementById('meshinfo').textContent);
        assert.match(info, /16 vertices, 24 faces/);
        assert.match(info, /repaired: 1 vertex split into separate fans \(first: vertex 7, 2 fans\)/);
        assert.match(other.stderr(), /repaired: 1 vertex split/);
        const session = await tab.evaluate(() => window.__trivcon.session);
        const txt = await (await fetch(new URL('/api/export?format=txt', other.url), {
          method: 'POST', headers: { 'X-Trivcon-Token': other.token, 'Content-Type': 'application/json' },
          // Every corner of both boxes +1/4: vertex 15 is the second box's copy of the shared corner 7.
          body: JSON.stringify({ ...session, singularities: [...Array(16).keys()].map((i) => [i, '1/4']) }),
        })).text();
        assert.match(txt, /# faces 24\n/);
      } finally {
        await tab.close();
        other.child.kill('SIGTERM');
        await once(other.child, 'exit');
      }
    });

    await check('glyphs cover large faces in proportion to area (two big triangles beside 20000 small ones)', async () => {
      const path = resolve(tmpdir(), `trivcon-uneven-${process.pid}.obj`);
      writeUnevenMesh(path);
      // Started with the big square's boundary loop at index 0: it does not balance, no field yet.
      const other = await startEditor(trivcon, [path, '-N', '4', '--boundary', '0:0']);
      const tab = await browser.newPage();
      await tab.setViewport({ width: 1200, height: 800 });
      tab.on('pageerror', (e) => pageErrors.push(e.message));
      try {
        await tab.goto(other.url);
        await tab.waitForFunction(() => window.__trivcon && window.__trivcon.ready, { timeout: 120000 });
        const message = await tab.evaluate(() => window.__trivcon.message);
        assert.match(message, /No field is shown: none has solved yet for this N\./);
        assert.doesNotMatch(message, /last valid field/);
        assert.equal(await tab.evaluate(() => window.__trivcon.glyphFaces.length), 0);
        // Left to the solver ("smoothest"), the loop balances: the field is drawn on both squares alike.
        await tab.click('#cycles .row[data-kind="loop"][data-id="0"] input', { clickCount: 3 });
        await tab.keyboard.press('Backspace');
        await tab.keyboard.press('Enter');
        await tab.evaluate(() => window.__trivcon.idle());
        assert.equal(await tab.evaluate(() => window.__trivcon.message), '');
        const faces = await tab.evaluate(() => window.__trivcon.glyphFaces);
        const big = faces.filter((f) => f < 2).length;
        assert.ok(faces.length > 100, `${faces.length} glyphs`);
        assert.ok(big > 0.35 * faces.length && big < 0.65 * faces.length, `${big} of ${faces.length} glyphs on the big square (half the area)`);
        // On screen: the big square shows about as much of the field as the fine one.
        const rect = async (a, b) => {
          const [p, q] = await tab.evaluate((u, v) => [window.__trivcon.projectVertex(u), window.__trivcon.projectVertex(v)], a, b);
          return { x: Math.min(p.x, q.x) + 5, y: Math.min(p.y, q.y) + 5, width: Math.abs(q.x - p.x) - 10, height: Math.abs(q.y - p.y) - 10 };
        };
        const onBig = await fieldPixels(tab, await rect(0, 2)), onFine = await fieldPixels(tab, await rect(4, 4 + 101 * 101 - 1));
        assert.ok(onBig > 0.5 * onFine && onFine > 200, `field pixels: ${onBig} on the big square, ${onFine} on the fine one`);
      } finally {
        await tab.close();
        other.child.kill('SIGTERM');
        await once(other.child, 'exit');
      }
    });

    await check('the page raised no script error', async () => assert.deepEqual(pageErrors, []));
  } finally {
    await browser.close();
    editor.child.kill('SIGTERM');
    const [code] = await once(editor.child, 'exit');
    await check('trivcon edit exits cleanly on SIGTERM', async () => assert.equal(code, 0));
  }
  const failed = results.filter(([, ok]) => !ok).length;
  console.log(`${results.length - failed} passed, ${failed} failed`);
  process.exit(failed ? 1 : 0);
}

if (process.argv[1] === fileURLToPath(import.meta.url)) main().catch((e) => (console.error(e), process.exit(1)));
