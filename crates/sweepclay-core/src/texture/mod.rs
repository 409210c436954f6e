//! Textures and twist (not in the paper; docs/ALGORITHMS.md §11).
//!
//! A texture displaces the surface along each column's offset direction:
//! ξ'(i, z) = ξ(i, z) + a(i, z) · D(i, z), with D the sum of the design's
//! textures (ripple, flute, spiral, image), each times its fade envelope.
//! Sampling (`surface/`) stores D per sample, its spacing and layer
//! heights refined so each texture gets at least [`SAMPLES_PER_PERIOD`]
//! samples a period ([`needs`], which `Design::printed` applies). The
//! corrections (`keep_texture` in `correct/texture.rs`) then choose the amount
//! kept, a ∈ [0, 1] per sample: 1 wherever the step from the bead below
//! stays within the support-free and overlap limit, less only where it
//! would not, and never more than [`MAX_A_STEP`] apart between
//! neighbouring samples, so a texture fades out smoothly where the clay
//! cannot hold it and every place where it does is reported.
//!
//! Twist turns each cross-section about o by `twist_deg · t` (t = z / h
//! of the column): `Column::point` (`surface/mod.rs`) applies it.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};

mod image;
mod report;

pub use image::*;
pub use report::*;

/// Samples a texture gets per period, along Ψ and in height (fewer
/// cannot show a sine as one).
pub const SAMPLES_PER_PERIOD: f64 = 8.0;

/// Most the amount kept changes between neighbouring samples.
pub const MAX_A_STEP: f64 = 0.2;

/// Most textures a design may carry.
pub const MAX_TEXTURES: usize = 16;

/// Largest image a texture may use (pixels).
pub const MAX_IMAGE_PIXELS: usize = 4_000_000;

/// Largest image file, encoded (bytes).
pub const MAX_IMAGE_BYTES: usize = 8 << 20;

/// Most pixels a design's pictures may decode to in all: two pictures of
/// [`MAX_IMAGE_PIXELS`] (32 MB of grey). Sixteen textures of 4 megapixels
/// each, from 566-byte files, held 256 MB a request.
pub const MAX_DESIGN_PIXELS: usize = 2 * MAX_IMAGE_PIXELS;

/// The kinds of texture.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    /// Horizontal rings: sin(2π z / period).
    Ripple,
    /// Vertical ribs: sin(2π n u), n = `count` (or Ψ's length / `period`).
    Flute,
    /// Ribs whose phase turns with height: sin(2π (n u + z / pitch)).
    Spiral,
    /// A greyscale picture over (u, t): 2 v − 1 for its grey value v.
    Image,
}

impl Kind {
    /// The name in the design file.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Ripple => "ripple",
            Kind::Flute => "flute",
            Kind::Spiral => "spiral",
            Kind::Image => "image",
        }
    }
}

/// One entry of the design's `texture` list (docs/FORMATS.md).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TextureSpec {
    /// Which texture.
    pub kind: Kind,
    /// Peak displacement along the offset direction (mm); positive
    /// pushes outward at the sine's crests.
    pub amplitude: f64,
    /// Ripple: period in height (mm). Flute: period along Ψ (mm), instead
    /// of `count`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub period: Option<f64>,
    /// Flute and spiral: ribs along Ψ (whole round a loop).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub count: Option<f64>,
    /// Spiral: height (mm) over which the ribs move on by one rib.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pitch: Option<f64>,
    /// Spiral, instead of `pitch`: how fast the ribs turn round o
    /// (degrees per mm of height; Ψ's length stands for 360°).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub deg_per_mm: Option<f64>,
    /// Image: a PNG file, relative to the design file (the CLI reads it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub path: Option<String>,
    /// Image: the PNG itself, base64 (what the modeler saves).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub png_base64: Option<String>,
    /// Rise from nothing over the first this many mm of height.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub fade_in: f64,
    /// Fall to nothing over the last this many mm below the rim.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub fade_out: f64,
    /// Ripple, flute and spiral: where the sine starts (degrees, added to
    /// its angle: 90 makes it a cosine). A mesh's ribs or rings fitted
    /// back lie wherever they lie (docs/MESHES.md, "Textures").
    #[serde(default, skip_serializing_if = "is_zero")]
    pub phase_deg: f64,
    /// The decoded image (grey values), filled by [`TextureSpec::load`]
    /// from `png_base64` or by the CLI from `path`.
    #[serde(skip)]
    pub image: Option<Grey>,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

impl TextureSpec {
    /// Checks the entry; `key` is `texture[k]` in messages.
    pub fn validate(&self, key: &str, closed: bool) -> Result<()> {
        let finite = |name: &str, v: f64, lo: f64, hi: f64| -> Result<()> {
            if v.is_finite() && v >= lo && v <= hi {
                Ok(())
            } else {
                Err(Error::invalid(
                    format!("{key}.{name}"),
                    format!("must be between {lo} and {hi} (got {v})"),
                ))
            }
        };
        finite("amplitude", self.amplitude, -50.0, 50.0)?;
        finite("fade_in", self.fade_in, 0.0, 10_000.0)?;
        finite("fade_out", self.fade_out, 0.0, 10_000.0)?;
        finite("phase_deg", self.phase_deg, -360.0, 360.0)?;
        let need = |name: &str, v: Option<f64>| -> Result<f64> {
            v.ok_or_else(|| Error::invalid(key, format!("a {} needs `{name}`", self.kind.name())))
        };
        match self.kind {
            Kind::Ripple => finite("period", need("period", self.period)?, 0.1, 10_000.0)?,
            Kind::Flute | Kind::Spiral => {
                match (self.count, self.period) {
                    (Some(n), None) => {
                        finite("count", n, 1.0, 10_000.0)?;
                        if closed && n.fract() != 0.0 {
                            return Err(Error::invalid(
                                format!("{key}.count"),
                                format!("must be whole round a closed trajectory, so the ribs meet at the seam (got {n})"),
                            ));
                        }
                    }
                    (None, Some(p)) if self.kind == Kind::Flute => {
                        finite("period", p, 0.1, 100_000.0)?
                    }
                    _ => {
                        return Err(Error::invalid(
                            key,
                            format!(
                                "a {} needs `count`{}",
                                self.kind.name(),
                                if self.kind == Kind::Flute {
                                    " or `period` (not both)"
                                } else {
                                    ""
                                }
                            ),
                        ))
                    }
                }
                if self.kind == Kind::Spiral {
                    match (self.pitch, self.deg_per_mm) {
                        (Some(p), None) => finite("pitch", p.abs(), 0.1, 100_000.0)?,
                        (None, Some(d)) => finite("deg_per_mm", d.abs(), 1e-6, 360.0)?,
                        _ => {
                            return Err(Error::invalid(
                                key,
                                "a spiral needs `pitch` (mm) or `deg_per_mm` (not both)",
                            ))
                        }
                    }
                }
            }
            Kind::Image => {
                if self.image.is_none() {
                    return Err(Error::invalid(
                        key,
                        if self.path.is_some() {
                            "the image at `path` was not read (the CLI reads it; elsewhere give `png_base64`)"
                        } else {
                            "an image needs `png_base64` or `path` (a PNG)"
                        },
                    ));
                }
            }
        }
        Ok(())
    }

    /// Refuses, by name, a key this kind of texture does not read
    /// (`count` on a ripple, a picture on a flute): it was ignored, and a
    /// picture on any kind was decoded.
    pub fn check_keys(&self, key: &str) -> Result<()> {
        let given = [
            ("period", self.period.is_some()),
            ("count", self.count.is_some()),
            ("pitch", self.pitch.is_some()),
            ("deg_per_mm", self.deg_per_mm.is_some()),
            ("path", self.path.is_some()),
            ("png_base64", self.png_base64.is_some()),
            ("phase_deg", self.phase_deg != 0.0),
        ];
        let reads: &[&str] = match self.kind {
            Kind::Ripple => &["period", "phase_deg"],
            Kind::Flute => &["count", "period", "phase_deg"],
            Kind::Spiral => &["count", "pitch", "deg_per_mm", "phase_deg"],
            Kind::Image => &["path", "png_base64"],
        };
        match given
            .iter()
            .find(|(name, set)| *set && !reads.contains(name))
        {
            Some((name, _)) => Err(Error::invalid(
                format!("{key}.{name}"),
                format!(
                    "a {} texture does not read `{name}` (it reads {})",
                    self.kind.name(),
                    reads
                        .iter()
                        .map(|r| format!("`{r}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            )),
            None => Ok(()),
        }
    }

    /// Decodes `png_base64` into [`TextureSpec::image`] (if given and not
    /// yet decoded), its pixels counted against `budget`
    /// ([`Grey::from_png_within`]).
    pub fn load(&mut self, key: &str, budget: &mut usize) -> Result<()> {
        use base64::Engine as _;
        if self.image.is_some() {
            return Ok(());
        }
        let Some(b64) = &self.png_base64 else {
            return Ok(());
        };
        // 4/3 of the byte cap, and the data-URL prefix the page may send.
        if b64.len() > MAX_IMAGE_BYTES / 3 * 4 + 64 {
            return Err(Error::invalid(
                format!("{key}.png_base64"),
                format!("the image is over the cap of {MAX_IMAGE_BYTES} bytes"),
            ));
        }
        let data = b64.rsplit(',').next().unwrap_or("");
        let bytes = base64::engine::general_purpose::STANDARD
            .decode(data.trim())
            .map_err(|e| Error::invalid(format!("{key}.png_base64"), format!("not base64: {e}")))?;
        self.image = Some(Grey::from_png_within(
            &bytes,
            &format!("{key}.png_base64"),
            budget,
        )?);
        Ok(())
    }

    /// Short words for reports: "ripple 2 mm".
    pub fn label(&self) -> String {
        format!("{} {} mm", self.kind.name(), fmt_mm(self.amplitude.abs()))
    }

    /// The entry with lengths scaled for firing shrinkage (`kxy` across,
    /// `kz` in height).
    pub fn scaled(&self, kxy: f64, kz: f64) -> TextureSpec {
        TextureSpec {
            amplitude: self.amplitude * kxy,
            period: self.period.map(|p| {
                if self.kind == Kind::Ripple {
                    p * kz
                } else {
                    p * kxy
                }
            }),
            pitch: self.pitch.map(|p| p * kz),
            deg_per_mm: self.deg_per_mm.map(|d| d / kz),
            fade_in: self.fade_in * kz,
            fade_out: self.fade_out * kz,
            ..self.clone()
        }
    }

    /// Ribs along Ψ of a flute or spiral over a Ψ `length` mm long.
    fn ribs(&self, length: f64, closed: bool) -> f64 {
        match (self.count, self.period) {
            (Some(n), _) => n,
            (None, Some(p)) if closed => (length / p).round().max(1.0),
            (None, Some(p)) => length / p,
            _ => 1.0,
        }
    }

    /// The spiral's phase per mm of height, in periods.
    fn turn_per_mm(&self, ribs: f64) -> f64 {
        match (self.pitch, self.deg_per_mm) {
            (Some(p), _) => 1.0 / p,
            (None, Some(d)) => ribs * d / 360.0,
            _ => 0.0,
        }
    }

    /// The shortest period along Ψ (mm) and in height (mm) this texture
    /// has over a Ψ `length` mm long; infinite where it does not vary.
    pub fn periods(&self, length: f64, closed: bool) -> [f64; 2] {
        match self.kind {
            Kind::Ripple => [f64::INFINITY, self.period.unwrap_or(f64::INFINITY)],
            Kind::Flute => [length / self.ribs(length, closed), f64::INFINITY],
            Kind::Spiral => {
                let n = self.ribs(length, closed);
                [length / n, 1.0 / self.turn_per_mm(n).abs()]
            }
            // An image is fitted to the sampling (below).
            Kind::Image => [f64::INFINITY; 2],
        }
    }
}

fn fmt_mm(v: f64) -> String {
    let s = format!("{v:.2}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// What a texture asks of the sampling: a step (mm) and the index of
/// the texture that asks it, or nothing.
pub type Need = Option<(f64, usize)>;

/// Validates a design's textures and twist.
pub fn validate(textures: &[TextureSpec], twist_deg: f64, closed: bool) -> Result<()> {
    if textures.len() > MAX_TEXTURES {
        return Err(Error::invalid(
            "texture",
            format!("has {} entries; at most {MAX_TEXTURES}", textures.len()),
        ));
    }
    for (k, t) in textures.iter().enumerate() {
        t.validate(&format!("texture[{k}]"), closed)?;
    }
    if !(twist_deg.is_finite() && twist_deg.abs() <= 720.0) {
        return Err(Error::invalid(
            "twist_deg",
            format!("must be between -720 and 720 degrees (got {twist_deg})"),
        ));
    }
    Ok(())
}

/// The sampling the textures need: the spacing along Ψ and the thickest
/// layer that give every texture [`SAMPLES_PER_PERIOD`] samples a
/// period, with the texture that asks most of each (index), for a Ψ
/// `length` mm long. `None` where no texture asks.
pub fn needs(textures: &[TextureSpec], length: f64, closed: bool) -> [Need; 2] {
    let mut spacing: Need = None;
    let mut layer: Need = None;
    for (k, t) in textures.iter().enumerate() {
        if t.amplitude == 0.0 {
            continue;
        }
        let [pu, pz] = t.periods(length, closed);
        let (su, sz) = (pu / SAMPLES_PER_PERIOD, pz / SAMPLES_PER_PERIOD);
        if su.is_finite() && spacing.is_none_or(|(s, _)| su < s) {
            spacing = Some((su, k));
        }
        if sz.is_finite() && layer.is_none_or(|(s, _)| sz < s) {
            layer = Some((sz, k));
        }
    }
    [spacing, layer]
}

/// The resolved textures of a sampled surface: D(u, z) for a column of
/// height h.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Field {
    entries: Vec<Entry>,
    closed: bool,
}

#[derive(Clone, Debug, PartialEq)]
struct Entry {
    spec: TextureSpec,
    ribs: f64,
    turn_per_mm: f64,
    image: Option<Grey>,
}

impl Field {
    /// The textures over a Ψ `length` mm long and `height` mm tall,
    /// sampled every `spacing` mm and `layer` mm: images are averaged
    /// down to half the samples a period needs.
    pub fn new(
        textures: &[TextureSpec],
        length: f64,
        height: f64,
        closed: bool,
        spacing: f64,
        layer: f64,
    ) -> Field {
        let cells = |extent: f64, step: f64| {
            (extent / (step * SAMPLES_PER_PERIOD / 2.0))
                .floor()
                .max(1.0) as usize
        };
        Field {
            entries: textures
                .iter()
                .filter(|t| t.amplitude != 0.0)
                .map(|t| {
                    let ribs = t.ribs(length, closed);
                    Entry {
                        spec: t.clone(),
                        ribs,
                        turn_per_mm: t.turn_per_mm(ribs),
                        image: t
                            .image
                            .as_ref()
                            .map(|g| g.fit(cells(length, spacing), cells(height, layer))),
                    }
                })
                .collect(),
            closed,
        }
    }

    /// Whether there is nothing to add.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// D at normalised arc length `u`, height `z`, in a column `h` tall,
    /// with its base `base` mm laid plain (a vessel's floor layers).
    pub fn at(&self, u: f64, z: f64, h: f64, base: f64) -> f64 {
        if base > 0.0 && z <= base + 1e-9 {
            return 0.0;
        }
        let t = (z / h).clamp(0.0, 1.0);
        self.entries
            .iter()
            .map(|e| {
                let s = &e.spec;
                let p = s.phase_deg.to_radians();
                let g = match s.kind {
                    Kind::Ripple => (TAU * z / s.period.unwrap_or(1.0) + p).sin(),
                    Kind::Flute => (TAU * e.ribs * u + p).sin(),
                    Kind::Spiral => (TAU * (e.ribs * u + z * e.turn_per_mm) + p).sin(),
                    Kind::Image => e
                        .image
                        .as_ref()
                        .map_or(0.0, |g| 2.0 * g.at(u, 1.0 - t, self.closed) - 1.0),
                };
                s.amplitude * envelope(z - base, s.fade_in) * envelope(h - z, s.fade_out) * g
            })
            .sum()
    }

    /// The textures' labels, for reports: "ripple 2 mm + flute 1 mm".
    pub fn label(&self) -> String {
        self.entries
            .iter()
            .map(|e| e.spec.label())
            .collect::<Vec<_>>()
            .join(" + ")
    }

    /// The largest |D| the textures can reach (mm): their amplitudes
    /// summed.
    pub fn peak(&self) -> f64 {
        self.entries.iter().map(|e| e.spec.amplitude.abs()).sum()
    }
}

/// Rises smoothly (half a cosine) from 0 at d ≤ 0 to 1 at d ≥ `len`; 1
/// without a fade. Below 0 (inside a plain base) it is 0.
fn envelope(d: f64, len: f64) -> f64 {
    if d < 0.0 {
        0.0
    } else if len <= 0.0 || d >= len {
        1.0
    } else {
        0.5 - 0.5 * (PI * d / len).cos()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_report_says_what_share_of_the_wall_was_reduced() {
        // 1,000 textured samples; 30 reduced in one band (two spots 1 mm
        // apart), one elsewhere: the band's least is 0, its share 3 %.
        let mut items: Vec<_> = (0..20)
            .map(|k| (10.0, 0.1 + 0.001 * k as f64, 0.5, "overhang"))
            .collect();
        items.extend((0..10).map(|_| (11.0, 0.6, 0.0, "overlap")));
        items.push((80.0, 0.3, 0.9, "overlap"));
        let r = report(items, "flute 3 mm", 3.75, 1000);
        assert_eq!(r.len(), 2);
        assert!((r[0].share - 0.03).abs() < 1e-12, "{}", r[0].share);
        assert_eq!(
            (r[0].kept, r[0].z_mm, r[0].why),
            (0.0, [10.0, 11.0], "overhang")
        );
        assert_eq!(
            r[0].summary(3.0),
            "texture flute 3 mm reduced on 3 % of the wall, between z 10 and 11 mm, u 0.10–0.60, to 0 % at the least (0 mm of 3 mm): overhang"
        );
        assert!(r[1].summary(3.0).contains("reduced on 0.1 % of the wall"));
    }

    fn ripple(a: f64, p: f64) -> TextureSpec {
        serde_json::from_str(&format!(
            r#"{{"kind": "ripple", "amplitude": {a}, "period": {p}}}"#
        ))
        .unwrap()
    }

    #[test]
    fn a_phase_starts_the_wave_later() {
        // A quarter turn makes the ripple's sine a cosine.
        let mut r = ripple(2.0, 10.0);
        r.phase_deg = 90.0;
        let f = Field::new(&[r.clone()], 100.0, 50.0, false, 1.0, 1.0);
        assert!((f.at(0.3, 0.0, 50.0, 0.0) - 2.0).abs() < 1e-12);
        assert!((f.at(0.3, 5.0, 50.0, 0.0) + 2.0).abs() < 1e-12);
        // Written only when not 0, checked in range, read by three kinds.
        assert!(serde_json::to_string(&ripple(2.0, 10.0))
            .unwrap()
            .find("phase")
            .is_none());
        r.phase_deg = 400.0;
        let e = r.validate("texture[0]", true).unwrap_err().to_string();
        assert!(e.starts_with("texture[0].phase_deg"), "{e}");
        let img: TextureSpec =
            serde_json::from_str(r#"{"kind": "image", "amplitude": 1, "phase_deg": 30}"#).unwrap();
        let e = img.check_keys("texture[0]").unwrap_err().to_string();
        assert!(e.starts_with("texture[0].phase_deg"), "{e}");
    }

    #[test]
    fn a_ripple_is_a_sine_in_height_and_fades_smoothly() {
        let f = Field::new(&[ripple(2.0, 10.0)], 100.0, 50.0, false, 1.0, 1.0);
        assert!((f.at(0.3, 2.5, 50.0, 0.0) - 2.0).abs() < 1e-12);
        assert!((f.at(0.7, 7.5, 50.0, 0.0) + 2.0).abs() < 1e-12);
        assert!(f.at(0.0, 10.0, 50.0, 0.0).abs() < 1e-12);
        let mut faded = ripple(2.0, 10.0);
        faded.fade_in = 10.0;
        let f = Field::new(&[faded], 100.0, 50.0, false, 1.0, 1.0);
        // Half way up the fade, half the amplitude; nothing at the base.
        assert!((f.at(0.0, 5.0, 50.0, 0.0) - 0.0).abs() < 1e-12);
        assert!((f.at(0.0, 2.5, 50.0, 0.0) - 2.0 * envelope(2.5, 10.0)).abs() < 1e-12);
        assert_eq!(f.at(0.0, 0.0, 50.0, 0.0), 0.0);
        // A plain base 4 mm deep: nothing below it, the fade from it.
        assert_eq!(f.at(0.0, 3.0, 50.0, 4.0), 0.0);
    }

    #[test]
    fn flutes_and_spirals_meet_at_the_seam_and_need_eight_samples_a_period() {
        let flute: TextureSpec =
            serde_json::from_str(r#"{"kind": "flute", "amplitude": 1, "count": 12}"#).unwrap();
        let f = Field::new(std::slice::from_ref(&flute), 300.0, 80.0, true, 1.0, 1.0);
        assert!((f.at(0.0, 10.0, 80.0, 0.0) - f.at(1.0, 10.0, 80.0, 0.0)).abs() < 1e-9);
        assert!((f.at(1.0 / 48.0, 10.0, 80.0, 0.0) - 1.0).abs() < 1e-12);
        let [s, z] = needs(std::slice::from_ref(&flute), 300.0, true);
        assert_eq!(s, Some((300.0 / 12.0 / 8.0, 0)));
        assert_eq!(z, None);
        let half: TextureSpec =
            serde_json::from_str(r#"{"kind": "flute", "amplitude": 1, "count": 2.5}"#).unwrap();
        assert!(half.validate("texture[0]", true).is_err());
        assert!(half.validate("texture[0]", false).is_ok());
        let spiral: TextureSpec =
            serde_json::from_str(r#"{"kind": "spiral", "amplitude": 1, "count": 6, "pitch": 40}"#)
                .unwrap();
        let f = Field::new(std::slice::from_ref(&spiral), 300.0, 80.0, true, 1.0, 1.0);
        // One pitch up, the ribs have moved on by one rib.
        assert!((f.at(0.1, 5.0, 80.0, 0.0) - f.at(0.1 - 1.0 / 6.0, 45.0, 80.0, 0.0)).abs() < 1e-9);
        assert_eq!(needs(&[spiral], 300.0, true)[1], Some((5.0, 0)));
    }

    #[test]
    fn caps_keep_the_step_within_the_limit_and_smoothing_bounds_the_change() {
        assert_eq!(cap(0.5, 0.3, 1.0), 1.0);
        assert!((cap(0.5, 1.0, 1.0) - 0.5).abs() < 1e-12);
        assert!((cap(-0.5, -1.0, 1.0) - 0.5).abs() < 1e-12);
        assert!((cap(0.5, -3.0, 1.0) - 0.5).abs() < 1e-12);
        // A line of ten samples, one capped at 0: its neighbours rise by
        // 0.2 a sample.
        let mut a = vec![1.0; 10];
        a[4] = 0.0;
        let nb: Vec<[u32; 4]> = (0..10u32)
            .map(|i| {
                [
                    i.wrapping_sub(1),
                    if i < 9 { i + 1 } else { u32::MAX },
                    u32::MAX,
                    u32::MAX,
                ]
            })
            .collect();
        smooth(&mut a, &nb, 0..10);
        let want = [0.8, 0.6, 0.4, 0.2, 0.0, 0.2, 0.4, 0.6, 0.8, 1.0];
        for (x, w) in a.iter().zip(want) {
            assert!((x - w).abs() < 1e-9, "{a:?}");
        }
    }

    #[test]
    fn png_images_decode_to_grey_and_average_down() {
        let mut bytes = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut bytes, 4, 2);
            enc.set_color(png::ColorType::Grayscale);
            enc.set_depth(png::BitDepth::Eight);
            let mut w = enc.write_header().unwrap();
            w.write_image_data(&[0, 255, 0, 255, 255, 255, 0, 0])
                .unwrap();
        }
        let g = Grey::from_png(&bytes, "texture[0]").unwrap();
        assert_eq!((g.width, g.height), (4, 2));
        assert_eq!(g.v[1], 1.0);
        let small = g.fit(2, 1);
        assert_eq!(small.v, vec![0.75, 0.25]);
        assert!(Grey::from_png(b"not a png", "texture[0]")
            .unwrap_err()
            .to_string()
            .contains("texture[0]"));
    }
}

#[cfg(test)]
mod budget_tests {
    #[test]
    fn a_designs_pictures_are_counted_against_one_budget_before_decoding() {
        // Three pictures of 2000 × 2000 (4 megapixels, a few kB each as
        // PNG): two fit the design's 8 megapixels, the third is refused by
        // name before its pixels are decoded.
        use base64::Engine as _;
        let mut bytes = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut bytes, 2000, 2000);
            enc.set_color(png::ColorType::Grayscale);
            enc.set_depth(png::BitDepth::Eight);
            let mut w = enc.write_header().unwrap();
            w.write_image_data(&vec![128u8; 2000 * 2000]).unwrap();
        }
        assert!(bytes.len() < 100_000, "{}", bytes.len());
        let b64 = base64::engine::general_purpose::STANDARD.encode(&bytes);
        let texture = format!(r#"{{"kind":"image","amplitude":1,"png_base64":"{b64}"}}"#);
        let design = |n: usize| {
            format!(
                r#"{{"sweepclay":1,"profile_start":{{"control_points":[[0,0],[0,40]]}},
                    "trajectory":{{"control_points":[[30,0],[0,30],[-30,0],[0,-30]],"closed":true}},
                    "texture":[{}]}}"#,
                vec![texture.as_str(); n].join(",")
            )
        };
        assert!(crate::Design::from_json(&design(2)).is_ok());
        match crate::Design::from_json(&design(3)).unwrap_err() {
            crate::Error::Invalid { key, reason } => {
                assert_eq!(key, "texture[2].png_base64");
                assert!(
                    reason.contains("8000000 pixels in all (0 left)"),
                    "{reason}"
                );
            }
            other => panic!("{other}"),
        }
    }
}

#[cfg(test)]
mod key_tests {
    #[test]
    fn a_key_the_kind_does_not_read_is_refused_before_any_picture_is_decoded() {
        let design = |texture: &str| {
            format!(
                r#"{{"sweepclay":1,"profile_start":{{"control_points":[[0,0],[0,40]]}},
                    "trajectory":{{"control_points":[[30,0],[0,30],[-30,0],[0,-30]],"closed":true}},
                    "texture":[{texture}]}}"#
            )
        };
        // `count` on a ripple was ignored; a picture on one was decoded
        // (this one is no base64 at all: refused for the key, not for
        // its bytes).
        for (texture, key) in [
            (
                r#"{"kind":"ripple","amplitude":1,"period":10,"count":5}"#,
                "texture[0].count",
            ),
            (
                r#"{"kind":"ripple","amplitude":1,"period":10,"png_base64":"!!"}"#,
                "texture[0].png_base64",
            ),
            (
                r#"{"kind":"flute","amplitude":1,"count":8,"deg_per_mm":2}"#,
                "texture[0].deg_per_mm",
            ),
            (
                r#"{"kind":"image","amplitude":1,"path":"a.png","period":3}"#,
                "texture[0].period",
            ),
        ] {
            let e = crate::Design::from_json(&design(texture)).unwrap_err();
            match e {
                crate::Error::Invalid { key: k, reason } => {
                    assert_eq!(k, key, "{reason}");
                    assert!(reason.contains("does not read"), "{reason}");
                }
                e => panic!("{e}"),
            }
        }
        // 17 entries are refused by the cap before any is decoded.
        let many =
            vec![r#"{"kind":"ripple","amplitude":1,"period":10,"png_base64":"!!"}"#; 17].join(",");
        let e = crate::Design::from_json(&design(&many))
            .unwrap_err()
            .to_string();
        assert!(e.contains("at most 16"), "{e}");
    }
}
