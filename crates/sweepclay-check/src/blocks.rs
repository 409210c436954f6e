//! Bounds of runs of consecutive beads, for searches whose cost must not
//! grow with how finely the path is sampled.
//!
//! The beads of a print are indexed in path order. Blocks of 8, 64, 512,
//! 4,096, 32,768 and 262,144 consecutive beads (aligned on their size;
//! the coarse ones so that a run of a million beads, clay laid again and
//! again over one place, is a few dozen blocks to ask, not two thousand:
//! docs/PERFORMANCE.md) each keep the box that
//! holds their centrelines and their widest half-width. A search that
//! walks a run of beads asks each block first and skips it whole when
//! its bounds show that no bead in it can matter (see
//! [`Blocks::scan`]); at a fine sampling a few blocks stand in for many
//! beads. The bounds are exact minima and maxima of the beads'
//! single-precision values, so they hold every bead of the block.

use crate::geom::rect_distance;

/// Bounds of a block of consecutive beads.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Bound {
    /// The low corner of the box of the centrelines: x, y, z.
    pub lo: [f32; 3],
    /// The high corner.
    pub hi: [f32; 3],
    /// The largest half-width of a bead in the block.
    pub half_width: f32,
}

impl Bound {
    fn grow(&mut self, b: &Bound) {
        for a in 0..3 {
            self.lo[a] = self.lo[a].min(b.lo[a]);
            self.hi[a] = self.hi[a].max(b.hi[a]);
        }
        self.half_width = self.half_width.max(b.half_width);
    }

    /// The bounds of one bead from `from` to `to`, `width` wide.
    pub fn bead(from: [f32; 3], to: [f32; 3], width: f32) -> Bound {
        Bound {
            lo: [0, 1, 2].map(|a| from[a].min(to[a])),
            hi: [0, 1, 2].map(|a| from[a].max(to[a])),
            half_width: 0.5 * width,
        }
    }

    /// Plan distance from `p` to the box (0 inside; 0 for a NaN `p`).
    pub fn plan_distance(&self, p: [f64; 2]) -> f64 {
        let rect = [self.lo[0], self.lo[1], self.hi[0], self.hi[1]];
        rect_distance(rect.map(f64::from), p)
    }
}

/// log2 of the block sizes, finest first.
const SHIFTS: [u32; 6] = [3, 6, 9, 12, 15, 18];

/// What a scan hands its visitor.
pub(crate) enum Visit<'a> {
    /// A block that may hold beads of the run: `false` skips it whole.
    Block(&'a Bound),
    /// A bead of the run in a block not skipped (what `f` returns is
    /// not read).
    Bead(u32),
}

/// The bounds of every block of beads `0..len`, at each size.
#[derive(Default)]
pub(crate) struct Blocks {
    levels: [Vec<Bound>; SHIFTS.len()],
    len: usize,
}

impl Blocks {
    /// Room for the blocks of `beads` beads, as far as memory allows.
    pub fn reserve(&mut self, beads: usize) {
        for (level, shift) in self.levels.iter_mut().zip(SHIFTS) {
            let _ = level.try_reserve_exact((beads >> shift) + 1);
        }
    }

    /// The number of beads in the blocks.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Bead `len` (the next index) with bounds `b` joins its blocks: the
    /// finest at once, a coarser one when the finer block ending with the
    /// bead is complete (until then [`Blocks::scan`] does not ask it).
    pub fn push(&mut self, b: &Bound) {
        let k = self.len >> SHIFTS[0];
        match self.levels[0].get_mut(k) {
            Some(block) => block.grow(b),
            None => self.levels[0].push(*b),
        }
        self.len += 1;
        for level in 1..SHIFTS.len() {
            if self.len & ((1 << SHIFTS[level - 1]) - 1) != 0 {
                break;
            }
            let done = self.levels[level - 1][(self.len - 1) >> SHIFTS[level - 1]];
            let k = (self.len - 1) >> SHIFTS[level];
            match self.levels[level].get_mut(k) {
                Some(block) => block.grow(&done),
                None => self.levels[level].push(done),
            }
        }
    }

    /// Whether the bounds of bead `k`'s block at `level` hold bead `k`
    /// (and so every bead of the block before it): always at the finest
    /// level, at a coarser one once the finer block of `k` is complete.
    fn complete(&self, level: usize, k: usize) -> bool {
        level == 0 || (k >> SHIFTS[level - 1]) < self.len >> SHIFTS[level - 1]
    }

    /// Walks beads `first..=last` (clamped to the beads there are) in
    /// index order, asking `f` about each block, coarsest first, before
    /// its beads; a block `f` rejects is skipped. The bounds of a block
    /// also hold its beads outside the run, so a block rejected only for
    /// what its bounds say rejects none of the run's beads wrongly.
    pub fn scan(&self, first: u32, last: u32, f: &mut impl FnMut(Visit) -> bool) {
        let end = (last as usize + 1).min(self.len);
        let mut k = first as usize;
        while k < end {
            k = self.scan_level(SHIFTS.len() - 1, k, end, f);
        }
    }

    /// Scans from bead `k` to the end of its block at `level` (or `end`),
    /// returning where it stopped.
    fn scan_level(
        &self,
        level: usize,
        k: usize,
        end: usize,
        f: &mut impl FnMut(Visit) -> bool,
    ) -> usize {
        let shift = SHIFTS[level];
        let stop = (((k >> shift) + 1) << shift).min(end);
        // A coarse block still taking beads is not asked (its last finer
        // block is not in it yet): its finer blocks are.
        let last_fine = (((k >> shift) + 1) << shift).min(self.len) - 1;
        if self.complete(level, last_fine) && !f(Visit::Block(&self.levels[level][k >> shift])) {
            return stop;
        }
        let mut k = k;
        if level == 0 {
            while k < stop {
                f(Visit::Bead(k as u32));
                k += 1;
            }
        } else {
            while k < stop {
                k = self.scan_level(level - 1, k, stop, f);
            }
        }
        stop
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn beads(n: usize, seed: u64) -> Vec<Bound> {
        let mut s = seed;
        let mut r = || (crate::xorshift(&mut s) % 1000) as f32 / 10.0;
        (0..n)
            .map(|_| Bound::bead([r(), r(), r()], [r(), r(), r()], r() / 10.0))
            .collect()
    }

    #[test]
    fn each_block_a_scan_asks_bounds_its_beads() {
        let all = beads(1500, 7);
        let mut blocks = Blocks::default();
        let checkpoints = [1, 7, 8, 9, 63, 64, 65, 511, 512, 513, 1000, 1500];
        for (n, b) in all.iter().enumerate() {
            blocks.push(b);
            if !checkpoints.contains(&(n + 1)) {
                continue;
            }
            assert_eq!(blocks.len(), n + 1);
            assert_eq!(blocks.levels[0].len(), (n >> SHIFTS[0]) + 1);
            for (level, shift) in SHIFTS.iter().enumerate() {
                for k in 0..=n >> shift {
                    let last = (((k + 1) << shift) - 1).min(n);
                    if !blocks.complete(level, last) {
                        // Only the last block of a coarse level waits.
                        assert!(
                            level > 0 && k == n >> shift,
                            "{n} beads: level {level} block {k}"
                        );
                        continue;
                    }
                    let mine = &all[k << shift..=last];
                    let mut want = mine[0];
                    mine.iter().for_each(|b| want.grow(b));
                    assert_eq!(
                        blocks.levels[level][k], want,
                        "{n} beads: level {level} block {k}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_scan_visits_the_run_minus_the_rejected_blocks() {
        let all = beads(1300, 11);
        let mut blocks = Blocks::default();
        for b in &all {
            blocks.push(b);
        }
        // Reject blocks whose box lies wholly above z = 50: a bead of the
        // run is visited exactly when no block holding it was rejected.
        let rejected = |b: &Bound| b.lo[2] > 50.0;
        for (first, last) in [
            (0, 1299),
            (5, 5),
            (7, 8),
            (63, 64),
            (100, 900),
            (1290, 5000),
        ] {
            let mut seen = Vec::new();
            blocks.scan(first, last, &mut |v| match v {
                Visit::Block(b) => !rejected(b),
                Visit::Bead(j) => {
                    seen.push(j);
                    true
                }
            });
            let want: Vec<u32> = (first..=last.min(1299))
                .filter(|&j| {
                    SHIFTS.iter().enumerate().all(|(level, shift)| {
                        // As the scan: a coarse block still taking
                        // beads is not asked.
                        let k = j as usize >> shift;
                        let last_fine = ((k + 1) << shift).min(blocks.len) - 1;
                        !blocks.complete(level, last_fine) || !rejected(&blocks.levels[level][k])
                    })
                })
                .collect();
            assert_eq!(seen, want, "run {first}..={last}");
        }
        // Nothing rejected: the whole run, in order.
        let mut seen = Vec::new();
        blocks.scan(3, 700, &mut |v| {
            if let Visit::Bead(j) = v {
                seen.push(j);
            }
            true
        });
        assert_eq!(seen, (3..=700).collect::<Vec<u32>>());
    }

    #[test]
    fn plan_distance_is_zero_inside_and_euclidean_outside() {
        let b = Bound::bead([0.0, 0.0, 0.0], [4.0, 2.0, 1.0], 1.0);
        assert_eq!(b.plan_distance([1.0, 1.0]), 0.0);
        assert_eq!(b.plan_distance([7.0, 6.0]), 5.0);
        assert_eq!(b.plan_distance([-3.0, 1.0]), 3.0);
        assert_eq!(b.plan_distance([f64::NAN, 1.0]), 0.0);
    }
}
