// The 3D view (WebGL2): shaded patches with their normals (trimmed ones as their triangle meshes,
// holes cut out), curves, derivative vectors, spines with their Bézier control points, trim
// curves on their surfaces, v = 0 marks, shared edges, control points and the handles of a local
// edit; orbit, pan and zoom; picking and drag planes.

import * as m from './math.js';

const SURFACE_VS = `#version 300 es
in vec3 position;
in vec3 normal;
in vec3 color;
uniform mat4 mvp;
out vec3 vNormal;
out vec3 vColor;
void main() {
  vNormal = normal;
  vColor = color;
  gl_Position = mvp * vec4(position, 1.0);
}`;

const SURFACE_FS = `#version 300 es
precision highp float;
in vec3 vNormal;
in vec3 vColor;
uniform vec3 eyeDir;
uniform vec3 lightDir;
out vec4 outColor;
void main() {
  vec3 n = normalize(vNormal);
  // Two-sided: light the side we see.
  if (dot(n, eyeDir) < 0.0) n = -n;
  float diffuse = max(dot(n, lightDir), 0.0);
  float rim = max(dot(n, eyeDir), 0.0);
  vec3 c = vColor * (0.28 + 0.62 * diffuse + 0.15 * rim);
  outColor = vec4(c, 1.0);
}`;

const LINE_VS = `#version 300 es
in vec3 position;
in vec3 color;
uniform mat4 mvp;
uniform float pointSize;
out vec3 vColor;
void main() {
  vColor = color;
  gl_Position = mvp * vec4(position, 1.0);
  gl_Position.z -= 0.002 * gl_Position.w; // lines and points in front of the surface they lie on
  gl_PointSize = pointSize;
}`;

const LINE_FS = `#version 300 es
precision highp float;
in vec3 vColor;
out vec4 outColor;
void main() { outColor = vec4(vColor, 1.0); }`;

// Colours of the legend (also used by app.js).
export const COLORS = {
  patches: [[0.78, 0.80, 0.86], [0.86, 0.78, 0.62], [0.66, 0.82, 0.70], [0.84, 0.68, 0.76], [0.68, 0.76, 0.88]],
  position: [0.85, 0.12, 0.10],
  other: [0.95, 0.55, 0.10],
  vector: [0.10, 0.60, 0.20],
  spine: [0.10, 0.30, 0.85],
  v0: [0.0, 0.0, 0.0],
  edge: [0.75, 0.0, 0.75],
  control: [0.05, 0.35, 0.60],
  controlLine: [0.45, 0.45, 0.45],
  spineControl: [0.55, 0.10, 0.75],
  trim: [0.90, 0.55, 0.08],
  local: [0.0, 0.65, 0.65],
  selected: [1.0, 0.85, 0.0],
};

function compile(gl, vs, fs) {
  const p = gl.createProgram();
  for (const [type, src] of [[gl.VERTEX_SHADER, vs], [gl.FRAGMENT_SHADER, fs]]) {
    const s = gl.createShader(type);
    gl.shaderSource(s, src);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    gl.attachShader(p, s);
  }
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
  return p;
}

// Triangles of an nu × nv grid (u-major), wrapping in v when periodic.
function gridIndices(nu, nv, periodic) {
  const cols = periodic ? nv : nv - 1;
  const out = new Uint32Array((nu - 1) * cols * 6);
  let k = 0;
  for (let i = 0; i < nu - 1; i++) {
    for (let j = 0; j < cols; j++) {
      const j1 = (j + 1) % nv;
      const a = i * nv + j, b = (i + 1) * nv + j, c = (i + 1) * nv + j1, d = i * nv + j1;
      out[k++] = a; out[k++] = b; out[k++] = c;
      out[k++] = a; out[k++] = c; out[k++] = d;
    }
  }
  return out;
}

export class View {
  constructor(canvas) {
    this.canvas = canvas;
    const gl = canvas.getContext('webgl2', { antialias: true, preserveDrawingBuffer: true });
    if (!gl) throw new Error('this browser has no WebGL2');
    this.gl = gl;
    this.surfaceProgram = compile(gl, SURFACE_VS, SURFACE_FS);
    this.lineProgram = compile(gl, LINE_VS, LINE_FS);
    this.meshes = [];
    this.indexCache = new Map();
    this.lines = null;
    this.points = null;
    this.camera = { target: [0, 0, 1], distance: 8, yaw: -0.95, pitch: 0.48, panned: false };
    this.pending = false;
    this.onDrawn = null;
    this.show = { curves: true, vectors: true, spines: true, control: true, edges: true };
    this.selected = null; // { kind: 'control', curve, index } or { kind: 'spine', patch, index }
    this.local = null; // a local edit's points: { x1, x2, handle }
  }

  // Meshes of a frame: one vertex array per surface, buffers reused when the sizes match.
  setSurfaces(surfaces, patchColors) {
    const gl = this.gl;
    while (this.meshes.length > surfaces.length) {
      const old = this.meshes.pop();
      gl.deleteVertexArray(old.vao);
      for (const b of old.buffers) gl.deleteBuffer(b);
    }
    surfaces.forEach((s, k) => {
      let mesh = this.meshes[k];
      if (!mesh) {
        const vao = gl.createVertexArray();
        const buffers = [gl.createBuffer(), gl.createBuffer(), gl.createBuffer(), gl.createBuffer()];
        mesh = { vao, buffers, key: '' };
        this.meshes[k] = mesh;
      }
      gl.bindVertexArray(mesh.vao);
      const p = this.surfaceProgram;
      gl.bindBuffer(gl.ARRAY_BUFFER, mesh.buffers[0]);
      gl.bufferData(gl.ARRAY_BUFFER, s.positions, gl.DYNAMIC_DRAW);
      let loc = gl.getAttribLocation(p, 'position');
      gl.enableVertexAttribArray(loc);
      gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, 0, 0);
      gl.bindBuffer(gl.ARRAY_BUFFER, mesh.buffers[1]);
      gl.bufferData(gl.ARRAY_BUFFER, s.normals, gl.DYNAMIC_DRAW);
      loc = gl.getAttribLocation(p, 'normal');
      gl.enableVertexAttribArray(loc);
      gl.vertexAttribPointer(loc, 3, gl.SHORT, true, 0, 0);
      loc = gl.getAttribLocation(p, 'color');
      if (s.colors) {
        gl.bindBuffer(gl.ARRAY_BUFFER, mesh.buffers[2]);
        gl.bufferData(gl.ARRAY_BUFFER, s.colors, gl.DYNAMIC_DRAW);
        gl.enableVertexAttribArray(loc);
        gl.vertexAttribPointer(loc, 3, gl.UNSIGNED_BYTE, true, 0, 0);
      } else {
        gl.disableVertexAttribArray(loc);
        const c = patchColors[k % patchColors.length];
        gl.vertexAttrib3f(loc, c[0], c[1], c[2]);
      }
      if (s.indices) {
        // A trimmed surface: its own triangles (the holes cut out).
        gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, mesh.buffers[3]);
        gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, s.indices, gl.DYNAMIC_DRAW);
        mesh.count = s.indices.length;
      } else {
        // A grid: its faces are implied, one index buffer per grid shape.
        const key = `${s.nu}x${s.nv}${s.periodic ? 'p' : ''}`;
        if (!this.indexCache.has(key)) {
          const ib = gl.createBuffer();
          gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ib);
          const idx = gridIndices(s.nu, s.nv, s.periodic);
          gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, idx, gl.STATIC_DRAW);
          this.indexCache.set(key, { ib, count: idx.length });
        }
        const { ib, count } = this.indexCache.get(key);
        gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ib);
        mesh.count = count;
      }
      mesh.trimmed = !!s.indices;
      gl.bindVertexArray(null);
    });
    this.bounds = this.computeBounds(surfaces);
    if (!this.camera.panned && this.bounds) {
      this.camera.target = this.bounds.center;
      if (!this.framed) {
        // The whole design in view, across the narrower of the view's two sides.
        const aspect = this.canvas.clientWidth / Math.max(this.canvas.clientHeight, 1);
        this.camera.distance = Math.max((this.bounds.radius * 4.2) / Math.min(1, aspect || 1), 1e-3);
        this.framed = true;
      }
    }
  }

  computeBounds(surfaces) {
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (const s of surfaces) {
      const p = s.positions;
      for (let i = 0; i < p.length; i += 3) {
        for (let c = 0; c < 3; c++) {
          if (p[i + c] < lo[c]) lo[c] = p[i + c];
          if (p[i + c] > hi[c]) hi[c] = p[i + c];
        }
      }
    }
    if (!isFinite(lo[0])) return null;
    return { center: m.scale(m.add(lo, hi), 0.5), radius: Math.max(m.norm(m.sub(hi, lo)) / 2, 1e-6) };
  }

  // Line segments (pairs of points) and points with colours, from a scene.
  setScene(scene) {
    this.scene = scene;
    const seg = [], segCol = [], pts = [], ptsCol = [];
    const line = (a, b, c) => { seg.push(...a, ...b); segCol.push(...c, ...c); };
    const polyline = (points, closed, c) => {
      for (let k = 0; k + 1 < points.length; k++) line(points[k], points[k + 1], c);
      if (closed && points.length > 2) line(points[points.length - 1], points[0], c);
    };
    // Curves along shared edges are drawn in the edge colour.
    const edgeCurves = new Set(this.show.edges ? scene.shared_curves : []);
    if (this.show.curves) {
      for (const c of scene.curves) {
        if (!c.points.length) continue;
        const col = edgeCurves.has(c.name) ? COLORS.edge
          : c.role === 'position' ? COLORS.position : COLORS.other;
        polyline(c.points, c.closed, col);
        if (c.v0) {
          // The v = 0 mark: a dot and a short tick along the direction of increasing v.
          pts.push(...c.v0.point); ptsCol.push(...COLORS.v0);
          const t = m.unit(c.v0.tangent);
          const r = this.bounds ? this.bounds.radius * 0.08 : 0.1;
          line(c.v0.point, m.add(c.v0.point, m.scale(t, r)), COLORS.v0);
        }
      }
    }
    if (this.show.vectors) {
      for (const v of scene.vectors) for (const [a, b] of v.segments) line(a, b, COLORS.vector);
    }
    // The trim curves' images on their surfaces (the holes' edges).
    for (const l of scene.trim_lines || []) polyline(l, true, COLORS.trim);
    const sel = this.selected || {};
    this.pickable = [];
    if (this.show.spines) {
      for (const s of scene.surfaces) {
        polyline(s.spine, false, COLORS.spine);
        // The spine's Bézier control points (§5.3): handles to drag.
        if (!s.spine_control) continue;
        polyline(s.spine_control, false, COLORS.spineControl);
        s.spine_control.forEach((p, index) => {
          const isSel = sel.kind === 'spine' && sel.patch === s.name && sel.index === index;
          pts.push(...p);
          ptsCol.push(...(isSel ? COLORS.selected : s.hosts ? COLORS.controlLine : COLORS.spineControl));
          // A host of attached patches keeps its spine: its points are shown, not handles.
          if (!s.hosts) this.pickable.push({ kind: 'spine', patch: s.name, index, point: p });
        });
      }
    }
    if (this.show.control) {
      for (const c of scene.curves) {
        if (!c.control) continue;
        polyline(c.control, c.closed, COLORS.controlLine);
        c.control.forEach((p, index) => {
          const isSel = sel.kind === 'control' && sel.curve === c.name && sel.index === index;
          pts.push(...p);
          ptsCol.push(...(isSel ? COLORS.selected : COLORS.control));
          this.pickable.push({ kind: 'control', curve: c.name, index, point: p });
        });
      }
    }
    if (this.local) {
      // A local edit (§6.2): X1 and X2 fixed, the handle X3 to drag.
      const { x1, x2, handle } = this.local;
      for (const p of [x1, x2]) { pts.push(...p); ptsCol.push(...COLORS.local); }
      line(x1, handle, COLORS.local);
      line(handle, x2, COLORS.local);
      pts.push(...handle);
      ptsCol.push(...(sel.kind === 'local' ? COLORS.selected : COLORS.local));
      this.pickable.push({ kind: 'local', point: handle });
    }
    this.lines = this.upload(this.lines, seg, segCol);
    this.points = this.upload(this.points, pts, ptsCol);
  }

  upload(target, positions, colors) {
    const gl = this.gl;
    if (!target) {
      target = { vao: gl.createVertexArray(), pb: gl.createBuffer(), cb: gl.createBuffer(), count: 0 };
    }
    gl.bindVertexArray(target.vao);
    const p = this.lineProgram;
    gl.bindBuffer(gl.ARRAY_BUFFER, target.pb);
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(positions), gl.DYNAMIC_DRAW);
    let loc = gl.getAttribLocation(p, 'position');
    gl.enableVertexAttribArray(loc);
    gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, 0, 0);
    gl.bindBuffer(gl.ARRAY_BUFFER, target.cb);
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(colors), gl.DYNAMIC_DRAW);
    loc = gl.getAttribLocation(p, 'color');
    gl.enableVertexAttribArray(loc);
    gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, 0, 0);
    gl.bindVertexArray(null);
    target.count = positions.length / 3;
    return target;
  }

  eye() {
    const c = this.camera;
    const dir = [Math.cos(c.pitch) * Math.cos(c.yaw), Math.cos(c.pitch) * Math.sin(c.yaw), Math.sin(c.pitch)];
    return m.add(c.target, m.scale(dir, c.distance));
  }

  matrices() {
    const w = this.canvas.clientWidth, h = this.canvas.clientHeight;
    const r = this.bounds ? this.bounds.radius : 1;
    const near = Math.max(this.camera.distance - 4 * r, this.camera.distance * 0.01);
    const proj = m.perspective(Math.PI / 6, w / Math.max(h, 1), near, this.camera.distance + 4 * r);
    const viewM = m.lookAt(this.eye(), this.camera.target, [0, 0, 1]);
    return { proj, view: viewM, mvp: m.multiply(proj, viewM), w, h };
  }

  // Asks for a draw at the next animation frame (several requests make one draw).
  request() {
    if (this.pending) return;
    this.pending = true;
    requestAnimationFrame(() => {
      this.pending = false;
      this.draw();
    });
  }

  draw() {
    const gl = this.gl;
    const dpr = window.devicePixelRatio || 1;
    const w = Math.round(this.canvas.clientWidth * dpr), h = Math.round(this.canvas.clientHeight * dpr);
    if (this.canvas.width !== w || this.canvas.height !== h) {
      this.canvas.width = w;
      this.canvas.height = h;
    }
    gl.viewport(0, 0, w, h);
    gl.clearColor(0.97, 0.97, 0.98, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    const { mvp } = this.matrices();
    const eyeDir = m.unit(m.sub(this.eye(), this.camera.target));
    const light = m.unit(m.add(eyeDir, [0.3, 0.2, 0.8]));
    gl.useProgram(this.surfaceProgram);
    gl.uniformMatrix4fv(gl.getUniformLocation(this.surfaceProgram, 'mvp'), false, mvp);
    gl.uniform3fv(gl.getUniformLocation(this.surfaceProgram, 'eyeDir'), eyeDir);
    gl.uniform3fv(gl.getUniformLocation(this.surfaceProgram, 'lightDir'), light);
    for (const mesh of this.meshes) {
      gl.bindVertexArray(mesh.vao);
      gl.drawElements(gl.TRIANGLES, mesh.count, gl.UNSIGNED_INT, 0);
    }
    gl.useProgram(this.lineProgram);
    gl.uniformMatrix4fv(gl.getUniformLocation(this.lineProgram, 'mvp'), false, mvp);
    gl.uniform1f(gl.getUniformLocation(this.lineProgram, 'pointSize'), 7 * dpr);
    if (this.lines && this.lines.count) {
      gl.bindVertexArray(this.lines.vao);
      gl.drawArrays(gl.LINES, 0, this.lines.count);
    }
    if (this.points && this.points.count) {
      gl.bindVertexArray(this.points.vao);
      gl.drawArrays(gl.POINTS, 0, this.points.count);
    }
    gl.bindVertexArray(null);
    if (this.onDrawn) this.onDrawn();
  }

  // Screen position (CSS pixels) of a world point.
  project(p, mats = this.matrices()) {
    const [x, y, , w] = m.transform(mats.mvp, p);
    if (w <= 0) return null;
    return [((x / w) * 0.5 + 0.5) * mats.w, (1 - ((y / w) * 0.5 + 0.5)) * mats.h];
  }

  // The ray through a screen position: origin (the eye) and unit direction.
  ray(sx, sy) {
    const c = this.camera;
    const eye = this.eye();
    const fwd = m.unit(m.sub(c.target, eye));
    const right = m.unit(m.cross(fwd, [0, 0, 1]));
    const up = m.cross(right, fwd);
    const w = this.canvas.clientWidth, h = this.canvas.clientHeight;
    const t = Math.tan(Math.PI / 12);
    const nx = ((sx / w) * 2 - 1) * t * (w / h);
    const ny = (1 - (sy / h) * 2) * t;
    return { origin: eye, dir: m.unit(m.add(fwd, m.add(m.scale(right, nx), m.scale(up, ny)))) };
  }

  // The drawn point of curve `name` nearest to a screen position (within `radius` CSS pixels):
  // its index in the curve's points, or -1.
  pickCurvePoint(sx, sy, name, radius = 14) {
    const c = this.scene && this.scene.curves.find((x) => x.name === name);
    if (!c) return -1;
    const mats = this.matrices();
    let best = -1, bestD = radius;
    c.points.forEach((p, k) => {
      const s = this.project(p, mats);
      if (!s) return;
      const d = Math.hypot(s[0] - sx, s[1] - sy);
      if (d < bestD) { bestD = d; best = k; }
    });
    return best;
  }

  // The handle (control point, spine control point, local-edit handle) nearest to a screen
  // position, within `radius` CSS pixels.
  pick(sx, sy, radius = 12) {
    const mats = this.matrices();
    let best = null, bestD = radius;
    for (const p of this.pickable || []) {
      const s = this.project(p.point, mats);
      if (!s) continue;
      const d = Math.hypot(s[0] - sx, s[1] - sy);
      if (d < bestD) { bestD = d; best = p; }
    }
    return best;
  }

  // The plane a drag moves in: through `point`, normal to the view or to a coordinate axis.
  dragPlane(point, mode) {
    const normal = { xy: [0, 0, 1], xz: [0, 1, 0], yz: [1, 0, 0] }[mode]
      || m.unit(m.sub(this.eye(), this.camera.target));
    return { point, normal };
  }

  orbit(dx, dy) {
    this.camera.yaw -= dx * 0.008;
    this.camera.pitch = Math.max(-1.55, Math.min(1.55, this.camera.pitch + dy * 0.008));
    this.request();
  }

  pan(dx, dy) {
    const c = this.camera;
    const fwd = m.unit(m.sub(c.target, this.eye()));
    const right = m.unit(m.cross(fwd, [0, 0, 1]));
    const up = m.cross(right, fwd);
    const k = (2 * c.distance * Math.tan(Math.PI / 12)) / this.canvas.clientHeight;
    c.target = m.add(c.target, m.add(m.scale(right, -dx * k), m.scale(up, dy * k)));
    c.panned = true;
    this.request();
  }

  zoom(factor) {
    this.camera.distance = Math.max(1e-4, this.camera.distance * factor);
    this.request();
  }
}
