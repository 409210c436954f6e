//! The design file (docs/FORMATS.md, format version 1): two profile curves, a
//! trajectory, an optional interpolation curve, parameters and a printer.
//!
//! Parsing rejects unknown keys (typos are caught) and reports the line and
//! column; [`Params::validate`] checks ranges and names the key.

use crate::error::{Error, Result};
use crate::printer::PrinterRef;
use serde::{Deserialize, Serialize};

/// The format version this library reads and writes.
pub const FORMAT_VERSION: u32 = 1;

/// One design file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Design {
    /// Format version; must be [`FORMAT_VERSION`].
    pub sweepclay: u32,
    /// Free-form name, written into the G-code header.
    #[serde(default)]
    pub name: String,
    /// C_s: profile at the start of the trajectory, points `[x, z]`.
    pub profile_start: CurveSpec,
    /// C_t: profile at the end of the trajectory, points `[x, z]`; left
    /// out, the start profile (a pot with one profile: [`Design::end_profile`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profile_end: Option<CurveSpec>,
    /// Ψ: the trajectory in the xy plane, relative to the centre `o`.
    pub trajectory: TrajectorySpec,
    /// Control curve of f(u), points `[u, f]`; omitted means linear.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub interpolation: Option<CurveSpec>,
    /// Slicing parameters; every key optional.
    #[serde(default)]
    pub params: Params,
    /// Printer preset name or inline profile; default `generic`.
    #[serde(default)]
    pub printer: PrinterRef,
    /// Textures added to the surface, kept where the clay allows
    /// (docs/FORMATS.md, docs/ALGORITHMS.md §11).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub texture: Vec<crate::texture::TextureSpec>,
    /// The cross-section turns about o by this angle from base to top
    /// (degrees; positive counter-clockwise seen from above).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub twist_deg: f64,
    /// A vessel's rim shaped round the loop from its one profile (a
    /// slant, waves, a raised arc), in place of `profile_end` and
    /// `interpolation` (docs/FORMATS.md, "rim").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rim: Option<crate::rim::RimSpec>,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// How far a profile's row (`points`) may lie from its curve (mm): the
/// modeler writes the curve through them to 3 decimals.
pub const ON_CURVE_MM: f64 = 0.05;

/// A curve given by the control points of a clamped B-spline.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CurveSpec {
    /// Control points; 2 give a segment, 3 a quadratic, 4 or more a cubic.
    pub control_points: Vec<[f64; 2]>,
    /// A profile's rows as a potter typed them, `[x, z]`: points the
    /// curve passes through (the modeler's widths at heights). Checked:
    /// each must lie on the curve within [`ON_CURVE_MM`]
    /// (docs/FORMATS.md). Omitted: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points: Option<Vec<[f64; 2]>>,
}

/// The trajectory: a B-spline or an imported polyline.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrajectorySpec {
    /// Control points of a clamped B-spline, `[x, y]` in mm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub control_points: Option<Vec<[f64; 2]>>,
    /// Or: the vertices of a polyline (e.g. from an SVG import).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points: Option<Vec<[f64; 2]>>,
    /// Ψ is a loop: a vessel with a floor and a spiral wall
    /// (docs/ALGORITHMS.md §8). A B-spline's control polygon then wraps
    /// round; a polyline closes from its last point to its first.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub closed: bool,
    /// The frame of the profiles' horizontal offset (default radial).
    #[serde(default, skip_serializing_if = "Offset::is_radial")]
    pub offset: Offset,
}

/// The direction in which a profile's horizontal offset x moves a point
/// of Ψ (docs/ALGORITHMS.md §2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Offset {
    /// Away from the centre `o`, d_i = (p_i − o)/|p_i − o| (the paper's
    /// revolution about the z axis): Ψ must keep 1 mm from `o`.
    #[default]
    Radial,
    /// Perpendicular to Ψ in the plane, to the left of the direction of
    /// travel: what a wall drawn anywhere, also through `o`, needs.
    Normal,
}

impl TrajectorySpec {
    /// The points as given: the control points of a B-spline or the
    /// vertices of a polyline (none when neither is given).
    pub fn given_points(&self) -> &[[f64; 2]] {
        self.control_points
            .as_deref()
            .or(self.points.as_deref())
            .unwrap_or(&[])
    }
}

impl Offset {
    /// Whether this is the default, radial frame.
    pub fn is_radial(&self) -> bool {
        *self == Offset::Radial
    }
}

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

fn range(key: &str, v: f64, lo: f64, hi: f64) -> Result<()> {
    if v.is_finite() && v >= lo && v <= hi {
        Ok(())
    } else {
        Err(Error::invalid(
            key,
            format!("must be between {lo} and {hi} (got {v})"),
        ))
    }
}

impl Design {
    /// Parses a design file. Unknown keys, wrong types and a wrong format
    /// version are errors naming the line.
    pub fn from_json(text: &str) -> Result<Design> {
        let de = &mut serde_json::Deserializer::from_str(text);
        let d: Design = serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner();
            let message = inner
                .to_string()
                .split(" at line ")
                .next()
                .unwrap_or("")
                .to_string();
            // A value of the wrong type or range names its key, so the
            // modeler can outline that field ("params.floor_layers:
            // invalid value: integer `-1`, expected u32").
            // An unknown key names itself, and is no field to outline.
            let known = !message.starts_with("unknown field");
            if inner.classify() == serde_json::error::Category::Data && path != "." && known {
                Error::invalid(
                    path,
                    format!(
                        "{message} (line {}, column {})",
                        inner.line(),
                        inner.column()
                    ),
                )
            } else {
                Error::Parse {
                    // An unknown key says where it sits ("texture[0].colour:
                    // unknown field `colour`"): a line of a one-line
                    // file the page sent says nothing.
                    message: if known || path == "." {
                        message
                    } else {
                        format!("{path}: {message}")
                    },
                    line: inner.line(),
                    column: inner.column(),
                }
            }
        })?;
        if d.sweepclay != FORMAT_VERSION {
            return Err(Error::invalid(
                "sweepclay",
                format!(
                    "format version {} is not supported (this build reads {FORMAT_VERSION})",
                    d.sweepclay
                ),
            ));
        }
        let chars = d.name.chars().count();
        if chars > MAX_NAME_CHARS {
            return Err(Error::invalid(
                "name",
                format!("is {chars} characters long; at most {MAX_NAME_CHARS} (it names the G-code file and heads it)"),
            ));
        }
        if let Some(r) = &d.rim {
            r.check(
                d.trajectory.closed,
                d.profile_end.is_some(),
                d.interpolation.is_some(),
            )?;
        }
        let mut d = d;
        // The cap and each entry's keys before any picture is decoded: a
        // ripple carrying a 4-megapixel PNG, 400 times over, ran a server
        // out of memory before the cap of 16 was looked at.
        if d.texture.len() > crate::texture::MAX_TEXTURES {
            return Err(Error::invalid(
                "texture",
                format!(
                    "has {} entries; at most {}",
                    d.texture.len(),
                    crate::texture::MAX_TEXTURES
                ),
            ));
        }
        for (k, t) in d.texture.iter().enumerate() {
            t.check_keys(&format!("texture[{k}]"))?;
        }
        let mut budget = crate::texture::MAX_DESIGN_PIXELS;
        for (k, t) in d.texture.iter_mut().enumerate() {
            t.load(&format!("texture[{k}]"), &mut budget)?;
        }
        Ok(d)
    }

    /// Reads the images the textures name by `path` with `read` (the
    /// path as written; the caller resolves it against the design's
    /// folder), decoding each; the error names the texture.
    pub fn load_images(
        &mut self,
        mut read: impl FnMut(&str) -> std::result::Result<Vec<u8>, String>,
    ) -> Result<()> {
        // What the pictures decoded with the design file left.
        let used: usize = self
            .texture
            .iter()
            .filter_map(|t| t.image.as_ref())
            .map(|g| g.width * g.height)
            .sum();
        let mut budget = crate::texture::MAX_DESIGN_PIXELS.saturating_sub(used);
        for (k, t) in self.texture.iter_mut().enumerate() {
            if t.image.is_some() || t.kind != crate::texture::Kind::Image {
                continue;
            }
            if let Some(path) = &t.path {
                let key = format!("texture[{k}].path");
                let bytes = read(path).map_err(|e| Error::invalid(&key, e))?;
                t.image = Some(crate::texture::Grey::from_png_within(
                    &bytes,
                    &key,
                    &mut budget,
                )?);
            }
        }
        Ok(())
    }

    /// The piece as printed: the geometry enlarged by 1 / (1 − s) across
    /// (profiles' offsets, Ψ) and in height (profiles' z) for the firing
    /// shrinkages `params.shrinkage_xy` and `shrinkage_z`, so that it has
    /// the designed size after the kiln (docs/ALGORITHMS.md §6). Layer
    /// heights, bead widths and the printer are not scaled: they are the
    /// process, not the piece. Without shrinkage, the design itself.
    pub fn printed(&self) -> Design {
        let mut d = self.scaled_for_firing();
        d.params = d.texture_params();
        d
    }

    /// The sampling the textures ask for: the spacing and the thickest
    /// layer that give each texture 8 samples a period (never under the
    /// thinnest layer [`Params::validate`] allows; [`Design::check_texture`]
    /// refuses a texture that would need less).
    pub(crate) fn texture_params(&self) -> Params {
        let mut p = self.params.clone();
        if self.texture.is_empty() {
            return p;
        }
        let length = crate::trajectory_length(self);
        let [along, up] = crate::texture::needs(&self.texture, length, self.trajectory.closed);
        if let Some((s, _)) = along.filter(|(s, _)| s.is_finite() && *s > 0.0) {
            p.spacing = p.spacing.min(s.max(MIN_SPACING));
        }
        if let Some((z, _)) = up.filter(|(z, _)| z.is_finite()) {
            p.max_layer_height = p.max_layer_height.min(z.max(MIN_LAYER));
            // Room below it, so a column's height splits into whole layers.
            p.layer_height = p
                .layer_height
                .min((0.6 * p.max_layer_height).max(MIN_LAYER))
                .min(p.max_layer_height);
        }
        p
    }

    /// Checks the textures and the twist, and refuses a texture whose
    /// period is too short to sample (it would need layers thinner than
    /// [`MIN_LAYER`] or a spacing under [`MIN_SPACING`]), naming it.
    pub fn check_texture(&self) -> Result<()> {
        crate::texture::validate(&self.texture, self.twist_deg, self.trajectory.closed)?;
        if self.texture.is_empty() {
            return Ok(());
        }
        let d = self.scaled_for_firing();
        let length = crate::trajectory_length(&d);
        let [along, up] = crate::texture::needs(&d.texture, length, d.trajectory.closed);
        if let Some((z, k)) = up.filter(|(z, _)| *z < MIN_LAYER) {
            return Err(Error::invalid(
                format!("texture[{k}]"),
                format!(
                    "needs layers of {z:.2} mm to show ({} samples a period in height), thinner than the thinnest layer ({MIN_LAYER} mm); make its period (or pitch) at least {} mm",
                    crate::texture::SAMPLES_PER_PERIOD,
                    MIN_LAYER * crate::texture::SAMPLES_PER_PERIOD
                ),
            ));
        }
        if let Some((s, k)) = along.filter(|(s, _)| *s < MIN_SPACING) {
            return Err(Error::invalid(
                format!("texture[{k}]"),
                format!(
                    "needs samples {s:.3} mm apart along the trajectory to show, closer than {MIN_SPACING} mm; use fewer ribs"
                ),
            ));
        }
        Ok(())
    }

    /// The design enlarged for the firing shrinkage, textures included.
    fn scaled_for_firing(&self) -> Design {
        let mut d = self.clone();
        let [kxy, kz] = self.params.print_scale();
        if kxy == 1.0 && kz == 1.0 {
            return d;
        }
        for c in std::iter::once(&mut d.profile_start).chain(d.profile_end.as_mut()) {
            // A scaled curve passes through its scaled rows (affine
            // invariance).
            for p in c
                .control_points
                .iter_mut()
                .chain(c.points.iter_mut().flatten())
            {
                *p = [p[0] * kxy, p[1] * kz];
            }
        }
        d.texture = self.texture.iter().map(|t| t.scaled(kxy, kz)).collect();
        if let Some(r) = d.rim.as_mut() {
            r.rise *= kz;
        }
        let t = &mut d.trajectory;
        for pts in [t.control_points.as_mut(), t.points.as_mut()]
            .into_iter()
            .flatten()
        {
            for p in pts.iter_mut() {
                *p = [p[0] * kxy, p[1] * kxy];
            }
        }
        d
    }

    /// C_t: `profile_end`, or `profile_start` where the design gives one
    /// profile (the same section all round the loop or along the wall),
    /// stretched to the taller rim where the design shapes its `rim`.
    pub fn end_profile(&self) -> std::borrow::Cow<'_, CurveSpec> {
        match (&self.profile_end, &self.rim) {
            (Some(end), _) => std::borrow::Cow::Borrowed(end),
            // Stretched, the start profile's rows are no longer on it.
            (None, Some(rim)) => std::borrow::Cow::Owned(CurveSpec {
                control_points: rim.stretched(&self.profile_start.control_points),
                points: None,
            }),
            (None, None) => std::borrow::Cow::Borrowed(&self.profile_start),
        }
    }

    /// The design as pretty JSON (the format [`Design::from_json`] reads).
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a design always serialises")
    }

    /// Refuses, before anything is sampled, a design that cannot fit its
    /// printer: the surface starts and ends at Ψ's first and last points
    /// on the bed and is as tall there as the profiles, so if those leave
    /// the build volume the whole does ([`Error::DoesNotFit`], as slicing
    /// would say). A closed B-spline Ψ does not pass through its control
    /// points, so for a closed Ψ only the height is checked here (slicing
    /// checks the rest). [`crate::check_size`] adds the cap on work.
    pub fn check_fit(&self) -> crate::Result<()> {
        let printed = self.printed();
        let this = &printed;
        let pr = self.printer.resolve()?;
        let t = &this.trajectory;
        let pts = t.given_points();
        let top = |c: &CurveSpec| c.control_points.last().map_or(0.0, |p| p[1]);
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let ends = pts
            .first()
            .into_iter()
            .chain(pts.last())
            .filter(|_| !t.closed);
        for p in ends {
            for a in 0..2 {
                lo[a] = lo[a].min(pr.origin[a] + p[a]);
                hi[a] = hi[a].max(pr.origin[a] + p[a]);
            }
        }
        lo[2] = 0.0;
        hi[2] = top(&this.profile_start).max(top(&this.end_profile()));
        for a in 0..3 {
            let (min, max) = (pr.bed_min[a], pr.bed_min[a] + pr.build_volume[a]);
            if lo[a] < min - 1e-9 || hi[a] > max + 1e-9 {
                return Err(Error::DoesNotFit {
                    printer: pr.name.clone(),
                    axis: ['x', 'y', 'z'][a],
                    min: lo[a],
                    max: hi[a],
                    low: min,
                    limit: max,
                });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_unknown_key_says_where_it_sits() {
        let mut v: serde_json::Value =
            serde_json::from_str(crate::examples::example("cup").unwrap()).unwrap();
        v["texture"] =
            serde_json::json!([{ "kind": "ripple", "amplitude": 1, "period": 8, "colour": 1 }]);
        let e = Design::from_json(&v.to_string()).unwrap_err().to_string();
        assert!(
            e.contains("texture[0].colour: unknown field `colour`"),
            "{e}"
        );
        v["texture"] = serde_json::json!([]);
        v["colour"] = serde_json::json!(1);
        let e = Design::from_json(&v.to_string()).unwrap_err().to_string();
        assert!(
            e.contains("line 1 column") && e.contains("colour: unknown field `colour`"),
            "{e}"
        );
    }

    const MINIMAL: &str = r#"{
        "sweepclay": 1,
        "profile_start": { "control_points": [[0, 0], [0, 20]] },
        "profile_end": { "control_points": [[0, 0], [0, 20]] },
        "trajectory": { "control_points": [[-50, 10], [50, 10]] }
    }"#;

    #[test]
    fn sample_estimate_bounds_the_real_count() {
        for (name, text) in crate::examples::EXAMPLES {
            let d = Design::from_json(text).unwrap();
            // Path points: the surface's samples and a vessel's floor.
            let real = crate::slice(&d).unwrap().toolpath.points.len() as f64;
            let est = crate::estimated_samples(&d);
            assert!((est / real - 1.0).abs() < 0.2, "{name}: {est} vs {real}");
            assert!(crate::samples_bound(&d) >= real, "{name}");
        }
        // A wall of about a million samples (once estimated at 2.2 M and
        // refused by the default cap of 1.5 M).
        let mut d = Design::from_json(crate::examples::example("t1").unwrap()).unwrap();
        d.params.spacing = 0.02;
        let real = crate::slice(&d).unwrap().toolpath.points.len() as f64;
        let est = crate::estimated_samples(&d);
        assert!(
            real > 0.9e6 && (est / real - 1.0).abs() < 0.2,
            "{est} vs {real}"
        );
    }

    #[test]
    fn a_parameter_out_of_range_is_named_before_any_size_estimate() {
        let mut d = Design::from_json(MINIMAL).unwrap();
        d.params.layer_height = 0.0;
        let e = crate::check_size(&d, 1e6).unwrap_err().to_string();
        assert!(e.starts_with("params.layer_height"), "{e}");
    }

    #[test]
    fn a_closed_spline_is_not_sized_by_its_control_points() {
        // A periodic B-spline over a square's corners (±40 mm) runs inside
        // ±27 mm: it fits a 70 mm bed its corners leave. The same points
        // as an open spline start and end outside it.
        let text = |closed: bool| {
            format!(
                r#"{{"sweepclay": 1,
                "profile_start": {{ "control_points": [[0, 0], [0, 20]] }},
                "profile_end": {{ "control_points": [[0, 0], [0, 20]] }},
                "trajectory": {{ "control_points": [[40, 40], [-40, 40], [-40, -40], [40, -40]], "closed": {closed} }},
                "printer": {{ "name": "small", "build_volume": [70, 70, 70], "origin": [35, 35] }}}}"#
            )
        };
        let closed = Design::from_json(&text(true)).unwrap();
        crate::check_size(&closed, 1e6).unwrap();
        let open = Design::from_json(&text(false)).unwrap();
        assert!(matches!(
            crate::check_size(&open, 1e6),
            Err(Error::DoesNotFit { .. })
        ));
    }

    #[test]
    fn minimal_design_takes_defaults() {
        let d = Design::from_json(MINIMAL).unwrap();
        assert_eq!(d.params, Params::default());
        assert_eq!(d.printer, PrinterRef::default());
        assert!(d.interpolation.is_none());
        d.params.validate().unwrap();
    }

    #[test]
    fn a_pot_with_one_profile_is_the_same_pot_with_two() {
        let one = r#"{"sweepclay": 1,
            "profile_start": { "control_points": [[0, 0], [8, 20], [2, 40]] },
            "trajectory": { "control_points": [[40, 0], [0, 40], [-40, 0], [0, -40]], "closed": true }}"#;
        let d = Design::from_json(one).unwrap();
        assert_eq!(*d.end_profile(), d.profile_start);
        // Saved as it was given: one profile stays one profile.
        assert!(!d.to_json().contains("profile_end"));
        assert_eq!(Design::from_json(&d.to_json()).unwrap(), d);
        let mut two = d.clone();
        two.profile_end = Some(d.profile_start.clone());
        let (a, b) = (crate::slice(&d).unwrap(), crate::slice(&two).unwrap());
        assert_eq!(a.toolpath, b.toolpath);
        assert_eq!(a.extrusion, b.extrusion);
    }

    #[test]
    fn round_trips_through_json() {
        let d = Design::from_json(MINIMAL).unwrap();
        assert_eq!(Design::from_json(&d.to_json()).unwrap(), d);
    }

    #[test]
    fn a_value_of_the_wrong_type_names_its_key() {
        // Floor layers −1 or 2.5 named only "line 1 column 377": the
        // modeler could outline no field.
        for bad in ["-1", "2.5", "\"two\""] {
            let text = MINIMAL.replace(
                "\"trajectory\": {",
                &format!("\"params\": {{\"floor_layers\": {bad}}}, \"trajectory\": {{"),
            );
            match Design::from_json(&text).unwrap_err() {
                Error::Invalid { key, reason } => {
                    assert_eq!(key, "params.floor_layers", "{reason}");
                    assert!(reason.contains("line"), "{reason}");
                }
                e => panic!("unexpected {e}"),
            }
        }
    }

    #[test]
    fn unknown_key_names_key_and_line() {
        let text = MINIMAL.replace("\"sweepclay\": 1,", "\"sweepclay\": 1, \"profil_end\": 3,");
        match Design::from_json(&text).unwrap_err() {
            Error::Parse { message, line, .. } => {
                assert!(message.contains("profil_end"), "{message}");
                assert_eq!(line, 2);
            }
            e => panic!("unexpected {e}"),
        }
        let text = MINIMAL.replace(
            "\"trajectory\": {",
            "\"params\": {\"layer_hieght\": 1}, \"trajectory\": {",
        );
        let e = Design::from_json(&text).unwrap_err().to_string();
        assert!(e.contains("layer_hieght"), "{e}");
    }

    #[test]
    fn wrong_version_is_refused() {
        let e = Design::from_json(&MINIMAL.replace("\"sweepclay\": 1", "\"sweepclay\": 2"))
            .unwrap_err();
        assert!(
            e.to_string().starts_with("sweepclay: format version 2"),
            "{e}"
        );
    }

    #[test]
    fn parameter_ranges_name_the_key() {
        let mut p = Params::default();
        p.set("layer_height", -1.0).unwrap();
        let e = p.validate().unwrap_err().to_string();
        assert!(
            e.starts_with("params.layer_height") && e.contains("-1"),
            "{e}"
        );
        let mut p = Params::default();
        p.set("width_max", 2.0).unwrap();
        assert!(p
            .validate()
            .unwrap_err()
            .to_string()
            .starts_with("params.width_max"));
        let mut p = Params::default();
        p.set("nozzle_height", 3.0).unwrap();
        assert!(p
            .validate()
            .unwrap_err()
            .to_string()
            .starts_with("params.nozzle_height"));
        assert!(Params::default().set("feed", 1.0).is_err());
    }

    #[test]
    fn max_offset_is_the_papers_bound() {
        let p = Params::default();
        // 1.25 · tan 57° = 1.925 < 6 · (1 − 2/3) = 2.
        assert!((p.max_offset(1.25) - 1.25 * 57f64.to_radians().tan()).abs() < 1e-12);
        assert!(
            (p.max_offset(2.5) - 2.0).abs() < 1e-12,
            "{}",
            p.max_offset(2.5)
        );
    }
}
