// The designer: wires the view, the (u, v) panel, the timeline and the panels to the API. Every
// change is an edit value sent to the server; the answer is a frame (scene + meshes). While a
// drag, a slider gesture or playback runs, at most one of its requests is in flight and only
// the newest value waits (channel.js: coalesced, never queued).

import { api, ApiError, transport } from './api.js';
import { Channel, MOVE_EVENT } from './channel.js';
import { View, COLORS, GESTURE_PIXELS } from './view.js';
import { UvPanel } from './uv.js';
import { Timeline } from './timeline.js';
import { LocalTool } from './local.js';
import * as params from './params.js';
import * as panels from './panels.js';
import * as m from './math.js';

const $ = (id) => document.getElementById(id);
const view = new View($('view'));
let scene = null;
let busy = Promise.resolve();

// Measurements for tests and benchmarks: pointer event → new surface on screen.
const perf = { latencies: [], server: [], serverSplit: [], roundTrips: [], frames: 0, drags: 0, sent: 0, coalesced: 0 };

// The view's query. While a gesture runs (`coarse`), frames come on a coarser grid (at least
// 8 × 8): half as fine in each direction (a quarter of the tessellation, of the bytes and of
// the upload), and on a software renderer, which spends about a microsecond of the CPU on each
// triangle it draws, as coarse as it takes to hold GESTURE_TRIANGLES triangles in all. The
// grid is chosen at the gesture's first frame and kept to its end (the server's drag model is
// made for one grid); the full grid follows when the gesture ends (scheduleRefine).
// "Full detail while dragging" turns that off (and the view's lower resolution, view.js).
const GESTURE_TRIANGLES = 4000;
let gestureGrid = null;
function coarseGrid(nu, nv) {
  let k = 2;
  if (view.software && lastFrame) {
    // The last frame's triangles, scaled to the full grid (it may be a coarse frame itself).
    const [lu, lv] = lastFrame.scene.grid;
    const drawn = view.meshes.reduce((n, mesh) => n + mesh.count / 3, 0);
    const full = (drawn * nu * nv) / Math.max(lu * lv, 1);
    k = Math.max(k, Math.sqrt(full / GESTURE_TRIANGLES));
  }
  return [Math.max(8, Math.round(nu / k)), Math.max(8, Math.round(nv / k))];
}
function query(coarse = false) {
  const lo = $('c-lo').value.trim(), hi = $('c-hi').value.trim();
  const range = lo !== '' && hi !== '' ? `&range=${encodeURIComponent(`${lo},${hi}`)}` : '';
  const comb = $('show-combs').checked ? '&comb=1' : '';
  let nu = $('nu').value, nv = $('nv').value;
  if (coarse && !$('full-drag').checked && Number(nu) >= 16 && Number(nv) >= 16) {
    gestureGrid = gestureGrid || coarseGrid(Number(nu), Number(nv));
    [nu, nv] = gestureGrid;
  }
  return `nu=${nu}&nv=${nv}&color=${$('color').value}${range}${comb}`;
}

function status(text) {
  $('status').textContent = text;
}

function message(e) {
  if (e instanceof ApiError) return e.place ? `${e.place}: ${e.message}` : e.message;
  return String(e && e.message ? e.message : e);
}

// Shows a frame: meshes, scene, panels; `onDrawn` runs after the frame is on screen.
let lastFrame = null;
// The side panels (lists, legend, sliders, timeline) follow a gesture's frames a moment after
// the newest one instead of at every frame: rebuilding them costs the browser's main thread (and
// a software raster of the panels) while the surface waits to be drawn.
let panelsTimer = null;
function fillPanels() {
  panelsTimer = null;
  panels.fill(scene);
  params.fill(scene, paramSlider);
  timeline.update(scene);
}
// The (u, v) panel follows every frame of its own drags and of the timeline, other gestures' a
// moment after their newest frame as the side panels do (a software renderer rasterises its 2-D
// canvas in the same GPU process as the view: the teacup's drag under SwiftShader took 40–57 ms
// a frame with it redrawn every frame, 23–24 ms without).
function show(frame, onDrawn, gesture = false, uvFollows = true) {
  lastFrame = frame;
  scene = frame.scene;
  view.setSurfaces(frame.surfaces, COLORS.patches);
  local.follow();
  view.setScene(scene);
  clearTimeout(panelsTimer);
  if (gesture) {
    panelsTimer = setTimeout(() => {
      fillPanels();
      if (!uvFollows) syncUvPatch();
    }, 120);
  } else fillPanels();
  if (uvFollows) syncUvPatch();
  perf.frames += 1;
  const verts = frame.surfaces.reduce((n, s) => n + s.positions.length / 3, 0);
  const trimmed = frame.surfaces.filter((s) => s.indices).length;
  status(`v${scene.version}  ${frame.surfaces.length} surfaces${trimmed ? ` (${trimmed} trimmed)` : ''}, ` +
    `${verts} vertices, ${(frame.bytes / 1024).toFixed(0)} KiB, server ${scene.server_ms.toFixed(1)} ms, ` +
    `round trip ${frame.roundTripMs.toFixed(1)} ms`);
  view.onDrawn = onDrawn || null;
  view.drawNow();
  scheduleReports();
}

// Runs one request at a time (outside drags); an error goes beside `area`.
function run(area, call, onDrawn) {
  busy = busy.then(async () => {
    try {
      const frame = await call();
      // A later success clears every earlier message (they described a state that is gone).
      panels.clearErrors();
      // Anything but a view change (grid, colouring) or a load changes the design.
      if (markClean) { unsaved = false; markClean = false; } else if (area !== 'view') unsaved = true;
      show(frame, onDrawn);
    } catch (e) {
      markClean = false; // a refused load leaves the design (and its unsaved state) as it was
      panels.showError(area, message(e));
      // The controls show the design as it stands (the refused value is not kept).
      if (scene) panels.fill(scene);
    }
  });
  return busy;
}

function edit(area, value, group) {
  return run(area, () => api.edit(query(), { edit: value, group }));
}

// A channel whose frames are shown (with their latency measured) and whose refusals are said
// beside `area`.
const channels = [];
function channel(area, send) {
  const ch = new Channel(send, (frame, t) => {
    panels.clearErrors();
    if (area !== 'time') unsaved = true; // the timeline shows the design at t, it does not edit it
    show(frame, () => {
      perf.latencies.push(performance.now() - t);
      perf.server.push(frame.scene.server_ms);
      perf.serverSplit.push(frame.scene.server_split);
      perf.roundTrips.push(frame.roundTripMs);
    }, area !== 'time', area === 'uv' || area === 'time'); // the timeline's label follows playback
    scheduleRefine();
  }, (e) => panels.showError(area, message(e)), perf);
  channels.push(ch);
  return ch;
}

// The check and analyze panels follow the design a moment after it settles: not while a drag
// runs or a gesture's request waits (the reports take the design for as long as a few frames,
// e.g. 0.5 s for the teacup's analysis, and a frame that waited for them would let the next
// reports start before the next frame: a drag stuck behind its own reports).
let reportsTimer = null;
function scheduleReports() {
  clearTimeout(reportsTimer);
  reportsTimer = setTimeout(() => {
    if (drag || !channels.every((c) => c.idle)) scheduleReports();
    else refreshReports();
  }, 600);
}
// Reports answered out of order (a scheduled refresh and a click) show only the newest.
let reportsAsked = 0;
async function refreshReports() {
  const asked = ++reportsAsked;
  try {
    const [check, analyze] = await Promise.all([api.check(g1Tolerance(), g2Tolerance()), api.analyze()]);
    if (asked !== reportsAsked) return;
    panels.reports(check, analyze);
    view.failing = new Set(panels.failing);
    if (scene) { panels.legend(scene); view.setScene(scene); view.request(); }
    panels.showError('reports', '');
  } catch (e) {
    panels.showError('reports', message(e));
  }
}

// The seam tolerance of the shared-edge list, in radians (the page asks for degrees).
function g1Tolerance() {
  const deg = Number($('g1-tol').value);
  return Number.isFinite(deg) && deg >= 0 ? (deg * Math.PI) / 180 : (Math.PI / 180);
}

// The curvature tolerance (1/length), or '' when the field is empty (G2 not judged).
function g2Tolerance() {
  const t = $('g2-tol').value.trim();
  return t !== '' && Number.isFinite(Number(t)) && Number(t) >= 0 ? t : '';
}

let groupCounter = Date.now();
const newGroup = () => ++groupCounter;

// ---- Channels of the gestures ------------------------------------------------------------
const controlChannel = channel('drag', (body) => api.edit(query(true), body));
const spineChannel = channel('spine', (body) => api.spine(query(true), body));
const localChannel = channel('local', (body) => api.local(query(true), body));
const uvChannel = channel('uv', (body) => api.edit(query(true), body));
const timeChannel = channel('time', (body) => api.time(query(), body.t));

const timeline = new Timeline(timeChannel);
const local = new LocalTool(view, (q) => api.localFrame(q), (text) => panels.showError('local', text));
const uv = new UvPanel($('uv'), {
  edit: (makeBody, t) => uvChannel.push(makeBody, t),
  newGroup,
  changed: () => uvTools(),
});
// A digest of the meshes on screen (positions and triangles), to see that a surface changed.
function digest() {
  let h = 0;
  for (const s of lastFrame ? lastFrame.surfaces : []) {
    for (const a of [new Uint32Array(s.positions.buffer, s.positions.byteOffset, s.positions.length), s.indices || []]) {
      for (let i = 0; i < a.length; i++) h = (Math.imul(h, 31) + a[i]) | 0;
    }
  }
  return h;
}
// The full grid after a gesture's coarse frames: once no drag runs and no gesture's request is
// in flight or waiting (a slider held still counts as ended), one frame on the full grid. It
// is not an edit (no version, no unsaved state) and clears no message.
let refineTimer = null;
let refining = false;
function scheduleRefine() {
  clearTimeout(refineTimer);
  refineTimer = setTimeout(refine, 150);
}
function refine() {
  if (drag || !channels.every((c) => c.idle)) {
    refineTimer = setTimeout(refine, 100);
    return;
  }
  refineTimer = null;
  gestureGrid = null; // the next gesture chooses its grid afresh
  const full = [Number($('nu').value), Number($('nv').value)];
  if (!lastFrame || (lastFrame.scene.grid[0] === full[0] && lastFrame.scene.grid[1] === full[1])) return;
  refining = true;
  busy = busy.then(async () => {
    try {
      show(await api.frame(query()));
    } catch (e) {
      panels.showError('view', message(e));
    } finally {
      refining = false;
    }
  });
}
// True when no gesture has a request in flight or waiting and the full grid is on screen.
const idle = () => channels.every((c) => c.idle) && panelsTimer === null && refineTimer === null && !refining;
window.__pdeshape = { perf, transport, moveEvent: MOVE_EVENT, gestureBudget: { triangles: GESTURE_TRIANGLES, pixels: GESTURE_PIXELS }, state: () => scene, lastFrame: () => lastFrame, view, uv, local, timeline, digest, idle, dirty: () => dirty() };

// ---- Dragging in the 3D view: control points, spine handles, the local-edit handle ----------
let drag = null;

function pointerPos(ev) {
  const r = view.canvas.getBoundingClientRect();
  return [ev.clientX - r.left, ev.clientY - r.top];
}

const patchRefOf = (name) => (scene && scene.has_patches ? name : null);

view.canvas.addEventListener('pointerdown', (ev) => {
  const [x, y] = pointerPos(ev);
  view.canvas.setPointerCapture(ev.pointerId);
  if (local.picking && ev.button === 0) {
    local.picked(scene, view.pickCurvePoint(x, y, local.curve));
    view.setScene(scene);
    view.request();
    return;
  }
  // A click on an end of the axis triad looks from that side.
  const end = ev.button === 0 ? view.triadPick(x, y) : null;
  if (end) {
    view.standardView(end.yaw, end.pitch);
    return;
  }
  const hit = ev.button === 0 && !ev.shiftKey ? view.pick(x, y) : null;
  if (!hit) {
    // A click (no movement) on a curve or a patch selects it; a drag turns the camera.
    drag = { camera: ev.button === 2 || ev.shiftKey ? 'pan' : 'orbit', last: [x, y], start: [x, y], button: ev.button };
    return;
  }
  if (hit.kind === 'control' && (ev.ctrlKey || ev.metaKey)) {
    // Ctrl-click adds a control point of the same curve to the selection (or takes it out).
    const multi = view.multi && view.multi.curve === hit.curve ? view.multi
      : { curve: hit.curve, indices: new Set(view.selected && view.selected.kind === 'control' && view.selected.curve === hit.curve ? [view.selected.index] : []) };
    if (multi.indices.has(hit.index)) multi.indices.delete(hit.index); else multi.indices.add(hit.index);
    view.multi = multi;
    view.selected = hit;
    pointPanel();
    selectionNote();
    view.setScene(scene);
    view.request();
    return;
  }
  if (!(hit.kind === 'control' && view.multi && view.multi.curve === hit.curve && view.multi.indices.has(hit.index))) view.multi = null;
  view.selected = hit;
  pointPanel();
  selectionNote();
  const group = newGroup();
  const mode = $('plane').value;
  if (hit.kind === 'control') {
    $('curve').value = hit.curve;
    panels.curvePanel(scene);
    const c = scene.curves.find((x) => x.name === hit.curve);
    // The file's control points at the drag's start (a group drag moves them from there).
    const start = c && c.spec && Array.isArray(c.spec.control) ? c.spec.control.map((q) => [...q]) : null;
    drag = { ...hit, group, start, ...{ plane: view.dragPlane(hit.point, mode) } };
  } else if (hit.kind === 'analytic') {
    $('curve').value = hit.curve;
    panels.curvePanel(scene);
    const c = scene.curves.find((x) => x.name === hit.curve);
    const n = m.unit(c.spec.normal || [0, 0, 1]);
    // The radii move in the curve's own plane; the centre in the chosen drag plane.
    const plane = hit.role === 'center' ? view.dragPlane(hit.point, mode) : { point: hit.point, normal: n };
    drag = { ...hit, group, plane, spec: c.spec, normal: n };
  } else if (hit.kind === 'spine') {
    $('patch').value = hit.patch;
    panels.patchPanel(scene);
    drag = { ...hit, group, plane: view.dragPlane(hit.point, mode) };
  } else {
    drag = { ...hit, group, ...local.geometry($('l-mode').value) };
  }
  perf.drags += 1;
  view.setScene(scene);
  view.request();
});

view.canvas.addEventListener(MOVE_EVENT, (ev) => {
  if (!drag) return;
  view.setGesture(true);
  const [x, y] = pointerPos(ev);
  if (drag.camera) {
    const [dx, dy] = [x - drag.last[0], y - drag.last[1]];
    drag.last = [x, y];
    if (drag.camera === 'pan') view.pan(dx, dy); else view.orbit(dx, dy);
    return;
  }
  const ray = view.ray(x, y);
  const hitPoint = drag.line
    ? m.rayLine(ray.origin, ray.dir, drag.line.point, drag.line.dir)
    : m.rayPlane(ray.origin, ray.dir, drag.plane.point, drag.plane.normal);
  if (!hitPoint) return;
  const p = drag.kind === 'local' ? hitPoint : snap(hitPoint, x, y, drag);
  const d = drag;
  const c = d.kind === 'control' && view.multi && view.multi.indices.size > 1
    && scene.curves.find((x) => x.name === d.curve);
  if (c && c.spec && Array.isArray(c.spec.control) && !(c.spec.transform && c.spec.transform.length)) {
    // Several points of one curve move together by the drag's displacement: one curve edit.
    const delta = m.sub(p, d.point);
    const control = d.start.map((q, i) => (view.multi.indices.has(i) ? m.add(q, delta) : q));
    controlChannel.push(() => ({ edit: { edit: 'set_curve', name: d.curve, curve: { ...c.spec, control } }, group: d.group }), ev.timeStamp);
  } else if (d.kind === 'control') {
    controlChannel.push(() => ({
      edit: { edit: 'move_control_point', name: d.curve, index: d.index, point: p },
      group: d.group,
      world: true,
    }), ev.timeStamp);
  } else if (d.kind === 'analytic') {
    const spec = { ...d.spec };
    if (d.role === 'center') {
      spec.center = m.add(d.spec.center, m.sub(p, d.point));
    } else {
      const r = m.sub(p, d.spec.center);
      const inPlane = m.sub(r, m.scale(d.normal, m.dot(r, d.normal)));
      const len = Math.max(m.norm(inPlane), 1e-6);
      if (d.role === 'radius') spec.radius = len; else spec[d.role] = len;
    }
    controlChannel.push(() => ({ edit: { edit: 'set_curve', name: d.curve, curve: spec }, group: d.group }), ev.timeStamp);
  } else if (d.kind === 'spine') {
    spineChannel.push(() => ({ patch: patchRefOf(d.patch), index: d.index, point: p, group: d.group }), ev.timeStamp);
  } else {
    localChannel.push(() => local.body(p, d.group), ev.timeStamp);
  }
});

// Selects what lies under a click: a curve (within a few pixels of its drawn line), else the
// patch whose surface is nearest in front.
function clickSelect(x, y) {
  if (!scene) return;
  view.multi = null;
  const curve = view.pickCurve(x, y);
  if (curve) {
    view.selected = { kind: 'curve', curve };
    $('curve').value = curve;
    panels.curvePanel(scene);
  } else {
    const k = view.pickPatch(x, y);
    if (k < 0) {
      view.selected = null;
      view.selectedPatch = -1;
    } else {
      const name = scene.surfaces[k].name;
      view.selected = { kind: 'patch', patch: name };
      view.selectedPatch = k;
      $('patch').value = name;
      panels.patchPanel(scene);
      syncUvPatch(name);
    }
  }
  pointPanel();
  selectionNote();
  view.setScene(scene);
  view.request();
}

function selectionNote() {
  const s = view.selected;
  $('selection').textContent = !s ? 'nothing selected: click a curve or a patch'
    : s.kind === 'curve' ? `curve ${s.curve} selected`
      : s.kind === 'patch' ? `patch ${s.patch} selected`
        : s.kind === 'control' && view.multi && view.multi.indices.size > 1
          ? `control points ${[...view.multi.indices].sort((a, b) => a - b).join(', ')} of ${s.curve} selected (drag one to move them all)`
        : s.kind === 'control' ? `control point ${s.index} of ${s.curve} selected`
          : s.kind === 'spine' ? `spine point ${s.index} of ${s.patch} selected` : '';
}

// Snapping of a dragged point: to the grid (every coordinate a multiple of the step), to the
// coordinate planes (x = 0, y = 0, z = 0) within 10 pixels on screen, or to the nearest end of
// a curve or control point of another curve within 10 pixels on screen.
function snap(p, sx, sy, d) {
  const mode = $('snap').value;
  if (mode === 'grid') {
    const step = Number($('snap-step').value);
    if (!(step > 0) || !Number.isFinite(step)) return p;
    // Rounded to the step, then to the decimal digits the step has (0.1 · 3 is 0.30000000000000004).
    const digits = Math.min(12, Math.max(0, -Math.floor(Math.log10(step)) + 3));
    return p.map((c) => Number((Math.round(c / step) * step).toFixed(digits)));
  }
  if (mode === 'planes') {
    // Each coordinate plane (x = 0, y = 0, z = 0) the point is within 10 pixels of on screen
    // takes it exactly: the coordinate becomes 0.
    const mats = view.matrices();
    const at = view.project(p, mats);
    if (!at) return p;
    const q = [...p];
    const r = view.bounds ? view.bounds.radius : 1;
    for (let c = 0; c < 3; c++) {
      // Not along an axis that points at the eye (its plane is seen edge-on: every point is
      // on it on screen).
      const step = [...p];
      step[c] += 0.1 * r;
      const t = view.project(step, mats);
      if (!t || Math.hypot(t[0] - at[0], t[1] - at[1]) < 3) continue;
      const on = [...p];
      on[c] = 0;
      const s = view.project(on, mats);
      if (s && Math.hypot(s[0] - at[0], s[1] - at[1]) < 10) q[c] = 0;
    }
    return q;
  }
  if (mode === 'points' && scene) {
    const mats = view.matrices();
    let best = null, bestD = 10;
    for (const c of scene.curves) {
      if (c.name === d.curve) continue;
      const cands = [...(c.control || [])];
      if (!c.closed && c.points.length) cands.push(c.points[0], c.points[c.points.length - 1]);
      for (const q of cands) {
        const s = view.project(q, mats);
        if (!s) continue;
        const dist = Math.hypot(s[0] - sx, s[1] - sy);
        if (dist < bestD) { bestD = dist; best = q; }
      }
    }
    if (best) return [...best];
  }
  return p;
}

function endDrag(ev) {
  const was = drag;
  drag = null;
  view.setGesture(false);
  if (was && was.camera && was.button === 0 && ev && ev.type === 'pointerup') {
    const [x, y] = pointerPos(ev);
    if (Math.hypot(x - was.start[0], y - was.start[1]) < 4) clickSelect(x, y);
  }
  // The point's coordinates as the drag left it: once its last frame is in.
  if (was && was.kind === 'control') {
    const again = () => (controlChannel.idle ? pointPanel() : setTimeout(again, 50));
    again();
  }
  // The next drag of the local handle starts from the curve as it is now.
  if (was && was.kind === 'local') {
    const again = () => (localChannel.idle ? local.show(local.curve).then(() => { view.setScene(scene); view.request(); }) : setTimeout(again, 50));
    again();
  }
}
view.canvas.addEventListener('pointerup', endDrag);
view.canvas.addEventListener('pointercancel', endDrag);
view.canvas.addEventListener('contextmenu', (ev) => ev.preventDefault());
// The wheel zooms; a trackpad's two-finger scroll (sideways, or small steps) pans, and its pinch
// (the wheel with Ctrl) zooms.
// A burst of wheel events is a gesture until 200 ms after its last event.
let wheelTimer = null;
view.canvas.addEventListener('wheel', (ev) => {
  ev.preventDefault();
  view.setGesture(true);
  clearTimeout(wheelTimer);
  wheelTimer = setTimeout(() => { if (!drag) view.setGesture(false); }, 200);
  const trackpad = !ev.ctrlKey && ev.deltaMode === 0 && (ev.deltaX !== 0 || Math.abs(ev.deltaY) < 40);
  if (trackpad) view.pan(-ev.deltaX, -ev.deltaY);
  else view.zoom(Math.exp(ev.deltaY * (ev.ctrlKey ? 0.01 : 0.001)));
}, { passive: false });
window.addEventListener('resize', () => { view.request(); uv.draw(); });

// ---- Panels ------------------------------------------------------------------------------
const selectedCurve = () => $('curve').value;
const selectedPatch = () => $('patch').value;
const patchRef = () => patchRefOf(selectedPatch());

// The centre of rotations and scalings: the picked control point of the curve, else the
// curve's centroid.
function curveCentre() {
  const c = scene.curves.find((x) => x.name === selectedCurve());
  const sel = view.selected;
  if (c && c.control && sel && sel.kind === 'control' && sel.curve === c.name && c.control[sel.index]) return c.control[sel.index];
  return (c && c.centroid) || [0, 0, 0];
}

function numbers(text, n, area) {
  const v = text.split(',').map((s) => Number(s.trim()));
  if (v.length !== n || v.some((x) => !Number.isFinite(x))) {
    panels.showError(area, `expected ${n} numbers separated by commas (got '${text}')`);
    return null;
  }
  return v;
}

$('convert').onclick = () => run('curve', () => api.convert(query(), selectedCurve()));
$('delete-curve').onclick = () => edit('curve', { edit: 'set_curve', name: selectedCurve(), curve: null });
$('translate').onclick = () => {
  const d = ['tx', 'ty', 'tz'].map((id) => Number($(id).value));
  if (d.some((x) => !Number.isFinite(x))) return panels.showError('curve', 'translate: expected numbers');
  edit('curve', { edit: 'transform', name: selectedCurve(), step: { translate: d } });
};
$('rotate').onclick = () => {
  const axis = { x: [1, 0, 0], y: [0, 1, 0], z: [0, 0, 1] }[$('raxis').value];
  edit('curve', { edit: 'transform', name: selectedCurve(),
    step: { rotate: { axis, angle: Number($('rangle').value), about: curveCentre() } } });
};
$('scale').onclick = () => edit('curve', { edit: 'transform', name: selectedCurve(),
  step: { scale: { factor: Number($('sfactor').value), about: curveCentre() } } });

// Sliders: one undo step per slider gesture, edits coalesced like drags.
function slider(input, area, makeEdit, label) {
  let group = null;
  const ch = channel(area, (body) => api.edit(query(true), body));
  input.addEventListener('pointerdown', () => { group = newGroup(); input.dataset.active = '1'; });
  input.addEventListener('input', (ev) => {
    if (group === null) group = newGroup();
    input.dataset.active = '1';
    view.setGesture(true);
    if (label) label.textContent = Number(input.value).toFixed(label.dataset.digits ? Number(label.dataset.digits) : 2);
    const value = Number(input.value);
    const g = group;
    ch.push(() => ({ edit: makeEdit(value), group: g }), ev.timeStamp);
  });
  input.addEventListener('change', () => { group = null; input.dataset.active = ''; view.setGesture(false); });
}
const paramSlider = (input, makeEdit, label) => {
  label.dataset.digits = '3';
  slider(input, 'params', makeEdit, label);
};

function curveSpecWith(changes) {
  const c = scene.curves.find((x) => x.name === selectedCurve());
  return { ...c.spec, ...changes };
}
slider($('v-origin'), 'curve', (v) => ({ edit: 'set_curve', name: selectedCurve(), curve: curveSpecWith({ v_origin: v }) }), $('v-origin-value'));
slider($('dscale'), 'curve', (v) => ({ edit: 'set_curve', name: selectedCurve(), curve: curveSpecWith({ scale: v }) }), $('dscale-value'));
slider($('a'), 'patch', (v) => ({ edit: 'set_smoothing', patch: patchRef(), a: v }), $('a-value'));
$('order').onchange = () => edit('patch', { edit: 'set_order', patch: patchRef(), order: Number($('order').value) });
$('modes').onchange = () => edit('patch', { edit: 'set_modes', modes: Number($('modes').value) });
$('delete-patch').onclick = () => edit('patch', { edit: 'remove_patch', name: selectedPatch() });
$('curve').onchange = () => { panels.curvePanel(scene); local.clear(); view.setScene(scene); view.request(); };
$('patch').onchange = () => { panels.patchPanel(scene); syncUvPatch(selectedPatch()); };

// Spine (§5.3): how the sections follow an edited spine, and back to the solved spine.
$('spine-carry').onchange = () => run('spine', () => api.spine(query(), { patch: patchRef(), carry: $('spine-carry').value }));
$('spine-reset').onclick = () => edit('spine', { edit: 'set_spine', patch: patchRef(), spine: null });

// Local edits (§6.2).
$('l-pick').onclick = () => { local.startPicking(selectedCurve()); view.setScene(scene); view.request(); };
$('l-show').onclick = async () => { await local.show(selectedCurve()); view.setScene(scene); view.request(); };
$('l-done').onclick = () => { local.clear(); view.setScene(scene); view.request(); };

$('add-curve').onclick = () => {
  const name = $('new-name').value.trim();
  if (!name) return panels.showError('add', 'name: give the new curve a name');
  const center = numbers($('new-center').value, 3, 'add');
  if (!center) return;
  const r = Number($('new-radius').value);
  const kind = $('new-kind').value;
  let curve;
  if (kind === 'point') curve = { type: 'point', at: center };
  else if (kind === 'ellipse') curve = { type: 'ellipse', center, rx: r, ry: r * 0.6 };
  else curve = { type: 'circle', center, radius: r };
  run('add', async () => {
    let frame = await api.edit(query(), { edit: { edit: 'set_curve', name, curve } });
    if (kind === 'bspline') frame = await api.convert(query(), name);
    return frame;
  });
};

$('add-patch').onclick = () => {
  const from = $('from').value, to = $('to').value;
  const name = $('patch-name').value.trim() || `${from}_${to}`;
  if (!scene.has_patches) {
    return panels.showError('add', 'this design has one patch given by top-level conditions; patches can be added to designs with [[patches]]');
  }
  // A biharmonic patch between two position curves. At an end where a patch already meets the
  // curve and continues across it (it ends there where the new one starts, or starts where the
  // new one ends), the new patch shares that patch's derivative curve: the seam is G1. Else X_u
  // is the straight join (s = 1).
  const straight = { type: 'derivative', position: from, direction: to, scale: 1 };
  const shared = (curve, theirU) => {
    for (const s of scene.surfaces) {
      const at = s.conditions.find((c) => c.derivative === 0 && c.curve === curve && c.u === theirU);
      const d = at && s.conditions.find((c) => c.derivative === 1 && c.u === theirU && c.curve);
      if (d) return { patch: s.name, curve: d.curve };
    }
    return null;
  };
  const atFrom = shared(from, 1), atTo = shared(to, 0);
  const conditions = [
    { u: 0, curve: from },
    { u: 0, derivative: 1, curve: atFrom ? atFrom.curve : straight },
    { u: 1, curve: to },
    { u: 1, derivative: 1, curve: atTo ? atTo.curve : straight },
  ];
  const g1 = [atFrom && `with ${atFrom.patch} along ${from}`, atTo && `with ${atTo.patch} along ${to}`].filter(Boolean);
  edit('add', { edit: 'insert_patch', index: scene.surfaces.length, patch: { name, conditions } })
    .then(() => { $('add-note').textContent = g1.length ? `G1 ${g1.join(' and ')} (the neighbour's derivative curve shared)` : ''; });
};

// ---- The (u, v) panel --------------------------------------------------------------------
let uvFile = null;
function syncUvPatch(name) {
  if (!scene) return;
  const sel = $('uv-patch');
  const names = scene.surfaces.map((s) => s.name);
  if (sel.options.length !== names.length || [...sel.options].some((o, k) => o.value !== names[k])) {
    sel.replaceChildren(...names.map((n) => {
      const o = document.createElement('option');
      o.value = n; o.textContent = n;
      return o;
    }));
  }
  if (name) sel.value = name;
  if (scene.file !== uvFile || !names.includes(sel.value)) {
    // A design just loaded: its first patch with holes or attachments, else its first.
    uvFile = scene.file;
    const hosts = new Set(scene.attachments.map((a) => a.host));
    const first = scene.surfaces.find((s) => s.trimmed || hosts.has(s.name));
    sel.value = first ? first.name : names[0];
  }
  uv.setScene(scene, sel.value);
  uvTools();
}
$('uv-patch').onchange = () => {
  $('patch').value = $('uv-patch').value;
  panels.patchPanel(scene);
  syncUvPatch();
};
function uvTools() {
  const e = uv.entry();
  $('uv-method').value = e ? (e.spec.method || 'cdt') : 'cdt';
  $('uv-method').disabled = !e;
  $('uv-delete').disabled = !(uv.selected && uv.selected.type === 'trim');
  const s = uv.selected;
  $('uv-selected').textContent = !s ? 'drag a curve to move it, its squares to reshape it'
    : s.type === 'trim' ? `trims[${s.index}].curves[${s.curve}]` : `${s.name} (attachment on ${uv.patch.name})`;
}
const uvEdit = (make) => {
  const value = make();
  if (value) edit('uv', value);
};
$('uv-add').onclick = () => uvEdit(() => uv.addEdit($('uv-kind').value));
$('uv-delete').onclick = () => { uvEdit(() => uv.deleteEdit()); uv.selected = null; };
$('uv-method').onchange = () => uvEdit(() => uv.methodEdit($('uv-method').value));

// ---- Files -------------------------------------------------------------------------------
async function refreshFiles() {
  try {
    const { files } = await api.files();
    const sel = $('files');
    sel.replaceChildren(...files.map((f) => {
      const o = document.createElement('option');
      o.value = f; o.textContent = f;
      return o;
    }));
    if (scene && files.includes(scene.file)) sel.value = scene.file;
  } catch (e) {
    panels.showError('file', message(e));
  }
}

function fresh() {
  panels.clearErrors();
  local.clear();
  timeline.pause();
  uv.selected = null;
  view.selected = null;
  view.selectedPatch = -1;
  view.multi = null;
  pointPanel();
  selectionNote();
  view.framed = false;
  view.camera.panned = false;
}
$('load').onclick = () => {
  if (!keepOrDiscard(`load ${$('files').value}`)) return;
  markClean = true;
  fresh();
  run('file', () => api.load(query(), $('files').value));
};
$('new').onclick = () => {
  if (!keepOrDiscard('start a new design')) return;
  markClean = true;
  fresh();
  run('file', () => api.reset(query()));
};
$('save').onclick = async () => {
  const path = $('save-path').value.trim() || (scene && scene.file) || 'design.toml';
  try {
    const r = await api.save(path);
    unsaved = false;
    panels.clearErrors();
    status(`saved ${r.saved}`);
    $('file-name').textContent = r.saved;
    refreshFiles();
  } catch (e) {
    panels.showError('file', message(e));
  }
};
$('undo').onclick = () => run('file', () => api.undo(query()));
$('redo').onclick = () => run('file', () => api.redo(query()));
// The page's words for the server's summary of a STEP or IGES file.
function cadNote(format, cad) {
  const f = Object.fromEntries(cad.split(';').map((kv) => kv.trim().split('=')));
  const rel = f.certified === 'true' ? '≤' : '≈';
  return `${format.toUpperCase()}: ${f.surfaces} B-spline surface(s), deviation from the design ${rel} ${f.deviation}` +
    ` (${f.certified === 'true' ? 'certified' : 'sampled, not certified'}; tolerance ${f.tolerance})`;
}
for (const a of document.querySelectorAll('.dl a')) {
  a.onclick = async (ev) => {
    ev.preventDefault();
    const format = a.dataset.format;
    let q = `${query()}&format=${format}`;
    if (format === 'png') {
      const eye = m.sub(view.eye(), view.camera.target);
      q += `&view=${eye.map((x) => x.toFixed(6)).join(',')}&size=1200x900`;
    }
    try {
      const { blob, cad } = await api.download(q);
      const url = URL.createObjectURL(blob);
      const link = document.createElement('a');
      link.href = url;
      link.download = `${(scene.file.split('/').pop() || 'design').replace(/\.toml$/, '')}.${format}`;
      link.click();
      setTimeout(() => URL.revokeObjectURL(url), 1000);
      panels.showError('file', '');
      $('file-note').textContent = cad ? cadNote(format, cad) : '';
    } catch (e) {
      panels.showError('file', message(e));
    }
  };
}
// "Full detail while dragging": the full grid and the full resolution during gestures.
view.fullDetail = $('full-drag').checked;
$('full-drag').onchange = () => { view.fullDetail = $('full-drag').checked; };
for (const id of ['color', 'nu', 'nv', 'c-lo', 'c-hi']) {
  $(id).onchange = () => run('view', () => api.frame(query()));
}
for (const key of ['curves', 'vectors', 'spines', 'control']) {
  $(`show-${key}`).onchange = (ev) => {
    view.show[key] = ev.target.checked;
    view.setScene(scene);
    view.request();
  };
}
$('show-uv').onchange = (ev) => {
  $('uv-box').hidden = !ev.target.checked;
  view.request();
  uv.draw();
};
$('refresh-reports').onclick = refreshReports;
$('legend').onclick = () => {
  $('legend').classList.toggle('folded');
  if (scene) panels.legend(scene);
};
// ---- Inspection: zebra stripes and isophotes -----------------------------------------------
function inspectChanged() {
  const ins = view.inspect;
  ins.mode = $('inspect').value;
  ins.axis = { x: [1, 0, 0], y: [0, 1, 0], z: [0, 0, 1] }[$('stripe-axis').value];
  ins.stripes = Number($('stripes').value);
  ins.lockedEye = $('stripe-lock').checked ? (ins.lockedEye || view.eye()) : null;
  const draft = Number($('draft-angle').value);
  if (Number.isFinite(draft) && draft >= 0 && draft < 90) ins.draft = draft;
  view.request();
}
for (const id of ['inspect', 'stripe-axis', 'stripes', 'stripe-lock', 'draft-angle']) $(id).addEventListener('input', inspectChanged);
$('g1-tol').onchange = refreshReports;
$('g2-tol').onchange = refreshReports;
// Curvature combs: the scene carries them only while they are shown.
$('show-combs').onchange = () => {
  view.comb.show = $('show-combs').checked;
  run('view', () => api.frame(query()));
};
for (const id of ['comb-scale', 'comb-density']) {
  $(id).addEventListener('input', () => {
    view.comb.scale = Number($('comb-scale').value);
    view.comb.every = Number($('comb-density').value);
    if (scene) { view.setScene(scene); view.request(); }
  });
}

// ---- Typed coordinates of the selected control point ---------------------------------------
function pointPanel() {
  const s = view.selected;
  const c = s && s.kind === 'control' && scene && scene.curves.find((x) => x.name === s.curve);
  const p = c && c.control && c.control[s.index];
  $('point-row').hidden = !p;
  if (!p) return;
  $('point-name').textContent = `${s.curve}[${s.index}]`;
  const rel = $('point-relative').checked;
  ['px', 'py', 'pz'].forEach((id, k) => { $(id).value = rel ? '0' : String(p[k]); });
}
$('point-relative').onchange = pointPanel;
$('point-set').onclick = () => {
  const s = view.selected;
  const c = s && s.kind === 'control' && scene.curves.find((x) => x.name === s.curve);
  if (!c) return panels.showError('point', 'select a control point first (click its dot)');
  const v = ['px', 'py', 'pz'].map((id) => Number($(id).value.trim() === '' ? NaN : $(id).value));
  const bad = v.findIndex((x) => !Number.isFinite(x));
  if (bad >= 0) return panels.showError('point', `${'xyz'[bad]}: expected a number (got '${$(['px', 'py', 'pz'][bad]).value}')`);
  const p0 = c.control[s.index];
  const point = $('point-relative').checked ? v.map((x, k) => p0[k] + x) : v;
  run('point', () => api.edit(query(), { edit: { edit: 'move_control_point', name: s.curve, index: s.index, point }, world: true }))
    .then(pointPanel);
};

// ---- Unsaved changes -----------------------------------------------------------------------
// Set by every edit (gestures, buttons, undo and redo), cleared by a load, a new design and a
// save.
let unsaved = false;
let markClean = true;
const dirty = () => unsaved;
function keepOrDiscard(what) {
  return !dirty() || window.confirm(`The design has unsaved changes. Discard them and ${what}?`);
}
window.addEventListener('beforeunload', (ev) => {
  if (!dirty()) return;
  ev.preventDefault();
  ev.returnValue = '';
});

// ---- Shortcuts and help --------------------------------------------------------------------
function toggleHelp(open = $('help').hidden) { $('help').hidden = !open; }
$('help-button').onclick = () => toggleHelp();
const VIEWS = {
  1: [-Math.PI / 2, 0], 2: [Math.PI / 2, 0], 3: [0, 0], 4: [Math.PI, 0],
  5: [-Math.PI / 2, 1.55], 6: [-Math.PI / 2, -1.55], 0: [-0.95, 0.48],
};
function toggleBox(id) {
  const box = $(id);
  box.checked = !box.checked;
  box.dispatchEvent(new Event('change'));
}
window.addEventListener('keydown', (ev) => {
  const mod = ev.ctrlKey || ev.metaKey;
  if (mod && (ev.key === 'z' || ev.key === 'Z')) { ev.preventDefault(); $(ev.shiftKey ? 'redo' : 'undo').click(); return; }
  if (mod && ev.key === 'y') { ev.preventDefault(); $('redo').click(); return; }
  if (mod && ev.key === 's') { ev.preventDefault(); $('save').click(); return; }
  if (mod || ev.altKey) return;
  const t = ev.target;
  if (t && (t.tagName === 'INPUT' || t.tagName === 'SELECT' || t.tagName === 'TEXTAREA')) return;
  if (ev.key === '?') { toggleHelp(); return; }
  if (ev.key === 'Escape') { toggleHelp(false); return; }
  const k = ev.key.toLowerCase();
  if (k === 'f') view.frameAll();
  else if (ev.key in VIEWS) view.standardView(...VIEWS[ev.key]);
  else if (k === 'z') {
    $('inspect').value = $('inspect').value === 'zebra' ? 'shaded' : 'zebra';
    inspectChanged();
  } else if (k === 'c') toggleBox('show-curves');
  else if (k === 'p') toggleBox('show-control');
  else if ((ev.key === 'Delete' || ev.key === 'Backspace') && view.selected && view.selected.kind === 'curve') {
    const name = view.selected.curve;
    view.selected = null;
    edit('curve', { edit: 'set_curve', name, curve: null });
  } else return;
  ev.preventDefault();
});

run('file', () => api.frame(query())).then(refreshFiles);
