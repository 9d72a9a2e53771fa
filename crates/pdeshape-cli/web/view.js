// The 3D view (WebGL2): shaded patches with their normals (trimmed ones as their triangle meshes,
// holes cut out), curves, derivative vectors, spines with their Bézier control points, trim
// curves on their surfaces, v = 0 marks, shared edges, control points and the handles of a local
// edit; orbit, pan and zoom; picking and drag planes.

import * as m from './math.js';

// The axis triad: its corner's size (CSS pixels) and its six ends, each with the standard view
// (eye yaw and pitch about the target) from that side; a click on an end sets that view.
const TRIAD = 70;
const TRIAD_ENDS = [
  { axis: '+x', tip: [1, 0, 0], yaw: 0, pitch: 0 },
  { axis: '-x', tip: [-0.6, 0, 0], yaw: Math.PI, pitch: 0 },
  { axis: '+y', tip: [0, 1, 0], yaw: Math.PI / 2, pitch: 0 },
  { axis: '-y', tip: [0, -0.6, 0], yaw: -Math.PI / 2, pitch: 0 },
  { axis: '+z', tip: [0, 0, 1], yaw: -Math.PI / 2, pitch: 1.55 },
  { axis: '-z', tip: [0, 0, -0.6], yaw: -Math.PI / 2, pitch: -1.55 },
];

const SURFACE_VS = `#version 300 es
in vec3 position;
in vec3 normal;
in vec3 color;
uniform mat4 mvp;
out vec3 vNormal;
out vec3 vColor;
out vec3 vPos;
void main() {
  vNormal = normal;
  vColor = color;
  vPos = position;
  gl_Position = mvp * vec4(position, 1.0);
}`;

// Shaded, zebra or isophotes. The stripes are computed per pixel from the normal interpolated
// between the vertices' exact unit normals (X_u × X_v from the surface's derivatives, on the
// frame's grid): a G1 seam keeps the stripes continuous, a crease breaks them, and the stripes
// do not follow the triangles as per-vertex stripe values would.
const SURFACE_FS = `#version 300 es
precision highp float;
in vec3 vNormal;
in vec3 vColor;
in vec3 vPos;
uniform vec3 eyeDir;
uniform vec3 lightDir;
uniform vec3 eyePos;
// 0 shaded, 1 zebra (reflected stripes), 2 isophotes, 3 draft, 4 reflection lines: a constant
// of each mode's own program (a software renderer would run every branch of a uniform's).
const int mode = MODE;
uniform float draftAngle; // the least draft angle (radians) of draft analysis
uniform vec3 stripeAxis; // the stripes' axis (unit)
uniform float stripes;   // stripes around the axis (zebra) or from the axis to its opposite
out vec4 outColor;
const float PI = 3.14159265358979;
void main() {
  vec3 n = normalize(vNormal);
  vec3 toEye = mode == 1 || mode == 4 ? normalize(eyePos - vPos) : eyeDir;
  // Two-sided: light the side we see.
  if (dot(n, toEye) < 0.0) n = -n;
  if (mode == 0) {
    float diffuse = max(dot(n, lightDir), 0.0);
    float rim = max(dot(n, eyeDir), 0.0);
    outColor = vec4(vColor * (0.28 + 0.62 * diffuse + 0.15 * rim), 1.0);
    return;
  }
  if (mode == 3) {
    // Draft analysis along the pull direction (the axis): the draft angle is the angle between
    // the surface and the pull direction, asin |n · d|, taken without the normal's sign (a
    // patch's X_u × X_v may point in or out). Below the least angle: red; above: green.
    float draft = asin(clamp(abs(dot(n, stripeAxis)), 0.0, 1.0));
    float w = max(fwidth(draft), 1e-4);
    vec3 c = mix(vec3(0.85, 0.15, 0.12), vec3(0.20, 0.68, 0.30), smoothstep(draftAngle - w, draftAngle + w, draft));
    float diffuse = max(dot(n, lightDir), 0.0);
    outColor = vec4(c * (0.45 + 0.55 * diffuse), 1.0);
    return;
  }
  float phase;
  if (mode == 1) {
    // The reflection of the view ray in an infinite cylinder of stripes around the axis.
    vec3 r = reflect(-toEye, n);
    vec3 b = normalize(abs(stripeAxis.z) < 0.9 ? cross(stripeAxis, vec3(0.0, 0.0, 1.0)) : cross(stripeAxis, vec3(1.0, 0.0, 0.0)));
    vec3 c = cross(stripeAxis, b);
    phase = (atan(dot(r, c), dot(r, b)) / (2.0 * PI) + 0.5) * stripes;
  } else if (mode == 4) {
    // Reflection lines: the reflected view ray's elevation from the plane normal to the axis
    // (bands of equal latitude of an environment sphere about the axis).
    vec3 r = reflect(-toEye, n);
    phase = (asin(clamp(dot(r, stripeAxis), -1.0, 1.0)) / PI + 0.5) * stripes;
  } else {
    // Isophotes: curves of equal angle between the normal and the axis.
    phase = acos(clamp(dot(n, stripeAxis), -1.0, 1.0)) / PI * stripes;
  }
  float w = clamp(fwidth(phase), 1e-4, 0.25);
  float t = abs(fract(phase) - 0.5);
  float v = smoothstep(0.25 - w, 0.25 + w, t);
  float shade = 0.85 + 0.15 * max(dot(n, eyeDir), 0.0);
  outColor = vec4(mix(vec3(0.06), vec3(0.97), v) * shade, 1.0);
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
  fail: [0.90, 0.0, 0.0],
  comb: [0.0, 0.50, 0.45],
  combOther: [0.60, 0.25, 0.75],
  handle: [0.10, 0.55, 0.15],
};

// The surface programs' attributes, at the same locations in every program (the meshes' vertex
// arrays serve all of them).
const SURFACE_ATTRIBUTES = ['position', 'normal', 'color'];
// The surface shading modes and their programs' MODE.
const SURFACE_MODES = { shaded: 0, zebra: 1, isophotes: 2, draft: 3, reflection: 4 };

function compile(gl, vs, fs, attributes = []) {
  const p = gl.createProgram();
  attributes.forEach((name, k) => gl.bindAttribLocation(p, k, name));
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

// The handles of a circle (centre, radius) or an ellipse given by rx, ry (centre, the two
// semi-axes) as [role, point] pairs; none for other curves or curves with a transform.
export function analyticHandles(c) {
  const spec = c.spec;
  if (!spec || (spec.transform && spec.transform.length) || c.role === 'derivative' || !c.points.length) return [];
  if (spec.type === 'circle' && c.v0) return [['center', spec.center], ['radius', c.v0.point]];
  // Every sample finite (none left out) and a whole number per quarter: point n/4 is at v = π/2.
  const n = c.points.length;
  if (spec.type === 'ellipse' && spec.rx != null && spec.ry != null && !spec.v_origin && n === c.samples && n % 4 === 0) {
    return [['center', spec.center], ['rx', c.points[0]], ['ry', c.points[n / 4]]];
  }
  return [];
}

// The WebGL renderer's name (the unmasked one where the browser gives it), from a context made
// and dropped for the question, since a canvas's context attributes are fixed at its first.
function rendererName() {
  const probe = document.createElement('canvas').getContext('webgl2');
  if (!probe) return '';
  const info = probe.getExtension('WEBGL_debug_renderer_info');
  const name = String(probe.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : probe.RENDERER));
  const lose = probe.getExtension('WEBGL_lose_context');
  if (lose) lose.loseContext();
  return name;
}

// A software renderer (SwiftShader, llvmpipe, lavapipe) shades every pixel on the CPU: a frame of
// the view at 1280 × 800 took 45–95 ms there at the full grid, against 2–12 ms for the server
// to make it. So on one, the view
// draws without multisampling, and while a gesture runs (a drag, an orbit, the wheel, a slider)
// at most GESTURE_PIXELS device pixels, scaled up by the page; the full resolution returns when
// the gesture ends. A GPU draws as before. "Full detail while dragging" keeps the full
// resolution too.
const SOFTWARE_RENDERER = /swiftshader|llvmpipe|lavapipe|softpipe|software/i;
export const GESTURE_PIXELS = 60000;

export class View {
  constructor(canvas) {
    this.canvas = canvas;
    this.renderer = rendererName();
    this.software = SOFTWARE_RENDERER.test(this.renderer);
    const gl = canvas.getContext('webgl2', { antialias: !this.software, preserveDrawingBuffer: true });
    if (!gl) throw new Error('this browser has no WebGL2');
    this.gl = gl;
    this.gesture = false; // a gesture runs (see setGesture)
    this.fullDetail = false; // the full resolution even while a gesture runs
    // One program per shading mode, compiled when first drawn (the shaded one now).
    this.surfacePrograms = new Map();
    this.surfaceProgramFor('shaded');
    this.lineProgram = compile(gl, LINE_VS, LINE_FS);
    this.meshes = [];
    this.indexCache = new Map();
    this.lines = null;
    this.points = null;
    this.camera = { target: [0, 0, 1], distance: 8, yaw: -0.95, pitch: 0.48, panned: false };
    this.pending = false;
    this.dirty = false; // something asked for a draw that has not happened yet
    this.immediate = false; // drawing outside an animation frame (drawNow)
    this.onDrawn = null; // runs once, when the next drawing is in a frame going to the screen
    this.show = { curves: true, vectors: true, spines: true, control: true, edges: true };
    this.selected = null; // { kind: 'control', curve, index } or { kind: 'spine', patch, index }
    this.local = null; // a local edit's points: { x1, x2, handle }
    // Surface inspection: 'shaded', 'zebra', 'isophotes' or 'draft'; the stripes' axis (the
    // pull direction of draft analysis) and count; a locked eye keeps the stripes on the model
    // while the view turns; the least draft angle in degrees.
    this.failing = new Set(); // curves along seams that fail the check
    this.selectedPatch = -1; // the index of a patch selected by a click
    this.multi = null; // control points picked with Ctrl-click: { curve, indices: Set }
    // Curvature combs: shown, tooth scale (1: the most curved tooth is 0.3 of the design's
    // radius), and every how many samples a tooth is drawn.
    this.comb = { show: false, scale: 1, every: 2 };
    this.inspect = { mode: 'shaded', axis: [0, 0, 1], stripes: 16, lockedEye: null, draft: 3 };
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
      gl.bindBuffer(gl.ARRAY_BUFFER, mesh.buffers[0]);
      gl.bufferData(gl.ARRAY_BUFFER, s.positions, gl.DYNAMIC_DRAW);
      let loc = SURFACE_ATTRIBUTES.indexOf('position');
      gl.enableVertexAttribArray(loc);
      gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, 0, 0);
      gl.bindBuffer(gl.ARRAY_BUFFER, mesh.buffers[1]);
      gl.bufferData(gl.ARRAY_BUFFER, s.normals, gl.DYNAMIC_DRAW);
      loc = SURFACE_ATTRIBUTES.indexOf('normal');
      gl.enableVertexAttribArray(loc);
      gl.vertexAttribPointer(loc, 3, gl.SHORT, true, 0, 0);
      loc = SURFACE_ATTRIBUTES.indexOf('color');
      if (s.colors) {
        gl.bindBuffer(gl.ARRAY_BUFFER, mesh.buffers[2]);
        gl.bufferData(gl.ARRAY_BUFFER, s.colors, gl.DYNAMIC_DRAW);
        gl.enableVertexAttribArray(loc);
        gl.vertexAttribPointer(loc, 3, gl.UNSIGNED_BYTE, true, 0, 0);
      } else {
        // A constant attribute value is the context's, not the vertex array's: draw() sets it
        // before each mesh.
        gl.disableVertexAttribArray(loc);
      }
      mesh.color = s.colors ? null : patchColors[k % patchColors.length];
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
    this.surfaceData = surfaces;
    this.bounds = this.computeBounds(surfaces);
    if (!this.camera.panned && this.bounds) {
      this.camera.target = this.bounds.center;
      if (!this.framed) {
        this.camera.distance = this.frameDistance();
        this.framed = true;
      }
    }
  }

  // The distance that shows the whole design across the narrower of the view's two sides.
  frameDistance() {
    const aspect = this.canvas.clientWidth / Math.max(this.canvas.clientHeight, 1);
    return Math.max((this.bounds.radius * 4.2) / Math.min(1, aspect || 1), 1e-3);
  }

  // Frame all: the whole design in view, centred.
  frameAll() {
    if (!this.bounds) return;
    this.camera.target = this.bounds.center;
    this.camera.distance = this.frameDistance();
    this.camera.panned = false;
    this.request();
  }

  // A standard view (yaw, pitch of the eye around the target), framed.
  standardView(yaw, pitch) {
    this.camera.yaw = yaw;
    this.camera.pitch = pitch;
    this.frameAll();
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
    const sel = this.selected || {};
    if (this.show.curves) {
      for (const c of scene.curves) {
        if (!c.points.length) continue;
        // A seam above the G1 tolerance is drawn red even with the curves hidden.
        const col = sel.kind === 'curve' && sel.curve === c.name ? COLORS.selected
          : this.failing.has(c.name) ? COLORS.fail
            : edgeCurves.has(c.name) ? COLORS.edge
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
    if (this.comb.show) {
      // Teeth along -κN (away from the centre of curvature), one scale for every curve so that
      // combs compare; the envelope joins their tips.
      const combs = scene.curves.filter((c) => c.comb && c.comb.length);
      const seams = scene.seam_combs || [];
      const kmax = Math.max(1e-300, ...combs.flatMap((c) => c.comb.map(([, k]) => m.norm(k))),
        ...seams.flatMap((e) => e.teeth.flatMap(([, , a, b]) => [Math.abs(a), Math.abs(b)])));
      const len = (this.comb.scale * 0.3 * (this.bounds ? this.bounds.radius : 1)) / kmax;
      // Across each shared edge, a comb per side of the surfaces' normal curvature across it:
      // where the seam is G2 the two coincide.
      for (const e of seams) {
        for (const [side, col] of [[2, COLORS.comb], [3, COLORS.combOther]]) {
          const tips = e.teeth.map((t) => m.sub(t[0], m.scale(t[1], len * t[side])));
          e.teeth.forEach((t, i) => { if (i % this.comb.every === 0) line(t[0], tips[i], col); });
          polyline(tips, true, col);
        }
      }
      for (const c of combs) {
        const tips = [];
        c.comb.forEach(([p, k], i) => {
          const tip = m.sub(p, m.scale(k, len));
          tips.push(tip);
          if (i % this.comb.every === 0) line(p, tip, COLORS.comb);
        });
        polyline(tips, c.closed, COLORS.comb);
      }
    }
    if (this.show.vectors) {
      for (const v of scene.vectors) for (const [a, b] of v.segments) line(a, b, COLORS.vector);
    }
    // The trim curves' images on their surfaces (the holes' edges).
    for (const l of scene.trim_lines || []) polyline(l, true, COLORS.trim);
    if (!this.show.curves) {
      for (const c of scene.curves) if (this.failing.has(c.name)) polyline(c.points, c.closed, COLORS.fail);
    }
    this.pickable = [];
    if (this.show.control) {
      // Circles and ellipses keep their kind: handles at the centre and on the radii (curves
      // with a transform have none: their file values are not where they are drawn). They are
      // listed before the spines' points, so a circle's centre wins over the spine's end there.
      for (const c of scene.curves) {
        const h = analyticHandles(c);
        for (const [role, point] of h) {
          const isSel = sel.kind === 'analytic' && sel.curve === c.name && sel.role === role;
          pts.push(...point);
          ptsCol.push(...(isSel ? COLORS.selected : COLORS.handle));
          this.pickable.push({ kind: 'analytic', curve: c.name, role, point });
        }
        if (h.length) for (const [, point] of h.slice(1)) line(h[0][1], point, COLORS.handle);
      }
    }
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
          const isSel = (sel.kind === 'control' && sel.curve === c.name && sel.index === index)
            || (this.multi && this.multi.curve === c.name && this.multi.indices.has(index));
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

  // The program of a shading mode (the shaded one for a mode it does not know).
  surfaceProgramFor(mode) {
    const k = SURFACE_MODES[mode] ?? 0;
    if (!this.surfacePrograms.has(k)) {
      const fs = SURFACE_FS.replace('#version 300 es', `#version 300 es\n#define MODE ${k}`);
      this.surfacePrograms.set(k, compile(this.gl, SURFACE_VS, fs, SURFACE_ATTRIBUTES));
    }
    return this.surfacePrograms.get(k);
  }

  // Asks for a draw at the next animation frame (several requests make one draw; none when a
  // draw since the request showed it already).
  request() {
    this.dirty = true;
    if (this.pending) return;
    this.pending = true;
    requestAnimationFrame(() => {
      this.pending = false;
      if (this.dirty) this.draw();
    });
  }

  // Draws now, outside the animation frames: a frame from the server is drawn as it arrives, so
  // that its rasterising (milliseconds on a software renderer) is done before the next frame is
  // put together instead of delaying it. `onDrawn` then runs at that next frame, when the
  // drawing goes to the screen.
  drawNow() {
    this.immediate = true;
    try {
      this.draw();
      // Hands the commands to the GPU process now (they would wait for the next frame).
      this.gl.flush();
    } finally {
      this.immediate = false;
    }
  }

  // Marks the start (true) or the end (false) of a gesture; its end draws at full resolution.
  setGesture(on) {
    if (this.gesture === on) return;
    this.gesture = on;
    if (!on) this.request();
  }

  // Device pixels per CSS pixel of the next draw: the page's ratio, or less while a gesture runs
  // on a software renderer (at most GESTURE_PIXELS in all).
  resolution() {
    const dpr = window.devicePixelRatio || 1;
    if (!this.gesture || !this.software || this.fullDetail) return dpr;
    const css = Math.max(this.canvas.clientWidth * this.canvas.clientHeight, 1);
    return Math.min(dpr, Math.sqrt(GESTURE_PIXELS / css));
  }

  draw() {
    this.dirty = false;
    const gl = this.gl;
    const dpr = this.resolution();
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
    const ins = this.inspect;
    const program = this.surfaceProgramFor(ins.mode);
    gl.useProgram(program);
    gl.uniformMatrix4fv(gl.getUniformLocation(program, 'mvp'), false, mvp);
    gl.uniform3fv(gl.getUniformLocation(program, 'eyeDir'), eyeDir);
    gl.uniform3fv(gl.getUniformLocation(program, 'lightDir'), light);
    gl.uniform1f(gl.getUniformLocation(program, 'draftAngle'), (ins.draft * Math.PI) / 180);
    gl.uniform3fv(gl.getUniformLocation(program, 'eyePos'), ins.lockedEye || this.eye());
    gl.uniform3fv(gl.getUniformLocation(program, 'stripeAxis'), m.unit(ins.axis));
    gl.uniform1f(gl.getUniformLocation(program, 'stripes'), Math.max(1, Math.round(ins.stripes)));
    const colorLoc = SURFACE_ATTRIBUTES.indexOf('color');
    for (const mesh of this.meshes) {
      gl.bindVertexArray(mesh.vao);
      if (mesh.color) {
        // The selected patch is tinted towards the selection colour.
        const c = this.meshes.indexOf(mesh) === this.selectedPatch
          ? mesh.color.map((x, i) => 0.55 * x + 0.45 * COLORS.selected[i]) : mesh.color;
        gl.vertexAttrib3f(colorLoc, c[0], c[1], c[2]);
      }
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
    this.drawTriad(dpr);
    gl.bindVertexArray(null);
    const drawn = this.onDrawn;
    this.onDrawn = null;
    if (drawn && this.immediate) requestAnimationFrame(() => drawn());
    else if (drawn) drawn();
  }

  // The triad's projection: the unit axes from 4.2 away fill the corner (a 30° field of view
  // spans ±1.1 there).
  triadMvp() {
    const eye = m.scale(m.unit(m.sub(this.eye(), this.camera.target)), 4.2);
    return m.multiply(m.perspective(Math.PI / 6, 1, 2, 6.5), m.lookAt(eye, [0, 0, 0], [0, 0, 1]));
  }

  // The axis triad in the bottom-left corner (TRIAD CSS pixels square): x red, y green, z
  // blue, their negative halves grey and shorter, turned with the view.
  drawTriad(dpr) {
    const gl = this.gl;
    if (!this.triad) {
      const pos = [], col = [];
      TRIAD_ENDS.forEach(({ tip }, k) => {
        pos.push(0, 0, 0, ...tip);
        const c = k % 2 ? [0.55, 0.55, 0.55] : [[0.85, 0.1, 0.1], [0.1, 0.6, 0.1], [0.1, 0.2, 0.9]][k >> 1];
        col.push(...c, ...c);
      });
      this.triad = this.upload(null, pos, col);
    }
    const size = Math.round(TRIAD * dpr);
    gl.viewport(0, 0, size, size);
    gl.clear(gl.DEPTH_BUFFER_BIT);
    const mvp = this.triadMvp();
    gl.uniformMatrix4fv(gl.getUniformLocation(this.lineProgram, 'mvp'), false, mvp);
    gl.bindVertexArray(this.triad.vao);
    gl.drawArrays(gl.LINES, 0, this.triad.count);
    gl.viewport(0, 0, this.canvas.width, this.canvas.height);
  }

  // The end of the triad under a click at (sx, sy) (CSS pixels in the canvas), within 12
  // pixels of its tip, the nearest: { axis: '+x' …, yaw, pitch } of the standard view from that
  // side; null elsewhere.
  triadPick(sx, sy) {
    const h = this.canvas.clientHeight;
    if (sx > TRIAD || sy < h - TRIAD) return null;
    const mvp = this.triadMvp();
    let best = null, bestD = 12;
    for (const end of TRIAD_ENDS) {
      const [x, y, , w] = m.transform(mvp, end.tip);
      if (w <= 0) continue;
      const px = ((x / w) * 0.5 + 0.5) * TRIAD, py = h - ((y / w) * 0.5 + 0.5) * TRIAD;
      const d = Math.hypot(px - sx, py - sy);
      if (d < bestD) { bestD = d; best = end; }
    }
    return best;
  }

  // Where the triad draws the tip of `axis` ('+x' …), in CSS pixels of the canvas.
  triadTip(axis) {
    const end = TRIAD_ENDS.find((e) => e.axis === axis);
    const [x, y, , w] = m.transform(this.triadMvp(), end.tip);
    return [((x / w) * 0.5 + 0.5) * TRIAD, this.canvas.clientHeight - ((y / w) * 0.5 + 0.5) * TRIAD];
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

  // The curve whose drawn line passes within `radius` CSS pixels of a screen position (the
  // nearest), or null.
  pickCurve(sx, sy, radius = 6) {
    if (!this.scene || !this.show.curves) return null;
    const mats = this.matrices();
    let best = null, bestD = radius;
    for (const c of this.scene.curves) {
      const pts = c.points.map((p) => this.project(p, mats));
      const n = pts.length;
      for (let k = 0; k + 1 < n + (c.closed ? 1 : 0); k++) {
        const a = pts[k], b = pts[(k + 1) % n];
        if (!a || !b) continue;
        const dx = b[0] - a[0], dy = b[1] - a[1];
        const len2 = dx * dx + dy * dy;
        const t = len2 > 0 ? Math.max(0, Math.min(1, ((sx - a[0]) * dx + (sy - a[1]) * dy) / len2)) : 0;
        const d = Math.hypot(a[0] + t * dx - sx, a[1] + t * dy - sy);
        if (d < bestD) { bestD = d; best = c.name; }
      }
      if (n === 1 && pts[0]) {
        const d = Math.hypot(pts[0][0] - sx, pts[0][1] - sy);
        if (d < bestD) { bestD = d; best = c.name; }
      }
    }
    return best;
  }

  // The index of the surface under a screen position (the first its triangles meet along the
  // ray through it), or -1.
  pickPatch(sx, sy) {
    const { origin: o, dir: d } = this.ray(sx, sy);
    let best = -1, bestT = Infinity;
    (this.surfaceData || []).forEach((s, k) => {
      const p = s.positions;
      const idx = s.indices || gridIndices(s.nu, s.nv, s.periodic);
      for (let t = 0; t < idx.length; t += 3) {
        const a = 3 * idx[t], b = 3 * idx[t + 1], c = 3 * idx[t + 2];
        // Möller–Trumbore.
        const e1 = [p[b] - p[a], p[b + 1] - p[a + 1], p[b + 2] - p[a + 2]];
        const e2 = [p[c] - p[a], p[c + 1] - p[a + 1], p[c + 2] - p[a + 2]];
        const h = m.cross(d, e2);
        const det = m.dot(e1, h);
        if (Math.abs(det) < 1e-14) continue;
        const f = 1 / det;
        const q0 = [o[0] - p[a], o[1] - p[a + 1], o[2] - p[a + 2]];
        const u = f * m.dot(q0, h);
        if (u < 0 || u > 1) continue;
        const q = m.cross(q0, e1);
        const v = f * m.dot(d, q);
        if (v < 0 || u + v > 1) continue;
        const dist = f * m.dot(e2, q);
        if (dist > 0 && dist < bestT) { bestT = dist; best = k; }
      }
    });
    this.lastPickDistance = bestT; // from the eye to the surface hit (Infinity: none)
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
