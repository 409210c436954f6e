// Pot mode (docs/MODELER.md): a design with one profile for the whole
// wall shows the widths-at-heights table in place of the end profile and
// the interpolation, the rim's shape for a vessel, and "New pot".
// Subscribed to the store: a new design shows or hides the table.

import { rowsOnCurve } from './bspline.js';
import { clone, edit, setDesign, state, subscribe } from './store.js';
import { fmtMm, parseDecimal } from './numbers.js';
import { currentPrinter } from './printer-dialog.js';
import { MIN_DZ, baseWidth, newPotDesign, potRows, setPotRows } from './shapes.js';

const $ = (id) => document.getElementById(id);


/**
 * Pot mode (docs/MODELER.md): a design without an end profile has one
 * profile for the whole wall. Its end-profile editor and the
 * interpolation give way to the widths-at-heights table.
 */
function showPotMode() {
  const d = state.design;
  const pot = !d.profile_end;
  $('one-profile').checked = pot;
  $('end-figure').hidden = pot;
  $('ed-interp').closest('figure').hidden = pot;
  $('pot-panel').hidden = !pot;
  const caption = pot ? 'side profile' : 'start side profile';
  if ($('start-caption').textContent !== caption) $('start-caption').textContent = caption;
  if (pot) fillPot();
}

$('one-profile').addEventListener('change', (e) => edit((d) => {
  if (e.target.checked) {
    delete d.profile_end;
    delete d.interpolation;
  } else {
    // Two profiles shape the rim themselves.
    delete d.rim;
    d.profile_end = clone(d.profile_start);
  }
}, true));

function fillPot() {
  const d = state.design;
  const pts = potRows(d);
  const w0 = baseWidth(d);
  const p = { ...state.meta.params, ...(d.params || {}) };
  // Widths as callipers read them: the outside, a bead wider than the
  // centreline the design keeps (docs/FORMATS.md, "Widths at heights").
  const bead = p.width_min;
  // Rebuilt only when it shows something else: a drag repaints no table.
  fillRim(d);
  const look = JSON.stringify([pts, w0, p.layer_height, bead]);
  if (look === state.potLook) return;
  state.potLook = look;
  const body = $('pot-rows').tBodies[0];
  const focused = document.activeElement?.closest?.('#pot-rows') ? document.activeElement.id : null;
  body.innerHTML = '';
  pts.forEach(([x, z], i) => {
    const tr = document.createElement('tr');
    const cell = (id, v, title, disabled) => {
      const td = document.createElement('td');
      const inp = document.createElement('input');
      inp.type = 'text';
      inp.inputMode = 'decimal';
      inp.id = id;
      inp.value = fmtMm(v);
      inp.title = title;
      inp.disabled = !!disabled;
      td.appendChild(inp);
      tr.appendChild(td);
      return inp;
    };
    const zi = cell(`pot-z${i}`, z, i === 0 ? 'the base stands on the bed' : 'height of this point above the bed (mm)', i === 0);
    const wi = cell(`pot-w${i}`, w0 + 2 * (x - pts[0][0]) + bead, i === 0 ? 'the width of the foot outside, as callipers read it (mm): the path seen from above scales with it' : 'the width outside at this height, as callipers read it (mm)');
    zi.addEventListener('change', () => potEdit(i, 'z', zi));
    wi.addEventListener('change', () => potEdit(i, 'w', wi));
    const td = document.createElement('td');
    if (i > 0 && pts.length > 2) {
      const del = document.createElement('button');
      del.type = 'button';
      del.textContent = '×';
      del.id = `pot-del${i}`;
      del.title = 'Remove this height';
      del.addEventListener('click', () => edit((dd) => {
        const rows = potRows(dd);
        rows.splice(i, 1);
        setPotRows(dd, rows);
      }, true));
      td.appendChild(del);
    }
    tr.appendChild(td);
    body.appendChild(tr);
  });
  if (focused && $(focused)) $(focused).focus();
  if (document.activeElement !== $('pot-height')) $('pot-height').value = fmtMm(pts[pts.length - 1][1]);
  if (document.activeElement !== $('pot-layer')) $('pot-layer').value = fmtMm(p.layer_height);
}

/** A potter's number typed into the table, or a message beside it. */
function potNumber(inp, what) {
  const v = parseDecimal(inp.value);
  if (!Number.isFinite(v)) {
    potError(inp, `${what}: "${inp.value}" is not a number (write 1.5 or 1,5)`);
    return null;
  }
  return v;
}

function potError(inp, msg) {
  $('pot-error').textContent = msg;
  inp.classList.add('bad');
  // On a phone the keyboard may cover it: bring the words into view.
  $('pot-error').scrollIntoView({ block: 'nearest' });
}

/** Row `i`'s height or width typed in, within the profile's rules. */
function potEdit(i, what, inp) {
  $('pot-error').textContent = '';
  const v = potNumber(inp, what === 'z' ? 'height' : 'width');
  if (v == null) return;
  const d = state.design;
  const pts = potRows(d);
  // Far past the printer is a slip of the keyboard, refused here before
  // anything is drawn or sampled: a row 1e6 mm up crashed the tab.
  const printer = currentPrinter(d);
  if (printer) {
    const bv = printer.build_volume;
    const most = what === 'z' ? 4 * bv[2] : 4 * Math.max(bv[0], bv[1]);
    if (v > most) {
      const says = what === 'z' ? `the ${fmtMm(bv[2])} mm the ${printer.name} prints in height` : `the ${fmtMm(Math.max(bv[0], bv[1]))} mm the ${printer.name}'s bed spans`;
      potError(inp, `${what === 'z' ? 'height' : 'width'} ${fmtMm(v)} mm: at most ${fmtMm(most)} mm here, four times ${says}`);
      return;
    }
  }
  if (what === 'z') {
    // Any height above the base takes its place among the rows (they
    // stay sorted, each keeping its width); it may not sit on another.
    if (!(v >= MIN_DZ)) {
      potError(inp, `height ${fmtMm(v)} mm: must be above the base (at least ${fmtMm(MIN_DZ)} mm)`);
      return;
    }
    const clash = pts.find((p, j) => j !== i && Math.abs(p[1] - v) < MIN_DZ);
    if (clash) {
      potError(inp, `height ${fmtMm(v)} mm: another row is at ${fmtMm(clash[1])} mm; heights must be at least ${fmtMm(MIN_DZ)} mm apart`);
      return;
    }
    edit((dd) => {
      const rows = potRows(dd);
      rows[i][1] = v;
      setPotRows(dd, rows);
    }, true);
    return;
  }
  // Typed outside; the design keeps the centreline, a bead in.
  const bead = { ...state.meta.params, ...(d.params || {}) }.width_min;
  if (!(v > 2 * bead)) {
    potError(inp, `width ${fmtMm(v)} mm: must be more than two beads (${fmtMm(2 * bead)} mm): the widths are outside, as callipers read them`);
    return;
  }
  const w0 = baseWidth(d);
  if (i === 0) {
    // The base's width scales the path about o; the heights' widths keep
    // their distance from the base's.
    const k = (v - bead) / w0;
    const others = pts.map(([x]) => w0 + 2 * (x - pts[0][0]) + bead);
    edit((dd) => {
      const t = dd.trajectory;
      const key = t.points ? 'points' : 'control_points';
      t[key] = t[key].map(([x, y]) => [+(x * k).toFixed(3), +(y * k).toFixed(3)]);
      const rows = potRows(dd);
      for (let j = 1; j < rows.length; j++) rows[j][0] = rows[0][0] + (others[j] - v) / 2;
      setPotRows(dd, rows);
    }, true);
    return;
  }
  edit((dd) => {
    const rows = potRows(dd);
    rows[i][0] = pts[0][0] + (v - bead - w0) / 2;
    setPotRows(dd, rows);
  }, true);
}

/**
 * The rim control (docs/MODELER.md): a vessel's rim level, slanted, raised
 * over an arc or wavy, as the design's `rim` (docs/FORMATS.md); only the
 * fields its shape reads are shown.
 */
function fillRim(d) {
  const row = $('rim-row');
  row.hidden = !d.trajectory.closed;
  const r = d.rim;
  const shape = r?.shape ?? '';
  if (document.activeElement !== $('rim-shape')) $('rim-shape').value = shape;
  const show = { 'rim-rise-l': !!shape, 'rim-toward-l': !!shape, 'rim-peaks-l': shape === 'wave', 'rim-width-l': shape === 'raised' };
  for (const [id, on] of Object.entries(show)) $(id).hidden = !on;
  const put = (id, v) => {
    if (document.activeElement !== $(id)) $(id).value = v == null ? '' : fmtMm(v);
  };
  put('rim-rise', r?.rise);
  put('rim-toward', r ? r.toward_deg ?? 0 : null);
  put('rim-peaks', r?.peaks);
  put('rim-width', r ? r.width_deg ?? 120 : null);
}

// A shape's starting values: a rim 20 mm higher at the back; a wave
// 5 mm high (three crests of 20 mm meet the extruder body on most pots:
// the spiral must climb and fall between them faster than it clears).
const RIM_START = { rise: 20, toward_deg: 90 };
const WAVE_START_RISE = 5;

/**
 * Beside the rim's fields, the most rise of this rim that prints, when
 * the verdict found it (docs/MODELER.md), with a button that takes it.
 */
export function showRimMost(verdict) {
  const most = verdict?.most_rise;
  const rim = state.design?.rim;
  const show = most != null && rim != null && most < rim.rise;
  $('rim-most').hidden = !show;
  if (show) {
    $('rim-most-mm').textContent = fmtMm(most);
    $('rim-most-use').dataset.mm = String(most);
    // The panel scrolls: the offer is beside the field, where it is read.
    $('rim-most').scrollIntoView({ block: 'nearest' });
  }
}
$('rim-most-use').addEventListener('click', (e) => {
  const most = Number(e.target.dataset.mm);
  $('rim-most').hidden = true;
  edit((d) => { if (d.rim) d.rim.rise = most; }, true);
});

$('rim-shape').addEventListener('change', (e) => edit((d) => {
  const shape = e.target.value;
  if (!shape) {
    delete d.rim;
    return;
  }
  const old = d.rim || RIM_START;
  const rise = shape === 'wave' && old.shape !== 'wave' ? Math.min(old.rise, WAVE_START_RISE) : old.rise;
  d.rim = { shape, rise, toward_deg: old.toward_deg ?? 90 };
  if (shape === 'wave') d.rim.peaks = old.peaks ?? 3;
  if (shape === 'raised') d.rim.width_deg = old.width_deg ?? 120;
}, true));

/** A rim field typed in, within its range, or a message beside it. */
function rimEdit(id, key, what, lo, hi, whole) {
  const inp = $(id);
  inp.classList.remove('bad');
  $('pot-error').textContent = '';
  const v = potNumber(inp, what);
  if (v == null) return;
  if (!(v >= lo && v <= hi) || (whole && !Number.isInteger(v))) {
    potError(inp, `${what} ${fmtMm(v)}: must be ${whole ? 'a whole number ' : ''}from ${lo} to ${hi}`);
    return;
  }
  edit((d) => { if (d.rim) d.rim[key] = v; }, true);
}
$('rim-rise').addEventListener('change', () => rimEdit('rim-rise', 'rise', 'rim rise (mm)', 0, 1000, false));
$('rim-toward').addEventListener('change', () => rimEdit('rim-toward', 'toward_deg', 'rim highest toward (°)', -360, 360, false));
$('rim-peaks').addEventListener('change', () => rimEdit('rim-peaks', 'peaks', 'rim crests', 1, 12, true));
$('rim-width').addEventListener('change', () => rimEdit('rim-width', 'width_deg', 'raised part (°)', 1, 360, false));

// A new height goes in the middle of the largest gap between the rows
// (type any height into it: the rows re-sort).
$('pot-add').addEventListener('click', () => edit((d) => {
  const ctrl = d.profile_start.control_points;
  const p = potRows(d);
  let k = 1;
  for (let j = 2; j < p.length; j++) if (p[j][1] - p[j - 1][1] > p[k][1] - p[k - 1][1]) k = j;
  // The curve's own point half way up between the two rows: the pot
  // keeps its shape there, and passes through every row as before.
  const z = (p[k - 1][1] + p[k][1]) / 2;
  p.splice(k, 0, rowsOnCurve(ctrl, [[0, z]])[1] ?? [(p[k - 1][0] + p[k][0]) / 2, z]);
  setPotRows(d, p);
}, true));

$('pot-height').addEventListener('change', () => {
  const inp = $('pot-height');
  $('pot-error').textContent = '';
  const h = potNumber(inp, 'height');
  if (h == null) return;
  const pts = state.design.profile_start.control_points;
  const top = pts[pts.length - 1][1];
  if (!(h >= MIN_DZ * (pts.length - 1))) {
    potError(inp, `height ${fmtMm(h)} mm: too low for its ${pts.length} rows, which stand at least ${fmtMm(MIN_DZ)} mm apart (at least ${fmtMm(MIN_DZ * (pts.length - 1))} mm)`);
    return;
  }
  // Taller than the printer is shown, the part outside in violet; far
  // taller is a slip of the keyboard (99999 once blamed the point spacing).
  const printer = currentPrinter(state.design);
  if (printer && h > 4 * printer.build_volume[2]) {
    potError(inp, `height ${fmtMm(h)} mm: at most ${fmtMm(4 * printer.build_volume[2])} mm here, four times the ${fmtMm(printer.build_volume[2])} mm the ${printer.name} prints (a taller pot is shown with the part outside the printer in violet)`);
    return;
  }
  edit((d) => {
    const c = d.profile_start;
    for (const p of [...c.control_points, ...(c.points || [])]) p[1] = +((p[1] * h) / top).toFixed(3);
  }, true);
});

$('pot-layer').addEventListener('change', () => {
  const inp = $('pot-layer');
  $('pot-error').textContent = '';
  const v = potNumber(inp, 'layer height');
  if (v == null) return;
  edit((d) => { d.params = { ...(d.params || {}), layer_height: v }; }, true);
  state.lastParam = 'layer_height';
});

/** A new pot on the design's printer, its parameters kept (shapes.js). */
function newPot() {
  const d = newPotDesign(state.design?.printer ?? 'generic', state.meta?.presets, state.design?.params);
  setDesign(d, { fit: true });
}
$('new-pot').addEventListener('click', newPot);

subscribe(() => showPotMode());
