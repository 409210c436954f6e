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

/**
 * `per` points a span along the periodic uniform cubic B-spline whose
 * control polygon wraps round (a closed trajectory: the same curve as
 * sweepclay-core's curves.rs `periodic_bspline`), closed by its first point.
 */
export function samplePeriodic(ctrl, per = 24) {
  const m = ctrl.length;
  if (m < 3) return ctrl.concat(ctrl.slice(0, 1));
  const out = [];
  for (let j = 0; j < m; j++) {
    const [p0, p1, p2, p3] = [0, 1, 2, 3].map((k) => ctrl[(j + k) % m]);
    for (let s = 0; s < per; s++) {
      const t = s / per;
      const b = [(1 - t) ** 3 / 6, (3 * t ** 3 - 6 * t * t + 4) / 6,
        (-3 * t ** 3 + 3 * t * t + 3 * t + 1) / 6, t ** 3 / 6];
      out.push([0, 1].map((a) => b[0] * p0[a] + b[1] * p1[a] + b[2] * p2[a] + b[3] * p3[a]));
    }
  }
  out.push(out[0]);
  return out;
}
