//! The slicing parameters (docs/FORMATS.md, "params"): their defaults,
//! ranges and the limits derived from them (the paper's §4 bound on a
//! bead's offset from the one below).

use super::*;

/// Slicing parameters (docs/FORMATS.md). Lengths in mm, angles in degrees,
/// feedrate in mm/min. Defaults are the paper's (§5–6).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Params {
    /// Δz_min: minimum layer height. Default 1.25 mm.
    pub layer_height: f64,
    /// Δz_max: thickest layer allowed. Default 2.5 mm.
    pub max_layer_height: f64,
    /// Sample spacing along the trajectory. Default 1.1 mm.
    pub spacing: f64,
    /// H: height of the extruder body above the nozzle tip. Default 30 mm.
    pub nozzle_height: f64,
    /// Narrowest bead. Default 3 mm.
    pub width_min: f64,
    /// Widest bead. Default 6 mm.
    pub width_max: f64,
    /// Target overlap with the bead below, as a fraction of the bead's
    /// width. Default 2/3.
    pub overlap: f64,
    /// Overhang threshold measured from vertical. Default 57°.
    pub max_overhang_deg: f64,
    /// Printing speed. Default 2000 mm/min.
    pub feedrate: f64,
    /// Flat layers of a vessel's floor (closed Ψ only; 0 = bottomless).
    /// Omitted: [`DEFAULT_FLOOR_LAYERS`] for a vessel.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub floor_layers: Option<u32>,
    /// Slow the nozzle on a turnaround step that lays more clay a
    /// millimetre than the bead before it, so the extruder's flow stays
    /// even through the turn (docs/ALGORITHMS.md §6). Default on.
    pub even_turn_flow: bool,
    /// Firing shrinkage across (x, y), a fraction: the piece is printed
    /// 1 / (1 − s) larger so that it has the designed size after the
    /// kiln (docs/ALGORITHMS.md §6). Default 0.
    pub shrinkage_xy: f64,
    /// Firing shrinkage in height, the same way. Default 0.
    pub shrinkage_z: f64,
    /// How far (mm) the corrections may move the printed shape from the
    /// drawn one before the verdict says "printable, but reshaped"
    /// (docs/ALGORITHMS.md §4). Default 5 mm.
    pub max_correction_mm: f64,
}

/// The tallest layer a design may ask for, in narrowest bead widths: the
/// checker's largest gap, a bead as tall as it is wide with the widths'
/// 25 % tolerance (docs/CHECKER.md, "Layer gaps").
pub const TALLEST_BEAD: f64 = 1.25;

/// Floor layers of a vessel when `params.floor_layers` is omitted.
pub const DEFAULT_FLOOR_LAYERS: u32 = 2;

/// Most floor layers a vessel may have.
pub const MAX_FLOOR_LAYERS: u32 = 20;

impl Default for Params {
    fn default() -> Self {
        Params {
            layer_height: 1.25,
            max_layer_height: 2.5,
            spacing: 1.1,
            nozzle_height: 30.0,
            width_min: 3.0,
            width_max: 6.0,
            overlap: 2.0 / 3.0,
            max_overhang_deg: 57.0,
            feedrate: 2000.0,
            floor_layers: None,
            even_turn_flow: true,
            shrinkage_xy: 0.0,
            shrinkage_z: 0.0,
            max_correction_mm: 5.0,
        }
    }
}

/// Safety margin (mm) kept between the highest printed clay and the bottom
/// of the carriage, on top of one layer (see `docs/ALGORITHMS.md`).
pub const COLLISION_MARGIN_MM: f64 = 1.0;

/// The longest design name (characters): it becomes a file name and a
/// download's header.
pub const MAX_NAME_CHARS: usize = 200;

/// The thinnest layer (mm) `params.layer_height` may ask for.
pub const MIN_LAYER: f64 = 0.5;

/// The closest sample spacing (mm) `params.spacing` may ask for.
pub const MIN_SPACING: f64 = 0.01;

/// Overlap of a floor bead with its neighbour in the same layer, as a
/// fraction of its width: enough to close the floor, little enough that the
/// clay has room (docs/ALGORITHMS.md §8). The floor is laid with it; the
/// sample estimate counts its rings with it.
pub const FLOOR_OVERLAP: f64 = 0.15;

impl Params {
    /// Checks every parameter against its allowed range.
    pub fn validate(&self) -> Result<()> {
        range("params.layer_height", self.layer_height, MIN_LAYER, 10.0)?;
        range(
            "params.max_layer_height",
            self.max_layer_height,
            self.layer_height,
            20.0,
        )?;
        range("params.spacing", self.spacing, MIN_SPACING, 50.0)?;
        let h_min = self.max_layer_height + self.layer_height + COLLISION_MARGIN_MM;
        if self.nozzle_height > crate::printer::MAX_MACHINE_MM {
            return Err(Error::invalid(
                "params.nozzle_height",
                format!(
                    "must be at most {} mm (got {}): no extruder body is that tall, and `check` would refuse to read its G-code",
                    crate::printer::MAX_MACHINE_MM,
                    self.nozzle_height
                ),
            ));
        }
        if !(self.nozzle_height.is_finite() && self.nozzle_height > h_min) {
            return Err(Error::invalid(
                "params.nozzle_height",
                format!(
                    "must exceed max_layer_height + layer_height + {COLLISION_MARGIN_MM} mm = {h_min} mm (got {})",
                    self.nozzle_height
                ),
            ));
        }
        range("params.width_min", self.width_min, 0.1, 50.0)?;
        range(
            "params.max_correction_mm",
            self.max_correction_mm,
            0.0,
            10_000.0,
        )?;
        range("params.width_max", self.width_max, self.width_min, 50.0)?;
        // A bead taller than it is wide does not stand: the checker fails
        // it as a layer gap (docs/CHECKER.md, "Layer gaps").
        let tallest = TALLEST_BEAD * self.width_min;
        if self.max_layer_height > tallest + 1e-9 {
            return Err(Error::invalid(
                "params.max_layer_height",
                format!(
                    "must be at most {TALLEST_BEAD} × width_min = {tallest:.3} mm: a bead taller than it is wide does not stand (got {}; raise width_min or lower max_layer_height)",
                    self.max_layer_height
                ),
            ));
        }
        range("params.overlap", self.overlap, 0.5, 0.95)?;
        range("params.max_overhang_deg", self.max_overhang_deg, 1.0, 80.0)?;
        range("params.feedrate", self.feedrate, 1.0, 100_000.0)?;
        // Clay bodies shrink 5–20 % in the kiln; past a half, a typo.
        range("params.shrinkage_xy", self.shrinkage_xy, 0.0, 0.5)?;
        range("params.shrinkage_z", self.shrinkage_z, 0.0, 0.5)?;
        if let Some(f) = self.floor_layers {
            if f > MAX_FLOOR_LAYERS {
                return Err(Error::invalid(
                    "params.floor_layers",
                    format!("must be between 0 and {MAX_FLOOR_LAYERS} (got {f})"),
                ));
            }
        }
        Ok(())
    }

    /// The largest horizontal step between two samples `dz` apart
    /// (docs/ALGORITHMS.md §4): the overhang limit and the offset the widest bead still covers
    /// with the target overlap.
    pub fn max_offset(&self, dz: f64) -> f64 {
        self.offset_limit(dz).0
    }

    /// [`Params::max_offset`] and which of its two limits binds: the
    /// overhang angle (`true`: dz · tan θ_max) or the bead overlap
    /// (`false`: w_max · (1 − overlap), the offset the widest bead still
    /// covers with the target overlap, whatever the layer height).
    pub fn offset_limit(&self, dz: f64) -> (f64, bool) {
        let by_angle = dz * self.max_overhang_deg.to_radians().tan();
        let by_width = self.width_max * (1.0 - self.overlap);
        if by_angle <= by_width {
            (by_angle, true)
        } else {
            (by_width, false)
        }
    }

    /// How much larger than designed the piece is printed, across and in
    /// height: 1 / (1 − s) for the firing shrinkages (1 without).
    pub fn print_scale(&self) -> [f64; 2] {
        [self.shrinkage_xy, self.shrinkage_z].map(|s| {
            if s > 0.0 && s < 1.0 {
                1.0 / (1.0 - s)
            } else {
                1.0
            }
        })
    }

    /// The keys `--set` accepts, in file order.
    pub const KEYS: &'static [&'static str] = &[
        "layer_height",
        "max_layer_height",
        "spacing",
        "nozzle_height",
        "width_min",
        "width_max",
        "overlap",
        "max_overhang_deg",
        "feedrate",
        "floor_layers",
        "even_turn_flow",
        "shrinkage_xy",
        "shrinkage_z",
        "max_correction_mm",
    ];

    /// Sets one parameter by name (`--set key=value`).
    pub fn set(&mut self, key: &str, value: f64) -> Result<()> {
        if key == "floor_layers" {
            if !(value.fract() == 0.0 && (0.0..=f64::from(MAX_FLOOR_LAYERS)).contains(&value)) {
                return Err(Error::invalid(
                    "params.floor_layers",
                    format!("must be a whole number from 0 to {MAX_FLOOR_LAYERS} (got {value})"),
                ));
            }
            self.floor_layers = Some(value as u32);
            return Ok(());
        }
        if key == "even_turn_flow" {
            if value != 0.0 && value != 1.0 {
                return Err(Error::invalid(
                    "params.even_turn_flow",
                    format!("must be 1 (on) or 0 (off) (got {value})"),
                ));
            }
            self.even_turn_flow = value == 1.0;
            return Ok(());
        }
        let slot = match key {
            "layer_height" => &mut self.layer_height,
            "max_layer_height" => &mut self.max_layer_height,
            "spacing" => &mut self.spacing,
            "nozzle_height" => &mut self.nozzle_height,
            "width_min" => &mut self.width_min,
            "width_max" => &mut self.width_max,
            "overlap" => &mut self.overlap,
            "max_overhang_deg" => &mut self.max_overhang_deg,
            "feedrate" => &mut self.feedrate,
            "shrinkage_xy" => &mut self.shrinkage_xy,
            "max_correction_mm" => &mut self.max_correction_mm,
            "shrinkage_z" => &mut self.shrinkage_z,
            _ => {
                return Err(Error::invalid(
                    format!("params.{key}"),
                    format!("unknown parameter (known: {})", Self::KEYS.join(", ")),
                ))
            }
        };
        *slot = value;
        Ok(())
    }
}

pub(super) fn range(key: &str, v: f64, lo: f64, hi: f64) -> Result<()> {
    if v.is_finite() && v >= lo && v <= hi {
        Ok(())
    } else {
        Err(Error::invalid(
            key,
            format!("must be between {lo} and {hi} (got {v})"),
        ))
    }
}
