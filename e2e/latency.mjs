// Latency of a drag in the real browser: from the pointer event to the new surface on its way
// to the screen — the page draws a frame as it arrives and the measure ends at the next
// animation frame (the one that takes the drawing to the compositor), or later if a pixel of it
// read back then (which waits for the rasteriser) is not ready — for the cup, the wine glass, the
// teacup and the five-sided panel at 64 × 128 per patch. Prints p50/p95 of the whole, of the server's share (its own timing of re-solve +
// tessellation + frame) and of the round trip; the browser's share is the rest (event handling,
// decode, upload, draw).
// Usage: node latency.mjs [moves] [WxH] [disable-gpu|swiftshader] [zebra]
//   (a benchmark: not part of the tests; default 150 moves, 1280x800, --disable-gpu, shaded)

import { startDir, startServer, stopServer, launchBrowser, openPage, percentile } from './harness.mjs';

const moves = Number(process.argv[2] || 150);
const [width, height] = (process.argv[3] || '1280x800').split('x').map(Number);
const renderer = process.argv[4] || 'disable-gpu';
const zebra = process.argv[5] === 'zebra';
// DESIGNS=teacup,cup runs only those; FULL_DRAG=1 keeps the full grid and resolution while
// dragging (the page's "full detail while dragging").
const only = (process.env.DESIGNS || '').split(',').filter(Boolean);
const cases = [
  { file: 'examples/cup.toml', curve: 'rim', index: 3 },
  { file: 'examples/wine_glass.toml', curve: 'belly', index: 3 },
  { file: 'examples/teacup.toml', curve: 'rim', index: 3 },
  // Five n-sided pieces; the side is a B-spline already (nothing to convert).
  { file: 'examples/nsided_pentagon.toml', curve: 'side0', index: 1, bspline: true },
].filter((c) => !only.length || only.includes(c.file.replace(/^examples\/|\.toml$/g, '')));

const dir = startDir();
const server = await startServer(dir);
const { context } = await launchBrowser({ viewport: { width, height }, renderer });
const { page } = await openPage(context, server.url);
// Loading the next design discards the last one's drag.
page.on('dialog', (d) => d.accept());
if (zebra) await page.selectOption('#inspect', 'zebra');
if (process.env.FULL_DRAG === '1') await page.check('#full-drag');
await page.evaluate(() => {
  // Count the GPU's work in: the surface is drawn when a pixel of it can be read back. (Chrome's
  // gl.finish() returns at once without a GPU: the rasterising then waits for the page's next
  // composite, where it was not counted before.)
  const gl = window.__pdeshape.view.gl;
  const perf = window.__pdeshape.perf;
  const push = perf.latencies.push.bind(perf.latencies);
  const pixel = new Uint8Array(4);
  perf.latencies.push = (x) => {
    const t0 = performance.now() - x;
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
    return push(performance.now() - t0);
  };
});
const rows = [];
for (const c of cases) {
  await page.selectOption('#files', c.file);
  await page.click('#load');
  await page.waitForFunction((f) => window.__pdeshape.state().file === f, c.file);
  await page.selectOption('#curve', c.curve);
  if (!c.bspline) await page.click('#convert');
  await page.waitForFunction((n) => {
    const x = window.__pdeshape.state().curves.find((k) => k.name === n);
    return x && x.control;
  }, c.curve);
  await page.waitForTimeout(1500);
  await page.evaluate(() => {
    const p = window.__pdeshape.perf;
    p.latencies.length = 0; p.server.length = 0; if (p.serverSplit) p.serverSplit.length = 0; p.roundTrips.length = 0;
    p.sent = 0; p.coalesced = 0;
  });
  const [x, y] = await page.evaluate(([curve, index]) => {
    const { view, state } = window.__pdeshape;
    const p = state().curves.find((k) => k.name === curve).control[index];
    const s = view.project(p);
    const r = view.canvas.getBoundingClientRect();
    return [s[0] + r.left, s[1] + r.top];
  }, [c.curve, c.index]);
  await page.mouse.move(x, y);
  await page.mouse.down();
  let dragGrid = '';
  for (let k = 1; k <= moves; k++) {
    const a = (k / moves) * 2 * Math.PI;
    await page.mouse.move(x + 40 * Math.sin(a), y - 25 * Math.sin(2 * a));
    await page.waitForTimeout(16);
    if (k === moves >> 1) {
      dragGrid = await page.evaluate(() => {
        const { state, view } = window.__pdeshape;
        return `${state().grid.join('x')} at ${view.canvas.width}x${view.canvas.height} px`;
      });
    }
  }
  await page.mouse.up();
  await page.waitForTimeout(500);
  const p = await page.evaluate(() => window.__pdeshape.perf);
  const s = await page.evaluate(() => window.__pdeshape.state());
  const browser = p.latencies.map((l, i) => l - p.roundTrips[i]);
  const vertices = s.surfaces.length * s.grid[0] * s.grid[1];
  rows.push({
    design: c.file, patches: s.surfaces.length, grid: s.grid.join('x'), dragGrid, vertices, moves,
    requests: p.sent, coalesced: p.coalesced, frames: p.latencies.length,
    p50: percentile(p.latencies, 50), p95: percentile(p.latencies, 95),
    server_p50: percentile(p.server, 50), server_p95: percentile(p.server, 95),
    // (the phases of the server's time: pages of builds before them have none)
    edit_p50: percentile((p.serverSplit || []).map((x) => x.edit), 50),
    scene_p50: percentile((p.serverSplit || []).map((x) => x.scene), 50),
    roundtrip_p50: percentile(p.roundTrips, 50), roundtrip_p95: percentile(p.roundTrips, 95),
    browser_p50: percentile(browser, 50), browser_p95: percentile(browser, 95),
  });
}
await context.close();
await stopServer(server);
console.log(`viewport ${width}x${height}, ${renderer}, ${zebra ? 'zebra' : 'shaded'}, ${process.env.FULL_DRAG === '1' ? 'full' : 'coarse'} detail while dragging`);
for (const r of rows) {
  const f = (x) => x.toFixed(1);
  console.log(`${r.design}: ${r.patches} patches ${r.grid} (${r.dragGrid} while dragging), ${r.moves} moves, ${r.requests} requests (${r.coalesced} positions coalesced), ${r.frames} frames`);
  console.log(`  pointer→drawn p50 ${f(r.p50)} ms p95 ${f(r.p95)} ms | server p50 ${f(r.server_p50)} p95 ${f(r.server_p95)} (edit and re-solve ${f(r.edit_p50)}, scene ${f(r.scene_p50)}) | round trip p50 ${f(r.roundtrip_p50)} p95 ${f(r.roundtrip_p95)} | browser p50 ${f(r.browser_p50)} p95 ${f(r.browser_p95)}`);
}
