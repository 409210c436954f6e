//! Stage 4: toolpath → extrusion plan (paper §5.3, Algorithm 3;
//! docs/ALGORITHMS.md §6).
//!
//! Every bead starts at w_min. Walking bottom-up in print order, a point at
//! horizontal offset s from the point below needs w = s / (1 − overlap),
//! clamped to [w_min, w_max]; both points are widened to it together (the
//! paper's "expand both with the same scale"). A second walk, top-down,
//! widens the point below wherever the overlap is still short of the
//! target (the paper adjusts "twice"), as far as that overlap needs and
//! no further, so a wide bead tapers down over a bead or two. With
//! s ≤ w_max (1 − overlap) from the support-free correction, every bead then
//! overlaps the one below by at least the target fraction of its width.
//! No bead is narrower than it is tall (within w_max).
//!
//! The volume of a move is the cuboid L · w̄ · Δz̄ (paper Fig. 5), except
//! a turnaround step, which climbs its own column to start the next layer:
//! it gets the clay the end of that layer needs, the half disc
//! (π/8) · w² · Δz of the new bead's rounded end (docs/ALGORITHMS.md §6).

use crate::design::Params;
use crate::toolpath::Toolpath;
use crate::widths::{across_chord, lean_width, least_support, overlap_fraction};

/// Bead sizes and volumes along a toolpath.
#[derive(Clone, Debug, PartialEq)]
pub struct Extrusion {
    /// Bead width at each point (mm).
    pub width: Vec<f64>,
    /// Layer height at each point: vertical distance to the point below, or
    /// to the bed (mm).
    pub layer_height: Vec<f64>,
    /// Clay volume of the move ending at each point (mm³); 0 for the first.
    pub volume: Vec<f64>,
    /// Sum of `volume` (mm³).
    pub total_volume: f64,
    /// Of it, the clay of the turnaround steps (mm³).
    pub turn_volume: f64,
    /// What the steps would get as cuboids, as the paper extrudes them
    /// (mm³): the clay that piled up at the turns.
    pub turn_volume_cuboid: f64,
    /// How many moves are steps ([`is_step`]).
    pub turn_steps: usize,
    /// Sum of move lengths (mm).
    pub path_length: f64,
    /// Moves printed slower than the feedrate, in order: the move's index
    /// (the point it ends at) and the fraction of the feedrate (a step
    /// laying more clay a millimetre than the bead before it, with
    /// `params.even_turn_flow`).
    pub slow: Vec<(u32, f64)>,
}

impl Extrusion {
    /// The fraction of the feedrate of each move, from the move into
    /// point 1 on: 1 but for the slowed steps of [`Extrusion::slow`].
    pub fn feed_factors(&self) -> impl Iterator<Item = f64> + '_ {
        let mut slow = self.slow.iter().peekable();
        (1..self.volume.len()).map(move |i| match slow.peek() {
            Some(&&(at, k)) if at as usize == i => {
                slow.next();
                k
            }
            _ => 1.0,
        })
    }
}

/// The slowest a step is printed, as a fraction of the feedrate: a
/// screw or piston cannot slow much further without stalling the clay.
pub const MIN_TURN_FEED: f64 = 0.25;

/// How far the point below (`q`) lies across the bead at point `i` on a
/// twisted surface: the horizontal offset less its part along the path,
/// which the bead below carries on under it. A twisted vessel's column
/// turns along the wall a layer (2.7 mm on a 33 mm radius at 360° over
/// 97 mm): counted whole it widened every bead to w_max and doubled the
/// clay. (Untwisted, the point below lies across, as Algorithm 3 has it.)
fn across(path: &Toolpath, i: usize, q: [f64; 3]) -> f64 {
    let p = path.points[i].pos;
    let d = [p[0] - q[0], p[1] - q[1]];
    // The bead's direction: the chord of its neighbours in its own
    // layer (a step up or down is no part of it).
    let level = |k: usize| {
        let r = path.points[k].pos;
        ((r[2] - p[2]).abs() < 0.5 * (p[2] - q[2]).abs()).then_some(r)
    };
    let a = i.checked_sub(1).and_then(level).unwrap_or(p);
    let b = path
        .points
        .get(i + 1)
        .and_then(|_| level(i + 1))
        .unwrap_or(p);
    across_chord([b[0] - a[0], b[1] - a[1]], d)
}

/// For a twisted vessel, whether point `i` lies behind the start of the
/// wall's first turn though its point below `b` is on that turn: a
/// column turns with height, so the point below a second-turn point lies
/// along the wall from it (4.7 mm at r 30 mm for two turns over 100 mm),
/// and where it lies ahead of the first turn's start, nothing but the
/// floor is under the point (the round vase twisted −720° laid three
/// beads 1.5 mm wide over a 2.5 mm gap there). Always false otherwise.
fn twisted_wall_start(path: &Toolpath) -> impl Fn(usize, usize) -> bool + '_ {
    use crate::toolpath::PointKind;
    let pts = &path.points;
    let start = path
        .vessel
        .as_ref()
        .filter(|_| path.twisted)
        .and_then(|_| pts.iter().position(|p| p.kind != PointKind::Floor));
    // Path length in plan from the wall's start to each of its points.
    let mut s = vec![0.0; pts.len()];
    if let Some(w) = start {
        for k in w + 1..pts.len() {
            let (a, b) = (pts[k - 1].pos, pts[k].pos);
            s[k] = s[k - 1] + (b[0] - a[0]).hypot(b[1] - a[1]);
        }
    }
    move |i, b| {
        let Some(w) = start else { return false };
        if b < w || b + 1 >= pts.len() {
            return false;
        }
        let (p, q) = (pts[i].pos, pts[b].pos);
        let (lo, hi) = (pts[b.saturating_sub(1).max(w)].pos, pts[b + 1].pos);
        let t = [hi[0] - lo[0], hi[1] - lo[1]];
        let l = t[0].hypot(t[1]);
        if l < 1e-9 {
            return false;
        }
        let along = ((p[0] - q[0]) * t[0] + (p[1] - q[1]) * t[1]) / l;
        s[b] + along < 0.0
    }
}

/// Computes widths and volumes. `origin` is where the path's origin lands
/// on the bed (the printer's): steps are told from beads on the
/// coordinates the G-code will carry, as the checker reads them.
pub fn plan_extrusion(path: &Toolpath, params: &Params, origin: [f64; 2]) -> Extrusion {
    let n = path.points.len();
    let (wmin, wmax, ov) = (params.width_min, params.width_max, params.overlap);
    let mut width = vec![wmin; n];
    // A vessel's wall starts on its floor's top (or the bed).
    let floor_top = path.vessel.as_ref().map_or(0.0, |v| v.floor_top_mm);
    let mut layer_height = Vec::with_capacity(n);
    let mut offset = Vec::with_capacity(n);
    let before_wall = twisted_wall_start(path);
    for (i, p) in path.points.iter().enumerate() {
        match path.below[i] {
            Some(b) if before_wall(i, b as usize) => {
                // Over the floor, where the wall's first turn has not
                // yet begun (docs/ALGORITHMS.md §8, "Twist").
                layer_height.push(p.pos[2] - floor_top);
                offset.push(0.0);
            }
            Some(b) => {
                let q = path.points[b as usize].pos;
                layer_height.push(p.pos[2] - q[2]);
                offset.push(if path.twisted {
                    across(path, i, q)
                } else {
                    (p.pos[0] - q[0]).hypot(p.pos[1] - q[1])
                });
            }
            None if p.kind == crate::toolpath::PointKind::Floor => {
                layer_height.push(p.pos[2]);
                offset.push(0.0);
            }
            None => {
                layer_height.push(p.pos[2] - floor_top);
                offset.push(0.0);
            }
        }
    }
    for i in 0..n {
        if let Some(b) = path.below[i] {
            let need = lean_width(offset[i], params);
            width[i] = width[i].max(need);
            width[b as usize] = width[b as usize].max(need);
        }
    }
    for i in (0..n).rev() {
        if let Some(b) = path.below[i] {
            let b = b as usize;
            if overlap_fraction(width[i], width[b], offset[i]) < ov {
                width[b] = width[b].max(least_support(width[i], width[b], offset[i], ov).min(wmax));
            }
        }
    }
    // A bead is at least as wide as it is tall (within w_max): a taller
    // one does not stand, and the check fails clay farther below a bead
    // than it is wide (a vessel's first turn over its floor, 3.75 mm up
    // on 2 / 3.75 mm layers, was left 3 mm wide).
    for (w, h) in width.iter_mut().zip(&layer_height) {
        *w = w.max(h.min(wmax));
    }
    // A floor's beads are as wide as their neighbours in the layer need,
    // whatever lies below them (docs/ALGORITHMS.md §8).
    if let Some(v) = &path.vessel {
        for &(i, w) in &v.floor_widths {
            width[i as usize] = w;
        }
    }
    let mut volume = Vec::with_capacity(n);
    let (mut total, mut length, mut turn, mut turn_cuboid) = (0.0, 0.0, 0.0, 0.0);
    let mut turn_steps = 0;
    let mut slow = Vec::new();
    // Clay a millimetre of the last bead that was no step.
    let mut bead_rate = f64::NAN;
    volume.push(0.0);
    for i in 1..n {
        let (a, b) = (path.points[i - 1].pos, path.points[i].pos);
        let xy2 = (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2);
        let l = (xy2 + (a[2] - b[2]).powi(2)).sqrt();
        let cuboid =
            l * 0.5 * (width[i] + width[i - 1]) * 0.5 * (layer_height[i] + layer_height[i - 1]);
        let v = if steep(a, b, xy2, origin) {
            turn_cuboid += cuboid;
            turn_steps += 1;
            let v = step_volume(width[i], b[2] - a[2]);
            turn += v;
            // The extruder keeps the bead's flow: the nozzle slows where
            // the step lays more clay a millimetre.
            let rate = v / l.max(1e-9);
            if params.even_turn_flow && rate > bead_rate {
                slow.push((i as u32, (bead_rate / rate).max(MIN_TURN_FEED)));
            }
            v
        } else {
            if l > 1e-9 {
                bead_rate = cuboid / l;
            }
            cuboid
        };
        volume.push(v);
        total += v;
        length += l;
    }
    Extrusion {
        width,
        layer_height,
        volume,
        total_volume: total,
        turn_volume: turn,
        turn_volume_cuboid: turn_cuboid,
        turn_steps,
        path_length: length,
        slow,
    }
}

/// Whether the move into point `i` is a step: it climbs (or drops) at
/// least half as much as it runs in plan, as the checker reads a step
/// (docs/CHECKER.md, "Turns"), on the coordinates the G-code carries
/// (3 decimals, with the path's `origin` on the bed added) so the two
/// agree on a move at the boundary. Such a move does not lie on the bead
/// below (its clay would run down it): the turnarounds of the zig-zag,
/// which climb their own column, and the steepest stretches of a top
/// edge.
pub fn is_step(path: &Toolpath, i: usize, origin: [f64; 2]) -> bool {
    let Some(prev) = i.checked_sub(1) else {
        return false;
    };
    let (q, p) = (path.points[prev].pos, path.points[i].pos);
    steep(q, p, (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2), origin)
}

/// [`is_step`] for the move from `a` to `b`, `xy2` the square of its plan
/// length.
fn steep(a: [f64; 3], b: [f64; 3], xy2: f64, origin: [f64; 2]) -> bool {
    // Rounding moves each coordinate by at most 0.0005 mm: away from the
    // boundary the exact coordinates answer (in squares: no root).
    let two_rise = 2.0 * (b[2] - a[2]).abs();
    if xy2 > (two_rise + 0.01).powi(2) {
        return false;
    }
    if two_rise > 0.01 && xy2 < (two_rise - 0.01).powi(2) {
        return true;
    }
    let at = |p: [f64; 3]| {
        let r = |v: f64| (v * 1000.0).round() / 1000.0;
        [r(p[0] + origin[0]), r(p[1] + origin[1]), r(p[2])]
    };
    let (p, q) = (at(b), at(a));
    let rise = (p[2] - q[2]).abs();
    rise > 0.0 && (p[0] - q[0]).hypot(p[1] - q[1]) <= 2.0 * rise
}

/// The clay a step lays (mm³): the rounded end of the new layer's bead, a
/// half disc of its width `w` as high as the step climbs (`dz`), so E
/// keeps rising and the turn gets what it needs, not the cuboid of a bead
/// as long as the climb.
pub fn step_volume(w: f64, dz: f64) -> f64 {
    std::f64::consts::PI / 8.0 * w * w * dz.abs()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::toolpath::{PathPoint, PointKind};
    use crate::widths::lowest_bead_width;

    fn column(offsets: &[f64], dz: f64) -> Toolpath {
        let points: Vec<PathPoint> = offsets
            .iter()
            .enumerate()
            .map(|(k, &x)| PathPoint {
                pos: [x, 0.0, dz * (k + 1) as f64],
                column: 0,
                pass: k as u32 + 1,
                kind: PointKind::Pass,
            })
            .collect();
        let below = (0..points.len())
            .map(|i| i.checked_sub(1).map(|b| b as u32))
            .collect();
        Toolpath {
            points,
            below,
            passes: offsets.len() as u32,
            stages: 1,
            returning_points: 0,
            vessel: None,
            twisted: false,
        }
    }

    #[test]
    fn vertical_wall_keeps_minimum_width() {
        let t = column(&[0.0, 0.0, 0.0], 1.25);
        let e = plan_extrusion(&t, &Params::default(), [0.0; 2]);
        assert_eq!(e.width, vec![3.0; 3]);
        assert_eq!(e.layer_height, vec![1.25; 3]);
    }

    #[test]
    fn widths_follow_algorithm_3() {
        // Offsets 0, 1.5 (w = 3·1.5 = 4.5), then 1.5 + 0.5 (w stays 4.5 from below link).
        let t = column(&[0.0, 1.5, 2.0], 1.25);
        let p = Params::default();
        let e = plan_extrusion(&t, &p, [0.0; 2]);
        assert!((e.width[1] - 4.5).abs() < 1e-12, "{:?}", e.width);
        assert!(
            (e.width[0] - 4.5).abs() < 1e-12,
            "the bead below widens with it"
        );
        for i in 1..3 {
            let f = overlap_fraction(
                e.width[i],
                e.width[i - 1],
                (t.points[i].pos[0] - t.points[i - 1].pos[0]).abs(),
            );
            assert!(f >= p.overlap - 1e-12, "bead {i} overlap {f}");
        }
    }

    #[test]
    fn the_lowest_bead_of_a_column_is_as_wide_as_the_path_makes_it() {
        let p = Params::default();
        // Closed forms (w_min 3, w_max 6, overlap 2/3: a lean of d needs
        // 3d): upright, one lean of 1.5, a lean past w_max.
        assert_eq!(lowest_bead_width(&[], &p), 3.0);
        assert_eq!(lowest_bead_width(&[0.0, 0.0], &p), 3.0);
        assert!((lowest_bead_width(&[1.5], &p) - 4.5).abs() < 1e-12);
        // A 6 mm bead (w_max) straight over the lowest needs it 4 wide.
        assert!((lowest_bead_width(&[0.0, 3.0], &p) - 4.0).abs() < 1e-9);
        // A lean high up widens the column below it as far as each bead
        // needs: 4.5 mm beads 0.96 off a 3 mm bead overlap it by 0.62 <
        // 2/3, so it widens to 3.42 (its near edge 0.75 mm past the upper
        // bead's middle), and the bead under that to 3.06, not to 4.5 all
        // the way down.
        assert!((lowest_bead_width(&[0.96, 0.96, 1.5], &p) - 3.06).abs() < 1e-9);
        // The same as `plan_extrusion` over such columns, leaning either
        // way by up to 2 mm a layer.
        let mut x = 0.37_f64;
        for _ in 0..200 {
            let leans: Vec<f64> = (0..6)
                .map(|_| {
                    x = (x * 7.31 + 0.17).fract();
                    4.0 * x - 2.0
                })
                .collect();
            let offsets: Vec<f64> = std::iter::once(0.0)
                .chain(leans.iter().scan(0.0, |at, d| {
                    *at += d;
                    Some(*at)
                }))
                .collect();
            let e = plan_extrusion(&column(&offsets, 1.25), &p, [0.0; 2]);
            let abs: Vec<f64> = leans.iter().map(|d| d.abs()).collect();
            assert!(
                (lowest_bead_width(&abs, &p) - e.width[0]).abs() < 1e-12,
                "{leans:?}: {:?}",
                e.width
            );
        }
    }

    #[test]
    fn a_beads_volume_is_the_cuboid() {
        // Two points 10 mm apart on the bed, 1.25 mm high, 3 mm wide.
        let mut t = column(&[0.0, 10.0], 1.25);
        t.points[1].pos[2] = 1.25;
        t.below = vec![None, None];
        let e = plan_extrusion(&t, &Params::default(), [0.0; 2]);
        assert!((e.total_volume - 10.0 * 3.0 * 1.25).abs() < 1e-12);
        assert_eq!(e.turn_volume, 0.0);
    }

    #[test]
    fn a_step_laying_more_clay_a_millimetre_than_its_bead_is_slowed() {
        // A 10 mm bead on the bed, then a 1.25 mm step up its end.
        let mut t = column(&[0.0, 10.0, 10.0], 1.25);
        t.points[1].pos[2] = 1.25;
        t.points[2].pos[2] = 2.5;
        t.below = vec![None, None, Some(1)];
        // 3 mm beads: 3.75 mm³ a mm on the bead, π/8 · 9 = 3.53 on the
        // step: even already.
        let e = plan_extrusion(&t, &Params::default(), [0.0; 2]);
        assert!(e.slow.is_empty(), "{:?}", e.slow);
        // 6 mm beads: 7.5 on the bead, π/8 · 36 = 14.1 on the step.
        let wide = Params {
            width_min: 6.0,
            ..Params::default()
        };
        let e = plan_extrusion(&t, &wide, [0.0; 2]);
        assert_eq!(e.slow.len(), 1);
        let (at, k) = e.slow[0];
        assert_eq!(at, 2);
        assert!(
            (k - 7.5 / (std::f64::consts::PI / 8.0 * 36.0)).abs() < 1e-12,
            "{k}"
        );
        let off = Params {
            even_turn_flow: false,
            ..wide
        };
        assert!(plan_extrusion(&t, &off, [0.0; 2]).slow.is_empty());
    }

    #[test]
    fn a_steps_volume_is_the_half_disc_end_of_the_new_layer() {
        // One vertical step of 1.25 mm up its own column, width 3: the
        // half disc π/8 · 3² · 1.25, where the cuboid gave 1.25 · 3 · 1.25.
        let t = column(&[0.0, 0.0], 1.25);
        let e = plan_extrusion(&t, &Params::default(), [0.0; 2]);
        let half_disc = std::f64::consts::PI / 8.0 * 9.0 * 1.25;
        assert!((e.total_volume - half_disc).abs() < 1e-12);
        assert!((e.turn_volume - half_disc).abs() < 1e-12);
        assert!((e.turn_volume_cuboid - 1.25 * 3.0 * 1.25).abs() < 1e-12);
        // A climb of 2.5 mm over 2 mm of plan at w = 6 (the pile):
        // the cuboid is a 3.2 mm bead, 48 mm³; the step needs 35 mm³.
        assert!((step_volume(6.0, 2.5) - std::f64::consts::PI / 8.0 * 36.0 * 2.5).abs() < 1e-12);
        // A move that runs more than twice as far as it climbs is a bead,
        // not a step.
        let slant = column(&[0.0, 3.0], 1.25);
        assert!(!is_step(&slant, 1, [0.0; 2]));
        assert!(is_step(&t, 1, [0.0; 2]));
    }
}
