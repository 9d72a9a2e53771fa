// The designer's API: every request carries the token from the page's URL; frames (scene JSON
// and meshes) are decoded from the server's binary layout (see serve/scene.rs).

const token = new URLSearchParams(location.search).get('token') || '';

export class ApiError extends Error {
  constructor(status, message, place) {
    super(message);
    this.status = status;
    this.place = place || '';
  }
}

async function request(method, path, body) {
  const init = { method, headers: { 'x-pdeshape-token': token } };
  if (body !== undefined) {
    init.body = JSON.stringify(body);
    init.headers['content-type'] = 'application/json';
  }
  const started = performance.now();
  const response = await fetch('/api/' + path, init);
  if (!response.ok) {
    let message = response.statusText;
    let place = '';
    try {
      const j = await response.json();
      message = j.error || message;
      place = j.place || '';
    } catch (_) { /* not JSON */ }
    throw new ApiError(response.status, message, place);
  }
  return { response, started };
}

export function decodeFrame(buffer) {
  const view = new DataView(buffer);
  const magic = String.fromCharCode(...new Uint8Array(buffer, 0, 4));
  if (magic !== 'PDSF') throw new ApiError(0, 'not a frame', '');
  const jsonLen = view.getUint32(4, true);
  const scene = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 8, jsonLen)));
  let at = 8 + jsonLen;
  const count = view.getUint32(at, true);
  at += 4;
  const surfaces = [];
  for (let s = 0; s < count; s++) {
    const nu = view.getUint32(at, true);
    const nv = view.getUint32(at + 4, true);
    const flags = view.getUint32(at + 8, true);
    at += 12;
    let n = nu * nv;
    let triangles = 0;
    if (flags & 4) {
      n = view.getUint32(at, true);
      triangles = view.getUint32(at + 4, true);
      at += 8;
    }
    const positions = new Float32Array(buffer, at, 3 * n);
    at += 12 * n;
    const normals = new Int16Array(buffer, at, 3 * n);
    at += Math.ceil((6 * n) / 4) * 4;
    let colors = null;
    if (flags & 2) {
      colors = new Uint8Array(buffer, at, 3 * n);
      at += Math.ceil((3 * n) / 4) * 4;
    }
    // A trimmed surface (holes cut out) comes with its triangles; a grid's are implied.
    let indices = null;
    if (flags & 4) {
      indices = new Uint32Array(buffer, at, 3 * triangles);
      at += 12 * triangles;
    }
    surfaces.push({ nu, nv, periodic: (flags & 1) !== 0, positions, normals, colors, indices });
  }
  return { scene, surfaces };
}

// The frames' requests go over one WebSocket while it is open (a browser's fetch costs a few
// milliseconds of its own per request, a message on an open socket well under one; see
// serve/socket.rs), else over HTTP. A request whose socket closes before its answer fails
// (the server may or may not have done it; the next frame shows which).
class Socket {
  constructor() {
    this.ws = null;
    this.next = 1;
    this.waiting = new Map();
    this.retryAt = 0;
  }

  // True when requests can go over the socket now; else starts opening it (at most every 2 s).
  ready() {
    if (this.ws && this.ws.readyState === WebSocket.OPEN) return true;
    if (typeof WebSocket === 'undefined' || this.ws || performance.now() < this.retryAt) return false;
    this.retryAt = performance.now() + 2000;
    const scheme = location.protocol === 'https:' ? 'wss:' : 'ws:';
    const ws = new WebSocket(`${scheme}//${location.host}/socket?token=${encodeURIComponent(token)}`);
    ws.binaryType = 'arraybuffer';
    ws.onmessage = (ev) => this.answer(ev.data);
    ws.onclose = () => {
      this.ws = null;
      for (const w of this.waiting.values()) w.reject(new ApiError(0, 'the connection to the server closed', ''));
      this.waiting.clear();
    };
    this.ws = ws;
    return false;
  }

  send(method, path, body) {
    const id = this.next++;
    const message = { id, method, path };
    if (body !== undefined) message.body = body;
    return new Promise((resolve, reject) => {
      this.waiting.set(id, { resolve, reject, started: performance.now() });
      this.ws.send(JSON.stringify(message));
    });
  }

  // An answer: id (u32), HTTP status (u16), kind (u16: 0 a frame, 1 JSON), then its bytes.
  answer(data) {
    if (!(data instanceof ArrayBuffer) || data.byteLength < 8) return;
    const head = new DataView(data, 0, 8);
    const id = head.getUint32(0, true), status = head.getUint16(4, true), kind = head.getUint16(6, true);
    const w = this.waiting.get(id);
    if (!w) return;
    this.waiting.delete(id);
    const body = data.slice(8);
    if (status >= 200 && status < 300 && kind === 0) {
      try {
        const frame = decodeFrame(body);
        frame.roundTripMs = performance.now() - w.started;
        frame.bytes = body.byteLength;
        transport.socket += 1;
        w.resolve(frame);
      } catch (e) { w.reject(e); }
      return;
    }
    let j = {};
    try { j = JSON.parse(new TextDecoder().decode(body)); } catch (_) { /* not JSON */ }
    w.reject(new ApiError(status, j.error || `the server answered ${status}`, j.place || ''));
  }
}
const socket = new Socket();
// Frames received by each way (the tests check that a drag's go over the socket).
export const transport = { socket: 0, http: 0 };
socket.ready(); // opened with the page, so the first gesture finds it open

async function frameOf(method, path, body) {
  if (socket.ready()) return socket.send(method, path, body);
  const { response, started } = await request(method, path, body);
  const buffer = await response.arrayBuffer();
  const frame = decodeFrame(buffer);
  frame.roundTripMs = performance.now() - started;
  frame.bytes = buffer.byteLength;
  transport.http += 1;
  return frame;
}

export const api = {
  frame: (q) => frameOf('GET', 'frame?' + q),
  edit: (q, body) => frameOf('POST', 'edit?' + q, body),
  convert: (q, name) => frameOf('POST', 'convert?' + q, { name }),
  spine: (q, body) => frameOf('POST', 'spine?' + q, body),
  local: (q, body) => frameOf('POST', 'local?' + q, body),
  localFrame: async (q) => (await (await request('GET', 'local?' + q)).response.json()),
  time: (q, t) => frameOf('POST', 'time?' + q, { t }),
  undo: (q) => frameOf('POST', 'undo?' + q),
  redo: (q) => frameOf('POST', 'redo?' + q),
  reset: (q) => frameOf('POST', 'new?' + q),
  load: (q, path) => frameOf('POST', 'load?' + q, { path }),
  save: async (path) => (await (await request('POST', 'save', { path })).response.json()),
  files: async () => (await (await request('GET', 'files')).response.json()),
  check: async (g1, g2 = '') => (await (await request('GET', `check?g1_tolerance=${g1}&g2_tolerance=${g2}`)).response.json()),
  analyze: async () => (await (await request('GET', 'analyze')).response.json()),
  download: async (q) => {
    const { response } = await request('GET', 'download?' + q);
    return { blob: await response.blob(), cad: response.headers.get('x-pdeshape-cad') };
  },
};
