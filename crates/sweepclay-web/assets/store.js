// The modeler's store (docs/MODELER.md): the design is the one state.
// Every change goes through `setDesign` (or `edit`, which records it as an
// undo step when a gesture ends), is kept in the browser a moment later,
// and is handed to the subscribers, which show it and slice it.

import { afterPaint } from './frame.js';

export const STORE = 'sweepclay.design.v1';
// The undo history, kept across reloads (newest 60 steps, so it stays well
// inside the browser's few megabytes of storage).
export const HISTORY = 'sweepclay.history.v1';
export const KEPT_STEPS = 60;
// This tab's own history (a second tab keeps its own; docs/MODELER.md).
export const TAB_HISTORY = 'sweepclay.tab-history.v1';

/** Everything the page knows besides the DOM; `window.sweepclay` for tests. */
export const state = {
  /** The print just sent to the printer's host and being followed: { file, kind, url }. */
  sending: null,
  // The curves as printed where the corrections moved them (showPrinted).
  printed: {},
  meta: null,
  design: null,
  history: [],
  at: -1,
  inFlight: false,
  pending: null,
  // Slices sent to the server (a drag sends one when it rests or ends).
  sent: 0,
  settling: false,
  restTimer: 0,
  // When the last drag move came, and the moves' mean gap (ms): a rest
  // is a pause longer than the moves' own gaps.
  lastMove: 0,
  moveGap: 16,
  lastEdit: null,
  roundTrips: [],
  // Pointer event → the painted frame with the edited curve (ms).
  editTimes: [],
  verdictTimes: [],
  // Each design sent to slice is numbered: an answer for an older one
  // never sets the verdict (docs/MODELER.md).
  seq: 0,
  sliced: null,
  // The point the point bar shows (its editor is `activeEditor`).
  barPoint: -1,
  activeEditor: null,
  // The curve editors (editors-panel.js) and the 3D view (app.js).
  editors: [],
  view: null,
  // Frame timing (frame.js), for the speed budget's tests.
  frames: null,
  // When the last edit was made (ms), and its verdict's times after it.
  lastEditAt: null,
  // The parameter typed last: an error about it is shown beside it.
  lastParam: null,
  // The design was restored from the browser, not opened or asked for.
  restored: false,
  // The printer the dialog started from (printer-dialog.js).
  printerBase: null,
  // What the pots table and the statistics last drew (none redrawn alike).
  potLook: null,
  statsHtml: null,
  // The 3D view was framed on a design once.
  fittedOnce: false,
  // The design waits to be kept in the browser's storage (saveSoon).
  unsaved: false,
  saveTimer: 0,
};

const listeners = [];


/** Calls `fn(design, { fit, live })` on every new design. */
export function subscribe(fn) {
  listeners.push(fn);
}

export function clone(d) {
  return JSON.parse(JSON.stringify(d));
}

/**
 * Replaces the design; `record` adds an undo step; `fit` frames the
 * editors on it (another design opened); `live` is a move of a drag
 * (docs/MODELER.md, "The curve follows the finger").
 */
export function setDesign(d, { record = true, fit = false, live = false } = {}) {
  state.design = d;
  if (record) {
    state.history = state.history.slice(0, state.at + 1);
    state.history.push(JSON.stringify(d));
    if (state.history.length > 200) state.history.shift();
    state.at = state.history.length - 1;
  }
  saveSoon();
  for (const fn of listeners) fn(d, { fit, live });
}

/**
 * Keeps the design and its history in the browser, a moment after the
 * last change: a drag's moves never wait for storage.
 */
function saveSoon() {
  clearTimeout(state.saveTimer);
  state.unsaved = true;
  state.saveTimer = setTimeout(saveNow, 300);
}

function saveNow() {
  clearTimeout(state.saveTimer);
  if (!state.design || !state.unsaved) return;
  state.unsaved = false;
  try {
    localStorage.setItem(STORE, JSON.stringify(state.design));
  } catch (e) {
    return; // private mode or full: no autosave
  }
  // A large design (a mesh's relief: a few hundred kilobytes a step)
  // keeps fewer undo steps rather than none.
  for (const steps of [KEPT_STEPS, 8, 1]) {
    const kept = state.history.slice(-steps);
    const at = Math.max(0, state.at - (state.history.length - kept.length));
    const h = JSON.stringify({ history: kept, at });
    try {
      localStorage.setItem(HISTORY, h);
      sessionStorage.setItem(TAB_HISTORY, h);
      return;
    } catch (e) {
      /* too large for the browser's storage: fewer steps */
    }
  }
}

window.addEventListener('pagehide', saveNow);

/**
 * Changes the design; `final` ends a gesture (an undo step); `since` is
 * the input event's own time (its `timeStamp`), from which the speed
 * budget counts (docs/MODELER.md).
 */
export function edit(mutate, final, since) {
  state.restored = false;
  const d = clone(state.design);
  // A parameter's own change sets it again just after this.
  state.lastParam = null;
  mutate(d);
  const t = since ?? performance.now();
  // A slice counts from the edit that starts it: a drag's release, or the
  // move the pointer rested after (docs/MODELER.md); moves it never
  // sliced are not its wait.
  state.lastEdit = t;
  state.lastEditAt = performance.now();
  setDesign(d, { record: final, live: !final });
  // From the event to the painted frame that shows the edited curve.
  if (since != null) {
    afterPaint((now) => {
      state.editTimes.push(now - since);
      if (state.editTimes.length > 400) state.editTimes.shift();
    });
  }
}

export function undo() {
  if (state.at <= 0) return;
  state.at--;
  setDesign(JSON.parse(state.history[state.at]), { record: false });
}

export function redo() {
  if (state.at >= state.history.length - 1) return;
  state.at++;
  setDesign(JSON.parse(state.history[state.at]), { record: false });
}
