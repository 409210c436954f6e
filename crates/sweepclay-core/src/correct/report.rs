//! What stage 2 changed, in numbers and in a potter's words: the curves
//! each correction moved, how far, where, and the summary lines `slice`
//! and the modeler print (docs/ALGORITHMS.md §4).

use serde::Serialize;

/// Which curve a correction touched.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CurveId {
    /// C_s, the start profile.
    ProfileStart,
    /// C_t, the end profile.
    ProfileEnd,
    /// The transition curve at column `i`.
    Transition(u32),
}

impl std::fmt::Display for CurveId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CurveId::ProfileStart => write!(f, "profile_start (C_s)"),
            CurveId::ProfileEnd => write!(f, "profile_end (C_t)"),
            CurveId::Transition(i) => write!(f, "transition curve {i}"),
        }
    }
}

/// A curve moved by the support-free correction.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SupportFix {
    /// The curve.
    pub curve: CurveId,
    /// Normalised arc length of the curve's position along Ψ.
    pub u: f64,
    /// Height of the first corrected point (mm).
    pub z_mm: f64,
    /// Largest horizontal move of a point of this curve (mm).
    pub max_shift_mm: f64,
    /// Number of points whose step was shortened.
    pub steps_shortened: u32,
    /// How many of them the bead overlap limited (w_max · (1 − overlap):
    /// the widest bead could not have covered the step with the target
    /// overlap) rather than the overhang angle.
    pub by_overlap: u32,
}

/// The self-intersection found and how it was removed.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct IntersectionFix {
    /// Where the surface met itself first (bed coordinates relative to o).
    pub at: [f64; 3],
    /// The two transition curves that met.
    pub curves: [u32; 2],
    /// Final factor applied to the profiles' x offsets.
    pub compression: f64,
    /// Compression steps taken.
    pub iterations: u32,
}

/// What the corrections changed.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct CorrectionReport {
    /// One entry per curve the support-free correction moved.
    pub support: Vec<SupportFix>,
    /// Present when the surface intersected itself.
    pub intersection: Option<IntersectionFix>,
    /// The sharp corners of a polyline Ψ that were rounded.
    pub corners: Vec<crate::curves::CornerFix>,
    /// The factor on all offsets that keeps the extruder body off a far
    /// part of the wall, when the correction loop needed one (beyond any
    /// self-intersection compression).
    pub body_compression: Option<f64>,
    /// Rounds of the correction loop after the first slicing (0: the
    /// first passed its check, or no loop ran).
    pub rounds: u32,
    /// The largest distance of the printed surface from the drawn one
    /// (textures aside).
    pub deviation: Option<Deviation>,
    /// Where a texture was kept at less than its amplitude, and why.
    pub texture: Vec<crate::texture::TextureFix>,
    /// The textures' summed amplitude (mm), for the report's words.
    #[serde(skip)]
    pub texture_peak: f64,
}

/// How far the printed shape lies from the drawn one at its farthest.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Deviation {
    /// The distance (mm).
    pub mm: f64,
    /// Where: on the bed relative to `o`, the height included (mm).
    pub at: [f64; 3],
    /// Normalised arc length along Ψ there.
    pub u: f64,
    /// What moved it: `support-free`, `self-intersection`, `extruder body`
    /// or `corner`.
    pub by: &'static str,
    /// Which way: `narrower` or `wider` than drawn (a vessel), `off` the
    /// drawn surface (a wall).
    pub way: &'static str,
}

impl CorrectionReport {
    /// The verdict's words when the corrections moved the shape more than
    /// `max_mm` from the drawing: "up to 29.9 mm narrower than drawn at z
    /// 230 mm (u = 0.50, support-free correction)".
    pub fn reshaped(&self, max_mm: f64) -> Option<String> {
        let d = self.deviation.as_ref().filter(|d| d.mm > max_mm)?;
        let way = match d.way {
            "off" => "off the drawn surface",
            "narrower" => "narrower than drawn",
            _ => "wider than drawn",
        };
        Some(format!(
            "up to {:.1} mm {way} at z {:.0} mm (u = {:.2}, {} correction)",
            d.mm, d.at[2], d.u, d.by
        ))
    }
}

impl CorrectionReport {
    /// Whether nothing was changed.
    pub fn is_empty(&self) -> bool {
        self.support.is_empty()
            && self.intersection.is_none()
            && self.corners.is_empty()
            && self.body_compression.is_none()
    }

    /// One line per kind of correction, for summaries.
    pub fn summary(&self) -> Vec<String> {
        let mut out = Vec::new();
        if !self.support.is_empty() {
            let worst = self
                .support
                .iter()
                .max_by(|a, b| a.max_shift_mm.total_cmp(&b.max_shift_mm))
                .expect("non-empty");
            let steps: u32 = self.support.iter().map(|f| f.steps_shortened).sum();
            let by_overlap: u32 = self.support.iter().map(|f| f.by_overlap).sum();
            let why = match (steps - by_overlap, by_overlap) {
                (_, 0) => "the overhang limit".to_string(),
                (0, _) => "the bead overlap (the widest bead covers no more with the target overlap)".to_string(),
                (a, o) => format!(
                    "the overhang limit ({a} steps) and the bead overlap ({o} steps: the widest bead covers no more with the target overlap)"
                ),
            };
            out.push(format!(
                "support-free: {} curve(s) corrected for {why}; largest move {:.2} mm on {} at z = {:.1} mm",
                self.support.len(),
                worst.max_shift_mm,
                worst.curve,
                worst.z_mm
            ));
        }
        if let Some(worst) = self
            .corners
            .iter()
            .max_by(|a, b| a.deviation_mm.total_cmp(&b.deviation_mm))
        {
            out.push(format!(
                "corners: {} sharp corner(s) of Ψ rounded (radius up to {:.1} mm); the printed path passes up to {:.1} mm inside the drawn corner at ({:.1}, {:.1}) mm",
                self.corners.len(),
                self.corners.iter().map(|c| c.radius_mm).fold(0.0, f64::max),
                worst.deviation_mm,
                worst.at[0],
                worst.at[1]
            ));
        }
        if self.rounds > 0 {
            out.push(format!(
                "correction loop: the G-code failed its check {} round(s); the corrections were tightened where it failed",
                self.rounds
            ));
        }
        if let Some(c) = self.body_compression {
            out.push(format!(
                "extruder body: profiles compressed along x by a further {c:.3}, the least that keeps the nozzle's body off the far parts of the wall"
            ));
        }
        for t in &self.texture {
            out.push(t.summary(self.texture_peak));
        }
        if let Some(x) = &self.intersection {
            out.push(format!(
                "self-intersection: transition curves {} and {} met at ({:.1}, {:.1}, {:.1}) mm; profiles compressed along x by {:.3} ({} steps)",
                x.curves[0], x.curves[1], x.at[0], x.at[1], x.at[2], x.compression, x.iterations
            ));
        }
        out
    }
}
