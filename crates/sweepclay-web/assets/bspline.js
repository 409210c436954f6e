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

/**
 * The parameters of a clamped B-spline with `n` control points at which it
 * passes through its rows (the Greville abscissae of its knots: one a
 * control point, the ends included; docs/MODELER.md, "Widths at heights").
 */
export function greville(n) {
  const p = Math.min(3, n - 1);
  const kv = knots(n, p);
  const out = [];
  for (let i = 0; i < n; i++) {
    let s = 0;
    for (let j = 1; j <= p; j++) s += kv[i + j];
    out.push(p > 0 ? s / p : 0);
  }
  return out;
}

/** The curve's points at [`greville`]: one on the curve for each control point. */
export function onCurve(ctrl) {
  const kv = knots(ctrl.length, Math.min(3, ctrl.length - 1));
  return greville(ctrl.length).map((t) => evalAt(ctrl, t, kv));
}

/**
 * The control points of the clamped B-spline that passes through `pts` at
 * [`greville`] (the inverse of [`onCurve`]): the basis matrix at those
 * parameters, solved by Gaussian elimination with partial pivoting. The
 * Schoenberg–Whitney condition holds there, so it is never singular.
 */
export function through(pts) {
  const n = pts.length;
  if (n < 3) return pts.map((p) => p.slice());
  const kv = knots(n, Math.min(3, n - 1));
  const ts = greville(n);
  // a[i][j]: basis j at t_i, read off the curve of the unit control points.
  // Each row: the basis at t_i (read off the curve of one unit control
  // point, only the p + 1 that can be non-zero there), then its point's x
  // and z, the right-hand sides.
  const p = Math.min(3, n - 1);
  const unit = Array.from({ length: n }, () => [0, 0]);
  const a = ts.map((t, i) => {
    const row = new Array(n).fill(0);
    let k = p;
    while (k + 1 < n && kv[k + 1] <= t) k++;
    for (let j = k - p; j <= k; j++) {
      unit[j][0] = 1;
      row[j] = evalAt(unit, t, kv)[0];
      unit[j][0] = 0;
    }
    return row.concat(pts[i]);
  });
  for (let c = 0; c < n; c++) {
    let best = c;
    for (let r = c + 1; r < n; r++) if (Math.abs(a[r][c]) > Math.abs(a[best][c])) best = r;
    [a[c], a[best]] = [a[best], a[c]];
    for (let r = 0; r < n; r++) {
      if (r === c || a[r][c] === 0) continue;
      const f = a[r][c] / a[c][c];
      for (let k = c; k < n + 2; k++) a[r][k] -= f * a[c][k];
    }
  }
  return a.map((row, i) => [row[n] / row[i], row[n + 1] / row[i]]);
}

/** The curve's x at height `z` (its z rising along it): the parameter
 * found by bisection, to a millionth of the curve. */
export function xAt(ctrl, z) {
  const kv = knots(ctrl.length, Math.min(3, ctrl.length - 1));
  let [lo, hi] = [0, 1];
  for (let i = 0; i < 40; i++) {
    const mid = (lo + hi) / 2;
    if (evalAt(ctrl, mid, kv)[1] < z) lo = mid;
    else hi = mid;
  }
  return evalAt(ctrl, (lo + hi) / 2, kv)[0];
}

/**
 * Control points of a profile through `rows` (`[x, z]`, heights rising):
 * the rows and, between them, points every `most` mm or closer on a cubic
 * Hermite curve through the rows (slopes from the neighbouring rows,
 * upright at the foot and the lip), all
 * passed through by [`through`]. Evenly spaced heights keep the curve's
 * height rising evenly with its parameter, so it bulges where the rows do
 * and nowhere else (docs/MODELER.md, "Widths at heights").
 */
export function throughRows(rows, most = 15) {
  const r = rows.map((p) => p.slice()).sort((a, b) => a[1] - b[1]);
  if (r.length <= 2) return r;
  // Points as evenly spaced in height as the rows allow: no further apart
  // than the closest two rows (from 2 to `most` mm), or the curve's height
  // stops rising evenly where a close pair meets a long gap.
  let gap = most;
  for (let k = 1; k < r.length; k++) gap = Math.min(gap, r[k][1] - r[k - 1][1]);
  const step = Math.max(2, gap);
  // The wall leaves the foot and meets the lip upright (slope 0 there), so
  // the floor, laid under the first turn, is as wide as the foot typed.
  const slope = r.map((p, k) => {
    if (k === 0 || k === r.length - 1) return 0;
    const [a, b] = [r[k - 1], r[k + 1]];
    return (b[0] - a[0]) / (b[1] - a[1]);
  });
  const pts = [r[0]];
  const last = r.length - 2;
  for (let k = 0; k + 1 < r.length; k++) {
    const [[x0, z0], [x1, z1]] = [r[k], r[k + 1]];
    const h = z1 - z0;
    const n = Math.max(1, Math.round(h / step));
    // A third of the way into the first and last segments, one more point
    // holds the curve upright at the foot and the lip.
    const at = Array.from({ length: n - 1 }, (_, j) => (j + 1) / n);
    if (k === 0) at.unshift(1 / (3 * n));
    if (k === last) at.push(1 - 1 / (3 * n));
    for (const s of at) {
      const [h00, h10, h01, h11] = [2 * s ** 3 - 3 * s ** 2 + 1, s ** 3 - 2 * s ** 2 + s, -2 * s ** 3 + 3 * s ** 2, s ** 3 - s ** 2];
      pts.push([h00 * x0 + h10 * h * slope[k] + h01 * x1 + h11 * h * slope[k + 1], z0 + s * h]);
    }
    pts.push(r[k + 1]);
  }
  return through(pts);
}

/**
 * `rows` moved onto the curve of `ctrl` at their heights (after the curve
 * was dragged or scaled): the base and the top follow the curve's ends,
 * rows above its top are dropped.
 */
export function rowsOnCurve(ctrl, rows) {
  const top = ctrl[ctrl.length - 1][1];
  const inner = rows.filter(([, z]) => z > 1e-6 && z < top - 1e-6).map(([, z]) => [xAt(ctrl, z), z]);
  return [ctrl[0].slice(), ...inner, ctrl[ctrl.length - 1].slice()];
}
