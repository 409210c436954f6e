//! Stage 3: corrected surface → toolpath (paper §5.2, Algorithm 2, Fig. 7;
//! docs/ALGORITHMS.md §3).
//!
//! One continuous boustrophedon over the surface's samples: pass k visits,
//! in order, the columns the [`LayerPlan`](crate::layers::LayerPlan) gives
//! it (always a run ending at the tall end). At the tall end the path steps
//! up along the end profile; after a pass toward the short end it climbs
//! along the top edge (laying the top-edge beads of the columns the next
//! pass no longer reaches) to the start of the next pass: the returning
//! turn. Every sample is visited exactly once.

use crate::correct::Corrected;
use crate::floor::{
    coverage, ring_area, spiral_floor_covering, FloorRefusal, FloorSpiral, MIN_COVER,
};
use crate::vessel::{floor_beads, VesselPlan};
use crate::widths::{across_chord, lowest_bead_width};
use serde::Serialize;

/// What kind of sample a path point is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PointKind {
    /// A point of a regular pass.
    Pass,
    /// A top-edge bead laid by a returning turn; in a vessel, a bead of
    /// the last turn, which lays the rim level.
    Top,
    /// A bead of a vessel's floor inside its first turn (not a surface
    /// sample).
    Floor,
}

/// One point of the toolpath, remembering where it came from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathPoint {
    /// Position relative to `o` (mm).
    pub pos: [f64; 3],
    /// Transition curve (column) index along Ψ.
    pub column: u32,
    /// Pass number (1-based); for a top bead, the pass it follows.
    pub pass: u32,
    /// Regular pass point or top-edge bead.
    pub kind: PointKind,
}

/// The toolpath: points in print order.
#[derive(Clone, Debug, PartialEq)]
pub struct Toolpath {
    /// The points, in the order the nozzle visits them.
    pub points: Vec<PathPoint>,
    /// For each point, the index of the point directly below it on the same
    /// transition curve (`None` on the first layer).
    pub below: Vec<Option<u32>>,
    /// Number of passes (K).
    pub passes: u32,
    /// 1 for the paper's single stage, 2 with an upper stage.
    pub stages: u8,
    /// Number of returning turns that climb the top edge.
    pub returning_points: u32,
    /// A vessel's floor and turns (closed Ψ), else `None`.
    pub vessel: Option<VesselPath>,
    /// Whether the surface turns as it rises (a twist): the point below
    /// a point then lies partly along its bead, not only across it.
    pub twisted: bool,
}

/// Orders the samples of a corrected surface into one continuous path.
pub fn plan_path(c: &Corrected) -> Toolpath {
    let s = &c.surface;
    if let Some(v) = &s.vessel {
        return plan_vessel_path(c, v);
    }
    let n = s.columns.len();
    let k_max = s.plan.passes;
    // a[k]: first ordered column visited by pass k.
    let mut start = vec![0usize; k_max as usize + 2];
    let mut m = 0;
    for (k, a) in start.iter_mut().enumerate().skip(1) {
        while m < n && s.columns[s.ordered(m)].passes < k as u32 {
            m += 1;
        }
        *a = m;
    }
    let mut points = Vec::with_capacity(s.samples.len());
    let mut sample_of = Vec::with_capacity(s.samples.len());
    let mut push = |m: usize, local: usize, pass: u32, kind: PointKind| {
        let ci = s.ordered(m);
        let col = &s.columns[ci];
        let si = col.first as usize + local;
        points.push(PathPoint {
            pos: s.position(ci, si),
            column: ci as u32,
            pass,
            kind,
        });
        sample_of.push(si);
    };
    let mut returning = 0;
    for k in 1..=k_max {
        let a = start[k as usize];
        if s.plan.toward_tall(k) {
            if k > 1 && !s.plan.toward_tall(k - 1) {
                let prev = start[k as usize - 1];
                if a > prev {
                    returning += 1;
                }
                for m in prev..a {
                    let col = &s.columns[s.ordered(m)];
                    if col.top {
                        push(m, col.passes as usize, k - 1, PointKind::Top);
                    }
                }
            }
            for m in a..n {
                push(m, k as usize - 1, k, PointKind::Pass);
            }
        } else {
            for m in (a..n).rev() {
                push(m, k as usize - 1, k, PointKind::Pass);
            }
        }
    }
    let mut path_of = vec![u32::MAX; s.samples.len()];
    for (pi, &si) in sample_of.iter().enumerate() {
        path_of[si] = pi as u32;
    }
    debug_assert!(
        path_of.iter().all(|&p| p != u32::MAX),
        "every sample is visited"
    );
    let below = sample_of
        .iter()
        .zip(&points)
        .map(|(&si, p)| {
            let col = &s.columns[p.column as usize];
            (si > col.first as usize).then(|| path_of[si - 1])
        })
        .collect();
    Toolpath {
        points,
        below,
        passes: k_max,
        stages: if s.plan.two_stage() { 2 } else { 1 },
        returning_points: returning,
        vessel: None,
        twisted: s.columns.iter().any(|c| c.twist != 0.0),
    }
}

/// The toolpath of a vessel (docs/ALGORITHMS.md §8): the floor's layers,
/// each one spiral ([`crate::floor`]) inside the wall's first turn, inward
/// on one layer and outward on the next so that the last ends where the
/// wall starts; then the spiral turns of the wall and the rim. Nothing
/// closes on itself at its own height and no move crosses clay: a floor
/// layer steps straight up onto the next where the one below ended, and
/// the last steps up onto the wall's first turn, a layer above the floor.
pub fn plan_vessel_path(c: &Corrected, v: &VesselPlan) -> Toolpath {
    let s = &c.surface;
    let n = s.columns.len();
    let order = |m: usize| (v.start + m) % n;
    let laid = (v.floor_layers > 0).then(|| vessel_floor(c, v));
    // A floor covering too little, or none, is refused by name after the
    // path is planned (`fits`).
    let floor_refusal = match &laid {
        Some(Err(why)) => Some(why.to_string()),
        Some(Ok(f)) if f.cover < MIN_COVER => Some(format!(
            "the floor's one spiral covers only {:.1} % of the inside (at least {:.0} % is needed)",
            100.0 * f.cover,
            100.0 * MIN_COVER
        )),
        _ => None,
    };
    let floor = laid.and_then(|f| f.ok());
    let floor_pts = floor.as_ref().map_or(0, |f| f.spiral.pts.len());
    let total = s.samples.len() + floor_pts * v.base_layers as usize;
    let mut points = Vec::with_capacity(total);
    let mut below: Vec<Option<u32>> = Vec::with_capacity(total);
    let mut floor_widths = Vec::with_capacity(floor_pts * v.base_layers as usize);
    if let Some(f) = &floor {
        let m = f.spiral.pts.len();
        for layer in 1..=v.base_layers {
            let z = f64::from(layer) * v.base_layer_mm;
            // The last floor layer runs outward, ending at the wall's
            // start; the one before inward, …
            let outward = (v.base_layers - layer).is_multiple_of(2);
            let first = points.len() as u32;
            for step in 0..m {
                let j = if outward { m - 1 - step } else { step };
                // The layer below ran the same points the other way.
                below.push((layer > 1).then(|| first - 1 - step as u32));
                floor_widths.push((points.len() as u32, f.spiral.widths[j]));
                points.push(PathPoint {
                    pos: [f.spiral.pts[j][0], f.spiral.pts[j][1], z],
                    column: order(0) as u32,
                    pass: layer,
                    kind: PointKind::Floor,
                });
            }
        }
    }
    if let (Some(last), Some(_)) = (points.last().copied(), &floor) {
        // The floor ends half a pitch outside the wall's start: its last
        // bead runs on, on its own layer, to under the wall's first point,
        // and the path steps straight up from there (a bead from the
        // floor's end in to the wall, a layer up, leaned 58° over the
        // floor's edge; a step up that slope was read as a thin bead).
        let first = s.position(order(0), s.columns[order(0)].first as usize);
        let end = points.len() - 1;
        below.push(below[end]);
        floor_widths.push((points.len() as u32, s.params.width_min));
        points.push(PathPoint {
            pos: [first[0], first[1], last.pos[2]],
            ..last
        });
    }
    let mut path_of = vec![u32::MAX; s.samples.len()];
    let mut visit = |points: &mut Vec<PathPoint>, i: usize, local: usize, pass, kind| {
        let col = &s.columns[i];
        let si = col.first as usize + local;
        path_of[si] = points.len() as u32;
        below.push((local > 0).then(|| path_of[si - 1]));
        points.push(PathPoint {
            pos: s.position(i, si),
            column: i as u32,
            pass,
            kind,
        });
    };
    let base = v.base_layers;
    for k in 1..=v.turns {
        for m in 0..n {
            visit(
                &mut points,
                order(m),
                k as usize - 1,
                base + k,
                PointKind::Pass,
            );
        }
    }
    let rim = base + v.turns + 1;
    for i in (0..n).map(order) {
        if s.columns[i].top {
            let local = s.columns[i].passes as usize;
            visit(&mut points, i, local, rim, PointKind::Top);
        }
    }
    let mut passes = rim;
    let mut returning = 0;
    if let Some(a) = &v.arc {
        // The raised arc (docs/ALGORITHMS.md §8, "Partial layers"), its
        // beads in the order `RaisedArc::order` gives. Sample `local` of an
        // arc column: its turns, its rim bead, then its passes and top;
        // its path point is numbered on from the rim as the samples lie
        // (the mesh finds a point's sample by its pass).
        let (order, climbs) = a.order();
        for (j, k, top) in order {
            let c = a.columns[j];
            let local = s.columns[c].passes as usize + k as usize + usize::from(top);
            visit(
                &mut points,
                c,
                local,
                base + local as u32 + 1,
                PointKind::Pass,
            );
        }
        returning = climbs;
        passes = rim + a.most_passes() + 1;
    }
    debug_assert!(
        path_of.iter().all(|&p| p != u32::MAX),
        "every sample is visited"
    );
    let (floor_area, floor_cover, floor_turns) = match &floor {
        Some(f) => (ring_area(&f.ring), f.cover, f.spiral.turns),
        None => (0.0, 0.0, 0),
    };
    Toolpath {
        points,
        below,
        passes,
        stages: 1,
        returning_points: returning,
        vessel: Some(VesselPath {
            floor_layers: if floor.is_some() { v.floor_layers } else { 0 },
            floor_turns,
            floor_area_mm2: floor_area,
            floor_cover,
            floor_top_mm: v.base_mm(),
            turns: v.turns,
            floor_widths,
            floor_refusal,
        }),
        twisted: s.columns.iter().any(|c| c.twist != 0.0),
    }
}

/// A floor laid out under a vessel's first turn.
struct LaidFloor {
    /// The first turn in plan, from the start column on.
    ring: Vec<[f64; 2]>,
    spiral: FloorSpiral,
    cover: f64,
}

/// The floor spiral inside the wall's first turn as corrected, from the
/// start column on; where it covers less than [`MIN_COVER`] and the
/// corrections moved that turn, the better of it and the spiral inside
/// the turn as drawn. Why no spiral can be laid, if none can.
fn vessel_floor(c: &Corrected, v: &VesselPlan) -> Result<LaidFloor, FloorRefusal> {
    let s = &c.surface;
    let n = s.columns.len();
    let beads = floor_beads(&s.params, s.spacing);
    let corrected: Vec<[f64; 2]> = (0..n)
        .map(|m| {
            let i = (v.start + m) % n;
            let p = s.position(i, s.columns[i].first as usize);
            [p[0], p[1]]
        })
        .collect();
    let mut out = first_turn_excess(c, v, &corrected);
    // The cover reported and judged is measured on a 0.5 mm grid (the
    // spiral was chosen on a 1 mm one).
    let lay = |ring: Vec<[f64; 2]>| {
        spiral_floor_covering(&ring, beads, 0.0, !c.blended_floor).map(|spiral| LaidFloor {
            cover: coverage(&ring, &spiral, 0.5),
            ring,
            spiral,
        })
    };
    // The floor's last bead runs on to under the wall's first point: moved
    // out, a floor that ends more than half a bead from it would run back
    // across its own outer ring (2.8 mm on a rounded triangle whose rim
    // bead leaned 2 mm at the start, widening that column to w_max), so
    // it is laid where the wall is instead.
    let start = corrected[0];
    let ends_near = |f: &LaidFloor| {
        (f.spiral.pts.first())
            .is_some_and(|p| (p[0] - start[0]).hypot(p[1] - start[1]) <= 0.5 * s.params.width_min)
    };
    let mut first = lay(moved_out(&corrected, &out));
    if out.iter().any(|&e| e > 0.0) && first.as_ref().is_ok_and(|f| !ends_near(f)) {
        out.fill(0.0);
        first = lay(corrected);
    }
    if first.as_ref().is_ok_and(|f| f.cover >= MIN_COVER) {
        return first;
    }
    // Only then the turn as drawn, if the corrections moved it.
    let drawn: Vec<[f64; 2]> = (0..n)
        .map(|m| {
            let col = &s.columns[(v.start + m) % n];
            let z = s.samples[col.first as usize].z;
            let q = col.point(s.design_offset(col, z, 1.0), 0.0);
            [q[0], q[1]]
        })
        .collect();
    let drawn = moved_out(&drawn, &out);
    let moved = first.as_ref().map_or(true, |f| {
        f.ring
            .iter()
            .zip(&drawn)
            .any(|(a, b)| (a[0] - b[0]).abs() + (a[1] - b[1]).abs() >= 1e-9)
    });
    if !moved {
        return first;
    }
    match (first, lay(drawn)) {
        (Ok(a), Ok(b)) => Ok(if b.cover > a.cover { b } else { a }),
        (Ok(a), Err(_)) => Ok(a),
        (Err(_), b) => b,
    }
}

/// How far the wall's first turn's bead reaches outside a floor bead on
/// the same line, at each column from the start column on (mm, ≥ 0): half
/// of what it is laid wider than `width_min`. The extrusion stage widens
/// a column's beads where the one above leans off them, each as far as
/// the one above needs (the paper's Algorithm 3; [`lowest_bead_width`]),
/// and a bead taller than wide. The floor's outermost ring goes out by
/// that much, so its outer edge is the wall's (docs/ALGORITHMS.md §8, "A
/// flush foot"): under the bowl, when every bead under a wide one was
/// widened to its width, the first turn was laid 3.8 mm wide on 3 mm
/// floor beads, its edge 0.4 mm outside them.
fn first_turn_excess(c: &Corrected, v: &VesselPlan, ring: &[[f64; 2]]) -> Vec<f64> {
    let s = &c.surface;
    let n = s.columns.len();
    let (wmin, wmax) = (s.params.width_min, s.params.width_max);
    let floor_top = v.base_mm();
    let mut leans = Vec::new();
    (0..n)
        .map(|m| {
            let i = (v.start + m) % n;
            let col = &s.columns[i];
            let first = col.first as usize;
            // Each bead's lean off the one below: across the wall where
            // the column twists (the rest runs along the bead below, as
            // the extrusion stage reads it), else all of it.
            leans.clear();
            leans.extend((1..col.len()).map(|k| {
                let (a, b) = (s.position(i, first + k - 1), s.position(i, first + k));
                let d = [b[0] - a[0], b[1] - a[1]];
                if col.twist == 0.0 {
                    return d[0].hypot(d[1]);
                }
                let (p, q) = (ring[(m + n - 1) % n], ring[(m + 1) % n]);
                across_chord([q[0] - p[0], q[1] - p[1]], d)
            }));
            let a = s.position(i, first);
            let w = lowest_bead_width(&leans, &s.params).max((a[2] - floor_top).min(wmax));
            0.5 * (w - wmin).max(0.0)
        })
        .collect()
}

/// `ring` with each point moved `out[m]` mm along the ring's outward
/// normal there (the chord of its neighbours turned a right angle).
fn moved_out(ring: &[[f64; 2]], out: &[f64]) -> Vec<[f64; 2]> {
    let n = ring.len();
    // Counter-clockwise (positive area): the outside on the chord's right.
    let side = crate::plane::signed_area2(ring).signum();
    (0..n)
        .map(|m| {
            let (p, q) = (ring[(m + n - 1) % n], ring[(m + 1) % n]);
            let t = [q[0] - p[0], q[1] - p[1]];
            let l = t[0].hypot(t[1]);
            if out[m] <= 0.0 || l < 1e-9 {
                return ring[m];
            }
            let k = side * out[m] / l;
            [ring[m][0] + k * t[1], ring[m][1] - k * t[0]]
        })
        .collect()
}

/// What the path of a vessel holds beyond its points.
#[derive(Clone, Debug, PartialEq)]
pub struct VesselPath {
    /// Floor layers (0: bottomless).
    pub floor_layers: u32,
    /// Turns of each floor layer's spiral.
    pub floor_turns: u32,
    /// Area inside the wall's first turn (mm²), 0 for a bottomless vessel.
    pub floor_area_mm2: f64,
    /// The share of that area the floor's beads cover (0 to 1).
    pub floor_cover: f64,
    /// The top of the floor (mm): where the wall's first turn stands; 0
    /// for a bottomless vessel.
    pub floor_top_mm: f64,
    /// Spiral turns of the wall.
    pub turns: u32,
    /// Every floor point (in order) and its bead width (mm): as wide as
    /// its neighbouring turns' distance needs ([`crate::floor`]).
    pub floor_widths: Vec<(u32, f64)>,
    /// Why the floor asked for cannot be laid as one spiral covering the
    /// inside, if so: `finish` refuses the design with it.
    pub floor_refusal: Option<String>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::correct::correct;
    use crate::design::Design;
    use crate::surface::sample_surface;

    fn path(hs: f64, ht: f64) -> (Corrected, Toolpath) {
        let d = Design::from_json(&format!(
            r#"{{"sweepclay":1,"profile_start":{{"control_points":[[0,0],[0,{hs}]]}},
                "profile_end":{{"control_points":[[0,0],[0,{ht}]]}},
                "trajectory":{{"points":[[-60,30],[60,30]]}}}}"#
        ))
        .unwrap();
        let c = correct(&sample_surface(&d).unwrap()).unwrap();
        let t = plan_path(&c);
        (c, t)
    }

    #[test]
    fn single_stage_is_a_zig_zag_of_full_passes() {
        let (c, t) = path(20.0, 25.0);
        assert_eq!(t.stages, 1);
        assert_eq!(t.passes, 16);
        let n = c.surface.columns.len();
        assert_eq!(t.points.len(), 16 * n);
        // Pass 1 runs from the short start to the tall end, pass 2 back.
        assert_eq!(t.points[0].column, 0);
        assert_eq!(t.points[n - 1].column as usize, n - 1);
        assert_eq!(t.points[n].column as usize, n - 1);
        assert_eq!(t.points[2 * n - 1].column, 0);
    }

    #[test]
    fn every_sample_is_visited_once_and_steps_are_local() {
        for (hs, ht) in [(20.0, 60.0), (60.0, 15.0), (30.0, 31.0)] {
            let (c, t) = path(hs, ht);
            assert_eq!(t.points.len(), c.surface.samples.len());
            for w in t.points.windows(2) {
                let d = ((w[0].pos[0] - w[1].pos[0]).powi(2) + (w[0].pos[1] - w[1].pos[1]).powi(2))
                    .sqrt();
                assert!(
                    d < 2.0 * c.surface.spacing,
                    "jump of {d} mm between {:?} and {:?}",
                    w[0],
                    w[1]
                );
                let dz = (w[0].pos[2] - w[1].pos[2]).abs();
                assert!(
                    dz <= c.surface.params.max_layer_height + 1e-9,
                    "vertical jump {dz}"
                );
            }
        }
    }

    #[test]
    fn two_stage_turns_along_the_top_edge() {
        let (_, t) = path(20.0, 60.0);
        assert_eq!(t.stages, 2);
        assert!(t.returning_points > 5, "{}", t.returning_points);
        assert!(t.points.iter().any(|p| p.kind == PointKind::Top));
        // Below-links point to lower points on the same column.
        for (i, b) in t.below.iter().enumerate() {
            if let Some(b) = b {
                let (p, q) = (t.points[i], t.points[*b as usize]);
                assert_eq!(p.column, q.column);
                assert!(q.pos[2] < p.pos[2]);
                assert!((*b as usize) < i, "the point below is printed first");
            }
        }
    }
}
