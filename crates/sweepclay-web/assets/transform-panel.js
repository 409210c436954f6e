// Size and turn (docs/MODELER.md, "Size and turn"): the whole design
// scaled and turned about o by the server (`Design::transformed`), so a
// mesh-backed design — its relief included — and any drawn one take the
// size and the side a potter wants; an undoable step.

import { setDesign, state } from './store.js';
import { fmtMm, parseDecimal } from './numbers.js';
import { postDesign } from './io.js';

const $ = (id) => document.getElementById(id);

/** A field's number within [lo, hi], or a message beside the fields. */
function field(id, what, lo, hi) {
  const inp = $(id);
  const v = parseDecimal(inp.value);
  if (!Number.isFinite(v) || v < lo || v > hi) {
    $('tf-error').textContent = `${what} "${inp.value}": must be a number from ${lo} to ${hi}`;
    inp.classList.add('bad');
    return null;
  }
  return v;
}

$('tf-apply').addEventListener('click', async () => {
  $('tf-error').textContent = '';
  for (const id of ['tf-scale', 'tf-turn']) $(id).classList.remove('bad');
  const scale = field('tf-scale', 'size (%)', 1, 10000);
  const turn = field('tf-turn', 'turn (°)', -360, 360);
  if (scale == null || turn == null || !state.design) return;
  if (scale === 100 && turn === 0) return;
  let r;
  try {
    r = await postDesign(`/api/transform?scale=${scale / 100}&turn=${turn}`, JSON.stringify(state.design));
  } catch (e) {
    $('tf-error').textContent = `the server did not answer: ${e.message || e}`;
    return;
  }
  const body = await r.json();
  if (!r.ok) {
    $('tf-error').textContent = body.error;
    return;
  }
  setDesign(body, { fit: true });
  $('tf-scale').value = fmtMm(100);
  $('tf-turn').value = fmtMm(0);
});
