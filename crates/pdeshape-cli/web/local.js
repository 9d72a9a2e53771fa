// Local edits of a curve (book §6.2): pick X1 and X2 on a curve (or type their parameters), and
// drag the handle X3 in the plane of X1X2X3 or perpendicular to it. The frame (X1, X2, X3 and
// the axes e1, e2, e3 the library takes the handle's displacement in) comes from the server;
// the displacement's components go back as the library's local edit, one per drag.

import * as m from './math.js';

const $ = (id) => document.getElementById(id);

export class LocalTool {
  constructor(view, fetchFrame, say) {
    this.view = view;
    this.fetchFrame = fetchFrame; // (query) => frame JSON
    this.say = say; // a message beside the tool
    this.curve = null;
    this.picking = 0; // 1: X1 next, 2: X2 next
    this.frame = null; // { from, to, at, x1, x2, x3, e1, e2, e3 }
    this.moved = null; // the handle's displacement in the drag under way
  }

  // The parameter of drawn point k of a curve of the scene.
  static parameter(c, k) {
    const [a, b] = c.range;
    const n = c.closed ? c.points.length : c.points.length - 1;
    return a + ((b - a) * k) / Math.max(n, 1);
  }

  startPicking(curve) {
    this.clear();
    this.curve = curve;
    this.picking = 1;
    this.say(`click X1 on the curve ${curve}`);
  }

  // A click on the 3D view while picking: `k` is the drawn point of the curve under it.
  picked(scene, k) {
    const c = scene.curves.find((x) => x.name === this.curve);
    if (!c || k < 0) return this.say(`click nearer to the curve ${this.curve}`);
    const v = LocalTool.parameter(c, k);
    if (this.picking === 1) {
      $('l-from').value = v.toFixed(4);
      this.picking = 2;
      this.say(`click X2 on the curve ${this.curve}`);
    } else {
      $('l-to').value = v.toFixed(4);
      this.picking = 0;
      this.show(this.curve);
    }
  }

  // Fetches the frame for the typed parameters and shows the handle.
  async show(curve) {
    this.curve = curve;
    const q = new URLSearchParams({ name: curve, from: $('l-from').value, to: $('l-to').value });
    if ($('l-at').value.trim()) q.set('at', $('l-at').value.trim());
    try {
      this.frame = await this.fetchFrame(q.toString());
      this.moved = null;
      this.view.local = { x1: this.frame.x1, x2: this.frame.x2, handle: this.frame.x3 };
      this.say('');
      $('l-status').textContent = `X1 at v = ${this.frame.from.toFixed(3)}, X2 at ${this.frame.to.toFixed(3)}, ` +
        `X3 at ${this.frame.at.toFixed(3)}: drag the cyan handle`;
    } catch (e) {
      this.clear();
      this.say(e.place ? `${e.place}: ${e.message}` : e.message);
    }
  }

  clear() {
    this.frame = null;
    this.picking = 0;
    this.moved = null;
    this.view.local = null;
    $('l-status').textContent = '';
  }

  // Where the handle moves: the plane of X1X2X3 (or the view plane when they are collinear), or
  // the line through X3 along e3.
  geometry(mode) {
    const f = this.frame;
    if (mode === 'normal' && f.e3) return { line: { point: f.x3, dir: f.e3 } };
    const normal = f.e3 || m.unit(m.sub(this.view.eye(), this.view.camera.target));
    return { plane: { point: f.x3, normal } };
  }

  // The request of the handle dragged to `p`.
  body(p, group) {
    const f = this.frame;
    const d = m.sub(p, f.x3);
    this.moved = d;
    return {
      name: this.curve, from: f.from, to: f.to, at: f.at, group,
      along: m.dot(d, f.e1), across: f.e2 ? m.dot(d, f.e2) : 0, normal: f.e3 ? m.dot(d, f.e3) : 0,
    };
  }

  // After a frame of the drag: the handle where it was sent.
  follow() {
    if (this.frame && this.moved && this.view.local) this.view.local.handle = m.add(this.frame.x3, this.moved);
  }
}
