//! Vessels: a closed Ψ printed as a floor and a spiral wall in one
//! continuous path (not in the paper; docs/ALGORITHMS.md §8).
//!
//! The layering ([`VesselPlan::choose`]) puts the floor's flat layers
//! (none for a bottomless vessel) under K spiral turns of the wall: turn k
//! visits column i of n, the f_i = (order(i) + 1)/n part of the way round
//! from the start column, at
//!
//! ```text
//! z = z_floor + a + (k − 1 + f_i) · δ_i,    δ_i = (h_i − z_floor − a) / K
//! ```
//!
//! so z rises along every turn with no seam, and a last, partial turn lays
//! the rim level at h_i. The first turn starts a full layer `a` above the
//! floor (or the bed) and rises to a + δ over the loop, so it never closes
//! over its own start at its own height and no bead sits on a gap near
//! zero (a ≤ `layer_height`, and a + f_i δ_i ≤ `max_layer_height`).
//! The floor inside the first turn is one spiral per layer
//! ([`crate::floor`]); the path stage (`plan_vessel_path` in the toolpath
//! module) lays it inward and outward in turn, so the last floor layer
//! ends where the wall begins.

use crate::design::{Params, COLLISION_MARGIN_MM};
use crate::error::{Error, Result};
use crate::floor::FloorBeads;

/// The layering of a vessel.
#[derive(Clone, Debug, PartialEq)]
pub struct VesselPlan {
    /// Floor layers asked for (0: bottomless).
    pub floor_layers: u32,
    /// Flat layers under the spiral: the floor's (0 for a bottomless
    /// vessel).
    pub base_layers: u32,
    /// Height of each floor layer (`layer_height`, mm).
    pub base_layer_mm: f64,
    /// a: the first turn's height above the floor (or the bed) where it
    /// starts (mm): `layer_height`, or less where the first turn's end,
    /// a + δ above the floor, would pass `max_layer_height`.
    pub first_mm: f64,
    /// K: spiral turns of the wall.
    pub turns: u32,
    /// The fewest turns that keep every layer within `max_layer_height`:
    /// thicker layers the sampling may fall back on where the extruder
    /// body would meet the turn below on a rim that rises and falls.
    pub fewest_turns: u32,
    /// Thinnest and thickest spiral layer δ_i round the loop (mm).
    pub turn_mm: [f64; 2],
    /// The column each turn begins at (where the floor's spiral ends
    /// and the wall starts; docs/ALGORITHMS.md §8).
    pub start: usize,
    /// The columns' rims h_i (mm).
    pub heights: Vec<f64>,
    /// Where, by the sampling's estimate, no layering keeps the extruder
    /// body clear of a rim that rises and falls; the path is laid anyway
    /// and its replay judges (docs/ALGORITHMS.md §8).
    pub uneven: Option<Uneven>,
    /// The part of the rim above what the spiral carries, laid as passes
    /// back and forth after the rim turn (docs/ALGORITHMS.md §8,
    /// "Partial layers").
    pub arc: Option<RaisedArc>,
}

/// A raised part of a vessel's rim (a slanted cut, a pitcher's back): the
/// spiral carries the rim up to a level H, its rim turn ends at the
/// arc's last column, and the arc's columns are built above H by flat
/// passes of δ back and forth, each turning at a returning point where
/// a climb along the rim lays the top beads of the columns the next
/// passes no longer reach (the paper's §5.2, Fig. 7, on an arc of the
/// loop). The first pass runs backward (against the loop's order) from
/// the arc's end; so the climbs at the arc's end run backward and
/// follow forward passes, those at its start run forward and follow
/// backward passes. A column on the start's side of the peak takes an
/// odd number of passes (none where its rim is under a pass above H:
/// the rim turn lays its rim), one on the end's side an even number;
/// each ends with a top bead at its rim, 0.5 δ to 2 δ thick (half a layer
/// above the drawn rim where that is less). The last pass also takes the other side's columns that reach
/// it, and the climb after it lays all their tops over the peak.
#[derive(Clone, Debug, PartialEq)]
pub struct RaisedArc {
    /// H: the level the spiral's rim turn lays the arc at (mm).
    pub level_mm: f64,
    /// δ: the passes' layer height (mm).
    pub layer_mm: f64,
    /// The arc's columns in the loop's order, its start to its end.
    pub columns: Vec<usize>,
    /// How many passes above the rim turn each of them gets.
    pub passes: Vec<u32>,
    /// The height of each one's top bead (mm): its rim, or half a layer
    /// above its last pass where that is higher.
    pub top_z: Vec<f64>,
    /// The height of each one's rim-turn bead (mm): H, or its own rim
    /// where that is under a pass above H on the start's side; at least
    /// half a layer above the spiral's last turn.
    pub rim: Vec<f64>,
    /// Where the arc is highest, in `columns`: it and those before it are
    /// the start's side.
    pub peak: usize,
}

impl RaisedArc {
    /// The passes and tops of an arc at level `level` of passes `layer`
    /// thick over `columns` (in the loop's order) whose rims are `h` and
    /// whose spiral's last turn is at `last`, a rim-turn bead at least
    /// `half` above it. Where a column's top would be thicker than two
    /// passes (a second rise inside the arc: the passes on either side of
    /// the peak only grow toward it), that column (its place in
    /// `columns`) and the highest its rim may be.
    pub fn new(
        level: f64,
        layer: f64,
        columns: Vec<usize>,
        h: &[f64],
        last: &[f64],
        half: f64,
    ) -> Result<RaisedArc, (usize, f64)> {
        let m = columns.len();
        let e: Vec<f64> = h.iter().map(|&x| x - level).collect();
        let peak = (0..m)
            .max_by(|&a, &b| e[a].total_cmp(&e[b]))
            .ok_or((0, level))?;
        // Each side's passes grow toward the peak: a column takes no more
        // than the lowest rim between it and the peak allows.
        let mut reach = e.clone();
        for j in (0..peak).rev() {
            reach[j] = reach[j].min(reach[j + 1]);
        }
        for j in peak + 1..m {
            reach[j] = reach[j].min(reach[j - 1]);
        }
        let mut passes = vec![0u32; m];
        let mut rim = vec![0.0; m];
        let mut top_z = vec![0.0; m];
        // The column rising most above what its side's passes allow.
        let mut over: Option<(usize, f64, f64)> = None;
        let mut note = |j: usize, most: f64| {
            if over.is_none_or(|o| h[j] - most > o.1) {
                over = Some((j, h[j] - most, most));
            }
        };
        for j in 0..m {
            let r = reach[j] + 1e-9;
            let n = if j <= peak {
                // Odd: one pass if the rim is a pass above H, then pairs.
                if r < layer {
                    0
                } else {
                    2 * ((r - layer) / (2.0 * layer)).floor() as u32 + 1
                }
            } else {
                2 * (r / (2.0 * layer)).floor() as u32
            };
            passes[j] = n;
            // On the start's side, the rim turn lays the rim of a column
            // whose rim is under a pass above H, and no other's.
            if n == 0 && j <= peak && e[j] >= layer - 1e-9 {
                note(j, level + layer);
            }
            let target = if n == 0 && j <= peak { h[j] } else { level };
            rim[j] = target.max(last[j] + half);
            let under = if n == 0 {
                rim[j]
            } else {
                level + f64::from(n) * layer
            };
            let t = h[j] - under;
            if t > 2.0 * layer + 1e-6 {
                note(j, under + 2.0 * layer);
            }
            // Every column whose rim the rim turn does not lay has a top,
            // half a layer thick at least (the rim then up to half a
            // layer above the drawing): a climb that left a column out
            // would run straight across to the next, off the wall where
            // the loop curves in (`RaisedArc::has_top`).
            top_z[j] = h[j].max(under + 0.5 * layer);
        }
        if let Some((j, _, most)) = over {
            return Err((j, most));
        }
        // The last pass takes the other side's columns that reach it, so
        // that one climb lays the tops round the peak, over it and down:
        // two climbs meeting there from either side would each rise
        // toward the other's clay.
        let most = passes.iter().copied().max().unwrap_or(0);
        if most > 0 {
            for j in 0..m {
                let other = if most % 2 == 1 { j > peak } else { j <= peak };
                if other && passes[j] + 1 == most && reach[j] + 1e-9 >= f64::from(most) * layer {
                    passes[j] = most;
                    top_z[j] = h[j].max(level + (f64::from(most) + 0.5) * layer);
                }
            }
        }
        Ok(RaisedArc {
            level_mm: level,
            layer_mm: layer,
            columns,
            passes,
            top_z,
            rim,
            peak,
        })
    }

    /// Whether the column at place `j` gets a top bead after its last
    /// pass: all but those on the start's side that take no pass, whose
    /// rim the rim turn lays.
    pub fn has_top(&self, j: usize) -> bool {
        !(self.passes[j] == 0 && j <= self.peak)
    }

    /// The most passes any column takes.
    pub fn most_passes(&self) -> u32 {
        self.passes.iter().copied().max().unwrap_or(0)
    }

    /// The height of bead (place `j`, pass `k`, top) of [`RaisedArc::order`]
    /// (mm).
    pub fn bead_z(&self, j: usize, k: u32, top: bool) -> f64 {
        if top {
            self.top_z[j]
        } else {
            self.level_mm + f64::from(k) * self.layer_mm
        }
    }

    /// Whether, by the sampling's estimate, the extruder body clears the
    /// clay as the arc is laid in [`RaisedArc::order`]: no bead is laid
    /// where clay laid more than `exempt` mm of path before stands more
    /// than [`BODY_GRAZE_MM`] above the nozzle within reach in plan
    /// (`near`, over all the loop's columns; the rim turn's beads count
    /// as laid before). Where a raised part's peak is narrow, its two
    /// sides' last climbs can each rise toward the other's clay.
    pub fn body_clears(&self, near: &Neighbours, exempt: f64) -> bool {
        let n = near.len();
        let mut place = vec![usize::MAX; n];
        for (j, &c) in self.columns.iter().enumerate() {
            place[c] = j;
        }
        // Per arc column, the beads laid so far: (z, path position).
        let mut laid: Vec<Vec<(f64, f64)>> = self
            .rim
            .iter()
            .map(|&z| vec![(z, f64::NEG_INFINITY)])
            .collect();
        let (order, _) = self.order();
        let mut at = 0.0;
        let mut prev: Option<usize> = None;
        for (j, k, top) in order {
            let c = self.columns[j];
            if let Some(p) = prev {
                at += near.distance(p, c);
            }
            prev = Some(c);
            let z = self.bead_z(j, k, top);
            let mut clear = true;
            near.each(c, |o| {
                let q = place[o];
                if q == usize::MAX || !clear {
                    return;
                }
                // The highest bead there laid long enough ago.
                let old = laid[q]
                    .iter()
                    .rev()
                    .find(|b| b.1 <= at - exempt)
                    .map_or(f64::MIN, |b| b.0);
                if old - z > BODY_GRAZE_MM {
                    clear = false;
                }
            });
            if !clear {
                return false;
            }
            laid[j].push((z, at));
        }
        true
    }

    /// The arc's beads in print order, each (place in `columns`, pass k,
    /// whether it is the top bead after pass k), and how many climbs
    /// (returning turns) there are. From the rim turn's end at the arc's
    /// end: a climb back along the rim over the end's side's columns that
    /// take no pass; then pass 1 backward, a climb forward at the start's
    /// side over the columns whose last pass it was, pass 2 forward, a
    /// climb back at the end's side, …; the last pass's climb runs over
    /// the peak and down the other side.
    pub fn order(&self) -> (Vec<(usize, u32, bool)>, u32) {
        let m = self.columns.len();
        let mut out = Vec::new();
        let mut climbs = 0;
        let mut climb =
            |out: &mut Vec<(usize, u32, bool)>, js: &mut dyn Iterator<Item = usize>, k: u32| {
                let before = out.len();
                out.extend(
                    js.filter(|&j| self.passes[j] == k && self.has_top(j))
                        .map(|j| (j, k, true)),
                );
                climbs += u32::from(out.len() > before);
            };
        let end_side = |j: usize| j > self.peak;
        climb(&mut out, &mut (self.peak + 1..m).rev(), 0);
        let most = self.most_passes();
        for k in 1..=most {
            let on: Vec<usize> = (0..m).filter(|&j| self.passes[j] >= k).collect();
            let backward = k % 2 == 1;
            if backward {
                out.extend(on.iter().rev().map(|&j| (j, k, false)));
            } else {
                out.extend(on.iter().map(|&j| (j, k, false)));
            }
            let (first, last) = (
                on.first().copied().unwrap_or(0),
                on.last().copied().unwrap_or(0),
            );
            match (k == most, backward) {
                (true, true) => climb(&mut out, &mut on.iter().copied(), k),
                (true, false) => climb(&mut out, &mut on.iter().rev().copied(), k),
                (false, true) => climb(&mut out, &mut (first..m).filter(|&j| !end_side(j)), k),
                (false, false) => {
                    climb(&mut out, &mut (0..=last).rev().filter(|&j| end_side(j)), k)
                }
            }
        }
        (out, climbs)
    }
}

/// A rim whose heights vary more round the loop than the spiral's
/// layering can keep clear of the extruder body, by the sampling's
/// estimate: what the check's advice names.
#[derive(Clone, Debug, PartialEq)]
pub struct Uneven {
    /// Where the body would first meet clay, in plan (mm).
    pub at: [f64; 2],
    /// How high above the nozzle (mm).
    pub over_mm: f64,
    /// The rim's heights' spread round the loop now (mm).
    pub spread_mm: f64,
    /// The largest spread (the same rim, its heights drawn together
    /// toward the lowest) whose spiral the body clears (mm).
    pub most_mm: f64,
    /// Where the rim rises in two or more places above what the spiral
    /// carries: which to lower, and to what (one continuous path lays
    /// only one raised part as partial layers).
    pub peaks: Option<String>,
}

impl VesselPlan {
    /// z_floor: the top of the floor's layers, 0 without (mm).
    pub fn base_mm(&self) -> f64 {
        f64::from(self.base_layers) * self.base_layer_mm
    }

    /// Chooses the layering for a loop whose columns are `h` tall: the
    /// most turns (the thinnest layers) that keep every δ_i within
    /// [layer_height, max_layer_height]. Refuses a rim whose height varies
    /// more than that allows, or more than the extruder body clears.
    pub fn choose(h: &[f64], params: &Params, floor_layers: u32) -> Result<VesselPlan> {
        let (dmin, dmax) = (params.layer_height, params.max_layer_height);
        let base_layers = floor_layers;
        let base = f64::from(base_layers) * dmin;
        let lo = h.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = h.iter().copied().fold(0.0, f64::max);
        // The first turn starts a layer up and ends two up; where two of
        // the thinnest layers pass the thickest, it starts lower.
        let a0 = dmin.min(dmax - dmin);
        if lo < base + a0 + dmin - 1e-9 {
            return Err(Error::invalid(
                "profile_start",
                format!(
                    "the vessel is {lo:.2} mm tall at its lowest, less than its {base_layers} floor layer(s) ({base:.2} mm) and one turn of wall ({:.2} mm); make it taller or lower params.floor_layers",
                    a0 + dmin
                ),
            ));
        }
        // The spiral's layers under the tall side are thicker; the extruder
        // body passes over the low side while the high side stands.
        let clear = params.nozzle_height - COLLISION_MARGIN_MM - dmax;
        if hi - lo > clear + 1e-9 {
            return Err(Error::invalid(
                "profile_end",
                format!(
                    "the rim's height varies by {:.1} mm round the loop ({lo:.1} to {hi:.1} mm); the extruder body ({} mm high) clears at most {clear:.1} mm: bring the two profiles' heights closer",
                    hi - lo,
                    params.nozzle_height
                ),
            ));
        }
        let most = ((lo - base - a0) / dmin + 1e-9).floor() as u32;
        let fewest = ((hi - base - a0) / dmax - 1e-9).ceil().max(1.0) as u32;
        if most < fewest {
            return Err(Error::invalid(
                "params.max_layer_height",
                format!(
                    "the rim's height varies from {lo:.1} to {hi:.1} mm round the loop: no whole number of spiral turns keeps every layer between {dmin} and {dmax} mm (at most {most} turns of {dmin} mm on the low side, at least {fewest} on the high side); with {most} turns the rim may lie from {:.1} to {:.1} mm (now {lo:.1} to {hi:.1} mm): bring the profiles' heights within that, or raise params.max_layer_height to about {:.2} mm",
                    base + a0 + f64::from(most) * dmin,
                    base + a0 + f64::from(most) * dmax,
                    (hi - base - a0) / f64::from(most.max(1))
                ),
            ));
        }
        let plan = VesselPlan {
            floor_layers,
            base_layers,
            base_layer_mm: dmin,
            first_mm: a0,
            turns: most,
            fewest_turns: fewest,
            turn_mm: [0.0, 0.0],
            start: 0,
            heights: h.to_vec(),
            uneven: None,
            arc: None,
        };
        Ok(plan.with(most, 0, params))
    }

    /// The same layering with `turns` spiral turns (between
    /// [`VesselPlan::fewest_turns`] and the most `choose` found) starting
    /// at column `start`: the first turn's height `a` fitted so that its
    /// end stays within `max_layer_height` of the floor.
    pub fn with(&self, turns: u32, start: usize, params: &Params) -> VesselPlan {
        let (dmin, dmax) = (params.layer_height, params.max_layer_height);
        let mut v = VesselPlan {
            turns,
            start,
            ..self.clone()
        };
        let n = v.heights.len();
        let base = v.base_mm();
        let k = f64::from(turns);
        // a + f_i (h_i − z_floor − a) / K ≤ dmax at every column, solved
        // for a.
        let a = (0..n)
            .map(|i| {
                let f = (v.order(i, n) + 1) as f64 / n as f64;
                (dmax - f * (v.heights[i] - base) / k) / (1.0 - f / k)
            })
            .fold(dmin.min(dmax - dmin), f64::min);
        v.first_mm = a;
        let d = |h: f64| (h - base - a) / k;
        let lo = v.heights.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.heights.iter().copied().fold(0.0, f64::max);
        v.turn_mm = [d(lo), d(hi)];
        v
    }

    /// Whether the first turn's start stands at least half the thinnest
    /// layer above the floor (see [`VesselPlan::with`]) and no turn is
    /// thicker than `max_layer_height`.
    pub fn first_fits(&self, params: &Params) -> bool {
        self.first_mm >= 0.5 * self.base_layer_mm - 1e-9
            && self.turn_mm[1] <= params.max_layer_height + 1e-9
    }

    /// The height of spiral turn `k` (1-based) at column `i` of `n`, whose
    /// rim is `h` (mm).
    pub fn spiral_z(&self, k: u32, i: usize, n: usize, h: f64) -> f64 {
        let base = self.base_mm() + self.first_mm;
        let d = (h - base) / f64::from(self.turns);
        base + (f64::from(k - 1) + (self.order(i, n) + 1) as f64 / n as f64) * d
    }

    /// Where column `i` of `n` comes in a turn (0 for [`VesselPlan::start`]).
    pub fn order(&self, i: usize, n: usize) -> usize {
        (i + n - self.start % n) % n
    }

    /// Whether column `i` of `n` gets a rim bead: where the last turn ends
    /// at least half a layer below the rim (a thinner bead is no bead, as
    /// for the top-edge beads of a wall; the rim is then level to within
    /// half a layer).
    pub fn has_rim(&self, i: usize, n: usize, h: f64) -> bool {
        h - self.spiral_z(self.turns, i, n, h) >= 0.5 * self.base_layer_mm - 1e-9
    }

    /// Which columns get a rim bead: the run from the turn's start while
    /// [`VesselPlan::has_rim`] holds and the nozzle, level at the rim,
    /// clears the last turn's clay within `reach` in plan and the rim
    /// beads laid more than `exempt` mm of path before (a rim that rises
    /// steeply ahead ends the run early: the rim is then level to within
    /// a layer there). `h` as for [`VesselPlan::body_violation`].
    pub fn rim_beads(&self, near: &Neighbours, h: &[f64], exempt: f64) -> Vec<bool> {
        let n = near.len();
        let mut rim: Vec<bool> = (0..n).map(|i| self.has_rim(i, n, h[i])).collect();
        // The rim turn is one run from the turn's start: once a bead is
        // left out, so are the rest (a gap would be a jump across).
        let mut ended = false;
        for m in 0..n {
            let i = (self.start + m) % n;
            if ended || !rim[i] {
                rim[i] = false;
                ended = true;
                continue;
            }
            let mut clear = true;
            near.each(i, |j| {
                let (oi, oj) = (self.order(i, n), self.order(j, n));
                // The last turn at j, laid just before (behind the seam),
                // is the bead just laid: the body meets the turn under it.
                let k = if oj > oi && near.behind(j, i) <= exempt {
                    self.turns - 1
                } else {
                    self.turns
                };
                let mut top = if k == 0 {
                    self.base_mm()
                } else {
                    self.spiral_z(k, j, n, h[j])
                };
                if oj < oi && near.behind(j, i) > exempt && rim[j] {
                    top = top.max(h[j]);
                }
                if top - h[i] > BODY_GRAZE_MM {
                    clear = false;
                }
            });
            rim[i] = clear;
            ended = !clear;
        }
        rim
    }

    /// Whether the nozzle laying a rim turn of beads at `rim` (every
    /// column, from the start on) clears, by the sampling's estimate, the
    /// last spiral turn ahead of it (laid a turn before) and the rim beads
    /// behind it laid more than `exempt` mm of path before, within reach
    /// in plan (`near`); `h` the columns' rims the spiral carries. Where
    /// the rim rises steeply ahead, the last turn there stands above the
    /// rim turn's nozzle.
    pub fn rim_turn_clears(&self, near: &Neighbours, h: &[f64], rim: &[f64], exempt: f64) -> bool {
        let n = near.len();
        (0..n).all(|i| {
            let mut clear = true;
            near.each(i, |j| {
                let (oi, oj) = (self.order(i, n), self.order(j, n));
                // The last turn just behind the seam is the bead just
                // laid: the body meets the turn under it.
                let fresh = near.behind(j, i) <= exempt;
                let top = if oj > oi && fresh {
                    match self.turns {
                        0 | 1 => self.base_mm(),
                        k => self.spiral_z(k - 1, j, n, h[j]),
                    }
                } else if oj > oi {
                    self.spiral_z(self.turns, j, n, h[j])
                } else if oj < oi && near.behind(j, i) > exempt {
                    rim[j]
                } else {
                    f64::MIN
                };
                if top - rim[i] > BODY_GRAZE_MM {
                    clear = false;
                }
            });
            clear
        })
    }

    /// The first column where the extruder body would meet clay already
    /// laid (docs/ALGORITHMS.md §8): for every pair of columns `i`, `j`
    /// within reach in plan (`near`), the turn below at `j` (or, more than
    /// `exempt` mm of path back along the loop, this turn at `j`) must not
    /// stand more than [`BODY_GRAZE_MM`] above the nozzle at `i`. Checked
    /// at the turns where the difference is largest (it is linear in the
    /// turn). `h` are the columns' rims.
    pub fn body_violation(
        &self,
        near: &Neighbours,
        h: &[f64],
        exempt: f64,
    ) -> Option<(usize, f64)> {
        let n = near.len();
        let turns = [1.max(self.turns.min(2)), self.turns];
        let mut worst: Option<(usize, f64)> = None;
        for i in 0..n {
            near.each(i, |j| {
                if j == i {
                    return;
                }
                let (oi, oj) = (self.order(i, n), self.order(j, n));
                for k in turns {
                    let me = self.spiral_z(k, i, n, h[i]);
                    // The turn below at j was laid `behind(j, i)` mm of
                    // path ago: within `exempt` (just behind the seam) it is
                    // the bead just laid, as the checker counts it, and the
                    // body meets what lies under it, a turn lower.
                    let fresh = oj > oi && near.behind(j, i) <= exempt;
                    let below = match k {
                        1 => self.base_mm(),
                        2 if fresh => self.base_mm(),
                        _ if fresh => self.spiral_z(k - 2, j, n, h[j]),
                        _ => self.spiral_z(k - 1, j, n, h[j]),
                    };
                    // This turn's clay at j, laid long enough ago to count.
                    let same = if oj < oi && near.behind(j, i) > exempt {
                        self.spiral_z(k, j, n, h[j])
                    } else {
                        f64::MIN
                    };
                    let over = below.max(same) - me;
                    if over > BODY_GRAZE_MM && worst.is_none_or(|w| over > w.1) {
                        worst = Some((i, over));
                    }
                }
            });
        }
        worst
    }
}

/// The columns of a loop within a reach of each other in plan, found by
/// a grid built once: what the extruder body can touch; and how much path
/// lies between two of them, which says whether clay is the bead just
/// laid (measured where the columns are, not along Ψ: a wall leaning in
/// has a shorter path at its rim than at its foot).
pub struct Neighbours<'a> {
    points: &'a [[f64; 2]],
    grid: crate::grid::Grid2,
    reach: f64,
    /// Path length from column 0 to each column, and round the loop.
    arc: Vec<f64>,
    length: f64,
}

impl<'a> Neighbours<'a> {
    /// The columns at `points` (in plan), `reach` apart or nearer.
    pub fn new(points: &'a [[f64; 2]], reach: f64) -> Neighbours<'a> {
        let mut grid = crate::grid::Grid2::new(reach.max(1e-3));
        for (i, p) in points.iter().enumerate() {
            grid.insert_segment(*p, *p, i as u32);
        }
        let mut arc = Vec::with_capacity(points.len());
        let mut s = 0.0;
        for (i, p) in points.iter().enumerate() {
            arc.push(s);
            let q = points[(i + 1) % points.len()];
            s += (q[0] - p[0]).hypot(q[1] - p[1]);
        }
        Neighbours {
            points,
            grid,
            reach,
            arc,
            length: s,
        }
    }

    /// The distance in plan between columns `i` and `j` (mm).
    pub fn distance(&self, i: usize, j: usize) -> f64 {
        let (p, q) = (self.points[i], self.points[j]);
        (p[0] - q[0]).hypot(p[1] - q[1])
    }

    /// The path from column `j` forward round the loop to column `i`
    /// (mm; a whole loop when they are the same column).
    pub fn behind(&self, j: usize, i: usize) -> f64 {
        let d = (self.arc[i] - self.arc[j]).rem_euclid(self.length);
        if i == j {
            self.length
        } else {
            d
        }
    }

    /// The number of columns.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether there are no columns.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Calls `f` with every column within reach of column `i` (`i` too).
    pub fn each(&self, i: usize, mut f: impl FnMut(usize)) {
        let (p, r) = (self.points[i], self.reach);
        self.grid.for_each_near_segment(p, p, r, |j| {
            let q = self.points[j as usize];
            if (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) <= r * r {
                f(j as usize);
            }
        });
    }
}

/// Clay this little above the nozzle tip, near the edge of the extruder
/// body, is a graze on a bead's rounded edge (as the checker allows).
pub const BODY_GRAZE_MM: f64 = 0.2;

/// The bead sizes of a vessel's floor from its parameters and the loop's
/// sample spacing, at least [`FLOOR_POINT_MM`] (docs/ALGORITHMS.md §8).
pub fn floor_beads(params: &Params, spacing: f64) -> FloorBeads {
    FloorBeads {
        width: params.width_min,
        spacing: spacing.max(FLOOR_POINT_MM),
        widest: params.width_max,
    }
}

/// The least distance between a floor's points (mm): a wall sampled
/// finer (0.275 mm) gains nothing from a floor of points closer than a
/// third of a bead, only time: the floor's work grows with its points.
pub const FLOOR_POINT_MM: f64 = 1.0;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::toolpath::{PathPoint, PointKind};

    fn circle(r: f64, n: usize) -> Vec<[f64; 2]> {
        (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                [r * a.cos(), r * a.sin()]
            })
            .collect()
    }

    fn cup(r: f64, h: f64, floor: u32) -> crate::Sliced {
        let cp: Vec<[f64; 2]> = circle(r, 400);
        let d = crate::Design::from_json(
            &serde_json::json!({
                "sweepclay": 1,
                "profile_start": { "control_points": [[0.0, 0.0], [0.0, h]] },
                "profile_end": { "control_points": [[0.0, 0.0], [0.0, h]] },
                "trajectory": { "points": cp, "closed": true },
                "params": { "floor_layers": floor },
            })
            .to_string(),
        )
        .unwrap();
        crate::slice(&d).unwrap()
    }

    #[test]
    fn a_triangular_pot_is_no_trajectory_that_meets_itself() {
        // Near a 60° corner the two sides come within a wide bead of each
        // other 12 mm apart along Ψ: laid in one go, round the corner, not
        // a surface meeting itself (it was refused: "the trajectory comes
        // within one bead width of itself").
        let tri: Vec<[f64; 2]> = (0..3)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / 3.0;
                [45.0 * a.cos(), 45.0 * a.sin()]
            })
            .collect();
        let d = crate::Design::from_json(
            &serde_json::json!({
                "sweepclay": 1,
                "profile_start": { "control_points": [[0.0, 0.0], [0.0, 30.0]] },
                "trajectory": { "points": tri, "closed": true, "offset": "normal" },
            })
            .to_string(),
        )
        .unwrap();
        let s = crate::slice(&d).unwrap();
        assert_eq!(s.corrected.report.intersection, None);
    }

    #[test]
    fn a_cylinder_is_a_helix_over_a_spiral_floor() {
        let s = cup(30.0, 40.0, 2);
        let t = &s.toolpath;
        let v = t.vessel.as_ref().unwrap();
        // 40 mm: 2 floor layers of 1.25 mm, the first turn a layer above
        // them, then 1.25 mm a turn: (40 − 2.5 − 1.25) / 1.25 = 29 turns.
        assert_eq!((v.floor_layers, v.turns), (2, 29));
        // Offsets 2.55 mm apart from half of one outside the first turn
        // in: (30 + 1.275) / 2.55 = 12.3, the last winding to the centre.
        assert_eq!(v.floor_turns, 12);
        let wall: Vec<&PathPoint> = t
            .points
            .iter()
            .filter(|p| p.kind == PointKind::Pass)
            .collect();
        let per_turn = s.corrected.surface.columns.len() as f64;
        // The wall starts a layer above the floor, not on it.
        let z0 = wall[0].pos[2];
        assert!((z0 - (2.5 + 1.25 + 1.25 / per_turn)).abs() < 1e-9, "{z0}");
        for w in wall.windows(2) {
            let (a, b) = (w[0].pos, w[1].pos);
            // On the cylinder (the polygon's points are within 0.01 mm)...
            assert!((a[0].hypot(a[1]) - 30.0).abs() < 0.02, "{a:?}");
            // ... rising one layer a turn: 1.25 mm over the loop.
            let rise = b[2] - a[2];
            assert!((rise - 1.25 / per_turn).abs() < 1e-9, "{rise}");
        }
        let top = wall.last().unwrap().pos[2];
        assert!((top - 40.0).abs() < 1e-9, "the spiral ends on the rim");
        // The rim turn is level with the rim.
        for p in t.points.iter().filter(|p| p.kind == PointKind::Top) {
            assert!((p.pos[2] - 40.0).abs() < 1e-9);
        }
    }

    #[test]
    fn the_floor_covers_the_inside_of_the_loop() {
        for r in [12.0, 30.0, 55.0] {
            let s = cup(r, 20.0, 1);
            let v = s.toolpath.vessel.as_ref().unwrap();
            assert!(v.floor_cover >= 0.97, "r = {r}: {}", v.floor_cover);
            // Its beads are between the thinnest and the widest.
            for &(_, w) in &v.floor_widths {
                assert!((3.0..=6.0).contains(&w), "r = {r}: {w}");
            }
        }
    }

    #[test]
    fn a_bottomless_vessel_starts_its_first_turn_a_layer_up() {
        let s = cup(30.0, 20.0, 0);
        let t = &s.toolpath;
        assert!(t.points.iter().all(|p| p.kind != PointKind::Floor));
        assert_eq!(t.vessel.as_ref().unwrap().floor_turns, 0);
        let n = s.corrected.surface.columns.len() as f64;
        assert!((t.points[0].pos[2] - (1.25 + 1.25 / n)).abs() < 1e-9);
    }

    #[test]
    fn no_turn_closes_over_its_own_start_at_its_own_height() {
        for floor in [0, 2] {
            let s = cup(30.0, 20.0, floor);
            let (t, e) = (&s.toolpath, &s.extrusion);
            let n = s.corrected.surface.columns.len();
            let first = t
                .points
                .iter()
                .position(|p| p.kind == PointKind::Pass)
                .unwrap();
            // The first turn ends a whole layer above where it began, on
            // a layer twice as thick: 1.25 → 2.5 mm over the floor.
            let (a, b) = (t.points[first].pos, t.points[first + n - 1].pos);
            assert!((b[2] - a[2] - 1.25 * (n - 1) as f64 / n as f64).abs() < 1e-9);
            assert!((e.layer_height[first] - 1.25 * (1.0 + 1.0 / n as f64)).abs() < 1e-9);
            assert!((e.layer_height[first + n - 1] - 2.5).abs() < 1e-9);
            // Every later wall bead lies a layer over the one below.
            for i in first + n..t.points.len() {
                if t.points[i].kind == PointKind::Pass {
                    assert!((e.layer_height[i] - 1.25).abs() < 1e-9);
                }
            }
        }
    }

    #[test]
    fn spiral_heights_rise_one_layer_a_turn() {
        let p = Params::default();
        let v = VesselPlan::choose(&[50.0; 10], &p, 2).unwrap();
        // 46.25 mm above the floor and the first layer in 37 turns.
        assert_eq!((v.base_layers, v.turns), (2, 37));
        assert!((v.first_mm - 1.25).abs() < 1e-12);
        assert!((v.spiral_z(1, 9, 10, 50.0) - 5.0).abs() < 1e-12);
        assert!((v.spiral_z(37, 9, 10, 50.0) - 50.0).abs() < 1e-12);
        assert!((v.spiral_z(2, 0, 10, 50.0) - v.spiral_z(1, 0, 10, 50.0) - 1.25).abs() < 1e-12);
    }

    #[test]
    fn thick_thinnest_layers_start_the_first_turn_lower() {
        // 2 mm layers, at most 3.75: the first turn cannot start 2 mm up
        // and end 4 mm up; it starts 1.75 mm up.
        let p = Params {
            layer_height: 2.0,
            max_layer_height: 3.75,
            ..Params::default()
        };
        let v = VesselPlan::choose(&[60.0; 10], &p, 2).unwrap();
        assert!(v.first_mm <= 1.75 + 1e-9, "{}", v.first_mm);
        let top_of_first = v.spiral_z(1, 9, 10, 60.0) - v.base_mm();
        assert!(top_of_first <= 3.75 + 1e-9, "{top_of_first}");
        assert!(v.turn_mm[0] >= 2.0 - 1e-9);
    }

    #[test]
    fn uneven_rims_spread_over_the_turns_or_are_refused() {
        let p = Params::default();
        let v = VesselPlan::choose(&[40.0, 55.0, 60.0], &p, 2).unwrap();
        assert!(
            v.turn_mm[0] >= 1.25 - 1e-9 && v.turn_mm[1] <= 2.5 + 1e-9,
            "{v:?}"
        );
        // 28 mm of rim against 30 − 1 − 2.5 = 26.5 mm of clearance.
        let e = VesselPlan::choose(&[40.0, 68.0], &p, 2)
            .unwrap_err()
            .to_string();
        assert!(e.contains("varies by 28.0 mm"), "{e}");
        let tight = Params {
            max_layer_height: 1.3,
            nozzle_height: 40.0,
            ..Params::default()
        };
        let e = VesselPlan::choose(&[20.0, 30.0], &tight, 2)
            .unwrap_err()
            .to_string();
        assert!(e.contains("no whole number of spiral turns"), "{e}");
        // The most it may be: 13 turns over 2.5 mm of floor and 0.05 mm of
        // first turn lay 18.8 to 19.5 mm; 27.45 mm of wall over 13 turns is
        // 2.11 mm a layer.
        assert!(
            e.contains("with 13 turns the rim may lie from 18.8 to 19.5 mm (now 20.0 to 30.0 mm)")
                && e.contains("max_layer_height to about 2.11 mm"),
            "{e}"
        );
    }

    /// The rims of a raised arc of 9 columns above level 50 (mm): a hill.
    const HILL: [f64; 9] = [0.6, 1.2, 2.5, 4.6, 5.9, 5.7, 2.1, 1.6, 0.7];

    /// [`HILL`] with passes of 1 mm, the last turn at 49.4 mm.
    fn hill() -> RaisedArc {
        let e = HILL;
        let h: Vec<f64> = e.iter().map(|x| 50.0 + x).collect();
        let last = vec![49.4; 9];
        RaisedArc::new(50.0, 1.0, (10..19).collect(), &h, &last, 0.5).unwrap()
    }

    #[test]
    fn a_raised_arc_takes_odd_passes_before_its_peak_and_even_after() {
        let a = hill();
        assert_eq!(a.peak, 4);
        // The start's side: none under a pass (the rim turn lays 50.6),
        // then odd counts, 1 + 2 a pair: 1, 1, 3, 5. The end's side: even
        // counts, 4 for 5.7, but it reaches the last pass (5), which takes
        // it; then 2, 0, 0.
        assert_eq!(a.passes, vec![0, 1, 1, 3, 5, 5, 2, 0, 0]);
        // Tops: on every column but the first, whose rim the rim turn
        // lays; at the rim, or half a pass above the last pass.
        assert_eq!(
            (0..9).map(|j| a.has_top(j)).collect::<Vec<_>>(),
            vec![false, true, true, true, true, true, true, true, true]
        );
        assert!((a.top_z[1] - 51.5).abs() < 1e-9 && (a.top_z[2] - 52.5).abs() < 1e-9);
        // The rim turn lays H, or the rim itself where no pass goes, half
        // a layer above the last turn at least.
        assert_eq!(a.rim[0], 50.6);
        assert_eq!(a.rim[8], 50.0);
        for (j, e) in HILL.iter().enumerate() {
            let under = if a.passes[j] == 0 {
                a.rim[j]
            } else {
                50.0 + f64::from(a.passes[j])
            };
            let t = 50.0 + e - under;
            assert!(t < 2.0 + 1e-9, "column {j}: top {t}");
            if a.has_top(j) {
                assert!(
                    (a.top_z[j] - (50.0 + e).max(under + 0.5)).abs() < 1e-9,
                    "{j}"
                );
            }
        }
    }

    #[test]
    fn a_raised_arc_is_one_path_visiting_every_bead_once_from_its_end() {
        let a = hill();
        let (order, climbs) = a.order();
        // Every pass of every column and every top, once.
        let mut want: Vec<(usize, u32, bool)> = Vec::new();
        for j in 0..9 {
            want.extend((1..=a.passes[j]).map(|k| (j, k, false)));
            if a.has_top(j) {
                want.push((j, a.passes[j], true));
            }
        }
        let mut got = order.clone();
        got.sort_unstable();
        want.sort_unstable();
        assert_eq!(got, want);
        // It starts at the arc's end (the rim turn ends there) and steps
        // between neighbouring columns, or stays, never jumping.
        assert_eq!(order[0], (8, 0, true));
        for w in order.windows(2) {
            assert!(w[0].0.abs_diff(w[1].0) <= 1, "{:?} to {:?}", w[0], w[1]);
        }
        // Each bead rests on the one below it, laid before.
        for (i, &(j, k, top)) in order.iter().enumerate() {
            if k > 1 || top && k > 0 {
                let below = if top {
                    (j, k, false)
                } else {
                    (j, k - 1, false)
                };
                assert!(
                    order[..i].contains(&below),
                    "{:?} before {below:?}",
                    (j, k, top)
                );
            }
        }
        // The last climb runs over the peak (4) and ends on the far side.
        assert_eq!(&order[order.len() - 2..], &[(4, 5, true), (5, 5, true)]);
        assert_eq!(climbs, 5, "{order:?}");
    }

    #[test]
    fn a_second_rise_inside_a_raised_arc_is_named_with_the_most_it_may_be() {
        // 5 mm, down to 1 mm, up again to 4 mm: the end's side passes
        // cannot grow again after the dip.
        let e = [1.0, 3.0, 5.0, 3.0, 1.0, 2.5, 4.0, 2.0, 0.7];
        let h: Vec<f64> = e.iter().map(|x| 50.0 + x).collect();
        let (j, most) =
            RaisedArc::new(50.0, 1.0, (0..9).collect(), &h, &[49.4; 9], 0.5).unwrap_err();
        assert_eq!(j, 6);
        // It takes no more passes than the dip allows (0): its rim may be
        // two passes above the rim turn's 50 mm.
        assert!((most - 52.0).abs() < 1e-9, "{most}");
    }

    #[test]
    fn the_turn_just_laid_behind_the_seam_is_not_in_the_bodys_way() {
        // A round pot whose rim rises 8 mm from one side to the other, its
        // turns starting where the rim slopes most (u = 1/4): the turn just
        // ended behind the seam stands up to a slope's worth higher than
        // the nozzle starting the next, but it is the bead just laid, which
        // the nozzle rides on (the checker exempts it too). Counting it as
        // old clay refused such pots.
        let n = 300;
        let pts = circle(40.0, n);
        let h: Vec<f64> = (0..n)
            .map(|i| 40.0 + 4.0 * (1.0 - (std::f64::consts::TAU * i as f64 / n as f64).cos()))
            .collect();
        let p = Params::default();
        let v = VesselPlan::choose(&h, &p, 2).unwrap();
        let v = v.with(v.turns, n / 4, &p);
        let near = Neighbours::new(&pts, 5.0 + 3.0);
        assert_eq!(v.body_violation(&near, &h, 5.0 + 6.0), None);
        // Without the exemption, the seam is refused.
        assert!(v.body_violation(&near, &h, 0.0).is_some());
    }
}
