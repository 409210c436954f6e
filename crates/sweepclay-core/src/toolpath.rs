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
use crate::floor::{floor_entries, floor_rings, ring_area, seam_at, FloorRing};
use crate::vessel::{floor_beads, VesselPlan};
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
    /// A bead of a vessel's floor inside its base ring (not a surface
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
    }
}

/// The toolpath of a vessel: the base layers (floor elements inward on one
/// layer, outward on the next, so the last ends on the base ring), the
/// spiral turns, and the rim. Every sample of the surface is visited once,
/// the base ring's first point of each base layer twice (the ring closes
/// over it); the floor's elements add their own points, each ring closing
/// on its entry. The move into each element, and from the floor to the
/// base ring, is a join ([`VesselPath::joins`]).
pub fn plan_vessel_path(c: &Corrected, v: &VesselPlan) -> Toolpath {
    let s = &c.surface;
    let n = s.columns.len();
    let base_ring: Vec<[f64; 2]> = (0..n)
        .map(|i| {
            let p = s.position(i, s.columns[i].first as usize);
            [p[0], p[1]]
        })
        .collect();
    let rings = match &v.floor {
        _ if v.floor_layers == 0 => Vec::new(),
        Some((ring, rings)) if *ring == base_ring => rings.clone(),
        _ => floor_rings(&base_ring, floor_beads(&s.params, s.spacing)),
    };
    // Where each ring is entered: nearest the previous ring's entry,
    // the first nearest column 0 (where the base ring starts).
    let c0 = &s.columns[v.start];
    let entry = floor_entries(&rings, base_ring[v.start], s.params.width_min).0;
    // An outward layer enters its rings about a bead farther along: its
    // joins then lie on the rings of the layer below, not on its joins.
    // The innermost, where the layer below turned, and a line are entered
    // where that layer left them.
    let shift = (s.params.width_min / s.spacing).ceil() as usize;
    let outward_entry: Vec<usize> = rings
        .iter()
        .zip(&entry)
        .enumerate()
        .map(|(r, (ring, &e))| match ring.open || r + 1 == rings.len() {
            true => e,
            false => seam_at(&ring.pts, (e + shift) % ring.pts.len(), s.params.width_min),
        })
        .collect();
    // A ring's points and its closing point again; a line's points.
    let floor_points: usize = rings
        .iter()
        .map(|r| r.pts.len() + usize::from(!r.open))
        .sum();
    let total = s.samples.len() + (floor_points + 1) * v.base_layers as usize;
    let mut points = Vec::with_capacity(total);
    let mut below = Vec::with_capacity(total);
    let mut joins = Vec::new();
    let mut narrow = Vec::new();
    // Path index of each column's samples, and of each floor ring's points
    // on the layer below.
    let mut path_of = vec![u32::MAX; s.samples.len()];
    let mut ring_below: Vec<Vec<u32>> = rings.iter().map(|r| vec![u32::MAX; r.pts.len()]).collect();
    let visit_column = |points: &mut Vec<PathPoint>,
                        below: &mut Vec<Option<u32>>,
                        path_of: &mut Vec<u32>,
                        i: usize,
                        local: usize,
                        pass: u32,
                        kind: PointKind| {
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
    // Sample `local` of every column, round the loop from the start.
    let visit_turn = |points: &mut Vec<PathPoint>,
                      below: &mut Vec<Option<u32>>,
                      path_of: &mut Vec<u32>,
                      local: usize,
                      pass: u32| {
        for m in 0..n {
            let i = (v.start + m) % n;
            visit_column(points, below, path_of, i, local, pass, PointKind::Pass);
        }
    };
    // The base ring closes on its own height: back over its first point
    // before the floor or the spiral goes on from there. Ended on the
    // spiral's first point, barely above the ring, the closing bead would
    // be sized for half the ring's height and leave a thin place under the
    // seam; ended on a join, it would leave a gap.
    let close_ring = |points: &mut Vec<PathPoint>, below: &mut Vec<Option<u32>>, first: usize| {
        below.push(below[first]);
        points.push(PathPoint {
            kind: PointKind::Pass,
            ..points[first]
        });
    };
    let base = v.base_layers;
    for layer in 1..=base {
        let z = f64::from(layer) * v.base_layer_mm;
        let local = layer as usize - 1;
        // The last base layer runs outward, the one before inward, …
        let outward = (base - layer).is_multiple_of(2);
        let mut floor = |points: &mut Vec<PathPoint>, below: &mut Vec<Option<u32>>, r: usize| {
            let FloorRing {
                pts: ring,
                open,
                widths,
                ..
            } = &rings[r];
            let m = ring.len();
            // A ring closes on its entry; a line runs inward from its
            // entry end, outward back to it.
            let steps = if *open { m } else { m + 1 };
            if !points.is_empty() {
                joins.push(points.len() as u32);
            }
            let e = if outward { outward_entry[r] } else { entry[r] };
            let mut entered_on = u32::MAX;
            for step in 0..steps {
                let j = match (*open, outward == (e == 0)) {
                    (false, _) => (e + step) % m,
                    (true, true) => m - 1 - step,
                    (true, false) => step,
                };
                // The closing point lies on what the entry lay on.
                let under = if step < m {
                    std::mem::replace(&mut ring_below[r][j], points.len() as u32)
                } else {
                    entered_on
                };
                if step == 0 {
                    entered_on = under;
                }
                below.push((under != u32::MAX).then_some(under));
                if let Some(w) = widths
                    .as_ref()
                    .map(|w| w[j])
                    .filter(|&w| (w - s.params.width_min).abs() > 1e-9)
                {
                    narrow.push((points.len() as u32, w));
                }
                points.push(PathPoint {
                    pos: [ring[j][0], ring[j][1], z],
                    column: 0,
                    pass: layer,
                    kind: PointKind::Floor,
                });
            }
        };
        // A floor layer that runs inward starts on the base ring; one that
        // runs outward ends on it.
        let floor_order: Vec<usize> = match layer <= v.floor_layers {
            false => Vec::new(),
            true if outward => (0..rings.len()).rev().collect(),
            true => (0..rings.len()).collect(),
        };
        let ring_at = |path_of: &[u32]| path_of[c0.first as usize + local] as usize;
        if !outward {
            visit_turn(&mut points, &mut below, &mut path_of, local, layer);
            close_ring(&mut points, &mut below, ring_at(&path_of));
        }
        for r in floor_order {
            floor(&mut points, &mut below, r);
        }
        if outward {
            if !points.is_empty() {
                joins.push(points.len() as u32);
            }
            visit_turn(&mut points, &mut below, &mut path_of, local, layer);
            close_ring(&mut points, &mut below, ring_at(&path_of));
        }
    }
    for k in 1..=v.turns {
        let local = (base + k) as usize - 1;
        visit_turn(&mut points, &mut below, &mut path_of, local, base + k);
    }
    let rim = base + v.turns + 1;
    for i in (0..n).map(|m| (v.start + m) % n) {
        if s.columns[i].top {
            let local = s.columns[i].passes as usize;
            visit_column(
                &mut points,
                &mut below,
                &mut path_of,
                i,
                local,
                rim,
                PointKind::Top,
            );
        }
    }
    debug_assert!(
        path_of.iter().all(|&p| p != u32::MAX),
        "every sample is visited"
    );
    let floor_area = if v.floor_layers > 0 {
        ring_area(&base_ring)
    } else {
        0.0
    };
    Toolpath {
        points,
        below,
        passes: rim,
        stages: 1,
        returning_points: 0,
        vessel: Some(VesselPath {
            floor_layers: v.floor_layers,
            floor_rings: rings.len() as u32,
            floor_area_mm2: floor_area,
            turns: v.turns,
            joins,
            narrow,
        }),
    }
}

/// What the path of a vessel holds beyond its points.
#[derive(Clone, Debug, PartialEq)]
pub struct VesselPath {
    /// Floor layers (0: bottomless).
    pub floor_layers: u32,
    /// Inner rings of each floor layer (the base ring not counted).
    pub floor_rings: u32,
    /// Area inside the base ring (mm²), 0 for a bottomless vessel.
    pub floor_area_mm2: f64,
    /// Spiral turns of the wall.
    pub turns: u32,
    /// The points (in order) the move into which is a join: from one floor
    /// element to the next, or between the floor and the base ring. It
    /// runs across clay both already cover, so it carries almost no clay
    /// (the extrusion stage's `JOIN_CLAY`).
    pub joins: Vec<u32>,
    /// The floor points (in order) laid at another width than the floor's
    /// bead, and that width (mm): narrower where a thin ring's two sides
    /// come closer than a pitch, wider along the line down a thin ring's
    /// middle (`FloorRing::widths` in the floor module).
    pub narrow: Vec<(u32, f64)>,
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
