// A STEP download from the page read back by OpenCascade (cadquery-ocp, as .ci/occ.sh installs
// it): the file reads, its shape is valid, it has one face per patch, and every vertex the page
// draws (exact points of the design's surfaces) lies within the deviation the page states of
// the nearest face. Needs OCC_PYTHON, a Python with the OCP bindings (.ci/.venv-occ/bin/python
// after .ci/occ.sh); without it the test fails, it does not skip.
// Run: OCC_PYTHON=../.ci/.venv-occ/bin/python npm run test:occ

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { spawnSync } from 'node:child_process';
import { startDir, startServer, stopServer, launchBrowser, openPage, settled } from './harness.mjs';

let dir, server, browser, page;

before(async () => {
  dir = startDir();
  server = await startServer(dir);
  browser = await launchBrowser();
  ({ page } = await openPage(browser.context, server.url));
  page.on('dialog', (d) => d.accept());
});

after(async () => {
  if (browser) await browser.context.close();
  if (server) await stopServer(server);
});

test('a STEP download is read back by OpenCascade within the stated deviation', async () => {
  const python = process.env.OCC_PYTHON;
  assert.ok(python && fs.existsSync(python), 'OCC_PYTHON must name a Python with the OCP bindings (see .ci/occ.sh)');
  for (const [file, patches] of [['examples/cup.toml', 2], ['examples/wine_glass.toml', 3]]) {
    await page.selectOption('#files', file);
    await page.click('#load');
    await page.waitForFunction((f) => window.__pdeshape.state().file === f, file);
    await settled(page);
    const [download] = await Promise.all([page.waitForEvent('download'), page.click('.dl a[data-format="step"]')]);
    const step = path.join(dir, `${path.basename(file, '.toml')}.step`);
    await download.saveAs(step);
    await page.waitForFunction(() => document.getElementById('file-note').textContent.startsWith('STEP:'));
    const note = await page.textContent('#file-note');
    const m = note.match(/deviation from the design ≤ (\d\.\d{3}e-\d+)/);
    assert.ok(m, note);
    // The stated deviation is rounded to four digits: allow the rounding.
    const deviation = Number(m[1]) * 1.001;
    // Every 7th vertex of the drawn grids: exact points of the solved surfaces.
    const points = await page.evaluate(() => {
      const out = [];
      for (const s of window.__pdeshape.lastFrame().surfaces) {
        for (let i = 0; i < s.positions.length; i += 21) out.push([s.positions[i], s.positions[i + 1], s.positions[i + 2]]);
      }
      return out;
    });
    assert.ok(points.length > 100);
    const json = path.join(dir, 'points.json');
    fs.writeFileSync(json, JSON.stringify({ points }));
    const r = spawnSync(python, [path.join(path.dirname(new URL(import.meta.url).pathname), 'occ_read.py'), step, json], { encoding: 'utf8' });
    assert.equal(r.status, 0, r.stderr);
    const got = JSON.parse(r.stdout);
    assert.equal(got.read, true, file);
    assert.equal(got.valid, true, file);
    assert.equal(got.faces, patches, file);
    // The page's vertices are single precision: add their rounding (about 1e-7 of the size).
    assert.ok(got.worst <= deviation + 1e-6, `${file}: a vertex lies ${got.worst} from the STEP faces (stated ≤ ${deviation})`);
  }
});
