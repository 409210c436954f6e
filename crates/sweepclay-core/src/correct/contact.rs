//! Where the surface meets itself (paper §4, "Self-intersection detection
//! and treatment"; docs/ALGORITHMS.md §4): folds at tight bends, samples
//! of curves far apart along Ψ closer than a bead (plain and twisted),
//! and the pass length that tells contact from a converging surface.

use crate::grid::Grid2;
use crate::surface::Surface;

/// The first pair of surface points from transition curves far apart along
/// Ψ that are closer than the widest bead: `(curve a, curve b, position)`.
///
/// Every sample of a transition curve lies on one radial segment in plan
/// (p_i + ξ·d_i over the curve's range of ξ), and two points are at least
/// as far apart in 3D as in plan. So a grid of those segments first finds
/// the pairs of curves, far apart along Ψ, whose segments come within
/// w_max in plan; only their samples are compared, each with the samples
/// of the other curve within w_max in height (both curves are sorted by
/// height). A surface that does not meet itself has no such pairs: the
/// cost is one segment query per curve, whatever the sampling density.
pub(super) fn find_self_intersection(s: &Surface) -> Option<(u32, u32, [f64; 3])> {
    if let Some(fold) = find_fold(s) {
        return Some(fold);
    }
    let w = s.params.width_max;
    // A U-turn of radius w/2 is the tightest curve whose sides do not touch:
    // its opposite points are π·w/2 ≈ 1.57 w apart along Ψ. Sides nearer
    // than 2 w along Ψ (a sharp corner's) are laid in one go, as fresh clay
    // the nozzle rides on (the checker counts them so too).
    let far = ((2.0 * w) / s.spacing).ceil() as usize;
    if s.columns.iter().any(|c| c.twist != 0.0) {
        return find_twisted_contact(s, w, far);
    }
    let segs: Vec<[[f64; 2]; 2]> = s
        .columns
        .iter()
        .map(|col| {
            let (lo, hi) = s.samples[col.samples()]
                .iter()
                .fold((f64::MAX, f64::MIN), |(lo, hi), smp| {
                    (lo.min(smp.xi), hi.max(smp.xi))
                });
            let a = col.point(lo, 0.0);
            let b = col.point(hi, 0.0);
            [[a[0], a[1]], [b[0], b[1]]]
        })
        .collect();
    let mut grid = Grid2::new(w.max(s.spacing));
    for (c, seg) in segs.iter().enumerate() {
        grid.insert_segment(seg[0], seg[1], c as u32);
    }
    let w2 = w * w;
    let mut near: Vec<u32> = Vec::new();
    for (a, seg) in segs.iter().enumerate() {
        near.clear();
        let n = segs.len();
        let closed = s.vessel.is_some();
        grid.for_each_near_segment(seg[0], seg[1], w, |b| {
            // Round a loop, the last curves are the first ones' neighbours.
            let apart = (b as usize) > a + far && (!closed || a + n - b as usize > far);
            if apart && segment_distance(*seg, segs[b as usize]) < w {
                near.push(b);
            }
        });
        near.sort_unstable();
        near.dedup();
        for &b in &near {
            let (ca, cb) = (&s.columns[a], &s.columns[b as usize]);
            let rb = cb.samples();
            let mut start = rb.start;
            let sb = segs[b as usize];
            for i in ca.samples() {
                let p = s.position(a, i);
                // All of b lies on its plan segment: a sample of a farther
                // than a bead from it in plan is farther in 3D.
                if point_segment2([p[0], p[1]], sb) >= w2 {
                    continue;
                }
                while start < rb.end && s.samples[start].z < p[2] - w {
                    start += 1;
                }
                for j in start..rb.end {
                    if s.samples[j].z > p[2] + w {
                        break;
                    }
                    let q = s.position(b as usize, j);
                    let d2 = (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2);
                    // Real contact: not two points of a surface that merely
                    // converges, whose pass between them at that height is
                    // short (an inward-leaning cone's top is small, but its
                    // neighbours are still neighbours).
                    if d2 < w2 && pass_apart(s, a, b as usize, i - ca.first as usize, w) {
                        return Some((a as u32, b, p));
                    }
                }
            }
        }
    }
    None
}

/// [`find_self_intersection`] for a twisted surface, whose curves turn as
/// they rise and so lie on no one plan segment: every sample goes into a
/// grid of cells a bead wide in plan and a layer high, and each is
/// compared with the samples of curves far along Ψ in its own and the
/// neighbouring cells. Only samples within a layer of each other in
/// height count: a twisted wall leans along itself, and points of it a
/// layer or more apart are the wall rising, not meeting itself. Linear in
/// the samples.
fn find_twisted_contact(s: &Surface, w: f64, far: usize) -> Option<(u32, u32, [f64; 3])> {
    let dz = s.params.max_layer_height;
    let n = s.columns.len();
    let closed = s.vessel.is_some();
    let key = |p: [f64; 3]| {
        (
            (p[0] / w).floor() as i64,
            (p[1] / w).floor() as i64,
            (p[2] / dz).floor() as i64,
        )
    };
    // Every sample's position once (a twisted one costs a sine), then
    // the samples sorted by cell, and each cell's range of them.
    let mut at = vec![[0.0; 3]; s.samples.len()];
    let mut by_cell: Vec<((i64, i64, i64), u32, u32)> = Vec::with_capacity(s.samples.len());
    for (c, col) in s.columns.iter().enumerate() {
        for i in col.samples() {
            at[i] = s.position(c, i);
            by_cell.push((key(at[i]), c as u32, i as u32));
        }
    }
    by_cell.sort_unstable_by_key(|e| e.0);
    let mut cells: rustc_hash::FxHashMap<(i64, i64, i64), (usize, usize)> =
        rustc_hash::FxHashMap::default();
    let mut start = 0;
    for k in 1..=by_cell.len() {
        if k == by_cell.len() || by_cell[k].0 != by_cell[start].0 {
            cells.insert(by_cell[start].0, (start, k));
            start = k;
        }
    }
    let w2 = w * w;
    for (a, col) in s.columns.iter().enumerate() {
        for i in col.samples() {
            let p = at[i];
            let (kx, ky, kz) = key(p);
            for k in [
                (-1i64, -1i64),
                (-1, 0),
                (-1, 1),
                (0, -1),
                (0, 0),
                (0, 1),
                (1, -1),
                (1, 0),
                (1, 1),
            ]
            .iter()
            .flat_map(|&(x, y)| (-1..=1).map(move |z| (kx + x, ky + y, kz + z)))
            {
                let Some(&(from, to)) = cells.get(&k) else {
                    continue;
                };
                for &(_, b, j) in &by_cell[from..to] {
                    let b = b as usize;
                    let apart = b > a + far && (!closed || a + n - b > far);
                    if !apart {
                        continue;
                    }
                    if (at[j as usize][2] - p[2]).abs() >= 0.5 * dz {
                        continue;
                    }
                    let q = at_height(s, b, j as usize, p[2]);
                    let d2 = (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2);
                    if d2 < w2 && pass_apart(s, a, b, i - col.first as usize, w) {
                        return Some((a as u32, b as u32, p));
                    }
                }
            }
        }
    }
    None
}

/// The point of column `c` at height `z`, between its sample `j` and
/// the neighbour on `z`'s side (or at the column's end). A twisted wall
/// turns as it rises, so two samples a part of a layer apart in height
/// sit turned apart too: a round vase twisted 720° over 97 mm turns 9°
/// a layer, and a sample of its neck 1.2 mm higher and 24° along came
/// within a bead of another, though the wall there is one round sheet.
/// Compared at one height, only a wall that meets itself is near.
fn at_height(s: &Surface, c: usize, j: usize, z: f64) -> [f64; 3] {
    let range = s.columns[c].samples();
    let zj = s.samples[j].z;
    let k = if z >= zj { j + 1 } else { j.wrapping_sub(1) };
    if !range.contains(&k) || (s.samples[k].z - zj).abs() < 1e-9 {
        return s.position(c, j);
    }
    let (a, b) = (s.samples[j], s.samples[k]);
    let t = ((z - a.z) / (b.z - a.z)).clamp(0.0, 1.0);
    s.columns[c].point(a.xi + t * (b.xi - a.xi), a.z + t * (b.z - a.z))
}

/// Whether two points of columns `a` and `b` closer than a bead (`w`) are
/// apart along the pass that lays sample `k` of column `a` (its pass
/// k + 1): more than 1.6 w of that pass between them (the U-turn of
/// radius w/2, the tightest whose sides do not touch, is π w/2 long), or
/// a pass that turns back on itself between them (a curl tighter than a
/// bead, whose sides touch however short it is). The same pass's samples
/// of the columns between are used (a column with fewer passes
/// contributes its top).
pub(super) fn pass_apart(s: &Surface, a: usize, b: usize, k: usize, w: f64) -> bool {
    let apart = |(len, turn): (f64, f64)| len > 1.6 * w || turn >= std::f64::consts::PI;
    let n = s.columns.len();
    // Round a loop the pass joins them both ways.
    apart(pass_length(s, a..=b, k))
        && (s.vessel.is_none() || apart(pass_length(s, (b..=a + n).map(|c| c % n), k)))
}

/// Plan length and net turning (radians, signed turns summed, so jitter
/// cancels and a curl counts its whole turn) of the pass that lays sample
/// `k` of the first column of `cols`, through the others in order (see
/// [`pass_apart`]).
fn pass_length(s: &Surface, cols: impl IntoIterator<Item = usize>, k: usize) -> (f64, f64) {
    let at = |c: usize| {
        let col = &s.columns[c];
        let i = col.first as usize + k.min(col.len().saturating_sub(1));
        s.position(c, i)
    };
    let (mut len, mut turn) = (0.0, 0.0);
    let mut cols = cols.into_iter();
    let Some(a) = cols.next() else {
        return (0.0, 0.0);
    };
    let mut prev = at(a);
    let mut heading: Option<f64> = None;
    for c in cols {
        let p = at(c);
        let (dx, dy) = (p[0] - prev[0], p[1] - prev[1]);
        let l = dx.hypot(dy);
        // Steps under 0.01 mm have no direction worth the name.
        if l > 0.01 {
            let h = dy.atan2(dx);
            if let Some(h0) = heading {
                let mut d = h - h0;
                while d > std::f64::consts::PI {
                    d -= std::f64::consts::TAU;
                }
                while d < -std::f64::consts::PI {
                    d += std::f64::consts::TAU;
                }
                turn += d;
            }
            heading = Some(h);
        }
        len += l;
        prev = p;
    }
    (len, turn.abs())
}

/// Where an offset larger than a bend's radius on its inner side folds the
/// surface (a normal offset at a tight bend, a radial one past `o`): two
/// neighbouring transition curves whose points at the same offset follow
/// each other against the direction of Ψ. Checked at each curve's
/// extreme offsets, where a fold starts; one test a curve.
pub(super) fn find_fold(s: &Surface) -> Option<(u32, u32, [f64; 3])> {
    let n = s.columns.len();
    // A loop's last curve is followed by its first.
    let pairs = n - usize::from(s.vessel.is_none());
    for a in 0..pairs {
        let w = [&s.columns[a], &s.columns[(a + 1) % n]];
        let step = [w[1].p[0] - w[0].p[0], w[1].p[1] - w[0].p[1]];
        for smp in [
            s.samples[w[0].samples().start],
            s.samples[w[0].samples().end - 1],
        ]
        .into_iter()
        .chain(
            s.samples[w[0].samples()]
                .iter()
                .copied()
                .min_by(|x, y| x.xi.total_cmp(&y.xi)),
        )
        .chain(
            s.samples[w[0].samples()]
                .iter()
                .copied()
                .max_by(|x, y| x.xi.total_cmp(&y.xi)),
        ) {
            let (p, q) = (w[0].point(smp.xi, smp.z), w[1].point(smp.xi, smp.z));
            // A twisted layer is turned whole: Ψ's step turns with it.
            let (sn, cs) = w[0].turn(smp.z).sin_cos();
            let along = [cs * step[0] - sn * step[1], sn * step[0] + cs * step[1]];
            if (q[0] - p[0]) * along[0] + (q[1] - p[1]) * along[1] <= 0.0 {
                return Some((a as u32, ((a + 1) % n) as u32, p));
            }
        }
    }
    None
}

/// Squared distance from a point to a segment in the plane.
fn point_segment2(p: [f64; 2], s: [[f64; 2]; 2]) -> f64 {
    let q = crate::plane::closest_on_segment(p, s[0], s[1]);
    (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)
}

/// Distance between two segments in the plane.
fn segment_distance(a: [[f64; 2]; 2], b: [[f64; 2]; 2]) -> f64 {
    if crate::curves::segments_cross(a[0], a[1], b[0], b[1]) {
        return 0.0;
    }
    point_segment2(a[0], b)
        .min(point_segment2(a[1], b))
        .min(point_segment2(b[0], a))
        .min(point_segment2(b[1], a))
        .sqrt()
}
