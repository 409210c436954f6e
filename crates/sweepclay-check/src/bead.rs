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

/// Beads per chunk of [`Beads`]: the unit the store lets go of.
pub(crate) const CHUNK: usize = 1 << 12;

/// Every bead laid, by its index in path order, in chunks of [`CHUNK`];
/// the oldest chunks may be let go once the path has risen far above them
/// ([`Beads::evict_oldest`], docs/CHECKER.md "Bounded memory"), their
/// indices staying those of the beads after them.
#[derive(Default)]
pub(crate) struct Beads {
    chunks: Vec<Option<Vec<Bead>>>,
    len: usize,
    /// Chunks `..first_chunk` are let go.
    first_chunk: usize,
}

impl Beads {
    /// How many beads were laid (the let-go ones included).
    #[inline]
    pub(crate) fn len(&self) -> usize {
        self.len
    }

    /// The first bead still kept.
    #[inline]
    pub(crate) fn first_kept(&self) -> usize {
        self.first_chunk * CHUNK
    }

    /// How many beads are kept.
    pub(crate) fn kept(&self) -> usize {
        self.len - self.first_kept()
    }

    pub(crate) fn push(&mut self, b: Bead) {
        let c = self.len / CHUNK;
        if c == self.chunks.len() {
            self.chunks.push(Some(Vec::with_capacity(CHUNK)));
        }
        self.chunks[c]
            .as_mut()
            .expect("the newest chunk is kept")
            .push(b);
        self.len += 1;
    }

    /// Bead `i`, if it was laid and is kept.
    #[inline]
    pub(crate) fn get(&self, i: usize) -> Option<&Bead> {
        self.chunks.get(i / CHUNK)?.as_ref()?.get(i % CHUNK)
    }

    pub(crate) fn get_mut(&mut self, i: usize) -> Option<&mut Bead> {
        self.chunks.get_mut(i / CHUNK)?.as_mut()?.get_mut(i % CHUNK)
    }

    /// Beads `from..` (from the first kept one at the earliest), with
    /// their indices.
    pub(crate) fn since(&self, from: usize) -> impl Iterator<Item = (usize, &Bead)> {
        let from = from.max(self.first_kept());
        (from..self.len).map(move |i| (i, &self[i]))
    }

    /// The oldest kept chunk's beads and their first index, or `None`
    /// while fewer than two chunks are laid (the newest is never let go).
    pub(crate) fn oldest(&self) -> Option<(usize, &[Bead])> {
        (self.first_chunk + 1 < self.chunks.len()).then(|| {
            let c = self.chunks[self.first_chunk].as_deref().expect("kept");
            (self.first_kept(), c)
        })
    }

    /// Lets the oldest kept chunk go (see [`Beads::oldest`]).
    pub(crate) fn evict_oldest(&mut self) {
        if self.oldest().is_some() {
            self.chunks[self.first_chunk] = None;
            self.first_chunk += 1;
        }
    }
}

impl std::ops::Index<usize> for Beads {
    type Output = Bead;

    /// Bead `i`; a question never asks one let go (it is refused before:
    /// docs/CHECKER.md, "Bounded memory").
    #[inline]
    fn index(&self, i: usize) -> &Bead {
        self.get(i).expect("a bead laid and kept")
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

    #[test]
    fn beads_keep_their_indices_when_the_oldest_go() {
        let mut beads = Beads::default();
        for k in 0..(2 * CHUNK + 5) {
            beads.push(Bead::new(
                [k as f64, 0.0, 0.0],
                [k as f64 + 1.0, 0.0, 0.0],
                3.0,
                k as f64,
                false,
            ));
        }
        assert_eq!(
            (beads.len(), beads.kept(), beads.first_kept()),
            (2 * CHUNK + 5, 2 * CHUNK + 5, 0)
        );
        assert_eq!(beads.oldest().map(|(i, c)| (i, c.len())), Some((0, CHUNK)));
        beads.evict_oldest();
        beads.evict_oldest();
        // The newest chunk stays.
        beads.evict_oldest();
        assert_eq!((beads.first_kept(), beads.kept()), (2 * CHUNK, 5));
        assert!(beads.get(CHUNK).is_none());
        assert_eq!(beads[2 * CHUNK + 3].from()[0], (2 * CHUNK + 3) as f64);
        assert_eq!(
            beads.since(0).map(|(i, _)| i).collect::<Vec<_>>(),
            (2 * CHUNK..2 * CHUNK + 5).collect::<Vec<_>>()
        );
    }
}
