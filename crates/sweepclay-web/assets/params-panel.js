// The Parameters panel (docs/MODELER.md): the printer, and the design's
// parameters in plain words, each typed as a number (a decimal comma
// taken), refused beside the field when it is not one. It reads the design
// from the store, changes it through `edit`, and refreshes on every new
// design.

import { parseDecimal } from './numbers.js';
import { edit, report, state, subscribe } from './store.js';

const $ = (id) => document.getElementById(id);

/** The printer dialog's helpers the panel's printer choice uses (app.js). */
let hooks = null;

// Each parameter: its key, its label, its unit, its input step, what it
// does (the tooltip, with the default), and the factor between the file's
// value and the one shown (overlap is a fraction in the file, % here).
export const PARAMS = [
  ['layer_height', 'layer height', 'mm', 0.05, 'the thinnest layer of clay (the paper\'s Δz₀)', 1],
  ['max_layer_height', 'max layer height', 'mm', 0.05, 'the thickest layer allowed where the two profiles differ in height', 1],
  ['spacing', 'point spacing', 'mm', 0.05, 'distance between points along the path seen from above', 1],
  ['nozzle_height', 'extruder body height', 'mm', 1, 'how high the extruder body reaches above the nozzle tip (the paper\'s H): no clay may rise above it', 1],
  ['width_min', 'bead width min', 'mm', 0.1, 'the narrowest bead of clay', 1],
  ['width_max', 'bead width max', 'mm', 0.1, 'the widest bead of clay', 1],
  ['overlap', 'overlap with the bead below', '%', 1, 'how much of each bead rests on the bead below it', 100],
  ['max_overhang_deg', 'steepest overhang', '°', 1, 'how far from vertical the wall may lean before it is corrected', 1],
  ['feedrate', 'print speed', 'mm/min', 50, 'how fast the nozzle moves while printing', 1],
  ['floor_layers', 'floor layers (vessel)', '', 1, 'flat layers of the floor of a closed vessel; 0 for bottomless', 1],
  ['shrinkage_xy', 'firing shrinkage across', '%', 0.5, 'how much your clay body shrinks across from wet to fired (0 to 50 %): the piece is printed that much larger, so the fired piece has the drawn size', 100],
  ['shrinkage_z', 'firing shrinkage in height', '%', 0.5, 'how much your clay body shrinks in height from wet to fired (0 to 50 %)', 100],
];

/** The label, unit and factor of parameter `key`, if it is one. */
export function param(key) {
  const p = PARAMS.find((q) => q[0] === key);
  return p && { label: p[1], unit: p[2], factor: p[5] };
}

export function buildParams(printers) {
  hooks = printers;
  const { fillPrinterOptions, keptPrinters, openPrinter } = printers;
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
  editPrinter.title = 'Set up your own printer: build volume, bed_min, origin, E per mm³, nozzle body, start and end code';
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
        report.error(`${label}: "${inp.value}" is not a number (write 1.5 or 1,5)`, `params.${key}`);
        return;
      }
      // Layers come whole: said beside the field, the value left as it was.
      if (key === 'floor_layers' && !(Number.isInteger(v) && v >= 0 && v <= state.meta.max_floor_layers)) {
        report.error(`${label}: "${inp.value}" is not a whole number of layers from 0 (bottomless) to ${state.meta.max_floor_layers}`, `params.${key}`);
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
  const { keptPrinters } = hooks;
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
  if (hooks) fillParams();
});
