//! Bead widths by the paper's Algorithm 3 (§5.3; docs/ALGORITHMS.md §3):
//! how wide a bead must be for the one resting on it to overlap it
//! enough. A leaf the extrusion stage (`extrude`) and the path stage's
//! flush foot (`toolpath`, docs/ALGORITHMS.md §8) both read, so neither
//! imports the other for it.

use crate::design::Params;

/// Overlap of a bead of width `wa` with one of width `wb` whose centre is
/// `s` to the side, as a fraction of `wa`.
pub fn overlap_fraction(wa: f64, wb: f64, s: f64) -> f64 {
    let lo = (-wa / 2.0).max(s - wb / 2.0);
    let hi = (wa / 2.0).min(s + wb / 2.0);
    ((hi - lo).max(0.0) / wa).min(1.0)
}

/// The least width (from `below` up to what overlaps fully) a bead needs
/// for the bead `above` wide on it, `lean` mm off it, to overlap it by
/// `overlap` of its width: widened only so far, a wide bead over a
/// flare no longer widens every bead under it to its own width
/// (docs/ALGORITHMS.md §6).
pub fn least_support(above: f64, below: f64, lean: f64, overlap: f64) -> f64 {
    let full = above + 2.0 * lean.abs();
    if overlap_fraction(above, below, lean) >= overlap {
        return below;
    }
    let (mut lo, mut hi) = (below, full.max(below));
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if overlap_fraction(above, mid, lean) >= overlap {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

/// How wide a bead must be for the bead on it, `lean` mm off it, to
/// overlap it by `params.overlap` (Algorithm 3), within the widths the
/// design allows.
pub fn lean_width(lean: f64, params: &Params) -> f64 {
    (lean / (1.0 - params.overlap)).clamp(params.width_min, params.width_max)
}

/// The part of the offset `d` between a bead and the one below that lies
/// across the bead, whose direction is the chord `t` (mm): on a twisted
/// surface the rest runs along it, the bead below carrying on under it.
/// A chord shorter than a hundredth of a millimetre (a bead's only point
/// in its layer) gives no direction: the whole offset counts.
pub fn across_chord(t: [f64; 2], d: [f64; 2]) -> f64 {
    let l = t[0].hypot(t[1]);
    if l < 1e-2 {
        return d[0].hypot(d[1]);
    }
    ((t[0] * d[1] - t[1] * d[0]) / l).abs()
}

/// The width the extrusion stage gives the lowest bead of a column of
/// beads each resting on the one before, `leans[k]` the offset of bead
/// k + 1 from bead k (mm): each bead as wide as the lean onto it and off
/// it needs ([`lean_width`]), and widened as far as the bead above needs
/// where that one would overlap it too little ([`least_support`]), the
/// rule run down from the top, as
/// `extrude::plan_extrusion` runs it over the path backwards. Linear in
/// the beads. The floor plans its outer ring with it before the path
/// exists (docs/ALGORITHMS.md §8, "A flush foot").
pub fn lowest_bead_width(leans: &[f64], params: &Params) -> f64 {
    let (wmin, wmax, ov) = (params.width_min, params.width_max, params.overlap);
    // Bead j + 1 is final when bead j is reached: (its width, its lean).
    let mut above: Option<(f64, f64)> = None;
    for j in (0..=leans.len()).rev() {
        let own = j
            .checked_sub(1)
            .map_or(wmin, |k| lean_width(leans[k], params));
        let mut w = own.max(leans.get(j).map_or(wmin, |&d| lean_width(d, params)));
        if let Some((wa, d)) = above {
            if overlap_fraction(wa, w, d) < ov {
                w = w.max(least_support(wa, w, d, ov).min(wmax));
            }
        }
        match j.checked_sub(1) {
            Some(k) => above = Some((w, leans[k])),
            None => return w,
        }
    }
    wmin
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overlap_fraction_closed_forms() {
        assert_eq!(overlap_fraction(3.0, 3.0, 0.0), 1.0);
        assert!((overlap_fraction(3.0, 3.0, 1.0) - 2.0 / 3.0).abs() < 1e-12);
        assert_eq!(overlap_fraction(3.0, 3.0, 4.0), 0.0);
        assert!((overlap_fraction(6.0, 3.0, 0.0) - 0.5).abs() < 1e-12);
    }

    /// A 6 mm bead centred on the one below needs it 4 mm wide for two
    /// thirds (not 6); 1 mm off, 5 mm (its near edge 1 mm in, the far
    /// one at the upper bead's); a bead wide enough already stays.
    #[test]
    fn least_support_closed_forms() {
        assert!((least_support(6.0, 3.0, 0.0, 2.0 / 3.0) - 4.0).abs() < 1e-9);
        assert!((least_support(6.0, 3.0, 1.0, 2.0 / 3.0) - 4.0).abs() < 1e-9);
        assert!((least_support(6.0, 3.0, 1.5, 2.0 / 3.0) - 5.0).abs() < 1e-9);
        assert_eq!(least_support(3.0, 3.0, 0.5, 2.0 / 3.0), 3.0);
    }
}
