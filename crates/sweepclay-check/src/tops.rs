//! Column tops: the highest clay in each plan cell of the bed, in a dense
//! array with a coarser array of 4 × 4-cell blocks on top, so "is any clay
//! this high near here?" is a few loads (docs/CHECKER.md, "Speed").

use crate::bead::Bead;
use crate::geom::{larger, len2};

/// Highest clay top in each plan cell of a fixed rectangle (the bed with
/// a margin): a dense array, so a question about a neighbourhood is a few
/// loads. Clay outside the rectangle is counted in its border cells, which
/// keeps every cell's value an upper bound.
pub(crate) struct TopGrid {
    pub(crate) cell: f64,
    /// `1 / cell`, exact: cells are a power of two times `base`.
    pub(crate) inv: f64,
    /// Plan coordinates of the rectangle's low corner.
    pub(crate) origin: [f64; 2],
    pub(crate) n: [usize; 2],
    pub(crate) top: Vec<f32>,
    /// The highest top of each block of 4 × 4 cells (`n / 4` rounded up
    /// a side): most questions are answered by a block or two.
    pub(crate) coarse: Vec<f32>,
    /// Blocks a row.
    pub(crate) bx: usize,
    /// The widest bead raised.
    pub(crate) widest: f32,
    /// With [`TopGrid::layered`], what lies under each cell's top layer,
    /// so a cell holding one layer over another (a floor's second layer
    /// on its first) still tells how high the clay under the top layer
    /// reaches: every bead raised in cell i lies wholly at or above
    /// `layer_lo[i]`, which is more than `layer` under `top[i]` (the top
    /// layer), or has its top at most `under[i]`. Empty otherwise.
    pub(crate) under: Vec<f32>,
    pub(crate) layer_lo: Vec<f32>,
    pub(crate) layer: f32,
}

impl TopGrid {
    /// A grid over `0..extent` in x and y plus a margin of 8 cells, with
    /// cells a power-of-two multiple of `base` mm (so each cell of a `base`
    /// grid lies in one of them) and at most 1016 a side.
    pub(crate) fn new(extent: [f64; 2], base: f64) -> TopGrid {
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
            under: Vec::new(),
            layer_lo: Vec::new(),
            layer: 0.0,
        }
    }

    /// [`TopGrid::new`] that also keeps what lies under each cell's top
    /// layer, `layer` mm thick ([`TopGrid::under`]).
    pub(crate) fn layered(extent: [f64; 2], base: f64, layer: f64) -> TopGrid {
        let mut g = TopGrid::new(extent, base);
        g.under = vec![f32::NEG_INFINITY; g.top.len()];
        g.layer_lo = vec![f32::INFINITY; g.top.len()];
        g.layer = layer as f32;
        g
    }

    /// Raises cell `i` to a bead from `bot` to `top` high. A bead that
    /// rises past the top layer starts a new one, the old layer moving
    /// under it unless all of it still lies in the new layer.
    #[inline]
    fn lift(&mut self, i: usize, bot: f32, top: f32) {
        let old = self.top[i];
        self.top[i] = larger(old, top);
        if self.under.is_empty() {
            return;
        }
        let (under, lo) = (&mut self.under[i], &mut self.layer_lo[i]);
        let new = self.top[i];
        // Also when either is NaN: moving clay under is always safe.
        if (*lo).partial_cmp(&(new - self.layer)) != Some(std::cmp::Ordering::Greater) {
            *under = under.max(old);
            *lo = f32::INFINITY;
        }
        if bot > new - self.layer {
            *lo = lo.min(bot);
        } else {
            *under = under.max(top);
        }
    }

    /// The highest any point of a bead raised in cell `i` can be while at
    /// most `lim`: at most the cell's top, and only the clay under its
    /// top layer if all of the top layer lies above `lim`. A
    /// [`TopGrid::new`] grid knows only its tops.
    #[inline]
    pub(crate) fn highest_under(&self, i: usize, lim: f64) -> f64 {
        let top = f64::from(self.top[i]).min(lim);
        match self.layer_lo.get(i) {
            Some(&lo) if f64::from(lo) > lim => f64::from(self.under[i]).min(top),
            _ => top,
        }
    }

    /// Cell index along axis `a`, clamped into the rectangle.
    #[inline]
    pub(crate) fn index(&self, v: f64, a: usize) -> usize {
        // `as` truncates toward zero and saturates (NaN to 0), which is the
        // floor for every cell index but the first; to `i32`, which is a
        // few instructions less than to `usize` (n is at most 1016).
        let c = ((v - self.origin[a]) * self.inv) as i32;
        c.clamp(0, self.n[a] as i32 - 1) as usize
    }

    /// Cell ranges `[x0, x1], [y0, y1]` (inclusive) of a plan box.
    #[inline]
    pub(crate) fn range(&self, lo: [f64; 2], hi: [f64; 2]) -> ([usize; 2], [usize; 2]) {
        (
            [self.index(lo[0], 0), self.index(hi[0], 0)],
            [self.index(lo[1], 1), self.index(hi[1], 1)],
        )
    }

    pub(crate) fn raise_box(&mut self, (xs, ys): ([usize; 2], [usize; 2]), bot: f32, top: f32) {
        let nx = self.n[0];
        for y in ys[0]..ys[1] + 1 {
            for x in xs[0]..xs[1] + 1 {
                self.lift(y * nx + x, bot, top);
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
    #[inline]
    pub(crate) fn blocks(
        &self,
        (xs, ys): ([usize; 2], [usize; 2]),
    ) -> impl Iterator<Item = std::ops::Range<usize>> + use<> {
        let bx = self.bx;
        (ys[0] / 4..ys[1] / 4 + 1).map(move |y| y * bx + xs[0] / 4..y * bx + xs[1] / 4 + 1)
    }

    /// The highest top in cells `xs`, `ys` (inclusive) or a little beyond:
    /// the blocks of 4 × 4 cells that hold them.
    #[inline]
    pub(crate) fn block_max(&self, cells: ([usize; 2], [usize; 2])) -> f32 {
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
    #[inline]
    pub(crate) fn raise(&mut self, b: &Bead) {
        let (f, t) = (b.from(), b.to());
        let top = b.top32();
        let bot = b.from32[2].min(b.to32[2]);
        self.widest = self.widest.max(b.width32);
        let (xs, ys) = self.range(
            [f[0].min(t[0]), f[1].min(t[1])],
            [f[0].max(t[0]), f[1].max(t[1])],
        );
        // Most beads: three cells a side or fewer, so two blocks a side at
        // most. Their cells and blocks without the loops of raise_box: the
        // first and last of each side (some perhaps the same), and, for a
        // third cell, the middle one. Faster than the loops, and than nine
        // fixed cells, which chain each store to the next load where beads
        // lie in one cell (docs/PERFORMANCE.md, "The checker's
        // micro-choices").
        if xs[1] - xs[0] <= 2 && ys[1] - ys[0] <= 2 {
            let nx = self.n[0];
            for (x, y) in [
                (xs[0], ys[0]),
                (xs[1], ys[0]),
                (xs[0], ys[1]),
                (xs[1], ys[1]),
            ] {
                self.lift(y * nx + x, bot, top);
                let c = &mut self.coarse[y / 4 * self.bx + x / 4];
                *c = larger(*c, top);
            }
            if xs[1] - xs[0] == 2 || ys[1] - ys[0] == 2 {
                let (xm, ym) = ((xs[0] + xs[1]) / 2, (ys[0] + ys[1]) / 2);
                for (x, y) in [(xm, ys[0]), (xm, ym), (xm, ys[1]), (xs[0], ym), (xs[1], ym)] {
                    self.lift(y * nx + x, bot, top);
                }
            }
            return;
        }
        if (xs[1] - xs[0] + 1) * (ys[1] - ys[0] + 1) <= 16 {
            return self.raise_box((xs, ys), bot, top);
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
            self.raise_box(cells, bot, top);
        }
    }

    /// The part of `lo..hi` on axis `a` inside cell `g` (its upper edge
    /// excluded); a border cell also holds the clay beyond the border, so
    /// its side is not cut there.
    #[inline]
    pub(crate) fn clip(&self, g: usize, a: usize, lo: f64, hi: f64) -> (f64, f64) {
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
    #[inline]
    pub(crate) fn rect(&self, x: usize, y: usize) -> [f64; 4] {
        let x0 = self.origin[0] + x as f64 * self.cell;
        let y0 = self.origin[1] + y as f64 * self.cell;
        [x0, y0, x0 + self.cell, y0 + self.cell]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layered_cells_bound_the_clay_under_their_top_layer() {
        // Short beads of random heights and slopes, in layers and not, in
        // a small grid (many beads a cell): every bead through a cell is
        // either wholly in its top layer or under its `under` bound, and
        // `highest_under` bounds every point of every bead under a limit.
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut rand = move |hi: f64| (crate::xorshift(&mut seed) % 1_000_000) as f64 / 1e6 * hi;
        let mut flat_tops = 0;
        for round in 0..40 {
            let mut g = TopGrid::layered([20.0, 20.0], 2.0, 0.3);
            let mut beads = Vec::new();
            for k in 0..400 {
                let z = if round % 2 == 0 {
                    1.25 * (1 + k / 100) as f64
                } else {
                    rand(6.0)
                };
                let from = [rand(20.0), rand(20.0), z];
                let rise = if round % 2 == 0 || rand(1.0) < 0.7 {
                    0.0
                } else {
                    rand(1.0) - 0.5
                };
                let to = [
                    from[0] + rand(3.0) - 1.5,
                    from[1] + rand(3.0) - 1.5,
                    z + rise,
                ];
                let b = Bead::new(from, to, 3.0, 0.0, false);
                g.raise(&b);
                beads.push(b);
            }
            for b in &beads {
                let (f, t) = (b.from(), b.to());
                for k in 0..=50 {
                    let u = f64::from(k) / 50.0;
                    let p = [0, 1, 2].map(|a| f[a] + u * (t[a] - f[a]));
                    let i = g.index(p[1], 1) * g.n[0] + g.index(p[0], 0);
                    let (bot, top) = (f[2].min(t[2]) as f32, b.top32());
                    assert!(
                        (bot >= g.layer_lo[i] && g.layer_lo[i] > g.top[i] - g.layer)
                            || top <= g.under[i],
                        "round {round}: bead {bot}..{top}, cell {} {} {}",
                        g.top[i],
                        g.layer_lo[i],
                        g.under[i]
                    );
                    for lim in [0.5, 1.0, 2.2, 3.45, 5.0] {
                        if p[2] <= lim {
                            assert!(g.highest_under(i, lim) >= f64::from(p[2] as f32) - 1e-6);
                        }
                    }
                }
            }
            if round % 2 == 0 {
                // Flat layers: under the top layer's own limit, only the
                // layer below counts.
                let i = g.index(10.0, 1) * g.n[0] + g.index(10.0, 0);
                if g.top[i] == 5.0 {
                    flat_tops += 1;
                    assert!(g.highest_under(i, 5.0 - 0.3) <= 3.75 + 1e-6);
                }
            }
        }
        assert!(flat_tops > 5, "{flat_tops}");
    }

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
}
