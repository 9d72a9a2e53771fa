// The designer: wires the view, the panels and the API together. Every change is an edit value
// sent to the server; the answer is a frame (scene + meshes). While a drag runs, at most one
// request is in flight and only the newest pointer position waits (events are coalesced, never
// queued).

import { api, ApiError } from './api.js';
import { View, COLORS } from './view.js';
import * as panels from './panels.js';
import * as m from './math.js';

const $ = (id) => document.getElementById(id);
const view = new View($('view'));
let scene = null;
let busy = Promise.resolve();

// Measurements for tests and benchmarks: pointer event → new surface on screen.
const perf = { latencies: [], server: [], roundTrips: [], frames: 0, drags: 0, sent: 0, coalesced: 0 };
window.__pdeshape = { perf, state: () => scene, view };

function query() {
  return `nu=${$('nu').value}&nv=${$('nv').value}&color=${$('color').value}`;
}

function status(text) {
  $('status').textContent = text;
}

// Shows a frame: meshes, scene, panels; `onDrawn` runs after the frame is on screen.
function show(frame, onDrawn) {
  scene = frame.scene;
  view.setSurfaces(frame.surfaces, COLORS.patches);
  view.setScene(scene);
  panels.fill(scene);
  perf.frames += 1;
  const verts = frame.surfaces.reduce((n, s) => n + s.nu * s.nv, 0);
  status(`v${scene.version}  ${frame.surfaces.length} surfaces, ${verts} vertices, ` +
    `${(frame.bytes / 1024).toFixed(0)} KiB, server ${scene.server_ms.toFixed(1)} ms, ` +
    `round trip ${frame.roundTrip.toFixed(1)} ms`);
  view.onDrawn = () => {
    view.onDrawn = null;
    if (onDrawn) onDrawn();
  };
  view.request();
  scheduleReports();
}

// Runs one request at a time (outside drags); an error goes beside `area`.
function run(area, call, onDrawn) {
  busy = busy.then(async () => {
    try {
      const frame = await call();
      frame.roundTrip = frame.roundTripMs;
      panels.showError(area, '');
      show(frame, onDrawn);
    } catch (e) {
      panels.showError(area, message(e));
      // The controls show the design as it stands (the refused value is not kept).
      if (scene) panels.fill(scene);
    }
  });
  return busy;
}

function message(e) {
  if (e instanceof ApiError) return e.place ? `${e.place}: ${e.message}` : e.message;
  return String(e && e.message ? e.message : e);
}

function edit(area, value, group) {
  return run(area, () => api.edit(query(), { edit: value, group }));
}

// The check and analyze panels follow the design a moment after it settles.
let reportsTimer = null;
function scheduleReports() {
  clearTimeout(reportsTimer);
  reportsTimer = setTimeout(refreshReports, 600);
}
async function refreshReports() {
  try {
    const [check, analyze] = await Promise.all([api.check(), api.analyze()]);
    panels.reports(check, analyze);
    panels.showError('reports', '');
  } catch (e) {
    panels.showError('reports', message(e));
  }
}

// ---- Dragging control points -------------------------------------------------------------
let drag = null; // { curve, index, plane, group, pending, inflight }
let groupCounter = Date.now();

function pointerPos(ev) {
  const r = view.canvas.getBoundingClientRect();
  return [ev.clientX - r.left, ev.clientY - r.top];
}

function sendDrag() {
  if (!drag || drag.inflight || !drag.pending) return;
  const { point, t } = drag.pending;
  drag.pending = null;
  drag.inflight = true;
  perf.sent += 1;
  const d = drag;
  const body = {
    edit: { edit: 'move_control_point', name: d.curve, index: d.index, point },
    group: d.group,
    world: true,
  };
  api.edit(query(), body).then((frame) => {
    frame.roundTrip = frame.roundTripMs;
    panels.showError('drag', '');
    show(frame, () => {
      const now = performance.now();
      perf.latencies.push(now - t);
      perf.server.push(frame.scene.server_ms);
      perf.roundTrips.push(frame.roundTripMs);
    });
  }).catch((e) => {
    // The server kept the last good surface; say why beside the curve controls.
    panels.showError('drag', message(e));
  }).finally(() => {
    d.inflight = false;
    sendDrag();
  });
}

view.canvas.addEventListener('pointerdown', (ev) => {
  const [x, y] = pointerPos(ev);
  view.canvas.setPointerCapture(ev.pointerId);
  const hit = ev.button === 0 && !ev.shiftKey ? view.pick(x, y) : null;
  if (hit) {
    view.selected = { curve: hit.curve, index: hit.index };
    $('curve').value = hit.curve;
    panels.curvePanel(scene);
    drag = {
      curve: hit.curve, index: hit.index, group: ++groupCounter,
      plane: view.dragPlane(hit.point, $('plane').value), pending: null, inflight: false,
    };
    perf.drags += 1;
    view.setScene(scene);
    view.request();
  } else {
    drag = { camera: ev.button === 2 || ev.shiftKey ? 'pan' : 'orbit', last: [x, y] };
  }
});

view.canvas.addEventListener('pointermove', (ev) => {
  if (!drag) return;
  const [x, y] = pointerPos(ev);
  if (drag.camera) {
    const [dx, dy] = [x - drag.last[0], y - drag.last[1]];
    drag.last = [x, y];
    if (drag.camera === 'pan') view.pan(dx, dy); else view.orbit(dx, dy);
    return;
  }
  const ray = view.ray(x, y);
  const hit = m.rayPlane(ray.origin, ray.dir, drag.plane.point, drag.plane.normal);
  if (!hit) return;
  if (drag.pending) perf.coalesced += 1;
  drag.pending = { point: hit, t: ev.timeStamp };
  sendDrag();
});

function endDrag() {
  drag = null;
}
view.canvas.addEventListener('pointerup', endDrag);
view.canvas.addEventListener('pointercancel', endDrag);
view.canvas.addEventListener('contextmenu', (ev) => ev.preventDefault());
view.canvas.addEventListener('wheel', (ev) => {
  ev.preventDefault();
  view.zoom(Math.exp(ev.deltaY * 0.001));
}, { passive: false });
window.addEventListener('resize', () => view.request());

// ---- Panels ------------------------------------------------------------------------------
const selectedCurve = () => $('curve').value;
const selectedPatch = () => $('patch').value;
const patchRef = () => (scene && scene.has_patches ? selectedPatch() : null);

// The centre of rotations and scalings: the picked control point of the curve, else the
// curve's centroid.
function curveCentre() {
  const c = scene.curves.find((x) => x.name === selectedCurve());
  const sel = view.selected;
  if (c && c.control && sel && sel.curve === c.name && c.control[sel.index]) return c.control[sel.index];
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
  let group = null, inflight = false, pending = null;
  const pump = () => {
    if (inflight || pending === null) return;
    const value = pending;
    pending = null;
    inflight = true;
    api.edit(query(), { edit: makeEdit(value), group }).then((frame) => {
      frame.roundTrip = frame.roundTripMs;
      panels.showError(area, '');
      show(frame);
    }).catch((e) => panels.showError(area, message(e))).finally(() => {
      inflight = false;
      pump();
    });
  };
  input.addEventListener('pointerdown', () => { group = ++groupCounter; });
  input.addEventListener('input', () => {
    if (group === null) group = ++groupCounter;
    if (label) label.textContent = Number(input.value).toFixed(2);
    pending = Number(input.value);
    pump();
  });
  input.addEventListener('change', () => { group = null; });
}

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
$('curve').onchange = () => panels.curvePanel(scene);
$('patch').onchange = () => panels.patchPanel(scene);

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
  // A biharmonic patch between two position curves, with X_u from the straight join (s = 1).
  const conditions = [
    { u: 0, curve: from },
    { u: 0, derivative: 1, curve: { type: 'derivative', position: from, direction: to, scale: 1 } },
    { u: 1, curve: to },
    { u: 1, derivative: 1, curve: { type: 'derivative', position: from, direction: to, scale: 1 } },
  ];
  edit('add', { edit: 'insert_patch', index: scene.surfaces.length, patch: { name, conditions } });
};

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

$('load').onclick = () => {
  panels.clearErrors();
  view.framed = false;
  view.camera.panned = false;
  run('file', () => api.load(query(), $('files').value));
};
$('new').onclick = () => {
  panels.clearErrors();
  view.framed = false;
  run('file', () => api.reset(query()));
};
$('save').onclick = async () => {
  const path = $('save-path').value.trim() || (scene && scene.file) || 'design.toml';
  try {
    const r = await api.save(path);
    panels.showError('file', '');
    status(`saved ${r.saved}`);
    $('file-name').textContent = r.saved;
    refreshFiles();
  } catch (e) {
    panels.showError('file', message(e));
  }
};
$('undo').onclick = () => run('file', () => api.undo(query()));
$('redo').onclick = () => run('file', () => api.redo(query()));
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
      const blob = await api.download(q);
      const url = URL.createObjectURL(blob);
      const link = document.createElement('a');
      link.href = url;
      link.download = `${(scene.file.split('/').pop() || 'design').replace(/\.toml$/, '')}.${format}`;
      link.click();
      setTimeout(() => URL.revokeObjectURL(url), 1000);
      panels.showError('file', '');
    } catch (e) {
      panels.showError('file', message(e));
    }
  };
}
for (const id of ['color', 'nu', 'nv']) {
  $(id).onchange = () => run('view', () => api.frame(query()));
}
for (const key of ['curves', 'vectors', 'spines', 'control']) {
  $(`show-${key}`).onchange = (ev) => {
    view.show[key] = ev.target.checked;
    view.setScene(scene);
    view.request();
  };
}
$('refresh-reports').onclick = refreshReports;
window.addEventListener('keydown', (ev) => {
  if ((ev.ctrlKey || ev.metaKey) && ev.key === 'z') { ev.preventDefault(); $(ev.shiftKey ? 'redo' : 'undo').click(); }
});

run('file', () => api.frame(query())).then(refreshFiles);
