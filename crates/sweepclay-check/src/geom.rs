//! Small geometry both the support search and the collision probes use:
//! plan lengths, cell indices, running extremes, the overlap of two beads'
//! cross-sections and a cheap bound of a turn's angle.

/// Length of a plan vector. Not `f64::hypot`: that guards against
/// overflow at a cost this hot loop cannot pay, and an overflow to
/// infinity only makes a distance compare as far.
#[inline]
pub(crate) fn len2(dx: f64, dy: f64) -> f64 {
    (dx * dx + dy * dy).sqrt()
}

/// `floor(v / size)`, clamped to ±10⁸ (NaN to 0). Not `f64::floor`, which
/// without SSE 4.1 is a library call this hot path cannot pay.
#[inline]
pub(crate) fn cell(v: f64, size: f64) -> i32 {
    let q = (v / size).clamp(-1e8, 1e8);
    let t = q as i32;
    if f64::from(t) > q {
        t - 1
    } else {
        t
    }
}

/// `a.max(b)` for an `a` that is not NaN (a running maximum, from `-inf`
/// or 0): the same value, by one compare, where `f32::max` and `f64::max`
/// add a NaN test.
#[inline(always)]
pub(crate) fn larger<T: PartialOrd>(a: T, b: T) -> T {
    if a < b {
        b
    } else {
        a
    }
}

/// Plan distance from `p` to a rectangle `[x0, y0, x1, y1]` (0 inside; 0
/// for a NaN `p`).
#[inline]
pub(crate) fn rect_distance(r: [f64; 4], p: [f64; 2]) -> f64 {
    let dx = (r[0] - p[0]).max(p[0] - r[2]).max(0.0);
    let dy = (r[1] - p[1]).max(p[1] - r[3]).max(0.0);
    len2(dx, dy)
}

/// Overlap of a bead of width `wa` with one of width `wb` whose centre is
/// `s` to the side, as a fraction of `wa`.
#[inline]
pub(crate) fn overlap_fraction(wa: f64, wb: f64, s: f64) -> f64 {
    let lo = (-wa / 2.0).max(s - wb / 2.0);
    let hi = (wa / 2.0).min(s + wb / 2.0);
    ((hi - lo).max(0.0) / wa).min(1.0)
}

pub(crate) fn minmax(slot: &mut Option<[(f64, usize); 2]>, v: f64, line: usize) {
    match slot {
        None => *slot = Some([(v, line), (v, line)]),
        Some([lo, hi]) => {
            if v < lo.0 {
                *lo = (v, line);
            }
            if v > hi.0 {
                *hi = (v, line);
            }
        }
    }
}

/// An upper bound of `acos c` for `c ≥ 0.5` (a turn under 60°):
/// `√(2(1 − c)) (1 + (1 − c)/6)`, at most 3.5 % over and cheaper than
/// `acos`; π below.
#[inline]
pub(crate) fn turn_bound(c: f64) -> f64 {
    if c >= 0.5 {
        let v = (1.0 - c).max(0.0);
        (2.0 * v).sqrt() * (1.0 + v / 6.0)
    } else {
        std::f64::consts::PI
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turn_bound_is_an_upper_bound_of_the_angle_and_close_to_it() {
        for k in 0..=100_000 {
            let c = 1.0 - 0.5 * f64::from(k) / 100_000.0;
            let (a, b) = (c.acos(), turn_bound(c));
            assert!(b >= a - 1e-15 && b <= 1.035 * a + 1e-15, "{c}: {b} vs {a}");
        }
        assert_eq!(turn_bound(0.4999), std::f64::consts::PI);
        assert_eq!(turn_bound(-1.0), std::f64::consts::PI);
        assert_eq!(turn_bound(f64::NAN), std::f64::consts::PI);
    }

    #[test]
    fn overlap_fraction_closed_forms() {
        assert_eq!(overlap_fraction(3.0, 3.0, 0.0), 1.0);
        assert!((overlap_fraction(3.0, 3.0, 1.5) - 0.5).abs() < 1e-12);
        assert_eq!(overlap_fraction(3.0, 3.0, 3.5), 0.0);
        // A narrow bead on a wide one, centred: fully supported.
        assert_eq!(overlap_fraction(3.0, 6.0, 1.0), 1.0);
    }
}
