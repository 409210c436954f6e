//! Clamped B-spline curves of degree ≤ 3 in the plane (paper §4: the user
//! draws "clamped cubic B-spline" curves; with fewer than four control points
//! the degree drops to `points − 1`).
//!
//! Evaluation is de Boor's algorithm on a uniform clamped knot vector, so the
//! curve starts at the first control point and ends at the last.

/// A clamped, uniform-knot B-spline of degree `min(3, points − 1)`.
#[derive(Clone, Debug, PartialEq)]
pub struct BSpline {
    degree: usize,
    knots: Vec<f64>,
    ctrl: Vec<[f64; 2]>,
}

impl BSpline {
    /// Builds the curve. Returns `None` for fewer than two control points.
    pub fn clamped(ctrl: Vec<[f64; 2]>) -> Option<Self> {
        let n = ctrl.len();
        if n < 2 {
            return None;
        }
        let p = (n - 1).min(3);
        let interior = n - p - 1;
        let mut knots = Vec::with_capacity(n + p + 1);
        knots.extend(std::iter::repeat_n(0.0, p + 1));
        for j in 1..=interior {
            knots.push(j as f64 / (interior + 1) as f64);
        }
        knots.extend(std::iter::repeat_n(1.0, p + 1));
        Some(BSpline {
            degree: p,
            knots,
            ctrl,
        })
    }

    /// Polynomial degree (1 to 3).
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// Number of polynomial spans (knot intervals of non-zero length).
    pub fn spans(&self) -> usize {
        self.ctrl.len() - self.degree
    }

    /// The control points.
    pub fn control_points(&self) -> &[[f64; 2]] {
        &self.ctrl
    }

    /// The point at parameter `t ∈ [0, 1]` (clamped to that range).
    pub fn eval(&self, t: f64) -> [f64; 2] {
        let p = self.degree;
        let n = self.ctrl.len();
        let t = t.clamp(0.0, 1.0);
        // Span k with knots[k] <= t < knots[k+1], k in p..n: a binary
        // search of the sorted knots, so a point costs O(log n), not O(n).
        let k = p + self.knots[p + 1..n].partition_point(|&u| u <= t);
        let mut d = [[0.0; 2]; 4];
        for (j, dj) in d.iter_mut().enumerate().take(p + 1) {
            *dj = self.ctrl[j + k - p];
        }
        for r in 1..=p {
            for j in (r..=p).rev() {
                let i = j + k - p;
                let denom = self.knots[i + p - r + 1] - self.knots[i];
                let a = if denom > 0.0 {
                    (t - self.knots[i]) / denom
                } else {
                    0.0
                };
                d[j] = [
                    (1.0 - a) * d[j - 1][0] + a * d[j][0],
                    (1.0 - a) * d[j - 1][1] + a * d[j][1],
                ];
            }
        }
        d[p]
    }

    /// The basis functions at `t`, one a control point: the weights that
    /// [`BSpline::eval`] gives the control points there (they sum to one).
    /// Curves fitted by least squares solve for the points through them.
    pub fn basis(&self, t: f64) -> Vec<f64> {
        let p = self.degree;
        let n = self.ctrl.len();
        let t = t.clamp(0.0, 1.0);
        let k = p + self.knots[p + 1..n].partition_point(|&u| u <= t);
        // N(k − p..=k) by the triangular recursion (Cox–de Boor).
        let (mut nb, mut left, mut right) = ([0.0f64; 4], [0.0f64; 4], [0.0f64; 4]);
        nb[0] = 1.0;
        for j in 1..=p {
            left[j] = t - self.knots[k + 1 - j];
            right[j] = self.knots[k + j] - t;
            let mut saved = 0.0;
            for r in 0..j {
                let den = right[r + 1] + left[j - r];
                let tmp = if den > 0.0 { nb[r] / den } else { 0.0 };
                nb[r] = saved + right[r + 1] * tmp;
                saved = left[j - r] * tmp;
            }
            nb[j] = saved;
        }
        let mut out = vec![0.0; n];
        out[k - p..=k].copy_from_slice(&nb[..=p]);
        out
    }

    /// The curve as a polyline with `per_span` segments per span (at least 1),
    /// from the first to the last control point.
    pub fn flatten(&self, per_span: usize) -> Vec<[f64; 2]> {
        let segs = self.spans() * per_span.max(1);
        (0..=segs)
            .map(|s| self.eval(s as f64 / segs as f64))
            .collect()
    }

    /// Length of the control polygon, an upper bound of the curve's length.
    pub fn polygon_length(&self) -> f64 {
        polyline_length(&self.ctrl)
    }
}

/// Length of a polyline (0 for fewer than two points).
pub fn polyline_length(pts: &[[f64; 2]]) -> f64 {
    pts.windows(2).map(|w| dist(w[0], w[1])).sum()
}

/// Euclidean distance of two plane points.
pub fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The basis, weighted by control points, is the curve BSpline
    /// evaluates; and the functions sum to one.
    #[test]
    fn the_basis_is_the_curves_own() {
        let ctrl: Vec<[f64; 2]> = (0..9)
            .map(|i| [(i as f64).sin() * 3.0, i as f64 * 2.0])
            .collect();
        let c = BSpline::clamped(ctrl.clone()).unwrap();
        for k in 0..=100 {
            let t = k as f64 / 100.0;
            let b = c.basis(t);
            assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{t}");
            let p = b
                .iter()
                .zip(&ctrl)
                .fold([0.0; 2], |a, (w, q)| [a[0] + w * q[0], a[1] + w * q[1]]);
            let q = c.eval(t);
            assert!(
                (p[0] - q[0]).abs() < 1e-9 && (p[1] - q[1]).abs() < 1e-9,
                "{t}: {p:?} {q:?}"
            );
        }
    }

    fn close(a: [f64; 2], b: [f64; 2]) -> bool {
        dist(a, b) < 1e-12
    }

    #[test]
    fn endpoints_are_interpolated() {
        let c = BSpline::clamped(vec![
            [0.0, 0.0],
            [4.0, 20.0],
            [-3.0, 45.0],
            [2.0, 60.0],
            [7.0, 70.0],
        ])
        .unwrap();
        assert_eq!(c.degree(), 3);
        assert!(close(c.eval(0.0), [0.0, 0.0]), "{:?}", c.eval(0.0));
        assert!(close(c.eval(1.0), [7.0, 70.0]), "{:?}", c.eval(1.0));
    }

    #[test]
    fn two_points_are_a_segment() {
        let c = BSpline::clamped(vec![[1.0, 0.0], [3.0, 10.0]]).unwrap();
        assert_eq!(c.degree(), 1);
        let m = c.eval(0.25);
        assert!(close(m, [1.5, 2.5]), "got {m:?}, expected [1.5, 2.5]");
    }

    #[test]
    fn three_points_are_a_quadratic_bezier() {
        let c = BSpline::clamped(vec![[0.0, 0.0], [1.0, 2.0], [2.0, 0.0]]).unwrap();
        assert_eq!(c.degree(), 2);
        // Quadratic Bézier at t = 0.5: (P0 + 2 P1 + P2) / 4 = (1, 1).
        let m = c.eval(0.5);
        assert!(close(m, [1.0, 1.0]), "got {m:?}, expected [1, 1]");
    }

    #[test]
    fn four_points_are_a_cubic_bezier() {
        let pts = [[0.0, 0.0], [1.0, 3.0], [3.0, 3.0], [4.0, 0.0]];
        let c = BSpline::clamped(pts.to_vec()).unwrap();
        let t: f64 = 0.3;
        let b = |i: usize| {
            let s = 1.0 - t;
            [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t][i]
        };
        let want = [
            (0..4).map(|i| b(i) * pts[i][0]).sum::<f64>(),
            (0..4).map(|i| b(i) * pts[i][1]).sum::<f64>(),
        ];
        assert!(
            close(c.eval(t), want),
            "got {:?}, expected {want:?}",
            c.eval(t)
        );
    }

    #[test]
    fn collinear_control_points_give_a_straight_line() {
        let c = BSpline::clamped((0..7).map(|i| [i as f64, 2.0 * i as f64]).collect()).unwrap();
        for s in 0..=20 {
            let p = c.eval(s as f64 / 20.0);
            assert!(
                (p[1] - 2.0 * p[0]).abs() < 1e-12,
                "{p:?} is off the line y = 2x"
            );
        }
    }

    #[test]
    fn the_span_search_finds_what_a_walk_along_the_knots_finds() {
        // A wiggly curve of 1,000 points: every evaluation, at the knots
        // and between them, equals de Boor's on the span a linear walk
        // finds (the old search).
        let pts: Vec<[f64; 2]> = (0..1000)
            .map(|i| [i as f64, ((i * 7919) % 13) as f64])
            .collect();
        let c = BSpline::clamped(pts).unwrap();
        let walk = |t: f64| {
            let mut k = c.degree;
            while k + 1 < c.ctrl.len() && c.knots[k + 1] <= t {
                k += 1;
            }
            k
        };
        for s in 0..=20_000 {
            let t = s as f64 / 20_000.0;
            let k = c.degree + c.knots[c.degree + 1..c.ctrl.len()].partition_point(|&u| u <= t);
            assert_eq!(k, walk(t), "t = {t}");
        }
        for &t in &c.knots {
            let k = c.degree + c.knots[c.degree + 1..c.ctrl.len()].partition_point(|&u| u <= t);
            assert_eq!(k, walk(t), "at the knot {t}");
        }
        assert!(close(c.eval(1.0), [999.0, ((999 * 7919) % 13) as f64]));
    }

    #[test]
    fn one_point_is_refused() {
        assert!(BSpline::clamped(vec![[0.0, 0.0]]).is_none());
    }
}
