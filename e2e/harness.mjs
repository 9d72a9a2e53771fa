// Starts `pdeshape serve` in a fresh start directory and headless Chromium (Debian's
// /usr/bin/chromium, driven by playwright-core) with a fresh profile.

import { spawn } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

export const repo = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');

export function binary() {
  if (process.env.PDESHAPE_BIN) return process.env.PDESHAPE_BIN;
  const target = process.env.CARGO_TARGET_DIR || path.join(repo, 'target');
  return path.join(target, 'release', 'pdeshape');
}

// A start directory holding copies of the examples the tests load.
export function startDir() {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'pdeshape-e2e-'));
  fs.mkdirSync(path.join(dir, 'examples', 'anim'), { recursive: true });
  for (const f of ['cup.toml', 'wine_glass.toml', 'teacup.toml', 'trimmed_vase.toml', 'aeroplane.toml', 'swirl_port_params.toml',
    'anim/ventricle.toml', 'anim/fish.toml', 'nsided_pentagon.toml']) {
    fs.copyFileSync(path.join(repo, 'examples', f), path.join(dir, 'examples', f));
  }
  return dir;
}

// Starts the server in `dir`; resolves to { url, origin, token, proc } once it prints its URL.
export function startServer(dir, args = []) {
  const bin = binary();
  if (!fs.existsSync(bin)) throw new Error(`${bin} is missing: build it with cargo build --release`);
  const proc = spawn(bin, ['serve', '--port', '0', ...args], { cwd: dir, stdio: ['ignore', 'pipe', 'pipe'] });
  return new Promise((resolve, reject) => {
    let out = '';
    let err = '';
    const timer = setTimeout(() => reject(new Error(`no URL within 30 s: ${out} ${err}`)), 30000);
    proc.stderr.on('data', (d) => { err += d; });
    proc.stdout.on('data', (d) => {
      out += d;
      const m = out.match(/(http:\/\/[^\s]+\/\?token=([0-9a-f]+))/);
      if (m) {
        clearTimeout(timer);
        const url = new URL(m[1]);
        resolve({ url: m[1], origin: url.origin, token: m[2], proc, stderr: () => err });
      }
    });
    proc.on('exit', (code) => reject(new Error(`server exited with ${code}: ${err}`)));
  });
}

export function stopServer(server) {
  return new Promise((resolve) => {
    if (server.proc.exitCode !== null) return resolve(server.proc.exitCode);
    server.proc.once('exit', (code, signal) => resolve(code ?? signal));
    server.proc.kill('SIGINT');
  });
}

// The test viewport is 1280 × 800 with `--disable-gpu`; `renderer: 'swiftshader'` draws WebGL
// with SwiftShader instead (the benchmarks compare both).
export async function launchBrowser({ viewport = { width: 1280, height: 800 }, renderer = 'disable-gpu' } = {}) {
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'pdeshape-chromium-'));
  const gpu = renderer === 'swiftshader' ? ['--use-angle=swiftshader', '--enable-unsafe-swiftshader'] : ['--disable-gpu'];
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: '/usr/bin/chromium',
    headless: true,
    viewport,
    args: [
      '--headless', '--no-sandbox', ...gpu, '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync',
    ],
  });
  return { context, profile };
}

// Opens the page and waits for the first frame on screen.
export async function openPage(context, url) {
  const page = await context.newPage();
  const errors = [];
  page.on('pageerror', (e) => errors.push(String(e)));
  await page.goto(url);
  await page.waitForFunction(() => window.__pdeshape && window.__pdeshape.perf.frames > 0 && window.__pdeshape.state());
  return { page, errors };
}

// Waits until no drag or request is in flight and the scene's version is at least `version`.
export async function settled(page, version = 0) {
  await page.waitForFunction((v) => {
    const s = window.__pdeshape.state();
    return s && s.version >= v;
  }, version);
  await page.waitForTimeout(100);
}

export function percentile(values, p) {
  const s = [...values].sort((a, b) => a - b);
  if (!s.length) return NaN;
  const k = Math.min(s.length - 1, Math.max(0, Math.ceil((p / 100) * s.length) - 1));
  return s[k];
}
