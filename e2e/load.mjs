// Load test of `pdeshape serve` on loopback: 50 concurrent clients × 1000 requests each, mixed
// (frames, edits, undo/redo, file lists, and bad requests: no token, foreign Origin, malformed
// JSON, oversized grid, unknown path, edit of a missing curve, a missing spine point, an empty
// local edit, time on a still design, a missing trim). Bounded in time (DEADLINE_S).
// Prints the count per status, p50/p99 latency per kind, and the server's resident memory.
// Usage: node load.mjs [clients] [requests per client]   (a benchmark: not part of the tests)

import fs from 'node:fs';
import { startDir, startServer, stopServer, percentile } from './harness.mjs';

const clients = Number(process.argv[2] || 50);
const perClient = Number(process.argv[3] || 1000);
const DEADLINE_S = 600;

const dir = startDir();
const server = await startServer(dir);
const rss = () => {
  const m = fs.readFileSync(`/proc/${server.proc.pid}/status`, 'utf8').match(/VmRSS:\s+(\d+)/);
  return m ? Number(m[1]) / 1024 : NaN;
};
const rssStart = rss();
let rssMax = rssStart;
const sampler = setInterval(() => { rssMax = Math.max(rssMax, rss()); }, 250);

const base = server.origin;
const auth = { 'x-pdeshape-token': server.token };
const q = 'nu=16&nv=32';
let seed = 12345;
const rand = () => { seed = (seed * 1103515245 + 12345) % 2147483648; return seed / 2147483648; };

function pick() {
  const r = rand();
  if (r < 0.30) return ['frame', () => fetch(`${base}/api/frame?${q}`, { headers: auth })];
  if (r < 0.55) {
    const body = JSON.stringify({ edit: { edit: 'move_control_point', name: 'rim', index: Math.floor(rand() * 8),
      point: [0.8 + 0.4 * rand(), 0.8 * rand(), 2 + 0.3 * rand()] } });
    return ['edit', () => fetch(`${base}/api/edit?${q}`, { method: 'POST', headers: auth, body })];
  }
  if (r < 0.62) return ['undo', () => fetch(`${base}/api/${rand() < 0.5 ? 'undo' : 'redo'}?${q}`, { method: 'POST', headers: auth })];
  if (r < 0.67) return ['files', () => fetch(`${base}/api/files`, { headers: auth })];
  const bad = [
    () => fetch(`${base}/api/frame?${q}`),
    () => fetch(`${base}/api/frame?${q}`, { headers: { ...auth, origin: 'http://evil.example' } }),
    () => fetch(`${base}/api/edit?${q}`, { method: 'POST', headers: auth, body: '{"edit": ' }),
    () => fetch(`${base}/api/frame?nu=100000&nv=5`, { headers: auth }),
    () => fetch(`${base}/api/nowhere`, { headers: auth }),
    () => fetch(`${base}/api/edit?${q}`, { method: 'POST', headers: auth,
      body: JSON.stringify({ edit: { edit: 'move_control_point', name: 'nope', index: 0, point: [0, 0, 0] } }) }),
    () => fetch(`${base}/api/load?${q}`, { method: 'POST', headers: auth, body: '{"path": "../../etc/x.toml"}' }),
    () => fetch(`${base}/api/spine?${q}`, { method: 'POST', headers: auth, body: '{"index": 9, "point": [0, 0, 1]}' }),
    () => fetch(`${base}/api/local?${q}`, { method: 'POST', headers: auth, body: '{"name": "rim", "from": 1, "to": 1}' }),
    () => fetch(`${base}/api/local?name=rim&from=x&to=1`, { headers: auth }),
    () => fetch(`${base}/api/time?${q}`, { method: 'POST', headers: auth, body: '{"t": 0.5}' }),
    () => fetch(`${base}/api/edit?${q}`, { method: 'POST', headers: auth, body: '{"edit": {"edit": "remove_trim", "index": 3}}' }),
  ];
  return ['bad', bad[Math.floor(rand() * bad.length)]];
}

const statuses = {};
const times = {};
let done = 0;
let failures = 0;
const started = performance.now();
const deadline = started + DEADLINE_S * 1000;

async function client() {
  for (let k = 0; k < perClient && performance.now() < deadline; k++) {
    const [kind, go] = pick();
    const t = performance.now();
    try {
      const r = await go();
      await r.arrayBuffer();
      statuses[r.status] = (statuses[r.status] || 0) + 1;
      (times[kind] ||= []).push(performance.now() - t);
    } catch (e) {
      failures++;
    }
    done++;
  }
}

await Promise.all(Array.from({ length: clients }, client));
const elapsed = (performance.now() - started) / 1000;
clearInterval(sampler);
const rssEnd = rss();
const code = await stopServer(server);
const all = Object.values(times).flat();
console.log(`${clients} clients × ${perClient} requests: ${done} done in ${elapsed.toFixed(1)} s (${(done / elapsed).toFixed(0)} req/s), ${failures} connection failures, server exit ${code}`);
console.log('statuses', JSON.stringify(statuses));
const f = (x) => x.toFixed(1);
console.log(`all: p50 ${f(percentile(all, 50))} ms p99 ${f(percentile(all, 99))} ms`);
for (const [kind, t] of Object.entries(times)) {
  console.log(`${kind} (${t.length}): p50 ${f(percentile(t, 50))} ms p99 ${f(percentile(t, 99))} ms`);
}
console.log(`server RSS: start ${f(rssStart)} MiB, max ${f(rssMax)} MiB, end ${f(rssEnd)} MiB`);
const fivexx = Object.entries(statuses).filter(([s]) => Number(s) >= 500).reduce((n, [, c]) => n + c, 0);
if (fivexx > 0 || failures > 0 || code !== 0) process.exit(1);
