// End-to-end tests of `pdeshape serve` in headless Chromium: open the page, drag a control point
// with real mouse events, save, undo, a bad edit, and the shaded surface on screen; drag a spine
// handle, a trim curve and an attachment in the (u, v) panel, a local-edit handle, a parameter
// slider, a side of an n-sided patch, and scrub and play the timeline. Screenshots of each state
// go to e2e/out/.

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
  // Loading another file after edits asks before discarding them; these tests discard.
  page.on('dialog', (d) => d.accept());
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
  // The (u, v) panel, which follows a 3-D drag a moment after its newest frame, shows it.
  assert.ok(await page.evaluate(() => window.__pdeshape.uv.scene === window.__pdeshape.state()), 'the (u, v) panel did not follow the drag');
  const moved = controlPoint(afterDrag, 'rim', 1);
  assert.ok(afterDrag.version > before.version, 'no edit reached the server');
  assert.ok(Math.hypot(...moved.map((c, i) => c - original[i])) > 0.05, `the point did not move: ${moved}`);
  const digestAfter = await meshDigest();
  assert.notDeepEqual(digestAfter.bounds, digestBefore.bounds, 'the surface did not change');
  const perf = await page.evaluate(() => window.__pdeshape.perf);
  assert.ok(perf.sent <= 20, `${perf.sent} requests for 20 moves`);
  // Chromium on loopback (a secure context) gives the raw pointer updates the drag follows.
  assert.equal(await page.evaluate(() => window.__pdeshape.moveEvent), 'pointerrawupdate');
  // The drag's frames came over the page's socket, not one fetch each.
  const transport = await page.evaluate(() => window.__pdeshape.transport);
  assert.ok(transport.socket >= perf.sent, `${transport.socket} frames over the socket for ${perf.sent} requests`);

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

// ---- Design operations: spine handles, the (u, v) panel, local edits, parameters, time -------

async function load(file) {
  const v = await page.evaluate(() => window.__pdeshape.state().version);
  await page.selectOption('#files', file);
  await page.click('#load');
  await page.waitForFunction(([f, v]) => {
    const s = window.__pdeshape.state();
    return s.file === f && s.version > v;
  }, [file, v]);
  await page.waitForTimeout(300);
}

const digest = () => page.evaluate(() => window.__pdeshape.digest());
const version = () => page.evaluate(() => window.__pdeshape.state().version);
const state = () => page.evaluate(() => window.__pdeshape.state());

async function dragMouse(x, y, dx, dy, steps, shot) {
  await page.mouse.move(x, y);
  await page.mouse.down();
  for (let k = 1; k <= steps; k++) {
    await page.mouse.move(x + (dx * k) / steps, y + (dy * k) / steps);
    await page.waitForTimeout(20);
    if (shot && k === Math.round(steps / 2)) await page.screenshot({ path: path.join(shots, shot) });
  }
  await page.mouse.up();
}

// Waits until every request of the gestures has come back (nothing in flight or waiting).
async function idle() {
  await page.waitForTimeout(100);
  await page.waitForFunction(() => window.__pdeshape.idle());
  await page.waitForTimeout(300);
}

test('a spine handle is dragged; the saved file states the spine edit', async () => {
  await load('examples/cup.toml');
  const before = await state();
  const d0 = await digest();
  const k = before.surfaces.findIndex((s) => s.name === 'bowl');
  const p0 = before.surfaces[k].spine_control[2];
  const [x, y] = await page.evaluate(([k]) => {
    const { view, state } = window.__pdeshape;
    const s = view.project(state().surfaces[k].spine_control[2]);
    const r = view.canvas.getBoundingClientRect();
    return [s[0] + r.left, s[1] + r.top];
  }, [k]);
  await dragMouse(x, y, 60, -10, 12, 'spine-drag.png');
  await idle();
  const after = await state();
  assert.ok(after.version > before.version, 'no spine edit reached the server');
  const p1 = after.surfaces[k].spine_control[2];
  assert.ok(Math.hypot(...p1.map((c, i) => c - p0[i])) > 0.05, `the spine point did not move: ${p1}`);
  assert.equal(after.surfaces[k].spine_carry, 'frame');
  assert.notEqual(await digest(), d0, 'the surface did not change');
  assert.match(await page.textContent('#spine-info'), /edited \(frame\)/);
  await page.fill('#save-path', 'spine.toml');
  await page.click('#save');
  await page.waitForFunction(() => document.getElementById('status').textContent.startsWith('saved spine.toml'));
  const text = fs.readFileSync(path.join(dir, 'spine.toml'), 'utf8');
  assert.match(text, /\[\[spine\]\]/);
  assert.match(text, /patch = "bowl"/);
  for (const c of p1) assert.ok(text.includes(String(c)), `${c} not in the saved file`);
  // One undo takes the whole drag back.
  await page.click('#undo');
  await page.waitForFunction((v) => window.__pdeshape.state().version > v, after.version);
  await page.waitForTimeout(200);
  assert.equal(await digest(), d0);
  assert.deepEqual((await state()).surfaces[k].spine_control[2], p0);
  assert.deepEqual(errors, []);
});

test('a trim curve dragged in the (u, v) panel moves the hole; undo restores', async () => {
  await load('examples/trimmed_vase.toml');
  await page.screenshot({ path: path.join(shots, 'trimmed-vase.png') });
  const before = await state();
  assert.equal(before.surfaces[0].trimmed, true);
  const d0 = await digest();
  const centre = before.trims[0].spec.curves[0].center;
  const [x, y] = await page.evaluate((c) => window.__pdeshape.uv.screenOf(c), centre);
  // The circle at v = 5.2 moves down the panel (to smaller v) and to the right (larger u).
  await dragMouse(x, y, -25, 40, 10, 'uv-drag.png');
  await idle();
  const after = await state();
  const moved = after.trims[0].spec.curves[0].center;
  assert.ok(moved[0] < centre[0] - 0.02 && moved[1] < centre[1] - 0.2, `the centre did not follow: ${moved}`);
  assert.notEqual(await digest(), d0, 'the hole did not move');
  await page.screenshot({ path: path.join(shots, 'uv-panel.png') });
  await page.fill('#save-path', 'vase.toml');
  await page.click('#save');
  await page.waitForFunction(() => document.getElementById('status').textContent.startsWith('saved vase.toml'));
  const text = fs.readFileSync(path.join(dir, 'vase.toml'), 'utf8');
  assert.ok(text.includes(String(moved[0])) && text.includes(String(moved[1])), 'the moved centre is not in the file');
  const r = spawnSync(binary(), ['surface', 'vase.toml', '-o', path.join(dir, 'vase.obj'), '--nu', '16', '--nv', '32'], { cwd: dir });
  assert.equal(r.status, 0, String(r.stderr));
  await page.click('#undo');
  await page.waitForFunction((v) => window.__pdeshape.state().version > v, after.version);
  await page.waitForTimeout(200);
  assert.equal(await digest(), d0);
  assert.deepEqual((await state()).trims[0].spec.curves[0].center, centre);
  // A hole added where there is room, picked in the panel and deleted.
  await page.click('#uv-add');
  await page.waitForFunction(() => window.__pdeshape.state().trims[0].spec.curves.length === 4);
  assert.equal(await page.textContent('.err[data-for="uv"]'), '');
  const added = (await state()).trims[0].spec.curves[3].center;
  const [ax, ay] = await page.evaluate((c) => window.__pdeshape.uv.screenOf(c), added);
  await page.mouse.click(ax + 3, ay + 3);
  await page.waitForFunction(() => !document.getElementById('uv-delete').disabled);
  await page.click('#uv-delete');
  await page.waitForFunction(() => window.__pdeshape.state().trims[0].spec.curves.length === 3);
  assert.deepEqual(errors, []);
});

test('the trimmed teacup is drawn with its attachments, and an attachment slides', async () => {
  await load('examples/teacup.toml');
  const s = await state();
  const bowl = s.surfaces.findIndex((x) => x.name === 'bowl');
  assert.equal(s.surfaces[bowl].trimmed, true);
  assert.equal(s.trim_lines.length, 2);
  await page.selectOption('#uv-patch', 'bowl');
  await page.waitForTimeout(200);
  await page.screenshot({ path: path.join(shots, 'teacup.png') });
  const d0 = await digest();
  const top = s.curves.find((c) => c.name === 'top_root').spec.path.center;
  const [x, y] = await page.evaluate((c) => window.__pdeshape.uv.screenOf(c), [top[0] - 0.05, top[1]]);
  await dragMouse(x, y, 0, -15, 6);
  await idle();
  const after = await state();
  const c = after.curves.find((k) => k.name === 'top_root').spec.path.center;
  assert.ok(c[1] > top[1] + 0.05, `the attachment did not slide: ${c}`);
  assert.notEqual(await digest(), d0);
  await page.screenshot({ path: path.join(shots, 'teacup-moved.png') });
  // The aeroplane: five attachments on the fuselage, the right wing's root across its seam v = 0.
  await load('examples/aeroplane.toml');
  const plane = await state();
  assert.equal(plane.surfaces.find((x) => x.name === 'fuselage').trimmed, true);
  assert.equal(plane.trim_lines.length, 5);
  assert.equal(await page.inputValue('#uv-patch'), 'fuselage');
  await page.screenshot({ path: path.join(shots, 'aeroplane.png') });
  assert.deepEqual(errors, []);
});

test('X1 and X2 of a local edit are picked on the curve with the mouse', async () => {
  await load('examples/cup.toml');
  await page.selectOption('#curve', 'rim');
  await page.click('#l-pick');
  const at = (k) => page.evaluate((k) => {
    const { view, state } = window.__pdeshape;
    const s = view.project(state().curves.find((c) => c.name === 'rim').points[k]);
    const r = view.canvas.getBoundingClientRect();
    return [s[0] + r.left, s[1] + r.top];
  }, k);
  // Points 16 and 48 of the 128 drawn: v = π/4 and 3π/4 (on the side facing the eye).
  for (const k of [16, 48]) {
    const [x, y] = await at(k);
    await page.mouse.click(x, y);
  }
  await page.waitForFunction(() => window.__pdeshape.view.local);
  assert.ok(Math.abs(Number(await page.inputValue('#l-from')) - Math.PI / 4) < 1e-3);
  assert.ok(Math.abs(Number(await page.inputValue('#l-to')) - (3 * Math.PI) / 4) < 1e-3);
  const frame = await page.evaluate(() => window.__pdeshape.local.frame);
  assert.ok(Math.abs(frame.at - Math.PI / 2) < 1e-3, `the handle at ${frame.at}`);
  await page.click('#l-done');
  assert.equal(await page.evaluate(() => window.__pdeshape.view.local), null);
});

test('a local edit: X1, X2 picked by number, the handle dragged', async () => {
  await load('examples/cup.toml');
  await page.selectOption('#curve', 'rim');
  await page.fill('#l-from', '0.5');
  await page.fill('#l-to', '2');
  await page.click('#l-show');
  await page.waitForFunction(() => window.__pdeshape.view.local);
  const v = await version();
  const [x, y] = await page.evaluate(() => {
    const { view } = window.__pdeshape;
    const s = view.project(view.local.handle);
    const r = view.canvas.getBoundingClientRect();
    return [s[0] + r.left, s[1] + r.top];
  });
  await dragMouse(x, y, 25, -25, 8, 'local-drag.png');
  await idle();
  const after = await state();
  assert.ok(after.version > v);
  const rim = after.curves.find((c) => c.name === 'rim');
  assert.equal(rim.spec.type, 'local');
  assert.equal(rim.spec.curve.type, 'circle', 'one drag is one local edit');
  assert.equal(await page.textContent('.err[data-for="local"]'), '');
  await page.click('#l-done');
});

test('design parameters have sliders', async () => {
  await load('examples/swirl_port_params.toml');
  const input = page.locator('#params input[data-param="theta"]');
  await input.waitFor();
  await input.scrollIntoViewIfNeeded();
  const v = await version();
  const d0 = await digest();
  const before = (await state()).parameters.find((p) => p.name === 'theta');
  assert.ok(before.value > 0, `theta starts at ${before.value}`);
  const box = await input.boundingBox();
  await page.mouse.click(box.x + box.width * 0.2, box.y + box.height / 2);
  await page.waitForFunction((x) => window.__pdeshape.state().version > x, v);
  await page.waitForTimeout(300);
  const theta = (await state()).parameters.find((p) => p.name === 'theta');
  assert.ok(theta.value < theta.min + 0.3 * (theta.max - theta.min), `theta = ${theta.value}`);
  assert.notEqual(await digest(), d0);
  await page.waitForFunction(() => document.getElementById('check').textContent.includes('swirl_port_params'));
  await page.screenshot({ path: path.join(shots, 'parameters.png') });
});

test('the timeline scrubs and plays a time-dependent design', async () => {
  await load('examples/anim/ventricle.toml');
  assert.equal(await page.isVisible('#timeline'), true);
  const s0 = await state();
  assert.equal(s0.time.t, 0);
  const d0 = await digest();
  const box = await page.locator('#t-slider').boundingBox();
  await page.mouse.click(box.x + box.width * 0.5, box.y + box.height / 2);
  await page.waitForFunction((v) => window.__pdeshape.state().version > v, s0.version);
  await page.waitForTimeout(400);
  const s1 = await state();
  assert.ok(Math.abs(s1.time.t - 0.4) < 0.05, `t = ${s1.time.t}`);
  assert.notEqual(await digest(), d0, 'the surface did not change with t');
  await page.screenshot({ path: path.join(shots, 'timeline.png') });
  // Play for a second: several times are shown, then pause.
  const shown = s1.version;
  await page.click('#t-play');
  await page.waitForTimeout(1500);
  await page.click('#t-play');
  await page.waitForTimeout(300);
  const s2 = await state();
  assert.ok(s2.version >= shown + 3, `only ${s2.version - shown} frames while playing`);
  assert.equal(await page.textContent('.err[data-for="time"]'), '');
  // The fish has a timeline too.
  await load('examples/anim/fish.toml');
  assert.equal(await page.isVisible('#timeline'), true);
  // A design without time has none.
  await load('examples/cup.toml');
  assert.equal(await page.isVisible('#timeline'), false);
  assert.deepEqual(errors, []);
});

test('an n-sided patch: a side\'s control point dragged re-solves the pieces; undo restores', async () => {
  await load('examples/nsided_pentagon.toml');
  const before = await state();
  assert.deepEqual(before.surfaces.map((s) => s.name), ['panel.0', 'panel.1', 'panel.2', 'panel.3', 'panel.4']);
  const d0 = await digest();
  const p0 = controlPoint(before, 'side0', 1);
  const s0 = await shading();
  assert.ok(s0.covered > 0.05 && s0.levels > 30, `the patch is not drawn shaded: ${JSON.stringify(s0)}`);
  await page.screenshot({ path: path.join(shots, 'nsided.png') });
  const [x, y] = await screenOf('side0', 1);
  await dragMouse(x, y, 30, -40, 10, 'nsided-drag.png');
  await idle();
  const after = await state();
  const moved = controlPoint(after, 'side0', 1);
  assert.ok(after.version > before.version, 'no edit reached the server');
  assert.ok(Math.hypot(...moved.map((c, i) => c - p0[i])) > 0.02, `the point did not move: ${moved}`);
  assert.notEqual(await digest(), d0, 'the patch on screen did not change');
  // Every piece is still drawn from the new solve, and the page shows no error.
  assert.equal(after.surfaces.length, 5);
  const shown = await page.evaluate(() => [...document.querySelectorAll('.err')].map((e) => e.textContent).join(''));
  assert.equal(shown, '', 'the page shows an error');
  await page.screenshot({ path: path.join(shots, 'nsided-dragged.png') });
  // One undo takes the whole drag back: the same point and the same meshes.
  await page.click('#undo');
  await page.waitForFunction((v) => window.__pdeshape.state().version > v, after.version);
  await idle();
  assert.deepEqual(controlPoint(await state(), 'side0', 1), p0);
  assert.equal(await digest(), d0);
  assert.deepEqual(errors, []);
});

test('the API refuses requests without the token', async () => {
  const r = await fetch(`${server.origin}/api/frame`);
  assert.equal(r.status, 403);
  const r2 = await fetch(`${server.origin}/api/frame`, { headers: { 'x-pdeshape-token': server.token, origin: 'http://evil.example' } });
  assert.equal(r2.status, 403);
});
