// End-to-end tests of `pdeshape serve` in headless Chromium: open the page, drag a control point
// with real mouse events, save, undo, a bad edit, and the shaded surface on screen.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { spawnSync } from 'node:child_process';
import { binary, startDir, startServer, stopServer, launchBrowser, openPage, settled } from './harness.mjs';

const shots = path.join(path.dirname(new URL(import.meta.url).pathname), 'out');
fs.mkdirSync(shots, { recursive: true });

let dir, server, browser, page, errors;

before(async () => {
  dir = startDir();
  server = await startServer(dir);
  browser = await launchBrowser();
  ({ page, errors } = await openPage(browser.context, server.url));
});

after(async () => {
  if (browser) await browser.context.close();
  if (server) {
    const code = await stopServer(server);
    // Ctrl-C (SIGINT) stops the server cleanly.
    assert.equal(code, 0, `server exit ${code}: ${server.stderr()}`);
  }
});

// Sum and extent of all mesh positions on the page (to see that the surface changed).
async function meshDigest() {
  return page.evaluate(() => {
    const v = window.__pdeshape.view;
    return { bounds: v.bounds, version: window.__pdeshape.state().version };
  });
}

// Fraction of the canvas that is not background, and the number of distinct grey levels in it.
async function shading() {
  return page.evaluate(() => {
    const c = document.getElementById('view');
    const off = document.createElement('canvas');
    off.width = c.width; off.height = c.height;
    const ctx = off.getContext('2d');
    ctx.drawImage(c, 0, 0);
    const d = ctx.getImageData(0, 0, off.width, off.height).data;
    let covered = 0;
    const levels = new Set();
    for (let i = 0; i < d.length; i += 4) {
      const [r, g, b] = [d[i], d[i + 1], d[i + 2]];
      if (Math.abs(r - 247) + Math.abs(g - 247) + Math.abs(b - 250) > 12) {
        covered++;
        // Grey surface pixels (not the coloured lines): their brightness varies with shading.
        if (Math.abs(r - g) < 20 && Math.abs(g - b) < 30) levels.add(Math.round((r + g + b) / 6));
      }
    }
    return { covered: covered / (d.length / 4), levels: levels.size };
  });
}

function controlPoint(scene, curve, index) {
  return scene.curves.find((c) => c.name === curve).control[index];
}

async function screenOf(curve, index) {
  return page.evaluate(([curve, index]) => {
    const { view, state } = window.__pdeshape;
    const p = state().curves.find((c) => c.name === curve).control[index];
    const s = view.project(p);
    const r = view.canvas.getBoundingClientRect();
    return [s[0] + r.left, s[1] + r.top];
  }, [curve, index]);
}

test('the page shows a shaded surface with its curves', async () => {
  await page.waitForTimeout(300);
  await page.screenshot({ path: path.join(shots, 'default.png') });
  const s = await shading();
  assert.ok(s.covered > 0.15, `only ${s.covered} of the view is drawn`);
  assert.ok(s.levels > 30, `only ${s.levels} grey levels: not shaded`);
  const scene = await page.evaluate(() => window.__pdeshape.state());
  assert.equal(scene.surfaces.length, 1);
  assert.equal(controlPoint(scene, 'rim', 1).length, 3);
  assert.deepEqual(errors, []);
});

test('dragging a control point re-solves the surface; save and undo follow', async () => {
  const before = await page.evaluate(() => window.__pdeshape.state());
  const digestBefore = await meshDigest();
  const original = controlPoint(before, 'rim', 1);
  const [x, y] = await screenOf('rim', 1);
  await page.mouse.move(x, y);
  await page.mouse.down();
  for (let k = 1; k <= 12; k++) {
    await page.mouse.move(x + 5 * k, y - 3 * k);
    await page.waitForTimeout(16);
  }
  await page.screenshot({ path: path.join(shots, 'drag.png') });
  for (let k = 13; k <= 20; k++) {
    await page.mouse.move(x + 5 * k, y - 3 * k);
    await page.waitForTimeout(16);
  }
  await page.mouse.up();
  await page.waitForFunction(() => {
    const p = window.__pdeshape.perf;
    return p.sent > 0 && p.latencies.length > 0;
  });
  await page.waitForTimeout(500);
  const afterDrag = await page.evaluate(() => window.__pdeshape.state());
  const moved = controlPoint(afterDrag, 'rim', 1);
  assert.ok(afterDrag.version > before.version, 'no edit reached the server');
  assert.ok(Math.hypot(...moved.map((c, i) => c - original[i])) > 0.05, `the point did not move: ${moved}`);
  const digestAfter = await meshDigest();
  assert.notDeepEqual(digestAfter.bounds, digestBefore.bounds, 'the surface did not change');
  const perf = await page.evaluate(() => window.__pdeshape.perf);
  assert.ok(perf.sent <= 20, `${perf.sent} requests for 20 moves`);

  // Save: the file holds the dragged point and the CLI reads it back.
  await page.fill('#save-path', 'dragged.toml');
  await page.click('#save');
  await page.waitForFunction(() => document.getElementById('status').textContent.startsWith('saved'));
  const text = fs.readFileSync(path.join(dir, 'dragged.toml'), 'utf8');
  for (const c of moved) assert.ok(text.includes(String(c)), `${c} not in the saved file`);
  const obj = path.join(dir, 'dragged.obj');
  const r = spawnSync(binary(), ['surface', 'dragged.toml', '-o', obj, '--nu', '8', '--nv', '16'], { cwd: dir });
  assert.equal(r.status, 0, String(r.stderr));
  assert.ok(fs.statSync(obj).size > 0);

  // Undo takes the whole drag back.
  await page.click('#undo');
  await page.waitForFunction((v) => window.__pdeshape.state().version > v, afterDrag.version);
  await page.waitForTimeout(200);
  const undone = await page.evaluate(() => window.__pdeshape.state());
  assert.deepEqual(controlPoint(undone, 'rim', 1), original);
  assert.deepEqual((await meshDigest()).bounds, digestBefore.bounds);
  assert.equal(undone.can_undo, false);
});

test('a bad edit shows its message and keeps the last good surface', async () => {
  const before = await page.evaluate(() => window.__pdeshape.state());
  // Order 3 needs six conditions; the patch has four.
  await page.fill('#order', '3');
  await page.dispatchEvent('#order', 'change');
  await page.waitForFunction(() => document.querySelector('.err[data-for="patch"]').textContent.length > 0);
  const message = await page.textContent('.err[data-for="patch"]');
  assert.match(message, /condition/);
  const after = await page.evaluate(() => window.__pdeshape.state());
  assert.equal(after.version, before.version);
  // The view still shows the surface.
  const s = await shading();
  assert.ok(s.levels > 30);
});

test('an example loads, and a circle becomes a B-spline to drag', async () => {
  await page.selectOption('#files', 'examples/cup.toml');
  await page.click('#load');
  await page.waitForFunction(() => window.__pdeshape.state().file === 'examples/cup.toml');
  await page.selectOption('#curve', 'rim');
  await page.click('#convert');
  await page.waitForFunction(() => {
    const c = window.__pdeshape.state().curves.find((x) => x.name === 'rim');
    return c && c.control && c.control.length === 8;
  });
  const scene = await page.evaluate(() => window.__pdeshape.state());
  assert.equal(scene.surfaces.length, 2);
  assert.deepEqual(scene.shared_curves, ['belly']);
  // The G0/G1 table follows once the reports are fetched.
  await page.waitForFunction(() => document.getElementById('edges').textContent.includes('belly'));
  await page.waitForTimeout(300);
  await page.screenshot({ path: path.join(shots, 'cup.png') });
  const s = await shading();
  assert.ok(s.levels > 30);
});

test('curve and patch controls: translate, the a slider, a library curve', async () => {
  const centroid = async (name) => page.evaluate((n) => window.__pdeshape.state().curves.find((c) => c.name === n).centroid, name);
  const version = async () => page.evaluate(() => window.__pdeshape.state().version);
  await page.selectOption('#curve', 'belly');
  const z0 = (await centroid('belly'))[2];
  let v = await version();
  await page.fill('#tz', '0.25');
  await page.click('#translate');
  await page.waitForFunction((x) => window.__pdeshape.state().version > x, v);
  assert.ok(Math.abs((await centroid('belly'))[2] - z0 - 0.25) < 1e-9);
  // The a slider re-solves the selected patch.
  v = await version();
  await page.selectOption('#patch', 'bowl');
  await page.fill('#a', '2');
  await page.waitForFunction((x) => window.__pdeshape.state().version > x, v);
  const op = await page.evaluate(() => window.__pdeshape.state().surfaces.find((s) => s.name === 'bowl').operator);
  assert.equal(op.a, 2);
  // A B-spline from the library.
  v = await version();
  await page.selectOption('#new-kind', 'bspline');
  await page.fill('#new-name', 'lid');
  await page.fill('#new-center', '0,0,3');
  await page.click('#add-curve');
  await page.waitForFunction(() => {
    const c = window.__pdeshape.state().curves.find((x) => x.name === 'lid');
    return c && c.control && c.control.length === 8;
  });
  assert.equal(await page.textContent('.err[data-for="add"]'), '');
  await page.waitForTimeout(300);
  await page.screenshot({ path: path.join(shots, 'controls.png') });
});

test('the API refuses requests without the token', async () => {
  const r = await fetch(`${server.origin}/api/frame`);
  assert.equal(r.status, 403);
  const r2 = await fetch(`${server.origin}/api/frame`, { headers: { 'x-pdeshape-token': server.token, origin: 'http://evil.example' } });
  assert.equal(r2.status, 403);
});
