//! A bead: one deposited move, its centreline, width and path distance,
//! as the grid, the column tops and the support search all keep it.

use crate::geom::len2;

/// A deposited move. Ends and width are kept in single precision (40
/// bytes a bead instead of 72): 15 µm at 400 mm, far below the 1 µm…1 mm
/// of the G-code's own numbers' last digits and the checker's tolerances.
pub(crate) struct Bead {
    pub(crate) from32: [f32; 3],
    pub(crate) to32: [f32; 3],
    pub(crate) width32: f32,
    /// Path distance at the end of the move.
    pub(crate) s_end: f64,
    /// Turnaround step (steeper than 1:2): clay, but no support for others.
    pub(crate) step: bool,
    /// Its layer height, the gap to the clay it rests on (0 if none), in
    /// µm: two bytes, so a bead stays 40 bytes.
    height_um: u16,
    /// The path turns into it by more than 10° in plan, or it is a step:
    /// near such beads a pass may fold back (see `support::alone`).
    pub(crate) bent: bool,
}

impl Bead {
    pub(crate) fn new(from: [f64; 3], to: [f64; 3], width: f64, s_end: f64, step: bool) -> Bead {
        Bead {
            from32: from.map(|v| v as f32),
            to32: to.map(|v| v as f32),
            width32: width as f32,
            s_end,
            step,
            height_um: 0,
            bent: false,
        }
    }

    #[inline]
    pub(crate) fn from(&self) -> [f64; 3] {
        self.from32.map(f64::from)
    }

    #[inline]
    pub(crate) fn to(&self) -> [f64; 3] {
        self.to32.map(f64::from)
    }

    /// The highest point of the centreline.
    #[inline]
    pub(crate) fn top32(&self) -> f32 {
        self.from32[2].max(self.to32[2])
    }

    #[inline]
    pub(crate) fn width(&self) -> f64 {
        f64::from(self.width32)
    }

    /// Its layer height (mm).
    #[inline]
    pub(crate) fn height(&self) -> f64 {
        f64::from(self.height_um) * 1e-3
    }

    /// Sets its layer height (mm; clamped to 0–65 mm, NaN to 0).
    pub(crate) fn set_height(&mut self, mm: f64) {
        self.height_um = (mm * 1e3).clamp(0.0, f64::from(u16::MAX)) as u16;
    }

    /// Whether `p` lies beside the bead's centreline in plan, between the
    /// perpendiculars at its ends (not beyond an end).
    #[inline]
    pub(crate) fn spans(&self, p: [f64; 3]) -> bool {
        let (from, to) = (self.from(), self.to());
        let (dx, dy) = (to[0] - from[0], to[1] - from[1]);
        let t = (p[0] - from[0]) * dx + (p[1] - from[1]) * dy;
        (0.0..=dx * dx + dy * dy).contains(&t)
    }

    /// Closest point of the bead's centreline (in plan) to `p`:
    /// `(horizontal distance, height there, the point)`.
    #[inline]
    pub(crate) fn closest(&self, p: [f64; 3]) -> (f64, f64, [f64; 2]) {
        let (from, to) = (self.from(), self.to());
        let (dx, dy) = (to[0] - from[0], to[1] - from[1]);
        let l2 = dx * dx + dy * dy;
        let t = if l2 > 0.0 {
            (((p[0] - from[0]) * dx + (p[1] - from[1]) * dy) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let (x, y) = (from[0] + t * dx, from[1] + t * dy);
        let z = from[2] + t * (to[2] - from[2]);
        (len2(p[0] - x, p[1] - y), z, [x, y])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bead_is_40_bytes_and_keeps_its_height_to_a_micrometre() {
        // The check keeps one a move: millions of them.
        assert_eq!(std::mem::size_of::<Bead>(), 40);
        let mut b = Bead::new([0.0; 3], [1.0, 0.0, 0.0], 3.0, 1.0, false);
        b.set_height(1.2504);
        assert!((b.height() - 1.250).abs() < 1e-9, "{}", b.height());
        b.set_height(f64::NAN);
        assert_eq!(b.height(), 0.0);
        b.set_height(1e9);
        assert!((b.height() - 65.535).abs() < 1e-9);
    }
}
