//! The checks: continuity, bounds, collision and support, from the replayed
//! moves. Beads are kept in a grid of 4 × 4 × 2 mm cells so each question
//! ("what clay is below this bead?", "is clay inside the nozzle cylinder?")
//! looks at a few cells, not at every earlier bead; a cell lists runs of
//! consecutive beads, and where a cell holds many (a finely sampled path)
//! the support search skips whole blocks of them by their bounds
//! ([`crate::blocks`]).

use crate::blocks::{Blocks, Bound, Visit};
use crate::parse::{Diagnostic, Line, LineParser};
use crate::replay::{Event, Move, Replayer};
use crate::report::{Count, Report};
use crate::CheckConfig;

const EPS_E: f64 = 1e-7;
const CELL_XY: f64 = 4.0;
const CELL_Z: f64 = 2.0;

/// A deposited move. Ends and width are kept in single precision (40
/// bytes a bead instead of 72): 15 µm at 400 mm, far below the 1 µm…1 mm
/// of the G-code's own numbers' last digits and the checker's tolerances.
struct Bead {
    from32: [f32; 3],
    to32: [f32; 3],
    width32: f32,
    /// Path distance at the end of the move.
    s_end: f64,
    /// Turnaround step (steeper than 1:2): clay, but no support for others.
    step: bool,
}

impl Bead {
    fn new(from: [f64; 3], to: [f64; 3], width: f64, s_end: f64, step: bool) -> Bead {
        Bead {
            from32: from.map(|v| v as f32),
            to32: to.map(|v| v as f32),
            width32: width as f32,
            s_end,
            step,
        }
    }

    fn from(&self) -> [f64; 3] {
        self.from32.map(f64::from)
    }

    fn to(&self) -> [f64; 3] {
        self.to32.map(f64::from)
    }

    /// The highest point of the centreline.
    fn top32(&self) -> f32 {
        self.from32[2].max(self.to32[2])
    }

    fn width(&self) -> f64 {
        f64::from(self.width32)
    }

    /// Closest point of the bead's centreline (in plan) to `p`:
    /// `(horizontal distance, height there, the point)`.
    fn closest(&self, p: [f64; 3]) -> (f64, f64, [f64; 2]) {
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

/// Length of a plan vector. Not `f64::hypot`: that guards against
/// overflow at a cost this hot loop cannot pay, and an overflow to
/// infinity only makes a distance compare as far.
fn len2(dx: f64, dy: f64) -> f64 {
    (dx * dx + dy * dy).sqrt()
}

/// `floor(v / size)`, clamped to ±10⁸ (NaN to 0). Not `f64::floor`, which
/// without SSE 4.1 is a library call this hot path cannot pay.
fn cell(v: f64, size: f64) -> i32 {
    let q = (v / size).clamp(-1e8, 1e8);
    let t = q as i32;
    if f64::from(t) > q {
        t - 1
    } else {
        t
    }
}

/// Cells are indexed over the build volume with a margin of this many
/// cells a side; clay beyond is counted in the border cells, whose lists
/// only grow by it (every reader tests each bead's geometry).
const MARGIN_CELLS: i32 = 8;

/// Cells a side of the bead lists, at most (4 m in plan, 8 m high); a
/// larger build volume shares the border cells.
const MAX_CELLS: [i32; 3] = [1024, 1024, 4096];

struct BeadGrid {
    /// Each cell's list of beads, newest first: the index of its first
    /// entry in `links` (`u32::MAX`: empty). A plan column's cells, bottom
    /// to top, are allocated when a bead first reaches it.
    columns: Vec<Box<[u32]>>,
    /// Cells a side: x, y, z (the first at `-MARGIN_CELLS`).
    dims: [i32; 3],
    /// List entries: a run of consecutive beads, one pass of the path
    /// through the cell. One array instead of a vector per cell.
    links: Vec<Run>,
    /// Beads `..settled` are settled: far enough back along the path that
    /// the nozzle is no longer laying them (see [`BeadGrid::settle`]).
    settled: usize,
    /// The highest top of every settled bead.
    settled_top: f32,
    /// Highest clay top in each plan column of the settled beads
    /// `..raised`; the others wait until a query reads the columns
    /// ([`BeadGrid::settled_near`]).
    settled_max: TopGrid,
    raised: usize,
}

/// Cell ranges of a bead: plan x, plan y, z (inclusive).
type Span = ([i32; 2], [i32; 2], [i32; 2]);

/// An entry of a cell's list: beads `first..=last` and the index of the
/// next entry in `BeadGrid::links` (`u32::MAX` ends the list).
struct Run {
    first: u32,
    last: u32,
    next: u32,
}

impl BeadGrid {
    fn new(cfg: &CheckConfig) -> BeadGrid {
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
        }
    }

    /// The cells a bead spans: plan x and y ranges and z range, or
    /// `None` for a move so long (other slicers) that indexing it would
    /// exhaust memory.
    fn span(b: &Bead) -> Option<Span> {
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
    fn clamp(&self, a: usize, r: [i32; 2]) -> [usize; 2] {
        r.map(|v| (v.saturating_add(MARGIN_CELLS)).clamp(0, self.dims[a] - 1) as usize)
    }

    fn insert(&mut self, b: &Bead, id: u32) {
        let Some((xs, ys, zs)) = Self::span(b) else {
            return;
        };
        let (xs, ys, zs) = (self.clamp(0, xs), self.clamp(1, ys), self.clamp(2, zs));
        let (nx, nz) = (self.dims[0] as usize, self.dims[2] as usize);
        for y in ys[0]..ys[1] + 1 {
            for x in xs[0]..xs[1] + 1 {
                let column = &mut self.columns[y * nx + x];
                if column.is_empty() {
                    *column = vec![u32::MAX; nz].into_boxed_slice();
                }
                for head in &mut column[zs[0]..zs[1] + 1] {
                    match self.links.get_mut(*head as usize) {
                        // The path is still in the cell: its run goes on.
                        Some(run) if run.last.checked_add(1) == Some(id) => run.last = id,
                        _ => {
                            self.links.push(Run {
                                first: id,
                                last: id,
                                next: *head,
                            });
                            *head = self.links.len() as u32 - 1;
                        }
                    }
                }
            }
        }
    }

    /// Settles the beads from the frontier on that are `done` (they are
    /// in path order): they count in the highest settled top at once, in
    /// the column tops only when a query reads them. A print laid bottom
    /// up keeps its settled clay below the nozzle's tip, so its probes
    /// never read the columns, which saves a raise a bead (7 % of the
    /// instructions of a check).
    fn settle(&mut self, beads: &[Bead], done: impl Fn(&Bead) -> bool) {
        let top = &mut self.settled_top;
        settle(beads, &mut self.settled, done, |_, b| {
            *top = top.max(b.top32());
        });
    }

    /// The runs of beads in the cells within `r` (plan) of `p` and
    /// heights `zlo..=zhi`, newest first in each cell.
    fn in_box(&self, p: [f64; 3], r: f64, zlo: f64, zhi: f64, mut f: impl FnMut(&Run)) {
        let xs = [cell(p[0] - r, CELL_XY), cell(p[0] + r, CELL_XY)];
        let ys = [cell(p[1] - r, CELL_XY), cell(p[1] + r, CELL_XY)];
        self.visit_runs(xs, ys, [cell(zlo, CELL_Z), cell(zhi, CELL_Z)], &mut f);
    }

    /// [`BeadGrid::in_box`], but only in plan columns whose settled clay
    /// reaches `zlo` (for a query that skips beads not settled; `beads`
    /// are all the beads).
    fn settled_near(
        &mut self,
        beads: &[Bead],
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
        for b in &beads[self.raised..self.settled] {
            self.settled_max.raise(b);
        }
        self.raised = self.settled;
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
    fn visit(&self, xs: [i32; 2], ys: [i32; 2], zs: [i32; 2], f: &mut impl FnMut(u32)) {
        self.visit_runs(xs, ys, zs, &mut |run| {
            (run.first..=run.last).rev().for_each(&mut *f)
        });
    }

    /// The runs of beads in the cells of ranges `xs`, `ys`, `zs`
    /// (inclusive, whole cells, clamped into the grid), newest first in
    /// each cell.
    fn visit_runs(&self, xs: [i32; 2], ys: [i32; 2], zs: [i32; 2], f: &mut impl FnMut(&Run)) {
        if zs[0] > zs[1] {
            return;
        }
        let (xs, ys, zs) = (self.clamp(0, xs), self.clamp(1, ys), self.clamp(2, zs));
        for y in ys[0]..ys[1] + 1 {
            for x in xs[0]..xs[1] + 1 {
                let column = &self.columns[y * self.dims[0] as usize + x];
                for &head in column.get(zs[0]..zs[1] + 1).unwrap_or_default() {
                    let mut e = head;
                    while let Some(run) = self.links.get(e as usize) {
                        f(run);
                        e = run.next;
                    }
                }
            }
        }
    }
}

/// Highest clay top in each plan cell of a fixed rectangle (the bed with
/// a margin): a dense array, so a question about a neighbourhood is a few
/// loads. Clay outside the rectangle is counted in its border cells, which
/// keeps every cell's value an upper bound.
struct TopGrid {
    cell: f64,
    /// `1 / cell`, exact: cells are a power of two times `base`.
    inv: f64,
    /// Plan coordinates of the rectangle's low corner.
    origin: [f64; 2],
    n: [usize; 2],
    top: Vec<f32>,
    /// The highest top of each block of 4 × 4 cells (`n / 4` rounded up
    /// a side): most questions are answered by a block or two.
    coarse: Vec<f32>,
    /// Blocks a row.
    bx: usize,
    /// The widest bead raised.
    widest: f32,
}

impl TopGrid {
    /// A grid over `0..extent` in x and y plus a margin of 8 cells, with
    /// cells a power-of-two multiple of `base` mm (so each cell of a `base`
    /// grid lies in one of them) and at most 1016 a side.
    fn new(extent: [f64; 2], base: f64) -> TopGrid {
        let extent = extent.map(|v| {
            if v.is_finite() {
                v.clamp(1.0, 1e6)
            } else {
                1.0
            }
        });
        let cell = base
            * (extent[0].max(extent[1]) / (1000.0 * base))
                .log2()
                .ceil()
                .max(0.0)
                .exp2();
        let margin = 8.0 * cell;
        let n = extent.map(|v| ((v + 2.0 * margin) / cell).ceil() as usize);
        TopGrid {
            cell,
            inv: 1.0 / cell,
            origin: [-margin, -margin],
            n,
            top: vec![f32::NEG_INFINITY; n[0] * n[1]],
            coarse: vec![f32::NEG_INFINITY; n[0].div_ceil(4) * n[1].div_ceil(4)],
            bx: n[0].div_ceil(4),
            widest: 0.0,
        }
    }

    /// Cell index along axis `a`, clamped into the rectangle.
    fn index(&self, v: f64, a: usize) -> usize {
        // `as` truncates toward zero and saturates (NaN to 0), which is the
        // floor for every cell index but the first; to `i32`, which is a
        // few instructions less than to `usize` (n is at most 1016).
        let c = ((v - self.origin[a]) * self.inv) as i32;
        c.clamp(0, self.n[a] as i32 - 1) as usize
    }

    /// Cell ranges `[x0, x1], [y0, y1]` (inclusive) of a plan box.
    fn range(&self, lo: [f64; 2], hi: [f64; 2]) -> ([usize; 2], [usize; 2]) {
        (
            [self.index(lo[0], 0), self.index(hi[0], 0)],
            [self.index(lo[1], 1), self.index(hi[1], 1)],
        )
    }

    fn raise_box(&mut self, (xs, ys): ([usize; 2], [usize; 2]), top: f32) {
        let nx = self.n[0];
        for y in ys[0]..ys[1] + 1 {
            for v in &mut self.top[y * nx + xs[0]..y * nx + xs[1] + 1] {
                *v = larger(*v, top);
            }
        }
        for row in self.blocks((xs, ys)) {
            for v in &mut self.coarse[row] {
                *v = larger(*v, top);
            }
        }
    }

    /// The blocks of 4 × 4 cells that hold cells `xs`, `ys` (inclusive):
    /// a range of `coarse` a row.
    fn blocks(
        &self,
        (xs, ys): ([usize; 2], [usize; 2]),
    ) -> impl Iterator<Item = std::ops::Range<usize>> + use<> {
        let bx = self.bx;
        (ys[0] / 4..ys[1] / 4 + 1).map(move |y| y * bx + xs[0] / 4..y * bx + xs[1] / 4 + 1)
    }

    /// The highest top in cells `xs`, `ys` (inclusive) or a little beyond:
    /// the blocks of 4 × 4 cells that hold them.
    fn block_max(&self, cells: ([usize; 2], [usize; 2])) -> f32 {
        let mut m = f32::NEG_INFINITY;
        for row in self.blocks(cells) {
            for &v in &self.coarse[row] {
                m = m.max(v);
            }
        }
        m
    }

    /// Raises the cells a bead's centreline passes through to its top:
    /// the cells of its plan bounding box, or for a long slanting move
    /// (other slicers) the cells around points every half cell along it.
    fn raise(&mut self, b: &Bead) {
        let (f, t) = (b.from(), b.to());
        let top = b.top32();
        self.widest = self.widest.max(b.width32);
        let (xs, ys) = self.range(
            [f[0].min(t[0]), f[1].min(t[1])],
            [f[0].max(t[0]), f[1].max(t[1])],
        );
        // Most beads: three cells a side or fewer, so two blocks a side at
        // most. Their cells and blocks without the loops of raise_box: the
        // first and last of each side (some perhaps the same), and, for a
        // third cell, the middle one. Check of the 44k text 12.39–12.47 ms
        // against 12.78–12.96 with loops over the cells and blocks (min of
        // 40, alternated); raising nine fixed cells for every bead instead
        // chained each store to the next load where beads lie in one cell
        // (1M: 1–2 % slower).
        if xs[1] - xs[0] <= 2 && ys[1] - ys[0] <= 2 {
            let nx = self.n[0];
            for (x, y) in [
                (xs[0], ys[0]),
                (xs[1], ys[0]),
                (xs[0], ys[1]),
                (xs[1], ys[1]),
            ] {
                self.top[y * nx + x] = larger(self.top[y * nx + x], top);
                let c = &mut self.coarse[y / 4 * self.bx + x / 4];
                *c = larger(*c, top);
            }
            if xs[1] - xs[0] == 2 || ys[1] - ys[0] == 2 {
                let (xm, ym) = ((xs[0] + xs[1]) / 2, (ys[0] + ys[1]) / 2);
                for (x, y) in [(xm, ys[0]), (xm, ym), (xm, ys[1]), (xs[0], ym), (xs[1], ym)] {
                    self.top[y * nx + x] = larger(self.top[y * nx + x], top);
                }
            }
            return;
        }
        if (xs[1] - xs[0] + 1) * (ys[1] - ys[0] + 1) <= 16 {
            return self.raise_box((xs, ys), top);
        }
        let len = len2(t[0] - f[0], t[1] - f[1]);
        let steps = ((2.0 * len / self.cell).ceil() as usize).min(1 << 20);
        for k in 0..=steps {
            let u = k as f64 / steps as f64;
            let p = [f[0] + u * (t[0] - f[0]), f[1] + u * (t[1] - f[1])];
            // Every point of the centreline is within half a cell of one
            // of these, so in its cell or a neighbour.
            let r = 0.5 * self.cell;
            let cells = self.range([p[0] - r, p[1] - r], [p[0] + r, p[1] + r]);
            self.raise_box(cells, top);
        }
    }

    /// The part of `lo..hi` on axis `a` inside cell `g` (its upper edge
    /// excluded); a border cell also holds the clay beyond the border, so
    /// its side is not cut there.
    fn clip(&self, g: usize, a: usize, lo: f64, hi: f64) -> (f64, f64) {
        let edge = self.origin[a] + g as f64 * self.cell;
        (
            if g == 0 { lo } else { lo.max(edge) },
            if g + 1 == self.n[a] {
                hi
            } else {
                hi.min(edge + self.cell - 1e-9)
            },
        )
    }

    /// The cell's plan rectangle `[x0, y0, x1, y1]`.
    fn rect(&self, x: usize, y: usize) -> [f64; 4] {
        let x0 = self.origin[0] + x as f64 * self.cell;
        let y0 = self.origin[1] + y as f64 * self.cell;
        [x0, y0, x0 + self.cell, y0 + self.cell]
    }
}

/// `a.max(b)` for an `a` that is not NaN (a running maximum, from `-inf`
/// or 0): the same value, by one compare, where `f32::max` and `f64::max`
/// add a NaN test.
#[inline(always)]
fn larger<T: PartialOrd>(a: T, b: T) -> T {
    if a < b {
        b
    } else {
        a
    }
}

/// `a.min(b)` for an `a` that is not NaN (a running minimum): see
/// [`larger`].
#[inline(always)]
fn smaller<T: PartialOrd>(a: T, b: T) -> T {
    if b < a {
        b
    } else {
        a
    }
}

/// Plan distance from `p` to a rectangle `[x0, y0, x1, y1]` (0 inside; 0
/// for a NaN `p`).
pub(crate) fn rect_distance(r: [f64; 4], p: [f64; 2]) -> f64 {
    let dx = (r[0] - p[0]).max(p[0] - r[2]).max(0.0);
    let dy = (r[1] - p[1]).max(p[1] - r[3]).max(0.0);
    len2(dx, dy)
}

/// A bead below a new bead: height at its point nearest to the new bead's
/// middle, that point, the horizontal distance to it, its width, and
/// whether its footprint (a capsule: centreline ± w/2) covers the middle.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    /// The bead's index.
    id: u32,
    z: f64,
    at: [f64; 2],
    d: f64,
    width: f64,
    covers: bool,
}

impl Candidate {
    /// Order by distance, ties (the shared end of two beads) to the
    /// earlier bead.
    fn nearer(&self, o: &Candidate) -> std::cmp::Ordering {
        self.d.total_cmp(&o.d).then(self.id.cmp(&o.id))
    }
}

/// The bead a new bead rests on. Under a bead, earlier passes form a stack
/// of ridges; it rests on the top of the stack nearest its centreline.
/// Start from the candidate nearest the middle among those whose footprint
/// covers it (if none does: the bed when `near_bed`, else the nearest
/// candidate, an overhang); while another candidate is higher
/// by at least `min_layer` and steeper than 1:2 from it, move up to it. A
/// step up a stack is steep (leaning walls keep rise ≥ 0.65 × run within
/// the overhang limit); a step along one tilted ridge is gentle, so the
/// walk climbs stacks without sliding along ridges.
fn pick_support(cands: &[Candidate], min_layer: f64, near_bed: bool) -> Option<Candidate> {
    let covering = cands.iter().any(|c| c.covers);
    if !covering && near_bed {
        // Nothing under its middle but the bed, which is within reach.
        return None;
    }
    let group: Vec<&Candidate> = cands.iter().filter(|c| c.covers == covering).collect();
    let mut best = **group.iter().min_by(|a, b| a.nearer(b))?;
    loop {
        let next = group
            .iter()
            .filter(|c| {
                let rise = c.z - best.z;
                rise >= min_layer && rise >= 0.5 * len2(c.at[0] - best.at[0], c.at[1] - best.at[1])
            })
            .min_by(|a, b| a.nearer(b));
        match next {
            Some(c) => best = **c,
            None => return Some(best),
        }
    }
}

/// What an earlier bead is to a new one.
enum Class {
    /// Clay below that may support it.
    Below(Candidate),
    /// Clay already at its height under its middle.
    Double,
    /// Neither: too far, too deep, above it, a step, or behind the nozzle.
    Neither,
}

/// A new bead whose support is sought: its move, its middle and the path
/// distance where it starts.
struct Query<'a> {
    m: &'a Move,
    mid: [f64; 3],
    s_start: f64,
    cfg: &'a CheckConfig,
}

impl Query<'_> {
    /// Judges earlier bead `b` (index `j`) against the new bead.
    /// Inlined into each of its callers (the shortcut, both searches):
    /// called from four places the compiler stops inlining it, which
    /// cost 5 % more instructions a check at 1M samples (callgrind:
    /// 3,953 M against 3,752 M; 44k: 166 M against 160 M).
    #[inline(always)]
    fn classify(&self, b: &Bead, j: u32) -> Class {
        let Query {
            m,
            mid,
            s_start,
            cfg,
        } = *self;
        if b.step || b.s_end >= s_start - 1e-9 {
            return Class::Neither;
        }
        let (d, z, at) = b.closest(mid);
        // A bead laid earlier in this run lies behind the nozzle, not below
        // it: little more path than the distance lies between them, and the
        // new bead clearly moves away from it (its middle ≥ 0.1 mm farther
        // from it than its start) or starts less than 0.5 mm above it (round
        // a sharp corner it may turn back toward it). A bead below that the
        // path returns over after a turn or a step-up is approached (or
        // passed alongside) and a layer down; a bead laid again right on top
        // of an earlier one (d ≈ 0) is neither.
        let from_end = len2(m.from[0] - at[0], m.from[1] - at[1]);
        if s_start - b.s_end <= 1.5 * d + 1e-6 && (d > from_end + 0.1 || m.from[2] - z < 0.5) {
            return Class::Neither;
        }
        if z <= mid[2] - cfg.min_layer_mm {
            if mid[2] - z <= cfg.max_gap_mm && d <= cfg.width_max.max(b.width() / 2.0) {
                return Class::Below(Candidate {
                    id: j,
                    z,
                    at,
                    d,
                    width: b.width(),
                    covers: d <= b.width() / 2.0,
                });
            }
        } else if (z - mid[2]).abs() < cfg.min_layer_mm
            && d < 0.5 * b.width().min(cfg.width_min)
            // Clay laid in the last 2 w_max of path is the run's own fresh
            // clay (a corner piles up, it is not laid twice).
            && s_start - b.s_end > 2.0 * cfg.width_max
        {
            return Class::Double;
        }
        Class::Neither
    }

    /// Whether none of `beads` (the first has index `first`) is clay below
    /// the new bead: `classify` puts none of them in `Below`. Oldest first,
    /// since clay below in the last stretch of path (the end of the pass
    /// before a reversal) is usually its oldest part.
    fn none_below(&self, beads: &[Bead], first: usize) -> bool {
        beads
            .iter()
            .zip(first as u32..)
            .all(|(b, j)| !matches!(self.classify(b, j), Class::Below(_)))
    }
}

/// An upper bound of `acos c` for `c ≥ 0.5` (a turn under 60°):
/// `√(2(1 − c)) (1 + (1 − c)/6)`, at most 3.5 % over and cheaper than
/// `acos`; π below.
fn turn_bound(c: f64) -> f64 {
    if c >= 0.5 {
        let v = (1.0 - c).max(0.0);
        (2.0 * v).sqrt() * (1.0 + v / 6.0)
    } else {
        std::f64::consts::PI
    }
}

/// The beads laid in the last stretch of path, not yet in the settled
/// tops: their lowest point (a sliding-window minimum: ids and heights both
/// increasing) and how much the path turns among them (in plan, radians; a
/// turnaround or a jump counts π).
#[derive(Default)]
struct Recent {
    low: std::collections::VecDeque<(u32, f32)>,
    /// The turn into each bead of the window, oldest first.
    turns: std::collections::VecDeque<f32>,
    turning: f64,
    /// Plan direction of the last bead and its path end, if it had one.
    last: Option<([f64; 2], f64)>,
}

impl Recent {
    /// The turn from the last bead into a move of plan vector `d` and
    /// length `l` starting at path distance `s_start`, or a little more
    /// ([`turn_bound`]; only sums under 60° matter in `clear_of`, and more
    /// turning only sends a bead to the full search).
    fn turn(&self, d: [f64; 2], l: f64, s_start: f64) -> f64 {
        match self.last {
            Some((u, s)) if l > 1e-9 && (s - s_start).abs() < 1e-9 => {
                turn_bound((u[0] * d[0] + u[1] * d[1]) / l)
            }
            _ => std::f64::consts::PI,
        }
    }

    /// Bead `id` (plan direction `heading` if it has one, ending at path
    /// distance `s_end`, lowest point `low`, turned into by `turn`) joins
    /// the window.
    fn push(&mut self, id: u32, heading: Option<[f64; 2]>, s_end: f64, low: f32, turn: f64) {
        self.turning += turn;
        self.turns.push_back(turn as f32);
        while self.low.back().is_some_and(|r| r.1 >= low) {
            self.low.pop_back();
        }
        self.low.push_back((id, low));
        self.last = heading.map(|u| (u, s_end));
    }

    /// Bead `id`, the oldest in the window, leaves it.
    fn settle(&mut self, id: u32) {
        if self.low.front().is_some_and(|r| r.0 == id) {
            self.low.pop_front();
        }
        if let Some(t) = self.turns.pop_front() {
            self.turning -= f64::from(t);
        }
        if self.turns.is_empty() {
            self.turning = 0.0;
        }
    }

    fn low(&self) -> f64 {
        self.low.front().map_or(f64::INFINITY, |r| f64::from(r.1))
    }

    /// Whether none of these beads can be clay below the new bead `m`
    /// (middle `mid`, turned into by `turn`, `xy` long in plan) for
    /// `classify`. Either all are less than `min_layer` below the middle,
    /// or the path turns less than 60° in plan through them and into `m`. Then each is farther from the middle than
    /// cos 30° ≈ 0.87 × the path between (more than the 1/1.5 `classify`
    /// asks), and `m` runs away from each by more than a quarter of its
    /// length. So, if `m` is longer than 0.45 mm in plan (or all are less
    /// than 0.5 mm below its start), `classify` puts each behind the
    /// nozzle.
    fn clear_of(&self, m: &Move, mid: [f64; 3], min_layer: f64, turn: f64, xy: f64) -> bool {
        let low = self.low();
        low > mid[2] - min_layer
            || ((low > m.from[2] - 0.5 || xy > 0.45)
                && self.turning + turn < std::f64::consts::FRAC_PI_3)
    }
}

/// The support of a new bead found without a search, or `None` when
/// anything about its surroundings is unusual (then the full search of
/// [`pick_support`] decides). Beads rest on the pass below, which runs
/// along under them: from `start`, the support of the bead before, walk
/// along the beads laid around it while they come nearer the middle. The
/// bead found is the answer only if it covers the middle and nothing
/// else could change the full search's answer:
/// - no settled clay near the middle is high enough above it to be
///   climbed to (see `pick_support`) or at the new bead's own height;
/// - none of the clay laid in the last 2 w_max of path can be clay below
///   (the caller asks [`Recent::clear_of`] first, or if its bound does not
///   hold, [`Query::none_below`]).
///
/// `beads[..settled]` are in `tops`. The cost does not depend on how
/// finely the path is sampled.
fn follow_support(
    beads: &[Bead],
    settled: usize,
    tops: &TopGrid,
    start: u32,
    q: &Query,
) -> Option<Candidate> {
    let (mid, cfg) = (q.mid, q.cfg);
    let eval = |k: usize| match beads.get(k) {
        Some(b) if k < settled => match q.classify(b, k as u32) {
            Class::Below(c) => Some(c),
            _ => None,
        },
        _ => None,
    };
    let mut best = eval(start as usize)?;
    for dir in [1isize, -1] {
        let mut k = start as isize;
        let mut moved = false;
        for _ in 0..64 {
            k += dir;
            match usize::try_from(k).ok().and_then(eval) {
                Some(c) if c.nearer(&best).is_lt() => {
                    best = c;
                    moved = true;
                }
                _ => break,
            }
        }
        if moved {
            break;
        }
    }
    if !best.covers {
        return None;
    }
    // The full search's square; wider if a settled bead is so wide that it
    // could cover the middle from farther (other slicers' files).
    let r = (cfg.width_max / 2.0 + 0.5).max(f64::from(tops.widest) / 2.0);
    if r > 2.0 * cfg.width_max {
        return None;
    }
    let (xs, ys) = tops.range([mid[0] - r, mid[1] - r], [mid[0] + r, mid[1] + r]);
    // Most beads: no clay that high in the blocks around.
    let block = f64::from(tops.block_max((xs, ys)));
    if block < best.z + cfg.min_layer_mm && block <= mid[2] - cfg.min_layer_mm {
        return Some(best);
    }
    for y in ys[0]..ys[1] + 1 {
        for x in xs[0]..xs[1] + 1 {
            let top = f64::from(tops.top[y * tops.n[0] + x]);
            // Most cells: clay lower than both tests' thresholds (or none).
            if top < best.z + cfg.min_layer_mm && top <= mid[2] - cfg.min_layer_mm {
                continue;
            }
            let rect = tops.rect(x, y);
            let climb = best.z + cfg.min_layer_mm.max(0.5 * rect_distance(rect, best.at));
            let own = rect_distance(rect, [mid[0], mid[1]]) < 0.5 * cfg.width_min
                && top > mid[2] - cfg.min_layer_mm;
            if top >= climb || own {
                return None;
            }
        }
    }
    Some(best)
}

/// How the support of a bead is found. Each way gives the same answer;
/// the tests hold them to it.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Walk {
    /// The checker's: the shortcut (`follow_support`) where it holds,
    /// else the full search, plain while the beads are few
    /// ([`PLAIN_MAX`]), else pruned.
    Auto,
    /// Always the full search, classifying every bead: the reference.
    Plain,
    /// Always the full search, by questions that skip blocks of beads.
    Pruned,
}

/// Up to this many beads in its cells, the full search classifies each
/// (cheaper than asking blocks when beads are long next to a block).
const PLAIN_MAX: usize = 64;

/// The support of a new bead by the full search (steps 1–4 of
/// docs/CHECKER.md), and whether clay already lies at its height under
/// its middle: every earlier bead in the cells within w_max/2 + 0.5 mm of
/// the middle (within w_max if none of them covers it), judged by
/// [`Query::classify`], then [`pick_support`].
///
/// The cells' beads come as runs of consecutive beads (merged, so each
/// bead once a box; when nothing covers, the wider box holds the first
/// box's beads again, in either walk: a repeated candidate changes no
/// answer). A few are each classified ([`Walk::Plain`]). Many (a
/// finely sampled path) are asked questions instead ([`Walk::Pruned`],
/// [`search_pruned`]), whose cost does not grow with the sampling.
fn search_support(
    beads: &[Bead],
    grid: &BeadGrid,
    blocks: &mut Blocks,
    scratch: &mut Scratch,
    q: &Query,
    walk: Walk,
) -> (Option<Candidate>, bool) {
    let (mid, cfg) = (q.mid, q.cfg);
    let (zlo, zhi) = (mid[2] - cfg.max_gap_mm, mid[2] + cfg.min_layer_mm);
    let Scratch { runs, cands } = scratch;
    runs.clear();
    grid.in_box(mid, cfg.width_max / 2.0 + 0.5, zlo, zhi, |r| {
        runs.push([r.first, r.last])
    });
    merge_runs(runs);
    let wider = |runs: &mut Vec<[u32; 2]>| {
        grid.in_box(mid, cfg.width_max, zlo, zhi, |r| {
            runs.push([r.first, r.last])
        });
        merge_runs(runs);
    };
    let many = runs
        .iter()
        .map(|r| (r[1] - r[0]) as usize + 1)
        .sum::<usize>()
        > PLAIN_MAX;
    if walk == Walk::Pruned || (walk == Walk::Auto && many) {
        // The blocks take the beads laid since the last such search.
        for b in &beads[blocks.len()..] {
            blocks.push(&Bound::bead(b.from32, b.to32, b.width32));
        }
        return search_pruned(beads, blocks, runs, q, wider);
    }
    cands.clear();
    let mut double = false;
    let covered = std::cell::Cell::new(false);
    let mut classify = |j: u32| match q.classify(&beads[j as usize], j) {
        Class::Below(c) => {
            covered.set(covered.get() || c.covers);
            cands.push(c);
        }
        Class::Double => double = true,
        Class::Neither => {}
    };
    let mut classify_runs = |runs: &[[u32; 2]]| {
        runs.iter()
            .for_each(|&[first, last]| (first..=last).for_each(&mut classify))
    };
    classify_runs(runs);
    if !covered.get() {
        // Look wider only when nothing covers (to measure an overhang).
        // The first box's beads come again: the same candidate twice
        // changes no answer of `pick_support`.
        wider(runs);
        classify_runs(runs);
    }
    let support = pick_support(cands, cfg.min_layer_mm, mid[2] <= cfg.first_layer_max_mm);
    (support, double)
}

/// The full search's buffers, kept to reuse their memory.
#[derive(Default)]
struct Scratch {
    runs: Vec<[u32; 2]>,
    cands: Vec<Candidate>,
}

/// Sorts runs of beads and merges those that overlap or touch: each
/// bead once.
fn merge_runs(runs: &mut Vec<[u32; 2]>) {
    runs.sort_unstable_by_key(|r| r[0]);
    let mut n = 0;
    for k in 0..runs.len() {
        let r = runs[k];
        if n > 0 && u64::from(r[0]) <= u64::from(runs[n - 1][1]) + 1 {
            runs[n - 1][1] = runs[n - 1][1].max(r[1]);
        } else {
            runs[n] = r;
            n += 1;
        }
    }
    runs.truncate(n);
}

/// [`search_support`] by questions over `runs` (the first box's; `wider`
/// adds the second's): [`pick_support`]'s steps as "the nearest bead that
/// `classify` puts below with this property": the nearest covering the
/// middle, else the nearest below at all, then each step of the climb.
/// Each question skips the blocks of beads (see [`Blocks`]) whose bounds
/// show that none of theirs can be the answer: too far, too high or too
/// low, too narrow to cover the middle, or not high enough to climb to.
/// The bounds are widened by a margin far above rounding, so a skip never
/// drops an answer.
fn search_pruned(
    beads: &[Bead],
    blocks: &Blocks,
    runs: &mut Vec<[u32; 2]>,
    q: &Query,
    wider: impl FnOnce(&mut Vec<[u32; 2]>),
) -> (Option<Candidate>, bool) {
    let (mid, cfg) = (q.mid, q.cfg);
    let ml = cfg.min_layer_mm;
    let slack = 1e-6
        + 1e-9
            * (mid.iter().fold(0.0f64, |m, v| m.max(v.abs()))
                + cfg.width_max.abs()
                + cfg.max_gap_mm.abs());
    let find = Nearest {
        beads,
        blocks,
        q,
        slack,
    };
    // No bead of the block is in `classify`'s height window for clay
    // below.
    let off_window = |b: &Bound| {
        f64::from(b.lo[2]) - slack > mid[2] - ml
            || mid[2] - (f64::from(b.hi[2]) + slack) > cfg.max_gap_mm
    };
    let no_cover = |b: &Bound, lb: f64| off_window(b) || lb > f64::from(b.half_width);
    let mut double = false;
    let mut cover = find.nearest(runs, no_cover, |c| c.covers, Some(&mut double));
    if cover.is_none() {
        // The first box's beads come again, and still cover nothing.
        wider(runs);
        cover = find.nearest(runs, no_cover, |c| c.covers, Some(&mut double));
    }
    let covering = cover.is_some();
    // The group `pick_support` walks: the covering beads, or if none
    // covers, every bead below.
    let out_of_group = |b: &Bound, lb: f64| {
        if covering {
            no_cover(b, lb)
        } else {
            off_window(b) || lb > cfg.width_max.max(f64::from(b.half_width))
        }
    };
    let mut best = match cover {
        Some(c) => c,
        None if mid[2] <= cfg.first_layer_max_mm => return (None, double),
        None => match find.nearest(runs, out_of_group, |_| true, None) {
            Some(c) => c,
            None => return (None, double),
        },
    };
    loop {
        let climb = |b: &Bound, lb: f64| {
            let rise = f64::from(b.hi[2]) + slack - best.z;
            out_of_group(b, lb) || rise < ml || rise < 0.5 * (b.plan_distance(best.at) - slack)
        };
        let next = find.nearest(
            runs,
            climb,
            |c| {
                let rise = c.z - best.z;
                c.covers == covering
                    && rise >= ml
                    && rise >= 0.5 * len2(c.at[0] - best.at[0], c.at[1] - best.at[1])
            },
            None,
        );
        match next {
            Some(c) => best = c,
            None => return (Some(best), double),
        }
    }
}

/// The questions of [`search_pruned`] over runs of beads.
struct Nearest<'a> {
    beads: &'a [Bead],
    blocks: &'a Blocks,
    q: &'a Query<'a>,
    /// Margin on every bound.
    slack: f64,
}

impl Nearest<'_> {
    /// The nearest bead of `runs` ([`Candidate::nearer`]) that `classify`
    /// puts below and `keep` accepts. Skips the blocks `skip` rejects,
    /// given their bounds and a lower bound of their beads' distances to
    /// the middle, and those no nearer than the nearest found so far.
    /// With `double`, also sets it if a bead of `runs` is
    /// [`Class::Double`] (in the same walk: a block is walked if either
    /// question needs it).
    fn nearest(
        &self,
        runs: &[[u32; 2]],
        skip: impl Fn(&Bound, f64) -> bool,
        keep: impl Fn(&Candidate) -> bool,
        mut double: Option<&mut bool>,
    ) -> Option<Candidate> {
        let (mid, cfg, slack) = (self.q.mid, self.q.cfg, self.slack);
        let ml = cfg.min_layer_mm;
        let mut best: Option<Candidate> = None;
        for &[first, last] in runs {
            self.blocks.scan(first, last, &mut |v| match v {
                Visit::Block(b) => {
                    let lb = b.plan_distance([mid[0], mid[1]]) - slack;
                    !(best.is_some_and(|c| lb > c.d) || skip(b, lb))
                        || double.as_ref().is_some_and(|found| {
                            // A bead at the new bead's height, under its
                            // middle.
                            !**found
                                && lb < 0.5 * cfg.width_min
                                && f64::from(b.hi[2]) + slack > mid[2] - ml
                                && f64::from(b.lo[2]) - slack < mid[2] + ml
                        })
                }
                Visit::Bead(j) => {
                    match self.q.classify(&self.beads[j as usize], j) {
                        Class::Below(c) => {
                            if keep(&c) && best.is_none_or(|o| c.nearer(&o).is_lt()) {
                                best = Some(c);
                            }
                        }
                        Class::Double => {
                            if let Some(found) = double.as_mut() {
                                **found = true;
                            }
                        }
                        Class::Neither => {}
                    }
                    true
                }
            });
        }
        best
    }
}

/// Moves a settled frontier on: hands each bead from `*next` on that is
/// `done` (they are in path order) to `f` with its index.
fn settle(
    beads: &[Bead],
    next: &mut usize,
    done: impl Fn(&Bead) -> bool,
    mut f: impl FnMut(u32, &Bead),
) {
    while let Some(b) = beads.get(*next).filter(|b| done(b)) {
        f(*next as u32, b);
        *next += 1;
    }
}

/// Overlap of a bead of width `wa` with one of width `wb` whose centre is
/// `s` to the side, as a fraction of `wa`.
fn overlap_fraction(wa: f64, wb: f64, s: f64) -> f64 {
    let lo = (-wa / 2.0).max(s - wb / 2.0);
    let hi = (wa / 2.0).min(s + wb / 2.0);
    ((hi - lo).max(0.0) / wa).min(1.0)
}

fn minmax(slot: &mut Option<[(f64, usize); 2]>, v: f64, line: usize) {
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

/// Checks a G-code text. Never panics, whatever the input.
pub fn check(text: &str, cfg: &CheckConfig) -> Report {
    check_with(text, cfg, Walk::Auto)
}

fn check_with(text: &str, cfg: &CheckConfig, walk: Walk) -> Report {
    let mut w = CheckWriter::new(cfg);
    w.checker.walk = walk;
    w.feed(text.as_bytes());
    w.finish()
}

/// [`check`] with the support always found by the full search, never by
/// following the bead below (`follow_support`), and the full search
/// always classifying every bead near the middle: the reference the
/// tests hold the fast path to. The two give the same report.
#[doc(hidden)]
pub fn check_exhaustive(text: &str, cfg: &CheckConfig) -> Report {
    check_with(text, cfg, Walk::Plain)
}

/// [`check_exhaustive`], but with every full search asking blocks of
/// beads however few the beads (`search_pruned`): the tests hold the two
/// to the same report, also on designs too coarse for [`check`] to prune.
#[doc(hidden)]
pub fn check_pruned(text: &str, cfg: &CheckConfig) -> Report {
    check_with(text, cfg, Walk::Pruned)
}

/// Checks G-code read line by line from `input`, holding no more of the
/// text than one line: for files too large to read into memory. Bytes that
/// are not UTF-8 are replaced, as by `String::from_utf8_lossy`.
pub fn check_reader<R: std::io::BufRead>(
    mut input: R,
    cfg: &CheckConfig,
) -> std::io::Result<Report> {
    let mut w = CheckWriter::new(cfg);
    std::io::copy(&mut input, &mut w)?;
    Ok(w.finish())
}

/// Checks G-code as it is written: an `io::Write` that feeds each complete
/// line to the check, so a writer can verify its output in the same pass
/// without keeping it. [`CheckWriter::finish`] gives the report.
pub struct CheckWriter<'a> {
    checker: Checker<'a>,
    partial: Vec<u8>,
}

impl<'a> CheckWriter<'a> {
    /// A check with `cfg`, fed by writing to it.
    pub fn new(cfg: &'a CheckConfig) -> Self {
        Self::with_capacity(cfg, 0)
    }

    /// A check with `cfg` of G-code of about `moves` moves (a writer
    /// knows how many it writes): the per-bead arrays are sized for them
    /// at once instead of growing by doubling, which at millions of moves
    /// holds the old and the new array at once and leaves up to half the
    /// last one unused. More moves than that are fine.
    pub fn with_capacity(cfg: &'a CheckConfig, moves: usize) -> Self {
        let mut checker = Checker::new(cfg);
        checker.reserve(moves);
        CheckWriter {
            checker,
            partial: Vec::new(),
        }
    }

    /// The report on everything written (a last line without a newline
    /// included).
    pub fn finish(mut self) -> Report {
        if !self.partial.is_empty() {
            self.checker.bytes(&self.partial);
        }
        self.checker.finish()
    }

    /// Feeds every complete line of `buf` (after what was left over from
    /// the last write) and keeps the rest.
    fn feed(&mut self, buf: &[u8]) {
        let mut start = 0;
        for nl in memchr::memchr_iter(b'\n', buf) {
            if self.partial.is_empty() {
                self.checker.bytes(&buf[start..nl]);
            } else {
                self.partial.extend_from_slice(&buf[start..nl]);
                self.checker.bytes(&self.partial);
                self.partial.clear();
            }
            start = nl + 1;
        }
        self.partial.extend_from_slice(&buf[start..]);
    }
}

impl std::io::Write for CheckWriter<'_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.feed(buf);
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// A count whose occurrences only count if an extrusion follows them
/// (travel, pauses and collisions between two beads, not after the last).
#[derive(Clone, Copy)]
enum Deferred {
    Travel,
    Pause,
    Nozzle,
    Carriage,
}

/// The check as a state machine fed one line at a time, in one pass: what
/// happens after the first bead is held back until the next bead proves it
/// was not after the last one.
struct Checker<'a> {
    cfg: &'a CheckConfig,
    parser: LineParser,
    line: Line,
    replayer: Replayer,
    diags: Vec<Diagnostic>,
    r: Report,
    /// An extruding move has been seen.
    started: bool,
    in_run: bool,
    pending: Vec<(Deferred, usize, f64)>,
    beads: Vec<Bead>,
    grid: BeadGrid,
    /// Bounds of blocks of consecutive beads, for the full search.
    blocks: Blocks,
    scratch: Scratch,
    s: f64,
    top_z: f64,
    lo: [f64; 3],
    hi: [f64; 3],
    layer_heights: Vec<f64>,
    /// Clay tops of the beads laid more than 2 w_max of path back, in
    /// finer cells, for the support's fast path (`follow_support`).
    support_tops: TopGrid,
    /// Beads `..support_settled` are in `support_tops`.
    support_settled: usize,
    /// The beads laid since (their lowest point, the path's turning).
    recent: Recent,
    /// The bead the last bead rests on.
    prev_support: Option<u32>,
    /// Offset / layer height of the steepest overhang so far, and a ratio
    /// just under the overhang limit's.
    steepest: f64,
    overhang_near: f64,
    /// How supports are found (tests compare the ways).
    walk: Walk,
}

impl<'a> Checker<'a> {
    fn new(cfg: &'a CheckConfig) -> Self {
        Checker {
            cfg,
            parser: LineParser::default(),
            line: Line::empty(),
            replayer: Replayer::default(),
            diags: Vec::new(),
            r: Report::default(),
            started: false,
            in_run: false,
            pending: Vec::new(),
            beads: Vec::new(),
            grid: BeadGrid::new(cfg),
            blocks: Blocks::default(),
            scratch: Scratch::default(),
            s: 0.0,
            top_z: f64::MIN,
            lo: [f64::MAX; 3],
            hi: [f64::MIN; 3],
            layer_heights: Vec::new(),
            support_tops: TopGrid::new([cfg.build_volume[0], cfg.build_volume[1]], 2.0),
            support_settled: 0,
            recent: Recent::default(),
            prev_support: None,
            steepest: f64::NEG_INFINITY,
            overhang_near: 0.999
                * (cfg.max_overhang_deg + cfg.overhang_tolerance_deg)
                    .to_radians()
                    .tan(),
            walk: Walk::Auto,
        }
    }

    /// Room for `moves` beads in every per-bead array, as far as memory
    /// allows (an array that gets none grows as it would have). The bead
    /// lists grow as they go: they hold a run of beads an entry, from
    /// 9 entries a bead (long beads across many cells) down to 0.04
    /// (3 million samples), too wide a range to guess.
    fn reserve(&mut self, moves: usize) {
        // A failed reservation only leaves the growing to `push`.
        let _ = self.beads.try_reserve_exact(moves);
        let _ = self.layer_heights.try_reserve_exact(moves);
        self.blocks.reserve(moves);
    }

    /// A line as bytes, without its `\n`: a `\r` before it is dropped.
    fn bytes(&mut self, mut raw: &[u8]) {
        if raw.last() == Some(&b'\r') {
            raw = &raw[..raw.len() - 1];
        }
        self.r.lines += 1;
        let n = self.r.lines;
        if !self
            .parser
            .parse_bytes(raw, n, &mut self.diags, &mut self.line)
        {
            return;
        }
        match self.replayer.feed(&self.line, &mut self.diags) {
            Some(Event::Pause(line)) if self.started => {
                self.pending.push((Deferred::Pause, line, 0.0));
                self.in_run = false;
            }
            Some(Event::Move(m)) => self.step(&m),
            Some(Event::Pause(_)) | None => {}
        }
    }

    fn defer_or_add(&mut self, extruding: bool, kind: Deferred, line: usize, v: f64) {
        if extruding {
            self.count(kind).add(line, v);
        } else {
            self.pending.push((kind, line, v));
        }
    }

    fn count(&mut self, kind: Deferred) -> &mut crate::report::Count {
        match kind {
            Deferred::Travel => &mut self.r.travel_moves,
            Deferred::Pause => &mut self.r.pauses,
            Deferred::Nozzle => &mut self.r.nozzle_collisions,
            Deferred::Carriage => &mut self.r.carriage_collisions,
        }
    }

    fn step(&mut self, m: &Move) {
        let cfg = self.cfg;
        let is_extruding = m.de > EPS_E;
        let len = m.length();
        // Continuity.
        self.r.moves += 1;
        if m.de < -EPS_E {
            if self.started {
                self.r.retractions.add(m.line, -m.de);
            }
            self.in_run = false;
        } else if is_extruding {
            self.started = true;
            // Whatever happened since the last bead was between beads.
            for (kind, line, v) in std::mem::take(&mut self.pending) {
                self.count(kind).add(line, v);
            }
            self.r.extruding_moves += 1;
            if len == 0.0 {
                self.r.extrusion_without_motion.add(m.line, m.de);
            }
            if !self.in_run {
                self.r.extrusion_runs += 1;
                if self.r.run_starts.len() < 20 {
                    self.r.run_starts.push(m.line);
                }
            }
            self.in_run = true;
        } else if len > 0.0 {
            if self.started {
                self.pending.push((Deferred::Travel, m.line, len));
            }
            self.in_run = false;
        }
        // Bounds.
        let out =
            m.to.iter()
                .zip(cfg.build_volume)
                .fold(0.0f64, |o, (&v, lim)| larger(larger(o, -v), v - lim));
        if out > 1e-3 {
            self.r.out_of_bounds.add(m.line, out);
        }

        // Deposition replay: support and collisions.
        let s_start = self.s;
        self.s += len;
        if m.feed > 0.0 {
            self.r.time_min += len / m.feed;
        }
        if !self.started {
            return;
        }
        let recent_nozzle = cfg.nozzle_radius + cfg.width_max;
        let reach = cfg.nozzle_radius + cfg.width_max / 2.0;
        // Collisions at points every r/2 mm of path (at most 200 a move).
        let every = (cfg.nozzle_radius / 2.0).max(0.5);
        // Path distances are ≥ 0, where truncation is the floor (and no
        // library call).
        let floor = |v: f64| (v as i64) as f64;
        let (first, last) = (floor(s_start / every) + 1.0, floor(self.s / every));
        let probes = (last - first + 1.0).clamp(0.0, 200.0) as usize;
        for k in 0..probes {
            let t = if probes < 200 {
                ((first + k as f64) * every - s_start) / len
            } else {
                (k + 1) as f64 / probes as f64
            };
            let p = [
                m.from[0] + t * (m.to[0] - m.from[0]),
                m.from[1] + t * (m.to[1] - m.from[1]),
                m.from[2] + t * (m.to[2] - m.from[2]),
            ];
            let sp = s_start + t * len;
            // Beads the nozzle has left behind count for collisions.
            self.grid
                .settle(&self.beads, |b| b.s_end <= sp - recent_nozzle);
            if self.top_z > p[2] + cfg.nozzle_height + cfg.collision_tolerance_mm {
                let v = self.top_z - p[2] - cfg.nozzle_height;
                self.defer_or_add(is_extruding, Deferred::Carriage, m.line, v);
            }
            let mut worst: f64 = 0.0;
            let zlo = p[2] + cfg.collision_tolerance_mm;
            let beads = &self.beads;
            self.grid
                .settled_near(beads, p, reach, zlo, p[2] + cfg.nozzle_height, |id| {
                    let b = &beads[id as usize];
                    if b.s_end > sp - recent_nozzle {
                        return;
                    }
                    let (d, z, _) = b.closest(p);
                    if z > zlo && d < cfg.nozzle_radius + b.width() / 2.0 {
                        worst = worst.max(z - p[2]);
                    }
                });
            if worst > 0.0 {
                self.defer_or_add(is_extruding, Deferred::Nozzle, m.line, worst);
            }
        }
        if !is_extruding || len == 0.0 {
            return;
        }
        self.bead(m, len, s_start);
    }

    /// Support analysis of an extruding move, then its bead joins the clay.
    fn bead(&mut self, m: &Move, len: f64, s_start: f64) {
        let cfg = self.cfg;
        let s = self.s;
        let Checker {
            r,
            beads,
            grid,
            blocks,
            scratch,
            top_z,
            lo,
            hi,
            layer_heights,
            support_tops,
            support_settled,
            recent,
            prev_support,
            walk,
            steepest,
            overhang_near,
            ..
        } = self;
        r.path_length_mm += len;
        let volume = m.de / cfg.e_per_mm3;
        r.volume_ml += volume / 1000.0;
        for p in [m.from, m.to] {
            for a in 0..3 {
                lo[a] = smaller(lo[a], p[a]);
                hi[a] = larger(hi[a], p[a]);
            }
        }
        if r.first_layer_z.is_none() {
            r.first_layer_z = Some(m.from[2].max(m.to[2]));
        }
        let rise = (m.to[2] - m.from[2]).abs();
        // The plan vector and length, once for every use below.
        let d = [m.to[0] - m.from[0], m.to[1] - m.from[1]];
        let xy = len2(d[0], d[1]);
        let step = xy <= 2.0 * rise;
        let id = beads.len() as u32;
        let mut width = cfg.width_min;
        let horizon = s_start - 2.0 * cfg.width_max;
        settle(
            beads,
            support_settled,
            |b| b.s_end < horizon,
            |j, b| {
                support_tops.raise(b);
                recent.settle(j);
            },
        );
        let turn = if step {
            std::f64::consts::PI
        } else {
            recent.turn(d, xy, s_start)
        };
        if step {
            r.support.steps += 1;
        } else {
            let mid = [
                0.5 * (m.from[0] + m.to[0]),
                0.5 * (m.from[1] + m.to[1]),
                0.5 * (m.from[2] + m.to[2]),
            ];
            let q = Query {
                m,
                mid,
                s_start,
                cfg,
            };
            // The shortcut needs the clay of the last 2 w_max of path not to
            // be clay below: the bound of `clear_of` says so for most beads;
            // for the rest (reversals, drops) each such bead is asked.
            let fast = prev_support
                .filter(|_| {
                    *walk == Walk::Auto
                        && (recent.clear_of(m, mid, cfg.min_layer_mm, turn, xy)
                            || q.none_below(&beads[*support_settled..], *support_settled))
                })
                .and_then(|j| follow_support(beads, *support_settled, support_tops, j, &q));
            r.support.beads += 1;
            let support = if fast.is_some() {
                fast
            } else {
                let (support, double) = search_support(beads, grid, blocks, scratch, &q, *walk);
                if double {
                    r.support.double_deposition.add(m.line, 0.0);
                }
                support
            };
            *prev_support = support.map(|c| c.id);
            let (dz, overlap, offset) = match support {
                Some(c) => {
                    let dz = mid[2] - c.z;
                    width = volume / (len * dz);
                    (dz, overlap_fraction(width, c.width, c.d), c.d)
                }
                None if mid[2] <= cfg.first_layer_max_mm => {
                    r.support.on_bed += 1;
                    width = volume / (len * mid[2].max(1e-6));
                    (mid[2], 1.0, 0.0)
                }
                None => {
                    r.support.unsupported.add(m.line, mid[2]);
                    (f64::NAN, f64::NAN, 0.0)
                }
            };
            if dz.is_finite() {
                layer_heights.push(dz);
                minmax(&mut r.support.layer_height, dz, m.line);
                minmax(&mut r.support.width, width, m.line);
                let bin = if overlap < 0.5 {
                    0
                } else if overlap < 0.6 {
                    1
                } else if overlap < cfg.overlap_target - 1e-9 {
                    2
                } else if overlap < 0.9 {
                    3
                } else {
                    4
                };
                r.support.overlap_histogram[bin] += 1;
                if r.support.min_overlap.is_none_or(|(v, _)| overlap < v) {
                    r.support.min_overlap = Some((overlap, m.line));
                }
                if overlap < cfg.overlap_min - 1e-9 {
                    r.support.under_min.add(m.line, cfg.overlap_min - overlap);
                }
                if overlap < cfg.overlap_target - 1e-6 {
                    r.support.under_target += 1;
                }
                // The angle (an arc tangent) only when it can matter: a
                // new steepest or one near the limit.
                let ratio = offset / dz;
                if !(ratio <= *steepest && ratio < *overhang_near) {
                    *steepest = steepest.max(ratio);
                    let angle = ratio.atan().to_degrees();
                    if r.support.max_overhang_deg.is_none_or(|(v, _)| angle > v) {
                        r.support.max_overhang_deg = Some((angle, m.line));
                    }
                    if angle > cfg.max_overhang_deg + cfg.overhang_tolerance_deg {
                        r.support.overhang.add(m.line, angle);
                    }
                }
            }
        }
        let bead = Bead::new(
            m.from,
            m.to,
            if width.is_finite() {
                width.clamp(0.0, 1e3)
            } else {
                cfg.width_min
            },
            s,
            step,
        );
        grid.insert(&bead, id);
        let low = bead.from32[2].min(bead.to32[2]);
        let heading = (xy > 1e-9 && !step).then(|| [d[0] / xy, d[1] / xy]);
        recent.push(id, heading, s, low, turn);
        *top_z = top_z.max(m.from[2].max(m.to[2]));
        beads.push(bead);
    }

    fn finish(mut self) -> Report {
        let r = &mut self.r;
        let (lo, hi) = (self.lo, self.hi);
        if r.extruding_moves > 0 {
            r.size_mm = [hi[0] - lo[0], hi[1] - lo[1], hi[2].max(0.0)];
        }
        if !self.layer_heights.is_empty() {
            // The element a sort would put in the middle, in linear time
            // (a total order: the same value as sorting).
            let mid = self.layer_heights.len() / 2;
            let (_, &mut median, _) = self
                .layer_heights
                .select_nth_unstable_by(mid, f64::total_cmp);
            if median > 0.0 {
                r.layers = (hi[2] / median).round() as usize;
            }
        }
        self.diags.sort_by_key(|d| d.line);
        self.diags.truncate(50);
        r.diagnostics = self.diags;
        verdict(r, self.cfg);
        self.r
    }
}

fn verdict(r: &mut Report, cfg: &CheckConfig) {
    let mut f = Vec::new();
    let line = |c: &Count| {
        c.first_line
            .map(|l| format!(" (first at line {l})"))
            .unwrap_or_default()
    };
    if r.extruding_moves == 0 {
        f.push("no extrusion at all".to_string());
    }
    if r.extrusion_runs > 1 {
        f.push(format!(
            "{} separate extrusion runs, must be 1 (the second starts at line {})",
            r.extrusion_runs, r.run_starts[1]
        ));
    }
    for (name, c) in [
        ("travel move(s) after the first bead", &r.travel_moves),
        ("retraction(s)", &r.retractions),
        ("pause(s)", &r.pauses),
        ("extrusion(s) without motion", &r.extrusion_without_motion),
        ("move(s) outside the build volume", &r.out_of_bounds),
        (
            "nozzle collision(s) with printed clay",
            &r.nozzle_collisions,
        ),
        (
            "carriage collision(s) with printed clay",
            &r.carriage_collisions,
        ),
        ("bead(s) with no clay below", &r.support.unsupported),
        (
            "bead(s) laid on clay at their own height",
            &r.support.double_deposition,
        ),
        (
            "bead(s) overlapping the bead below by less than half",
            &r.support.under_min,
        ),
        ("overhang(s) beyond the limit", &r.support.overhang),
    ] {
        if c.count > 0 {
            f.push(format!("{} {name}{}", c.count, line(c)));
        }
    }
    if let Some(z) = r.first_layer_z {
        if z > cfg.first_layer_max_mm {
            f.push(format!(
                "the first bead is {z:.2} mm above the bed (at most {} mm)",
                cfg.first_layer_max_mm
            ));
        }
    }
    r.printable = f.is_empty();
    r.failures = f;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn column_top_blocks_bound_their_cells() {
        // Beads of every length and direction raise a 2 mm grid over a
        // 200 mm bed; each cell must be as high as the beads through it,
        // each block must hold its cells' highest top, and a box's cells
        // must be under the blocks that hold it.
        let mut g = TopGrid::new([200.0, 200.0], 2.0);
        let mut beads = Vec::new();
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut rand = move |hi: f64| (crate::xorshift(&mut seed) % 1_000_000) as f64 / 1e6 * hi;
        for _ in 0..3_000 {
            let from = [rand(260.0) - 30.0, rand(260.0) - 30.0, rand(50.0)];
            let len = if rand(1.0) < 0.9 {
                rand(4.0)
            } else {
                rand(120.0)
            };
            let a = rand(std::f64::consts::TAU);
            let to = [from[0] + len * a.cos(), from[1] + len * a.sin(), from[2]];
            let bead = Bead::new(from, to, 3.0, 0.0, false);
            g.raise(&bead);
            beads.push(bead);
        }
        // Each cell a centreline passes through is at least as high as it,
        // among all the beads and for a bead alone (1–7 mm long: boxes of
        // one to four cells a side).
        let through = |g: &TopGrid, b: &Bead| {
            let (f, t) = (b.from(), b.to());
            for k in 0..=200 {
                let u = f64::from(k) / 200.0;
                let p = [f[0] + u * (t[0] - f[0]), f[1] + u * (t[1] - f[1])];
                let (x, y) = (g.index(p[0], 0), g.index(p[1], 1));
                assert!(g.top[y * g.n[0] + x] >= b.top32(), "{p:?}");
            }
        };
        for b in &beads {
            through(&g, b);
        }
        for _ in 0..300 {
            let mut alone = TopGrid::new([40.0, 40.0], 2.0);
            let from = [rand(30.0), rand(30.0), rand(50.0)];
            let (len, a) = (1.0 + rand(6.0), rand(std::f64::consts::TAU));
            let to = [from[0] + len * a.cos(), from[1] + len * a.sin(), from[2]];
            let b = Bead::new(from, to, 3.0, 0.0, false);
            alone.raise(&b);
            through(&alone, &b);
        }
        for y in 0..g.n[1] {
            for x in 0..g.n[0] {
                let top = g.top[y * g.n[0] + x];
                assert!(g.coarse[y / 4 * g.bx + x / 4] >= top, "{x} {y}");
            }
        }
        for _ in 0..3_000 {
            let (x0, y0) = (rand(g.n[0] as f64) as usize, rand(g.n[1] as f64) as usize);
            let xs = [x0, (x0 + rand(9.0) as usize).min(g.n[0] - 1)];
            let ys = [y0, (y0 + rand(9.0) as usize).min(g.n[1] - 1)];
            let cells = (ys[0]..=ys[1])
                .flat_map(|y| (xs[0]..=xs[1]).map(move |x| (x, y)))
                .map(|(x, y)| g.top[y * g.n[0] + x])
                .fold(f32::NEG_INFINITY, f32::max);
            assert!(g.block_max((xs, ys)) >= cells);
        }
    }

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

    fn cand(z: f64, x: f64, d: f64) -> Candidate {
        Candidate {
            id: 0,
            z,
            at: [x, 0.0],
            d,
            width: 3.0,
            covers: d <= 1.5,
        }
    }

    #[test]
    fn climbs_a_leaning_stack_to_its_top() {
        // Layers 1.2 mm apart, each 0.8 mm further out (a 34° lean); the
        // lowest is nearest the new bead's middle.
        let c = [
            cand(1.2, 0.0, 0.2),
            cand(2.4, 0.8, 0.6),
            cand(3.6, 1.6, 1.4),
        ];
        let s = pick_support(&c, 0.3, false).unwrap();
        assert_eq!(s.z, 3.6);
    }

    #[test]
    fn does_not_slide_along_a_tilted_ridge() {
        // One pass rising 0.3 mm per mm: the bead below is the nearest.
        let c = [
            cand(5.0, 0.0, 0.1),
            cand(5.3, 1.0, 1.0),
            cand(5.6, 2.0, 1.45),
        ];
        let s = pick_support(&c, 0.3, false).unwrap();
        assert_eq!(s.z, 5.0);
    }

    #[test]
    fn bed_when_nothing_covers_and_low() {
        let c = [cand(1.2, 5.0, 5.0)];
        assert!(pick_support(&c, 0.3, true).is_none());
        assert_eq!(pick_support(&c, 0.3, false).unwrap().z, 1.2, "an overhang");
        assert!(pick_support(&[], 0.3, false).is_none());
    }

    #[test]
    fn merged_runs_hold_each_bead_of_the_runs_once() {
        let mut state = 3u64;
        for case in 0..500 {
            let n = case % 40;
            let mut runs: Vec<[u32; 2]> = (0..n)
                .map(|_| {
                    let a = (crate::xorshift(&mut state) % 200) as u32;
                    [a, a + (crate::xorshift(&mut state) % 6) as u32]
                })
                .collect();
            if case == 1 {
                runs.push([u32::MAX - 1, u32::MAX]);
                runs.push([u32::MAX, u32::MAX]);
            }
            let want: std::collections::BTreeSet<u32> =
                runs.iter().flat_map(|r| r[0]..=r[1]).collect();
            merge_runs(&mut runs);
            let got: Vec<u32> = runs.iter().flat_map(|r| r[0]..=r[1]).collect();
            assert_eq!(got, want.into_iter().collect::<Vec<_>>(), "case {case}");
            // Disjoint and not touching: nothing left to merge.
            assert!(runs
                .windows(2)
                .all(|w| u64::from(w[0][1]) + 1 < u64::from(w[1][0])));
        }
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
