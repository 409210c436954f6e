// Clamped uniform B-splines of degree min(3, n − 1), evaluated by de Boor's
// algorithm: the same curves as sweepclay-core's bspline.rs, so what the
// editors draw is what the pipeline samples.

function knots(n, p) {
  const interior = n - p - 1;
  const k = [];
  for (let i = 0; i <= p; i++) k.push(0);
  for (let j = 1; j <= interior; j++) k.push(j / (interior + 1));
  for (let i = 0; i <= p; i++) k.push(1);
  return k;
}

/** The point at t ∈ [0, 1] of the clamped B-spline with control points `ctrl`. */
export function evalAt(ctrl, t, kv = knots(ctrl.length, Math.min(3, ctrl.length - 1))) {
  const n = ctrl.length;
  const p = Math.min(3, n - 1);
  t = Math.min(1, Math.max(0, t));
  let k = p;
  while (k + 1 < n && kv[k + 1] <= t) k++;
  const d = [];
  for (let j = 0; j <= p; j++) d.push(ctrl[j + k - p].slice());
  for (let r = 1; r <= p; r++) {
    for (let j = p; j >= r; j--) {
      const i = j + k - p;
      const den = kv[i + p - r + 1] - kv[i];
      const a = den > 0 ? (t - kv[i]) / den : 0;
      d[j] = [(1 - a) * d[j - 1][0] + a * d[j][0], (1 - a) * d[j - 1][1] + a * d[j][1]];
    }
  }
  return d[p];
}

/** `count` + 1 points along the curve, ends included. */
export function sample(ctrl, count = 200) {
  if (ctrl.length < 2) return ctrl.slice();
  const kv = knots(ctrl.length, Math.min(3, ctrl.length - 1));
  const out = [];
  for (let i = 0; i <= count; i++) out.push(evalAt(ctrl, i / count, kv));
  return out;
}
