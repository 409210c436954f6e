//! The bead grid: every deposited bead (its centreline, width and path
//! distance) and, for each 4 × 4 × 2 mm cell, a list of the runs of
//! consecutive beads that pass through it, so a question about a
//! neighbourhood reads a few cells, not every earlier bead
//! (docs/CHECKER.md, "Speed").

use crate::bead::{Bead, Beads};
use crate::geom::cell;
use crate::tops::TopGrid;
use crate::CheckConfig;

pub(crate) const CELL_XY: f64 = 4.0;
pub(crate) const CELL_Z: f64 = 2.0;

/// Passes of the path through one cell that a question reads, newest
/// first. A clay print lays a few in a 4 × 4 × 2 mm cell (beads of 1.5 mm
/// and more, layers of 0.3 mm and more: a dozen); more is clay stacked
/// at one place (the same ring laid hundreds of times), which fails
/// as clay on clay from its second pass. Reading only the newest keeps
/// every question's cost bounded, so such a file checks in linear time
/// (docs/CHECKER.md, "Bounded cost").
pub(crate) const MAX_CELL_RUNS: usize = 32;

/// Beads one cell may hold before the check stops judging the file
/// ("cannot judge", naming the place): a clay print lays a dozen passes
/// of a few beads there (the corpus's files at most 33, a design sampled
/// every 0.02 mm 709; docs/CHECKER.md, "Bounded cost").
/// A question reads a cell's beads, so the cap bounds what each costs.
pub(crate) const MAX_CELL_BEADS: u32 = 4096;

/// Cells are indexed over the build volume with a margin of this many
/// cells a side; clay beyond is counted in the border cells, whose lists
/// only grow by it (every reader tests each bead's geometry).
const MARGIN_CELLS: i32 = 8;

/// Cells a side of the bead lists, at most (4 m in plan, 8 m high); a
/// larger build volume shares the border cells.
const MAX_CELLS: [i32; 3] = [1024, 1024, 4096];

pub(crate) struct BeadGrid {
    /// Each cell's list of beads, newest first: the index of its first
    /// entry in `links` (`u32::MAX`: empty). A plan column's cells, bottom
    /// to top, are allocated when a bead first reaches it.
    pub(crate) columns: Vec<Box<[u32]>>,
    /// Cells a side: x, y, z (the first at `-MARGIN_CELLS`).
    pub(crate) dims: [i32; 3],
    /// List entries: a run of consecutive beads, one pass of the path
    /// through the cell. One array instead of a vector per cell.
    pub(crate) links: Vec<Run>,
    /// Beads `..settled` are settled: far enough back along the path that
    /// the nozzle is no longer laying them (see [`BeadGrid::settle`]).
    pub(crate) settled: usize,
    /// The highest top of every settled bead.
    pub(crate) settled_top: f32,
    /// Highest clay top in each plan column of the settled beads
    /// `..raised`; the others wait until a query reads the columns
    /// ([`BeadGrid::settled_near`]).
    pub(crate) settled_max: TopGrid,
    pub(crate) raised: usize,
    /// Beads before it are let go.
    pub(crate) first_kept: u32,
}

/// Cell ranges of a bead: plan x, plan y, z (inclusive).
type Span = ([i32; 2], [i32; 2], [i32; 2]);

/// An entry of a cell's list: beads `first..=last` and the index of the
/// next entry in `BeadGrid::links` (`u32::MAX` ends the list).
#[derive(Clone, Copy)]
pub(crate) struct Run {
    pub(crate) first: u32,
    pub(crate) last: u32,
    pub(crate) next: u32,
    /// Beads laid in the cell up to this run's last, all runs counted.
    pub(crate) total: u32,
}

impl BeadGrid {
    pub(crate) fn new(cfg: &CheckConfig) -> BeadGrid {
        let plate = [cfg.build_volume[0], cfg.build_volume[1]];
        let dims = [0, 1, 2].map(|a| {
            let size = if a == 2 { CELL_Z } else { CELL_XY };
            let v = cfg.build_volume[a];
            let inside = if v.is_finite() {
                cell(v.max(0.0), size)
            } else {
                0
            };
            (inside + 1 + 2 * MARGIN_CELLS).clamp(1, MAX_CELLS[a])
        });
        BeadGrid {
            columns: vec![Box::default(); (dims[0] * dims[1]) as usize],
            dims,
            links: Vec::new(),
            settled: 0,
            settled_top: f32::NEG_INFINITY,
            settled_max: TopGrid::new(plate, CELL_XY),
            raised: 0,
            first_kept: 0,
        }
    }

    /// Beads before `first` are let go (docs/CHECKER.md, "Bounded
    /// memory"): no run hands them out again.
    pub(crate) fn forget_before(&mut self, first: u32) {
        self.first_kept = first;
    }

    /// Raises the settled beads not yet in the settled column tops into
    /// them (before the oldest beads are let go, so the tops keep them).
    pub(crate) fn raise_settled(&mut self, beads: &Beads) {
        for k in self.raised..self.settled {
            if let Some(b) = beads.get(k) {
                self.settled_max.raise(b);
            }
        }
        self.raised = self.raised.max(self.settled);
    }

    /// The cells a bead spans: plan x and y ranges and z range, or
    /// `None` for a move so long (other slicers) that indexing it would
    /// exhaust memory.
    #[inline]
    pub(crate) fn span(b: &Bead) -> Option<Span> {
        let (from, to) = (b.from(), b.to());
        let x = [
            cell(from[0].min(to[0]), CELL_XY),
            cell(from[0].max(to[0]), CELL_XY),
        ];
        let y = [
            cell(from[1].min(to[1]), CELL_XY),
            cell(from[1].max(to[1]), CELL_XY),
        ];
        let z = [
            cell(from[2].min(to[2]), CELL_Z),
            cell(from[2].max(to[2]), CELL_Z),
        ];
        let n = (x[1] - x[0] + 1) as i64 * (y[1] - y[0] + 1) as i64 * (z[1] - z[0] + 1) as i64;
        (n <= 100_000).then_some((x, y, z))
    }

    /// A cell range on axis `a` as indices into the grid (inclusive),
    /// clamped into it.
    #[inline]
    pub(crate) fn clamp(&self, a: usize, r: [i32; 2]) -> [usize; 2] {
        r.map(|v| (v.saturating_add(MARGIN_CELLS)).clamp(0, self.dims[a] - 1) as usize)
    }

    /// Adds bead `id` to the lists of the cells it spans. Returns the
    /// lowest corner of a cell inside the grid's border that now holds
    /// more than [`MAX_CELL_BEADS`] beads (the first time one does).
    #[inline]
    pub(crate) fn insert(&mut self, b: &Bead, id: u32) -> Option<[f64; 3]> {
        let (xs, ys, zs) = Self::span(b)?;
        let mut full = None;
        let (xs, ys, zs) = (self.clamp(0, xs), self.clamp(1, ys), self.clamp(2, zs));
        let (nx, nz) = (self.dims[0] as usize, self.dims[2] as usize);
        for y in ys[0]..ys[1] + 1 {
            for x in xs[0]..xs[1] + 1 {
                let column = &mut self.columns[y * nx + x];
                if column.is_empty() {
                    *column = vec![u32::MAX; nz].into_boxed_slice();
                }
                for (z, head) in column[zs[0]..zs[1] + 1].iter_mut().enumerate() {
                    let total = match self.links.get_mut(*head as usize) {
                        // The path is still in the cell: its run goes on.
                        Some(run) if run.last.checked_add(1) == Some(id) => {
                            run.last = id;
                            run.total += 1;
                            run.total
                        }
                        before => {
                            let total = before.map_or(0, |r| r.total) + 1;
                            self.links.push(Run {
                                first: id,
                                last: id,
                                next: *head,
                                total,
                            });
                            *head = self.links.len() as u32 - 1;
                            total
                        }
                    };
                    let cellv = [x, y, zs[0] + z];
                    // Border cells gather all clay beyond the grid: they
                    // fill by what is out of bounds, not by stacking.
                    let inside =
                        (0..3).all(|a| cellv[a] > 0 && cellv[a] + 1 < self.dims[a] as usize);
                    if total == MAX_CELL_BEADS + 1 && inside && full.is_none() {
                        full = Some(cellv);
                    }
                }
            }
        }
        full.map(|c| {
            let size = [CELL_XY, CELL_XY, CELL_Z];
            [0, 1, 2].map(|a| (c[a] as f64 - f64::from(MARGIN_CELLS)) * size[a])
        })
    }

    /// Settles the beads from the frontier on that are `done` (they are
    /// in path order): they count in the highest settled top at once, in
    /// the column tops only when a query reads them. A print laid bottom
    /// up keeps its settled clay below the nozzle's tip, so its probes
    /// never read the columns, which saves a raise a bead
    /// (docs/PERFORMANCE.md, "The checker's micro-choices").
    pub(crate) fn settle(&mut self, beads: &Beads, done: impl Fn(&Bead) -> bool) {
        let top = &mut self.settled_top;
        settle(beads, &mut self.settled, done, |_, b| {
            *top = top.max(b.top32());
        });
    }

    /// The runs of beads in the cells within `r` (plan) of `p` and
    /// heights `zlo..=zhi`, newest first in each cell.
    pub(crate) fn in_box(&self, p: [f64; 3], r: f64, zlo: f64, zhi: f64, mut f: impl FnMut(&Run)) {
        let xs = [cell(p[0] - r, CELL_XY), cell(p[0] + r, CELL_XY)];
        let ys = [cell(p[1] - r, CELL_XY), cell(p[1] + r, CELL_XY)];
        self.visit_runs(xs, ys, [cell(zlo, CELL_Z), cell(zhi, CELL_Z)], &mut f);
    }

    /// [`BeadGrid::in_box`], but only in plan columns whose settled clay
    /// reaches `zlo` (for a query that skips beads not settled; `beads`
    /// are all the beads).
    pub(crate) fn settled_near(
        &mut self,
        beads: &Beads,
        p: [f64; 3],
        r: f64,
        zlo: f64,
        zhi: f64,
        mut f: impl FnMut(u32),
    ) {
        // Most queries of a print laid bottom up: no settled clay that
        // high anywhere.
        if f64::from(self.settled_top) < zlo {
            return;
        }
        self.raise_settled(beads);
        let (z0, z1) = (cell(zlo, CELL_Z), cell(zhi, CELL_Z));
        let (lo, hi) = ([p[0] - r, p[1] - r], [p[0] + r, p[1] + r]);
        let tops = &self.settled_max;
        // The column tops first (a load each); the bead lists of a column
        // only when its clay reaches `zlo`.
        let (gxs, gys) = tops.range(lo, hi);
        if f64::from(tops.block_max((gxs, gys))) < zlo {
            return;
        }
        for gy in gys[0]..gys[1] + 1 {
            for gx in gxs[0]..gxs[1] + 1 {
                let top = f64::from(tops.top[gy * tops.n[0] + gx]);
                if top < zlo {
                    continue;
                }
                // The `CELL_XY` columns of this one inside the query box.
                let (x0, x1) = tops.clip(gx, 0, lo[0], hi[0]);
                let (y0, y1) = tops.clip(gy, 1, lo[1], hi[1]);
                let xs = [cell(x0, CELL_XY), cell(x1, CELL_XY)];
                let ys = [cell(y0, CELL_XY), cell(y1, CELL_XY)];
                self.visit(xs, ys, [z0, z1.min(cell(top, CELL_Z))], &mut f);
            }
        }
    }

    /// Ids in the cells of ranges `xs`, `ys`, `zs` (inclusive, whole
    /// cells, clamped into the grid), newest first in each cell.
    pub(crate) fn visit(&self, xs: [i32; 2], ys: [i32; 2], zs: [i32; 2], f: &mut impl FnMut(u32)) {
        self.visit_runs(xs, ys, zs, &mut |run| {
            (run.first..=run.last).rev().for_each(&mut *f)
        });
    }

    /// The runs of beads in the cells of ranges `xs`, `ys`, `zs`
    /// (inclusive, whole cells, clamped into the grid), newest first in
    /// each cell.
    pub(crate) fn visit_runs(
        &self,
        xs: [i32; 2],
        ys: [i32; 2],
        zs: [i32; 2],
        f: &mut impl FnMut(&Run),
    ) {
        if zs[0] > zs[1] {
            return;
        }
        let (xs, ys, zs) = (self.clamp(0, xs), self.clamp(1, ys), self.clamp(2, zs));
        for y in ys[0]..ys[1] + 1 {
            for x in xs[0]..xs[1] + 1 {
                let column = &self.columns[y * self.dims[0] as usize + x];
                for &head in column.get(zs[0]..zs[1] + 1).unwrap_or_default() {
                    let mut e = head;
                    let mut n = 0;
                    while let Some(run) = self.links.get(e as usize) {
                        // Newest first: past a run of beads let go, all are.
                        if n == MAX_CELL_RUNS || run.last < self.first_kept {
                            break;
                        }
                        if run.first < self.first_kept {
                            f(&Run {
                                first: self.first_kept,
                                ..*run
                            });
                        } else {
                            f(run);
                        }
                        e = run.next;
                        n += 1;
                    }
                }
            }
        }
    }
}

/// Moves a settled frontier on: hands each bead from `*next` on that is
/// `done` (they are in path order) to `f` with its index.
pub(crate) fn settle(
    beads: &Beads,
    next: &mut usize,
    done: impl Fn(&Bead) -> bool,
    mut f: impl FnMut(u32, &Bead),
) {
    while let Some(b) = beads.get(*next).filter(|b| done(b)) {
        f(*next as u32, b);
        *next += 1;
    }
}
