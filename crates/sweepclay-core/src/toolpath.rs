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
    pub vessel: Option<crate::vessel::VesselPath>,
}

/// Orders the samples of a corrected surface into one continuous path.
pub fn plan_path(c: &Corrected) -> Toolpath {
    let s = &c.surface;
    if let Some(v) = &s.vessel {
        return crate::vessel::plan_vessel_path(c, v);
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
