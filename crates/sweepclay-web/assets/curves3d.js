// The edited curves in 3D, drawn over the 3D view while the pointer moves
// and while a slice is in flight (docs/MODELER.md): the path on the bed and
// the two profiles standing where the library stands them, offset the way
// the design says (docs/FORMATS.md). A browser test holds the profiles to
// the library's own transition curves (`the_3d_views_drawn_profiles_are_the_librarys`).

import { sample, samplePeriodic } from './bspline.js';

/** A profile's points; a pot's end profile is its start one (docs/FORMATS.md). */
export function profilePoints(d, key) {
  return (d[key] || d.profile_start).control_points;
}

/** The path seen from above as drawn: a polyline, closed by its first point round a loop. */
function pathOf(t) {
  const given = t.points || t.control_points;
  if (!given || given.length < 2) return null;
  if (t.closed) return t.points ? given.concat([given[0]]) : samplePeriodic(given);
  return t.points ? given : sample(given, 160);
}

/**
 * The start and end profiles in 3D, each a polyline of 81 points: the
 * start profile at the path's start, the end profile at its end (round a
 * loop, at its start too), each point moved from the path by the
 * profile's offset x along the frame there: away from o (radial), or to
 * the left of the path (normal), outward round a loop.
 */
export function profileLines(d) {
  const t = d.trajectory;
  const path = pathOf(t);
  if (!path) return [];
  const n = path.length;
  let area = 0;
  for (let i = 0; i + 1 < n; i++) area += path[i][0] * path[i + 1][1] - path[i + 1][0] * path[i][1];
  const outward = t.closed && area > 0 ? -1 : 1;
  const frame = (k) => {
    const p = path[k];
    if (t.offset === 'normal') {
      // The chord of the neighbours, as the library takes it: round a
      // loop the seam's neighbours are across it (the last point repeats
      // the first).
      const q = t.closed ? path[(k + 1) % (n - 1)] : path[Math.min(n - 1, k + 1)];
      const r = t.closed ? path[(k + n - 2) % (n - 1)] : path[Math.max(0, k - 1)];
      const [dx, dy] = [q[0] - r[0], q[1] - r[1]];
      const l = Math.hypot(dx, dy) || 1;
      return [p, [(-dy / l) * outward, (dx / l) * outward]];
    }
    const l = Math.hypot(p[0], p[1]) || 1;
    return [p, [p[0] / l, p[1] / l]];
  };
  return [['profile_start', 0], ['profile_end', t.closed ? 0 : n - 1]].map(([key, k]) => {
    const [p, dir] = frame(k);
    return sample(profilePoints(d, key), 80).map(([x, z]) => [p[0] + x * dir[0], p[1] + x * dir[1], z]);
  });
}

/** The path on the bed and the two profiles, as pairs of points (line segments). */
export function curveLines(d) {
  const path = pathOf(d.trajectory);
  if (!path) return [];
  const out = [];
  for (let i = 0; i + 1 < path.length; i++) out.push([path[i][0], path[i][1], 0], [path[i + 1][0], path[i + 1][1], 0]);
  for (const prof of profileLines(d)) {
    for (let i = 0; i + 1 < prof.length; i++) out.push(prof[i], prof[i + 1]);
  }
  return out;
}
