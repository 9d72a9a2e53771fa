// The side panels: the lists of curves and patches, the spine of the selected patch, the
// shared-edge table, the check report and the analyze numbers, and error messages beside the
// control that caused them.

import { COLORS, analyticHandles } from './view.js';

const $ = (id) => document.getElementById(id);

export function showError(area, message) {
  const el = document.querySelector(`.err[data-for="${area}"]`);
  if (el) el.textContent = message || '';
}

export function clearErrors() {
  for (const el of document.querySelectorAll('.err')) el.textContent = '';
}

function fillSelect(sel, names, keep) {
  const old = keep ? sel.value : null;
  sel.replaceChildren(...names.map((n) => {
    const o = document.createElement('option');
    o.value = n; o.textContent = n;
    return o;
  }));
  if (old && names.includes(old)) sel.value = old;
}

// Text from the design file, safe inside HTML.
const esc = (s) => String(s).replace(/[&<>"']/g, (c) => `&#${c.charCodeAt(0)};`);

const rgb = (c) => `rgb(${c.map((x) => Math.round(x * 255)).join(',')})`;

// The legend (built with DOM calls: the page's content security policy allows no inline styles).
// The curves along seams that failed the check (drawn red).
export const failing = new Set();

export function legend(scene) {
  const box = $('legend');
  const row = (color, text, swatch = 'line') => {
    const div = document.createElement('div');
    const sw = document.createElement('span');
    sw.className = `sw ${swatch}`;
    sw.style.background = color;
    div.append(sw, text);
    return div;
  };
  const title = document.createElement('div');
  title.className = 'title';
  title.textContent = box.classList.contains('folded') ? 'Legend ▸' : 'Legend ▾';
  const rows = [title];
  rows.push(...scene.surfaces.map((s, k) =>
    row(rgb(COLORS.patches[k % COLORS.patches.length]), `patch ${s.name} (${s.kind})`, 'patch')));
  rows.push(row(rgb(COLORS.position), 'position curves (click to select)'));
  rows.push(row(rgb(COLORS.other), 'other curves (derivative directions)'));
  rows.push(row(rgb(COLORS.vector), 'derivative vectors X_u (1/3 length)'));
  rows.push(row(rgb(COLORS.spine), 'spines'));
  if (scene.surfaces.some((s) => s.spine_control)) rows.push(row(rgb(COLORS.spineControl), 'spine control points (drag them)', 'dot'));
  if (scene.trim_lines && scene.trim_lines.length) rows.push(row(rgb(COLORS.trim), 'trim curves (holes)'));
  rows.push(row(rgb(COLORS.edge), 'shared edges (seams)'));
  if (failing && failing.size) rows.push(row(rgb(COLORS.fail), 'seams above the G1 or G2 tolerance'));
  rows.push(row('#000', 'v = 0 marks (tick: increasing v)'));
  rows.push(row('rgb(217,26,26)', 'axes at the bottom left: x red, y green, z blue'));
  if (scene.curves.some((c) => c.comb && c.comb.length)) rows.push(row(rgb(COLORS.comb), 'curvature combs (teeth ∝ curvature)'));
  if (scene.seam_combs && scene.seam_combs.length) rows.push(row(rgb(COLORS.combOther), 'across a seam: the second patch\'s normal-curvature comb'));
  if (scene.curves.some((c) => c.control)) rows.push(row(rgb(COLORS.control), 'control points (drag them)', 'dot'));
  if (scene.curves.some((c) => analyticHandles(c).length)) rows.push(row(rgb(COLORS.handle), 'circle and ellipse handles: centre, radii (drag them)', 'dot'));
  if (scene.color_range) {
    const f = (x) => Number(Number(x).toPrecision(3)).toString();
    const [lo, hi] = scene.color_range;
    const div = document.createElement('div');
    div.className = 'colorbar';
    const bar = document.createElement('span');
    bar.className = 'bar';
    const full = scene.color_full_range;
    div.append(`${f(lo)} `, bar, ` ${f(hi)}`);
    if (full) {
      div.title = 'the colours span the 2nd to 98th percentile; beyond them they saturate';
      div.append(`  (true range ${f(full[0])} … ${f(full[1])})`);
    }
    rows.push(div);
  }
  box.replaceChildren(...rows);
}

export function fill(scene) {
  $('file-name').textContent = scene.file + (scene.title ? ` — ${scene.title}` : '');
  $('undo').disabled = !scene.can_undo;
  $('redo').disabled = !scene.can_redo;
  const curves = scene.curves.map((c) => c.name);
  fillSelect($('curve'), curves, true);
  const positions = scene.curves.filter((c) => c.role !== 'derivative').map((c) => c.name);
  fillSelect($('from'), positions, true);
  fillSelect($('to'), positions, true);
  fillSelect($('patch'), scene.surfaces.map((s) => s.name), true);
  $('modes').value = scene.modes;
  curvePanel(scene);
  patchPanel(scene);
  legend(scene);
}

export function selectedCurve(scene) {
  return scene.curves.find((c) => c.name === $('curve').value);
}

export function selectedPatch(scene) {
  return scene.surfaces.find((s) => s.name === $('patch').value);
}

export function curvePanel(scene) {
  const c = selectedCurve(scene);
  if (!c) return;
  $('curve-kind').textContent = `${c.kind}, ${c.role}` + (c.control ? `, ${c.control.length} control points` : '');
  $('convert').disabled = !(c.kind === 'circle' || c.kind === 'ellipse');
  $('v0-row').style.display = c.v0 ? '' : 'none';
  $('v-origin').value = c.v_origin || 0;
  $('v-origin-value').textContent = (c.v_origin || 0).toFixed(2);
  $('s-row').style.display = c.scale != null ? '' : 'none';
  if (c.scale != null) {
    $('dscale').value = c.scale;
    $('dscale-value').textContent = c.scale.toFixed(2);
  }
}

export function patchPanel(scene) {
  const s = selectedPatch(scene);
  if (!s) return;
  // The spine (§5.3).
  const n = s.spine_control ? s.spine_control.length : 0;
  $('spine-info').textContent = !n ? `${s.kind}: no spine to edit`
    : `degree ${n - 1}, ${n} control points${s.spine_carry ? `, edited (${s.spine_carry})` : ', as solved'}${s.spine_wave ? ', with a wave' : ''}`;
  if (n && s.hosts) $('spine-info').textContent += ' (hosts attached patches: the spine stays as solved)';
  $('spine-carry').disabled = !n || s.hosts;
  $('spine-reset').disabled = !s.spine_carry;
  if (s.spine_carry) $('spine-carry').value = s.spine_carry;
  const op = s.operator;
  if (op && op.kind === 'polyharmonic') {
    $('patch-op').textContent = `polyharmonic N = ${op.order}, a = ${op.a}`;
    $('a').value = op.a;
    $('a-value').textContent = Number(op.a).toFixed(2);
    $('order').value = op.order;
  } else {
    $('patch-op').textContent = op ? op.text || op.kind : s.kind;
  }
}

// The shared edges (seams): G0 distance, G1 angle in degrees (radians in the tooltip), G2 figure;
// a seam above the G1 or the G2 tolerance is marked red (its `failed` from the check) with ✗
// beside the figure that failed.
function edges(list) {
  const t = $('edges');
  if (!list.length) {
    t.innerHTML = '<tr><td>none (no position curve shared by two patches)</td></tr>';
    return;
  }
  const deg = (x) => (x == null ? 'NaN' : `${((x * 180) / Math.PI).toPrecision(3)}°`);
  t.innerHTML = '<tr><th>seam</th><th>along</th><th title="largest distance between the two sides">G0</th>' +
    '<th title="largest angle between the two tangent planes">G1</th>' +
    '<th title="largest jump of the normal curvature across the seam (1/length)">G2</th></tr>' + list.map((e) =>
    `<tr class="${e.failed ? 'bad' : 'ok'}" data-curve="${esc(e.curve)}"><td>${esc(e.a)} u=${e.ua} | ${esc(e.b)} u=${e.ub}</td><td>${esc(e.curve)}</td>` +
    `<td>${e.g0 == null ? 'NaN' : e.g0.toExponential(2)}</td>` +
    `<td class="g1${e.g1_failed ? ' over' : ''}" title="${e.g1 == null ? 'NaN' : e.g1.toExponential(3)} rad">${deg(e.g1)}</td>` +
    `<td class="g2${e.g2_failed ? ' over' : ''}">${e.g2 == null ? 'NaN' : e.g2.toExponential(2)}</td></tr>`).join('');
}

const PLAIN = { area: 'area', volume: 'volume', bending_energy: 'bending', willmore: 'Willmore',
  gauss_integral: '∫K', mean_integral: '∫H' };

export function reports(check, analyze) {
  edges(check.edges);
  failing.clear();
  for (const e of check.edges) if (e.failed) failing.add(e.curve);
  $('check').textContent = check.text;
  $('check').classList.toggle('fail', check.verdict === 'fail');
  const keys = Object.keys(PLAIN);
  const row = (name, v) => `<tr><td>${esc(name)}</td>${keys.map((k) => `<td>${v[k] == null ? '–' : Number(v[k]).toPrecision(4)}</td>`).join('')}</tr>`;
  $('analyze').innerHTML = `<tr><th></th>${keys.map((k) => `<th title="${k}">${PLAIN[k]}</th>`).join('')}</tr>` +
    analyze.patches.map((p) => row(p.name, p)).join('') + row('total', analyze.total);
}
