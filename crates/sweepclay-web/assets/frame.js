// One animation frame for the whole page (docs/MODELER.md, "Input that
// never lags"): input handlers only note what changed; the work runs
// here, once per frame, with the latest pointer position. Work queued
// while the frame runs joins the same frame, so an edit, the editors and
// the 3D view all show in one paint.

const jobs = new Map();
let asked = 0;

/** Runs `fn` in the next frame; a second call with the same `key` replaces the first. */
export function onFrame(key, fn) {
  jobs.set(key, fn);
  if (!asked) asked = requestAnimationFrame(flush);
}

let inFrame = false;
let lastFrame = 0;

/**
 * For the speed budget (docs/MODELER.md): each frame's own work and the
 * time since the previous one (ms), newest last.
 */
export const frameStats = { work: [], gap: [], input: [] };

/** Notes how long an input event waited before the page heard it (ms). */
export function noteInput(e) {
  frameStats.input.push(performance.now() - e.timeStamp);
  if (frameStats.input.length > 400) frameStats.input.shift();
}

function flush(t) {
  asked = 0;
  inFrame = true;
  const start = performance.now();
  if (lastFrame) frameStats.gap.push(t - lastFrame);
  lastFrame = t;
  // Jobs added by a job run in this same frame; a bound keeps a job that
  // queues itself from spinning.
  for (let round = 0; round < 8 && jobs.size; round++) {
    const now = [...jobs.values()];
    jobs.clear();
    for (const fn of now) {
      try {
        fn();
      } catch (e) {
        setTimeout(() => { throw e; });
      }
    }
  }
  inFrame = false;
  frameStats.work.push(performance.now() - start);
  for (const k of ['work', 'gap']) if (frameStats[k].length > 400) frameStats[k].shift();
}

const channel = new MessageChannel();
const painted = [];
channel.port1.onmessage = () => {
  const t = performance.now();
  for (const f of painted.splice(0)) f(t);
};

/**
 * Calls `fn(time)` once the frame that shows the latest change has been
 * painted: a message posted from a frame callback is handled after the
 * browser's rendering steps for that frame (from elsewhere, the next
 * frame is waited for first).
 */
export function afterPaint(fn) {
  painted.push(fn);
  if (painted.length > 1) return;
  if (inFrame) channel.port2.postMessage(0);
  else requestAnimationFrame(() => channel.port2.postMessage(0));
}
