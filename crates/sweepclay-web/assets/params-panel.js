// The Parameters panel (docs/MODELER.md): the printer, and the design's
// parameters in plain words, each typed as a number (a decimal comma
// taken), refused beside the field when it is not one. It reads the design
// from the store, changes it through `edit`, and refreshes on every new
// design.

import { parseDecimal } from './numbers.js';
import { PARAMS } from './params.js';
import { fillPrinterOptions, keptPrinters, openPrinter } from './printer-dialog.js';
import { showError } from './status.js';
import { edit, state, subscribe } from './store.js';

const $ = (id) => document.getElementById(id);

/** Whether the panel is built (its fields exist). */
let built = false;

export function buildParams() {
  built = true;
  const form = $('params');
  const printer = document.createElement('label');
  printer.innerHTML = 'printer <select id="p-printer" title="The printer the G-code is for: its build volume, where the design lands, its extruder"></select>';
  form.appendChild(printer);
  const sel = printer.querySelector('select');
  fillPrinterOptions();
  sel.addEventListener('change', () => {
    if (sel.value.startsWith('kept:')) {
      const k = keptPrinters().find((p) => `kept:${p.printer.name}` === sel.value);
      if (k) edit((d) => { d.printer = k.printer; d.params = { ...(d.params || {}), nozzle_height: k.nozzle_height }; }, true);
    } else if (sel.value) {
      edit((d) => { d.printer = sel.value; }, true);
    }
  });
  const editPrinter = document.createElement('button');
  editPrinter.type = 'button';
  editPrinter.id = 'printer-edit';
  editPrinter.textContent = 'Edit printer…';
  editPrinter.title = 'Set up your own printer: build volume, where the bed and the pot sit, E per mm³, nozzle body, start and end code';
  editPrinter.addEventListener('click', openPrinter);
  form.appendChild(editPrinter);
  for (const [key, label, unit, step, help, factor] of PARAMS) {
    const l = document.createElement('label');
    l.innerHTML = `<span>${label} <small>${unit}</small></span>`;
    const inp = document.createElement('input');
    // Text, not a number field: a browser's number field reads "1,5" as
    // 15 in some locales; a decimal comma is read here as a decimal.
    inp.type = 'text';
    inp.inputMode = 'decimal';
    inp.dataset.step = step;
    inp.id = `p-${key}`;
    const def = state.meta.params[key] ?? (key === 'floor_layers' ? 2 : null);
    const shown = def == null ? '' : ` (default ${Number((def * factor).toFixed(4))}${unit ? ` ${unit}` : ''})`;
    inp.title = `${help}${shown}`;
    l.title = inp.title;
    inp.addEventListener('change', () => {
      const v = parseDecimal(inp.value);
      if (!Number.isFinite(v)) {
        showError(`${label}: "${inp.value}" is not a number (write 1.5 or 1,5)`, `params.${key}`);
        return;
      }
      // Layers come whole: said beside the field, the value left as it was.
      if (key === 'floor_layers' && !(Number.isInteger(v) && v >= 0 && v <= state.meta.max_floor_layers)) {
        showError(`${label}: "${inp.value}" is not a whole number of layers from 0 (bottomless) to ${state.meta.max_floor_layers}`, `params.${key}`);
        return;
      }
      edit((d) => { d.params = { ...(d.params || {}), [key]: v / factor }; }, true);
      state.lastParam = key;
    });
    l.appendChild(inp);
    form.appendChild(l);
  }
  $('name').addEventListener('change', () => edit((d) => { d.name = $('name').value; }, true));
}

function fillParams() {
  const d = state.design;
  const p = { ...state.meta.params, ...(d.params || {}) };
  if (p.floor_layers === undefined || p.floor_layers === null) p.floor_layers = 2;
  for (const [key, , , , , factor] of PARAMS) {
    const inp = $(`p-${key}`);
    // A percentage to two decimals (2/3 is 66.67 %).
    const v = String(Number((Number(p[key]) * factor).toFixed(factor === 1 ? 4 : 2)));
    if (document.activeElement !== inp && inp.value !== v) inp.value = v;
  }
  // Only a vessel has a floor.
  $('p-floor_layers').disabled = !d.trajectory.closed;
  const kept = typeof d.printer === 'object' && d.printer && keptPrinters().find((k) => JSON.stringify(k.printer) === JSON.stringify(d.printer));
  const printer = typeof d.printer === 'string' ? d.printer : kept ? `kept:${kept.printer.name}` : d.printer ? '' : 'generic';
  $('p-printer').value = printer;
  if (document.activeElement !== $('name')) $('name').value = d.name || '';
}

subscribe(() => {
  if (built) fillParams();
});
