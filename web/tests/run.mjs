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
    await check('an unbalanced set shows what to add and keeps the last field', async () => {
      assert.notEqual(A, B);
      const version = await T(() => window.__trivcon.fieldVersion);
      await page.keyboard.down('Shift');
      await page.keyboard.press('Digit1'); // palette: −1/4
      await page.keyboard.up('Shift');
      const p = await pos(A);
      await page.mouse.click(p.x, p.y);
      await idle();
      assert.deepEqual((await singularities()).find((s) => s[0] === A), [A, '-1/4']);
      const message = await T(() => window.__trivcon.message);
      assert.match(message, /add 1\/4 on component 0/);
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

    await check('automatic placement gives a balanced set the server solves', async () => {
      const entries = await T(() => window.__trivcon.historyLength);
      await page.click('#auto');
      await page.waitForFunction((n) => window.__trivcon.historyLength > n, { timeout: 60000 }, entries);
      await idle();
      assert.equal(await T(() => window.__trivcon.message), '');
      assert.equal((await api('/api/state')).solved, true);
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
      assert.ok(seen.some((t) => /^re-factoring for 1 fixed face\(s\)… \d+\.\d s of about \d+\.\d s$/.test(t)), JSON.stringify(seen));
      assert.equal(await page.evaluate(() => document.getElementById('progress').hidden), true);
      assert.match(await page.evaluate(() => document.getElementById('status').textContent), /^solved: energy /);
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
        method: 'POST', headers: { 'X-Trivcon-Token': editor.token }, body: JSON.stringify(session),
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

    await check('a PNG of the view can be saved', async () => {
      const png = await page.evaluate(() => window.__trivcon.pngSize());
      assert.ok(png > 10000, `PNG of ${png} bytes`);
      await page.click('#dl-png');
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
