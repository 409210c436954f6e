//! Curves through fitted values (docs/MESHES.md, "Fitting"): a profile's
//! and an interpolation's control points chosen so that the clamped cubic
//! B-spline passes through the values, and piecewise-linear reading of
//! the fitted polylines.

use super::*;
/// A profile's control points through `pts` (`[x, z]`, z rising): as few
/// as keep the curve within a third of the tolerance of the values, a
/// profile a potter can still edit.
pub(super) fn profile_through(pts: &[[f64; 2]], tol: f64) -> Vec<[f64; 2]> {
    let mut curve = Vec::new();
    for k in [6, 8, 12, 16, 24, 32, 48, 64, 96, 128, MAX_CURVE_POINTS] {
        curve = through(&thin(pts, k));
        let line = dense(&curve);
        let off = pts
            .iter()
            .map(|p| (at_z(&line, p[1]) - p[0]).abs())
            .fold(0.0, f64::max);
        if off <= tol / 3.0 || k >= pts.len() {
            break;
        }
    }
    curve
}

/// An interpolation curve through `lambda` (one value a point of Ψ, from
/// u = 0): from (0, 0) to (1, 0), f in [0, 1], as the design's rules ask.
pub(super) fn interpolation_through(lambda: &[f64]) -> Vec<[f64; 2]> {
    let jj = lambda.len();
    let mut pts: Vec<[f64; 2]> = (0..jj)
        .map(|j| [j as f64 / jj as f64, lambda[j].clamp(0.0, 1.0)])
        .collect();
    pts.push([1.0, 0.0]);
    pts[0] = [0.0, 0.0];
    let mut c = through(&thin(&pts, MAX_CURVE_POINTS));
    for p in &mut c {
        p[1] = p[1].clamp(0.0, 1.0);
    }
    let last = c.len() - 1;
    c[0] = [0.0, 0.0];
    c[last] = [1.0, 0.0];
    c
}

/// At most `k` of `pts`, evenly chosen, the ends kept.
pub(super) fn thin(pts: &[[f64; 2]], k: usize) -> Vec<[f64; 2]> {
    if pts.len() <= k {
        return pts.to_vec();
    }
    (0..k)
        .map(|i| pts[(i * (pts.len() - 1) + (k - 1) / 2) / (k - 1)])
        .collect()
}

/// Control points whose clamped B-spline passes (nearly) through `pts` at
/// their Greville abscissae: the points moved by what the curve misses
/// them by, a few times over.
pub(super) fn through(pts: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let n = pts.len();
    if n < 4 {
        return pts.to_vec();
    }
    let p = 3usize;
    let interior = n - p - 1;
    let knot = |i: usize| -> f64 {
        if i <= p {
            0.0
        } else if i >= n {
            1.0
        } else {
            (i - p) as f64 / (interior + 1) as f64
        }
    };
    let greville: Vec<f64> = (0..n)
        .map(|i| (knot(i + 1) + knot(i + 2) + knot(i + 3)) / 3.0)
        .collect();
    let mut ctrl = pts.to_vec();
    for _ in 0..30 {
        let Some(c) = BSpline::clamped(ctrl.clone()) else {
            break;
        };
        let mut moved = 0.0f64;
        for i in 1..n - 1 {
            let q = c.eval(greville[i]);
            let e = [pts[i][0] - q[0], pts[i][1] - q[1]];
            ctrl[i] = [ctrl[i][0] + e[0], ctrl[i][1] + e[1]];
            moved = moved.max(e[0].abs().max(e[1].abs()));
        }
        if moved < 1e-4 {
            break;
        }
    }
    ctrl
}

/// A profile's curve, densely, as the sampling reads it.
pub(super) fn dense(ctrl: &[[f64; 2]]) -> Vec<[f64; 2]> {
    BSpline::clamped(ctrl.to_vec()).expect("points").flatten(16)
}

/// x of a polyline at height `z` (its second coordinate), by the first
/// segment spanning it.
pub(super) fn at_z(poly: &[[f64; 2]], z: f64) -> f64 {
    for w in poly.windows(2) {
        let (a, b) = (w[0], w[1]);
        if (a[1] <= z && z <= b[1]) || (b[1] <= z && z <= a[1]) {
            let t = if (b[1] - a[1]).abs() > 1e-12 {
                (z - a[1]) / (b[1] - a[1])
            } else {
                0.0
            };
            return a[0] + t * (b[0] - a[0]);
        }
    }
    if z <= poly[0][1] {
        poly[0][0]
    } else {
        poly[poly.len() - 1][0]
    }
}

/// The second coordinate of a polyline at first coordinate `x`.
pub(super) fn at_x(poly: &[[f64; 2]], x: f64) -> f64 {
    let swapped: Vec<[f64; 2]> = poly.iter().map(|p| [p[1], p[0]]).collect();
    at_z(&swapped, x)
}
