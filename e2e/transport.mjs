// What a request costs the browser itself, apart from any server work: a POST answered at once
// with 98 000 bytes (a drag frame's size), by `fetch` and by a message on an open WebSocket, to
// a minimal Node server in this process (no design, no pdeshape). BENCHMARKS.md quotes it for
// the designer's socket (crates/pdeshape-cli/src/serve/socket.rs).
// Usage: node transport.mjs [requests] [disable-gpu|swiftshader]   (a benchmark, not a test)

import http from 'node:http';
import crypto from 'node:crypto';
import { launchBrowser, percentile } from './harness.mjs';

const n = Number(process.argv[2] || 60);
const renderer = process.argv[3] || 'disable-gpu';
const payload = Buffer.alloc(98000, 7);
const page = `<!doctype html><script>
window.run = async (n) => {
  const out = { fetch: [], socket: [] };
  const pause = () => new Promise((r) => setTimeout(r, 15));
  for (let i = 0; i < n; i++) {
    const t = performance.now();
    const r = await fetch('/data', { method: 'POST', body: '{"edit":1}' });
    await r.arrayBuffer();
    out.fetch.push(performance.now() - t);
    await pause();
  }
  const ws = new WebSocket('ws://' + location.host + '/socket');
  ws.binaryType = 'arraybuffer';
  await new Promise((r) => { ws.onopen = r; });
  for (let i = 0; i < n; i++) {
    const t = performance.now();
    const answered = new Promise((r) => { ws.onmessage = r; });
    ws.send('{"edit":1}');
    await answered;
    out.socket.push(performance.now() - t);
    await pause();
  }
  return out;
};</script>`;

const server = http.createServer((req, res) => {
  if (req.url === '/data') {
    req.resume();
    req.on('end', () => {
      res.writeHead(200, { 'content-type': 'application/octet-stream' });
      res.end(payload);
    });
    return;
  }
  res.writeHead(200, { 'content-type': 'text/html' });
  res.end(page);
});
// A WebSocket by hand (RFC 6455): the handshake, then one unmasked binary frame per message.
server.on('upgrade', (req, socket) => {
  const accept = crypto.createHash('sha1')
    .update(req.headers['sec-websocket-key'] + '258EAFA5-E914-47DA-95CA-C5AB0DC85B11').digest('base64');
  socket.write(`HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Accept: ${accept}\r\n\r\n`);
  socket.setNoDelay(true);
  socket.on('data', () => {
    const head = Buffer.alloc(10);
    head[0] = 0x82;
    head[1] = 127;
    head.writeBigUInt64BE(BigInt(payload.length), 2);
    socket.write(Buffer.concat([head, payload]));
  });
});
await new Promise((r) => server.listen(0, '127.0.0.1', r));
const { context } = await launchBrowser({ viewport: { width: 800, height: 600 }, renderer });
const tab = await context.newPage();
await tab.goto(`http://127.0.0.1:${server.address().port}/`);
const r = await tab.evaluate((k) => window.run(k), n);
await context.close();
server.close();
const f = (x) => x.toFixed(2);
for (const k of ['fetch', 'socket']) {
  console.log(`${k}: p50 ${f(percentile(r[k], 50))} ms p95 ${f(percentile(r[k], 95))} ms (${n} requests of 98 000 bytes)`);
}
