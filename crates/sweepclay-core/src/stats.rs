//! The statistics of a slicing (the paper's Table 1, and more): samples,
//! passes, path length, time, clay, bounds, the layering's figures, the
//! cartridge refills, and the warnings a potter should read.

use crate::toolpath::{self, Toolpath};
use crate::{motion, stability, Corrected, Extrusion, Printer};
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
    // The number of cartridges is the clay over one; only the first
    // refills are placed (a tiny cartridge must not list millions).
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
        while clay > cap * (out.len() + 1) as f64 + 1e-9 && out.len() < MAX_REFILLS {
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
pub(crate) fn layer_stats(c: &Corrected) -> LayerStats {
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

pub(crate) fn stats(c: &Corrected, t: &Toolpath, e: &Extrusion) -> Stats {
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
pub(crate) fn planned_min(c: &Corrected, t: &Toolpath, e: &Extrusion) -> f64 {
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

/// The most refills [`refills`] places.
pub const MAX_REFILLS: usize = 100;

/// The warnings of [`Stats::warnings`].
pub(crate) fn warnings(pr: &Printer, t: &Toolpath, e: &Extrusion) -> Vec<String> {
    let mut w = Vec::new();
    let ml = e.total_volume / 1000.0;
    if let Some(c) = pr.cartridge_ml.filter(|&c| ml > c) {
        let at: Vec<String> = refills(&t.points, &e.volume, c)
            .iter()
            .take(5)
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
            "the print needs {ml:.0} ml of clay, more than printer `{}`'s cartridge holds ({c:.0} ml): {} cartridges, refilled at {}{}; a refill breaks the one continuous extrusion, so make it smaller or thinner, or use a larger cartridge",
            pr.name,
            (ml / c).ceil(),
            at.join(", "),
            if (ml / c).ceil() > 6.0 { ", …" } else { "" }
        ));
    }
    w
}
