// The four curve editors (docs/MODELER.md): the side profiles, the path
// seen from above and the interpolation, each drawing its part of the
// design and changing it through the store; the point bar that types a
// selected point's coordinates; the loop and offset switches. Subscribed
// to the store: a new design re-frames and redraws them.

import { CurveEditor, fmt } from './editor.js';
import { rowsOnCurve, sample, samplePeriodic } from './bspline.js';
import { profilePoints } from './curves3d.js';
import { edit, state, subscribe } from './store.js';
import { parseDecimal } from './numbers.js';
import { MIN_DZ, interpolationPoints, mm3, setClosed, trajectoryPoints } from './shapes.js';

const $ = (id) => document.getElementById(id);


const curve = (pts) => (pts.length >= 2 ? sample(pts, 160) : pts);

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

export const editors = [
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
$('closed').addEventListener('change', (e) => edit((d) => setClosed(d, e.target.checked, state.meta?.presets), true));
$('offset').addEventListener('change', (e) => edit((d) => {
  if (e.target.value === 'normal') d.trajectory.offset = 'normal';
  else delete d.trajectory.offset;
}, true));

// A new design everywhere in the editors: another design (opened, an
// example, a new pot) is framed afresh, and no refusal of a value typed
// for the last one stays beside the point bar.
subscribe((d, { fit }) => {
  if (fit) $('pb-error').textContent = '';
  for (const ed of editors) {
    if (fit) ed.fitted = false;
    if (fit) ed.fit();
    ed.refresh();
  }
  $('offset').value = d.trajectory.offset === 'normal' ? 'normal' : 'radial';
  $('closed').checked = !!d.trajectory.closed;
});
