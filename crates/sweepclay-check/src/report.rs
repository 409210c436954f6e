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
    /// The lines of the first [`Count::LINES_KEPT`] occurrences (not in
    /// the JSON report): where a slicer's correction loop tightens.
    #[serde(skip)]
    pub lines: Vec<usize>,
}

impl Count {
    /// How many occurrences' lines [`Count::lines`] keeps.
    pub const LINES_KEPT: usize = 256;

    /// Records one occurrence at `line` with value `v` (larger is worse).
    pub fn add(&mut self, line: usize, v: f64) {
        self.count += 1;
        if self.lines.len() < Self::LINES_KEPT {
            self.lines.push(line);
        }
        self.first_line.get_or_insert(line);
        if self.worst.is_none_or(|(w, _)| v > w) {
            self.worst = Some((v, line));
        }
    }
}

/// Everything that makes a file not printable in clay, one kind each. The
/// verdict, the text report, `--json` and the modeler's failure lines all
/// read this one list.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Finding {
    /// A move without extrusion between two beads of the print.
    TravelMove,
    /// E going back between two beads of the print.
    Retraction,
    /// G4, M0, M1 or M600 between two beads of the print.
    Pause,
    /// E rising with no motion between two beads of the print: a blob.
    ExtrusionWithoutMotion,
    /// A move outside the printer's box; worst distance outside (mm).
    OutOfBounds,
    /// A print bead with a point below the first-layer minimum: the nozzle
    /// dragged on or into the bed; worst depth below the minimum (mm).
    IntoBed,
    /// The print's first bead too far above the bed; its height (mm).
    FirstLayerHigh,
    /// Earlier clay inside the nozzle cylinder; worst height above the tip.
    NozzleCollision,
    /// Clay higher than the carriage; worst height above it (mm).
    CarriageCollision,
    /// A bead with no clay below it and not on the bed; its height (mm).
    Unsupported,
    /// A bead resting on clay farther below it than the bead is wide: a
    /// bead taller than wide does not stand, and clay two layers down is
    /// no support (docs/CHECKER.md, "Layer gaps"); the worst gap (mm).
    LayerGap,
    /// A stretch of beads laid on clay at their own height whose clay has
    /// no room to go; the clay that has none (mm³).
    DoubleDeposition,
    /// A bead overlapping the bead below by less than the minimum; the
    /// shortfall (fraction of its width).
    UnderMinOverlap,
    /// An overhang beyond the limit; the angle (degrees).
    Overhang,
    /// A number firmwares read differently (`Z5e-05`).
    AmbiguousNumber,
    /// A number on a move no firmware reads as written (`X-`, `X-inf`,
    /// `X.`): Marlin reads it as 0 and moves there.
    UnreadableNumber,
    /// A bead carrying more clay a millimetre than fits under the nozzle
    /// ([`OVERFLOW_SECTIONS`]); its cross-section (mm²).
    ClayOverflow,
    /// A turnaround step carrying more than [`TURN_FACTOR`] times the clay
    /// the end of the bead after it needs: clay piles up at the turn
    /// (docs/CHECKER.md, "Turns"). Worst: that ratio.
    TurnPile,
    /// A move between two beads of the print, no climbing step, that
    /// carries less than [`UNDER_EXTRUDED`] of a `width_min` bead of its
    /// layer: no clay extruder drops its flow that far within a move
    /// (docs/CHECKER.md, "Under-extruded moves"). Worst: its width (mm).
    UnderExtruded,
}

/// The share of a `width_min` bead's clay under which a move of the print
/// is an under-extruded bead (docs/CHECKER.md, "Under-extruded moves").
pub const UNDER_EXTRUDED: f64 = 0.25;

/// A bead whose clay cross-section (volume over length) exceeds this many
/// times that of the widest bead laid half as high as it is wide carries
/// more clay than fits under the nozzle: `M83` half way through an
/// absolute-E file, a lost `G92 E0` (docs/CHECKER.md, "Clay that cannot
/// fit").
pub const OVERFLOW_SECTIONS: f64 = 4.0;

/// How much more clay than the end of the next bead needs a turnaround
/// step may carry before it counts as a pile (docs/CHECKER.md, "Turns").
pub const TURN_FACTOR: f64 = 2.0;

impl Finding {
    /// Every kind, in the order reports list them.
    pub const ALL: [Finding; 19] = [
        Finding::TravelMove,
        Finding::Retraction,
        Finding::Pause,
        Finding::ExtrusionWithoutMotion,
        Finding::OutOfBounds,
        Finding::IntoBed,
        Finding::FirstLayerHigh,
        Finding::NozzleCollision,
        Finding::CarriageCollision,
        Finding::Unsupported,
        Finding::LayerGap,
        Finding::DoubleDeposition,
        Finding::UnderMinOverlap,
        Finding::Overhang,
        Finding::AmbiguousNumber,
        Finding::UnreadableNumber,
        Finding::ClayOverflow,
        Finding::TurnPile,
        Finding::UnderExtruded,
    ];

    /// The row of the text report (with the unit of the worst value).
    pub fn label(self) -> &'static str {
        match self {
            Finding::TravelMove => "travel moves",
            Finding::Retraction => "retractions",
            Finding::Pause => "pauses",
            Finding::ExtrusionWithoutMotion => "extrusion without motion",
            Finding::OutOfBounds => "out of bounds (mm)",
            Finding::IntoBed => "beads into the bed (mm)",
            Finding::FirstLayerHigh => "first layer too high (mm)",
            Finding::NozzleCollision => "nozzle collisions (mm)",
            Finding::CarriageCollision => "carriage collisions (mm)",
            Finding::Unsupported => "unsupported beads",
            Finding::LayerGap => "layer gaps (mm)",
            Finding::DoubleDeposition => "clay on clay (mm³)",
            Finding::UnderMinOverlap => "overlap < minimum",
            Finding::Overhang => "overhang > limit (deg)",
            Finding::AmbiguousNumber => "ambiguous numbers",
            Finding::UnreadableNumber => "unreadable numbers",
            Finding::ClayOverflow => "clay beyond the nozzle (mm²)",
            Finding::TurnPile => "clay piled at turns (x)",
            Finding::UnderExtruded => "under-extruded moves (mm)",
        }
    }

    /// What the verdict says of `n` of them.
    pub fn failure(self) -> &'static str {
        match self {
            Finding::TravelMove => "travel move(s) after the first bead",
            Finding::Retraction => "retraction(s)",
            Finding::Pause => "pause(s)",
            Finding::ExtrusionWithoutMotion => "extrusion(s) without motion",
            Finding::OutOfBounds => "move(s) outside the build volume",
            Finding::IntoBed => "bead(s) at or into the bed (the nozzle drags on it)",
            Finding::FirstLayerHigh => "first layer too far above the bed",
            Finding::NozzleCollision => "nozzle collision(s) with printed clay",
            Finding::CarriageCollision => "carriage collision(s) with printed clay",
            Finding::Unsupported => "bead(s) with no clay below",
            Finding::LayerGap => {
                "bead(s) resting on clay farther below than they are wide (a coil narrower than its layer does not stand; clay two layers down is no support)"
            }
            Finding::DoubleDeposition => "stretch(es) of beads laid on clay at their own height",
            Finding::UnderMinOverlap => "bead(s) overlapping the bead below by less than half",
            Finding::Overhang => "overhang(s) beyond the limit",
            Finding::AmbiguousNumber => "number(s) that firmwares read differently",
            Finding::ClayOverflow => {
                "bead(s) carrying more clay than fits under the nozzle (a cross-section over 4 widest beads of half their width in height)"
            }
            Finding::UnreadableNumber => {
                "move(s) with a number no firmware reads as written (Marlin moves to 0 there)"
            }
            Finding::TurnPile => {
                "turnaround step(s) carrying more than twice the clay the end of the next bead needs (it piles up at the turn)"
            }
            Finding::UnderExtruded => {
                "under-extruded move(s) between beads (less than a quarter of the narrowest bead's clay: no clay extruder drops its flow that fast)"
            }
        }
    }
}

/// One [`Count`] per [`Finding`]; `--json` writes them as an object keyed
/// by the finding's snake-case name.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Findings([Count; Finding::ALL.len()]);

impl std::ops::Index<Finding> for Findings {
    type Output = Count;
    fn index(&self, f: Finding) -> &Count {
        &self.0[f as usize]
    }
}

impl std::ops::IndexMut<Finding> for Findings {
    fn index_mut(&mut self, f: Finding) -> &mut Count {
        &mut self.0[f as usize]
    }
}

impl Findings {
    /// The kinds that occurred, with their counts, in report order.
    pub fn occurred(&self) -> impl Iterator<Item = (Finding, &Count)> {
        Finding::ALL
            .into_iter()
            .map(move |f| (f, &self[f]))
            .filter(|(_, c)| c.count > 0)
    }
}

impl Serialize for Findings {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut m = s.serialize_map(Some(Finding::ALL.len()))?;
        for f in Finding::ALL {
            m.serialize_entry(&f, &self[f])?;
        }
        m.end()
    }
}

/// Start or end code: what comes before the print's first bead or after
/// its last (docs/CHECKER.md: reported, never a reason to fail).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Segment {
    /// First and last line of it.
    pub lines: [usize; 2],
    /// Moves in it.
    pub moves: usize,
    /// Clay it extrudes (ml): primes, purges, a skirt.
    pub clay_ml: f64,
    /// What it holds, in words with lines (at most 12).
    pub items: Vec<String>,
}

impl Segment {
    /// Notes `item` (kept while there are fewer than 12).
    pub(crate) fn note(&mut self, item: String) {
        if self.items.len() < 12 && !self.items.contains(&item) {
            self.items.push(item);
        }
    }

    /// Widens the line range to hold `line`.
    pub(crate) fn cover(&mut self, line: usize) {
        if self.lines[0] == 0 || line < self.lines[0] {
            self.lines[0] = line;
        }
        self.lines[1] = self.lines[1].max(line);
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
    /// Clay laid on the steps and what they need, the half-disc end of
    /// the bead after each (mm³; docs/CHECKER.md, "Turns").
    pub turn_clay_mm3: [f64; 2],
    /// Beads laid on clay at about their own height (a vase's first turn
    /// rising from its flat first loop, a seam): pressed into the clay
    /// below rather than resting a layer above it.
    pub on_clay: usize,
    /// Smallest overlap fraction and its line.
    pub min_overlap: Option<(f64, usize)>,
    /// Beads by overlap: `<1/2`, `1/2–0.6`, `0.6–target`, `target–0.9`, `≥0.9`.
    pub overlap_histogram: [usize; 5],
    /// Beads under the target (reported).
    pub under_target: usize,
    /// Largest overhang angle (degrees) and its line.
    pub max_overhang_deg: Option<(f64, usize)>,
    /// Smallest and largest local layer height (mm) with lines.
    pub layer_height: Option<[(f64, usize); 2]>,
    /// Smallest and largest bead width (mm) with lines.
    pub width: Option<[(f64, usize); 2]>,
    /// Beads wider than `width_max` by more than the tolerance
    /// (over-squished; a warning). Worst width (mm).
    pub wide: Count,
    /// Beads narrower than `width_min` by more than the tolerance (a
    /// warning). Worst: how much narrower (mm).
    pub thin: Count,
}

/// The full report. `printable` is the verdict.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Report {
    /// Whether the file is printable in clay.
    pub printable: bool,
    /// The reasons it is not (empty when printable).
    pub failures: Vec<String>,
    /// What deserves a look but prints (over-squished beads, …).
    pub warnings: Vec<String>,
    /// The printer the file was judged for, and where that came from.
    pub printer: String,
    /// The firmware whose reading of the G-code was replayed.
    pub firmware: String,
    /// Lines in the file.
    pub lines: usize,
    /// Moves replayed.
    pub moves: usize,
    /// Extruding moves.
    pub extruding_moves: usize,
    /// Separate extrusion runs in the print (must be 1).
    pub extrusion_runs: usize,
    /// First lines of the print's runs (at most 20).
    pub run_starts: Vec<usize>,
    /// Every kind of failure: how many, where first, how bad at worst.
    pub findings: Findings,
    /// Height of the print's first bead.
    pub first_layer_z: Option<f64>,
    /// Start code: before the print's first bead.
    pub start_code: Option<Segment>,
    /// End code: after the print's last bead.
    pub end_code: Option<Segment>,
    /// Support analysis.
    pub support: SupportStats,
    /// Length of the extrusion path (mm).
    pub path_length_mm: f64,
    /// Clay volume (ml).
    pub volume_ml: f64,
    /// Time from the feedrates, all moves (min).
    pub time_min: f64,
    /// Size of the print (mm): its beads' centrelines from its first bead
    /// on, start code beside it left out; z is the highest bead's.
    pub size_mm: [f64; 3],
    /// Estimated layer count: height over the median layer height; 0 when
    /// no bead rests on another (the report then says so).
    pub layers: usize,
    /// Set when the file holds a command the replay cannot follow as
    /// firmware would (an arc in another plane, with no centre, or with
    /// a radius shorter than half its chord): no verdict is given
    /// (`printable` is false, and `sweepclay check` exits with 3).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cannot_judge: Option<Diagnostic>,
    /// Parse and replay diagnostics (the first 50).
    pub diagnostics: Vec<Diagnostic>,
    /// How many diagnostics there were in all.
    pub diagnostics_total: usize,
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
        if let Some(d) = &self.cannot_judge {
            let _ = writeln!(
                s,
                "CANNOT JUDGE: line {}: {}; no verdict is given",
                d.line, d.message
            );
        } else if self.printable {
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
        for f in Finding::ALL {
            let c = &self.findings[f];
            if c.count > 0
                || !matches!(
                    f,
                    Finding::IntoBed
                        | Finding::LayerGap
                        | Finding::FirstLayerHigh
                        | Finding::AmbiguousNumber
                        | Finding::UnreadableNumber
                        | Finding::ClayOverflow
                        | Finding::TurnPile
                )
            {
                row(&mut s, f.label(), format!("{} {}", c.count, at(c)));
            }
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
        if sp.steps > 0 {
            let [laid, need] = sp.turn_clay_mm3;
            row(
                &mut s,
                "clay at turns",
                format!(
                    "{:.2} ml laid, {:.2} ml needed ({:.2}x; at most {TURN_FACTOR}x a step)",
                    laid / 1000.0,
                    need / 1000.0,
                    if need > 0.0 { laid / need } else { 0.0 }
                ),
            );
        }
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
        for (k, c) in [
            ("over-squished beads (mm)", &sp.wide),
            ("thin beads (mm)", &sp.thin),
        ] {
            if c.count > 0 {
                row(&mut s, k, format!("{} {}", c.count, at(c)));
            }
        }
        if sp.on_clay > 0 {
            row(&mut s, "beads pressed on clay", format!("{}", sp.on_clay));
        }
        if let Some(z) = self.first_layer_z {
            row(&mut s, "first bead at z", format!("{z:.3} mm"));
        }
        row(
            &mut s,
            "size",
            format!(
                "{:.1} x {:.1} x {:.1} mm, {}",
                self.size_mm[0],
                self.size_mm[1],
                self.size_mm[2],
                match self.layers {
                    // No bead rests on another: no layer height to count by.
                    0 => "layers not counted (no bead rests on another)".to_string(),
                    n => format!("~{n} layers"),
                }
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
        for (k, seg) in [
            ("start code", &self.start_code),
            ("end code", &self.end_code),
        ] {
            if let Some(seg) = seg {
                row(
                    &mut s,
                    k,
                    format!(
                        "lines {}-{}: {} moves, {:.2} ml of clay",
                        seg.lines[0], seg.lines[1], seg.moves, seg.clay_ml
                    ),
                );
                for item in &seg.items {
                    let _ = writeln!(s, "  {:<26}   {item}", "");
                }
            }
        }
        row(&mut s, "printer", self.printer.clone());
        row(&mut s, "firmware", self.firmware.clone());
        if !self.warnings.is_empty() {
            let _ = writeln!(s, "\n  warnings:");
            for w in &self.warnings {
                let _ = writeln!(s, "    {w}");
            }
        }
        if !self.diagnostics.is_empty() {
            let _ = writeln!(s, "\n  notes:");
            for d in &self.diagnostics {
                let _ = writeln!(s, "    line {}: {}", d.line, d.message);
            }
            if self.diagnostics_total > self.diagnostics.len() {
                let _ = writeln!(
                    s,
                    "    … and {} more",
                    self.diagnostics_total - self.diagnostics.len()
                );
            }
        }
        s
    }
}
