//! How well each bead sits: the stability map the modeler colours the
//! path by (docs/ALGORITHMS.md §11). The paper's constraints (overlap with
//! the bead below, overhang, layer height, the extruder body's height H;
//! docs/ALGORITHMS.md §3–6) hold for the whole path; this shows, bead by
//! bead, how much room each one has. For every path point, four figures:
//!
//! - **overlap** with the bead below, as a fraction of its width (at least
//!   1/2 to be supported, `params.overlap` the target);
//! - **overhang**, the angle from vertical of the line to the centre of the
//!   bead below, over the taller of the two beads (as the checker, so a
//!   thin bead pressed onto a thick one is no steep overhang);
//! - **layer height** above the bead below (or the bed);
//! - **clearance** of the extruder body: how far the highest clay already
//!   laid within the body's reach lies below the body's underside,
//!   `z + H − top`; under zero, the body would touch clay.
//!
//! The clearance asks a grid of the tops laid so far (dense, over the
//! path's plan box, cells of the body's radius, larger only where the box
//! is over 1024 of them along a side): a cell counts whole when it touches the
//! body's square, so the figure errs low (by at most a cell's diagonal in
//! reach). One pass, linear in the path's points.

use crate::extrude::Extrusion;
use crate::toolpath::Toolpath;
use crate::widths::overlap_fraction;

/// The four figures of every path point, in path order.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct BeadMap {
    /// Overlap with the bead below (fraction of this bead's width); 1 on
    /// the bed.
    pub overlap: Vec<f32>,
    /// Angle from vertical to the bead below (degrees); 0 on the bed.
    pub overhang_deg: Vec<f32>,
    /// Height above the bead below, or above the bed (mm).
    pub layer_height: Vec<f32>,
    /// The extruder body's clearance over the clay within its reach (mm).
    pub clearance: Vec<f32>,
}

/// The stability map of a toolpath and its extrusion, for an extruder body
/// of radius `body_radius` reaching `nozzle_height` above the tip.
pub fn bead_map(t: &Toolpath, e: &Extrusion, body_radius: f64, nozzle_height: f64) -> BeadMap {
    let n = t.points.len();
    let mut map = BeadMap {
        overlap: Vec::with_capacity(n),
        overhang_deg: Vec::with_capacity(n),
        layer_height: Vec::with_capacity(n),
        clearance: Vec::with_capacity(n),
    };
    // A dense grid over the path's plan box: cells of the body's radius,
    // larger where the box is over 1024 of them along a side (a million
    // cells at most).
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &t.points {
        for a in 0..2 {
            lo[a] = lo[a].min(p.pos[a]);
            hi[a] = hi[a].max(p.pos[a]);
        }
    }
    let span = [(hi[0] - lo[0]).max(0.0), (hi[1] - lo[1]).max(0.0)];
    let cell = body_radius.max(1.0).max(span[0].max(span[1]) / 1024.0);
    let (nx, ny) = ((span[0] / cell) as usize + 1, (span[1] / cell) as usize + 1);
    let at = |v: f64, a: usize, n: usize| (((v - lo[a]) / cell).max(0.0) as usize).min(n - 1);
    let mut tops = vec![f64::NEG_INFINITY; if n == 0 { 0 } else { nx * ny }];
    for (i, p) in t.points.iter().enumerate() {
        let [x, y, z] = p.pos;
        let (overlap, overhang) = match t.below[i] {
            Some(b) => {
                let q = t.points[b as usize].pos;
                let off = (x - q[0]).hypot(y - q[1]);
                let dz = z - q[2];
                // Against the taller of this bead and the one below, as
                // the checker measures it: a thin bead pressed onto a
                // thick one (a spiral's first turn rising from the floor)
                // leans over that bead's height, not its own.
                let h = dz.max(e.layer_height[b as usize]).max(1e-9);
                (
                    overlap_fraction(e.width[i], e.width[b as usize], off),
                    off.atan2(h).to_degrees(),
                )
            }
            None => (1.0, 0.0),
        };
        map.overlap.push(overlap as f32);
        map.overhang_deg.push(overhang as f32);
        map.layer_height.push(e.layer_height[i] as f32);
        // The body reaches half a bead past its radius: a bead's edge is
        // clay too.
        let reach = body_radius + 0.5 * e.width[i];
        let mut top = f64::NEG_INFINITY;
        for cy in at(y - reach, 1, ny)..=at(y + reach, 1, ny) {
            let row = &tops[cy * nx..(cy + 1) * nx];
            for &h in &row[at(x - reach, 0, nx)..=at(x + reach, 0, nx)] {
                top = top.max(h);
            }
        }
        let clearance = if top.is_finite() {
            z + nozzle_height - top
        } else {
            nozzle_height
        };
        map.clearance.push(clearance.min(nozzle_height) as f32);
        let slot = &mut tops[at(y, 1, ny) * nx + at(x, 0, nx)];
        *slot = slot.max(z);
    }
    map
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::toolpath::{PathPoint, PointKind};

    fn path(pts: &[[f64; 3]], below: &[Option<u32>]) -> Toolpath {
        Toolpath {
            points: pts
                .iter()
                .map(|&pos| PathPoint {
                    pos,
                    column: 0,
                    pass: 1,
                    kind: PointKind::Pass,
                })
                .collect(),
            below: below.to_vec(),
            passes: 2,
            stages: 1,
            returning_points: 0,
            vessel: None,
            twisted: false,
        }
    }

    fn extrusion(n: usize, w: f64, h: &[f64]) -> Extrusion {
        Extrusion {
            width: vec![w; n],
            layer_height: h.to_vec(),
            volume: vec![0.0; n],
            total_volume: 0.0,
            turn_volume: 0.0,
            turn_volume_cuboid: 0.0,
            turn_steps: 0,
            path_length: 0.0,
            slow: Vec::new(),
        }
    }

    #[test]
    fn a_bead_leaning_out_by_a_third_of_its_width() {
        // A bead on the bed, one 1 mm up and 1 mm out, both 3 mm wide.
        let t = path(&[[0.0, 0.0, 1.0], [1.0, 0.0, 2.0]], &[None, Some(0)]);
        let e = extrusion(2, 3.0, &[1.0, 1.0]);
        let m = bead_map(&t, &e, 5.0, 30.0);
        assert_eq!(m.overlap[0], 1.0);
        assert!((m.overlap[1] - 2.0 / 3.0).abs() < 1e-6);
        assert!((m.overhang_deg[1] - 45.0).abs() < 1e-4);
        assert_eq!(m.layer_height[1], 1.0);
        // Nothing was laid before the first bead; the second has the first
        // 1 mm below its tip: the body clears it by H + 1.
        assert_eq!(m.clearance[0], 30.0);
        assert_eq!(m.clearance[1], 30.0);
    }

    #[test]
    fn a_thin_bead_pressed_on_a_thick_one_leans_over_the_thick_one() {
        // 0.3 mm up and 0.3 mm out from a 1.25 mm bead: 13.5°, not 45°.
        let t = path(&[[0.0, 0.0, 1.25], [0.3, 0.0, 1.55]], &[None, Some(0)]);
        let e = extrusion(2, 3.0, &[1.25, 0.3]);
        let m = bead_map(&t, &e, 5.0, 30.0);
        assert!(
            (m.overhang_deg[1] - 0.24f32.atan().to_degrees()).abs() < 1e-3,
            "{}",
            m.overhang_deg[1]
        );
    }

    #[test]
    fn a_path_kilometres_across_keeps_its_grid_small() {
        // 1000 km apart: cells of a kilometre, a million of them at most;
        // the far bead is out of the first one's reach.
        let t = path(&[[0.0, 0.0, 25.0], [1e9, 1e9, 2.0]], &[None, None]);
        let e = extrusion(2, 3.0, &[25.0, 2.0]);
        assert_eq!(bead_map(&t, &e, 5.0, 30.0).clearance[1], 30.0);
    }

    #[test]
    fn clay_higher_than_the_tip_takes_the_body_clearance() {
        // A tall bead at z = 25, then one at z = 2 beside it, 4 mm away:
        // within the 5 mm body, the body clears it by 2 + 30 − 25 = 7 mm.
        let t = path(&[[0.0, 0.0, 25.0], [4.0, 0.0, 2.0]], &[None, None]);
        let e = extrusion(2, 3.0, &[25.0, 2.0]);
        let m = bead_map(&t, &e, 5.0, 30.0);
        assert!((m.clearance[1] - 7.0).abs() < 1e-6);
        // 40 mm away it is out of reach.
        let t = path(&[[0.0, 0.0, 25.0], [40.0, 0.0, 2.0]], &[None, None]);
        assert_eq!(bead_map(&t, &e, 5.0, 30.0).clearance[1], 30.0);
    }
}
