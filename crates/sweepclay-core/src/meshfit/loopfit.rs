//! The loop Ψ with few control points (docs/MESHES.md, "Few control
//! points"): the foot's wall, read as one point a ray (360 round), is
//! fitted by the closed curve the design file takes — a periodic uniform
//! cubic B-spline (docs/FORMATS.md, `trajectory`) — with the fewest
//! control points that keep the whole design within the tolerance. Each
//! ray's wall moves by as much as the curve lies off its point along
//! that ray, so the design's difference from the mesh is known exactly
//! from the fit's residual, section by section. A loop no such curve
//! holds (a polygon's corners) is tried as the polygon of its corners.

use super::*;

/// The fewest control points a loop is tried with: a triangle's three
/// round off to a curve no pot's foot is.
const LOOP_MIN: usize = 4;

/// The most: a round, oval or lobed loop a potter edits point by point
/// (docs/MESHES.md).
const LOOP_MAX: usize = 16;

/// The most corners of a polygon loop: a polygon's rounded corners take
/// two or three points each (the hexagonal planter's, 18).
const POLYGON_MAX: usize = 24;

/// Curve points a span when the fit reads it.
const PER_SPAN: usize = 48;

/// The parameter corrections a fit makes (Hoschek's).
const REPROJECT: usize = 8;

/// How much a point's turn counts toward its parameter, tried in turn.
const TURN_WEIGHTS: [f64; 3] = [0.0, 0.5, 1.0];

/// The loop as the design file writes it.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Loop {
    /// The control points of a closed curve (`control_points`).
    Curve(Vec<[f64; 2]>),
    /// The corners of a closed polyline (`points`): a polygon's sides
    /// straight and its corners as sharp as the mesh's.
    Polygon(Vec<[f64; 2]>),
}

/// A loop, the design's largest difference from the mesh with it, and
/// where (section, ray).
pub(super) type LoopFit = (Loop, f64, (usize, usize));

/// A loop of the fewest control points ([`LOOP_MIN`] to [`LOOP_MAX`])
/// whose curve lies within a third of `tol` of the loop along each ray
/// (a round pot stays round to a tenth of a millimetre, as a profile
/// keeps two thirds for its own) and keeps the design within `tol` of
/// the mesh: `psi` the loop as fitted, `dirs` its rays, `residual` the
/// mesh's offsets less the design's (section by section, ray by ray).
/// With it, the design's new largest difference and where (section,
/// ray). Where sixteen are not enough, the polygon of its corners
/// ([`Rays::polygon`]); `None` where that does not hold either (a wall of
/// facets too coarse for the tolerance, a design already near it).
pub(super) fn loop_fewest(
    psi: &[[f64; 2]],
    dirs: &[[f64; 2]],
    residual: &[Vec<f64>],
    tol: f64,
) -> Option<LoopFit> {
    if psi.len() < 2 * LOOP_MAX {
        return None;
    }
    let rays = Rays {
        psi,
        dirs,
        residual,
        tol,
    };
    for m in LOOP_MIN..=LOOP_MAX {
        // The points placed along the curve by length and by length and
        // turn, the better kept (by length alone, a 60 × 40 mm oval took
        // 16 points to hold 0.05 mm).
        let mut best: Option<LoopFit> = None;
        for w in TURN_WEIGHTS {
            let mut t: Vec<f64> = shares(psi, w).iter().map(|x| x * m as f64).collect();
            let Some(mut ctrl) = periodic_least_squares(psi, &t, m) else {
                continue;
            };
            for _ in 0..REPROJECT {
                reproject_periodic(&ctrl, psi, &mut t);
                match periodic_least_squares(psi, &t, m) {
                    Some(c) => ctrl = c,
                    None => break,
                }
            }
            let curve = crate::curves::periodic_bspline(&ctrl, PER_SPAN);
            if let Some((own, dev, at)) = rays.measure(&curve) {
                if own <= tol / 3.0 && best.as_ref().is_none_or(|b| dev < b.1) {
                    best = Some((Loop::Curve(ctrl), dev, at));
                }
            }
        }
        if let Some(b) = best.filter(|b| b.1 <= tol) {
            return Some(b);
        }
    }
    rays.polygon()
}

/// What a loop is fitted against: `psi` the loop as fitted, `dirs` its
/// rays, `residual` the mesh's offsets less the design's (section by
/// section, ray by ray), `tol` the tolerance.
struct Rays<'a> {
    psi: &'a [[f64; 2]],
    dirs: &'a [[f64; 2]],
    residual: &'a [Vec<f64>],
    tol: f64,
}

impl Rays<'_> {
    /// The loop as a polygon of at most [`POLYGON_MAX`] corners, where
    /// no curve of as few points holds (a hexagonal planter's corners):
    /// the loop's points simplified (Douglas–Peucker, round the loop from
    /// its two farthest-apart points) within a third of the tolerance and
    /// then a sixth, measured as the design draws it (its sharpest corners
    /// rounded for the bead, `curves::round_corners`), kept on the same
    /// terms as a curve.
    fn polygon(&self) -> Option<LoopFit> {
        let (psi, tol) = (self.psi, self.tol);
        let n = psi.len();
        let far = (0..n)
            .max_by(|&a, &b| {
                let d = |i: usize| (psi[i][0] - psi[0][0]).hypot(psi[i][1] - psi[0][1]);
                d(a).total_cmp(&d(b))
            })
            .filter(|&k| k > 0)?;
        let params = crate::design::Params::default();
        for eps in [tol / 3.0, tol / 6.0] {
            let mut corners = simplify(&psi[..=far], eps);
            let back: Vec<[f64; 2]> = psi[far..].iter().chain(&psi[..1]).copied().collect();
            let back = simplify(&back, eps);
            corners.extend_from_slice(&back[1..back.len() - 1]);
            // The two points it started from stay only where they are
            // corners.
            let corners = without_straight(corners, eps);
            if corners.len() < 3 || corners.len() > POLYGON_MAX {
                continue;
            }
            // As the design draws it before sampling: its corners sharper
            // than a loop's limit rounded for the widest bead (sampled, every
            // loop's corners are cut alike, the 360 points' too).
            let (mut line, _) = crate::curves::round_corners(
                &corners,
                true,
                params.width_max,
                0.25 * params.spacing,
            );
            line.push(line[0]);
            if let Some((own, dev, at)) = self.measure(&line) {
                if own <= tol / 3.0 && dev <= tol {
                    return Some((Loop::Polygon(corners), dev, at));
                }
            }
        }
        None
    }

    /// How far the closed polyline `curve` (its first point repeated at
    /// its end) lies off the loop along its rays at most, and the design's
    /// largest difference from the mesh with it for its loop and where
    /// (section, ray): each ray's residual less how far along the ray the
    /// curve lies off its point; `None` when a ray misses the curve.
    fn measure(&self, curve: &[[f64; 2]]) -> Option<(f64, f64, (usize, usize))> {
        let moved = (0..self.psi.len())
            .map(|j| along_ray(curve, self.psi[j], self.dirs[j]))
            .collect::<Option<Vec<f64>>>()?;
        let mut worst = (0.0f64, (0, 0));
        for (k, row) in self.residual.iter().enumerate() {
            for (j, (r, e)) in row.iter().zip(&moved).enumerate() {
                let off = (r - e).abs();
                if off > worst.0 {
                    worst = (off, (k, j));
                }
            }
        }
        let own = moved.iter().fold(0.0f64, |m, e| m.max(e.abs()));
        Some((own, worst.0, worst.1))
    }
}

/// Each point's share of the loop from the first, a step counting its
/// length and `w` times its turn (as a share of the loop's length a full
/// turn): uniform spans then put more control points where the loop
/// bends most.
fn shares(psi: &[[f64; 2]], w: f64) -> Vec<f64> {
    let n = psi.len();
    let len = |a: [f64; 2], b: [f64; 2]| (b[0] - a[0]).hypot(b[1] - a[1]);
    let turn = |i: usize| bend(psi[(i + n - 1) % n], psi[i], psi[(i + 1) % n]).abs();
    let total = perimeter(psi);
    let step = |i: usize| {
        let j = (i + 1) % n;
        len(psi[i], psi[j]) + w * total * 0.5 * (turn(i) + turn(j)) / std::f64::consts::TAU
    };
    let mut u = Vec::with_capacity(n);
    let mut acc = 0.0;
    for i in 0..n {
        u.push(acc);
        acc += step(i);
    }
    u.iter().map(|x| x / acc.max(1e-12)).collect()
}

/// The closed polygon `corners` without the vertices that lie within
/// `eps` of the line through their neighbours.
fn without_straight(mut corners: Vec<[f64; 2]>, eps: f64) -> Vec<[f64; 2]> {
    let mut i = 0;
    while corners.len() > 3 && i < corners.len() {
        let n = corners.len();
        let (a, b, c) = (corners[(i + n - 1) % n], corners[i], corners[(i + 1) % n]);
        if off_line(a, c, b) <= eps {
            corners.remove(i);
        } else {
            i += 1;
        }
    }
    corners
}

/// The periodic uniform cubic B-spline's four basis values at `t` (in
/// [0, m)) and the first of the four control points they weigh.
fn basis(t: f64, m: usize) -> (usize, [f64; 4]) {
    let t = t.rem_euclid(m as f64);
    let j = (t.floor() as usize).min(m - 1);
    (j, crate::curves::uniform_cubic_basis(t - j as f64))
}

/// The `m` control points of the closed curve nearest `pts` at
/// parameters `t` in least squares. No pull toward an even polygon, as
/// a profile's fit has: round a loop with no ends held, that pull
/// shrinks the loop, and a dozen points from hundreds need none.
fn periodic_least_squares(pts: &[[f64; 2]], t: &[f64], m: usize) -> Option<Vec<[f64; 2]>> {
    use nalgebra::{DMatrix, DVector};
    let mut ata = DMatrix::<f64>::zeros(m, m);
    let mut atb = [DVector::<f64>::zeros(m), DVector::<f64>::zeros(m)];
    for (p, &ti) in pts.iter().zip(t) {
        let (j, b) = basis(ti, m);
        for (a, ba) in b.iter().enumerate() {
            let i = (j + a) % m;
            for (c, bc) in b.iter().enumerate() {
                ata[(i, (j + c) % m)] += ba * bc;
            }
            atb[0][i] += ba * p[0];
            atb[1][i] += ba * p[1];
        }
    }
    let lu = ata.lu();
    let xs = [lu.solve(&atb[0])?, lu.solve(&atb[1])?];
    let ctrl: Vec<[f64; 2]> = (0..m).map(|i| [xs[0][i], xs[1][i]]).collect();
    ctrl.iter()
        .all(|p| p[0].is_finite() && p[1].is_finite())
        .then_some(ctrl)
}

/// Moves each parameter to the nearest place on the curve to its
/// point, searched near where it was (the points run round the curve
/// in order).
fn reproject_periodic(ctrl: &[[f64; 2]], pts: &[[f64; 2]], t: &mut [f64]) {
    let m = ctrl.len();
    let eval = |t: f64| {
        let (j, b) = basis(t, m);
        let mut p = [0.0; 2];
        for (a, w) in b.iter().enumerate() {
            let c = ctrl[(j + a) % m];
            p = [p[0] + w * c[0], p[1] + w * c[1]];
        }
        p
    };
    let d2 = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2);
    let h = 0.25;
    for (p, ti) in pts.iter().zip(t.iter_mut()) {
        let (mut lo, mut hi) = (*ti - h, *ti + h);
        for _ in 0..30 {
            let (a, b) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
            if d2(eval(a), *p) < d2(eval(b), *p) {
                hi = b;
            } else {
                lo = a;
            }
        }
        *ti = 0.5 * (lo + hi);
    }
}

/// A crossing farther than this from the loop is the loop's other side
/// (mm).
const NEAR_MM: f64 = 5.0;

/// Of crossings (t along the ray, segment), the nearest the ray's start,
/// if it is nearer than [`NEAR_MM`].
fn nearest(c: impl Iterator<Item = (f64, usize)>) -> Option<(f64, usize)> {
    c.min_by(|a, b| a.0.abs().total_cmp(&b.0.abs()))
        .filter(|c| c.0.abs() < NEAR_MM)
}

/// How far along `dir` from `p` the closed polyline `curve` lies (the
/// crossing nearest `p`), or `None` when the ray meets it nowhere near.
fn along_ray(curve: &[[f64; 2]], p: [f64; 2], dir: [f64; 2]) -> Option<f64> {
    nearest(crossings(curve, p, dir).into_iter()).map(|c| c.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::meshfit::tests::ring;

    fn curve_of(l: Loop) -> Vec<[f64; 2]> {
        match l {
            Loop::Curve(c) => c,
            Loop::Polygon(p) => panic!("a polygon of {} corners", p.len()),
        }
    }

    fn radial(psi: &[[f64; 2]]) -> Vec<[f64; 2]> {
        (0..psi.len())
            .map(|j| ray(psi, j, Offset::Radial))
            .collect()
    }

    /// A circle (r 40 mm) takes few points and stays round (within a
    /// third of the tolerance); an oval and a four-lobed loop stay within
    /// sixteen; a square's and a hexagon's corners take a polygon.
    #[test]
    fn round_oval_and_lobed_loops_take_few_points_and_polygons_their_corners() {
        let zero = vec![vec![0.0; 360]; 3];
        let circle = ring(|_| 40.0, 360);
        let (c, dev, _) = loop_fewest(&circle, &radial(&circle), &zero, 0.15).expect("a circle");
        let c = curve_of(c);
        assert!(c.len() <= 8, "{} points", c.len());
        assert!(dev <= 0.05);
        // Measured independently: every curve point's radius.
        for q in crate::curves::periodic_bspline(&c, 64) {
            assert!((q[0].hypot(q[1]) - 40.0).abs() <= 0.05, "{q:?}");
        }
        let oval: Vec<[f64; 2]> = circle.iter().map(|p| [1.5 * p[0], p[1]]).collect();
        let (c, _, _) = loop_fewest(&oval, &radial(&oval), &zero, 0.15).expect("an oval");
        let c = curve_of(c);
        assert!(c.len() <= 10, "{} points", c.len());
        let lobes = ring(|a| 40.0 + 4.0 * (4.0 * a).cos(), 360);
        let (c, _, _) = loop_fewest(&lobes, &radial(&lobes), &zero, 0.3).expect("four lobes");
        let c = curve_of(c);
        assert!(c.len() <= 16, "{} points", c.len());
        // A square's corners: no curve of sixteen holds them (its 90°
        // corners, rounded for the bead as the design draws a loop's,
        // are no polygon within the tolerance either).
        let square: Vec<[f64; 2]> = ring(|a| 40.0 / a.cos().abs().max(a.sin().abs()), 360);
        assert!(!matches!(
            loop_fewest(&square, &radial(&square), &zero, 0.3),
            Some((Loop::Curve(_), _, _))
        ));
        // A hexagon (a planter's): its six corners, the polygon within
        // 0.05 mm of it along every ray (measured independently).
        let hexagon = ring(
            |a| {
                let s = std::f64::consts::PI / 3.0;
                40.0 * (s / 2.0).cos() / ((a + s / 2.0).rem_euclid(s) - s / 2.0).cos()
            },
            360,
        );
        let dirs = radial(&hexagon);
        match loop_fewest(&hexagon, &dirs, &zero, 0.3) {
            Some((Loop::Polygon(p), _, _)) => {
                assert_eq!(p.len(), 6, "{p:?}");
                let mut line = p.clone();
                line.push(p[0]);
                for (j, q) in hexagon.iter().enumerate() {
                    let off = along_ray(&line, *q, dirs[j]).expect("crosses");
                    assert!(off.abs() < 0.05, "{j}: {off}");
                }
            }
            other => panic!("{other:?}"),
        }
    }

    /// The wall's own difference from the design adds to the loop's:
    /// sections off by ±0.25 mm leave a loop of three 2 mm lobes 0.05 mm of a 0.3 mm
    /// tolerance, which takes more points than the whole 0.3 does.
    #[test]
    fn the_loops_difference_adds_to_the_walls() {
        let r = |a: f64| 40.0 + 2.0 * (3.0 * a).cos();
        let lobes = ring(r, 360);
        let dirs = radial(&lobes);
        let (loose, _, _) = loop_fewest(&lobes, &dirs, &[vec![0.0; 360]], 0.3).expect("loose");
        let loose = curve_of(loose);
        let walls = [vec![0.25; 360], vec![-0.25; 360]];
        let (tight, dev, _) = loop_fewest(&lobes, &dirs, &walls, 0.3).expect("tight");
        let tight = curve_of(tight);
        assert!(
            tight.len() > loose.len(),
            "{} vs {}",
            tight.len(),
            loose.len()
        );
        assert!((0.25..=0.3).contains(&dev), "{dev}");
        // Measured independently: the curve's radius along each ray.
        let curve = crate::curves::periodic_bspline(&tight, 64);
        for (j, p) in lobes.iter().enumerate() {
            let a = p[1].atan2(p[0]);
            let off = along_ray(&curve, *p, dirs[j]).expect("crosses");
            assert!(off.abs() <= 0.05 + 1e-9, "{j}: {off}");
            let q = [p[0] + off * dirs[j][0], p[1] + off * dirs[j][1]];
            assert!((q[0].hypot(q[1]) - r(a)).abs() <= 0.05 + 1e-9);
        }
    }
}
