// What a design's curves are, read and changed as plain data (no page):
// the points each editor shows, a vessel's default loop, a pot's widths at
// heights (docs/MODELER.md, "Widths at heights"), a new pot. The panels
// (editors-panel.js, pots-panel.js, files.js) change designs through these.

import { onCurve, sample, samplePeriodic, throughRows } from './bspline.js';

/** Least height between a profile's points, and a pot's rows (mm). */
export const MIN_DZ = 0.5;

/** A point written to 3 decimals, as the design file keeps it. */
export const mm3 = ([x, z]) => [+x.toFixed(3), +z.toFixed(3)];

/** The path's points as drawn: a polyline's, else its control points. */
export function trajectoryPoints(d) {
  return d.trajectory.points || d.trajectory.control_points;
}

/** The interpolation's control points, or the default's ends. */
export function interpolationPoints(d) {
  if (d.interpolation) return d.interpolation.control_points;
  // A vessel's default, (1 − cos 2πu)/2, is drawn as a curve (editors-panel.js).
  return d.trajectory.closed ? [[0, 0], [1, 0]] : [[0, 0], [1, 1]];
}

/** `d`'s printer as an object: inline, or the preset it names. */
export function printerOf(d, presets) {
  if (typeof d.printer === 'object' && d.printer) return d.printer;
  return presets?.find((p) => p.name === (d.printer || 'generic'));
}

/** Control points of a circle a quarter as wide as `d`'s printer bed (8 points, periodic). */
export function defaultLoop(d, presets) {
  const bed = printerOf(d, presets)?.build_volume || [200, 200, 200];
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
export function setClosed(d, closed, presets) {
  const ip = d.interpolation?.control_points;
  if (closed) {
    // An open wall's points wrapped round make a sliver: a new vessel
    // starts as a round pot a quarter of the printer's bed across.
    if (!d.trajectory.closed) d.trajectory = { control_points: defaultLoop(d, presets), closed: true };
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

/** The x-extent of the path seen from above (mm): a round pot's base diameter. */
export function baseWidth(d) {
  const t = d.trajectory;
  const pts = t.points || t.control_points;
  const path = t.closed ? (t.points ? pts : samplePeriodic(pts)) : t.points ? pts : sample(pts, 160);
  const xs = path.map((p) => p[0]);
  return Math.max(...xs) - Math.min(...xs);
}

/**
 * The widths table's rows: the points the profile passes through as the
 * potter typed them (the profile's `points`), or, for a profile drawn
 * without them, its own points one a control point (`onCurve`); each is
 * a height and a width across. Typed rows become the control points of a
 * curve through them (`throughRows`) and are kept as `points`, so the pot
 * is as wide as typed at each typed height.
 */
export function potRows(d) {
  const c = d.profile_start;
  return (c.points || onCurve(c.control_points)).map((p) => p.slice());
}

/** Sets the profile to the curve through `rows` (heights sorted). */
export function setPotRows(d, rows) {
  rows.sort((a, b) => a[1] - b[1]);
  d.profile_start = { control_points: throughRows(rows).map(mm3), points: rows.map(mm3) };
}

/**
 * A round pot a quarter as wide as the printer's bed, 60 % of its height
 * at most: one profile, a floor; on `printer`, with `params` kept.
 */
export function newPotDesign(printer, presets, params) {
  const d = {
    sweepclay: 1,
    name: 'new pot',
    profile_start: { control_points: [[0, 0], [8, 30], [10, 60], [4, 90]] },
    trajectory: { control_points: [], closed: true },
    printer,
  };
  d.trajectory.control_points = defaultLoop(d, presets);
  const zmax = printerOf(d, presets)?.build_volume?.[2] ?? 200;
  const k = Math.min(1, (0.6 * zmax) / 90);
  for (const p of d.profile_start.control_points) p[1] = +(p[1] * k).toFixed(2);
  if (params) d.params = { ...params };
  return d;
}
