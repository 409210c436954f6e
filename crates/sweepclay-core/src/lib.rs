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
pub mod rim;
pub mod sections;
pub mod stability;
pub mod surface;
pub mod texture;
pub mod toolpath;
pub mod vessel;

pub use correct::{Corrected, CorrectionReport};
pub use design::{Design, Offset, Params};
pub use error::{Error, Result};
pub use extrude::Extrusion;
pub use printer::{Printer, PrinterRef};
pub use surface::Surface;
pub use toolpath::Toolpath;

use serde::Serialize;

/// The statistics of the paper's Table 1, and a few more.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Stats {
    /// Bounding box of the path, bead edges included (mm).
    pub size_mm: [f64; 3],
    /// Path points (= surface samples).
    pub sample_points: usize,
    /// Passes of the zig-zag.
    pub passes: u32,
    /// 1 or 2.
    pub stages: u8,
    /// Returning turns along the top edge.
    pub returning_points: u32,
    /// Transition curves (columns along Ψ).
    pub curves: usize,
    /// Length of the extrusion path (mm).
    pub path_length_mm: f64,
    /// Clay volume (ml).
    pub volume_ml: f64,
    /// Clay mass (g), at the printer's `clay_density_g_ml`.
    pub clay_g: f64,
    /// Of it, the clay of the turnaround steps (ml): the rounded ends of
    /// the layers (docs/ALGORITHMS.md §6).
    pub turn_clay_ml: f64,
    /// What the steps would have got as cuboids, a bead as long as each
    /// climb (ml): the clay the paper saw pile up at the turns.
    pub turn_clay_cuboid_ml: f64,
    /// Turnaround steps.
    pub turn_steps: usize,
    /// How much larger than designed the piece is printed, across and in
    /// height, for the firing shrinkage (1 without).
    pub print_scale: [f64; 2],
    /// Printing time as the firmware's planner spends it (acceleration,
    /// corners, axis and extruder limits; docs/ALGORITHMS.md §9), plus the
    /// first rapid move (min).
    pub time_min: f64,
    /// The path at the feedrate alone, as the paper's model (min).
    pub time_at_feedrate_min: f64,
    /// Bed coordinates of the bounding box: `[[xmin, ymin, zmin], [xmax, ymax, zmax]]`.
    pub bounds_mm: [[f64; 3]; 2],
    /// The layer heights the path really uses.
    pub layers: LayerStats,
    /// What a potter should know before printing: more clay than the
    /// cartridge holds, a piece that may topple or sag while wet.
    pub warnings: Vec<String>,
    /// Where the clay runs out and a full cartridge must go in, when the
    /// print needs more than the printer's `cartridge_ml` (empty when it
    /// fits, or the cartridge is not known).
    pub refills: Vec<Refill>,
    /// Cartridges the print needs, when the printer's is known.
    pub cartridges: Option<u32>,
    /// A vessel's floor and wall, else `None`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vessel: Option<VesselStats>,
}

/// A point of the print where the cartridge is empty: where the potter
/// must stop and refill (docs/PRINTING.md, "Clay budget").
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Refill {
    /// The clay laid before it (ml).
    pub after_ml: f64,
    /// The pass (layer) it falls in, 1-based.
    pub pass: u32,
    /// The nozzle's height there (mm).
    pub z_mm: f64,
    /// How far along the path, 0 to 1.
    pub share: f64,
}

/// Where a print of these volumes runs through each cartridge of `ml`:
/// the first point whose clay, counted from the start, passes each whole
/// cartridge.
/// `volume[i]` is the clay of the move ending at `points[i]` (mm³).
pub fn refills(points: &[toolpath::PathPoint], volume: &[f64], cartridge_ml: f64) -> Vec<Refill> {
    let mut out = Vec::new();
    if cartridge_ml.is_nan() || cartridge_ml <= 0.0 {
        return out;
    }
    let cap = cartridge_ml * 1000.0;
    let total_len: f64 = points
        .windows(2)
        .map(|w| {
            let (p, q) = (w[1].pos, w[0].pos);
            (p[0] - q[0]).hypot(p[1] - q[1]).hypot(p[2] - q[2])
        })
        .sum::<f64>()
        .max(1e-9);
    let (mut clay, mut len) = (0.0, 0.0);
    for (i, p) in points.iter().enumerate().skip(1) {
        clay += volume.get(i).copied().unwrap_or(0.0);
        let q = points[i - 1].pos;
        len += (p.pos[0] - q[0])
            .hypot(p.pos[1] - q[1])
            .hypot(p.pos[2] - q[2]);
        // A cartridge is empty once the clay passes it (a refill per
        // cartridge, however many a long move empties).
        while clay > cap * (out.len() + 1) as f64 + 1e-9 {
            out.push(Refill {
                after_ml: cap * (out.len() + 1) as f64 / 1000.0,
                pass: p.pass,
                z_mm: p.pos[2],
                share: (len / total_len).min(1.0),
            });
        }
    }
    out
}

/// The parts of a vessel (docs/ALGORITHMS.md §8).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct VesselStats {
    /// Flat floor layers (0: bottomless).
    pub floor_layers: u32,
    /// Turns of each floor layer's spiral.
    pub floor_turns: u32,
    /// Area of the floor inside the wall's first turn (cm²).
    pub floor_area_cm2: f64,
    /// The share of that area the floor's beads cover, in per cent.
    pub floor_cover_pct: f64,
    /// Spiral turns of the wall, the rim turn not counted.
    pub wall_turns: u32,
    /// The part of the rim above what the spiral carries, laid as partial
    /// layers (docs/ALGORITHMS.md §8), if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub raised: Option<RaisedStats>,
}

/// A vessel's raised rim: where its partial layers start and how many.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RaisedStats {
    /// The level the spiral carries the rim to (mm).
    pub level_mm: f64,
    /// The most passes back and forth above it.
    pub passes: u32,
    /// Returning turns: climbs along the rim between passes.
    pub returning: u32,
    /// How much of the loop the raised part spans (%).
    pub span_pct: f64,
}

/// The layer heights a sliced design uses, per stage (docs/ALGORITHMS.md
/// §3), and why, where they are thicker than `layer_height`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LayerStats {
    /// Thinnest and thickest layer of the lower (or only) stage (mm); the
    /// last layer under a column's top edge, which may be thinner, left
    /// out of the thinnest.
    pub lower_mm: [f64; 2],
    /// The same for the upper stage of a two-stage path.
    pub upper_mm: Option<[f64; 2]>,
    /// Why some layers are thicker than `layer_height`, if they are.
    pub thicker_because: Option<String>,
}

impl LayerStats {
    /// One line for summaries: "1.25–2.31 mm (upper stage 1.25–1.30 mm)".
    pub fn summary(&self) -> String {
        let [lo, hi] = self.lower_mm;
        match self.upper_mm {
            Some([ulo, uhi]) => {
                format!("{lo:.2}–{hi:.2} mm lower stage, {ulo:.2}–{uhi:.2} mm upper stage")
            }
            None => format!("{lo:.2}–{hi:.2} mm"),
        }
    }
}

/// The layer heights of the corrected surface: each column's samples are
/// its passes' heights, bottom up.
fn layer_stats(c: &Corrected) -> LayerStats {
    let s = &c.surface;
    let plan = &s.plan;
    if let Some(v) = &s.vessel {
        // The spiral's layers (the first turn rises from the floor and the
        // rim turn tapers to the rim, as in any vase mode).
        let asked = s.params.layer_height;
        return LayerStats {
            lower_mm: v.turn_mm,
            upper_mm: None,
            thicker_because: (v.turn_mm[1] > asked * 1.005).then(|| {
                if v.turn_mm[1] - v.turn_mm[0] < 1e-6 {
                    format!(
                        "layers may not be thinner than layer_height, and the wall above the floor divides into {} whole spiral turns of {:.3} mm",
                        v.turns, v.turn_mm[1]
                    )
                } else {
                    format!(
                        "the rim's height varies round the loop: each column's wall above the floor is split into the same {} spiral turns, so its layers are thicker where it is taller",
                        v.turns
                    )
                }
            }),
        };
    }
    let mut lower = [f64::INFINITY, 0.0f64];
    let mut upper = [f64::INFINITY, 0.0f64];
    for col in &s.columns {
        let r = col.samples();
        let mut prev = 0.0;
        for (k, i) in r.clone().enumerate() {
            let z = s.samples[i].z;
            let dz = z - prev;
            prev = z;
            let slot = if (k as u32) < plan.lower_passes {
                &mut lower
            } else {
                &mut upper
            };
            slot[1] = slot[1].max(dz);
            if i + 1 < r.end {
                slot[0] = slot[0].min(dz);
            }
        }
    }
    let fix = |v: [f64; 2]| [if v[0].is_finite() { v[0] } else { v[1] }, v[1]];
    let lower_mm = fix(lower);
    let upper_mm = (upper[1] > 0.0).then(|| fix(upper));
    let asked = s.params.layer_height;
    let thickest = lower_mm[1].max(upper_mm.map_or(0.0, |u| u[1]));
    let thicker_because = (thickest > asked * 1.005).then(|| {
        let short = (s.columns.iter().map(|c| c.height).fold(f64::INFINITY, f64::min) / asked)
            .floor();
        if lower_mm[1] <= asked * 1.005 {
            let rest = plan.tall(plan.passes) - plan.tall(plan.lower_passes);
            let below = match plan.lower_passes {
                1 => "first layer".to_string(),
                n => format!("first {n} layers"),
            };
            format!(
                "layers may not be thinner than layer_height, and the tall end's {rest:.2} mm above its {below} divides into {} whole layers of {:.3} mm",
                plan.passes - plan.lower_passes,
                plan.upper_layer_mm
            )
        } else if f64::from(plan.lower_passes) < short {
            format!(
                "the extruder body ({} mm radius) limits how steeply a tilted pass may climb past clay already laid (the slope condition): {} tilted passes where the short end alone has room for {short}, so each column's layers are its height over {}",
                s.printer.nozzle_radius, plan.lower_passes, plan.lower_passes
            )
        } else {
            format!(
                "the passes tilt between the two ends: each column is printed in the same {} passes, so a column's layers are its height over {}, thicker where it is taller",
                plan.lower_passes, plan.lower_passes
            )
        }
    });
    LayerStats {
        lower_mm,
        upper_mm,
        thicker_because,
    }
}

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

/// The length of Ψ (mm) without resampling it: a spline flattened to
/// a few dozen points a span (its control polygon can be twice as
/// long as the curve), a polyline's own. NaN when a coordinate is not
/// a number.
pub fn trajectory_length(d: &Design) -> f64 {
    use crate::bspline::polyline_length as poly;
    let t = &d.trajectory;
    let pts = t.given_points();
    match (&t.control_points, pts.len()) {
        (Some(cp), m) if t.closed && m >= 3 => poly(&crate::curves::periodic_bspline(cp, 32)),
        (Some(cp), m) if m >= 2 => {
            crate::bspline::BSpline::clamped(cp.clone()).map_or(poly(pts), |c| poly(&c.flatten(32)))
        }
        (None, m) if t.closed && m > 1 => poly(pts) + crate::bspline::dist(pts[m - 1], pts[0]),
        _ => poly(pts),
    }
}

/// A bound on the number of path points, from the curves without
/// sampling anything (a server refuses a design before it allocates
/// anything for it): columns (Ψ's length / spacing + 1) times the
/// samples a column can get — a wall's mean height over the layer
/// height (flat layers, the most the layering chooses), a vessel's
/// lowest (its spiral turns), its rim turn and the partial layers of a
/// raised rim above — plus a vessel's floor spirals, a pitch apart over
/// the control polygon's area. [`estimated_samples`] narrows it.
/// Textures' finer sampling counted. NaN when a
/// coordinate is not a number (slicing then names it).
pub fn samples_bound(d: &Design) -> f64 {
    let t = &d.trajectory;
    // The sampling a texture asks for (idempotent: `d` may be refined).
    let p = &d.texture_params();
    let top =
        |c: &crate::design::CurveSpec| c.control_points.iter().map(|p| p[1]).fold(0.0, f64::max);
    let (zs, zt) = (top(&d.profile_start), top(&d.end_profile()));
    let per_column = if t.closed {
        // The spiral under the lower rim, a rim turn, and a raised arc's
        // passes of at most min(Δz_min, Δz_max/2) and its top above
        // (docs/ALGORITHMS.md §8).
        let arc_layer = p.layer_height.min(0.5 * p.max_layer_height);
        zs.min(zt) / p.layer_height + (zs - zt).abs() / arc_layer + 3.0
    } else {
        // The mean of λ(u) (0.5 for the default f(u) = u).
        let f = crate::curves::Interpolation::new(d.interpolation.as_ref());
        let mean = f.map_or(0.5, |f| {
            (0..=64).map(|k| f.eval(k as f64 / 64.0)).sum::<f64>() / 65.0
        });
        ((1.0 - mean) * zs + mean * zt) / p.layer_height + 1.0
    };
    (trajectory_length(d) / p.spacing + 1.0) * per_column + floor_bound(d, p)
}

/// At most how many path points a vessel's floor takes at the sampling
/// `p`: its layers of beads a pitch apart over the control polygon's
/// area (0 for a wall).
fn floor_bound(d: &Design, p: &Params) -> f64 {
    let t = &d.trajectory;
    let pts = t.given_points();
    if !t.closed || pts.len() < 2 {
        return 0.0;
    }
    let area = 0.5 * crate::plane::signed_area2(pts).abs();
    let pitch = p.width_min * (1.0 - crate::design::FLOOR_OVERLAP);
    let layers = p
        .floor_layers
        .unwrap_or(crate::design::DEFAULT_FLOOR_LAYERS);
    1.5 * area / (pitch * p.spacing) * f64::from(layers)
}

/// Most columns the estimate samples a wall at (coarser than its spacing
/// where it has more): enough to see its layering, far from its cost.
const ESTIMATE_COLUMNS: f64 = 2000.0;

/// Most samples the estimate's coarse sampling may take.
const ESTIMATE_SAMPLES: f64 = 200_000.0;

/// The number of path points a design will have, within about 20 %
/// (docs/PERFORMANCE.md, "The size cap"): for a wall, the samples a
/// column gets in a sampling of at most 2,000 columns (the layering as
/// slicing will choose it: tilted passes give every column the short
/// end's count, flat ones each its own height's) times the columns at
/// the design's spacing (a vessel's floor bounded as in
/// [`samples_bound`]); where that coarse sampling would be large or
/// fails, [`samples_bound`].
pub fn estimated_samples(design: &Design) -> f64 {
    let d = design.printed();
    let bound = samples_bound(&d);
    let length = trajectory_length(&d);
    let columns = length / d.params.spacing + 1.0;
    // `printed` has the textures' sampling already.
    let floor = floor_bound(&d, &d.params);
    let per_column = (bound - floor) / columns;
    if !bound.is_finite() || !length.is_finite() {
        return bound;
    }
    let coarse_columns = ESTIMATE_COLUMNS.min(ESTIMATE_SAMPLES / per_column.max(1.0));
    if coarse_columns < 50.0 {
        return bound;
    }
    let mut coarse = d.clone();
    coarse.params.spacing = d.params.spacing.max(length / coarse_columns);
    // A vessel's wall as the coarse sampling lays it (its spiral's turns
    // and any raised arc), and its floor's bound.
    match surface::sample_surface(&coarse) {
        Ok(s) if !s.columns.is_empty() => {
            s.samples.len() as f64 / s.columns.len() as f64 * columns + floor
        }
        _ => bound,
    }
}

/// Refuses, before the design is sampled at its spacing, one with a
/// parameter out of its range or whose [`estimated_samples`] is over
/// `max_samples` ([`Error::TooLarge`]): the cap on work, without
/// [`check_size`]'s early fit check (for a preview that shows what
/// leaves the printer).
pub fn check_samples(design: &Design, max_samples: f64) -> Result<()> {
    // A parameter out of its range is that, not a huge estimate (a layer
    // height of 0 is no "infinitely many samples").
    design.params.validate()?;
    design.check_texture()?;
    let estimate = estimated_samples(design);
    if estimate > max_samples {
        // Over the cap only for the sampling a texture asks: name it.
        let mut plain = design.clone();
        plain.texture.clear();
        if !design.texture.is_empty() && estimated_samples(&plain) <= max_samples {
            let d = design.printed();
            let [along, up] =
                texture::needs(&d.texture, trajectory_length(&d), d.trajectory.closed);
            let k = up.or(along).map_or(0, |(_, k)| k);
            return Err(Error::invalid(
                format!("texture[{k}]"),
                format!(
                    "needs samples {:.2} mm apart and layers of at most {:.2} mm to show ({} a period): about {estimate:.0} samples, over the cap of {max_samples:.0}; lengthen its period, use fewer ribs, or make the piece smaller",
                    d.params.spacing,
                    d.params.max_layer_height,
                    texture::SAMPLES_PER_PERIOD
                ),
            ));
        }
        return Err(Error::TooLarge {
            estimate,
            limit: max_samples,
        });
    }
    Ok(())
}

/// [`check_samples`], then [`Design::check_fit`].
pub fn check_size(design: &Design, max_samples: f64) -> Result<()> {
    check_samples(design, max_samples)?;
    design.check_fit()
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
    let stats = stats(&corrected, &toolpath, &extrusion);
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

fn stats(c: &Corrected, t: &Toolpath, e: &Extrusion) -> Stats {
    let pr = &c.surface.printer;
    let mut lo = [f64::MAX; 3];
    let mut hi = [f64::MIN; 3];
    for (p, w) in t.points.iter().zip(&e.width) {
        for a in 0..2 {
            lo[a] = lo[a].min(p.pos[a] + pr.origin[a] - w / 2.0);
            hi[a] = hi[a].max(p.pos[a] + pr.origin[a] + w / 2.0);
        }
        hi[2] = hi[2].max(p.pos[2]);
    }
    lo[2] = 0.0;
    let p0 = t.points[0].pos;
    let travel = (p0[0] + pr.origin[0])
        .hypot(p0[1] + pr.origin[1])
        .hypot(p0[2]);
    Stats {
        size_mm: [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]],
        sample_points: t.points.len(),
        passes: t.passes,
        stages: t.stages,
        returning_points: t.returning_points,
        curves: c.surface.columns.len(),
        path_length_mm: e.path_length,
        volume_ml: e.total_volume / 1000.0,
        clay_g: e.total_volume / 1000.0 * pr.clay_density_g_ml,
        refills: pr
            .cartridge_ml
            .map_or_else(Vec::new, |c| refills(&t.points, &e.volume, c)),
        cartridges: pr
            .cartridge_ml
            .map(|c| (e.total_volume / 1000.0 / c).ceil().max(1.0) as u32),
        warnings: warnings(pr, t, e)
            .into_iter()
            .chain(stability::warnings(t, e, c.surface.params.max_layer_height))
            .collect(),
        turn_clay_ml: e.turn_volume / 1000.0,
        turn_clay_cuboid_ml: e.turn_volume_cuboid / 1000.0,
        print_scale: c.surface.params.print_scale(),
        turn_steps: e.turn_steps,
        time_min: planned_min(c, t, e) + travel / pr.travel_feedrate,
        time_at_feedrate_min: e.path_length / c.surface.params.feedrate
            + travel / pr.travel_feedrate,
        bounds_mm: [lo, hi],
        layers: layer_stats(c),
        vessel: t.vessel.as_ref().map(|v| VesselStats {
            floor_layers: v.floor_layers,
            floor_turns: v.floor_turns,
            floor_area_cm2: v.floor_area_mm2 / 100.0,
            floor_cover_pct: 100.0 * v.floor_cover,
            wall_turns: v.turns,
            raised: c
                .surface
                .vessel
                .as_ref()
                .and_then(|p| p.arc.as_ref())
                .map(|a| RaisedStats {
                    level_mm: a.level_mm,
                    passes: a.most_passes(),
                    returning: t.returning_points,
                    span_pct: 100.0 * a.columns.len() as f64
                        / c.surface.columns.len().max(1) as f64,
                }),
        }),
    }
}

/// The planner's time of the path (min): the moves at the feedrate (the
/// slowed steps slower), from rest at the first point.
fn planned_min(c: &Corrected, t: &Toolpath, e: &Extrusion) -> f64 {
    let feed = c.surface.params.feedrate / 60.0;
    let moves = t
        .points
        .iter()
        .skip(1)
        .zip(e.volume.iter().skip(1))
        .zip(e.feed_factors())
        .map(|((p, &volume), k)| motion::Move {
            to: p.pos,
            feed: feed * k,
            volume,
        });
    let start = t.points.first().map_or([0.0; 3], |p| p.pos);
    motion::print_time(start, moves, &motion::Limits::of(&c.surface.printer)) / 60.0
}

/// The warnings of [`Stats::warnings`].
fn warnings(pr: &Printer, t: &Toolpath, e: &Extrusion) -> Vec<String> {
    let mut w = Vec::new();
    let ml = e.total_volume / 1000.0;
    if let Some(c) = pr.cartridge_ml.filter(|&c| ml > c) {
        let at: Vec<String> = refills(&t.points, &e.volume, c)
            .iter()
            .map(|r| {
                format!(
                    "layer {} at {:.1} mm ({:.0} % of the path)",
                    r.pass,
                    r.z_mm,
                    r.share * 100.0
                )
            })
            .collect();
        w.push(format!(
            "the print needs {ml:.0} ml of clay, more than printer `{}`'s cartridge holds ({c:.0} ml): {} cartridges, refilled at {}; a refill breaks the one continuous extrusion, so make it smaller or thinner, or use a larger cartridge",
            pr.name,
            at.len() + 1,
            at.join(", ")
        ));
    }
    w
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
