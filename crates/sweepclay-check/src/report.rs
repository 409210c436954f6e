//! The check report: counts, worst cases with their lines, the verdict, and
//! a readable rendering.

use crate::parse::Diagnostic;
use serde::Serialize;
use std::fmt::Write;

/// How often something happened, where first, and how bad at worst.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Count {
    /// Occurrences.
    pub count: usize,
    /// Line of the first occurrence.
    pub first_line: Option<usize>,
    /// Worst value (meaning depends on the check), with its line.
    pub worst: Option<(f64, usize)>,
}

impl Count {
    /// Records one occurrence at `line` with value `v` (larger is worse).
    pub fn add(&mut self, line: usize, v: f64) {
        self.count += 1;
        self.first_line.get_or_insert(line);
        if self.worst.is_none_or(|(w, _)| v > w) {
            self.worst = Some((v, line));
        }
    }
}

/// Support of the beads on the clay below.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SupportStats {
    /// Beads analysed (extruding moves that are not vertical steps).
    pub beads: usize,
    /// Beads on the bed.
    pub on_bed: usize,
    /// Vertical steps (turnarounds): extruding moves steeper than 1:2.
    pub steps: usize,
    /// Smallest overlap fraction and its line.
    pub min_overlap: Option<(f64, usize)>,
    /// Beads by overlap: `<1/2`, `1/2–0.6`, `0.6–target`, `target–0.9`, `≥0.9`.
    pub overlap_histogram: [usize; 5],
    /// Beads under the hard minimum (fail).
    pub under_min: Count,
    /// Beads under the target (reported).
    pub under_target: usize,
    /// Overhang angles beyond the threshold (fail); worst in degrees.
    pub overhang: Count,
    /// Largest overhang angle (degrees) and its line.
    pub max_overhang_deg: Option<(f64, usize)>,
    /// Beads with no clay below them and not on the bed (fail).
    pub unsupported: Count,
    /// Beads laid where clay already is at that height (fail).
    pub double_deposition: Count,
    /// Smallest and largest local layer height (mm) with lines.
    pub layer_height: Option<[(f64, usize); 2]>,
    /// Smallest and largest bead width (mm) with lines.
    pub width: Option<[(f64, usize); 2]>,
}

/// The full report. `printable` is the verdict.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Report {
    /// Whether the file is printable in clay.
    pub printable: bool,
    /// The reasons it is not (empty when printable).
    pub failures: Vec<String>,
    /// Lines in the file.
    pub lines: usize,
    /// Moves replayed.
    pub moves: usize,
    /// Extruding moves.
    pub extruding_moves: usize,
    /// Separate extrusion runs (must be 1); first lines of up to 20.
    pub extrusion_runs: usize,
    /// First lines of the runs (at most 20).
    pub run_starts: Vec<usize>,
    /// Moves without extrusion after the first bead.
    pub travel_moves: Count,
    /// Moves with negative E.
    pub retractions: Count,
    /// Pauses after the first bead.
    pub pauses: Count,
    /// Extrusion with no motion.
    pub extrusion_without_motion: Count,
    /// Moves outside the build volume; worst distance outside (mm).
    pub out_of_bounds: Count,
    /// Height of the first bead.
    pub first_layer_z: Option<f64>,
    /// Clay inside the nozzle cylinder; worst height above the tip (mm).
    pub nozzle_collisions: Count,
    /// Clay above the carriage; worst height above the carriage (mm).
    pub carriage_collisions: Count,
    /// Support analysis.
    pub support: SupportStats,
    /// Length of the extrusion path (mm).
    pub path_length_mm: f64,
    /// Clay volume (ml).
    pub volume_ml: f64,
    /// Time from the feedrates, all moves (min).
    pub time_min: f64,
    /// Size of the extruded part (mm).
    pub size_mm: [f64; 3],
    /// Estimated layer count: height over the median layer height.
    pub layers: usize,
    /// Parse and replay diagnostics (at most 50).
    pub diagnostics: Vec<Diagnostic>,
}

fn at(c: &Count) -> String {
    match (c.first_line, c.worst) {
        (Some(l), Some((w, wl))) => format!("first at line {l}, worst {w:.2} at line {wl}"),
        (Some(l), None) => format!("first at line {l}"),
        _ => String::new(),
    }
}

impl Report {
    /// The readable report: a verdict line, then a table.
    pub fn render(&self) -> String {
        let mut s = String::new();
        if self.printable {
            let _ = writeln!(
                s,
                "PRINTABLE in clay: one continuous extrusion, collision-free, every bead supported"
            );
        } else {
            let _ = writeln!(s, "NOT PRINTABLE in clay: {}", self.failures.join("; "));
        }
        let _ = writeln!(s);
        let row = |s: &mut String, k: &str, v: String| {
            let _ = writeln!(s, "  {k:<26} {v}");
        };
        row(
            &mut s,
            "moves",
            format!("{} ({} extruding)", self.moves, self.extruding_moves),
        );
        row(
            &mut s,
            "extrusion runs",
            format!(
                "{}{}",
                self.extrusion_runs,
                if self.extrusion_runs > 1 {
                    format!(" (starting at lines {:?})", self.run_starts)
                } else {
                    String::new()
                }
            ),
        );
        for (k, c) in [
            ("travel moves", &self.travel_moves),
            ("retractions", &self.retractions),
            ("pauses", &self.pauses),
            ("extrusion without motion", &self.extrusion_without_motion),
            ("out of bounds (mm)", &self.out_of_bounds),
            ("nozzle collisions (mm)", &self.nozzle_collisions),
            ("carriage collisions (mm)", &self.carriage_collisions),
            ("unsupported beads", &self.support.unsupported),
            ("double deposition", &self.support.double_deposition),
            ("overlap < minimum", &self.support.under_min),
            ("overhang > limit (deg)", &self.support.overhang),
        ] {
            row(&mut s, k, format!("{} {}", c.count, at(c)));
        }
        let sp = &self.support;
        row(
            &mut s,
            "beads",
            format!(
                "{} ({} on the bed, {} turnaround steps)",
                sp.beads, sp.on_bed, sp.steps
            ),
        );
        if let Some((v, l)) = sp.min_overlap {
            row(
                &mut s,
                "min overlap",
                format!(
                    "{:.1}% at line {l}; {} bead(s) under target",
                    v * 100.0,
                    sp.under_target
                ),
            );
        }
        let h = sp.overlap_histogram;
        row(
            &mut s,
            "overlap histogram",
            format!(
                "<50%: {} | 50-60%: {} | 60%-target: {} | target-90%: {} | >=90%: {}",
                h[0], h[1], h[2], h[3], h[4]
            ),
        );
        if let Some((v, l)) = sp.max_overhang_deg {
            row(&mut s, "max overhang", format!("{v:.1}° at line {l}"));
        }
        if let Some([(lo, ll), (hi, hl)]) = sp.layer_height {
            row(
                &mut s,
                "layer height",
                format!("{lo:.3} (line {ll}) .. {hi:.3} mm (line {hl})"),
            );
        }
        if let Some([(lo, ll), (hi, hl)]) = sp.width {
            row(
                &mut s,
                "bead width",
                format!("{lo:.2} (line {ll}) .. {hi:.2} mm (line {hl})"),
            );
        }
        if let Some(z) = self.first_layer_z {
            row(&mut s, "first bead at z", format!("{z:.3} mm"));
        }
        row(
            &mut s,
            "size",
            format!(
                "{:.1} x {:.1} x {:.1} mm, ~{} layers",
                self.size_mm[0], self.size_mm[1], self.size_mm[2], self.layers
            ),
        );
        row(
            &mut s,
            "path length",
            format!("{:.1} mm", self.path_length_mm),
        );
        row(&mut s, "clay volume", format!("{:.2} ml", self.volume_ml));
        row(
            &mut s,
            "estimated time",
            format!("{:.1} min", self.time_min),
        );
        if !self.diagnostics.is_empty() {
            let _ = writeln!(s, "\n  notes:");
            for d in &self.diagnostics {
                let _ = writeln!(s, "    line {}: {}", d.line, d.message);
            }
        }
        s
    }
}
