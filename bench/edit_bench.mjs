// SPDX-License-Identifier: MIT
// The editor's latency in a real browser: `trivcon edit` on each mesh, its page in headless Chromium
// (puppeteer-core, WebGL through SwiftShader: a CPU rasterizer, so "drawing" here is not a GPU's time).
//
//   node bench/edit_bench.mjs --trivcon build/trivcon [--edits 25] [--json FILE] NAME=MESH ...
//
// Per mesh: the page load (navigation to the first field on screen), then `edits` edits made the way a
// user makes them — a singularity dragged across the surface, one vertex per step — each waited for
// before the next. For each edit the page records (web/src/main.js, window.__trivcon.timings): the
// pointer event → the new field drawn and finished on the GPU (total), the server's time for the
// request (server; of which the solve itself: solve + field + verification, from the report), the
// rest of the round trip (transfer) and the upload + render (draw). Medians are printed as a markdown
// table (`scripts/bench.sh --edit` runs this on sphere-400k and the dragon; BENCHMARKS.md, "Editor").
import { startEditor, launchBrowser } from '../web/tests/run.mjs';

const args = process.argv.slice(2);
const opt = (name, fallback) => (args.includes(name) ? args[args.indexOf(name) + 1] : fallback);
const trivcon = opt('--trivcon', 'build/trivcon');
const edits = parseInt(opt('--edits', '25'), 10);
const jsonOut = opt('--json', '');
const meshes = args.filter((a, i) => /=/.test(a) && !args[i - 1]?.startsWith('--'));

const median = (xs) => {
  const s = [...xs].sort((a, b) => a - b);
  return s.length ? (s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2) : NaN;
};

async function benchMesh(name, path) {
  const t0 = Date.now();
  const editor = await startEditor(trivcon, [path, '-N', '4']);
  const serverReady = (Date.now() - t0) / 1000;
  const browser = await launchBrowser();
  const page = await browser.newPage();
  await page.setViewport({ width: 1200, height: 800 });
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  try {
    const tNav = Date.now();
    await page.goto(editor.url);
    await page.waitForFunction(() => window.__trivcon && window.__trivcon.ready, { timeout: 300000, polling: 50 });
    const pageLoad = (Date.now() - tNav) / 1000;
    const faces = await page.evaluate(() => window.__trivcon.faces);
    const phases = await page.evaluate(() => window.__trivcon.loadPhases);
    const view = await page.evaluate(() => {
      const r = document.getElementById('view').getBoundingClientRect();
      return { x: r.left, y: r.top, w: r.width, h: r.height };
    });
    const idle = () => page.evaluate(() => window.__trivcon.idle());
    // A +1/4 singularity in the middle of the view (balanced by a far one where the surface is closed).
    const c = { x: view.x + view.w * 0.5, y: view.y + view.h * 0.5 };
    await page.mouse.click(c.x, c.y);
    await idle();
    if (await page.evaluate(() => window.__trivcon.message !== '')) {
      await page.click('#balance');
      await idle();
    }
    const v0 = await page.evaluate((x, y) => window.__trivcon.pickVertex(x, y), c.x, c.y);
    const start = await page.evaluate((v) => window.__trivcon.projectVertex(v), v0);
    const samples = [];
    await page.mouse.move(start.x, start.y);
    await page.mouse.down();
    let x = start.x, y = start.y, version = await page.evaluate(() => window.__trivcon.fieldVersion);
    for (let step = 0; samples.length < edits && step < edits * 20; ++step) {
      x += 3 * Math.cos(step / 7);
      y += 3 * Math.sin(step / 7);
      await page.mouse.move(x, y);
      await idle();
      const now = await page.evaluate(() => window.__trivcon.fieldVersion);
      if (now !== version) {
        version = now;
        samples.push(await page.evaluate(() => window.__trivcon.timings));
      }
    }
    await page.mouse.up();
    await idle();
    const m = (k) => median(samples.map((s) => s[k]));
    return {
      name, faces, edits: samples.length, server_ready_s: serverReady, page_load_s: pageLoad, load_phases: phases,
      total_ms: m('total_ms'), server_ms: m('server_ms'), solve_ms: m('solve_ms'), transfer_ms: m('transfer_ms'), draw_ms: m('draw_ms'), draw_submit_ms: m('draw_submit_ms'),
      max_total_ms: Math.max(...samples.map((s) => s.total_ms)), errors,
    };
  } finally {
    await browser.close();
    editor.child.kill('SIGTERM');
  }
}

const rows = [];
for (const spec of meshes) {
  const eq = spec.indexOf('=');
  const name = spec.slice(0, eq), path = spec.slice(eq + 1);
  console.error(`== ${name}: ${path}`);
  const r = await benchMesh(name, path);
  console.error(JSON.stringify(r));
  rows.push(r);
}
if (jsonOut) (await import('node:fs')).writeFileSync(jsonOut, JSON.stringify(rows, null, 1));
const f = (v, d = 0) => (Number.isFinite(v) ? v.toFixed(d) : '–');
console.log('| mesh | faces | edits | edit → field on screen (median) | server (solve) | transfer | drawing | worst edit | page load | `trivcon edit` ready |');
console.log('|---|---|---|---|---|---|---|---|---|---|');
for (const r of rows)
  console.log(`| ${r.name} | ${r.faces} | ${r.edits} | ${f(r.total_ms)} ms | ${f(r.server_ms)} ms (${f(r.solve_ms)} ms) | ${f(r.transfer_ms)} ms | ` +
    `${f(r.draw_ms)} ms | ${f(r.max_total_ms)} ms | ${f(r.page_load_s, 2)} s | ${f(r.server_ready_s, 1)} s |`);
