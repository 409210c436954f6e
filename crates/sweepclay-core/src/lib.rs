//! # sweepclay-core
//!
//! Turns a sweeping-surface design (two profile curves, a trajectory and an
//! interpolation curve; Zhong et al., "Ceramic 3D printed sweeping
//! surfaces", C&G 2020) into G-code for a clay printer: one strictly
//! continuous extrusion path, collision-free, self-supporting, with the
//! extrusion adapted so each bead rests on the one below.
//!
//! The library is pure: each stage is a function from one plain type to the
//! next, with no I/O and no shared state.
//!
//! | stage | function | input → output | paper |
//! |---|---|---|---|
//! | 1 | [`surface::sample_surface`] | [`Design`] → [`Surface`] | §4 sample points |
//! | 2 | [`correct::correct`] | [`Surface`] → [`Corrected`] | §4 support-free, self-intersection |
//! | 3 | [`toolpath::plan_path`] | [`Corrected`] → [`Toolpath`] | §5.2, Alg. 2 |
//! | 4 | [`extrude::plan_extrusion`] | [`Toolpath`] → [`Extrusion`] | §5.3, Alg. 3 |
//! | 5 | [`gcode::emit`] | [`Sliced`] → G-code text | §5.1, Alg. 1 |
//!
//! [`slice()`] runs them all and computes the statistics of the paper's
//! Table 1. The layering that decides single or two stages is in
//! [`layers`]; `docs/ALGORITHMS.md` gives the formulation and its proofs.
//!
//! A closed Ψ (a vessel, not in the paper) goes through the same stages:
//! sampling samples its wall and [`vessel`] chooses its layering (flat base
//! layers, then spiral turns); the path stage lays the floor, whose
//! geometry is [`floor`]'s (a region in, the bead elements that fill it
//! out), and the spiral ([`toolpath::plan_vessel_path`]).
//!
//! ```
//! let design = sweepclay_core::Design::from_json(r#"{
//!   "sweepclay": 1,
//!   "profile_start": { "control_points": [[0, 0], [3, 20], [0, 40]] },
//!   "profile_end":   { "control_points": [[0, 0], [0, 45]] },
//!   "trajectory":    { "control_points": [[-40, 20], [0, 50], [40, 20]] }
//! }"#).unwrap();
//! let sliced = sweepclay_core::slice(&design).unwrap();
//! let gcode = sweepclay_core::gcode::to_string(&sliced);
//! assert!(gcode.contains("G1 F2000"));
//! assert_eq!(sliced.stats.stages, 1);
//! ```

pub mod beads;
pub mod bspline;
pub mod calibrate;
pub mod correct;
pub mod curves;
pub mod design;
pub mod error;
pub mod examples;
pub mod extrude;
pub mod floor;
pub mod gcode;
pub mod grid;
pub mod import;
pub mod layers;
pub mod mesh;
pub mod meshfit;
pub mod meshread;
pub mod motion;
pub mod plane;
pub mod preview;
pub mod printer;
pub mod relief;
pub mod rim;
pub mod sections;
pub mod size;
pub mod stability;
pub mod stats;
pub mod surface;
pub mod texture;
pub mod toolpath;
pub mod vessel;
pub mod widths;

pub use correct::{Corrected, CorrectionReport};
pub use design::{Design, Offset, Params};
pub use error::{Error, Result};
pub use extrude::Extrusion;
pub use printer::{Printer, PrinterRef};
pub use size::{check_samples, check_size, estimated_samples, samples_bound, trajectory_length};
pub use stats::{refills, LayerStats, RaisedStats, Refill, Stats, VesselStats};
pub use surface::Surface;
pub use toolpath::Toolpath;

/// Everything the pipeline computed for one design.
#[derive(Clone, Debug, PartialEq)]
pub struct Sliced {
    /// The corrected surface and the correction report.
    pub corrected: Corrected,
    /// The toolpath.
    pub toolpath: Toolpath,
    /// Bead widths and volumes.
    pub extrusion: Extrusion,
    /// Table-1 statistics.
    pub stats: Stats,
}

/// Runs the whole pipeline: validate, sample, correct, plan the path and the
/// extrusion, and check that the result fits the printer.
pub fn slice(design: &Design) -> Result<Sliced> {
    let surface = surface::sample_surface(design)?;
    finish(correct::correct(&surface)?)
}

/// The stages after the corrections: plan the path and the extrusion,
/// compute the statistics and check that the result fits the printer.
pub fn finish(corrected: Corrected) -> Result<Sliced> {
    let sliced = finish_unchecked(corrected);
    fits(&sliced)?;
    Ok(sliced)
}

/// [`finish`] without the check that the print fits the printer: for a
/// preview that shows what lies outside the build volume.
pub fn finish_unchecked(corrected: Corrected) -> Sliced {
    let toolpath = toolpath::plan_path(&corrected);
    let extrusion = extrude::plan_extrusion(
        &toolpath,
        &corrected.surface.params,
        corrected.surface.printer.origin,
    );
    let stats = stats::stats(&corrected, &toolpath, &extrusion);
    Sliced {
        corrected,
        toolpath,
        extrusion,
        stats,
    }
}

/// Whether a sliced design fits its printer's build volume (and round
/// bed), and a vessel's floor could be laid as one spiral covering its
/// inside (docs/ALGORITHMS.md §8).
pub fn fits(s: &Sliced) -> Result<()> {
    let (toolpath, extrusion, stats) = (&s.toolpath, &s.extrusion, &s.stats);
    if let Some(why) = toolpath
        .vessel
        .as_ref()
        .and_then(|v| v.floor_refusal.as_ref())
    {
        return Err(Error::invalid(
            "trajectory",
            format!("{why}: make the shape rounder or its narrow parts wider, or print the vessel bottomless (params.floor_layers = 0)"),
        ));
    }
    let pr = &s.corrected.surface.printer;
    if let Some(d) = pr.bed_diameter {
        let c = pr.bed_centre();
        let reach = toolpath
            .points
            .iter()
            .zip(&extrusion.width)
            .map(|(p, w)| {
                (p.pos[0] + pr.origin[0] - c[0]).hypot(p.pos[1] + pr.origin[1] - c[1]) + w / 2.0
            })
            .fold(0.0, f64::max);
        if reach > d / 2.0 + 1e-9 {
            return Err(Error::OffRoundBed {
                printer: pr.name.clone(),
                reach,
                diameter: d,
            });
        }
    }
    for axis in 0..3 {
        let (lo, hi) = (stats.bounds_mm[0][axis], stats.bounds_mm[1][axis]);
        let min = pr.bed_min[axis];
        if lo < min - 1e-9 || hi > min + pr.build_volume[axis] + 1e-9 {
            return Err(Error::DoesNotFit {
                printer: pr.name.clone(),
                axis: ['x', 'y', 'z'][axis],
                min: lo,
                max: hi,
                low: min,
                limit: min + pr.build_volume[axis],
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wall(zs: f64, zt: f64) -> Design {
        Design::from_json(&format!(
            r#"{{"sweepclay":1,"profile_start":{{"control_points":[[0,0],[0,{zs}]]}},
                "profile_end":{{"control_points":[[0,0],[0,{zt}]]}},
                "trajectory":{{"control_points":[[-60,40],[0,70],[60,40]]}}}}"#
        ))
        .unwrap()
    }

    #[test]
    fn a_round_bed_refuses_what_leaves_its_circle() {
        // A 100 mm straight wall on the WASP 2040 Clay's Ø 200 mm bed: at
        // y = −50 its ends are 71 mm from the centre; at y = −90, 103 mm,
        // though still inside the 200 mm box.
        let at = |y: f64| {
            Design::from_json(&format!(
                r#"{{"sweepclay":1,"profile_start":{{"control_points":[[0,0],[0,10]]}},
                    "profile_end":{{"control_points":[[0,0],[0,10]]}},
                    "trajectory":{{"control_points":[[-50,{y}],[50,{y}]],"offset":"normal"}},
                    "printer":"wasp-2040-clay"}}"#
            ))
            .unwrap()
        };
        slice(&at(-50.0)).unwrap();
        match slice(&at(-90.0)) {
            Err(Error::OffRoundBed {
                reach, diameter, ..
            }) => {
                assert_eq!(diameter, 200.0);
                assert!(reach > 100.0 && reach < 106.0, "{reach}");
            }
            other => panic!("{:?}", other.map(|s| s.stats.size_mm)),
        }
    }

    #[test]
    fn clay_is_weighed_and_a_print_larger_than_the_cartridge_is_warned_of() {
        let with = |cartridge: Option<f64>| {
            let mut d = examples::scaled(10_000);
            if let PrinterRef::Inline(p) = &mut d.printer {
                p.cartridge_ml = cartridge;
                p.clay_density_g_ml = 2.0;
            }
            slice(&d).unwrap().stats
        };
        let st = with(None);
        assert!((st.clay_g - 2.0 * st.volume_ml).abs() < 1e-9);
        assert!(st.warnings.is_empty(), "{:?}", st.warnings);
        assert!(with(Some(st.volume_ml + 1.0)).warnings.is_empty());
        let small = with(Some(st.volume_ml / 2.0));
        assert_eq!(small.warnings.len(), 1);
        assert!(
            small.warnings[0].contains("cartridge"),
            "{:?}",
            small.warnings
        );
        // Half the clay a cartridge: two cartridges, one refill half way
        // through the clay, at the pass and height it falls in.
        assert_eq!(small.cartridges, Some(2));
        assert_eq!(small.refills.len(), 1, "{:?}", small.refills);
        let r = &small.refills[0];
        assert!((r.after_ml - st.volume_ml / 2.0).abs() < 1e-9);
        assert!(r.pass >= 1 && r.pass <= small.passes, "{r:?}");
        assert!(r.z_mm > 0.0 && r.z_mm < small.size_mm[2], "{r:?}");
        assert!(
            small.warnings[0].contains("2 cartridges, refilled at layer"),
            "{:?}",
            small.warnings
        );
        // A third of the clay: three cartridges, two refills, in order.
        let third = with(Some(st.volume_ml / 3.0 + 1e-6));
        assert_eq!(third.cartridges, Some(3));
        assert_eq!(third.refills.len(), 2);
        assert!(third.refills[0].share < third.refills[1].share);
        assert_eq!(with(Some(st.volume_ml * 2.0)).cartridges, Some(1));
    }

    #[test]
    fn a_refill_falls_where_the_clay_passes_the_cartridge() {
        // Ten 1 mm moves up a column, 100 mm³ each: a 0.25 ml cartridge
        // empties in the third move (300 > 250), the sixth (600 > 500; at
        // 500 the second is just used up) and the eighth.
        let points: Vec<toolpath::PathPoint> = (0..=10)
            .map(|i| toolpath::PathPoint {
                pos: [0.0, 0.0, f64::from(i)],
                column: 0,
                pass: i as u32,
                kind: toolpath::PointKind::Pass,
            })
            .collect();
        let volume: Vec<f64> = std::iter::once(0.0).chain([100.0; 10]).collect();
        let r = refills(&points, &volume, 0.25);
        assert_eq!(r.iter().map(|r| r.pass).collect::<Vec<_>>(), [3, 6, 8]);
        assert_eq!(r[0].after_ml, 0.25);
        assert!((r[1].share - 0.6).abs() < 1e-12);
        assert!(refills(&points, &volume, 0.0).is_empty());
    }

    #[test]
    fn firing_shrinkage_prints_a_cylinder_larger_by_one_over_one_minus_s() {
        // A cylinder: a 64-gon of radius 30 mm, profiles straight up 40 mm.
        let ring: Vec<String> = (0..64)
            .map(|k| {
                let a = std::f64::consts::TAU * f64::from(k) / 64.0;
                format!("[{:.6}, {:.6}]", 30.0 * a.cos(), 30.0 * a.sin())
            })
            .collect();
        let design = |sxy: f64, sz: f64| {
            Design::from_json(&format!(
                r#"{{"sweepclay":1,"profile_start":{{"control_points":[[0,0],[0,40]]}},
                    "profile_end":{{"control_points":[[0,0],[0,40]]}},
                    "trajectory":{{"points":[{}],"closed":true}},
                    "params":{{"shrinkage_xy":{sxy},"shrinkage_z":{sz}}}}}"#,
                ring.join(",")
            ))
            .unwrap()
        };
        // The wall's (the floor's outermost turn starts outside it).
        let reach = |s: &Sliced| {
            let r = s
                .toolpath
                .points
                .iter()
                .filter(|p| p.kind != crate::toolpath::PointKind::Floor)
                .map(|p| p.pos[0].hypot(p.pos[1]))
                .fold(0.0, f64::max);
            let z = s
                .toolpath
                .points
                .iter()
                .map(|p| p.pos[2])
                .fold(0.0, f64::max);
            (r, z)
        };
        let (r0, z0) = reach(&slice(&design(0.0, 0.0)).unwrap());
        assert!(
            (r0 - 30.0).abs() < 0.01 && (z0 - 40.0).abs() < 1e-6,
            "{r0} {z0}"
        );
        let shrunk = slice(&design(0.2, 0.1)).unwrap();
        let (r, z) = reach(&shrunk);
        assert!((r - 30.0 / 0.8).abs() < 0.01, "{r}");
        assert!((z - 40.0 / 0.9).abs() < 1e-6, "{z}");
        assert_eq!(shrunk.stats.print_scale, [1.25, 1.0 / 0.9]);
        // Layers are the process, not the piece: within the bounds asked.
        let [lo, hi] = shrunk.stats.layers.lower_mm;
        assert!(lo >= 1.25 - 1e-9 && hi <= 2.5 + 1e-9, "{lo} {hi}");
    }

    #[test]
    fn layer_heights_are_reported_as_used_and_why_when_thicker() {
        // Both ends 50 mm: 40 flat layers of exactly 1.25 mm, no reason.
        let s = slice(&wall(50.0, 50.0)).unwrap();
        let l = &s.stats.layers;
        assert!(
            (l.lower_mm[0] - 1.25).abs() < 1e-9 && (l.lower_mm[1] - 1.25).abs() < 1e-9,
            "{l:?}"
        );
        assert_eq!(l.upper_mm, None);
        assert_eq!(l.thicker_because, None);
        // 30 and 40 mm: 24 tilted passes, the tall end's layers 40/24.
        let s = slice(&wall(30.0, 40.0)).unwrap();
        let l = &s.stats.layers;
        assert!((l.lower_mm[1] - 40.0 / 24.0).abs() < 1e-6, "{l:?}");
        assert!(
            l.thicker_because.as_ref().unwrap().contains("over 24"),
            "{l:?}"
        );
        assert!(gcode::to_string(&s).contains("; layer_heights: 1.25–1.67 mm"));
    }
}
