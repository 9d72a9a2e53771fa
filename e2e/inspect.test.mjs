// End-to-end tests of drawing and surface inspection in headless Chromium: per-patch colours
// sampled from pixels, the legend and panels beside (not over) the model, stale messages
// cleared, a seam creased beyond the G1 tolerance or curved unlike its neighbour beyond the G2
// tolerance failing the check and drawn red, zebra
// stripes that flow across a G1 seam and break at a crease, curvature maps with a robust range,
// click-to-select, shortcuts and help, typed coordinates, the unsaved-changes question, STEP
// downloads read back, and `serve` with a design outside the start directory. Screenshots go
// to e2e/out/.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { spawnSync } from 'node:child_process';
import { binary, repo, startDir, startServer, stopServer, launchBrowser, openPage, settled } from './harness.mjs';

const shots = path.join(path.dirname(new URL(import.meta.url).pathname), 'out');
fs.mkdirSync(shots, { recursive: true });

let dir, server, browser, page, errors;
const dialogs = [];

// The cup with a crease along 'belly': the bowl leaves the belly flared outwards (its own
// derivative curve) while the base arrives vertically.
function creasedCup() {
  const text = fs.readFileSync(path.join(repo, 'examples', 'cup.toml'), 'utf8');
  const bowl = text.indexOf('name = "bowl"');
  assert.ok(bowl > 0);
  return `${text.slice(0, bowl)}${text.slice(bowl).replace('{ u = 0.0, derivative = 1, curve = "belly_tangent" }',
    '{ u = 0.0, derivative = 1, curve = "belly_flare" }')}
[curves.belly_out]
type = "circle"
center = [0.0, 0.0, 1.9]
radius = 2.3

[curves.belly_flare]
type = "derivative"
position = "belly"
direction = "belly_out"
scale = 1.6
`;
}

before(async () => {
  dir = startDir();
  fs.writeFileSync(path.join(dir, 'examples', 'cup_creased.toml'), creasedCup());
  server = await startServer(dir);
  browser = await launchBrowser();
  ({ page, errors } = await openPage(browser.context, server.url));
  page.on('dialog', async (d) => {
    dialogs.push({ type: d.type(), message: d.message() });
    if (page.acceptDialogs) await d.accept(); else await d.dismiss();
  });
});

after(async () => {
  if (browser) await browser.context.close();
  if (server) {
    const code = await stopServer(server);
    assert.equal(code, 0, `server exit ${code}: ${server.stderr()}`);
  }
});

const state = () => page.evaluate(() => window.__pdeshape.state());

async function load(file) {
  const v = (await state()).version;
  page.acceptDialogs = true;
  await page.selectOption('#files', file);
  await page.click('#load');
  // The same file may be on screen already: wait for the load's own frame.
  await page.waitForFunction(([f, v]) => window.__pdeshape.state().version > v && window.__pdeshape.state().file === f, [file, v]);
  await settled(page);
  page.acceptDialogs = false;
}

// Waits for the check panel to follow the design on screen.
async function reports() {
  const file = (await state()).file;
  await page.click('#refresh-reports');
  await page.waitForFunction((f) => document.getElementById('check').textContent.includes(`design: ${f}`), file);
  await page.waitForTimeout(100);
}

// The starting design, anew (its file name is always untitled.toml: wait for its frame).
async function newDesign() {
  const v = (await state()).version;
  page.acceptDialogs = true;
  await page.click('#new');
  await page.waitForFunction((v) => window.__pdeshape.state().version > v && window.__pdeshape.state().file === 'untitled.toml', v);
  await settled(page);
  page.acceptDialogs = false;
}

async function show(id, on) {
  if ((await page.isChecked(`#${id}`)) !== on) await page.click(`#${id}`);
}

// Only the surfaces on screen: curves, vectors, spines and control points hidden.
async function surfacesOnly(on = true) {
  for (const id of ['show-curves', 'show-vectors', 'show-spines', 'show-control']) await show(id, !on);
  await page.waitForTimeout(150);
}

// RGB of canvas pixels at CSS positions (device pixel ratio 1).
async function pixels(points) {
  return page.evaluate((pts) => {
    const c = document.getElementById('view');
    const off = document.createElement('canvas');
    off.width = c.width; off.height = c.height;
    const ctx = off.getContext('2d');
    ctx.drawImage(c, 0, 0);
    return pts.map(([x, y]) => Array.from(ctx.getImageData(Math.round(x), Math.round(y), 1, 1).data.slice(0, 3)));
  }, points);
}

// Screen positions (CSS pixels in the canvas) on a grid, with the patch under each.
async function patchMap(step = 12) {
  return page.evaluate((step) => {
    const v = window.__pdeshape.view;
    const out = [];
    for (let y = step; y < v.canvas.clientHeight; y += step) {
      for (let x = step; x < v.canvas.clientWidth; x += step) out.push([x, y, v.pickPatch(x, y)]);
    }
    return out;
  }, step);
}

const chroma = (c) => {
  const s = c[0] + c[1] + c[2];
  return s > 0 ? c.map((x) => x / s) : [1 / 3, 1 / 3, 1 / 3];
};

test('each patch is drawn in its colour in the legend', async () => {
  await load('examples/cup.toml');
  await surfacesOnly();
  await page.screenshot({ path: path.join(shots, 'patch-colors.png') });
  const scene = await state();
  const legend = await page.evaluate(() => [...document.querySelectorAll('#legend .sw.patch')].map((e) => getComputedStyle(e).backgroundColor));
  assert.equal(legend.length, scene.surfaces.length);
  const swatch = legend.map((t) => t.match(/\d+/g).map(Number));
  const map = await patchMap();
  for (let k = 0; k < scene.surfaces.length; k++) {
    const pts = map.filter((p) => p[2] === k).map((p) => [p[0], p[1]]);
    assert.ok(pts.length > 20, `patch ${k}: only ${pts.length} samples on screen`);
    const px = await pixels(pts);
    const want = chroma(swatch[k]);
    const other = chroma(swatch[1 - k]);
    // Shading scales the colour: compare chromaticities, nearer the patch's own than the other's.
    const near = px.filter((c) => {
      const h = chroma(c);
      const d = (a) => Math.hypot(h[0] - a[0], h[1] - a[1], h[2] - a[2]);
      return d(want) < 0.02 && d(want) < d(other);
    }).length;
    assert.ok(near / px.length > 0.9, `patch ${scene.surfaces[k].name}: ${near} of ${px.length} pixels in its legend colour ${swatch[k]}`);
  }
  await surfacesOnly(false);
});

test('the legend and the status bar lie beside the model; reports wrap inside the panel', async () => {
  for (const [file, size] of [['examples/teacup.toml', { width: 1400, height: 900 }], ['examples/cup.toml', { width: 1280, height: 800 }]]) {
    // The last size is the tests' own.
    await page.setViewportSize(size);
    await load(file);
    await reports();
    await page.screenshot({ path: path.join(shots, `layout-${path.basename(file, '.toml')}.png`) });
    const m = await page.evaluate(() => {
      const r = (id) => document.getElementById(id).getBoundingClientRect();
      const overlap = (a, b) => a.left < b.right && b.left < a.right && a.top < b.bottom && b.top < a.bottom;
      const side = document.getElementById('side');
      const check = document.getElementById('check');
      const table = document.getElementById('analyze');
      return {
        legendOver: overlap(r('legend'), r('view')),
        statusOver: overlap(r('status'), r('view')),
        legendRows: document.querySelectorAll('#legend > div').length,
        sideScrolls: side.scrollWidth > side.clientWidth,
        checkCut: check.scrollWidth > check.clientWidth,
        tableRight: table.getBoundingClientRect().right,
        sideRight: side.getBoundingClientRect().right,
        checkText: check.textContent.length,
      };
    });
    assert.equal(m.legendOver, false, `${file}: the legend covers the model`);
    assert.equal(m.statusOver, false, `${file}: the status covers the model`);
    assert.ok(m.legendRows > 5);
    assert.equal(m.sideScrolls, false, `${file}: the side panel scrolls sideways`);
    assert.equal(m.checkCut, false, `${file}: the check text is cut on the right`);
    assert.ok(m.checkText > 200);
    assert.ok(m.tableRight <= m.sideRight, `${file}: the analysis table ends at ${m.tableRight}, the panel at ${m.sideRight}`);
  }
  await page.setViewportSize({ width: 1280, height: 800 });
});

test('a later success clears an earlier message', async () => {
  await load('examples/cup.toml');
  await page.fill('#tx', 'abc');
  await page.click('#translate');
  await page.waitForFunction(() => document.querySelector('.err[data-for="curve"]').textContent.length > 0);
  await page.fill('#tx', '0');
  await page.fill('#tz', '0.05');
  await page.selectOption('#curve', 'rim');
  await page.click('#translate');
  await page.waitForFunction(() => [...document.querySelectorAll('.err')].every((e) => e.textContent === ''));
});

test('a seam creased beyond the G1 tolerance fails the check and is drawn red', async () => {
  await load('examples/cup_creased.toml');
  await reports();
  const check = await page.textContent('#check');
  assert.ok(check.startsWith('FAIL\nfail: shared edge \'base\' u = 1 | \'bowl\' u = 0 along \'belly\''), check.slice(0, 200));
  const rows = await page.evaluate(() => [...document.querySelectorAll('#edges tr[data-curve]')].map((r) => [r.dataset.curve, r.className]));
  assert.deepEqual(rows, [['belly', 'bad']]);
  // The seam in red on screen, even with the curves hidden.
  await surfacesOnly();
  await page.screenshot({ path: path.join(shots, 'seam-red.png') });
  const seam = await page.evaluate(() => {
    const v = window.__pdeshape.view;
    return window.__pdeshape.state().curves.find((c) => c.name === 'belly').points.map((p) => v.project(p)).filter(Boolean);
  });
  const around = seam.flatMap(([x, y]) => [[x, y], [x, y - 1], [x, y + 1], [x - 1, y], [x + 1, y]]);
  const px = await pixels(around);
  const red = px.filter(([r, g, b]) => r > 170 && g < 70 && b < 70).length;
  assert.ok(red > seam.length / 3, `${red} red pixels along ${seam.length} seam points`);
  // A tolerance above the crease: the seam passes, the verdict asks for attention only.
  await page.fill('#g1-tol', '60');
  await page.dispatchEvent('#g1-tol', 'change');
  await page.waitForFunction(() => document.getElementById('check').textContent.startsWith('ATTENTION'));
  const after = await page.evaluate(() => [...document.querySelectorAll('#edges tr[data-curve]')].map((r) => r.className));
  assert.deepEqual(after, ['ok']);
  const px2 = await pixels(around);
  assert.equal(px2.filter(([r, g, b]) => r > 170 && g < 70 && b < 70).length, 0);
  await page.fill('#g1-tol', '1');
  await page.dispatchEvent('#g1-tol', 'change');
  await surfacesOnly(false);
});

test('a seam whose curvature jumps beyond the G2 tolerance fails the check and is drawn red', async () => {
  // The cup's belly is G1 (a shared derivative curve) but its two patches curve differently.
  await load('examples/cup.toml');
  await reports();
  assert.ok((await page.textContent('#check')).startsWith('OK\n'));
  const g2 = await page.evaluate(async () => (await (await fetch('/api/check', {
    headers: { 'x-pdeshape-token': new URLSearchParams(location.search).get('token') },
  })).json()).edges[0].g2);
  assert.ok(g2 > 1e-3, `G2 figure ${g2}`);
  await surfacesOnly();
  const seam = await page.evaluate(() => {
    const v = window.__pdeshape.view;
    return window.__pdeshape.state().curves.find((c) => c.name === 'belly').points.map((p) => v.project(p)).filter(Boolean);
  });
  const around = seam.flatMap(([x, y]) => [[x, y], [x, y - 1], [x, y + 1], [x - 1, y], [x + 1, y]]);
  const redOf = (px) => px.filter(([r, g, b]) => r > 170 && g < 70 && b < 70).length;
  assert.equal(redOf(await pixels(around)), 0, 'no red before a G2 tolerance is set');
  // Just below the figure: the seam fails, its G2 cell marked, red in the view.
  await page.fill('#g2-tol', (0.99 * g2).toPrecision(4));
  await page.dispatchEvent('#g2-tol', 'change');
  await page.waitForFunction(() => document.getElementById('check').textContent.startsWith('FAIL'));
  const check = await page.textContent('#check');
  assert.ok(check.startsWith("FAIL\nfail: shared edge 'base' u = 1 | 'bowl' u = 0 along 'belly': G2 = "), check.slice(0, 200));
  const row = await page.evaluate(() => {
    const r = document.querySelector('#edges tr[data-curve="belly"]');
    return { cls: r.className, g1: r.querySelector('td.g1').className, g2: r.querySelector('td.g2').className };
  });
  assert.deepEqual(row, { cls: 'bad', g1: 'g1', g2: 'g2 over' });
  await page.waitForTimeout(150);
  await page.screenshot({ path: path.join(shots, 'seam-g2-red.png') });
  const red = redOf(await pixels(around));
  assert.ok(red > seam.length / 3, `${red} red pixels along ${seam.length} seam points`);
  // Just above: it passes; empty: not judged.
  await page.fill('#g2-tol', (1.01 * g2).toPrecision(4));
  await page.dispatchEvent('#g2-tol', 'change');
  await page.waitForFunction(() => document.getElementById('check').textContent.startsWith('OK'));
  assert.equal(await page.evaluate(() => document.querySelector('#edges tr[data-curve="belly"]').className), 'ok');
  await page.waitForTimeout(150);
  assert.equal(redOf(await pixels(around)), 0);
  await page.fill('#g2-tol', '');
  await page.dispatchEvent('#g2-tol', 'change');
  await surfacesOnly(false);
});

// Where zebra stripes cross a seam on screen: along lines parallel to the seam's image (its part
// in sight) at 2 and 5 pixels on either side, the stripes' edges (grey crossing mid-level, to a
// fraction of a pixel); each edge is followed from 5 to 2 pixels and carried on to the seam, from
// above and from below. Returns the edges matched across the seam and the median distance
// between where the two sides put them: a fraction of a pixel where the stripes connect (G1),
// pixels where they jump (a crease: the normals differ across the seam).
async function stripeJump(curve) {
  return page.evaluate((name) => {
    const v = window.__pdeshape.view;
    const c = document.getElementById('view');
    const off = document.createElement('canvas');
    off.width = c.width; off.height = c.height;
    const ctx = off.getContext('2d', { willReadFrequently: true });
    ctx.drawImage(c, 0, 0);
    const img = ctx.getImageData(0, 0, off.width, off.height).data;
    const grey = (x, y) => {
      // Bilinear, so that edges are found to a fraction of a pixel.
      const x0 = Math.floor(x), y0 = Math.floor(y), fx = x - x0, fy = y - y0;
      const at = (i, j) => { const k = 4 * (j * off.width + i); return (img[k] + img[k + 1] + img[k + 2]) / 3; };
      return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) + fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
    };
    const world = window.__pdeshape.state().curves.find((k) => k.name === name).points;
    // The seam's image where it is in sight: the first surface along the ray meets it.
    const seen = world.map((q) => {
      const p = v.project(q);
      if (!p || v.pickPatch(...p) < 0) return null;
      const ray = v.ray(...p);
      const d = Math.hypot(q[0] - ray.origin[0], q[1] - ray.origin[1], q[2] - ray.origin[2]);
      return Math.abs(v.lastPickDistance - d) < 0.01 * v.bounds.radius ? p : null;
    });
    // The longest run of points in sight (the curve is closed).
    let best = [], run = [];
    for (let k = 0; k < 2 * seen.length; k++) {
      const p = seen[k % seen.length];
      if (p) { run.push(p); if (run.length > best.length) best = run.slice(0, seen.length); } else run = [];
    }
    // Dense samples along it, every half pixel, with the unit normal of the image.
    const path = [];
    for (let k = 0; k + 1 < best.length; k++) {
      const [a, b] = [best[k], best[k + 1]];
      const len = Math.hypot(b[0] - a[0], b[1] - a[1]);
      const t = [(b[0] - a[0]) / len, (b[1] - a[1]) / len];
      for (let s = 0; s < len; s += 0.5) path.push({ p: [a[0] + s * t[0], a[1] + s * t[1]], n: [-t[1], t[0]] });
    }
    const edges = (d) => {
      const out = [];
      let prev = null;
      path.forEach(({ p, n }, i) => {
        const x = p[0] + d * n[0], y = p[1] + d * n[1];
        const ok = v.pickPatch(x, y) >= 0;
        const g = ok ? grey(x, y) - 128 : null;
        if (g !== null && prev !== null && Math.sign(g) !== Math.sign(prev) && g !== prev) out.push((i - 1 + prev / (prev - g)) * 0.5);
        prev = g;
      });
      return out;
    };
    const nearest = (list, x, within) => {
      let b = null;
      for (const y of list) if (Math.abs(y - x) <= within && (b === null || Math.abs(y - x) < Math.abs(b - x))) b = y;
      return b;
    };
    // Edges carried to the seam from one side: followed from 5 to 2 pixels, on to 0.
    const carried = (sign) => {
      const near = edges(2 * sign), far = edges(5 * sign);
      const out = [];
      for (const e of near) {
        const f = nearest(far, e, 4);
        if (f !== null) out.push(e + ((e - f) * 2) / 3);
      }
      return out;
    };
    const above = carried(-1), below = carried(1);
    const gaps = [];
    for (const e of above) {
      const f = nearest(below, e, 6);
      if (f !== null) gaps.push(Math.abs(f - e));
    }
    gaps.sort((a, b) => a - b);
    return { length: path.length / 2, edges: above.length, matched: gaps.length, median: gaps.length ? gaps[gaps.length >> 1] : NaN };
  }, curve);
}

test('zebra stripes flow across a G1 seam and break at a crease', async () => {
  const result = {};
  for (const file of ['examples/cup.toml', 'examples/cup_creased.toml']) {
    await load(file);
    await surfacesOnly();
    await page.selectOption('#inspect', 'zebra');
    await page.waitForTimeout(200);
    await page.screenshot({ path: path.join(shots, `zebra-${path.basename(file, '.toml')}.png`) });
    const { levels, dark, light } = await page.evaluate(() => {
      const c = document.getElementById('view');
      const off = document.createElement('canvas');
      off.width = c.width; off.height = c.height;
      const ctx = off.getContext('2d');
      ctx.drawImage(c, 0, 0);
      const d = ctx.getImageData(0, 0, off.width, off.height).data;
      let dark = 0, light = 0;
      for (let i = 0; i < d.length; i += 4) {
        if (d[i] < 40 && d[i + 1] < 40 && d[i + 2] < 40) dark++;
        if (d[i] > 200 && d[i + 1] > 200 && d[i + 2] > 200 && !(d[i] === 247 && d[i + 1] === 247)) light++;
      }
      return { levels: 0, dark, light };
    });
    assert.ok(dark > 5000 && light > 5000, `${file}: no stripes (${dark} dark, ${light} light pixels)`);
    result[file] = await stripeJump('belly');
    assert.ok(result[file].length > 150, `${file}: ${JSON.stringify(result[file])}`);
    await page.selectOption('#inspect', 'shaded');
    await surfacesOnly(false);
  }
  const smooth = result['examples/cup.toml'], creased = result['examples/cup_creased.toml'];
  console.log(`stripes across the seam: G1 ${JSON.stringify(smooth)}, creased ${JSON.stringify(creased)}`);
  assert.ok(smooth.matched > 8 && smooth.median < 0.75, `the stripes do not connect across the G1 seam: ${JSON.stringify(smooth)}`);
  assert.ok(creased.matched >= 3 && creased.median > 2 && creased.median > 4 * smooth.median, `the stripes do not jump at the crease: ${JSON.stringify(creased)}`);
});

test('isophotes and stripe controls change the picture; the lock keeps stripes on the model', async () => {
  await load('examples/cup.toml');
  const digest = () => page.evaluate(() => {
    const c = document.getElementById('view');
    const off = document.createElement('canvas');
    off.width = c.width; off.height = c.height;
    const ctx = off.getContext('2d');
    ctx.drawImage(c, 0, 0);
    const d = ctx.getImageData(0, 0, off.width, off.height).data;
    let h = 0;
    for (let i = 0; i < d.length; i += 4) h = (Math.imul(h, 31) + d[i]) | 0;
    return h;
  });
  await page.selectOption('#inspect', 'zebra');
  await page.waitForTimeout(150);
  const zebra = await digest();
  await page.selectOption('#inspect', 'isophotes');
  await page.waitForTimeout(150);
  const iso = await digest();
  assert.notEqual(zebra, iso);
  await page.selectOption('#inspect', 'reflection');
  await page.waitForTimeout(150);
  const lines = await digest();
  assert.notEqual(lines, zebra);
  assert.notEqual(lines, iso);
  await page.screenshot({ path: path.join(shots, 'reflection-lines.png') });
  await page.selectOption('#inspect', 'isophotes');
  await page.waitForTimeout(150);
  await page.selectOption('#stripe-axis', 'x');
  await page.waitForTimeout(150);
  assert.notEqual(await digest(), iso);
  await page.selectOption('#inspect', 'zebra');
  await page.check('#stripe-lock');
  const locked = await page.evaluate(() => window.__pdeshape.view.inspect.lockedEye);
  assert.ok(Array.isArray(locked) && locked.length === 3);
  await page.uncheck('#stripe-lock');
  assert.equal(await page.evaluate(() => window.__pdeshape.view.inspect.lockedEye), null);
  await page.selectOption('#stripe-axis', 'z');
  await page.selectOption('#inspect', 'shaded');
});

test('draft analysis marks the walls steeper than the least draft angle', async () => {
  await load('examples/cup.toml');
  await surfacesOnly();
  const counts = () => page.evaluate(() => {
    const c = document.getElementById('view');
    const off = document.createElement('canvas');
    off.width = c.width; off.height = c.height;
    const ctx = off.getContext('2d');
    ctx.drawImage(c, 0, 0);
    const d = ctx.getImageData(0, 0, off.width, off.height).data;
    let red = 0, green = 0;
    for (let i = 0; i < d.length; i += 4) {
      if (d[i] > 2 * d[i + 1] + 20 && d[i] > 2 * d[i + 2] + 20) red++;
      if (d[i + 1] > 1.5 * d[i] + 10 && d[i + 1] > 1.5 * d[i + 2] + 10) green++;
    }
    return { red, green };
  });
  await page.selectOption('#inspect', 'draft');
  await page.fill('#draft-angle', '3');
  await page.dispatchEvent('#draft-angle', 'input');
  await page.waitForTimeout(150);
  await page.screenshot({ path: path.join(shots, 'draft.png') });
  const at3 = await counts();
  // The cup's wall is vertical at the belly (its X_u there is vertical): a red band; the bottom
  // and the flaring bowl draw green.
  assert.ok(at3.red > 1000 && at3.green > 5000, JSON.stringify(at3));
  await page.fill('#draft-angle', '15');
  await page.dispatchEvent('#draft-angle', 'input');
  await page.waitForTimeout(150);
  const at15 = await counts();
  assert.ok(at15.red > 1.5 * at3.red, `${JSON.stringify(at15)} against ${JSON.stringify(at3)}`);
  await page.fill('#draft-angle', '0');
  await page.dispatchEvent('#draft-angle', 'input');
  await page.waitForTimeout(150);
  const at0 = await counts();
  assert.ok(at0.red < at3.red / 5, `${JSON.stringify(at0)} against ${JSON.stringify(at3)}`);
  await page.fill('#draft-angle', '3');
  await page.selectOption('#inspect', 'shaded');
  await surfacesOnly(false);
});

test('curvature combs are drawn from the curves\' exact curvature', async () => {
  await load('examples/cup.toml');
  const combPixels = () => page.evaluate(() => {
    const c = document.getElementById('view');
    const off = document.createElement('canvas');
    off.width = c.width; off.height = c.height;
    const ctx = off.getContext('2d');
    ctx.drawImage(c, 0, 0);
    const d = ctx.getImageData(0, 0, off.width, off.height).data;
    let n = 0;
    // The comb colour (0, 0.50, 0.45): green and blue near 128 and 115, no red.
    for (let i = 0; i < d.length; i += 4) if (d[i] < 30 && Math.abs(d[i + 1] - 128) < 25 && Math.abs(d[i + 2] - 115) < 25) n++;
    return n;
  });
  const none = await combPixels();
  assert.equal((await state()).curves.find((c) => c.name === 'belly').comb.length, 0);
  await page.check('#show-combs');
  await page.waitForFunction(() => window.__pdeshape.state().curves.find((c) => c.name === 'belly').comb.length > 0);
  await settled(page);
  await page.screenshot({ path: path.join(shots, 'combs.png') });
  const belly = (await state()).curves.find((c) => c.name === 'belly');
  // A circle of radius 1.5: curvature 1/1.5 everywhere, pointing at its centre (0, 0, 0.9).
  assert.equal(belly.comb.length, 128);
  for (const [p, k] of belly.comb) {
    assert.ok(Math.abs(Math.hypot(...k) - 1 / 1.5) < 1e-12, `${k}`);
    const toCentre = [0 - p[0], 0 - p[1], 0.9 - p[2]];
    const dot = toCentre[0] * k[0] + toCentre[1] * k[1] + toCentre[2] * k[2];
    assert.ok(dot > 0.999 * Math.hypot(...toCentre) * Math.hypot(...k), 'κN does not point at the centre');
  }
  const shown = await combPixels();
  assert.ok(shown > none + 500, `${shown} comb pixels (${none} without combs)`);
  // Across the seam along 'belly': both patches' normal curvatures, at the same points.
  const seams = (await state()).seam_combs;
  assert.equal(seams.length, 1);
  assert.deepEqual([seams[0].curve, seams[0].a, seams[0].b], ['belly', 'base', 'bowl']);
  assert.equal(seams[0].teeth.length, 64);
  const jump = Math.max(...seams[0].teeth.map(([, , a, b]) => Math.abs(a - b)));
  const check = await page.evaluate(async () => {
    const token = new URLSearchParams(location.search).get('token');
    return (await fetch('/api/check', { headers: { 'x-pdeshape-token': token } })).json();
  });
  // The largest jump along the seam is the check's G2 figure (64 of its 256 samples).
  assert.ok(jump > 1e-3 && jump <= check.edges[0].g2 * (1 + 1e-12), `${jump} ${check.edges[0].g2}`);
  await page.$eval('#comb-scale', (e) => { e.value = '2.5'; e.dispatchEvent(new Event('input')); });
  await page.waitForTimeout(150);
  assert.ok((await combPixels()) > shown, 'a larger scale draws longer teeth');
  await page.uncheck('#show-combs');
  await page.waitForFunction(() => window.__pdeshape.state().curves.every((c) => !c.comb || c.comb.length === 0));
});

test('curvature maps take a robust range and show the true one', async () => {
  await load('examples/teacup.toml');
  await page.selectOption('#color', 'gauss');
  await page.waitForFunction(() => !!window.__pdeshape.state().color_range);
  await settled(page);
  await page.waitForTimeout(200);
  await page.screenshot({ path: path.join(shots, 'teacup-gauss.png') });
  const s = await state();
  const [lo, hi] = s.color_range, [min, max] = s.color_full_range;
  assert.ok(min <= lo + 1e-12 || lo < 0, `${lo} ${min}`);
  assert.ok(hi < Math.max(Math.abs(min), Math.abs(max)) / 4, `range ${lo}..${hi} is not narrower than the true ${min}..${max}`);
  const legend = await page.textContent('#legend');
  assert.match(legend, /true range/);
  // A user range is taken as given.
  await page.fill('#c-lo', '-0.5');
  await page.fill('#c-hi', '2');
  await page.dispatchEvent('#c-hi', 'change');
  await page.waitForFunction(() => {
    const r = window.__pdeshape.state().color_range;
    return r && r[0] === -0.5 && r[1] === 2;
  });
  await page.fill('#c-lo', '');
  await page.fill('#c-hi', '');
  await page.selectOption('#color', 'none');
  await settled(page);
});

test('a click selects a curve or a patch; shortcuts frame and turn the view; ? shows help', async () => {
  await load('examples/cup.toml');
  await surfacesOnly(false);
  const box = await page.locator('#view').boundingBox();
  const at = await page.evaluate(() => {
    const v = window.__pdeshape.view;
    const c = window.__pdeshape.state().curves.find((x) => x.name === 'belly');
    // The belly's leftmost point on screen (its silhouette, away from the handles).
    return c.points.map((p) => v.project(p)).filter(Boolean).sort((a, b) => a[0] - b[0])[0];
  });
  await page.mouse.click(box.x + at[0], box.y + at[1]);
  await page.waitForTimeout(100);
  assert.deepEqual(await page.evaluate(() => window.__pdeshape.view.selected), { kind: 'curve', curve: 'belly' });
  assert.equal(await page.inputValue('#curve'), 'belly');
  // A point on the bowl, away from every curve.
  const map = await patchMap(10);
  const scene = await state();
  const bowl = scene.surfaces.findIndex((s) => s.name === 'bowl');
  const far = await page.evaluate((pts) => pts.filter(([x, y]) => !window.__pdeshape.view.pickCurve(x, y, 12)), map.filter((p) => p[2] === bowl));
  const spot = far[Math.floor(far.length / 2)];
  assert.ok(spot);
  await page.mouse.click(box.x + spot[0], box.y + spot[1]);
  await page.waitForTimeout(100);
  assert.deepEqual(await page.evaluate(() => window.__pdeshape.view.selected), { kind: 'patch', patch: 'bowl' });
  assert.equal(await page.inputValue('#patch'), 'bowl');
  assert.match(await page.textContent('#selection'), /patch bowl selected/);
  await page.screenshot({ path: path.join(shots, 'selected-bowl.png') });

  // Pan away (a trackpad's two-finger scroll pans; the wheel zooms), then frame all.
  const cam = () => page.evaluate(() => JSON.parse(JSON.stringify(window.__pdeshape.view.camera)));
  const c0 = await cam();
  await page.mouse.move(box.x + 50, box.y + 50);
  await page.mouse.wheel(30, 8);
  await page.waitForTimeout(100);
  const c1 = await cam();
  assert.notDeepEqual(c1.target, c0.target);
  assert.equal(c1.distance, c0.distance);
  await page.mouse.wheel(0, 200);
  await page.waitForTimeout(100);
  assert.ok((await cam()).distance > c1.distance);
  await page.evaluate(() => document.activeElement && document.activeElement.blur());
  await page.keyboard.press('f');
  const framed = await page.evaluate(() => {
    const v = window.__pdeshape.view;
    return { target: v.camera.target, centre: v.bounds.center, d: v.camera.distance, want: v.frameDistance() };
  });
  assert.deepEqual(framed.target, framed.centre);
  assert.equal(framed.d, framed.want);
  await page.keyboard.press('5');
  assert.equal((await cam()).pitch, 1.55);
  await page.keyboard.press('1');
  const front = await cam();
  assert.equal(front.pitch, 0);
  assert.ok(Math.abs(front.yaw + Math.PI / 2) < 1e-12);
  await page.waitForTimeout(100);
  await page.screenshot({ path: path.join(shots, 'front-view.png') });
  await page.keyboard.press('0');
  // Z toggles the zebra stripes.
  await page.keyboard.press('z');
  assert.equal(await page.inputValue('#inspect'), 'zebra');
  await page.keyboard.press('z');
  assert.equal(await page.inputValue('#inspect'), 'shaded');
  // ? opens the help, Escape closes it.
  assert.equal(await page.isVisible('#help'), false);
  await page.keyboard.press('?');
  assert.equal(await page.isVisible('#help'), true);
  assert.match(await page.textContent('#help'), /frame all/);
  await page.screenshot({ path: path.join(shots, 'help.png') });
  await page.keyboard.press('Escape');
  assert.equal(await page.isVisible('#help'), false);
  // Plain labels: section numbers only in tooltips.
  const headings = await page.evaluate(() => [...document.querySelectorAll('h2, h3, button, label')]
    .map((e) => (e.querySelector('#file-name') ? e.firstChild.textContent : e.textContent)).join(' '));
  assert.doesNotMatch(headings, /§/);
});

test('a circle keeps its kind: its centre and radius handles are dragged', async () => {
  await load('examples/cup.toml');
  await surfacesOnly(false);
  const handle = (role) => page.evaluate((role) => {
    const { view } = window.__pdeshape;
    const h = view.pickable.find((p) => p.kind === 'analytic' && p.curve === 'belly' && p.role === role);
    const s = view.project(h.point);
    const r = view.canvas.getBoundingClientRect();
    return [s[0] + r.left, s[1] + r.top];
  }, role);
  const belly = async () => (await state()).curves.find((c) => c.name === 'belly');
  const [x, y] = await handle('radius');
  const v0 = (await state()).version;
  await page.mouse.move(x, y);
  await page.mouse.down();
  for (let k = 1; k <= 8; k++) {
    await page.mouse.move(x + 4 * k, y);
    await page.waitForTimeout(16);
  }
  await page.mouse.up();
  await page.waitForFunction((v) => window.__pdeshape.state().version > v && window.__pdeshape.idle(), v0);
  await settled(page);
  let c = await belly();
  assert.equal(c.kind, 'circle');
  assert.equal(c.spec.type, 'circle');
  assert.ok(Math.abs(c.spec.radius - 1.5) > 0.05, `radius ${c.spec.radius}`);
  assert.deepEqual(c.spec.center, [0, 0, 0.9]);
  await page.screenshot({ path: path.join(shots, 'circle-handles.png') });
  // The centre handle moves the whole circle; one undo step per drag.
  const [cx, cy] = await handle('center');
  const v1 = (await state()).version;
  await page.mouse.move(cx, cy);
  await page.mouse.down();
  for (let k = 1; k <= 6; k++) {
    await page.mouse.move(cx, cy - 4 * k);
    await page.waitForTimeout(16);
  }
  await page.mouse.up();
  await page.waitForFunction((v) => window.__pdeshape.state().version > v && window.__pdeshape.idle(), v1);
  await settled(page);
  c = await belly();
  assert.ok(c.spec.center[2] > 0.95, `centre ${c.spec.center}`);
  const radius = c.spec.radius;
  await page.click('#undo');
  await page.waitForFunction(() => window.__pdeshape.state().curves.find((x) => x.name === 'belly').spec.center[2] === 0.9);
  assert.equal((await belly()).spec.radius, radius);
});

test('a dragged control point snaps to the grid; the axis triad turns with the view', async () => {
  await newDesign();
  await page.selectOption('#snap', 'grid');
  await page.fill('#snap-step', '0.25');
  const [x, y] = await page.evaluate(() => {
    const { view, state } = window.__pdeshape;
    const s = view.project(state().curves.find((c) => c.name === 'rim').control[1]);
    const r = view.canvas.getBoundingClientRect();
    return [s[0] + r.left, s[1] + r.top];
  });
  const v0 = (await state()).version;
  await page.mouse.move(x, y);
  await page.mouse.down();
  for (let k = 1; k <= 10; k++) {
    await page.mouse.move(x + 6 * k, y - 2 * k);
    await page.waitForTimeout(16);
  }
  await page.mouse.up();
  await page.waitForFunction((v) => window.__pdeshape.state().version > v && window.__pdeshape.idle(), v0);
  await settled(page);
  const p = (await state()).curves.find((c) => c.name === 'rim').control[1];
  assert.notDeepEqual(p, [1.1, 0, 2]);
  for (const c of p) assert.ok(Number.isInteger(c / 0.25), `${p} is not on the 0.25 grid`);
  await page.selectOption('#snap', 'off');
  // The triad: red, green and blue pixels in the bottom-left corner, moving with the view.
  const corner = () => page.evaluate(() => {
    const c = document.getElementById('view');
    const off = document.createElement('canvas');
    off.width = c.width; off.height = c.height;
    const ctx = off.getContext('2d');
    ctx.drawImage(c, 0, 0);
    const d = ctx.getImageData(0, c.height - 70, 70, 70).data;
    const n = { r: 0, g: 0, b: 0, at: [] };
    for (let i = 0; i < d.length; i += 4) {
      // Antialiased lines blend with the background: the channel's lead over the other two.
      const [r, g, b] = [d[i], d[i + 1], d[i + 2]];
      if (r - Math.max(g, b) > 50) { n.r++; n.at.push(i); }
      if (g - Math.max(r, b) > 30) n.g++;
      if (b - Math.max(r, g) > 50) n.b++;
    }
    n.at = n.at.join(',');
    return n;
  });
  const a = await corner();
  assert.ok(a.r > 10 && a.g > 10 && a.b > 10, JSON.stringify({ ...a, at: '' }));
  await page.evaluate(() => window.__pdeshape.view.orbit(120, 0));
  await page.waitForTimeout(100);
  assert.notEqual((await corner()).at, a.at, 'the triad did not turn');
});

test('a dragged control point snaps to the coordinate planes; a click on the triad sets the view', async () => {
  // The same small drag of the rim's point [1.1, 0, 2] (on the plane y = 0) in the view plane,
  // without snapping and snapping to the planes: only the snapped one stays exactly on y = 0.
  const drag = async (mode) => {
    await newDesign();
    await page.selectOption('#snap', mode);
    const [x, y] = await page.evaluate(() => {
      const { view, state } = window.__pdeshape;
      const s = view.project(state().curves.find((c) => c.name === 'rim').control[1]);
      const r = view.canvas.getBoundingClientRect();
      return [s[0] + r.left, s[1] + r.top];
    });
    const v0 = (await state()).version;
    await page.mouse.move(x, y);
    await page.mouse.down();
    for (let k = 1; k <= 4; k++) {
      await page.mouse.move(x + 2 * k, y - 1 * k);
      await page.waitForTimeout(16);
    }
    await page.mouse.up();
    await page.waitForFunction((v) => window.__pdeshape.state().version > v && window.__pdeshape.idle(), v0);
    await settled(page);
    return (await state()).curves.find((c) => c.name === 'rim').control[1];
  };
  const free = await drag('off');
  assert.notEqual(free[1], 0, `the free drag stayed on y = 0: ${free}`);
  const snapped = await drag('planes');
  assert.equal(snapped[1], 0, `not snapped to y = 0: ${snapped}`);
  // The typed-coordinates fields show where the drag left the point.
  const typed = await page.evaluate(() => ['px', 'py', 'pz'].map((id) => Number(document.getElementById(id).value)));
  assert.deepEqual(typed, snapped);
  assert.ok(Math.abs(snapped[0] - 1.1) > 1e-3 || Math.abs(snapped[2] - 2) > 1e-3, `the point did not move: ${snapped}`);
  await page.selectOption('#snap', 'off');

  // The triad's +z end gives the top view, its +x end the view from +x (the right view).
  const clickEnd = async (axis) => {
    const [x, y] = await page.evaluate((a) => {
      const v = window.__pdeshape.view;
      const [tx, ty] = v.triadTip(a);
      const r = v.canvas.getBoundingClientRect();
      return [tx + r.left, ty + r.top];
    }, axis);
    await page.mouse.click(x, y);
    await page.waitForTimeout(100);
    return page.evaluate(() => { const c = window.__pdeshape.view.camera; return [c.yaw, c.pitch]; });
  };
  const version = (await state()).version;
  const [, pitch] = await clickEnd('+z');
  assert.equal(pitch, 1.55);
  await page.screenshot({ path: path.join(shots, 'triad-top.png') });
  const [yaw, pitch2] = await clickEnd('+x');
  assert.deepEqual([yaw, pitch2], [0, 0]);
  assert.equal((await state()).version, version, 'a click on the triad changed the design');
  await page.screenshot({ path: path.join(shots, 'triad-right.png') });
  await page.keyboard.press('0');
});

test('a drag shows a coarser grid (and, on a software renderer, fewer pixels) while it runs and the full detail when it ends', async () => {
  await load('examples/cup.toml');
  await page.selectOption('#curve', 'rim');
  await page.click('#convert');
  await page.waitForFunction(() => window.__pdeshape.state().curves.find((c) => c.name === 'rim').control);
  await settled(page);
  const [px, py] = await page.evaluate(() => {
    const { view, state } = window.__pdeshape;
    const s = view.project(state().curves.find((c) => c.name === 'rim').control[2]);
    const r = view.canvas.getBoundingClientRect();
    return [s[0] + r.left, s[1] + r.top];
  });
  const v0 = (await state()).version;
  const grids = [];
  await page.mouse.move(px, py);
  await page.mouse.down();
  for (let k = 1; k <= 12; k++) {
    await page.mouse.move(px + 3 * k, py - k);
    await page.waitForTimeout(30);
    grids.push((await state()).grid.join('x'));
  }
  const drawn = () => page.evaluate(() => {
    const { view } = window.__pdeshape;
    return {
      triangles: view.meshes.reduce((n, m) => n + m.count / 3, 0),
      counts: view.meshes.map((m) => m.count),
      buffer: [view.canvas.width, view.canvas.height],
      css: [view.canvas.clientWidth, view.canvas.clientHeight],
      software: view.software,
    };
  });
  const during = await drawn();
  await page.mouse.up();
  await page.waitForFunction((v) => window.__pdeshape.state().version > v && window.__pdeshape.idle(), v0);
  await settled(page);
  const budget = await page.evaluate(() => window.__pdeshape.gestureBudget);
  // At most half the grid in each direction, and the same grid all through the drag.
  const coarse = grids.filter((g) => g !== '64x128');
  assert.ok(coarse.length > 0, `no coarse frame during the drag: ${grids}`);
  const [cu, cv] = coarse[0].split('x').map(Number);
  assert.ok(cu <= 32 && cv <= 64 && coarse.every((g) => g === coarse[0]), `${grids}`);
  // This test's Chromium draws without a GPU (SwiftShader): the gesture's frames hold at most
  // budget.triangles triangles, up to the grid's rounding (each side rounded by ≤ 0.5 on ≥ 8
  // points: a factor ≤ (1 + 0.5/8)² ≈ 1.13), and at most budget.pixels device pixels (each side
  // rounded by ≤ 0.5 pixel).
  assert.ok(during.software, 'the test expects a software renderer');
  assert.ok(during.triangles <= 1.13 * budget.triangles, `triangles drawn during the drag: ${during.triangles}`);
  const [bw, bh] = during.buffer;
  assert.ok(bw * bh <= budget.pixels + (bw + bh) / 2 + 1, `drawing buffer during the drag: ${bw}x${bh}`);
  const dpr = await page.evaluate(() => window.devicePixelRatio || 1);
  const full = (d) => d.css.map((x) => Math.round(x * dpr));
  if (during.css[0] * during.css[1] * dpr * dpr > 1.1 * budget.pixels) {
    assert.ok(bw < full(during)[0], `the drawing buffer is not reduced: ${bw}x${bh} for ${during.css}`);
  }
  assert.deepEqual((await state()).grid, [64, 128]);
  const after = await drawn();
  assert.ok(after.counts[0] > 3 * during.counts[0], `triangles drawn ${during.counts} during, ${after.counts} after`);
  assert.deepEqual(after.buffer, full(after), 'the full resolution after the drag');
  // With "full detail while dragging" every frame of a drag is on the full grid, drawn at full
  // resolution.
  await page.check('#full-drag');
  const grids2 = [];
  const v1 = (await state()).version;
  await page.mouse.move(px + 36, py - 12);
  await page.mouse.down();
  for (let k = 1; k <= 6; k++) {
    await page.mouse.move(px + 36 - 3 * k, py - 12 + k);
    await page.waitForTimeout(30);
    grids2.push((await state()).grid.join('x'));
  }
  const during2 = await drawn();
  await page.mouse.up();
  await page.waitForFunction((v) => window.__pdeshape.state().version > v && window.__pdeshape.idle(), v1);
  assert.ok(grids2.every((g) => g === '64x128'), `${grids2}`);
  assert.deepEqual(during2.buffer, full(during2), 'the full resolution during a full-detail drag');
  await page.uncheck('#full-drag');
});

test('control points picked with Ctrl-click move together', async () => {
  await newDesign();
  const at = (index) => page.evaluate((index) => {
    const { view, state } = window.__pdeshape;
    const s = view.project(state().curves.find((c) => c.name === 'rim').control[index]);
    const r = view.canvas.getBoundingClientRect();
    return [s[0] + r.left, s[1] + r.top];
  }, index);
  const before = (await state()).curves.find((c) => c.name === 'rim').control;
  const [x2, y2] = await at(2);
  await page.keyboard.down('Control');
  await page.mouse.click(x2, y2);
  const [x1, y1] = await at(1);
  await page.mouse.click(x1, y1);
  await page.keyboard.up('Control');
  assert.match(await page.textContent('#selection'), /control points 1, 2 of rim selected/);
  const v0 = (await state()).version;
  await page.mouse.move(x1, y1);
  await page.mouse.down();
  for (let k = 1; k <= 8; k++) {
    await page.mouse.move(x1 + 5 * k, y1 - 3 * k);
    await page.waitForTimeout(16);
  }
  await page.mouse.up();
  await page.waitForFunction((v) => window.__pdeshape.state().version > v && window.__pdeshape.idle(), v0);
  await settled(page);
  const after = (await state()).curves.find((c) => c.name === 'rim').control;
  const d1 = after[1].map((c, i) => c - before[1][i]);
  const d2 = after[2].map((c, i) => c - before[2][i]);
  assert.ok(Math.hypot(...d1) > 0.05, `${after[1]}`);
  for (let i = 0; i < 3; i++) assert.ok(Math.abs(d1[i] - d2[i]) < 1e-12, `${d1} ${d2}`);
  for (const k of [0, 3, 4, 5, 6, 7]) assert.deepEqual(after[k], before[k]);
  // One undo takes the whole group drag back.
  await page.click('#undo');
  await page.waitForFunction(() => !window.__pdeshape.state().can_undo);
  assert.deepEqual((await state()).curves.find((c) => c.name === 'rim').control, before);
});

test('typed coordinates move the selected control point exactly', async () => {
  await newDesign();
  const [x, y] = await page.evaluate(() => {
    const { view, state } = window.__pdeshape;
    const s = view.project(state().curves.find((c) => c.name === 'rim').control[1]);
    const r = view.canvas.getBoundingClientRect();
    return [s[0] + r.left, s[1] + r.top];
  });
  await page.mouse.click(x, y);
  await page.waitForFunction(() => !document.getElementById('point-row').hidden);
  assert.equal(await page.textContent('#point-name'), 'rim[1]');
  const v0 = (await state()).version;
  await page.fill('#px', '0.9');
  await page.fill('#py', '-0.125');
  await page.fill('#pz', '2.3');
  await page.click('#point-set');
  await page.waitForFunction((v) => window.__pdeshape.state().version > v, v0);
  const p = (await state()).curves.find((c) => c.name === 'rim').control[1];
  assert.deepEqual(p, [0.9, -0.125, 2.3]);
  // Relative: the numbers are added to the point.
  await page.check('#point-relative');
  await page.fill('#px', '0.25');
  await page.fill('#py', '0');
  await page.fill('#pz', '-0.5');
  const v1 = (await state()).version;
  await page.click('#point-set');
  await page.waitForFunction((v) => window.__pdeshape.state().version > v, v1);
  const q = (await state()).curves.find((c) => c.name === 'rim').control[1];
  assert.deepEqual(q, [0.9 + 0.25, -0.125, 2.3 - 0.5]);
  await page.uncheck('#point-relative');
  // A bad number is named and changes nothing.
  await page.fill('#py', 'two');
  await page.click('#point-set');
  await page.waitForFunction(() => document.querySelector('.err[data-for="point"]').textContent.includes("y: expected a number (got 'two')"));
});

test('from a new design to a saved G1 multi-patch shape without a text editor', async () => {
  await newDesign();
  // A circle above the rim, then a patch from the rim to it: G1 along the rim by default.
  await page.selectOption('#new-kind', 'circle');
  await page.fill('#new-name', 'top');
  await page.fill('#new-center', '0,0,3');
  await page.fill('#new-radius', '0.7');
  let v = (await state()).version;
  await page.click('#add-curve');
  await page.waitForFunction((v) => window.__pdeshape.state().version > v, v);
  await page.selectOption('#from', 'rim');
  await page.selectOption('#to', 'top');
  await page.fill('#patch-name', 'neck');
  v = (await state()).version;
  await page.click('#add-patch');
  await page.waitForFunction((v) => window.__pdeshape.state().version > v, v);
  await page.waitForFunction(() => document.getElementById('add-note').textContent.length > 0);
  assert.match(await page.textContent('#add-note'), /^G1 with body along rim/);
  await page.click('#refresh-reports');
  await page.waitForFunction(() => document.querySelector('#edges tr[data-curve="rim"]')
    && document.getElementById('check').textContent.includes('curves: 7'));
  const rows = await page.evaluate(() => [...document.querySelectorAll('#edges tr[data-curve]')].map((r) => [r.dataset.curve, r.className]));
  assert.deepEqual(rows, [['rim', 'ok']]);
  assert.ok((await page.textContent('#check')).startsWith('OK\n'));
  await page.screenshot({ path: path.join(shots, 'new-design.png') });
  await page.fill('#save-path', 'new_shape.toml');
  await page.click('#save');
  await page.waitForFunction(() => document.getElementById('status').textContent.startsWith('saved new_shape.toml'));
  const r = spawnSync(binary(), ['check', 'new_shape.toml'], { cwd: dir });
  assert.equal(r.status, 0, String(r.stdout) + String(r.stderr));
  assert.equal(String(r.stdout).split('\n')[0], 'OK');
  assert.match(String(r.stdout), /shared edges:\n  'body' u = 1 \| 'neck' u = 0  along 'rim'/);
});

test('a STEP download carries its certified deviation and reads back', async () => {
  await load('examples/cup.toml');
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('.dl a[data-format="step"]')]);
  const file = path.join(dir, 'cup-download.step');
  await download.saveAs(file);
  assert.equal(download.suggestedFilename(), 'cup.step');
  const text = fs.readFileSync(file, 'utf8');
  assert.ok(text.startsWith('ISO-10303-21;'), text.slice(0, 40));
  await page.waitForFunction(() => document.getElementById('file-note').textContent.startsWith('STEP:'));
  const note = await page.textContent('#file-note');
  assert.match(note, /^STEP: 2 B-spline surface\(s\), deviation from the design ≤ \d\.\d{3}e-\d+ \(certified; tolerance \d\.\d{3}e-\d+\)$/);
  const r = spawnSync(binary(), ['roundtrip', path.join(dir, 'examples', 'cup.toml'), file], { cwd: dir });
  assert.equal(r.status, 0, String(r.stdout) + String(r.stderr));
  assert.match(String(r.stdout), /2 surface\(s\) read back/);
  // IGES too; an unknown format is a 400 naming it.
  const [iges] = await Promise.all([page.waitForEvent('download'), page.click('.dl a[data-format="iges"]')]);
  assert.equal(iges.suggestedFilename(), 'cup.iges');
  const bad = await fetch(`${server.origin}/api/download?format=dxf`, { headers: { 'x-pdeshape-token': server.token } });
  assert.equal(bad.status, 400);
  assert.match((await bad.json()).error, /step or igs/);
});

test('unsaved changes are asked about before loading and before closing', async () => {
  await load('examples/cup.toml');
  assert.equal(await page.evaluate(() => window.__pdeshape.dirty()), false);
  await page.selectOption('#curve', 'rim');
  await page.fill('#tx', '0');
  await page.fill('#tz', '0.05');
  await page.click('#translate');
  await page.waitForFunction(() => window.__pdeshape.dirty());
  const before = dialogs.length;
  await page.selectOption('#files', 'examples/wine_glass.toml');
  page.acceptDialogs = false;
  await page.click('#load');
  await page.waitForTimeout(300);
  assert.equal(dialogs.length, before + 1);
  assert.equal(dialogs[before].type, 'confirm');
  assert.match(dialogs[before].message, /unsaved changes/);
  // Dismissed: the edited cup stays.
  assert.equal((await state()).file, 'examples/cup.toml');
  // Saved work is not asked about.
  await page.fill('#save-path', 'kept.toml');
  await page.click('#save');
  await page.waitForFunction(() => document.getElementById('status').textContent.startsWith('saved'));
  assert.equal(await page.evaluate(() => window.__pdeshape.dirty()), false);
  await page.selectOption('#files', 'examples/wine_glass.toml');
  await page.click('#load');
  await page.waitForFunction(() => window.__pdeshape.state().file === 'examples/wine_glass.toml');
  assert.equal(dialogs.length, before + 1);
  // Scrubbing a timeline shows the design at another time: nothing to save.
  await load('examples/anim/ventricle.toml');
  const s0 = await state();
  const box = await page.locator('#t-slider').boundingBox();
  await page.mouse.click(box.x + box.width * 0.5, box.y + box.height / 2);
  await page.waitForFunction((v) => window.__pdeshape.state().version > v, s0.version);
  await settled(page);
  assert.equal(await page.evaluate(() => window.__pdeshape.dirty()), false);
  assert.equal(dialogs.length, before + 1);
  // Closing the tab with unsaved work asks too.
  await page.selectOption('#curve', (await state()).curves[0].name);
  await page.click('#translate');
  await page.waitForFunction(() => window.__pdeshape.dirty());
  await page.close({ runBeforeUnload: true });
  for (let k = 0; k < 50 && dialogs.length < before + 2; k++) await new Promise((r) => setTimeout(r, 100));
  assert.equal(dialogs.length, before + 2);
  assert.equal(dialogs[before + 1].type, 'beforeunload');
  assert.deepEqual(errors, []);
});

test('serve takes a design outside the start directory and saves beside it', async () => {
  const outside = fs.mkdtempSync(path.join(os.tmpdir(), 'pdeshape-outside-'));
  const design = path.join(outside, 'mine.toml');
  fs.copyFileSync(path.join(repo, 'examples', 'cup.toml'), design);
  const elsewhere = fs.mkdtempSync(path.join(os.tmpdir(), 'pdeshape-cwd-'));
  for (const [args, saveDir] of [[[design], outside], [[design, '--root', path.dirname(outside)], path.dirname(outside)]]) {
    const s = await startServer(elsewhere, args);
    try {
      const headers = { 'x-pdeshape-token': s.token };
      const frame = await fetch(`${s.origin}/api/frame?nu=8&nv=16`, { headers });
      assert.equal(frame.status, 200);
      const saved = await fetch(`${s.origin}/api/save`, {
        method: 'POST', headers: { ...headers, 'content-type': 'application/json' }, body: JSON.stringify({ path: 'copy.toml' }),
      });
      assert.equal(saved.status, 200, await saved.clone().text());
      assert.ok(fs.existsSync(path.join(saveDir, 'copy.toml')), `not saved in ${saveDir}`);
      fs.rmSync(path.join(saveDir, 'copy.toml'));
    } finally {
      await stopServer(s);
    }
  }
  // A design outside --root is refused with one line.
  const r = spawnSync(binary(), ['serve', '--port', '0', design, '--root', elsewhere], { cwd: elsewhere });
  assert.equal(r.status, 2);
  const lines = String(r.stderr).trim().split('\n');
  assert.equal(lines.length, 1, String(r.stderr));
  assert.match(lines[0], /^error: .*mine\.toml: lies outside --root/);
});
