//! Bounded memory (docs/CHECKER.md, "Bounded memory"): the checker keeps
//! the newest beads and lets the oldest go, a chunk of 4,096 at a time,
//! once the path has risen well above all of them: every question asked of
//! a move reaches at most `max_gap_mm` and two grid cells below it, so clay
//! lower than that is never read again while the path stays up. Where a
//! move does come back down over clay let go, the file gets no verdict
//! ("cannot judge"), naming the cap, rather than one from half the clay.

use super::Checker;
use crate::bead::CHUNK;
use crate::grid::{CELL_XY, CELL_Z};
use crate::replay::Move;
use crate::tops::TopGrid;
use crate::CheckConfig;

/// Beads kept before the oldest may go: 4,194,304, 160 MB. Files of fewer
/// moves keep every bead, as before.
pub(crate) const KEPT_BEADS: usize = 1 << 22;

/// What is let go, and how far below a move its questions reach.
pub(crate) struct Memory {
    /// Beads kept before the oldest chunk may go.
    kept: usize,
    /// The highest clay of each chunk (its beads' tops), by chunk.
    chunk_tops: Vec<f32>,
    /// The highest clay let go, by plan cell; `None` until some is.
    gone: Option<TopGrid>,
    /// How far below a move's lowest point its questions reach (mm), and
    /// how far around it in plan.
    below: f64,
    around: f64,
}

impl Memory {
    pub(crate) fn new(cfg: &CheckConfig, kept: usize) -> Memory {
        Memory {
            kept: kept.max(CHUNK),
            chunk_tops: Vec::new(),
            gone: None,
            // The support and gap searches reach `max_gap_mm` below a
            // bead's middle; the grid hands over whole cells (2 mm high);
            // a bead's top is at most a cell above its low end. One more
            // cell of margin.
            below: cfg.max_gap_mm.max(0.0) + 3.0 * CELL_Z,
            // The widest box a question asks for (the nozzle's reach, the
            // wider support search), and a cell.
            around: (cfg.nozzle_radius + cfg.width_max).max(2.0 * cfg.width_max) + CELL_XY,
        }
    }

    /// Whether move `m`'s questions may reach clay let go.
    pub(crate) fn reaches_let_go(&self, m: &Move) -> bool {
        let Some(gone) = &self.gone else {
            return false;
        };
        let low = m.from[2].min(m.to[2]) - self.below;
        let lo = [
            m.from[0].min(m.to[0]) - self.around,
            m.from[1].min(m.to[1]) - self.around,
        ];
        let hi = [
            m.from[0].max(m.to[0]) + self.around,
            m.from[1].max(m.to[1]) + self.around,
        ];
        f64::from(gone.block_max(gone.range(lo, hi))) >= low
    }

    /// Notes bead `id`'s top in its chunk's.
    fn laid(&mut self, id: usize, top: f32) {
        let c = id / CHUNK;
        if c == self.chunk_tops.len() {
            self.chunk_tops.push(f32::NEG_INFINITY);
        }
        self.chunk_tops[c] = self.chunk_tops[c].max(top);
    }
}

impl Checker<'_> {
    /// After bead `m` is laid: notes its top, and lets the oldest chunk
    /// go if more than the cap are kept and all its clay lies lower than
    /// any question of a move at `m`'s height reaches.
    pub(super) fn let_go(&mut self, m: &Move) {
        let id = self.beads.len() - 1;
        let top = self.beads[id].top32();
        self.memory.laid(id, top);
        if self.beads.kept() < self.memory.kept + CHUNK {
            return;
        }
        let Some((first, chunk)) = self.beads.oldest() else {
            return;
        };
        let end = first + chunk.len();
        let below = m.from[2].min(m.to[2]) - self.memory.below;
        if f64::from(self.memory.chunk_tops[first / CHUNK]) >= below - CELL_Z {
            return;
        }
        // Whatever reads beads in order has read these: the settled tops
        // (support and collisions) and the blocks of the full search.
        if self.support_settled < end {
            return;
        }
        let last_s = chunk.last().map_or(0.0, |b| b.s_end);
        self.grid.settle(&self.beads, |b| b.s_end <= last_s);
        self.grid.raise_settled(&self.beads);
        if self.grid.settled < end {
            return;
        }
        for k in self.blocks.len()..end {
            let b = &self.beads[k];
            self.blocks
                .push(&crate::blocks::Bound::bead(b.from32, b.to32, b.width32));
        }
        let gone = self.memory.gone.get_or_insert_with(|| {
            TopGrid::new(
                [self.cfg.build_volume[0], self.cfg.build_volume[1]],
                CELL_XY,
            )
        });
        for b in chunk {
            gone.raise(b);
        }
        self.beads.evict_oldest();
        self.grid.forget_before(self.beads.first_kept() as u32);
    }

    /// One 4 × 4 × 2 mm cell holds more beads than a question may read
    /// ([`crate::grid::MAX_CELL_BEADS`]): no verdict from here on.
    pub(super) fn cell_full(&mut self, line: usize, at: [f64; 3]) {
        self.deep = false;
        self.replayer.cannot_judge.get_or_insert((
            line,
            format!(
                "more than {} moves of clay within one {} × {} × {} mm cell (x {:.0}–{:.0}, y {:.0}–{:.0}, z {:.0}–{:.0} mm): no clay print lays that many in one place (a dozen passes of a few moves), and the check reads a bounded number of them",
                crate::grid::MAX_CELL_BEADS,
                crate::grid::CELL_XY,
                crate::grid::CELL_XY,
                crate::grid::CELL_Z,
                at[0],
                at[0] + crate::grid::CELL_XY,
                at[1],
                at[1] + crate::grid::CELL_XY,
                at[2],
                at[2] + crate::grid::CELL_Z,
            ),
        ));
    }

    /// A move comes back down over clay let go: no verdict from here on.
    pub(super) fn cannot_follow(&mut self, m: &Move) {
        self.deep = false;
        self.replayer.cannot_judge.get_or_insert((
            m.line,
            format!(
                "the path comes back down over clay laid {} or more beads earlier, which the check lets go to keep its memory bounded (it keeps the newest {} beads once the path has risen {:.1} mm above the rest)",
                self.memory.kept, self.memory.kept, self.memory.below
            ),
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testkit::*;

    #[test]
    fn a_tall_spiral_keeps_a_bounded_number_of_beads() {
        // 300 turns of 126 beads (37,800), keeping at least one chunk: the
        // beads kept stay within the cap and two chunks, and the spiral
        // prints as it does keeping all.
        let mut g = G::new([120.0, 60.0, 0.5 * LAYER]);
        spiral(&mut g, (100.0, 60.0), 20.0, 300, 0.5 * LAYER);
        let per = 126;
        let cfg = CheckConfig {
            min_layer_mm: 0.3,
            ..CheckConfig::default()
        };
        let mut w = crate::CheckWriter::new(&cfg);
        w.checker.memory = Memory::new(&cfg, 1);
        std::io::Write::write_all(&mut w, g.out.as_bytes()).unwrap();
        let (laid, kept) = (w.checker.beads.len(), w.checker.beads.kept());
        let r = w.finish();
        assert_eq!(laid, 300 * per);
        assert!(kept <= 3 * CHUNK, "{kept} of {laid} beads kept");
        assert!(r.printable, "{}", r.render());
        assert_eq!(
            serde_json::to_string(&r).unwrap(),
            serde_json::to_string(&check(&g.out, &cfg)).unwrap()
        );
    }
}
