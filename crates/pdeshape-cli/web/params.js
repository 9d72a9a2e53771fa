// Design parameters (`[[parameters]]`, book §6.1, §6.4, §7.5): one slider per named parameter
// within its bounds; each slider gesture sends Edit::SetParameter values (one undo step).

const $ = (id) => document.getElementById(id);

let shown = ''; // the names the rows were made for

// Rows for the scene's parameters; `slider(input, makeEdit, label)` wires one slider.
export function fill(scene, slider) {
  const list = scene.parameters || [];
  $('params-section').hidden = list.length === 0;
  const names = list.map((p) => p.name).join('\n');
  const box = $('params');
  if (names !== shown) {
    shown = names;
    box.replaceChildren(...list.map((p) => {
      const row = document.createElement('div');
      row.className = 'row param';
      const name = document.createElement('span');
      name.className = 'pname';
      name.textContent = p.name;
      name.title = `${p.place}: ${p.kind}${p.curve ? ` of ${p.curve}` : ''}`;
      const input = document.createElement('input');
      input.type = 'range';
      input.min = p.min;
      input.max = p.max;
      input.step = (p.max - p.min) / 500;
      input.dataset.param = p.name;
      input.setAttribute('aria-label', p.name);
      const value = document.createElement('span');
      value.className = 'pvalue';
      const kind = document.createElement('small');
      kind.textContent = ` ${p.kind}${p.curve ? ` (${p.curve})` : ''} [${p.min}, ${p.max}]`;
      row.append(name, input, value, kind);
      slider(input, (v) => ({ edit: 'set_parameter', name: p.name, value: v }), value);
      return row;
    }));
  }
  for (const p of list) {
    const input = box.querySelector(`input[data-param="${CSS.escape(p.name)}"]`);
    if (!input || input.dataset.active === '1') continue;
    if (p.value != null) {
      input.value = p.value;
      input.nextSibling.textContent = Number(p.value).toFixed(3);
    }
  }
}
