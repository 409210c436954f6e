//! # sweepclay-check
//!
//! An independent clay-printability verifier for G-code (docs/CHECKER.md). It
//! shares no code with the sweepclay pipeline, so it cannot share its bugs:
//! it reads any G-code, replays the deposition bead by bead, and says
//! whether the file prints in clay:
//!
//! - **continuity**: one extrusion run; no travel, retraction or pause after
//!   the first bead; no extrusion without motion;
//! - **bounds**: inside the build volume, z ≥ 0, first bead near the bed;
//! - **collision**: the extruder as a cylinder of radius r up to H above the
//!   tip, the carriage above that; no earlier clay inside (the clay the
//!   nozzle laid in the last r + w_max of path excepted);
//! - **support**: each bead's width follows from its volume, its length and
//!   its local layer height (distance to the clay below); it must overlap
//!   the bead below by at least half its width, within the overhang limit,
//!   and never float or land on clay at its own height.
//!
//! ```
//! use sweepclay_check::{check, CheckConfig};
//! let mut g = String::from("G21\nG90\nM82\nG0 X50 Y50 Z1.2\n");
//! let mut e = 0.0;
//! for layer in 1..=5 {
//!     let z = 1.2 * layer as f64;
//!     let (x0, x1) = if layer % 2 == 1 { (50.0, 90.0) } else { (90.0, 50.0) };
//!     if layer > 1 { e += 0.13 * 1.2 * 3.0 * 1.2; g += &format!("G1 X{x0} Y50 Z{z} E{e:.5}\n"); }
//!     for k in 1..=40 {
//!         let x = x0 + (x1 - x0) * k as f64 / 40.0;
//!         e += 0.13 * 1.0 * 3.0 * 1.2;
//!         g += &format!("G1 X{x} Y50 Z{z} E{e:.5}\n");
//!     }
//! }
//! let report = check(&g, &CheckConfig::default());
//! assert!(report.printable, "{}", report.render());
//! ```

mod bead;
mod blocks;
mod checker;
mod collide;
mod geom;
mod grid;
pub mod header;
pub mod parse;
pub mod replay;
mod report;
mod support;
#[cfg(test)]
mod testkit;
// The shared test helpers name this crate as its tests outside do.
#[cfg(test)]
extern crate self as sweepclay_check;
mod tops;
mod verdict;

pub use checker::{check, check_reader, CheckWriter};
#[doc(hidden)]
pub use checker::{check_exhaustive, check_kept, check_pruned};
pub use parse::Diagnostic;
pub use report::{
    Count, Finding, Findings, Report, Segment, SupportStats, OVERFLOW_SECTIONS, TURN_FACTOR,
    UNDER_EXTRUDED,
};

/// One xorshift step: the unit tests' reproducible random numbers.
#[cfg(test)]
fn xorshift(state: &mut u64) -> u64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    *state
}

use serde::Serialize;

/// What the checker assumes about the printer and the clay. Lengths in mm.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CheckConfig {
    /// Build volume `[x, y, z]`: the printer's box spans `bed_min` to
    /// `bed_min + build_volume`. Default 200³.
    pub build_volume: [f64; 3],
    /// The box's lowest corner in the printer's coordinates: `[0, 0, 0]`
    /// (the default) for a bed with its origin at a corner, `[-R, -R, 0]`
    /// for a delta or a WASP with the origin at the bed's centre.
    pub bed_min: [f64; 3],
    /// A round bed's diameter (a delta's), centred in the box's plan: a
    /// move farther from its centre is out of bounds too. Default none.
    pub bed_diameter: Option<f64>,
    /// The printer the file is judged for, as the report names it
    /// (default `generic`).
    pub printer: String,
    /// Whose reading of the G-code to replay where firmwares differ.
    /// Default Marlin.
    pub firmware: Firmware,
    /// E units per mm³ of clay. Default 0.13.
    pub e_per_mm3: f64,
    /// Radius of the extruder body (nozzle cylinder). Default 5.
    pub nozzle_radius: f64,
    /// H: height of the nozzle cylinder above the tip; the carriage is
    /// above it. Default 30.
    pub nozzle_height: f64,
    /// Narrowest bead expected (used for the double-deposition test).
    /// Default 3.
    pub width_min: f64,
    /// Widest bead expected (search radius for the clay below). Default 6.
    pub width_max: f64,
    /// Target overlap with the bead below; beads under it are counted.
    /// Default 2/3.
    pub overlap_target: f64,
    /// Overlap below which a bead fails. Default 1/2.
    pub overlap_min: f64,
    /// Overhang threshold from vertical, degrees. Default 57.
    pub max_overhang_deg: f64,
    /// Tolerance on the overhang threshold, degrees. Default 0.5.
    pub overhang_tolerance_deg: f64,
    /// Layers thinner than this land on clay at their own height: double
    /// deposition. Default 0.3.
    pub min_layer_mm: f64,
    /// The first bead must start at most this high. Default 3.
    pub first_layer_max_mm: f64,
    /// No bead of the print may have a point lower than this: below it
    /// the nozzle drags on the bed. Default 0.3.
    pub first_layer_min_mm: f64,
    /// Clay deeper than this below a bead does not support it. Default 6.
    pub max_gap_mm: f64,
    /// Clay this little above the nozzle tip is not a collision: a graze
    /// on a bead's rounded edge. Default 0.2.
    pub collision_tolerance_mm: f64,
}

impl Default for CheckConfig {
    fn default() -> Self {
        CheckConfig {
            build_volume: [200.0, 200.0, 200.0],
            bed_min: [0.0, 0.0, 0.0],
            bed_diameter: None,
            printer: "generic".into(),
            firmware: Firmware::Marlin,
            e_per_mm3: 0.13,
            nozzle_radius: 5.0,
            nozzle_height: 30.0,
            width_min: 3.0,
            width_max: 6.0,
            overlap_target: 2.0 / 3.0,
            overlap_min: 0.5,
            max_overhang_deg: 57.0,
            overhang_tolerance_deg: 0.5,
            min_layer_mm: 0.3,
            first_layer_max_mm: 3.0,
            first_layer_min_mm: 0.3,
            max_gap_mm: 6.0,
            collision_tolerance_mm: 0.2,
        }
    }
}

/// The firmwares whose readings of G-code differ where the checker must
/// choose (docs/CHECKER.md, "Firmwares").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Firmware {
    /// Marlin: `G90`/`G91` also switch E; `Z5e-05` is Z 0.00005.
    #[default]
    Marlin,
    /// Klipper: `G90`/`G91` leave E as `M82`/`M83` set it; `Z5e-05` is
    /// Z5 then E-05.
    Klipper,
    /// RepRapFirmware: `G90`/`G91` leave E as `M82`/`M83` set it; `Z5e-05`
    /// is Z 0.00005.
    Reprap,
}

impl Firmware {
    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Firmware::Marlin => "marlin",
            Firmware::Klipper => "klipper",
            Firmware::Reprap => "reprap",
        }
    }

    /// Whether `G90`/`G91` also set absolute/relative E.
    pub fn g91_moves_e(self) -> bool {
        self == Firmware::Marlin
    }

    /// Whether a number's `e`/`E` starts an exponent (`5e-05` is one
    /// number) rather than the next word.
    pub fn reads_exponents(self) -> bool {
        self != Firmware::Klipper
    }
}

impl std::str::FromStr for Firmware {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "marlin" => Ok(Firmware::Marlin),
            "klipper" => Ok(Firmware::Klipper),
            "reprap" | "rrf" | "reprapfirmware" => Ok(Firmware::Reprap),
            _ => Err(format!(
                "unknown firmware `{s}` (marlin, klipper or reprap)"
            )),
        }
    }
}

/// An option of [`CheckConfig`] out of its range: which one (the field's
/// name) and why.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("`{field}` {reason}")]
pub struct ConfigError {
    /// The field of [`CheckConfig`].
    pub field: &'static str,
    /// What is wrong with its value.
    pub reason: String,
}

/// The largest machine dimension a check accepts (mm): 100 m.
pub const MAX_MACHINE_MM: f64 = 100_000.0;

/// The largest bead, layer or tolerance a check accepts (mm).
pub const MAX_BEAD_MM: f64 = 100.0;

/// The widest extruder body read (radius, mm): half a metre across, past
/// the largest clay extruder made. A body radius is a physical size; a
/// huge one is a typo, not a printer (docs/CHECKER.md, "Collisions").
pub const MAX_NOZZLE_RADIUS_MM: f64 = 250.0;

impl CheckConfig {
    /// Checks every value: finite, positive where it must be, fractions in
    /// [0, 1], angles in (0, 90). A NaN would silently turn every test it
    /// enters into a pass.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let err = |field, reason: String| Err(ConfigError { field, reason });
        let bad = |v: &[f64; 3], ok: fn(f64) -> bool| v.iter().copied().find(|&x| !ok(x));
        if let Some(v) = bad(&self.build_volume, |x| x.is_finite() && x > 0.0) {
            return err(
                "build_volume",
                format!("must be positive numbers (got {v})"),
            );
        }
        if let Some(v) = bad(&self.bed_min, f64::is_finite) {
            return err("bed_min", format!("must be finite numbers (got {v})"));
        }
        if let Some(d) = self.bed_diameter.filter(|d| !(d.is_finite() && *d > 0.0)) {
            return err(
                "bed_diameter",
                format!("must be a positive number of mm (got {d})"),
            );
        }
        for (field, v) in [
            ("e_per_mm3", self.e_per_mm3),
            ("nozzle_height", self.nozzle_height),
            ("width_min", self.width_min),
            ("width_max", self.width_max),
            ("min_layer_mm", self.min_layer_mm),
            ("first_layer_max_mm", self.first_layer_max_mm),
            ("max_gap_mm", self.max_gap_mm),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return err(field, format!("must be a positive number (got {v})"));
            }
        }
        for (field, v) in [
            ("nozzle_radius", self.nozzle_radius),
            ("first_layer_min_mm", self.first_layer_min_mm),
            ("collision_tolerance_mm", self.collision_tolerance_mm),
            ("overhang_tolerance_deg", self.overhang_tolerance_deg),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return err(field, format!("must be a finite number ≥ 0 (got {v})"));
            }
        }
        if self.width_max < self.width_min {
            return err(
                "width_max",
                format!(
                    "must be at least width_min {} (got {})",
                    self.width_min, self.width_max
                ),
            );
        }
        for (field, v) in [
            ("overlap_target", self.overlap_target),
            ("overlap_min", self.overlap_min),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return err(field, format!("must be a fraction from 0 to 1 (got {v})"));
            }
        }
        if !(self.max_overhang_deg > 0.0 && self.max_overhang_deg < 90.0) {
            return err(
                "max_overhang_deg",
                format!(
                    "must be an angle between 0 and 90 degrees (got {})",
                    self.max_overhang_deg
                ),
            );
        }
        // A physical range for every value: a huge number (1e308) would
        // switch a rule off as surely as NaN did.
        let most = |v: &[f64; 3]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for (field, v, hi) in [
            ("build_volume", most(&self.build_volume), MAX_MACHINE_MM),
            ("bed_min", most(&self.bed_min), MAX_MACHINE_MM),
            (
                "bed_diameter",
                self.bed_diameter.unwrap_or(0.0),
                MAX_MACHINE_MM,
            ),
            ("e_per_mm3", self.e_per_mm3, 10_000.0),
            ("nozzle_height", self.nozzle_height, MAX_MACHINE_MM),
            ("nozzle_radius", self.nozzle_radius, MAX_NOZZLE_RADIUS_MM),
            ("width_min", self.width_min, MAX_BEAD_MM),
            ("width_max", self.width_max, MAX_BEAD_MM),
            ("min_layer_mm", self.min_layer_mm, MAX_BEAD_MM),
            ("first_layer_min_mm", self.first_layer_min_mm, MAX_BEAD_MM),
            ("first_layer_max_mm", self.first_layer_max_mm, MAX_BEAD_MM),
            ("max_gap_mm", self.max_gap_mm, MAX_BEAD_MM),
            (
                "collision_tolerance_mm",
                self.collision_tolerance_mm,
                MAX_BEAD_MM,
            ),
            ("overhang_tolerance_deg", self.overhang_tolerance_deg, 90.0),
        ] {
            if v > hi {
                return err(
                    field,
                    format!(
                        "must be at most {hi} (got {v}): no clay printer or bead is that large"
                    ),
                );
            }
        }
        Ok(())
    }
}
