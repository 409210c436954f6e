//! The support search (docs/CHECKER.md, "The bead model"): which earlier
//! bead a new bead rests on, by the definition (the full search, plain or
//! pruned by blocks of beads) or by the shortcut that follows the pass
//! below, and the recent path that tells when the shortcut holds.

use crate::bead::{Bead, Beads};
use crate::blocks::{Blocks, Bound, Visit};
use crate::geom::{len2, rect_distance, turn_bound};
use crate::grid::BeadGrid;
use crate::replay::Move;
use crate::tops::TopGrid;
use crate::CheckConfig;

/// A bead below a new bead: height at its point nearest to the new bead's
/// middle, that point, the horizontal distance to it, its width, and
/// whether its footprint (a capsule: centreline ± w/2) covers the middle.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Candidate {
    /// The bead's index.
    pub(crate) id: u32,
    pub(crate) z: f64,
    pub(crate) at: [f64; 2],
    pub(crate) d: f64,
    pub(crate) width: f64,
    /// The bead's own layer height.
    pub(crate) height: f64,
    pub(crate) covers: bool,
}

impl Candidate {
    /// Order by distance, ties (the shared end of two beads) to the
    /// earlier bead.
    #[inline]
    pub(crate) fn nearer(&self, o: &Candidate) -> std::cmp::Ordering {
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
pub(crate) fn pick_support(
    cands: &[Candidate],
    min_layer: f64,
    near_bed: bool,
) -> Option<Candidate> {
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

/// Heights closer than this are one height (mm): below any printer's Z
/// step (docs/CHECKER.md, "Heights a micrometre apart").
pub(crate) const SAME_HEIGHT_MM: f64 = 1e-3;

/// Clay at a new bead's own height under its middle: the highest such
/// bead's top, and its width (a film pressed onto it becomes part of its
/// top, as wide: docs/CHECKER.md, "Films").
#[derive(Clone, Copy, Debug)]
pub(crate) struct Own {
    pub(crate) z: f64,
    pub(crate) width: f64,
}

impl Own {
    /// The higher of this and `other` (the wider at one height).
    fn higher(self, other: Option<Own>) -> Own {
        match other {
            Some(o) if o.z > self.z || (o.z == self.z && o.width > self.width) => o,
            _ => self,
        }
    }
}

/// What an earlier bead is to a new one.
pub(crate) enum Class {
    /// Clay below that may support it.
    Below(Candidate),
    /// Clay already at its height under its middle: its top and width.
    Double(Own),
    /// Neither: too far, too deep, above it, a step, or behind the nozzle.
    Neither,
}

/// A new bead whose support is sought: its move, its middle and the path
/// distance where it starts.
pub(crate) struct Query<'a> {
    pub(crate) m: &'a Move,
    pub(crate) mid: [f64; 3],
    pub(crate) s_start: f64,
    pub(crate) cfg: &'a CheckConfig,
}

impl Query<'_> {
    /// Judges earlier bead `b` (index `j`) against the new bead.
    /// Inlined into each of its callers (the shortcut, both searches):
    /// called from four places the compiler stops inlining it, at a
    /// measured cost (docs/PERFORMANCE.md, "The checker's micro-choices").
    #[inline(always)]
    pub(crate) fn classify(&self, b: &Bead, j: u32) -> Class {
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
            // A smear a quarter of the thinnest bead wide (a join across
            // clay, a ramp's start) holds nothing up: what it lies on does.
            if mid[2] - z <= cfg.max_gap_mm
                && d <= cfg.width_max.max(b.width() / 2.0)
                && !is_smear(b.width(), cfg)
            {
                return Class::Below(Candidate {
                    id: j,
                    z,
                    at,
                    d,
                    width: b.width(),
                    height: b.height(),
                    covers: d <= b.width() / 2.0,
                });
            }
        } else if (z - mid[2]).abs() < cfg.min_layer_mm
            && d < 0.5 * b.width().min(cfg.width_min)
            // Nor is a smear clay to be laid on.
            && !is_smear(b.width(), cfg)
            // Clay laid in the last 2 w_max of path is the run's own fresh
            // clay (a corner piles up, it is not laid twice).
            && s_start - b.s_end > 2.0 * cfg.width_max
            // Under the middle within the bead's length, not past its end:
            // a loop's last bead ending on its own first bead (a seam) is
            // not laid on it.
            && b.spans(mid)
        {
            // Clay less than a micrometre below the middle is at its
            // height: no printer steps that finely, and a stack of such
            // beads is then found at its first, not walked whole
            // (docs/CHECKER.md, "Heights a micrometre apart").
            return Class::Double(Own {
                z: if z >= mid[2] - SAME_HEIGHT_MM {
                    mid[2]
                } else {
                    z
                },
                width: b.width(),
            });
        }
        Class::Neither
    }

    /// Whether none of `beads` (the first has index `first`) is clay below
    /// the new bead: `classify` puts none of them in `Below`. Oldest first,
    /// since clay below in the last stretch of path (the end of the pass
    /// before a reversal) is usually its oldest part.
    #[inline]
    pub(crate) fn none_below(&self, beads: &Beads, first: usize) -> bool {
        beads
            .since(first)
            .all(|(j, b)| !matches!(self.classify(b, j as u32), Class::Below(_)))
    }
}

/// The beads laid in the last stretch of path, not yet in the settled
/// tops: their lowest point (a sliding-window minimum: ids and heights both
/// increasing) and how much the path turns among them (in plan, radians; a
/// turnaround or a jump counts π).
#[derive(Default)]
pub(crate) struct Recent {
    pub(crate) low: std::collections::VecDeque<(u32, f32)>,
    /// The turn into each bead of the window, oldest first.
    pub(crate) turns: std::collections::VecDeque<f32>,
    pub(crate) turning: f64,
    /// Plan direction of the last bead and its path end, if it had one.
    pub(crate) last: Option<([f64; 2], f64)>,
}

impl Recent {
    /// The turn from the last bead into a move of plan vector `d` and
    /// length `l` starting at path distance `s_start`, or a little more
    /// ([`turn_bound`]; only sums under 60° matter in `clear_of`, and more
    /// turning only sends a bead to the full search).
    #[inline]
    pub(crate) fn turn(&self, d: [f64; 2], l: f64, s_start: f64) -> f64 {
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
    #[inline]
    pub(crate) fn push(
        &mut self,
        id: u32,
        heading: Option<[f64; 2]>,
        s_end: f64,
        low: f32,
        turn: f64,
    ) {
        self.turning += turn;
        self.turns.push_back(turn as f32);
        while self.low.back().is_some_and(|r| r.1 >= low) {
            self.low.pop_back();
        }
        self.low.push_back((id, low));
        self.last = heading.map(|u| (u, s_end));
    }

    /// Bead `id`, the oldest in the window, leaves it.
    #[inline]
    pub(crate) fn settle(&mut self, id: u32) {
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

    #[inline]
    pub(crate) fn low(&self) -> f64 {
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
    #[inline]
    pub(crate) fn clear_of(
        &self,
        m: &Move,
        mid: [f64; 3],
        min_layer: f64,
        turn: f64,
        xy: f64,
    ) -> bool {
        let low = self.low();
        low > mid[2] - min_layer
            || ((low > m.from[2] - 0.5 || xy > 0.45)
                && self.turning + turn < std::f64::consts::FRAC_PI_3)
    }
}

/// Beads the shortcut looks past its answer, each way, for a nearer one.
const LOOK_PAST: usize = 8;

/// Whether no bead within [`LOOK_PAST`] of the shortcut's answer `best`
/// is nearer the middle. The walk stops at the first bead that is no
/// nearer, which is the nearest of a pass that runs straight or gently
/// curved (the distance to a point is then unimodal along it); where the
/// pass below turns (a bead marked `bent`: a corner, a tight curl, a
/// turnaround) a nearer bead may lie a few beads on, so the beads past
/// the turn are asked. A bead whose start is farther from the middle than
/// `best` plus its own length (an L1 bound: no square root) cannot be
/// nearer.
#[inline]
fn alone(
    beads: &Beads,
    bent_before: &[u32],
    settled: usize,
    best: &Candidate,
    q: &Query,
    mid: [f64; 3],
) -> bool {
    let kb = best.id as usize;
    let lo = kb.saturating_sub(LOOK_PAST);
    let hi = (kb + LOOK_PAST).min(settled.saturating_sub(1));
    // `bent_before[k]` counts the bent beads before bead k.
    if bent_before
        .get(hi + 1)
        .zip(bent_before.get(lo))
        .is_none_or(|(h, l)| h == l)
    {
        return true;
    }
    alone_past_bends(beads, best, q, mid, (lo, kb, hi))
}

/// [`alone`] where the pass turns within reach: the beads past a bend,
/// each way, asked. Rare, so kept out of the shortcut's code.
#[cold]
#[inline(never)]
fn alone_past_bends(
    beads: &Beads,
    best: &Candidate,
    q: &Query,
    mid: [f64; 3],
    (lo, kb, hi): (usize, usize, usize),
) -> bool {
    // Along a pass that runs straight up to a bend the distance only grows
    // away from the walk's answer: only beads past a bend are asked.
    let nearer = |k: usize| {
        let b = &beads[k];
        let (f, t) = (b.from32, b.to32);
        let (fx, fy) = (f64::from(f[0]) - mid[0], f64::from(f[1]) - mid[1]);
        let l1 = f64::from((t[0] - f[0]).abs() + (t[1] - f[1]).abs());
        let reach = best.d + l1;
        fx * fx + fy * fy <= reach * reach
            && matches!(q.classify(b, k as u32), Class::Below(c) if c.nearer(best).is_lt())
    };
    let side = |ks: &mut dyn Iterator<Item = usize>| {
        let mut past_bend = false;
        for k in ks {
            past_bend |= beads[k].bent;
            if past_bend && nearer(k) {
                return false;
            }
        }
        true
    };
    side(&mut (kb + 1..=hi)) && side(&mut (lo..kb).rev())
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
#[inline]
pub(crate) fn follow_support(
    beads: &Beads,
    grid: &BeadGrid,
    bent_before: &[u32],
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
    if !best.covers || !alone(beads, bent_before, settled, &best, q, mid) {
        return None;
    }
    // The full search's square; wider if a settled bead is so wide that it
    // could cover the middle from farther (other slicers' files).
    let r = (cfg.width_max / 2.0 + 0.5).max(f64::from(tops.widest) / 2.0);
    if r > 2.0 * cfg.width_max {
        return None;
    }
    let (xs, ys) = tops.range([mid[0] - r, mid[1] - r], [mid[0] + r, mid[1] + r]);
    // Another pass of the layer below nearer the middle would be the
    // support. Passes of a layer may lie less than a bead apart (the
    // rings of a floor), and near a bend the pass may step across to the
    // next: unless the answer is right under the middle the beads
    // themselves are asked.
    let kb = best.id as usize;
    let bend = bent_before
        .get(kb + 3)
        .zip(bent_before.get(kb.saturating_sub(2)));
    let near_bend = bend.is_none_or(|(h, l)| h != l);
    if best.d > NEAR_BEND * cfg.width_min
        && (best.d > RIGHT_UNDER * cfg.width_min || near_bend)
        && nearer_below(beads, grid, q, &best)
    {
        return None;
    }
    // Most beads: no clay that high in the blocks around.
    let block = f64::from(tops.block_max((xs, ys)));
    if block < best.z + cfg.min_layer_mm && block <= mid[2] - cfg.min_layer_mm {
        return Some(best);
    }
    // Only beads below the new one can be climbed to: below that, the
    // highest clay a cell can hold (not its top layer, if that is the
    // new bead's own, as the rings of a floor's upper layer lie).
    let lim = mid[2] - cfg.min_layer_mm;
    let mut own = false;
    for y in ys[0]..ys[1] + 1 {
        for x in xs[0]..xs[1] + 1 {
            let i = y * tops.n[0] + x;
            let (top, under) = (f64::from(tops.top[i]), tops.highest_under(i, lim));
            // Most cells: clay lower than both tests' thresholds (or none).
            if under < best.z + cfg.min_layer_mm && top <= lim {
                continue;
            }
            let rect = tops.rect(x, y);
            let climb = best.z + cfg.min_layer_mm.max(0.5 * rect_distance(rect, best.at));
            if under >= climb {
                return None;
            }
            own |= top > lim && rect_distance(rect, [mid[0], mid[1]]) < 0.5 * cfg.width_min;
        }
    }
    if own && laid_twice(beads, grid, q) {
        return None;
    }
    Some(best)
}

/// Whether a bead `width` mm wide is a wisp of clay: under a quarter of
/// `w_min`, it holds nothing up and is no clay to be laid on; in the
/// print it fails as under-extruded (docs/CHECKER.md, "Under-extruded
/// moves").
pub(crate) fn is_smear(width: f64, cfg: &CheckConfig) -> bool {
    width < 0.25 * cfg.width_min
}

/// Within this many `w_min` of the middle, the shortcut's answer is taken
/// as the nearest bead below without asking the beads around: passes of
/// one layer lie at least 3/4 `w_min` apart (a floor's rings 0.85 `w_min`),
/// so a nearer one would lie farther out than this. Where passes lie
/// closer (other slicers' heavily overlapping lines), the answer is the
/// farther pass, whose overlap is smaller: the check errs toward
/// refusing (docs/CHECKER.md, "Speed").
const RIGHT_UNDER: f64 = 0.375;

/// The same within two beads of a bend of the pass below, where it may
/// step across to the next pass (a floor's ring to the next) or close a
/// loop beside its own start: a nearer pass lies farther out than this.
const NEAR_BEND: f64 = 0.1;

/// Whether any bead in the bead grid's cells within `r` of the middle,
/// between heights `zlo` and `zhi`, is one `classify` puts in a class
/// `hit` accepts: the exact question for where a cell of the column tops
/// is too coarse to tell. Rare, so kept out of the shortcut's code.
#[cold]
#[inline(never)]
fn any_near(
    beads: &Beads,
    grid: &BeadGrid,
    q: &Query,
    (r, zlo, zhi): (f64, f64, f64),
    hit: impl Fn(Class) -> bool,
) -> bool {
    let mut found = false;
    grid.in_box(q.mid, r, zlo, zhi, |run| {
        found = found || (run.first..=run.last).any(|j| hit(q.classify(&beads[j as usize], j)));
    });
    found
}

/// Whether a bead below other than `best` covers the middle and is
/// nearer to it ([`Candidate::nearer`]): then the full search starts from
/// that one.
fn nearer_below(beads: &Beads, grid: &BeadGrid, q: &Query, best: &Candidate) -> bool {
    let (mid, cfg) = (q.mid, q.cfg);
    let window = (best.d, mid[2] - cfg.max_gap_mm, mid[2] - cfg.min_layer_mm);
    any_near(
        beads,
        grid,
        q,
        window,
        |c| matches!(c, Class::Below(c) if c.covers && c.nearer(best).is_lt()),
    )
}

/// The gentlest lean over any bead below that covers the new bead's
/// middle within `max_gap`: the least offset / height ratio (height the
/// larger of the gap and that bead's own). Asked only of a bead about to
/// fail the overhang limit, whose support the walk of [`pick_support`]
/// climbed to: a bead pressed on a thin top-edge bead beside it may still
/// sit squarely on the full bead under its middle (docs/CHECKER.md,
/// "Overhang").
pub(crate) fn gentlest_lean(beads: &Beads, grid: &BeadGrid, q: &Query, max_gap: f64) -> f64 {
    let (mid, cfg) = (q.mid, q.cfg);
    let mut best = f64::INFINITY;
    let r = cfg.width_max;
    grid.in_box(mid, r, mid[2] - max_gap, mid[2] - cfg.min_layer_mm, |run| {
        for j in run.first..=run.last {
            if let Class::Below(c) = q.classify(&beads[j as usize], j) {
                let dz = mid[2] - c.z;
                if c.covers && dz <= max_gap {
                    best = best.min(c.d / dz.max(c.height));
                }
            }
        }
    });
    best
}

/// Whether any clay laid before the new bead, however recently, lies
/// under its middle between a thinnest layer and `gap` below it: a bead
/// with such clay under it is no bead over a layer gap, whatever the
/// support walk settled on (docs/CHECKER.md, "Layer gaps"). Asked only
/// of a bead about to fail for its gap.
pub(crate) fn clay_within_gap(beads: &Beads, grid: &BeadGrid, q: &Query, gap: f64) -> bool {
    let (mid, cfg) = (q.mid, q.cfg);
    let (lo, hi) = (mid[2] - gap, mid[2] - cfg.min_layer_mm);
    let mut found = false;
    grid.in_box(mid, cfg.width_max, lo, hi, |run| {
        found = found
            || (run.first..=run.last).any(|j| {
                let b = &beads[j as usize];
                if b.step || b.s_end >= q.s_start - 1e-9 || is_smear(b.width(), cfg) {
                    return false;
                }
                let (d, z, _) = b.closest(mid);
                z >= lo && z <= hi && d <= b.width() / 2.0
            });
    });
    found
}

/// Whether earlier clay lies beside the new bead at its own height (within
/// a thinnest layer, `width_max` in plan), not counting the run's fresh
/// clay of the last 2 `width_max` of path: a thin bead between such
/// neighbours (a floor's narrowed tail) stands between them; a thin coil
/// with nothing beside it does not (docs/CHECKER.md, "Layer gaps").
pub(crate) fn flanked(beads: &Beads, grid: &BeadGrid, q: &Query) -> bool {
    let (mid, cfg) = (q.mid, q.cfg);
    let (lo, hi) = (mid[2] - cfg.min_layer_mm, mid[2] + cfg.min_layer_mm);
    let mut found = false;
    grid.in_box(mid, cfg.width_max, lo, hi, |run| {
        found = found
            || (run.first..=run.last).any(|j| {
                let b = &beads[j as usize];
                if b.step || q.s_start - b.s_end <= 2.0 * cfg.width_max || is_smear(b.width(), cfg)
                {
                    return false;
                }
                let (d, z, _) = b.closest(mid);
                z > lo && z < hi && d <= cfg.width_max
            });
    });
    found
}

/// Whether a bead lies at the new bead's own height under its middle
/// ([`Class::Double`]): asked of the beads themselves where a cell too
/// coarse to tell holds clay that high near it (beside the rings of a
/// floor's layer, the next ring of the same layer).
fn laid_twice(beads: &Beads, grid: &BeadGrid, q: &Query) -> bool {
    let (mid, ml) = (q.mid, q.cfg.min_layer_mm);
    let window = (0.5 * q.cfg.width_min, mid[2] - ml, mid[2] + ml);
    any_near(beads, grid, q, window, |c| matches!(c, Class::Double(..)))
}

/// Whether the full search would find nothing under a bead near the bed
/// (it rests on the bed) and no clay at its own height under it, without
/// the search: no cell within reach of it holds clay low enough to be
/// below it. The caller asks first, as for [`follow_support`], that none
/// of the clay laid in the last 2 w_max of path is below.
#[inline]
pub(crate) fn on_bare_bed(beads: &Beads, grid: &BeadGrid, tops: &TopGrid, q: &Query) -> bool {
    let (mid, cfg) = (q.mid, q.cfg);
    let r = cfg.width_max.max(f64::from(tops.widest) / 2.0);
    if mid[2] > cfg.first_layer_max_mm || r > 2.0 * cfg.width_max {
        return false;
    }
    let (lim, low) = (mid[2] - cfg.min_layer_mm, mid[2] - cfg.max_gap_mm);
    let (xs, ys) = tops.range([mid[0] - r, mid[1] - r], [mid[0] + r, mid[1] + r]);
    if f64::from(tops.block_max((xs, ys))) < low {
        return true;
    }
    let mut own = false;
    for y in ys[0]..ys[1] + 1 {
        for x in xs[0]..xs[1] + 1 {
            let i = y * tops.n[0] + x;
            if tops.highest_under(i, lim) >= low {
                return false;
            }
            own |= f64::from(tops.top[i]) > lim
                && rect_distance(tops.rect(x, y), [mid[0], mid[1]]) < 0.5 * cfg.width_min;
        }
    }
    !(own && laid_twice(beads, grid, q))
}

/// How the support of a bead is found. Each way gives the same answer;
/// the tests hold them to it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Walk {
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
pub(crate) fn search_support(
    beads: &Beads,
    grid: &BeadGrid,
    blocks: &mut Blocks,
    scratch: &mut Scratch,
    q: &Query,
    walk: Walk,
) -> (Option<Candidate>, Option<Own>) {
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
        for (_, b) in beads.since(blocks.len()) {
            blocks.push(&Bound::bead(b.from32, b.to32, b.width32));
        }
        return search_pruned(beads, blocks, runs, q, wider);
    }
    cands.clear();
    let mut double: Option<Own> = None;
    let covered = std::cell::Cell::new(false);
    let mut classify = |j: u32| match q.classify(&beads[j as usize], j) {
        Class::Below(c) => {
            covered.set(covered.get() || c.covers);
            cands.push(c);
        }
        Class::Double(o) => double = Some(o.higher(double)),
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
pub(crate) struct Scratch {
    pub(crate) runs: Vec<[u32; 2]>,
    pub(crate) cands: Vec<Candidate>,
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
    beads: &Beads,
    blocks: &Blocks,
    runs: &mut Vec<[u32; 2]>,
    q: &Query,
    wider: impl FnOnce(&mut Vec<[u32; 2]>),
) -> (Option<Candidate>, Option<Own>) {
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
    let mut double = None;
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
    pub(crate) beads: &'a Beads,
    pub(crate) blocks: &'a Blocks,
    pub(crate) q: &'a Query<'a>,
    /// Margin on every bound.
    pub(crate) slack: f64,
}

impl Nearest<'_> {
    /// The nearest bead of `runs` ([`Candidate::nearer`]) that `classify`
    /// puts below and `keep` accepts. Skips the blocks `skip` rejects,
    /// given their bounds and a lower bound of their beads' distances to
    /// the middle, and those no nearer than the nearest found so far.
    /// With `double`, also sets it if a bead of `runs` is
    /// [`Class::Double`] (in the same walk: a block is walked if either
    /// question needs it).
    pub(crate) fn nearest(
        &self,
        runs: &[[u32; 2]],
        skip: impl Fn(&Bound, f64) -> bool,
        keep: impl Fn(&Candidate) -> bool,
        mut double: Option<&mut Option<Own>>,
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
                            // middle, higher than any found so far; none
                            // matters once one is found at the middle's
                            // height (no gap is left), so clay stacked
                            // at one height costs one find, not a walk of
                            // the whole stack.
                            found.is_none_or(|o| o.z < mid[2])
                                && lb < 0.5 * cfg.width_min
                                && f64::from(b.hi[2]) + slack
                                    > found.map_or(mid[2] - ml, |o| o.z.max(mid[2] - ml))
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
                        Class::Double(o) => {
                            if let Some(found) = double.as_mut() {
                                **found = Some(o.higher(**found));
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

#[cfg(test)]
mod tests {
    use super::*;

    fn cand(z: f64, x: f64, d: f64) -> Candidate {
        Candidate {
            id: 0,
            z,
            at: [x, 0.0],
            d,
            width: 3.0,
            height: 1.2,
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
}
