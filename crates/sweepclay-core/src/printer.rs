//! Printer profiles: where the design lands on the bed, how big the bed is,
//! how extrusion volume becomes E, and how big the extruder body is.
//!
//! docs/FORMATS.md: `printer` is a preset name or an inline object whose missing
//! keys take the `generic` values.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// A resolved printer profile. Lengths in mm, feedrates in mm/min.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Printer {
    /// Profile name, written into the G-code header.
    pub name: String,
    /// Build volume `[x, y, z]` in mm: the printable box spans `bed_min`
    /// to `bed_min + build_volume`.
    pub build_volume: [f64; 3],
    /// The box's lowest corner in the printer's coordinates (mm): `[0, 0,
    /// 0]` by default; a delta or a WASP with its origin at the bed's
    /// centre is `[-R, -R, 0]`.
    pub bed_min: [f64; 3],
    /// A round bed's diameter (mm; a delta's): the print must also stay
    /// within it, centred in the box's plan. Omitted: the box's rectangle.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bed_diameter: Option<f64>,
    /// Where the design's centre `o` lands on the bed, `[x, y]` in mm.
    pub origin: [f64; 2],
    /// Extrusion calibration: E units per mm³ of clay. Default 0.13.
    pub e_per_mm3: f64,
    /// Relative E (`M83`) instead of absolute (`M82`, the default).
    pub relative_e: bool,
    /// Radius of the extruder body (mm) that must not touch printed clay
    /// below `nozzle_height`. Default 5.
    pub nozzle_radius: f64,
    /// Feedrate of the single rapid move to the first point, mm/min.
    pub travel_feedrate: f64,
    /// Acceleration of printing moves (mm/s², `M204 P`), for the print
    /// time (docs/ALGORITHMS.md §9). Default 3000, Marlin's
    /// `DEFAULT_ACCELERATION`.
    pub acceleration_mm_s2: f64,
    /// Fastest speed of the x, y and z axes (mm/s, `M203`). Default
    /// Marlin's `DEFAULT_MAX_FEEDRATE`, 300, 300, 5.
    pub max_speed_mm_s: [f64; 3],
    /// Fastest acceleration of the x, y and z axes (mm/s², `M201`).
    /// Default Marlin's `DEFAULT_MAX_ACCELERATION`, 3000, 3000, 100.
    pub max_acceleration_mm_s2: [f64; 3],
    /// Junction deviation (mm), which sets the speed of a corner. Default
    /// 0.013, Marlin's `JUNCTION_DEVIATION_MM`.
    pub junction_deviation_mm: f64,
    /// Most clay the extruder pushes a second (mm³/s); a screw or piston
    /// is often the slowest axis. Omitted: not limited.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_flow_mm3_s: Option<f64>,
    /// Density of the clay body as printed (g/ml), for the clay's mass.
    /// Default 1.9: a plastic clay body of about 22 % water by mass whose
    /// mineral solids are 2.6 g/cm³ (kaolinite 2.6, quartz 2.65) has
    /// 1 / (0.22 / 1.0 + 0.78 / 2.6) = 1.92 g/ml (docs/FORMATS.md).
    pub clay_density_g_ml: f64,
    /// How much clay the cartridge, tank or tube holds (ml); a print
    /// that needs more is warned of (it cannot be continuous). Omitted:
    /// not known.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cartridge_ml: Option<f64>,
    /// G-code sent before the first move.
    pub start_gcode: String,
    /// G-code sent after the last move.
    pub end_gcode: String,
    /// The nozzle's bore (mm), where known. The modeler's printer dialog
    /// sets the bead widths from it: from the bore (a bead laid without
    /// pressing) to twice it (pressed to half its height), the paper's 3
    /// and 6 mm for its 3 mm nozzle (docs/FORMATS.md). Omitted: not known.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nozzle_diameter: Option<f64>,
    /// The print host the machine sits behind, for `sweepclay send` and
    /// the modeler's "Send to printer" (docs/PRINTING.md). Its key or
    /// password is never part of the profile. Omitted: none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub host: Option<PrintHost>,
}

/// Which print host software a printer sits behind.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum HostKind {
    /// OctoPrint (Marlin machines on a Raspberry Pi).
    Octoprint,
    /// Klipper's Moonraker.
    Moonraker,
    /// RepRapFirmware's own web server (Duet boards).
    Reprap,
}

impl HostKind {
    /// The name a profile spells it with.
    pub fn name(self) -> &'static str {
        match self {
            HostKind::Octoprint => "octoprint",
            HostKind::Moonraker => "moonraker",
            HostKind::Reprap => "reprap",
        }
    }
}

/// A print host: its kind and its `http://` or `https://` address on the
/// studio's network, e.g. `{"kind": "octoprint", "url":
/// "http://octopi.local"}`; for an `https://` host with its own
/// (self-signed) certificate, that certificate's SHA-256 fingerprint.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PrintHost {
    /// The host software.
    pub kind: HostKind,
    /// Its address: `http://` or `https://`, a host name or IP address, an
    /// optional port and path; no user name or password in it.
    pub url: String,
    /// The SHA-256 fingerprint of the certificate accepted for an
    /// `https://` host (64 hex digits): its own, which this computer's
    /// roots do not vouch for. Public, unlike the key.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cert_sha256: Option<String>,
}

impl PrintHost {
    /// Checks the address's form; `key` names the field in messages.
    pub fn validate(&self, key: &str) -> Result<()> {
        let rest = self
            .url
            .strip_prefix("http://")
            .or_else(|| self.url.strip_prefix("https://"));
        if let Some(fp) = &self.cert_sha256 {
            let hex: String = fp.chars().filter(|c| !matches!(c, ':' | ' ')).collect();
            if hex.len() != 64 || !hex.chars().all(|c| c.is_ascii_hexdigit()) {
                return Err(Error::invalid(
                    format!("{key}.cert_sha256"),
                    "a certificate's SHA-256 fingerprint is 64 hex digits, e.g. AB:CD:…",
                ));
            }
        }
        let why = if rest.is_none() {
            Some("must start with http:// or https:// (e.g. http://octopi.local)")
        } else if rest
            .and_then(|r| r.split('/').next())
            .is_none_or(str::is_empty)
        {
            Some("has no host name after http://")
        } else if self.url.contains('@') {
            Some("must not carry a user name or password; the key is kept apart (docs/PRINTING.md)")
        } else if self.url.contains(['?', '#', ' ']) || self.url.len() > 2048 {
            Some("must be only the host, port and path")
        } else {
            None
        };
        match why {
            Some(w) => Err(Error::invalid(
                format!("{key}.url"),
                format!(
                    "{w} (got `{}`)",
                    self.url.chars().take(80).collect::<String>()
                ),
            )),
            None => Ok(()),
        }
    }
}

impl Default for Printer {
    fn default() -> Self {
        Printer {
            name: "generic".into(),
            build_volume: [200.0, 200.0, 200.0],
            bed_min: [0.0, 0.0, 0.0],
            bed_diameter: None,
            origin: [100.0, 100.0],
            e_per_mm3: 0.13,
            relative_e: false,
            nozzle_radius: 5.0,
            travel_feedrate: 2400.0,
            acceleration_mm_s2: 3000.0,
            max_speed_mm_s: [300.0, 300.0, 5.0],
            max_acceleration_mm_s2: [3000.0, 3000.0, 100.0],
            junction_deviation_mm: 0.013,
            max_flow_mm3_s: None,
            clay_density_g_ml: 1.9,
            cartridge_ml: None,
            start_gcode: "G28 ; home all axes\nG92 E0\n".into(),
            end_gcode: "M84 ; motors off\n".into(),
            nozzle_diameter: None,
            host: None,
        }
    }
}

/// Names of the built-in presets, in the order `--help` lists them.
pub const PRESETS: &[&str] = &[
    "cerambot-plus",
    "cerambot-mini",
    "wasp-2040-clay",
    "wasp-40100-clay",
    "eazao-zero",
    "eazao-potter",
    "eazao-m500",
    "eazao-m600",
    "vormvrij-lutum-4.6",
    "generic",
];

/// Where each preset's values come from (docs/FORMATS.md has the table
/// with the commits read): a published definition, or a maker's page.
pub fn preset_source(name: &str) -> Option<&'static str> {
    Some(match name {
        "generic" => "sweepclay's defaults (Marlin's motion limits)",
        "cerambot-plus" | "cerambot-mini" => "the paper, Fig. 10 (build volume only)",
        "wasp-2040-clay" => "3dwasp.com technical data; FullControl's wasp2040clay.py",
        "wasp-40100-clay" => "3dwasp.com technical data; DDU's clayprinting-slicer start code",
        "eazao-zero" => "Cura resources/definitions/eazao_zero.def.json",
        "eazao-potter" => "Cura resources/definitions/eazao_potter.def.json",
        "eazao-m500" => "Cura resources/definitions/eazao_m500.def.json",
        "eazao-m600" => "Cura resources/definitions/eazao_m600.def.json",
        "vormvrij-lutum-4.6" => "IceSL's printer profile fff/Lutum_4.6 (shapeforge/icesl-printers)",
        _ => return None,
    })
}

/// The extrusion mode a start code leaves: `Some(true)` for relative
/// (`M83`), `Some(false)` for absolute (`M82`), the last one said, comments
/// and case aside; `None` when it says neither.
pub fn extrusion_mode(start: &str) -> Option<bool> {
    let mut mode = None;
    for line in start.lines() {
        let code = line
            .split(';')
            .next()
            .unwrap_or("")
            .trim()
            .to_ascii_uppercase();
        match code.split_whitespace().next() {
            Some("M83") => mode = Some(true),
            Some("M82") => mode = Some(false),
            _ => {}
        }
    }
    mode
}

/// The Eazao presets' end codes, as their Cura definitions give them: a
/// 10 mm lift written as a new origin (`G92 Z0`, then `G1 Z10`), which
/// firmware and `sweepclay check` read as a lift (docs/CHECKER.md,
/// "Firmwares"), after the writer's own 10 mm lift.
const EAZAO_ZERO_END: &str = "G92 Z0 E0\nG1 F1500 E-2\nG1 F1500 Z10\nG28 X0;move X Y to min endstops\nM82\nM84 ;steppers off\n";
/// [`EAZAO_ZERO_END`]'s kin for the Potter.
const EAZAO_POTTER_END: &str = "G92 Z0 E0\nG1 F1500 Z10 E-2\nM82\nM84 ;steppers off\n";
/// [`EAZAO_ZERO_END`]'s kin for the M500.
const EAZAO_M500_END: &str =
    "G92 Z0\nG1 F1500 Z10\nG28 X0 Y300 ;move X Y to min endstops\nM82\nM84 ;steppers off\n";
/// [`EAZAO_ZERO_END`]'s kin for the M600.
const EAZAO_M600_END: &str =
    "G92 Z0\nG1 F1500 Z10\nG28 X0 Y400 ;move X Y to min endstops\nM82\nM84 ;steppers off\n";

/// E per mm³ of a machine whose firmware counts E as millimetres of
/// filament of diameter `d` mm, as Cura writes it: 1 / (π d² / 4).
fn filament_e_per_mm3(d: f64) -> f64 {
    1.0 / (std::f64::consts::PI * d * d / 4.0)
}

/// An Eazao machine as Ultimaker Cura's definition gives it (docs/
/// FORMATS.md): a box of `size` mm with the origin at its corner, the
/// design's o at the bed's middle, Cura's 1.75 mm filament-equivalent E,
/// 300 mm/s² (`machine_acceleration`), axes to 500/500/50 mm/s² and
/// 100/100/5 mm/s, and 10 mm/s of jerk as Marlin's junction deviation
/// 0.4 · jerk² / acceleration. The body radius is not published: the
/// generic 5 mm.
fn eazao(name: &str, size: [f64; 3], travel_mm_s: f64, start: &str, end: &str) -> Printer {
    let accel = 300.0;
    Printer {
        name: name.into(),
        build_volume: size,
        origin: [size[0] / 2.0, size[1] / 2.0],
        e_per_mm3: filament_e_per_mm3(1.75),
        travel_feedrate: travel_mm_s * 60.0,
        acceleration_mm_s2: accel,
        max_speed_mm_s: [100.0, 100.0, 5.0],
        max_acceleration_mm_s2: [500.0, 500.0, 50.0],
        junction_deviation_mm: 0.4 * 10.0 * 10.0 / accel,
        start_gcode: start.into(),
        end_gcode: end.into(),
        ..Printer::default()
    }
}

impl Printer {
    /// A built-in preset by name.
    pub fn preset(name: &str) -> Option<Printer> {
        let base = Printer::default();
        match name {
            "generic" => Some(base),
            // Paper Fig. 10: CERAMBOT Plus, 180 × 190 × 200 mm.
            "cerambot-plus" => Some(Printer {
                name: name.into(),
                build_volume: [180.0, 190.0, 200.0],
                origin: [90.0, 95.0],
                ..base
            }),
            // Paper Fig. 10: CERAMBOT Mini, 120 × 135 × 100 mm.
            "cerambot-mini" => Some(Printer {
                name: name.into(),
                build_volume: [120.0, 135.0, 100.0],
                origin: [60.0, 67.5],
                ..base
            }),
            // WASP's published printing volume of the DeltaWASP 2040
            // Clay, Ø 200 × 400 mm (www.3dwasp.com, DeltaWASP 2040 Clay,
            // technical data); a delta with its origin at the bed's
            // centre.
            // FullControl's profile of the machine (wasp2040clay.py, docs/
            // FORMATS.md): relative E, E as mm of a 3.1 mm feed measured
            // against printed volumes, travel at 4000 mm/min.
            "wasp-2040-clay" => Some(Printer {
                name: name.into(),
                build_volume: [200.0, 200.0, 400.0],
                bed_min: [-100.0, -100.0, 0.0],
                bed_diameter: Some(200.0),
                origin: [0.0, 0.0],
                relative_e: true,
                e_per_mm3: filament_e_per_mm3(3.1),
                travel_feedrate: 4000.0,
                ..base
            }),
            // WASP's published printing volume of the DeltaWASP 40100
            // Clay, Ø 400 × 1000 mm (www.3dwasp.com, DeltaWASP 40100
            // Clay, technical data).
            "wasp-40100-clay" => Some(Printer {
                name: name.into(),
                build_volume: [400.0, 400.0, 1000.0],
                bed_min: [-200.0, -200.0, 0.0],
                bed_diameter: Some(400.0),
                origin: [0.0, 0.0],
                // The header of the Digital Design Unit's slicer for this
                // machine (docs/FORMATS.md), heaters' lines left out: a
                // clay extruder has none.
                start_gcode: "M82 ; absolute E\nG90 ; absolute coordinates\nG28 ; home all axes\nG21 ; millimetres\nG92 E0\n".into(),
                ..base
            }),
            // Vormvrij Lutum 4.6 as IceSL's profile gives it (docs/
            // FORMATS.md): 435 × 460 × 510 mm from the corner, a 3 mm
            // nozzle fed as 3 mm "filament", travel 150 mm/s, absolute E,
            // and its header with the bed-levelling slot filled as IceSL
            // fills it without a probe. Its footer is not published.
            "vormvrij-lutum-4.6" => Some(Printer {
                name: name.into(),
                build_volume: [435.0, 460.0, 510.0],
                origin: [217.5, 230.0],
                e_per_mm3: filament_e_per_mm3(3.0),
                travel_feedrate: 150.0 * 60.0,
                start_gcode: "G21 ; set units to millimeters\nG90 ; use absolute coordinates\nM82 ; use absolute distances for extrusion\nG28 ; home all axes\nG0 F6200 X0 Y0\nG92 E0\nG1 Z1.0 F3000 ; move z up little to prevent scratching of surface\nG1 X20 Y10 Z0.3 F5000.0 ; move to start-line position\nG1 X150 Y10 Z0.3 F1500.0 E15 ; draw 1st line\nG1 X150 Y10 Z0.3 F5000.0 ; move to side a little\nG1 X20 Y10.3 Z0.3 F1500.0 E30 ; draw 2nd line\nG92 E0 ; reset extruder\n".into(),
                ..base
            }),
            // Start and end code as the definitions give them (docs/
            // FORMATS.md).
            "eazao-zero" => Some(eazao(
                name,
                [150.0, 150.0, 240.0],
                25.0,
                "G21\nG90 ;absolute positioning\nM82 ;set extruder to absolute mode\nG28 ;Home\nG1 Z15.0 F1500 ;move the platform down 15mm\nG92 E0\nG1 F1500 E2\nG92 E0\nM302\nM163 S0 P0.8 ;Set Mix Factor\nM163 S1 P0.2 ;Set Mix Factor\nM164 S0\n",
                EAZAO_ZERO_END,
            )),
            "eazao-potter" => Some(eazao(
                name,
                [167.0, 167.0, 280.0],
                25.0,
                "G21 ;set units to millimeters\nG90 ;absolute positioning\nM82 ;set extruder to absolute mode\nG28 ;Home\nG1 Z25.0 F1500 ;move the platform down 25mm\nG92 E0 ;extruder reset\nG1 F1500 E2\nG92 E0\nM302\nM163 S0 P0.85 ;Set Mix Factor\nM163 S1 P0.15 ;Set Mix Factor\nM164 S0\n",
                EAZAO_POTTER_END,
            )),
            "eazao-m500" => Some(eazao(
                name,
                [320.0, 320.0, 520.0],
                20.0,
                "G21 ;set units to millimeters\nG90 ;absolute positioning\nM82 ;set extruder to absolute mode\nG28 ;Home\nG1 Z25.0 F1500\nG92 E0 ;extruder reset\nG1 F300 E5\nG92 E0\nM302\nM163 S0 P0.85 ;Set Mix Factor\nM163 S1 P0.15 ;Set Mix Factor\nM164 S0\n",
                EAZAO_M500_END,
            )),
            "eazao-m600" => Some(eazao(
                name,
                [420.0, 420.0, 620.0],
                20.0,
                "G21 ;set units to millimeters\nG90 ;absolute positioning\nM82 ;set extruder to absolute mode\nG28 ;Home\nG1 Z25.0 F1500\nG92 E0 ;extruder reset\nG1 F300 E5\nG92 E0\nM302\nM163 S0 P0.87 ;Set Mix Factor\nM163 S1 P0.13 ;Set Mix Factor\nM164 S0\n",
                EAZAO_M600_END,
            )),
            _ => None,
        }
    }

    /// The plan centre of the bed: the middle of the box.
    pub fn bed_centre(&self) -> [f64; 2] {
        [
            self.bed_min[0] + self.build_volume[0] / 2.0,
            self.bed_min[1] + self.build_volume[1] / 2.0,
        ]
    }

    /// Checks every value; `key` is the dotted path used in messages.
    pub fn validate(&self, key: &str) -> Result<()> {
        for (i, v) in self.build_volume.iter().enumerate() {
            if !v.is_finite() || *v <= 0.0 {
                return Err(Error::invalid(
                    format!("{key}.build_volume[{i}]"),
                    format!("must be a positive number of mm (got {v})"),
                ));
            }
        }
        for (i, v) in self.bed_min.iter().enumerate() {
            if !v.is_finite() {
                return Err(Error::invalid(
                    format!("{key}.bed_min[{i}]"),
                    format!("must be a finite number of mm (got {v})"),
                ));
            }
        }
        for (i, v) in self.origin.iter().enumerate() {
            if !v.is_finite() {
                return Err(Error::invalid(
                    format!("{key}.origin[{i}]"),
                    format!("must be a finite number (got {v})"),
                ));
            }
        }
        positive(&format!("{key}.e_per_mm3"), self.e_per_mm3)?;
        if let Some(d) = self.bed_diameter {
            positive(&format!("{key}.bed_diameter"), d)?;
        }
        // Each rate and amount within what a clay printer can have, so no
        // number makes a summary, a time or a list run away.
        let k = |f: &str| format!("{key}.{f}");
        within(
            &k("travel_feedrate"),
            self.travel_feedrate,
            1.0,
            1e6,
            "mm/min",
        )?;
        within(
            &k("clay_density_g_ml"),
            self.clay_density_g_ml,
            0.5,
            5.0,
            "g/ml",
        )?;
        within(
            &k("acceleration_mm_s2"),
            self.acceleration_mm_s2,
            1.0,
            1e6,
            "mm/s²",
        )?;
        within(
            &k("junction_deviation_mm"),
            self.junction_deviation_mm,
            1e-4,
            10.0,
            "mm",
        )?;
        for i in 0..3 {
            within(
                &k(&format!("max_speed_mm_s[{i}]")),
                self.max_speed_mm_s[i],
                0.01,
                1e4,
                "mm/s",
            )?;
            within(
                &k(&format!("max_acceleration_mm_s2[{i}]")),
                self.max_acceleration_mm_s2[i],
                1.0,
                1e6,
                "mm/s²",
            )?;
        }
        if let Some(f) = self.max_flow_mm3_s {
            within(&k("max_flow_mm3_s"), f, 0.01, 1e6, "mm³/s")?;
        }
        if let Some(c) = self.cartridge_ml {
            // From a 1 ml syringe to a 100 l tank.
            within(&k("cartridge_ml"), c, 1.0, 100_000.0, "ml")?;
        }
        if let Some(d) = self.nozzle_diameter {
            if !(d.is_finite() && d > 0.0 && d <= 100.0) {
                return Err(Error::invalid(
                    format!("{key}.nozzle_diameter"),
                    format!("must be a bore from above 0 to 100 mm (got {d})"),
                ));
            }
        }
        if let Some(h) = &self.host {
            h.validate(&format!("{key}.host"))?;
        }
        if let Some(relative) = extrusion_mode(&self.start_gcode) {
            if relative != self.relative_e {
                let (kind, says) = if relative {
                    ("relative", "M83")
                } else {
                    ("absolute", "M82")
                };
                return Err(Error::invalid(
                    format!("{key}.start_gcode"),
                    format!(
                        "sets {kind} extrusion ({says}) but {key}.relative_e is {}: the G-code's own mode would cancel it; set \"relative_e\": {relative} or take {says} out of the start code",
                        self.relative_e
                    ),
                ));
            }
        }
        if !self.nozzle_radius.is_finite() || self.nozzle_radius < 0.0 {
            return Err(Error::invalid(
                format!("{key}.nozzle_radius"),
                format!("must be ≥ 0 mm (got {})", self.nozzle_radius),
            ));
        }
        // The checker's ranges (docs/CHECKER.md, "Bounded cost"): a
        // printer it would refuse to read is refused here, by name.
        let most = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for (field, v, hi) in [
            ("build_volume", most(&self.build_volume), MAX_MACHINE_MM),
            ("bed_min", most(&self.bed_min), MAX_MACHINE_MM),
            ("origin", most(&self.origin), MAX_MACHINE_MM),
            (
                "bed_diameter",
                self.bed_diameter.unwrap_or(0.0),
                MAX_MACHINE_MM,
            ),
            ("e_per_mm3", self.e_per_mm3, MAX_E_PER_MM3),
            ("nozzle_radius", self.nozzle_radius, MAX_NOZZLE_RADIUS_MM),
        ] {
            if v > hi {
                return Err(Error::invalid(
                    format!("{key}.{field}"),
                    format!("must be at most {hi} (got {v}): no clay printer is that large, and `check` would refuse to read its G-code"),
                ));
            }
        }
        Ok(())
    }
}

/// The largest machine dimension a printer may name (mm): 100 m, as
/// `check` reads a G-code header.
pub const MAX_MACHINE_MM: f64 = 100_000.0;

/// The most E per mm³ of clay a printer may name, as `check` reads it.
pub const MAX_E_PER_MM3: f64 = 10_000.0;

/// The widest extruder body a printer may name (radius, mm), as `check`
/// reads it: half a metre across, past the largest clay extruder made.
pub const MAX_NOZZLE_RADIUS_MM: f64 = 250.0;

/// The `printer` key: a preset name or an inline profile.
#[derive(Clone, Debug, PartialEq)]
pub enum PrinterRef {
    /// One of [`PRESETS`].
    Preset(String),
    /// An inline object; missing keys took the `generic` values (boxed:
    /// a profile is large beside a name).
    Inline(Box<Printer>),
}

impl Default for PrinterRef {
    fn default() -> Self {
        PrinterRef::Preset("generic".into())
    }
}

impl PrinterRef {
    /// The profile this reference names.
    pub fn resolve(&self) -> Result<Printer> {
        match self {
            PrinterRef::Preset(name) => Printer::preset(name).ok_or_else(|| {
                Error::invalid(
                    "printer",
                    format!("unknown preset `{name}` (known: {})", PRESETS.join(", ")),
                )
            }),
            PrinterRef::Inline(p) => {
                p.validate("printer")?;
                Ok((**p).clone())
            }
        }
    }
}

impl Serialize for PrinterRef {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        match self {
            PrinterRef::Preset(n) => s.serialize_str(n),
            PrinterRef::Inline(p) => p.serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for PrinterRef {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        use serde::de::Error as _;
        match serde_json::Value::deserialize(d)? {
            serde_json::Value::String(s) => Ok(PrinterRef::Preset(s)),
            v @ serde_json::Value::Object(_) => serde_json::from_value(v)
                .map(|p| PrinterRef::Inline(Box::new(p)))
                .map_err(|e| D::Error::custom(format!("printer: {e}"))),
            other => Err(D::Error::custom(format!(
                "printer: expected a preset name or an object, got {other}"
            ))),
        }
    }
}

/// `v` within `lo..=hi` (in `unit`), or an error naming `key`.
fn within(key: &str, v: f64, lo: f64, hi: f64, unit: &str) -> Result<()> {
    if v.is_finite() && (lo..=hi).contains(&v) {
        Ok(())
    } else {
        Err(Error::invalid(
            key,
            format!("must be from {lo} to {hi} {unit} (got {v})"),
        ))
    }
}

fn positive(key: &str, v: f64) -> Result<()> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(key, format!("must be > 0 (got {v})")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_printer_check_would_not_read_is_refused_by_name() {
        // A build volume of 1e6 mm sliced, and `check` then refused the
        // file (exit 2: header limit 100 m). One limit for both.
        let mut p = Printer::preset("generic").unwrap();
        p.build_volume[2] = 1e6;
        let e = p.validate("printer").unwrap_err().to_string();
        assert!(
            e.starts_with("printer.build_volume: must be at most 100000"),
            "{e}"
        );
        let mut p = Printer::preset("generic").unwrap();
        p.nozzle_radius = 2000.0;
        let e = p.validate("printer").unwrap_err().to_string();
        assert!(
            e.starts_with("printer.nozzle_radius: must be at most 250"),
            "{e}"
        );
        let d = crate::Design::from_json(
            r#"{"sweepclay":1,"profile_start":{"control_points":[[0,0],[0,20]]},
                "trajectory":{"control_points":[[-30,10],[30,10]]},
                "params":{"nozzle_height":1e308}}"#,
        )
        .unwrap();
        let e = d.params.validate().unwrap_err().to_string();
        assert!(
            e.starts_with("params.nozzle_height: must be at most 100000"),
            "{e}"
        );
        // What `check` reads, the pipeline writes: the largest allowed is
        // within the checker's range.
        assert_eq!(MAX_MACHINE_MM, sweepclay_check::MAX_MACHINE_MM);
    }

    #[test]
    fn presets_have_the_papers_build_volumes() {
        assert_eq!(
            Printer::preset("cerambot-plus").unwrap().build_volume,
            [180.0, 190.0, 200.0]
        );
        assert_eq!(
            Printer::preset("cerambot-mini").unwrap().build_volume,
            [120.0, 135.0, 100.0]
        );
        for name in PRESETS {
            assert!(preset_source(name).is_some(), "{name} has no source");
            Printer::preset(name).unwrap().validate("printer").unwrap();
        }
    }

    #[test]
    fn a_start_code_that_contradicts_the_extrusion_mode_is_refused() {
        assert_eq!(extrusion_mode("G28\nM83 ; relative\n"), Some(true));
        assert_eq!(extrusion_mode("m83\nM82\n"), Some(false));
        assert_eq!(extrusion_mode("G28 ; M83 in a comment\n"), None);
        let p = Printer {
            start_gcode: "G28\nM83\n".into(),
            ..Printer::default()
        };
        let e = p.validate("printer").unwrap_err().to_string();
        assert!(
            e.contains("printer.start_gcode") && e.contains("\"relative_e\": true"),
            "{e}"
        );
        let p = Printer {
            relative_e: true,
            ..p
        };
        p.validate("printer").unwrap();
        let p = Printer {
            start_gcode: "M82\n".into(),
            ..p
        };
        let e = p.validate("printer").unwrap_err().to_string();
        assert!(e.contains("\"relative_e\": false"), "{e}");
    }

    #[test]
    fn inline_printer_fills_missing_keys_from_generic() {
        let r: PrinterRef = serde_json::from_str(r#"{"name":"mine","e_per_mm3":0.2}"#).unwrap();
        let p = r.resolve().unwrap();
        assert_eq!(p.e_per_mm3, 0.2);
        assert_eq!(p.build_volume, Printer::default().build_volume);
    }

    #[test]
    fn unknown_preset_and_unknown_key_are_named() {
        let e = PrinterRef::Preset("prusa".into()).resolve().unwrap_err();
        assert!(e.to_string().contains("unknown preset `prusa`"), "{e}");
        let e = serde_json::from_str::<PrinterRef>(r#"{"nozle_radius":3}"#).unwrap_err();
        assert!(e.to_string().contains("nozle_radius"), "{e}");
    }

    #[test]
    fn bad_values_are_refused() {
        let p = Printer {
            e_per_mm3: -1.0,
            ..Printer::default()
        };
        let e = p.validate("printer").unwrap_err();
        assert!(e.to_string().starts_with("printer.e_per_mm3"), "{e}");
        for d in [0.0, -3.0, 101.0, f64::NAN] {
            let p = Printer {
                nozzle_diameter: Some(d),
                ..Printer::default()
            };
            let e = p.validate("printer").unwrap_err().to_string();
            assert!(
                e.starts_with("printer.nozzle_diameter") && e.contains("from above 0 to 100 mm"),
                "{e}"
            );
        }
        let p = Printer {
            nozzle_diameter: Some(3.0),
            ..Printer::default()
        };
        assert!(p.validate("printer").is_ok());
    }

    #[test]
    fn a_host_is_http_or_https_and_its_certificate_a_sha256() {
        let host = |url: &str, cert: Option<&str>| PrintHost {
            kind: HostKind::Octoprint,
            url: url.into(),
            cert_sha256: cert.map(str::to_string),
        };
        let fp = ["3F"; 32].join(":");
        assert!(host("http://octopi.local", None).validate("h").is_ok());
        assert!(host("https://octopi.local", Some(&fp))
            .validate("h")
            .is_ok());
        let e = host("ftp://octopi.local", None)
            .validate("h")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("h.url") && e.contains("https://"), "{e}");
        let e = host("https://octopi.local", Some("3F:A0"))
            .validate("h")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("h.cert_sha256") && e.contains("64 hex"),
            "{e}"
        );
        // Written only when there is one: older profiles read unchanged.
        let j = serde_json::to_string(&host("http://octopi.local", None)).unwrap();
        assert!(!j.contains("cert_sha256"), "{j}");
    }
}
