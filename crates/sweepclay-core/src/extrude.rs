//! Stage 4: toolpath → extrusion plan (paper §5.3, Algorithm 3;
//! docs/ALGORITHMS.md §6).
//!
//! Every bead starts at w_min. Walking bottom-up in print order, a point at
//! horizontal offset s from the point below needs w = s / (1 − overlap),
//! clamped to [w_min, w_max]; both points are widened to it together (the
//! paper's "expand both with the same scale"). A second walk, top-down,
//! widens the point below to the width of the point above wherever the
//! overlap is still short of the target (the paper adjusts "twice"). With
//! s ≤ w_max (1 − overlap) from the support-free correction, every bead then
//! overlaps the one below by at least the target fraction of its width.
//!
//! The volume of a move is the cuboid L · w̄ · Δz̄ (paper Fig. 5).

use crate::design::Params;
use crate::toolpath::Toolpath;

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
    /// Sum of move lengths (mm).
    pub path_length: f64,
}

/// Overlap of a bead of width `wa` with one of width `wb` whose centre is
/// `s` to the side, as a fraction of `wa`.
pub fn overlap_fraction(wa: f64, wb: f64, s: f64) -> f64 {
    let lo = (-wa / 2.0).max(s - wb / 2.0);
    let hi = (wa / 2.0).min(s + wb / 2.0);
    ((hi - lo).max(0.0) / wa).min(1.0)
}

/// Computes widths and volumes.
pub fn plan_extrusion(path: &Toolpath, params: &Params) -> Extrusion {
    let n = path.points.len();
    let (wmin, wmax, ov) = (params.width_min, params.width_max, params.overlap);
    let mut width = vec![wmin; n];
    let mut layer_height = Vec::with_capacity(n);
    let mut offset = Vec::with_capacity(n);
    for (i, p) in path.points.iter().enumerate() {
        match path.below[i] {
            Some(b) => {
                let q = path.points[b as usize].pos;
                layer_height.push(p.pos[2] - q[2]);
                offset.push((p.pos[0] - q[0]).hypot(p.pos[1] - q[1]));
            }
            None => {
                layer_height.push(p.pos[2]);
                offset.push(0.0);
            }
        }
    }
    for i in 0..n {
        if let Some(b) = path.below[i] {
            let need = (offset[i] / (1.0 - ov)).clamp(wmin, wmax);
            width[i] = width[i].max(need);
            width[b as usize] = width[b as usize].max(need);
        }
    }
    for i in (0..n).rev() {
        if let Some(b) = path.below[i] {
            let b = b as usize;
            if overlap_fraction(width[i], width[b], offset[i]) < ov {
                width[b] = width[b].max(width[i]);
            }
        }
    }
    let mut volume = Vec::with_capacity(n);
    let (mut total, mut length) = (0.0, 0.0);
    volume.push(0.0);
    for i in 1..n {
        let (a, b) = (path.points[i - 1].pos, path.points[i].pos);
        let l = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
        let v = l * 0.5 * (width[i] + width[i - 1]) * 0.5 * (layer_height[i] + layer_height[i - 1]);
        volume.push(v);
        total += v;
        length += l;
    }
    Extrusion {
        width,
        layer_height,
        volume,
        total_volume: total,
        path_length: length,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::toolpath::{PathPoint, PointKind};

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
        }
    }

    #[test]
    fn overlap_fraction_closed_forms() {
        assert_eq!(overlap_fraction(3.0, 3.0, 0.0), 1.0);
        assert!((overlap_fraction(3.0, 3.0, 1.0) - 2.0 / 3.0).abs() < 1e-12);
        assert_eq!(overlap_fraction(3.0, 3.0, 4.0), 0.0);
        assert!((overlap_fraction(6.0, 3.0, 0.0) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn vertical_wall_keeps_minimum_width() {
        let t = column(&[0.0, 0.0, 0.0], 1.25);
        let e = plan_extrusion(&t, &Params::default());
        assert_eq!(e.width, vec![3.0; 3]);
        assert_eq!(e.layer_height, vec![1.25; 3]);
    }

    #[test]
    fn widths_follow_algorithm_3() {
        // Offsets 0, 1.5 (w = 3·1.5 = 4.5), then 1.5 + 0.5 (w stays 4.5 from below link).
        let t = column(&[0.0, 1.5, 2.0], 1.25);
        let p = Params::default();
        let e = plan_extrusion(&t, &p);
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
    fn volume_is_the_cuboid() {
        let t = column(&[0.0, 0.0], 1.25);
        let e = plan_extrusion(&t, &Params::default());
        // One vertical move of 1.25 mm, width 3, layer 1.25.
        assert!((e.total_volume - 1.25 * 3.0 * 1.25).abs() < 1e-12);
    }
}
