//! The three kinds of design curve, validated and turned into the sampled
//! forms the surface needs (paper §4, docs/FORMATS.md, docs/ALGORITHMS.md §1–2):
//!
//! - [`Profile`]: C_s or C_t as a table of horizontal offset against
//!   normalised height t ∈ [0, 1] (z strictly increasing along the curve);
//! - [`Trajectory`]: Ψ resampled by arc length into points ≈ `spacing` apart;
//! - [`Interpolation`]: f(u), monotone, f(0) = 0, f(1) = 1.
//!
//! Known limitation: curves are flattened to polylines fine enough that the
//! chord error is far below a bead width (≤ spacing/8 along Ψ, ≤ 0.05 mm of
//! height along profiles); resampling interpolates linearly on them.

use crate::bspline::{dist, BSpline};
use crate::design::{CurveSpec, TrajectorySpec};
use crate::error::{Error, Result};
use crate::grid::Grid2;
use crate::plane::signed_area2;

fn check_points(key: &str, pts: &[[f64; 2]], min: usize) -> Result<()> {
    if pts.len() < min {
        return Err(Error::invalid(
            key,
            format!("needs at least {min} points (got {})", pts.len()),
        ));
    }
    for (i, p) in pts.iter().enumerate() {
        if !p[0].is_finite() || !p[1].is_finite() || p[0].abs() > 1e5 || p[1].abs() > 1e5 {
            return Err(Error::invalid(
                format!("{key}[{i}]"),
                format!("coordinates must be finite numbers below 100000 mm (got {p:?})"),
            ));
        }
    }
    Ok(())
}

/// A profile curve sampled as horizontal offset from its start against
/// normalised height.
#[derive(Clone, Debug, PartialEq)]
pub struct Profile {
    /// Z(C): the curve's height in mm.
    pub height: f64,
    /// x(t·Z) − x(0) at t = k / (len − 1).
    table: Vec<f64>,
}

impl Profile {
    /// Validates and samples a profile. `key` is `profile_start` or
    /// `profile_end`, used in error messages.
    pub fn new(key: &str, spec: &CurveSpec) -> Result<Profile> {
        let ckey = format!("{key}.control_points");
        check_points(&ckey, &spec.control_points, 2)?;
        let first = spec.control_points[0];
        if first[1] != 0.0 {
            return Err(Error::invalid(
                format!("{ckey}[0]"),
                format!("the first point must have z = 0 (got z = {})", first[1]),
            ));
        }
        let curve = BSpline::clamped(spec.control_points.clone()).expect("≥ 2 points");
        let height = spec.control_points.last().expect("≥ 2 points")[1];
        if height <= 0.0 {
            return Err(Error::invalid(
                &ckey,
                format!("the curve must rise: its last point has z = {height}"),
            ));
        }
        let per_span = ((height / 0.05) as usize / curve.spans()).clamp(32, 4096);
        let poly = curve.flatten(per_span);
        for w in poly.windows(2) {
            if w[1][1] <= w[0][1] {
                return Err(Error::invalid(
                    &ckey,
                    format!(
                        "z must increase strictly along the curve, but it turns down near z = {:.2} mm (x = {:.2})",
                        w[0][1], w[0][0]
                    ),
                ));
            }
        }
        // Resample x at uniform heights by walking the monotone polyline.
        let rows = ((height / 0.05).ceil() as usize).clamp(64, 1 << 16);
        let mut table = Vec::with_capacity(rows + 1);
        let mut seg = 0;
        for k in 0..=rows {
            let z = height * k as f64 / rows as f64;
            while seg + 2 < poly.len() && poly[seg + 1][1] < z {
                seg += 1;
            }
            let (a, b) = (poly[seg], poly[seg + 1]);
            let s = ((z - a[1]) / (b[1] - a[1])).clamp(0.0, 1.0);
            table.push(a[0] + s * (b[0] - a[0]) - first[0]);
        }
        let profile = Profile { height, table };
        // The rows a potter typed must be where the curve is: the file
        // says both, and they must not disagree.
        for (i, &[x, z]) in spec.points.iter().flatten().enumerate() {
            let pkey = format!("{key}.points[{i}]");
            if !(x.is_finite() && z.is_finite() && (-1e-9..=height + 1e-9).contains(&z)) {
                return Err(Error::invalid(
                    pkey,
                    format!("must be a point of the curve, from z = 0 to its height {height} mm (got [{x}, {z}])"),
                ));
            }
            let on = first[0] + profile.offset(z / height);
            if (on - x).abs() > crate::design::ON_CURVE_MM {
                return Err(Error::invalid(
                    pkey,
                    format!(
                        "is {:.2} mm off the curve its control points draw (x = {on:.2} mm at z = {z} mm): the rows must lie on the curve; remove `points` to keep the curve as drawn",
                        (on - x).abs()
                    ),
                ));
            }
        }
        Ok(profile)
    }

    /// x(t·Z) − x(0), the horizontal offset at normalised height `t`.
    pub fn offset(&self, t: f64) -> f64 {
        lerp_table(&self.table, t)
    }
}

fn lerp_table(table: &[f64], t: f64) -> f64 {
    let last = table.len() - 1;
    let f = t.clamp(0.0, 1.0) * last as f64;
    let i = (f as usize).min(last - 1);
    let s = f - i as f64;
    table[i] + s * (table[i + 1] - table[i])
}

/// f of a control curve `[u, f]` with u strictly increasing, sampled at
/// u = k / 2048 and clamped to [0, 1].
fn function_table(pts: &[[f64; 2]]) -> Vec<f64> {
    let curve = BSpline::clamped(pts.to_vec()).expect("≥ 2 points");
    let poly = curve.flatten(256);
    let rows = 2048;
    let mut table = Vec::with_capacity(rows + 1);
    let mut seg = 0;
    for k in 0..=rows {
        let u = k as f64 / rows as f64;
        while seg + 2 < poly.len() && poly[seg + 1][0] < u {
            seg += 1;
        }
        let (a, b) = (poly[seg], poly[seg + 1]);
        let s = if b[0] > a[0] {
            ((u - a[0]) / (b[0] - a[0])).clamp(0.0, 1.0)
        } else {
            0.0
        };
        table.push((a[1] + s * (b[1] - a[1])).clamp(0.0, 1.0));
    }
    table
}

/// The interpolation function f(u) of paper §4 (Fig. 3).
#[derive(Clone, Debug, PartialEq)]
pub enum Interpolation {
    /// f(u) = u, the default.
    Linear,
    /// f(u) = (1 − cos 2πu) / 2, the default round a closed Ψ: C_s at the
    /// start point, C_t half way round, and back.
    Cosine,
    /// f sampled at u = k / (len − 1).
    Table(Vec<f64>),
}

impl Interpolation {
    /// Validates the control curve: first point (0, 0), last (1, 1), u
    /// strictly and f weakly increasing between control points (which makes
    /// the B-spline a monotone function of u).
    pub fn new(spec: Option<&CurveSpec>) -> Result<Interpolation> {
        Self::validated(spec, false)
    }

    /// f(u) round a closed Ψ: f(0) = f(1) = 0, values in [0, 1], u
    /// strictly increasing between control points; f may rise and fall.
    /// Omitted: [`Interpolation::Cosine`].
    pub fn new_closed(spec: Option<&CurveSpec>) -> Result<Interpolation> {
        Self::validated(spec, true)
    }

    /// [`Interpolation::new`] (open Ψ) or [`Interpolation::new_closed`].
    fn validated(spec: Option<&CurveSpec>, closed: bool) -> Result<Interpolation> {
        let Some(spec) = spec else {
            return Ok(if closed {
                Interpolation::Cosine
            } else {
                Interpolation::Linear
            });
        };
        if spec.points.is_some() {
            return Err(Error::invalid(
                "interpolation.points",
                "only a profile takes points (its rows); the interpolation is given by control_points",
            ));
        }
        let key = "interpolation.control_points";
        let pts = &spec.control_points;
        check_points(key, pts, 2)?;
        let (first, last) = (pts[0], pts[pts.len() - 1]);
        if first != [0.0, 0.0] {
            return Err(Error::invalid(
                format!("{key}[0]"),
                format!("must be [0, 0] (got {first:?})"),
            ));
        }
        let (end, named) = if closed {
            ([1.0, 0.0], "[1, 0]")
        } else {
            ([1.0, 1.0], "[1, 1]")
        };
        if last != end {
            let why = if closed {
                " for a closed trajectory: the loop comes back to the start profile, so f(1) = f(0) = 0"
            } else {
                ""
            };
            return Err(Error::invalid(
                format!("{key}[{}]", pts.len() - 1),
                format!("must be {named}{why} (got {last:?})"),
            ));
        }
        for i in 1..pts.len() {
            if pts[i][0] <= pts[i - 1][0] {
                return Err(Error::invalid(
                    format!("{key}[{i}]"),
                    format!(
                        "u must increase strictly ({} after {})",
                        pts[i][0],
                        pts[i - 1][0]
                    ),
                ));
            }
            if closed && !(0.0..=1.0).contains(&pts[i][1]) {
                return Err(Error::invalid(
                    format!("{key}[{i}]"),
                    format!("f must lie between 0 and 1 (got {})", pts[i][1]),
                ));
            }
            if !closed && pts[i][1] < pts[i - 1][1] {
                return Err(Error::invalid(
                    format!("{key}[{i}]"),
                    format!(
                        "f must not decrease: the interpolation is monotone ({} after {})",
                        pts[i][1],
                        pts[i - 1][1]
                    ),
                ));
            }
        }
        let mut table = function_table(pts);
        if !closed {
            // Flattening error can break monotonicity by a rounding step;
            // repair.
            for k in 1..table.len() {
                if table[k] < table[k - 1] {
                    table[k] = table[k - 1];
                }
            }
        }
        Ok(Interpolation::Table(table))
    }

    /// λ = f(u) for u ∈ [0, 1].
    pub fn eval(&self, u: f64) -> f64 {
        match self {
            Interpolation::Linear => u.clamp(0.0, 1.0),
            Interpolation::Cosine => 0.5 * (1.0 - (std::f64::consts::TAU * u).cos()),
            Interpolation::Table(t) => lerp_table(t, u),
        }
    }
}

/// Ψ resampled by arc length.
#[derive(Clone, Debug, PartialEq)]
pub struct Trajectory {
    /// The sample points p_0 … p_{n−1}, relative to `o`. A closed Ψ does
    /// not repeat p_0 at the end: p_{n−1} is followed by p_0.
    pub points: Vec<[f64; 2]>,
    /// Arc length of Ψ in mm (a closed Ψ's whole loop).
    pub length: f64,
    /// Whether Ψ is a loop (a vessel, docs/ALGORITHMS.md §8).
    pub closed: bool,
    /// The corners of a polyline Ψ that were rounded.
    pub corners: Vec<CornerFix>,
}

/// Corners of a polyline Ψ sharper than this (interior angle, degrees)
/// are rounded: nearer the tip than about a bead, the wall's beads on the
/// two arms, laid more than two beads apart along Ψ, would lie on each
/// other (docs/ALGORITHMS.md §4).
pub const SHARPEST_CORNER_DEG: f64 = 60.0;

/// Corners of a closed Ψ (a vessel) sharper than this are rounded too:
/// at an acute corner the floor's turns, offsets of the wall's line, lie
/// farther from the corner's tip than the wall's first turn can lean
/// over (docs/ALGORITHMS.md §8).
pub const SHARPEST_VESSEL_CORNER_DEG: f64 = 90.0;

/// A sharp corner of a polyline Ψ, rounded by a circular arc tangent to
/// both arms (docs/ALGORITHMS.md §4).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct CornerFix {
    /// The drawn corner (mm, relative to `o`).
    pub at: [f64; 2],
    /// Its interior angle (degrees).
    pub angle_deg: f64,
    /// The arc's radius (mm): 1.1 w_max / (2 cos(θ/2)), the least that
    /// keeps the two arms a bead apart where they meet the arc, or less
    /// where an arm is too short for it.
    pub radius_mm: f64,
    /// How far the printed path lies from the drawn corner (mm).
    pub deviation_mm: f64,
}

/// A polyline (`closed`: its last vertex joins its first, not repeated)
/// with every corner sharper than [`SHARPEST_CORNER_DEG`] (a loop's:
/// [`SHARPEST_VESSEL_CORNER_DEG`]) replaced by an
/// arc of points about `step` apart, and the corners it rounded. `bead`
/// is the widest bead the wall lays.
pub fn round_corners(
    v: &[[f64; 2]],
    closed: bool,
    bead: f64,
    step: f64,
) -> (Vec<[f64; 2]>, Vec<CornerFix>) {
    let sharpest = if closed {
        SHARPEST_VESSEL_CORNER_DEG
    } else {
        SHARPEST_CORNER_DEG
    };
    round_corners_by(v, closed, step, |_, theta| {
        let half = 0.5 * theta;
        (theta.to_degrees() < sharpest - 1e-9).then(|| 1.1 * bead / (2.0 * half.cos()))
    })
}

/// [`round_corners`] with the radius each vertex asks for: `radius(i,
/// θ)` for vertex `i` of interior angle θ (radians), `None` to keep it.
/// The correction loop rounds a corner where the check keeps failing
/// (docs/ALGORITHMS.md §4).
pub fn round_corners_by(
    v: &[[f64; 2]],
    closed: bool,
    step: f64,
    radius: impl Fn(usize, f64) -> Option<f64>,
) -> (Vec<[f64; 2]>, Vec<CornerFix>) {
    let m = v.len();
    let mut out = Vec::with_capacity(m);
    let mut fixes = Vec::new();
    let unit = |p: [f64; 2], l: f64| [p[0] / l, p[1] / l];
    for i in 0..m {
        let inner = closed || (i > 0 && i + 1 < m);
        if !inner || m < 3 {
            out.push(v[i]);
            continue;
        }
        let (a, b, c) = (v[(i + m - 1) % m], v[i], v[(i + 1) % m]);
        let (e1, e2) = ([a[0] - b[0], a[1] - b[1]], [c[0] - b[0], c[1] - b[1]]);
        let (l1, l2) = (e1[0].hypot(e1[1]), e2[0].hypot(e2[1]));
        if l1 < 1e-9 || l2 < 1e-9 {
            out.push(b);
            continue;
        }
        let (u1, u2) = (unit(e1, l1), unit(e2, l2));
        let theta = (u1[0] * u2[0] + u1[1] * u2[1]).clamp(-1.0, 1.0).acos();
        let wanted =
            radius(i, theta).filter(|_| theta > 1e-6 && theta < std::f64::consts::PI - 1e-6);
        let Some(wanted) = wanted else {
            out.push(b);
            continue;
        };
        let half = 0.5 * theta;
        // Half of each arm at most: the next corner may round the rest.
        let tangent = (wanted / half.tan()).min(0.5 * l1.min(l2));
        let radius = tangent * half.tan();
        let bis = unit(
            [u1[0] + u2[0], u1[1] + u2[1]],
            (u1[0] + u2[0]).hypot(u1[1] + u2[1]),
        );
        let to_centre = radius / half.sin();
        let centre = [b[0] + bis[0] * to_centre, b[1] + bis[1] * to_centre];
        let (t1, t2) = (
            [b[0] + u1[0] * tangent, b[1] + u1[1] * tangent],
            [b[0] + u2[0] * tangent, b[1] + u2[1] * tangent],
        );
        let a1 = (t1[1] - centre[1]).atan2(t1[0] - centre[0]);
        let a2 = (t2[1] - centre[1]).atan2(t2[0] - centre[0]);
        let mut sweep = a2 - a1;
        while sweep > std::f64::consts::PI {
            sweep -= std::f64::consts::TAU;
        }
        while sweep < -std::f64::consts::PI {
            sweep += std::f64::consts::TAU;
        }
        let k = ((radius * sweep.abs() / step).ceil() as usize).max(2);
        for j in 0..=k {
            let ang = a1 + sweep * j as f64 / k as f64;
            out.push([
                centre[0] + radius * ang.cos(),
                centre[1] + radius * ang.sin(),
            ]);
        }
        fixes.push(CornerFix {
            at: b,
            angle_deg: theta.to_degrees(),
            radius_mm: radius,
            deviation_mm: to_centre - radius,
        });
    }
    (out, fixes)
}

/// The polyline of a periodic uniform cubic B-spline whose control polygon
/// wraps round (`pts` not repeated), `per_span` points a span, closed by
/// repeating its first point. Each span j is the cubic of control points
/// j … j + 3 (mod m) in the uniform basis.
pub fn periodic_bspline(pts: &[[f64; 2]], per_span: usize) -> Vec<[f64; 2]> {
    let m = pts.len();
    let mut out = Vec::with_capacity(m * per_span + 1);
    for j in 0..m {
        let [p0, p1, p2, p3] = [0, 1, 2, 3].map(|k| pts[(j + k) % m]);
        for step in 0..per_span {
            let [b0, b1, b2, b3] = uniform_cubic_basis(step as f64 / per_span as f64);
            out.push([
                b0 * p0[0] + b1 * p1[0] + b2 * p2[0] + b3 * p3[0],
                b0 * p0[1] + b1 * p1[1] + b2 * p2[1] + b3 * p3[1],
            ]);
        }
    }
    out.push(out[0]);
    out
}

/// The four weights of a uniform cubic B-spline's span at `t` in [0, 1]:
/// of its control points j … j + 3 for span j.
pub fn uniform_cubic_basis(t: f64) -> [f64; 4] {
    let (t2, t3) = (t * t, t * t * t);
    [
        (1.0 - t).powi(3) / 6.0,
        (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0,
        (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0,
        t3 / 6.0,
    ]
}

/// Arc length at each vertex of a polyline (0 at the first).
pub fn arc_lengths(poly: &[[f64; 2]]) -> Vec<f64> {
    let mut cum = Vec::with_capacity(poly.len());
    let mut acc = 0.0;
    cum.push(0.0);
    for w in poly.windows(2) {
        acc += dist(w[0], w[1]);
        cum.push(acc);
    }
    cum
}

/// `n ≥ 2` points equally spaced by arc length along a polyline of at least
/// two vertices, ends kept; `cum` is [`arc_lengths`] of it.
pub fn resample_polyline(poly: &[[f64; 2]], cum: &[f64], n: usize) -> Vec<[f64; 2]> {
    let length = cum[cum.len() - 1];
    let mut points = Vec::with_capacity(n);
    let mut seg = 0;
    for m in 0..n {
        let s = length * m as f64 / (n - 1) as f64;
        while seg + 2 < poly.len() && cum[seg + 1] < s {
            seg += 1;
        }
        let (a, b) = (poly[seg], poly[seg + 1]);
        let l = cum[seg + 1] - cum[seg];
        let f = if l > 0.0 {
            ((s - cum[seg]) / l).clamp(0.0, 1.0)
        } else {
            0.0
        };
        points.push([a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])]);
    }
    points
}

impl Trajectory {
    /// Validates Ψ (no self-intersection, non-zero length), rounds a
    /// polyline's corners sharper than [`SHARPEST_CORNER_DEG`] for beads
    /// up to `bead` wide, and resamples it: `round(length / spacing) + 1`
    /// points open, `round(length / spacing)` round a loop.
    pub fn new(spec: &TrajectorySpec, spacing: f64, bead: f64) -> Result<Trajectory> {
        let closed = spec.closed;
        let mut corners = Vec::new();
        let poly = match (&spec.control_points, &spec.points) {
            (Some(_), Some(_)) => {
                return Err(Error::invalid(
                    "trajectory",
                    "give either `control_points` or `points`, not both",
                ))
            }
            (None, None) => {
                return Err(Error::invalid(
                    "trajectory",
                    "needs `control_points` (a B-spline) or `points` (a polyline)",
                ))
            }
            (Some(cp), None) if closed => {
                check_points("trajectory.control_points", cp, 3)?;
                let est: f64 = (0..cp.len())
                    .map(|i| dist(cp[i], cp[(i + 1) % cp.len()]))
                    .sum();
                let per_span = ((est / (spacing / 8.0)) as usize / cp.len()).clamp(16, 1 << 14);
                periodic_bspline(cp, per_span)
            }
            (Some(cp), None) => {
                check_points("trajectory.control_points", cp, 2)?;
                let curve = BSpline::clamped(cp.clone()).expect("≥ 2 points");
                let est = curve.polygon_length();
                let per_span =
                    ((est / (spacing / 8.0)) as usize / curve.spans()).clamp(16, 1 << 14);
                curve.flatten(per_span)
            }
            (None, Some(p)) => {
                check_points("trajectory.points", p, if closed { 3 } else { 2 })?;
                let mut v: Vec<[f64; 2]> = Vec::with_capacity(p.len() + 1);
                for q in p {
                    if v.last().is_none_or(|l| dist(*l, *q) > 1e-9) {
                        v.push(*q);
                    }
                }
                if closed {
                    // A loop closes back to its first point (given again
                    // or not).
                    if v.len() > 1 && dist(v[0], v[v.len() - 1]) <= 1e-9 {
                        v.pop();
                    }
                    if v.len() < 3 {
                        return Err(Error::invalid(
                            "trajectory.points",
                            "a closed trajectory needs at least 3 distinct points",
                        ));
                    }
                }
                let (mut v, fixes) = round_corners(&v, closed, bead, 0.25 * spacing);
                corners = fixes;
                if closed {
                    v.push(v[0]);
                }
                v
            }
        };
        let cum = arc_lengths(&poly);
        let length = cum[cum.len() - 1];
        if length < 2.0 * spacing.max(0.5) {
            return Err(Error::invalid(
                "trajectory",
                format!("is too short ({length:.2} mm); it must be at least two samples long"),
            ));
        }
        let points = if closed {
            // n points round the loop; the (n + 1)-th would be p_0 again.
            let n = ((length / spacing).round() as usize).max(3);
            let mut pts = resample_polyline(&poly, &cum, n + 1);
            pts.pop();
            if signed_area2(&pts).abs() < 1e-9 {
                return Err(Error::invalid(
                    "trajectory",
                    "a closed trajectory must enclose an area",
                ));
            }
            pts
        } else {
            let n = ((length / spacing).round() as usize).max(1) + 1;
            resample_polyline(&poly, &cum, n)
        };
        let traj = Trajectory {
            points,
            length,
            closed,
            corners,
        };
        traj.check_self_intersection()?;
        Ok(traj)
    }

    /// The number of segments of the polyline: n − 1 open, n closed.
    fn segments(&self) -> usize {
        self.points.len() - usize::from(!self.closed)
    }

    /// Refuses a trajectory whose polyline crosses itself (grid of
    /// segments; linear time for curves that do not pile up in one place).
    fn check_self_intersection(&self) -> Result<()> {
        let pts = &self.points;
        let segs = self.segments();
        let end = |i: usize| pts[(i + 1) % pts.len()];
        let seg_len = self.length / segs as f64;
        let mut grid = Grid2::new(seg_len.max(1e-3));
        for (i, &p) in pts.iter().enumerate().take(segs) {
            grid.insert_segment(p, end(i), i as u32);
        }
        for i in 0..segs {
            let (a, b) = (pts[i], end(i));
            let mut hit = None;
            grid.for_each_near_segment(a, b, 0.0, |j| {
                let j = j as usize;
                // Neighbours share an end; a loop's last segment is the
                // first one's neighbour.
                let neighbour = j <= i + 1 || (self.closed && i == 0 && j == segs - 1);
                if !neighbour && hit.is_none() && segments_cross(a, b, pts[j], end(j)) {
                    hit = Some(j);
                }
            });
            if let Some(j) = hit {
                let u1 = i as f64 / segs as f64;
                let u2 = j as f64 / segs as f64;
                return Err(Error::invalid(
                    "trajectory",
                    format!(
                        "crosses itself near ({:.1}, {:.1}) mm, at u = {u1:.3} and u = {u2:.3}",
                        a[0], a[1]
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// Whether two closed segments intersect (touching counts).
pub(crate) fn segments_cross(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    fn orient(p: [f64; 2], q: [f64; 2], r: [f64; 2]) -> f64 {
        (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
    }
    let (d1, d2) = (orient(c, d, a), orient(c, d, b));
    let (d3, d4) = (orient(a, b, c), orient(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    let on = |p: [f64; 2], q: [f64; 2], r: [f64; 2], o: f64| {
        o == 0.0
            && r[0] >= p[0].min(q[0])
            && r[0] <= p[0].max(q[0])
            && r[1] >= p[1].min(q[1])
            && r[1] <= p[1].max(q[1])
    };
    on(c, d, a, d1) || on(c, d, b, d2) || on(a, b, c, d3) || on(a, b, d, d4)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve(p: &[[f64; 2]]) -> CurveSpec {
        CurveSpec {
            control_points: p.to_vec(),
            points: None,
        }
    }

    #[test]
    fn a_profiles_rows_must_lie_on_its_curve() {
        // A quadratic through (0, 0), (5, 20) and (0, 40) at its middle
        // parameter: control point x = 2 · 5 − (0 + 0) / 2 = 10.
        let mut c = curve(&[[0.0, 0.0], [10.0, 20.0], [0.0, 40.0]]);
        c.points = Some(vec![[0.0, 0.0], [5.0, 20.0], [0.0, 40.0]]);
        assert!(Profile::new("profile_start", &c).is_ok());
        c.points = Some(vec![[0.0, 0.0], [6.0, 20.0]]);
        let e = Profile::new("profile_start", &c).unwrap_err().to_string();
        assert!(
            e.contains("profile_start.points[1]") && e.contains("1.00 mm off the curve"),
            "{e}"
        );
        c.points = Some(vec![[0.0, 50.0]]);
        let e = Profile::new("profile_start", &c).unwrap_err().to_string();
        assert!(e.contains("from z = 0 to its height 40"), "{e}");
    }

    #[test]
    fn two_point_profile_is_a_straight_line() {
        let p = Profile::new("profile_start", &curve(&[[10.0, 0.0], [16.0, 30.0]])).unwrap();
        assert_eq!(p.height, 30.0);
        for k in 0..=10 {
            let t = k as f64 / 10.0;
            assert!(
                (p.offset(t) - 6.0 * t).abs() < 1e-9,
                "offset({t}) = {}",
                p.offset(t)
            );
        }
    }

    #[test]
    fn profile_errors_name_the_key() {
        let e = Profile::new("profile_end", &curve(&[[0.0, 1.0], [0.0, 10.0]])).unwrap_err();
        assert!(
            e.to_string().starts_with("profile_end.control_points[0]"),
            "{e}"
        );
        let e = Profile::new(
            "profile_end",
            &curve(&[[0.0, 0.0], [1.0, 30.0], [2.0, 10.0]]),
        )
        .unwrap_err();
        assert!(e.to_string().contains("increase strictly"), "{e}");
        let e = Profile::new("profile_start", &curve(&[[0.0, 0.0], [f64::NAN, 10.0]])).unwrap_err();
        assert!(
            e.to_string().starts_with("profile_start.control_points[1]"),
            "{e}"
        );
        let e = Profile::new("profile_start", &curve(&[[0.0, 0.0]])).unwrap_err();
        assert!(e.to_string().contains("at least 2"), "{e}");
    }

    #[test]
    fn linear_interpolation_is_identity_and_curves_are_monotone() {
        assert_eq!(Interpolation::new(None).unwrap().eval(0.3), 0.3);
        let f = Interpolation::new(Some(&curve(&[[0.0, 0.0], [0.4, 0.1], [1.0, 1.0]]))).unwrap();
        let mut last = 0.0;
        for k in 0..=100 {
            let v = f.eval(k as f64 / 100.0);
            assert!(v >= last, "f decreased at u = {}", k as f64 / 100.0);
            last = v;
        }
        assert!((f.eval(0.0)).abs() < 1e-12 && (f.eval(1.0) - 1.0).abs() < 1e-12);
        // Straight control polygon: f(u) = u.
        let g = Interpolation::new(Some(&curve(&[[0.0, 0.0], [0.5, 0.5], [1.0, 1.0]]))).unwrap();
        assert!((g.eval(0.25) - 0.25).abs() < 1e-6, "{}", g.eval(0.25));
    }

    #[test]
    fn interpolation_errors_name_the_point() {
        let e = Interpolation::new(Some(&curve(&[
            [0.0, 0.0],
            [0.5, 0.7],
            [0.6, 0.4],
            [1.0, 1.0],
        ])))
        .unwrap_err();
        assert!(
            e.to_string().starts_with("interpolation.control_points[2]"),
            "{e}"
        );
        let e = Interpolation::new(Some(&curve(&[[0.0, 0.0], [1.0, 0.9]]))).unwrap_err();
        assert!(
            e.to_string().starts_with("interpolation.control_points[1]"),
            "{e}"
        );
    }

    #[test]
    fn trajectory_is_resampled_by_arc_length() {
        let spec = TrajectorySpec {
            control_points: None,
            points: Some(vec![[0.0, 10.0], [30.0, 10.0], [30.0, 50.0]]),
            closed: false,
            offset: Default::default(),
        };
        let t = Trajectory::new(&spec, 1.0, 6.0).unwrap();
        assert!((t.length - 70.0).abs() < 1e-9);
        assert_eq!(t.points.len(), 71);
        for w in t.points.windows(2) {
            let d = dist(w[0], w[1]);
            assert!(d <= 1.0 + 1e-9 && d > 0.7, "spacing {d}");
        }
    }

    #[test]
    fn self_intersecting_and_closed_trajectories_are_refused() {
        let spec = TrajectorySpec {
            control_points: None,
            points: Some(vec![
                [0.0, 10.0],
                [40.0, 10.0],
                [40.0, 40.0],
                [20.0, 40.0],
                [20.0, 0.0],
            ]),
            closed: false,
            offset: Default::default(),
        };
        let e = Trajectory::new(&spec, 1.1, 6.0).unwrap_err();
        assert!(e.to_string().contains("crosses itself"), "{e}");
        // Closed, it crosses itself too; a loop's two ends are neighbours,
        // not a crossing.
        let spec = TrajectorySpec {
            closed: true,
            ..spec
        };
        let e = Trajectory::new(&spec, 1.1, 6.0).unwrap_err();
        assert!(e.to_string().contains("crosses itself"), "{e}");
        let square = TrajectorySpec {
            points: Some(vec![[0.0, 0.0], [40.0, 0.0], [40.0, 40.0], [0.0, 40.0]]),
            ..spec
        };
        let t = Trajectory::new(&square, 1.0, 6.0).unwrap();
        assert!(t.closed && (t.length - 160.0).abs() < 1e-9);
        assert_eq!(t.points.len(), 160, "p_0 is not repeated");
        let wrap = dist(t.points[159], t.points[0]);
        assert!((wrap - 1.0).abs() < 1e-9, "the loop closes evenly: {wrap}");
    }

    #[test]
    fn sharp_corners_are_rounded_by_the_least_arc_that_keeps_the_arms_apart() {
        // A 40° corner at o: the arc of radius 1.1 w / (2 cos 20°) meets
        // the arms where they are 1.1 w apart, and passes ρ / sin 20° − ρ
        // inside the drawn tip. A square's corners stay.
        let a = 20f64.to_radians();
        let v = [
            [-100.0 * a.cos(), 100.0 * a.sin()],
            [0.0, 0.0],
            [-100.0 * a.cos(), -100.0 * a.sin()],
        ];
        let (out, fixes) = round_corners(&v, false, 6.0, 0.05);
        assert_eq!(fixes.len(), 1);
        let rho = 1.1 * 6.0 / (2.0 * a.cos());
        assert!((fixes[0].radius_mm - rho).abs() < 1e-9);
        assert!((fixes[0].angle_deg - 40.0).abs() < 1e-9);
        let tip = rho / a.sin() - rho;
        assert!((fixes[0].deviation_mm - tip).abs() < 1e-9);
        let nearest = out
            .iter()
            .map(|p| p[0].hypot(p[1]))
            .fold(f64::MAX, f64::min);
        assert!((nearest - tip).abs() < 0.01, "{nearest} {tip}");
        let (t1, t2) = (out[1], out[out.len() - 2]);
        assert!((dist(t1, t2) - 6.6).abs() < 1e-9, "{}", dist(t1, t2));
        // Ends of an open Ψ are no corners; a square's are not sharp.
        let square = [[0.0, 0.0], [40.0, 0.0], [40.0, 40.0], [0.0, 40.0]];
        assert!(round_corners(&square, true, 6.0, 0.05).1.is_empty());
        // A corner between short arms is rounded within half of each.
        let short = [[-4.0, 1.0], [0.0, 0.0], [-4.0, -1.0]];
        let (_, f) = round_corners(&short, false, 6.0, 0.05);
        assert!(f[0].radius_mm < rho && f[0].radius_mm > 0.0);
    }

    #[test]
    fn a_periodic_b_spline_of_a_regular_polygon_is_round() {
        // The uniform cubic B-spline of a regular m-gon of radius R is a
        // closed curve between R·(2 + cos(2π/m))/3 and the same at the
        // span ends: for m = 8 within 3 % of a circle.
        let cp: Vec<[f64; 2]> = (0..8)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / 8.0;
                [30.0 * a.cos(), 30.0 * a.sin()]
            })
            .collect();
        let poly = periodic_bspline(&cp, 32);
        assert_eq!(poly.first(), poly.last());
        let want = 30.0 * (2.0 + (std::f64::consts::TAU / 8.0).cos()) / 3.0;
        let r0 = poly[0][0].hypot(poly[0][1]);
        assert!((r0 - want).abs() < 1e-9, "{r0} vs {want}");
        for p in &poly {
            let r = p[0].hypot(p[1]);
            assert!(r > 0.97 * want && r < 1.03 * want, "{r}");
        }
    }
}
