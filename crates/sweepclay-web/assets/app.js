// The modeler page: the design (docs/FORMATS.md) is the one state
// (store.js); the panels change it, every change is recorded for undo,
// saved to the browser, and sliced once by the server; the preview, the
// statistics and the checker's verdict follow. Here: the slicing, the
// preview, the guide, phone tabs and sending to a printer; each panel is
// its own module (docs/ARCHITECTURE.md, "The page").

import { View3D } from './view3d.js';
import { afterPaint, frameStats, onFrame } from './frame.js';
import { fetchSlice } from './mesh.js';
import { curveLines } from './curves3d.js';
import { HISTORY, STORE, TAB_HISTORY, clone, redo, setDesign, state, subscribe, undo } from './store.js';
import { postDesign } from './io.js';
import { buildSurface } from './surface-panel.js';
import { buildParams } from './params-panel.js';
import { list, plainWords, setBusy, setVerdict, showError, showNote } from './status.js';
import { fmtMm } from './numbers.js';
import { currentPrinter, fillPrinterOptions, keptPrinters, openPrinter, withMyPrinter } from './printer-dialog.js';
import { editors } from './editors-panel.js';
import { showRimMost } from './pots-panel.js';
import { downloadFrom } from './files.js';
import './transform-panel.js';

const $ = (id) => document.getElementById(id);
const GUIDE_SEEN = 'sweepclay.guide.v1';

// For tests and the curious: the last round trips (edit → preview drawn), ms.
window.sweepclay = state;
state.frames = frameStats;
window.sweepclayErrors = [];
window.addEventListener('error', (e) => window.sweepclayErrors.push(String(e.message)));
window.addEventListener('unhandledrejection', (e) => window.sweepclayErrors.push(String(e.reason)));

// ---------------------------------------------------------------- design

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
  setVerdict('checking');
  clearTimeout(state.restTimer);
  // A rest is a pause three times as long as the moves' own gaps, at
  // least REST_MS: on a busy machine a drag's moves reach the page
  // 100 ms and more apart, and a fixed 100 ms took each gap for a rest,
  // slicing 15 to 45 times a drag while the server and the worker took
  // the core the page needed (docs/MODELER.md, "Speed budget").
  const now = performance.now();
  const gap = now - state.lastMove;
  state.lastMove = now;
  if (gap < 1000) state.moveGap = 0.7 * state.moveGap + 0.3 * gap;
  state.restTimer = setTimeout(() => requestSlice(false, { rest: true }), Math.max(REST_MS, 3 * state.moveGap));
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
 * A new design, after the panels have shown it (each subscribed in its
 * module): the undo buttons; then it is sliced, or for a drag's move its
 * curves are drawn and it is sliced when the pointer rests
 * (docs/MODELER.md, "The curve follows the finger").
 */
subscribe((d, { fit, live }) => {
  updateUndo();
  if (live) sliceAtRest();
  else requestSlice(fit);
});


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
  setVerdict('checking');
  if (!state.inFlight) sendSlice();
}

/** The design did not slice: the error, no verdict, the old preview greyed. */
function sliceFailed(msg, key) {
  setSettling(false);
  showError(msg, key);
  showPrinted({});
  setVerdict(null);
  setStale(true);
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
  // The preview carries its verdict: one edit, one plan (docs/MODELER.md).
  if (current && body.verdict) {
    setVerdict(body.verdict);
    showRimMost(body.verdict);
    // For the speed budget (docs/MODELER.md): last edit → its verdict.
    if (state.lastEditAt != null) state.verdictTimes.push(performance.now() - state.lastEditAt);
    if (state.verdictTimes.length > 100) state.verdictTimes.shift();
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
  // Ask first, with what the print takes (docs/PRINTING.md).
  const st = state.view?.data?.stats;
  $('send-what').textContent = `${state.design.name || 'This design'} to ${printer.host.kind} at ${printer.host.url}` +
    (st ? `: about ${Math.round(st.time_min)} min and ${st.volume_ml.toFixed(0)} ml of clay.` : '.') +
    ' It starts as soon as it arrives.';
  const d = $('send-confirm');
  const go = await new Promise((done) => {
    d.addEventListener('close', () => done(d.returnValue === 'go'), { once: true });
    d.returnValue = '';
    d.showModal();
  });
  if (!go) {
    sendStatus('not sent');
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
    showJob(s);
    const pct = s.progress == null ? '' : ` ${Math.floor(s.progress * 100)} %`;
    if (s.printing) sendStatus(`${/paus/i.test(s.state) ? 'Paused' : 'Printing'} ${file}${pct} (${s.state})`);
    else if (polls > 2) {
      // The job ended: done, or stopped before its end.
      sendStatus(s.progress === 1 ? `${file}: done` : `${file}: stopped (${s.state}${pct})`);
      state.sending = null;
      showJob(null);
      return;
    }
  } catch (e) {
    sendStatus(`lost the printer: ${e.message || e}`, true);
    return;
  }
  setTimeout(() => followPrint(host, file, polls + 1), 2000);
}

$('send-printer').addEventListener('click', (e) => sendToPrinter(e.currentTarget));

/** The pause, resume and cancel buttons, for the print a status shows. */
function showJob(s) {
  $('send-job').hidden = !s || !s.printing;
  if (!s) return;
  // Pausing or resuming: neither until the printer has done it.
  const paused = /^paused$/i.test(s.state);
  const moving = /ing$/i.test(s.state) && !/^printing$/i.test(s.state);
  $('job-pause').hidden = paused || moving;
  $('job-resume').hidden = !paused;
}

/** Pauses, resumes or cancels the print being followed. */
async function job(action) {
  const printer = currentPrinter(state.design);
  if (!printer?.host) return;
  if (action === 'cancel' && !window.confirm('Cancel the print for good?')) return;
  const r = await postDesign('/api/host/job', JSON.stringify({ host: printer.host, action }));
  const s = await r.json();
  if (!r.ok) {
    sendStatus(s.error, true);
    return;
  }
  showJob(s);
  sendStatus(`${action === 'pause' ? 'Pausing' : action === 'resume' ? 'Resuming' : 'Cancelling'}… (${s.state})`);
}
$('job-pause').addEventListener('click', () => job('pause'));
$('job-resume').addEventListener('click', () => job('resume'));
$('job-cancel').addEventListener('click', () => job('cancel'));

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
