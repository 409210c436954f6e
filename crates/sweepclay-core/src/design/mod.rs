//! The design file (docs/FORMATS.md, format version 1): two profile curves, a
//! trajectory, an optional interpolation curve, parameters and a printer.
//!
//! Parsing rejects unknown keys (typos are caught) and reports the line and
//! column; [`Params::validate`] checks ranges and names the key.

use crate::error::{Error, Result};
use crate::printer::PrinterRef;
use serde::{Deserialize, Serialize};

mod params;
mod printed;

pub use params::*;

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
    /// What a mesh has beyond the closest sweep, added to the profiles'
    /// blend round a vessel's loop (docs/FORMATS.md, "relief";
    /// docs/MESHES.md).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub relief: Option<crate::relief::Relief>,
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
        if let Some(r) = &d.relief {
            r.validate(d.trajectory.closed)?;
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

    /// C_t: `profile_end`, or `profile_start` where the design gives one
    /// profile (the same section all round the loop or along the wall),
    /// stretched to the taller rim where the design shapes its `rim` (for
    /// the columns' heights; their shape is `surface::continued`).
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
    /// A relief's table is written a row a line: one number a line made
    /// a mesh's design three times as long (1.3 MB for 241 × 360).
    pub fn to_json(&self) -> String {
        let pretty =
            |d: &Design| serde_json::to_string_pretty(d).expect("a design always serialises");
        let Some(relief) = &self.relief else {
            return pretty(self);
        };
        let plain = Design {
            relief: None,
            ..self.clone()
        };
        let mut s = pretty(&plain);
        // The object's closing brace, to go on after the relief.
        debug_assert!(s.ends_with("\n}"));
        s.truncate(s.len() - 2);
        let line = |v: &[f64]| serde_json::to_string(v).expect("numbers serialise");
        let rows: Vec<String> = relief.offsets.iter().map(|r| line(r)).collect();
        s.push_str(&format!(
            ",\n  \"relief\": {{\n    \"z\": {},\n    \"u\": {},\n    \"offsets\": [\n      {}\n    ]\n  }}\n}}",
            line(&relief.z),
            line(&relief.u),
            rows.join(",\n      ")
        ));
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_design_scaled_and_turned_prints_that_size_and_side() {
        // A cup with its rim cut 10 mm higher toward 150°.
        let mut v: serde_json::Value =
            serde_json::from_str(crate::examples::example("cup").unwrap()).unwrap();
        let o = v.as_object_mut().unwrap();
        o.remove("profile_end");
        o.remove("interpolation");
        v["rim"] = serde_json::json!({ "shape": "slant", "rise": 10, "toward_deg": 150 });
        let d = Design::from_json(&v.to_string()).unwrap();
        let a = crate::slice(&d).unwrap().stats.size_mm;
        let t = d.transformed(0.5, 90.0).unwrap();
        let b = crate::slice(&t).unwrap().stats.size_mm;
        // Half as large; a quarter turn swaps its width and depth (the
        // beads keep their width: the sizes halve within a bead).
        let w = d.params.width_max;
        assert!((b[0] - 0.5 * a[1]).abs() < w, "{a:?} {b:?}");
        assert!((b[1] - 0.5 * a[0]).abs() < w, "{a:?} {b:?}");
        assert!((b[2] - 0.5 * a[2]).abs() < 1.5, "{a:?} {b:?}");
        // 150° + 90° is −120°.
        assert_eq!(t.rim.as_ref().unwrap().toward_deg, -120.0);
        let e = d.transformed(0.0, 0.0).unwrap_err().to_string();
        assert!(e.starts_with("scale:"), "{e}");
        let e = d.transformed(1.0, 720.0).unwrap_err().to_string();
        assert!(e.starts_with("turn:"), "{e}");
    }

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
