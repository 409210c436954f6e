//! # sweepclay-check
//!
//! An independent clay-printability verifier for G-code (DESIGN.md §9). It
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
mod geom;
mod grid;
pub mod parse;
pub mod replay;
mod report;
mod support;
mod tops;
mod verdict;

pub use checker::{check, check_reader, CheckWriter};
#[doc(hidden)]
pub use checker::{check_exhaustive, check_pruned};
pub use parse::Diagnostic;
pub use report::{Count, Report, SupportStats};

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
    /// Build volume `[x, y, z]`; the bed spans `0..x`, `0..y`. Default 200³.
    pub build_volume: [f64; 3],
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
            max_gap_mm: 6.0,
            collision_tolerance_mm: 0.2,
        }
    }
}
