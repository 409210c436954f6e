// The modeler page: the design (docs/FORMATS.md) is the one state; the editors
// and the parameters change it, every change is recorded for undo, saved to
// the browser, and re-sliced by the server; the preview, the statistics and
// the checker's verdict follow.

import { CurveEditor, fmt, segDist } from './editor.js';
import { View3D } from './view3d.js';
import { onCurve, rowsOnCurve, sample, samplePeriodic, throughRows } from './bspline.js';
import { afterPaint, frameStats, onFrame } from './frame.js';
import { fetchSlice } from './mesh.js';
import { curveLines, profilePoints } from './curves3d.js';
import { HISTORY, STORE, TAB_HISTORY, clone, edit, redo, setDesign, state, subscribe, undo } from './store.js';
import { buildSurface } from './surface-panel.js';
import { buildParams } from './params-panel.js';
import { parseDecimal } from './numbers.js';
import { list, plainWords, setBusy, setVerdict, showError, showNote } from './status.js';
import { download, postDesign } from './io.js';
import { fmtMm } from './numbers.js';
import { currentPrinter, fillPrinterOptions, keptPrinters, openPrinter, withMyPrinter } from './printer-dialog.js';

const $ = (id) => document.getElementById(id);
const GUIDE_SEEN = 'sweepclay.guide.v1';

// For tests and the curious: the last round trips (edit → preview drawn), ms.
window.sweepclay = state;
state.frames = frameStats;
window.sweepclayErrors = [];
window.addEventListener('error', (e) => window.sweepclayErrors.push(String(e.message)));
window.addEventListener('unhandledrejection', (e) => window.sweepclayErrors.push(String(e.reason)));

// ---------------------------------------------------------------- design

function trajectoryPoints(d) {
  return d.trajectory.points || d.trajectory.control_points;
}

function interpolationPoints(d) {
  if (d.interpolation) return d.interpolation.control_points;
  // A vessel's default, (1 − cos 2πu)/2, is drawn as a curve (below).
  return d.trajectory.closed ? [[0, 0], [1, 0]] : [[0, 0], [1, 1]];
}

/** How long the pointer rests mid-drag before the design is sliced (ms). */
const REST_MS = 100;

/**
 * A drag's move: the edited curves are drawn now, over the last preview,
 * greyed until the slice arrives; the slice starts when the pointer rests
 * REST_MS or lets go (a release calls `requestSlice` at once).
 */
function sliceAtRest() {
  if (view && state.design) {
    const d = state.design;
    view.showCurves(() => curveLines(d), state.lastEdit);
  }
  setSettling(true);
  // A slice in flight is of a design the editors have left.
  state.seq++;
  cancelVerify();
  setVerdict('checking');
  clearTimeout(state.restTimer);
  state.restTimer = setTimeout(() => requestSlice(false, { rest: true }), REST_MS);
}

/** Greys the preview while it shows a design older than the editors'. */
function setSettling(on) {
  if (state.settling === on) return;
  state.settling = on;
  $('preview').classList.toggle('settling', on);
}

// Another tab saved its design: this tab keeps its own, says so, and
// offers the other one (an undoable step), never losing either.
window.addEventListener('storage', (e) => {
  if (e.key !== STORE || !e.newValue || !state.design) return;
  if (e.newValue === JSON.stringify(state.design)) return;
  let other;
  try {
    other = JSON.parse(e.newValue);
  } catch (err) {
    return;
  }
  const s = $('status');
  s.querySelector('.note')?.remove();
  const div = document.createElement('div');
  div.className = 'note';
  div.id = 'other-tab';
  div.append(`Another tab saved a different design${other.name ? ` ("${other.name}")` : ''}; this tab keeps yours and its undo history. `);
  const b = document.createElement('button');
  b.id = 'open-other-tab';
  b.textContent = 'Open that design here';
  b.addEventListener('click', () => {
    div.remove();
    setDesign(other, { fit: true });
  });
  div.append(b);
  s.appendChild(div);
});

function updateUndo() {
  $('undo').disabled = state.at <= 0;
  $('redo').disabled = state.at >= state.history.length - 1;
}

/**
 * Shows a new design everywhere (the store's one subscriber here): the
 * editors, the panels, the undo buttons; then slices it, or for a drag's
 * move draws its curves and slices when the pointer rests (docs/MODELER.md,
 * "The curve follows the finger").
 */
subscribe((d, { fit, live }) => {
  // Another design (opened, an example, a new pot): no refusal of a value
  // typed for the last one stays beside the point bar.
  if (fit) $('pb-error').textContent = '';
  for (const ed of editors) {
    if (fit) ed.fitted = false;
    if (fit) ed.fit();
    ed.refresh();
  }
  showPotMode();
  $('offset').value = d.trajectory.offset === 'normal' ? 'normal' : 'radial';
  $('closed').checked = !!d.trajectory.closed;
  updateUndo();
  if (live) sliceAtRest();
  else requestSlice(fit);
});


// ---------------------------------------------------------------- editors

const curve = (pts) => (pts.length >= 2 ? sample(pts, 160) : pts);
const MIN_DZ = 0.5;

function profileEditor(id, key, otherKey) {
  return new CurveEditor($(id), {
    get: () => (state.design ? profilePoints(state.design, key) : []),
    // A drag moves the curve; a pot's typed rows stay at their heights,
    // on the curve (`rowsOnCurve`).
    set: (pts, final, since) => edit((d) => {
      const rows = d[key]?.points;
      d[key] = rows ? { control_points: pts, points: rowsOnCurve(pts, rows).map(mm3) } : { control_points: pts };
    }, final, since),
    curve,
    // A pot has no other profile to show faintly.
    ghost: () => (state.design?.profile_end ? profilePoints(state.design, otherKey) : null),
    printed: () => state.printed?.[key] ?? null,
    ground: true,
    snap: 1,
    grid: 5,
    minPoints: 2,
    // The base point (z = 0) slides along the bed but stays.
    kept: (i) => i === 0,
    constrain: (i, [x, z], pts) => {
      // z = 0 for the first point, strictly increasing along the curve.
      if (i === 0) return [x, 0];
      const lo = pts[i - 1][1] + MIN_DZ;
      const hi = i + 1 < pts.length ? pts[i + 1][1] - MIN_DZ : Infinity;
      if (lo > hi) return null;
      return [x, Math.min(hi, Math.max(lo, z))];
    },
    label: ([x, z]) => `x ${fmt(x)}, z ${fmt(z)} mm`,
  });
}

const editors = [
  profileEditor('ed-start', 'profile_start', 'profile_end'),
  profileEditor('ed-end', 'profile_end', 'profile_start'),
  new CurveEditor($('ed-traj'), {
    get: () => (state.design ? trajectoryPoints(state.design) : []),
    printed: () => state.printed?.trajectory ?? null,
    set: (pts, final, since) => edit((d) => {
      if (d.trajectory.points) d.trajectory.points = pts;
      else d.trajectory.control_points = pts;
    }, final, since),
    curve: (pts) => {
      const t = state.design?.trajectory;
      // A closed trajectory wraps round: the polygon closes, the
      // B-spline is periodic (docs/FORMATS.md).
      if (t?.closed) return t.points ? pts.concat(pts.slice(0, 1)) : samplePeriodic(pts);
      return t?.points ? pts : curve(pts);
    },
    centre: true,
    snap: 1,
    grid: 10,
    minPoints: 2,
    label: ([x, y]) => `x ${fmt(x)}, y ${fmt(y)} mm`,
  }),
  new CurveEditor($('ed-interp'), {
    get: () => (state.design ? interpolationPoints(state.design) : [[0, 0], [1, 1]]),
    set: (pts, final, since) => edit((d) => { d.interpolation = { control_points: pts }; }, final, since),
    curve: (pts) => {
      const d = state.design;
      if (d?.trajectory.closed && !d.interpolation) {
        return Array.from({ length: 101 }, (_, i) => [i / 100, (1 - Math.cos(2 * Math.PI * i / 100)) / 2]);
      }
      return curve(pts);
    },
    fixed: [-0.04, -0.04, 1.04, 1.04],
    snap: 0.02,
    grid: 0.1,
    minPoints: 2,
    pinned: (i, pts) => i === 0 || i === pts.length - 1,
    constrain: (i, [u, f], pts) => {
      // Endpoints pinned; u strictly and f weakly increasing: monotone. Round
      // a vessel f comes back to 0 and may rise and fall between.
      const closed = state.design?.trajectory.closed;
      if (i === 0) return [0, 0];
      if (i === pts.length - 1) return [1, closed ? 0 : 1];
      const [pu, pf] = pts[i - 1];
      const [nu, nf] = pts[i + 1];
      if (nu - pu < 0.02) return null;
      if (closed) return [Math.min(nu - 0.01, Math.max(pu + 0.01, u)), Math.min(1, Math.max(0, f))];
      return [Math.min(nu - 0.01, Math.max(pu + 0.01, u)), Math.min(nf, Math.max(pf, f))];
    },
    label: ([u, f]) => `u ${fmt(u)}, λ ${fmt(f)}`,
  }),
];

state.editors = editors;

// The selected point, typed in or added and deleted with buttons (touch
// screens have no double-click).
const EDITOR_NAMES = ['start side profile', 'end side profile', 'path seen from above', 'how one profile turns into the other'];
const AXES = [['x', 'z'], ['x', 'z'], ['x', 'y'], ['u', 'λ']];
function showPoint(ed, user = true) {
  // Only the user's own selection makes an editor the bar's: a refresh of
  // every editor after an edit made the last one refreshed (the end
  // profile) take the start profile's typed values.
  if (user && ed.selected >= 0) {
    // A refusal beside the bar was about the last value typed there.
    if (ed !== state.activeEditor || ed.selected !== state.barPoint) {
      $('pb-error').textContent = '';
      $('pb-x').classList.remove('bad');
      $('pb-y').classList.remove('bad');
    }
    state.activeEditor = ed;
    state.barPoint = ed.selected;
  } else if (ed !== state.activeEditor) return;
  const a = state.activeEditor;
  const k = editors.indexOf(a);
  const p = a && a.selected >= 0 ? a.points[a.selected] : null;
  // On a phone the editors stand one under another: the bar follows the
  // editor of the selected point, just under it (style.css, `--bar`).
  const figs = [...$('editors').querySelectorAll(':scope > figure')];
  const at = figs.indexOf(a?.canvas.closest('figure'));
  $('editors').style.setProperty('--bar', String(at >= 0 ? 2 * at + 3 : 20));
  $('pb-what').textContent = p ? `${EDITOR_NAMES[k]}, point ${a.selected + 1} of ${a.points.length}:` : 'Click or tap a point to select it.';
  for (const [id, v, axis] of [['pb-x', p && p[0], k >= 0 ? AXES[k][0] : 'x'], ['pb-y', p && p[1], k >= 0 ? AXES[k][1] : 'y']]) {
    const inp = $(id);
    inp.disabled = !p;
    $(`${id}l`).textContent = axis;
    if (document.activeElement !== inp) inp.value = p ? Number(v.toFixed(3)) : '';
  }
  $('pb-del').disabled = !(a && a.canRemove());
  $('pb-del').title = a && a.selected >= 0 && !a.canRemove() ? 'This point stays (the base of a profile, an end, or the fewest points allowed)' : 'Delete the selected point';
}
for (const ed of editors) ed.o.onSelect = showPoint;
for (const id of ['pb-x', 'pb-y']) {
  $(id).addEventListener('change', () => {
    const a = state.activeEditor;
    if (!a || a.selected < 0) return;
    const k = editors.indexOf(a);
    $('pb-error').textContent = '';
    $(id).classList.remove('bad');
    const said = (msg) => {
      $('pb-error').textContent = msg;
      $(id).classList.add('bad');
    };
    const axis = $(`${id}l`).textContent;
    const v = parseDecimal($(id).value);
    if (!Number.isFinite(v)) {
      said(`${axis}: "${$(id).value}" is not a number (write 1.5 or 1,5)`);
      return;
    }
    const old = a.points[a.selected];
    const p = id === 'pb-x' ? [v, old[1]] : [old[0], v];
    // Taken as typed or refused: a point its neighbours hold in place
    // is not moved somewhere else silently.
    if (a.o.pinned && a.o.pinned(a.selected, a.points)) {
      said(`this point of the ${EDITOR_NAMES[k]} stays where it is (the base of a profile, or an end)`);
      return;
    }
    const q = a.o.constrain ? a.o.constrain(a.selected, p, a.points) : p;
    if (!q || Math.abs(q[0] - p[0]) > 1e-6 || Math.abs(q[1] - p[1]) > 1e-6) {
      const near = q ? ` (the nearest it may go: ${AXES[k][0]} ${Number(q[0].toFixed(3))}, ${AXES[k][1]} ${Number(q[1].toFixed(3))})` : '';
      said(`${axis} ${Number(v.toFixed(3))}: the point cannot go there, between its neighbours${near}`);
      return;
    }
    if (!a.moveSelected(p)) showPoint(a);
  });
}
$('pb-add').addEventListener('click', () => {
  const a = state.activeEditor || editors[2];
  state.activeEditor = a;
  a.addAfterSelected();
});
$('pb-del').addEventListener('click', () => {
  const a = state.activeEditor;
  if (a && a.selected >= 0) a.remove(a.selected);
});

$('snap').addEventListener('change', (e) => editors.forEach((ed) => { ed.snapOn = e.target.checked; }));
/** Control points of a circle a quarter as wide as `d`'s printer bed (8 points, periodic). */
function defaultLoop(d) {
  const pr = typeof d.printer === 'object' && d.printer ? d.printer : state.meta?.presets.find((p) => p.name === (d.printer || 'generic'));
  const bed = pr?.build_volume || [200, 200, 200];
  const r = Math.max(15, Math.round(Math.min(bed[0], bed[1]) / 8));
  // A periodic cubic B-spline through a regular octagon's points runs
  // about 0.93 of the way out: the control polygon is drawn wider.
  return Array.from({ length: 8 }, (_, i) => {
    const a = (2 * Math.PI * i) / 8;
    return [+(1.08 * r * Math.cos(a)).toFixed(2), +(1.08 * r * Math.sin(a)).toFixed(2)];
  });
}

/**
 * Makes `d`'s trajectory a loop (a vessel) or an open wall; the
 * interpolation (a loop's ends at 0, a wall's at 0 and 1) and the floor
 * follow (docs/FORMATS.md).
 */
function setClosed(d, closed) {
  const ip = d.interpolation?.control_points;
  if (closed) {
    // An open wall's points wrapped round make a sliver: a new vessel
    // starts as a round pot a quarter of the printer's bed across.
    if (!d.trajectory.closed) d.trajectory = { control_points: defaultLoop(d), closed: true };
    d.trajectory.closed = true;
    if (ip && ip[ip.length - 1][1] !== 0) delete d.interpolation;
  } else {
    delete d.trajectory.closed;
    // An open wall has no rim round a loop.
    delete d.rim;
    if (ip && ip[ip.length - 1][1] !== 1) delete d.interpolation;
    if (d.params) delete d.params.floor_layers;
  }
}
$('closed').addEventListener('change', (e) => edit((d) => setClosed(d, e.target.checked), true));
$('offset').addEventListener('change', (e) => edit((d) => {
  if (e.target.value === 'normal') d.trajectory.offset = 'normal';
  else delete d.trajectory.offset;
}, true));


// ---------------------------------------------------------------- pots

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

/** The x-extent of the path seen from above (mm): a round pot's base diameter. */
function baseWidth(d) {
  const t = d.trajectory;
  const pts = t.points || t.control_points;
  const path = t.closed ? (t.points ? pts : samplePeriodic(pts)) : t.points ? pts : sample(pts, 160);
  const xs = path.map((p) => p[0]);
  return Math.max(...xs) - Math.min(...xs);
}

/**
 * The table's rows: the points the profile passes through as the potter
 * typed them (the profile's `points`), or, for a profile drawn without
 * them, its own points one a control point (`onCurve`); each is a height
 * and a width across. Typed rows become the control points of a curve
 * through them (`throughRows`) and are kept as `points`, so the pot is as
 * wide as typed at each typed height (docs/MODELER.md, "Widths at
 * heights").
 */
function potRows(d) {
  const c = d.profile_start;
  return (c.points || onCurve(c.control_points)).map((p) => p.slice());
}

const mm3 = ([x, z]) => [+x.toFixed(3), +z.toFixed(3)];

/** Sets the profile to the curve through `rows` (heights sorted). */
function setPotRows(d, rows) {
  rows.sort((a, b) => a[1] - b[1]);
  d.profile_start = { control_points: throughRows(rows).map(mm3), points: rows.map(mm3) };
}

function fillPot() {
  const d = state.design;
  const pts = potRows(d);
  const w0 = baseWidth(d);
  const p = { ...state.meta.params, ...(d.params || {}) };
  // Rebuilt only when it shows something else: a drag repaints no table.
  fillRim(d);
  const look = JSON.stringify([pts, w0, p.layer_height]);
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
    const wi = cell(`pot-w${i}`, w0 + 2 * (x - pts[0][0]), i === 0 ? 'the width of the base across (mm): the path seen from above scales with it' : 'the width across at this height (mm)');
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
}

/** Row `i`'s height or width typed in, within the profile's rules. */
function potEdit(i, what, inp) {
  $('pot-error').textContent = '';
  const v = potNumber(inp, what === 'z' ? 'height' : 'width');
  if (v == null) return;
  const d = state.design;
  const pts = potRows(d);
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
  if (!(v > 0)) {
    potError(inp, `width ${fmtMm(v)} mm: must be more than 0`);
    return;
  }
  const w0 = baseWidth(d);
  if (i === 0) {
    // The base's width scales the path about o; the heights' widths keep
    // their distance from the base's.
    const k = v / w0;
    const others = pts.map(([x]) => w0 + 2 * (x - pts[0][0]));
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
    rows[i][0] = pts[0][0] + (v - w0) / 2;
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

// A shape's starting values: a rim 20 mm higher at the back.
const RIM_START = { rise: 20, toward_deg: 90 };

$('rim-shape').addEventListener('change', (e) => edit((d) => {
  const shape = e.target.value;
  if (!shape) {
    delete d.rim;
    return;
  }
  const old = d.rim || RIM_START;
  d.rim = { shape, rise: old.rise, toward_deg: old.toward_deg ?? 90 };
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
    potError(inp, `height ${fmtMm(h)} mm: too low for ${pts.length} heights`);
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

/** A round pot a quarter as wide as the printer's bed: one profile, a floor. */
function newPot() {
  const printer = state.design?.printer ?? 'generic';
  const d = {
    sweepclay: 1,
    name: 'new pot',
    profile_start: { control_points: [[0, 0], [8, 30], [10, 60], [4, 90]] },
    trajectory: { control_points: [], closed: true },
    printer,
  };
  d.trajectory.control_points = defaultLoop(d);
  const pr = typeof printer === 'object' ? printer : state.meta.presets.find((p) => p.name === printer);
  // Tall enough to be a pot, never taller than the printer.
  const zmax = pr?.build_volume?.[2] ?? 200;
  const k = Math.min(1, (0.6 * zmax) / 90);
  for (const p of d.profile_start.control_points) p[1] = +(p[1] * k).toFixed(2);
  if (state.design?.params) d.params = { ...state.design.params };
  setDesign(d, { fit: true });
}
$('new-pot').addEventListener('click', newPot);

// ---------------------------------------------------------------- slicing

let view = null;
try {
  view = new View3D($('view3d'), $('view-overlay'));
} catch (e) {
  showError(String(e.message || e));
}
state.view = view;

/** Slices the design now (`rest`: the pointer rested mid-drag). */
function requestSlice(fit, { rest = false } = {}) {
  clearTimeout(state.restTimer);
  if (view && state.design) {
    const d = state.design;
    view.showCurves(() => curveLines(d), state.lastEdit);
  }
  // The round trip counts from the oldest edit not yet shown: one merged
  // into a waiting request keeps that request's start.
  const edit = state.pending?.edit ?? state.lastEdit;
  state.seq++;
  state.pending = { design: JSON.stringify(state.design), edit, fit: fit || state.pending?.fit, seq: state.seq, rest };
  state.lastEdit = null;
  // A verdict belongs to one design: the last one no longer applies.
  // The slice's answer carries the check of the very G-code it shows
  // (one edit, one slice: docs/MODELER.md).
  cancelVerify();
  setVerdict('checking');
  if (!state.inFlight) sendSlice();
}

/** The design did not slice: the error, no verdict, the old preview greyed. */
function sliceFailed(msg, key) {
  setSettling(false);
  showError(msg, key);
  showPrinted({});
  cancelVerify();
  setVerdict(null);
  setStale(true);
}

function cancelVerify() {
  clearTimeout(state.verifyTimer);
  state.verifySeq++;
  state.verifyFor = null;
}

/**
 * Marks the preview and the statistics as out of date (the design does
 * not slice; they still show the last one that did), or clears the mark.
 */
function setStale(on) {
  for (const id of ['preview', 'stats']) $(id).classList.toggle('stale', on);
  $('stale-note').hidden = !on;
}

// The slice is fetched and read in a worker (slice-worker.js): the page's
// main thread stays free for input. Without workers, it is done here.
let worker = null;
const waiting = new Map();
try {
  worker = new Worker('/assets/slice-worker.js', { type: 'module' });
  worker.onmessage = (e) => {
    const w = waiting.get(e.data.id);
    waiting.delete(e.data.id);
    if (w) w(e.data);
  };
} catch (e) {
  worker = null;
}
let workerIds = 0;

/** Slices a design (JSON text): `{ ok, body, timing }`, or `{ failed }` when the server did not answer. */
async function sliceDesign(design) {
  if (worker) {
    const id = ++workerIds;
    return new Promise((resolve) => {
      waiting.set(id, resolve);
      worker.postMessage({ id, design });
    });
  }
  return fetchSlice(design);
}

function sendSlice() {
  const job = state.pending;
  state.pending = null;
  if (!job) return;
  state.inFlight = true;
  state.sent++;
  setBusy(true);
  const t0 = performance.now();
  sliceDesign(job.design)
    // The answer is shown at the next frame, never inside a handler.
    .then((res) => new Promise((resolve) => {
      onFrame('slice', () => {
        try {
          showSlice(job, res, t0);
        } finally {
          resolve();
        }
      });
    }))
    .finally(() => {
      state.inFlight = false;
      if (state.pending) sendSlice();
      else setBusy(false);
    });
}

/** Shows a slice's answer: the preview, or the error; the verdict only for the newest design. */
function showSlice(job, res, t0) {
  // Whether this is the design now in the editors: an older one's
  // answer may draw, but never sets the verdict or the error.
  const current = job.seq === state.seq;
  if (!res.ok) {
    if (current) sliceFailed(res.failed ? `the server did not answer: ${res.failed}` : res.body.error, res.body?.key);
    return;
  }
  const body = res.body;
  showError(null);
  setStale(false);
  if (current) setSettling(false);
  state.restored = false;
  const t1 = performance.now();
  render(body, job.fit);
  if (body.fit_error && current) {
    // Shown as it is, with what lies outside the printer marked; it
    // cannot be printed, so there is no check to wait for.
    showError(body.fit_error.error, body.fit_error.key);
    cancelVerify();
    setVerdict({ printable: false, failures: [plainWords(body.fit_error.error)], locations: [] });
  }
  const since = job.edit ?? t0;
  const drawn = performance.now();
  afterPaint((now) => {
    state.roundTrips.push({
      ms: now - since,
      // Sliced when the pointer rested mid-drag, not at the gesture's end.
      rest: job.rest,
      request_ms: res.timing.request_ms,
      headers_ms: res.timing.headers_ms,
      worker_ms: res.timing.worker_ms,
      render_ms: drawn - t1,
      server_ms: body.slice_ms,
      samples: body.stats.sample_points,
    });
    if (state.roundTrips.length > 100) state.roundTrips.shift();
    showTiming();
  });
  if (current && body.verdict) {
    cancelVerify();
    state.verifyFor = job.seq;
    setVerdict(body.verdict);
    // For the speed budget (docs/MODELER.md): last edit → its verdict.
    if (state.lastEditAt != null) state.verdictTimes.push(performance.now() - state.lastEditAt);
    if (state.verdictTimes.length > 100) state.verdictTimes.shift();
  } else if (current && !body.fit_error && state.verifyFor !== job.seq) {
    scheduleVerify(job.design, job.seq);
  }
}

function render(data, fit) {
  state.sliced = data;
  if (view) {
    view.update(data, state.design.params ? { ...state.meta.params, ...state.design.params } : state.meta.params, fit || !state.fittedOnce);
    state.fittedOnce = true;
    $('legend').innerHTML = view.legend();
  }
  const s = data.stats;
  const rows = [
    ['size', `${s.size_mm.map((v) => v.toFixed(1)).join(' × ')} mm`],
    ['sample points', s.sample_points.toLocaleString('en')],
    ['transition curves', s.curves.toLocaleString('en')],
    ...(s.vessel
      ? [
        ['floor', s.vessel.floor_layers > 0
          ? `${s.vessel.floor_layers} layers, each a spiral of ${s.vessel.floor_turns} turns, ${s.vessel.floor_area_cm2.toFixed(1)} cm² (${s.vessel.floor_cover_pct.toFixed(1)} % covered)`
          : 'none (bottomless)'],
        ['wall', `${s.vessel.wall_turns} spiral turns + rim`],
        ...(s.vessel.raised
          ? [['raised rim', `above ${s.vessel.raised.level_mm.toFixed(1)} mm: ${s.vessel.raised.passes} partial layers back and forth`]]
          : []),
      ]
      : [
        ['passes', `${s.passes} (${s.stages} stage${s.stages > 1 ? 's' : ''})`],
        ['returning turns', s.returning_points],
      ]),
    ...(s.print_scale[0] !== 1 || s.print_scale[1] !== 1
      ? [['firing shrinkage', `printed ${((s.print_scale[0] - 1) * 100).toFixed(1)} % larger across, ${((s.print_scale[1] - 1) * 100).toFixed(1)} % taller: fired, the drawn size`]]
      : []),
    ['path length', `${(s.path_length_mm / 1000).toFixed(2)} m`],
    ['clay', `${s.volume_ml.toFixed(1)} ml, ${s.clay_g.toFixed(0)} g${s.cartridges != null ? `, ${s.cartridges} cartridge${s.cartridges === 1 ? '' : 's'}` : ''}`],
    ...(s.refills || []).map((r, i) => [`refill ${i + 1}`, `layer ${r.pass}, ${r.z_mm.toFixed(1)} mm up (${Math.round(r.share * 100)} %)`]),
    ['printing time', `${s.time_min.toFixed(1)} min`],
  ];
  // Rewritten only when they say something new: a drag's slices mostly
  // change a few numbers.
  const html = rows.map(([k, v]) => `<tr><td>${k}</td><td data-stat="${k}">${v}</td></tr>`).join('');
  if (html !== state.statsHtml) {
    state.statsHtml = html;
    $('stats').innerHTML = html;
  }
  list($('corrections'), data.corrections);
  list($('warnings'), data.warnings);
  showPrinted(data.printed || {});
}

/**
 * The curves as the corrections left them, drawn beside the drawn ones in
 * the editors (docs/MODELER.md): a potter sees where the print departs
 * from the drawing before reading any number.
 */
function showPrinted(printed) {
  const t = printed.trajectory;
  state.printed = {
    ...printed,
    // A loop's printed outline closes on itself, as its editor draws it.
    trajectory: t && state.design?.trajectory?.closed ? [...t, t[0]] : t,
  };
  // Only an editor whose printed curve changed is drawn again.
  editors.forEach((e) => e.refresh());
}

function showTiming() {
  const rt = state.roundTrips[state.roundTrips.length - 1];
  const el = $('timing') || document.createElement('tr');
  el.id = 'timing';
  el.innerHTML = `<td>preview</td><td>${rt.ms.toFixed(0)} ms (server ${rt.server_ms.toFixed(0)} ms)</td>`;
  $('stats').appendChild(el);
}


function scheduleVerify(design, forSeq) {
  cancelVerify();
  state.verifyFor = forSeq;
  const seq = state.verifySeq;
  setVerdict('checking');
  state.verifyTimer = setTimeout(async () => {
    try {
      const r = await postDesign('/api/verify', design);
      const body = await r.json();
      if (seq !== state.verifySeq) return;
      setVerdict(r.ok ? body : { printable: false, failures: [body.error], locations: [] });
      // For the speed budget (docs/MODELER.md): last edit → its verdict.
      if (state.lastEditAt != null) state.verdictTimes.push(performance.now() - state.lastEditAt);
      if (state.verdictTimes.length > 100) state.verdictTimes.shift();
    } catch (e) {
      if (seq === state.verifySeq) setVerdict(null);
    }
  }, VERIFY_DELAY_MS);
}

// How long the page waits after a preview before it asks for the verdict:
// long enough that a drag does not check every step, short enough that
// the verdict follows the last edit within DESIGN's 250 ms
// (docs/MODELER.md).
const VERIFY_DELAY_MS = 60;






// ---------------------------------------------------------------- files


/**
 * The design's name as a file name: Unicode kept, only what no file
 * system takes (/ \ : * ? " < > |, control characters) replaced, and
 * dots and spaces at the ends dropped.
 */
function baseName() {
  const n = (state.design.name || '').replace(/[/\\:*?"<>|\u0000-\u001f]+/g, '_').replace(/^[\s.]+|[\s.]+$/g, '');
  return n || 'sweepclay';
}

async function downloadFrom(route, ext, button) {
  button.disabled = true;
  const label = button.textContent;
  button.textContent = 'working…';
  try {
    const r = await postDesign(route, JSON.stringify(state.design));
    if (!r.ok) {
      const body = await r.json();
      if (body.failures) setVerdict({ printable: false, failures: body.failures, locations: body.locations || [] });
      showError(`No ${ext.toUpperCase()} file: ${body.error}`, body.key);
      return;
    }
    download(await r.blob(), `${baseName()}.${ext}`);
  } catch (e) {
    showError(`the server did not answer: ${e.message || e}`);
  } finally {
    button.disabled = false;
    button.textContent = label;
  }
}

function readFile(input) {
  return new Promise((resolve, reject) => {
    const f = input.files[0];
    input.value = '';
    if (!f) return;
    const r = new FileReader();
    r.onload = () => resolve({ name: f.name, text: String(r.result) });
    r.onerror = () => reject(r.error);
    r.readAsText(f);
  });
}

$('save').addEventListener('click', () => {
  download(new Blob([JSON.stringify(state.design, null, 1) + '\n'], { type: 'application/json' }), `${baseName()}.json`);
});
$('open').addEventListener('click', () => $('open-file').click());
$('open-file').addEventListener('change', async () => {
  const file = $('open-file').files[0];
  if (file && /\.(stl|obj)$/i.test(file.name)) {
    $('open-file').value = '';
    openMesh(file);
    return;
  }
  const { name, text } = await readFile($('open-file'));
  let d;
  try {
    d = JSON.parse(text);
  } catch (e) {
    showError(`${name}: not JSON: ${e.message}`);
    return;
  }
  if (typeof d !== 'object' || !d || !d.profile_start || !d.trajectory) {
    showError(`${name}: not a sweepclay design (it needs profile_start and trajectory)`);
    return;
  }
  setDesign(d, { fit: true });
});
/**
 * A vessel mesh: the server cuts it into sections and fits it by a
 * design (docs/MESHES.md), which opens as any design does; the note
 * says how close the fit is, or the error why there is none.
 */
async function openMesh(file) {
  showNote(`${file.name}: cutting and fitting the mesh…`);
  let r;
  try {
    r = await fetch(`/api/mesh?name=${encodeURIComponent(file.name)}`, {
      method: 'POST', headers: { 'content-type': 'application/octet-stream' }, body: await file.arrayBuffer(),
    });
  } catch (e) {
    showError(`${file.name}: the server could not be reached (${e.message})`);
    return;
  }
  const body = await r.json();
  if (!r.ok) {
    $('status').querySelector('.note')?.remove();
    showError(`${file.name}: ${body.error}`);
    return;
  }
  setDesign(body.design, { fit: true });
  const kind = body.kind === 'shell' ? 'a wall with its thickness, fitted at its middle' : 'a solid, fitted at its outside';
  showNote(`${file.name}: ${body.triangles} triangles (${kind}), now an editable design within ${body.deviation_mm.toFixed(2)} mm of the mesh${body.note ? `; ${body.note}` : ''}`);
}

$('import').addEventListener('click', () => $('import-file').click());
$('import-file').addEventListener('change', async () => {
  const { name, text } = await readFile($('import-file'));
  const format = /\.svg$/i.test(name) || text.trimStart().startsWith('<') ? 'svg' : 'csv';
  const r = await fetch(`/api/import/${format}`, {
    method: 'POST', headers: { 'content-type': 'application/octet-stream' }, body: text,
  });
  const body = await r.json();
  if (!r.ok) {
    showError(`${name}: ${body.error}`);
    return;
  }
  openImport(name, body);
});

/**
 * Ramer–Douglas–Peucker: the fewest of `pts` that keep the polyline within
 * `tol` of itself (a loop is split at its farthest point first).
 */
function simplify(pts, tol, closed) {
  if (pts.length < 3) return pts.slice();
  const keep = new Uint8Array(pts.length);
  const run = (i, j) => {
    const stack = [[i, j]];
    while (stack.length) {
      const [a, b] = stack.pop();
      let far = -1;
      let fd = tol;
      for (let k = a + 1; k < b; k++) {
        const d = segDist(pts[a], pts[b % pts.length], pts[k]);
        if (d > fd) {
          fd = d;
          far = k;
        }
      }
      if (far >= 0) {
        keep[far] = 1;
        stack.push([a, far], [far, b]);
      }
    }
  };
  keep[0] = 1;
  if (closed) {
    // The point farthest from the first splits the loop in two.
    let far = 1;
    for (let k = 1; k < pts.length; k++) {
      if ((pts[k][0] - pts[0][0]) ** 2 + (pts[k][1] - pts[0][1]) ** 2 > (pts[far][0] - pts[0][0]) ** 2 + (pts[far][1] - pts[0][1]) ** 2) far = k;
    }
    keep[far] = 1;
    run(0, far);
    run(far, pts.length);
  } else {
    keep[pts.length - 1] = 1;
    run(0, pts.length - 1);
  }
  return pts.filter((_, k) => keep[k]);
}

/** Shows an import before it replaces the path: which shape, how dense. */
function openImport(name, body) {
  const shapes = body.shapes;
  const pick = $('im-pick');
  pick.innerHTML = '';
  shapes.forEach((sh, i) => {
    const o = document.createElement('option');
    o.value = i;
    o.textContent = `${i + 1}: ${sh.label} (${sh.points.length} points${sh.closed ? ', closed' : ''})`;
    pick.appendChild(o);
  });
  $('im-pick-row').hidden = shapes.length < 2;
  // Dense shapes become editable points by default: the picked one's
  // density decides, not the first's.
  const denseDefault = () => { $('im-simplify').checked = shapes[Number(pick.value) || 0].points.length > 150; };
  denseDefault();
  const chosen = () => {
    const sh = shapes[Number(pick.value) || 0];
    const tol = parseFloat($('im-tol').value);
    const pts = $('im-simplify').checked && tol > 0 ? simplify(sh.points, tol, sh.closed) : sh.points;
    return { sh, pts, tol };
  };
  const draw = () => {
    const { sh, pts, tol } = chosen();
    $('im-count').textContent = $('im-simplify').checked ? `${sh.points.length} → ${pts.length} points (within ${tol} mm)` : `${sh.points.length} points`;
    const left = (body.skipped || []).length ? ` ${body.skipped.join('; ')}.` : '';
    $('im-what').textContent = `${name}: ${shapes.length} shape${shapes.length > 1 ? 's' : ''}; the path is replaced only when you press “Use this path”.${left}`;
    drawImport($('im-preview'), sh.points, pts, sh.closed);
  };
  pick.onchange = () => { denseDefault(); draw(); };
  $('im-simplify').onchange = draw;
  $('im-tol').oninput = draw;
  draw();
  const dlg = $('import-dialog');
  dlg.onclose = () => {
    if (dlg.returnValue !== 'use') return;
    const { sh, pts } = chosen();
    useImport(name, { ...sh, points: pts });
  };
  dlg.returnValue = '';
  dlg.showModal();
}

/** The imported curve (grey) and the points that will be kept (blue). */
function drawImport(canvas, all, kept, closed) {
  const c = canvas.getContext('2d');
  const [w, h] = [canvas.width, canvas.height];
  c.clearRect(0, 0, w, h);
  const xs = all.map((p) => p[0]);
  const ys = all.map((p) => p[1]);
  const [x0, x1, y0, y1] = [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
  const k = Math.min((w - 20) / Math.max(1e-6, x1 - x0), (h - 20) / Math.max(1e-6, y1 - y0));
  const at = (p) => [10 + (p[0] - x0) * k + (w - 20 - (x1 - x0) * k) / 2, h - 10 - (p[1] - y0) * k - (h - 20 - (y1 - y0) * k) / 2];
  const line = (pts, colour, width) => {
    c.beginPath();
    pts.forEach((p, i) => (i ? c.lineTo(...at(p)) : c.moveTo(...at(p))));
    if (closed) c.closePath();
    c.strokeStyle = colour;
    c.lineWidth = width;
    c.stroke();
  };
  line(all, '#bbb', 4);
  line(kept, '#b5653a', 1.5);
  if (kept.length <= 400) {
    c.fillStyle = '#1d5fbf';
    for (const p of kept) {
      const [x, y] = at(p);
      c.fillRect(x - 2, y - 2, 4, 4);
    }
  }
}

function useImport(name, body) {
  edit((d) => {
    d.trajectory = body.closed ? { points: body.points, closed: true } : { points: body.points };
    if (body.offset === 'normal') d.trajectory.offset = 'normal';
    setClosed(d, body.closed);
  }, true);
  // The note of the last import, or none: an earlier import's stays no
  // longer.
  if (body.note) showNote(`${name}: ${body.note}`);
  else $('status').querySelector('.note')?.remove();
  editors[2].fitted = false;
  editors[2].fit();
  editors[2].refresh();
}

// ---------------------------------------------------------------- guide, printer, tabs

/**
 * Shows the guide; once shown it is seen: it opens by itself on the
 * first visit only (its close event is not relied on: a page closed
 * with the guide open would show it again, in every new tab).
 */
function showGuide() {
  const g = $('guide');
  if (!g.open) g.showModal();
  try {
    localStorage.setItem(GUIDE_SEEN, '1');
  } catch (e) {
    /* no storage: the guide comes back next time */
  }
}
$('guide-open').addEventListener('click', showGuide);

// Phones: one panel at a time, chosen by tabs.
for (const b of document.querySelectorAll('#tabs button')) {
  b.addEventListener('click', () => showTab(b.dataset.tab));
}
function showTab(tab) {
  document.body.dataset.tab = tab;
  for (const b of document.querySelectorAll('#tabs button')) b.setAttribute('aria-selected', String(b.dataset.tab === tab));
  // Canvases sized while hidden are redrawn at their real size.
  window.dispatchEvent(new Event('resize'));
  if (view) view.redraw();
  editors.forEach((ed) => ed.resize());
}
document.body.dataset.tab = 'editors';


/** Says how the print is going, beside the Send button. */
function sendStatus(text, bad) {
  const s = $('send-status');
  s.textContent = text;
  s.classList.toggle('bad-text', !!bad);
}

/**
 * Slices, checks and sends the design to its printer's print host and
 * starts it (the server sends exactly what "Download G-code" gives), then
 * follows the print until it ends.
 */
async function sendToPrinter(button) {
  const printer = currentPrinter(state.design);
  if (!printer || !printer.host) {
    sendStatus('No print host: set one in the printer dialog', true);
    openPrinter();
    return;
  }
  button.disabled = true;
  sendStatus('slicing, checking and sending…');
  try {
    const r = await postDesign('/api/send?start=true', JSON.stringify(state.design));
    const body = await r.json();
    if (!r.ok) {
      if (body.failures) setVerdict({ printable: false, failures: body.failures, locations: body.locations || [] });
      sendStatus(`Not sent: ${body.error}`, true);
      return;
    }
    sendStatus(`Sent ${body.file}; printing…`);
    state.sending = body;
    followPrint(printer.host, body.file, 0);
  } catch (e) {
    sendStatus(`the server did not answer: ${e.message || e}`, true);
  } finally {
    button.disabled = false;
  }
}

/** Polls the host every 2 s while the print runs (at most a day). */
async function followPrint(host, file, polls) {
  if (state.sending?.file !== file || polls > 43200) return;
  try {
    const r = await postDesign('/api/host/status', JSON.stringify(host));
    const s = await r.json();
    if (!r.ok) {
      sendStatus(s.error, true);
      return;
    }
    const pct = s.progress == null ? '' : ` ${Math.floor(s.progress * 100)} %`;
    if (s.printing) sendStatus(`Printing ${file}${pct} (${s.state})`);
    else if (polls > 2) {
      sendStatus(`${file}: ${s.state}${pct}`);
      state.sending = null;
      return;
    }
  } catch (e) {
    sendStatus(`lost the printer: ${e.message || e}`, true);
    return;
  }
  setTimeout(() => followPrint(host, file, polls + 1), 2000);
}

$('send-printer').addEventListener('click', (e) => sendToPrinter(e.currentTarget));

// On a phone the header's extras open under "More" and close once used.
$('more').addEventListener('click', () => {
  const open = document.querySelector('header').classList.toggle('open');
  $('more').setAttribute('aria-expanded', String(open));
});
for (const e of document.querySelectorAll('header .extra')) {
  e.addEventListener('click', (ev) => {
    if (ev.target.tagName === 'SELECT') return;
    document.querySelector('header').classList.remove('open');
    $('more').setAttribute('aria-expanded', 'false');
  });
}
$('download-gcode').addEventListener('click', (e) => downloadFrom('/api/gcode', 'gcode', e.currentTarget));
$('download-stl').addEventListener('click', (e) => downloadFrom('/api/stl', 'stl', e.currentTarget));
$('undo').addEventListener('click', undo);
$('redo').addEventListener('click', redo);
$('new').addEventListener('click', () => setDesign(clone(NEW_DESIGN), { fit: true }));
$('example').addEventListener('change', (e) => {
  const ex = state.meta.examples.find((x) => x.name === e.target.value);
  if (ex) setDesign(withMyPrinter(clone(ex.design)), { fit: true });
  e.target.value = '';
});
$('colour-by').addEventListener('change', (e) => {
  if (!view) return;
  view.colourBy = e.target.value;
  view.recolour();
  $('legend').innerHTML = view.legend();
});
$('true-width').addEventListener('change', (e) => { if (view) view.setTrueWidth(e.target.checked); });
$('show-surface').addEventListener('change', (e) => { if (view) { view.showSurface = e.target.checked; view.redraw(); } });
$('show-path').addEventListener('change', (e) => { if (view) { view.showPath = e.target.checked; view.redraw(); } });
$('fit-view').addEventListener('click', () => view && view.fit());

document.addEventListener('keydown', (e) => {
  if (e.target instanceof HTMLInputElement || e.target instanceof HTMLSelectElement) return;
  const mod = e.ctrlKey || e.metaKey;
  if (mod && e.key.toLowerCase() === 'z') {
    e.preventDefault();
    if (e.shiftKey) redo();
    else undo();
  } else if (mod && e.key.toLowerCase() === 'y') {
    e.preventDefault();
    redo();
  }
});

const NEW_DESIGN = {
  sweepclay: 1,
  name: 'new wall',
  profile_start: { control_points: [[0, 0], [4, 20], [0, 40]] },
  profile_end: { control_points: [[0, 0], [6, 25], [0, 50]] },
  trajectory: { control_points: [[-50, 20], [-20, 55], [20, 55], [50, 20]] },
  printer: 'cerambot-plus',
};

// ---------------------------------------------------------------- start

async function start() {
  const r = await fetch('/api/meta');
  state.meta = await r.json();
  // Pots first (one profile, typed as widths at heights), then the
  // paper's test pieces (t1–t6), then the other vessels and textures.
  const groups = [['Pots', []], ["The paper's walls (Table 1)", []], ['Vessels and textures', []]];
  for (const ex of state.meta.examples) {
    const o = document.createElement('option');
    o.value = ex.name;
    o.textContent = `${ex.name}: ${ex.design.name || ''}`;
    const k = /^t\d$/.test(ex.name) ? 1 : ex.design.profile_end || ex.design.texture ? 2 : 0;
    groups[k][1].push(o);
  }
  for (const [label, opts] of groups) {
    if (!opts.length) continue;
    const g = document.createElement('optgroup');
    g.label = label;
    g.append(...opts);
    $('example').appendChild(g);
  }
  buildParams();
  buildSurface();
  // ?example=t3 opens a bundled example; ?colour=pass|stage|width picks the
  // toolpath colouring; ?surface=0 / ?path=0 hide one of the two.
  const q = new URLSearchParams(location.search);
  if (q.get('colour') && view) {
    view.colourBy = q.get('colour');
    $('colour-by').value = q.get('colour');
  }
  for (const [key, box, prop] of [['surface', 'show-surface', 'showSurface'], ['path', 'show-path', 'showPath']]) {
    if (q.get(key) === '0' && view) {
      view[prop] = false;
      $(box).checked = false;
    }
  }
  const asked = state.meta.examples.find((x) => x.name === q.get('example'));
  let d = null;
  try {
    d = JSON.parse(localStorage.getItem(STORE));
    // This tab's own history first (a reload); a new tab starts from the
    // last one saved in any tab.
    const h = JSON.parse(sessionStorage.getItem(TAB_HISTORY) || localStorage.getItem(HISTORY));
    if (h && Array.isArray(h.history) && h.history.length && h.at >= 0 && h.at < h.history.length) {
      state.history = h.history;
      state.at = h.at;
      d = JSON.parse(h.history[h.at]);
    }
  } catch (e) {
    d = null;
  }
  // What was autosaved may not slice (a key mistyped in a file opened
  // last time): the first answer then offers a way out, and undo works.
  state.restored = !asked && !!(d && d.trajectory);
  if (asked) {
    d = clone(asked.design);
    // Opened once: a reload then keeps the edits made since (autosave),
    // not the example again.
    q.delete('example');
    history.replaceState(null, '', `${location.pathname}${q.size ? `?${q}` : ''}`);
  }
  const shown = d && d.trajectory ? d : clone(state.meta.examples[0].design);
  // The restored design is already the history's newest step.
  setDesign(shown, { fit: true, record: !(state.restored && state.history.length) });
  if (!localStorage.getItem(GUIDE_SEEN)) showGuide();
}

start().catch((e) => showError(`could not start: ${e.message || e}`));
