// The status line and the verdict (docs/MODELER.md): an error in the
// page's words beside the field it blames (and on a phone's Shape tab),
// a passing note, "slicing…", and the checker's verdict.

import { param } from './params.js';
import { clone, setDesign, state } from './store.js';

const $ = (id) => document.getElementById(id);

export function list(ul, items) {
  const said = JSON.stringify(items);
  if (ul.dataset.said === said) return;
  ul.dataset.said = said;
  ul.innerHTML = '';
  for (const t of items) {
    const li = document.createElement('li');
    li.textContent = t;
    ul.appendChild(li);
  }
}

export function setVerdict(v) {
  const el = $('verdict');
  // A drag asks for 'checking' every frame: the page is not touched again.
  if (v === 'checking' && el.dataset.state === 'checking') return;
  el.dataset.state = v === 'checking' ? 'checking' : '';
  el.className = '';
  if (v === null) {
    el.textContent = '— no verdict: the design does not slice';
  } else if (v === 'checking') {
    el.textContent = 'checking…';
  } else if (v.printable && v.reshaped) {
    // The corrections moved the shape beyond params.max_correction_mm:
    // printable, but not as drawn (docs/ALGORITHMS.md §4).
    el.className = 'warn';
    el.textContent = `⚠ printable, but reshaped: ${v.reshaped}`;
  } else if (v.printable) {
    el.className = 'ok';
    const ov = v.min_overlap != null ? `, smallest overlap ${(100 * v.min_overlap).toFixed(0)} %` : '';
    el.textContent = `✓ printable: one continuous path, no collision, every bead supported${ov}`;
  } else {
    el.className = 'bad';
    el.innerHTML = '✗ not printable<ul></ul>';
    list(el.querySelector('ul'), [...v.failures, ...(v.advice || []).map((a) => `change: ${a}`), ...v.locations]);
  }
  el.dataset.printable = v && v !== 'checking' ? String(!!v.printable) : '';
}

export function setBusy(on) {
  const s = $('status');
  if (on && !s.querySelector('.error') && !s.querySelector('.busy')) {
    s.insertAdjacentHTML('afterbegin', '<span class="busy">slicing…</span>');
  }
  if (!on) s.querySelector('.busy')?.remove();
}

/// A passing remark in the status line (not an error).
export function showNote(msg) {
  const s = $('status');
  s.querySelector('.note')?.remove();
  const div = document.createElement('div');
  div.className = 'note';
  div.textContent = msg;
  s.appendChild(div);
}

/**
 * A server message about a parameter in the page's words: `params.KEY:
 * must be between A and B (got V)` becomes "KEY's label must be between
 * A and B unit (it is V)".
 */
export function plainWords(msg) {
  const fit = /the design does not fit printer `([^`]+)`: (\w) spans (\S+)\.\.(\S+) mm but the build volume is (\S+)\.\.(\S+) mm/.exec(msg);
  if (fit) {
    const [, printer, axis, a, b, lo, hi] = fit;
    const over = Math.max(Number(lo) - Number(a), Number(b) - Number(hi));
    const word = { x: 'wide', y: 'deep', z: 'tall' }[axis];
    // What came before it ("No GCODE file: ") stays: it says what was refused.
    return `${msg.slice(0, fit.index)}${over.toFixed(1)} mm too ${word} for ${printer}: along ${axis} it spans ${Number(a).toFixed(1)} to ${Number(b).toFixed(1)} mm, the printer ${Number(lo).toFixed(1)} to ${Number(hi).toFixed(1)} mm (the part outside is violet in the 3D view)`;
  }
  const round = /the design does not fit printer `([^`]+)`: it reaches (\S+) mm from the bed's centre but the round bed is (\S+) mm across/.exec(msg);
  if (round) {
    const [, printer, reach, dia] = round;
    return `${msg.slice(0, round.index)}${(Number(reach) - Number(dia) / 2).toFixed(1)} mm past the edge of ${printer}'s round bed (${dia} mm across; the part outside is violet in the 3D view)`;
  }
  return msg.replace(/params\.(\w+): must be between (\S+) and (\S+) \(got ([^)]+)\)/, (all, k, a, b, v) => {
    const p = param(k);
    if (!p) return all;
    const f = (x) => (Number.isFinite(Number(x)) ? Number((Number(x) * p.factor).toFixed(4)) : x);
    return `${p.label} must be between ${f(a)} and ${f(b)} ${p.unit} (it is ${f(v)})`;
  }).replace(/params\.(\w+)/g, (all, k) => (param(k) ? param(k).label : all));
}

export function showError(msg, key) {
  const s = $('status');
  document.querySelectorAll('#params input.bad').forEach((i) => i.classList.remove('bad'));
  document.querySelectorAll('#params .field-error').forEach((p) => p.remove());
  $('side-error').textContent = '';
  $('shape-error').textContent = '';
  if (!msg) {
    s.querySelector('.error')?.remove();
    // A good slice: the next error is nobody's earlier change.
    state.lastParam = null;
    return;
  }
  s.innerHTML = '';
  const div = document.createElement('div');
  div.className = 'error';
  const m = /^params\.(\w+)/.exec(key || msg);
  // The field the user just changed is the one to blame, though the
  // range it broke is another's (a layer height above the max).
  const changed = state.lastParam;
  let text = plainWords(msg);
  let blamed = m && m[1];
  if (m && changed && changed !== m[1] && param(changed)) {
    const p = param(changed);
    const v = Number(((state.design.params || {})[changed] ?? 0) * p.factor);
    text = `${p.label} ${Number(v.toFixed(4))} ${p.unit}: ${text}`;
    blamed = changed;
  }
  div.textContent = text;
  if (state.restored) {
    // The design from last time does not slice: never a dead end.
    const out = document.createElement('div');
    out.className = 'way-out';
    out.append('This is the design from your last visit. ');
    const ex = document.createElement('button');
    ex.textContent = 'Open the first example instead';
    ex.id = 'escape-example';
    ex.addEventListener('click', () => setDesign(clone(state.meta.examples[0].design), { fit: true }));
    out.append(ex);
    if (state.at > 0) out.append(' or press Undo.');
    div.append(out);
  }
  s.appendChild(div);
  // On a phone's Shape tab too: the status line is on the 3D tab, and a
  // refused download would seem to do nothing (docs/MODELER.md).
  $('shape-error').textContent = text;
  // Beside the field too: on a phone the 3D panel with the status line is
  // hidden while the settings are shown (docs/MODELER.md).
  const field = blamed && $(`p-${blamed}`);
  if (field) {
    field.classList.add('bad');
    const p = document.createElement('p');
    p.className = 'field-error';
    p.id = `err-${blamed}`;
    p.textContent = text;
    field.closest('label').after(p);
  } else {
    $('side-error').textContent = text;
  }
}
