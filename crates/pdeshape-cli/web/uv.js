// The (u, v) panel (book Figs. 5.5–5.7, 5.11): the parameter rectangle of the selected patch (v
// periodic: the curves are drawn again one period up and down), its trim curves (`[[trims]]`)
// and the (u, v) curves of the patches attached to it (`on_patch`), as the library samples them.
// Drag a curve to move it (MoveTrimCurve / MoveAttachment by offsets), drag its handles (centre,
// radii, points) to reshape it (SetTrim / SetCurve); every drag is one undo step.

import { MOVE_EVENT } from './channel.js';

const MARGIN = { left: 36, right: 12, top: 12, bottom: 26 };
const PERIOD = 2 * Math.PI;

const sub2 = (a, b) => [a[0] - b[0], a[1] - b[1]];
const add2 = (a, b) => [a[0] + b[0], a[1] + b[1]];
const clone = (x) => JSON.parse(JSON.stringify(x));

// The handles of a (u, v) curve table: where they are and what dragging them changes.
export function handles(c) {
  if (c.type === 'circle') {
    return [{ role: 'center', p: c.center }, { role: 'radius', p: [c.center[0] + c.radius, c.center[1]] }];
  }
  if (c.type === 'ellipse') {
    const t = c.angle || 0;
    const [a, b] = c.radii;
    return [
      { role: 'center', p: c.center },
      { role: 'a', p: [c.center[0] + a * Math.cos(t), c.center[1] + a * Math.sin(t)] },
      { role: 'b', p: [c.center[0] - b * Math.sin(t), c.center[1] + b * Math.cos(t)] },
    ];
  }
  return c.points.map((p, j) => ({ role: 'point', j, p }));
}

// The table with handle `h` moved to `p`.
export function moveHandle(c, h, p) {
  const out = clone(c);
  const d = sub2(p, c.center || [0, 0]);
  const len = Math.hypot(d[0], d[1]);
  if (h.role === 'center') out.center = p;
  else if (h.role === 'radius') out.radius = len;
  else if (h.role === 'a') { out.radii[0] = len; out.angle = Math.atan2(d[1], d[0]); }
  else if (h.role === 'b') out.radii[1] = len;
  else out.points[h.j] = p;
  return out;
}

// The point that follows the whole curve (its centre or first point).
const anchor = (c) => (c.center ? c.center : c.points[0]);

// Inside a closed polygon (even-odd).
function inside(p, poly) {
  let c = false;
  for (let i = 0, j = poly.length - 1; i < poly.length; j = i++) {
    const [a, b] = [poly[i], poly[j]];
    if ((a[1] > p[1]) !== (b[1] > p[1]) && p[0] < ((b[0] - a[0]) * (p[1] - a[1])) / (b[1] - a[1]) + a[0]) c = !c;
  }
  return c;
}

export class UvPanel {
  // `edit(makeBody, t)`: sends an edit through the panel's channel; `newGroup()`: a drag's undo
  // group; `changed()`: the selection changed.
  constructor(canvas, { edit, newGroup, changed }) {
    this.canvas = canvas;
    this.ctx = canvas.getContext('2d');
    this.edit = edit;
    this.newGroup = newGroup;
    this.changed = changed || (() => {});
    this.scene = null;
    this.patch = null;
    this.selected = null; // { type: 'trim', index, curve } | { type: 'attach', name }
    this.drag = null;
    canvas.addEventListener('pointerdown', (ev) => this.down(ev));
    canvas.addEventListener(MOVE_EVENT, (ev) => this.move(ev));
    canvas.addEventListener('pointerup', () => this.up());
    canvas.addEventListener('pointercancel', () => this.up());
  }

  setScene(scene, patch) {
    this.scene = scene;
    this.patch = scene.surfaces.find((s) => s.name === patch) || scene.surfaces[0] || null;
    if (this.selected && !this.curveOf(this.selected)) this.selected = null;
    this.draw();
  }

  // The curves of the patch shown: trim curves and attachments, with their tables and points.
  curves() {
    if (!this.scene || !this.patch) return [];
    const out = [];
    for (const t of this.scene.trims) {
      if (t.surface !== this.patch.name) continue;
      t.spec.curves.forEach((c, j) => out.push({ key: { type: 'trim', index: t.index, curve: j }, spec: c, uv: t.uv[j] }));
    }
    for (const a of this.scene.attachments) {
      if (a.host !== this.patch.name) continue;
      const c = this.scene.curves.find((x) => x.name === a.name);
      if (c) out.push({ key: { type: 'attach', name: a.name }, spec: c.spec.path, uv: a.uv, trim: a.trim });
    }
    return out;
  }

  curveOf(key) {
    return this.curves().find((c) => JSON.stringify(c.key) === JSON.stringify(key));
  }

  // The [[trims]] entry of the patch shown, if any.
  entry() {
    return this.scene && this.patch && this.scene.trims.find((t) => t.surface === this.patch.name);
  }

  box() {
    const w = this.canvas.clientWidth, h = this.canvas.clientHeight;
    return { x0: MARGIN.left, y0: MARGIN.top, w: Math.max(w - MARGIN.left - MARGIN.right, 10), h: Math.max(h - MARGIN.top - MARGIN.bottom, 10) };
  }

  // Screen position (CSS pixels in the canvas) of (u, v): u across, v up.
  toScreen([u, v]) {
    const d = this.patch.domain, b = this.box();
    return [b.x0 + ((u - d.u[0]) / (d.u[1] - d.u[0])) * b.w, b.y0 + b.h - ((v - d.v[0]) / (d.v[1] - d.v[0])) * b.h];
  }

  toUv([x, y]) {
    const d = this.patch.domain, b = this.box();
    return [d.u[0] + ((x - b.x0) / b.w) * (d.u[1] - d.u[0]), d.v[0] + ((b.y0 + b.h - y) / b.h) * (d.v[1] - d.v[0])];
  }

  // The copies of the plane a curve is drawn in: one period up and down for a periodic v.
  shifts() {
    return this.patch && this.patch.domain.periodic ? [-PERIOD, 0, PERIOD] : [0];
  }

  draw() {
    const dpr = window.devicePixelRatio || 1;
    const c = this.canvas, ctx = this.ctx;
    const w = Math.round(c.clientWidth * dpr), h = Math.round(c.clientHeight * dpr);
    if (c.width !== w || c.height !== h) { c.width = w; c.height = h; }
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.clearRect(0, 0, c.clientWidth, c.clientHeight);
    if (!this.patch) return;
    const b = this.box(), d = this.patch.domain;
    ctx.fillStyle = '#fff';
    ctx.fillRect(b.x0, b.y0, b.w, b.h);
    // Grid lines and labels.
    ctx.strokeStyle = '#e2e2e2';
    ctx.lineWidth = 1;
    ctx.font = '11px system-ui, sans-serif';
    ctx.fillStyle = '#444';
    const vTicks = d.periodic ? [0, 0.5, 1, 1.5, 2].map((k) => k * Math.PI) : [d.v[0], (d.v[0] + d.v[1]) / 2, d.v[1]];
    const vLabel = d.periodic ? ['0', 'π/2', 'π', '3π/2', '2π'] : vTicks.map((x) => x.toFixed(2));
    vTicks.forEach((v, k) => {
      const [, y] = this.toScreen([d.u[0], v]);
      ctx.beginPath(); ctx.moveTo(b.x0, y); ctx.lineTo(b.x0 + b.w, y); ctx.stroke();
      ctx.textAlign = 'right'; ctx.textBaseline = 'middle';
      ctx.fillText(vLabel[k], b.x0 - 4, y);
    });
    [0, 0.25, 0.5, 0.75, 1].forEach((f) => {
      const u = d.u[0] + f * (d.u[1] - d.u[0]);
      const [x] = this.toScreen([u, d.v[0]]);
      ctx.beginPath(); ctx.moveTo(x, b.y0); ctx.lineTo(x, b.y0 + b.h); ctx.stroke();
      ctx.textAlign = 'center'; ctx.textBaseline = 'top';
      ctx.fillText(String(+u.toFixed(2)), x, b.y0 + b.h + 3);
    });
    ctx.textAlign = 'left'; ctx.textBaseline = 'top';
    ctx.fillText('u →', b.x0 + b.w - 26, b.y0 + b.h + 13);
    ctx.save();
    ctx.translate(10, b.y0 + 14); ctx.rotate(-Math.PI / 2);
    ctx.textAlign = 'right';
    ctx.fillText(d.periodic ? 'v (periodic) →' : 'v →', 0, -8);
    ctx.restore();
    ctx.strokeStyle = '#888';
    ctx.strokeRect(b.x0, b.y0, b.w, b.h);
    // The curves, clipped to the rectangle.
    ctx.save();
    ctx.beginPath(); ctx.rect(b.x0, b.y0, b.w, b.h); ctx.clip();
    for (const c of this.curves()) {
      const sel = this.selected && JSON.stringify(this.selected) === JSON.stringify(c.key);
      const color = c.key.type === 'trim' ? '#e08c14' : '#1a7f37';
      for (const s of this.shifts()) {
        ctx.beginPath();
        c.uv.forEach((p, k) => {
          const [x, y] = this.toScreen([p[0], p[1] + s]);
          if (k) ctx.lineTo(x, y); else ctx.moveTo(x, y);
        });
        ctx.closePath();
        ctx.fillStyle = c.key.type === 'trim' || c.trim ? 'rgba(224,140,20,0.12)' : 'rgba(26,127,55,0.08)';
        ctx.fill();
        ctx.strokeStyle = sel ? '#d4a000' : color;
        ctx.lineWidth = sel ? 2.5 : 1.5;
        ctx.stroke();
        for (const h of handles(c.spec)) {
          const [x, y] = this.toScreen([h.p[0], h.p[1] + s]);
          ctx.fillStyle = sel ? '#d4a000' : color;
          ctx.fillRect(x - 3.5, y - 3.5, 7, 7);
        }
      }
      const label = c.key.type === 'attach' ? c.key.name : `trims[${c.key.index}].curves[${c.key.curve}]`;
      const [lx, ly] = this.toScreen(c.uv.reduce((m, p) => (p[1] > m[1] ? p : m), c.uv[0] || [0, 0]));
      ctx.fillStyle = '#333'; ctx.textAlign = 'center'; ctx.textBaseline = 'bottom';
      ctx.fillText(label, Math.min(Math.max(lx, b.x0 + 40), b.x0 + b.w - 40), Math.max(ly - 4, b.y0 + 12));
    }
    ctx.restore();
  }

  pos(ev) {
    const r = this.canvas.getBoundingClientRect();
    return [ev.clientX - r.left, ev.clientY - r.top];
  }

  // The handle or curve under a screen position: { curve, handle?, shift }.
  hit(sp) {
    let best = null, bestD = 9;
    const curves = this.curves();
    for (const c of curves) {
      for (const s of this.shifts()) {
        for (const h of handles(c.spec)) {
          const q = this.toScreen([h.p[0], h.p[1] + s]);
          const d = Math.hypot(q[0] - sp[0], q[1] - sp[1]);
          if (d < bestD) { bestD = d; best = { curve: c, handle: h, shift: s }; }
        }
      }
    }
    if (best) return best;
    for (const c of curves) {
      for (const s of this.shifts()) {
        const poly = c.uv.map((p) => this.toScreen([p[0], p[1] + s]));
        if (inside(sp, poly)) return { curve: c, handle: null, shift: s };
      }
    }
    return null;
  }

  down(ev) {
    if (!this.patch || ev.button !== 0) return;
    const sp = this.pos(ev);
    const hit = this.hit(sp);
    this.selected = hit ? hit.curve.key : null;
    this.changed(this.selected);
    this.draw();
    if (!hit) return;
    this.canvas.setPointerCapture(ev.pointerId);
    const uv = this.toUv(sp);
    this.drag = {
      key: hit.curve.key, handle: hit.handle, shift: hit.shift, group: this.newGroup(),
      grab: uv, anchor: anchor(hit.curve.spec),
    };
  }

  move(ev) {
    const dr = this.drag;
    if (!dr) return;
    const p = this.toUv(this.pos(ev));
    // In the curve's own copy of the plane.
    const at = [p[0], p[1] - dr.shift];
    this.edit(() => this.body(dr, at), ev.timeStamp);
  }

  up() {
    this.drag = null;
  }

  // The edit of a drag to `at`, made when it is sent (from the newest scene).
  body(dr, at) {
    const c = this.curveOf(dr.key);
    if (!c) return null;
    let edit;
    if (dr.handle) {
      const h = handles(c.spec).find((x) => x.role === dr.handle.role && x.j === dr.handle.j);
      const moved = moveHandle(c.spec, h || dr.handle, at);
      edit = this.replace(dr.key, moved);
    } else {
      // The whole curve follows the pointer: the offset still missing, from where it is now.
      const want = add2(dr.anchor, sub2(at, dr.grab));
      const offset = sub2(want, anchor(c.spec));
      if (Math.hypot(offset[0], offset[1]) < 1e-9) return null;
      edit = dr.key.type === 'trim'
        ? { edit: 'move_trim_curve', index: dr.key.index, curve: dr.key.curve, offset }
        : { edit: 'move_attachment', name: dr.key.name, offset };
    }
    return { edit, group: dr.group };
  }

  // The edit that sets the curve `key` to the table `c`.
  replace(key, c) {
    if (key.type === 'trim') {
      const t = clone(this.scene.trims.find((x) => x.index === key.index).spec);
      t.curves[key.curve] = c;
      return { edit: 'set_trim', index: key.index, trim: t };
    }
    const curve = clone(this.scene.curves.find((x) => x.name === key.name).spec);
    curve.path = c;
    return { edit: 'set_curve', name: key.name, curve };
  }

  // The edit that adds a hole of `kind` where the patch's (u, v) plane is freest of curves.
  addEdit(kind) {
    const d = this.patch.domain;
    const su = d.u[1] - d.u[0], sv = d.v[1] - d.v[0];
    const taken = this.curves().flatMap((x) => x.uv);
    let c = [d.u[0] + su / 2, d.v[0] + sv / 2], room = -1;
    for (const fu of [0.3, 0.5, 0.7]) {
      for (let k = 0; k < 8; k++) {
        const p = [d.u[0] + fu * su, d.v[0] + ((k + 0.5) / 8) * sv];
        let near = Infinity;
        for (const q of taken) {
          for (const s of this.shifts()) {
            near = Math.min(near, Math.hypot((q[0] - p[0]) / su, (q[1] + s - p[1]) / sv));
          }
        }
        if (near > room) { room = near; c = p; }
      }
    }
    const du = su * 0.08, dv = sv * 0.05;
    const ring = (n, r) => Array.from({ length: n }, (_, k) => {
      const a = (2 * Math.PI * k) / n;
      return [c[0] + r * du * Math.cos(a), c[1] + r * dv * Math.sin(a)];
    });
    const curve = {
      circle: { type: 'circle', center: c, radius: Math.min(du, dv) },
      ellipse: { type: 'ellipse', center: c, radii: [du, dv * 1.5] },
      polyline: { type: 'polyline', points: ring(4, 1.2) },
      bspline: { type: 'bspline', degree: 3, points: ring(6, 1.3) },
    }[kind];
    const e = this.entry();
    if (e) {
      const t = clone(e.spec);
      t.curves.push(curve);
      return { edit: 'set_trim', index: e.index, trim: t };
    }
    const trim = { curves: [curve] };
    if (this.scene.surfaces.length > 1) trim.surface = this.patch.name;
    return { edit: 'insert_trim', index: this.scene.trims.length, trim };
  }

  // The edit that removes the selected trim curve (the whole entry with its last curve).
  deleteEdit() {
    const s = this.selected;
    if (!s || s.type !== 'trim') return null;
    const e = this.scene.trims.find((x) => x.index === s.index);
    if (e.spec.curves.length === 1) return { edit: 'remove_trim', index: s.index };
    const t = clone(e.spec);
    t.curves.splice(s.curve, 1);
    return { edit: 'set_trim', index: s.index, trim: t };
  }

  // The edit that re-meshes the patch's holes by `method`.
  methodEdit(method) {
    const e = this.entry();
    if (!e) return null;
    const t = clone(e.spec);
    if (method === 'cdt') delete t.method; else t.method = method;
    return { edit: 'set_trim', index: e.index, trim: t };
  }

  // Page coordinates of a (u, v) point (for tests).
  screenOf(uv) {
    const [x, y] = this.toScreen(uv);
    const r = this.canvas.getBoundingClientRect();
    return [x + r.left, y + r.top];
  }
}
