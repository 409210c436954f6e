//! Stage 2: sampled surface → corrected surface (paper §4 "Support-free
//! correction" and "Self-intersection detection and treatment"; docs/ALGORITHMS.md §4).
//!
//! - Support-free: each transition curve is walked upward; a step whose
//!   horizontal offset exceeds s_max(Δz) is shortened to s_max and every
//!   point above moves with it.
//! - Self-intersection: surface points of transition curves more than two
//!   bead widths apart along Ψ that come closer than the widest bead are
//!   found through a plan grid of each curve's radial segment (one query
//!   per curve), comparing samples only for curves whose segments come
//!   within a bead width. As in the paper, C_s and C_t are
//!   then compressed along x (all radial offsets scaled by c = 0.9, 0.81, …)
//!   until none remains.

use crate::error::{Error, Result};
use crate::grid::Grid2;
use crate::surface::Surface;
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

/// The corrected surface and what was changed.
#[derive(Clone, Debug, PartialEq)]
pub struct Corrected {
    /// The surface, now support-free and free of self-intersection.
    pub surface: Surface,
    /// The amount of the texture kept at each sample, 0–1 (empty
    /// without textures; docs/ALGORITHMS.md §11).
    pub kept: Vec<f64>,
    /// What changed.
    pub report: CorrectionReport,
}

impl Corrected {
    /// [`CorrectionReport::reshaped`] beyond the design's
    /// `params.max_correction_mm`: the verdict's "printable, but
    /// reshaped: …" words, if it gets them.
    pub fn reshaped(&self) -> Option<String> {
        self.report.reshaped(self.surface.params.max_correction_mm)
    }
}

/// How the correction loop tightens the corrections where the pipeline's
/// own check of the planned G-code failed (docs/ALGORITHMS.md §4, "The
/// loop closes"). The default tightens nothing.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tightening {
    /// Per transition curve, a factor (at most 1) on the support-free
    /// step limit s_max; missing curves (or an empty list) keep 1.
    pub support: Vec<f64>,
    /// A factor (below 1) on all offsets, on top of any self-intersection
    /// compression: keeps the extruder body off a far part of the wall.
    pub body: Option<f64>,
    /// Rounds of the loop so far (reported).
    pub rounds: u32,
}

/// Applies both corrections.
pub fn correct(surface: &Surface) -> Result<Corrected> {
    correct_with(surface, &Tightening::default())
}

/// [`correct`], tightened as the correction loop asks.
pub fn correct_with(surface: &Surface, tight: &Tightening) -> Result<Corrected> {
    let scale = &tight.support;
    let mut out = surface.clone();
    let mut support = support_free(&mut out, scale);
    let mut intersection = None;
    let mut compression = 1.0;
    if let Some((a, b, at)) = find_self_intersection(&out) {
        // Compressing to nothing must fix it; else Ψ itself is too tight.
        let mut flat = surface.clone();
        scale_offsets(&mut flat, surface, 0.0);
        if let Some((a0, b0, at0)) = find_self_intersection(&flat) {
            return Err(Error::SelfIntersection(format!(
                "the trajectory comes within one bead width ({} mm) of itself near ({:.1}, {:.1}) mm (transition curves {a0} and {b0}); move those parts of Ψ apart",
                surface.params.width_max, at0[0], at0[1]
            )));
        }
        // Compress only as much as needed: the largest factor that
        // clears, by bisection between 0 (clear, above) and 1 (not),
        // to within 1 %.
        let (mut clear, mut meets) = (0.0, 1.0);
        let mut iterations = 0;
        while meets - clear > 0.01 {
            let c = 0.5 * (clear + meets);
            iterations += 1;
            scale_offsets(&mut out, surface, c);
            support_free(&mut out, scale);
            if find_self_intersection(&out).is_none() {
                clear = c;
            } else {
                meets = c;
            }
        }
        compression = clear;
        scale_offsets(&mut out, surface, compression);
        support = support_free(&mut out, scale);
        intersection = Some(IntersectionFix {
            at,
            curves: [a, b],
            compression,
            iterations,
        });
    }
    if let Some(body) = tight.body {
        scale_offsets(&mut out, surface, compression * body);
        support = support_free(&mut out, scale);
    }
    let by = if tight.body.is_some() {
        "extruder body"
    } else if intersection.is_some() {
        "self-intersection"
    } else {
        "support-free"
    };
    let mut deviation = deviation(surface, &out, by);
    if let Some(c) = surface
        .corners
        .iter()
        .max_by(|a, b| a.deviation_mm.total_cmp(&b.deviation_mm))
    {
        if deviation.as_ref().is_none_or(|d| c.deviation_mm > d.mm) {
            deviation = Some(Deviation {
                mm: c.deviation_mm,
                at: [c.at[0], c.at[1], 0.0],
                u: nearest_u(surface, c.at),
                by: "corner",
                way: if surface.vessel.is_some() {
                    "narrower"
                } else {
                    "off"
                },
            });
        }
    }
    let (kept, texture) = if out.texture.is_empty() {
        (Vec::new(), Vec::new())
    } else {
        let (kept, fixes) = keep_texture(&mut out, scale);
        // A texture the clay can hold nowhere (less than a quarter of it
        // anywhere) is refused, not printed all but plain under its name.
        let textured = || {
            out.texture
                .iter()
                .zip(&kept)
                .filter(|(d, _)| d.abs() > 0.01)
        };
        if textured().next().is_some() && textured().all(|(_, &a)| a < 0.25) {
            let why = fixes.first().map_or("overhang", |f| f.why);
            return Err(Error::invalid(
                "texture",
                format!(
                    "{} cannot be kept anywhere (not a quarter of it at any place: {why}); make it shallower or its period longer",
                    out.texture_label.0
                ),
            ));
        }
        // What a texture pushed past the limits anyway is held back as any
        // other step is (and reported so).
        support.extend(support_free(&mut out, scale));
        (kept, fixes)
    };
    Ok(Corrected {
        kept,
        report: CorrectionReport {
            texture,
            texture_peak: out.texture_label.1,
            support,
            intersection,
            corners: surface.corners.clone(),
            body_compression: tight.body,
            rounds: tight.rounds,
            deviation,
        },
        surface: out,
    })
}

/// The share of the step limit a texture may use (see [`keep_texture`]).
const TEXTURE_MARGIN: f64 = 0.85;

/// The neighbours of each sample for the texture's smoothness: the
/// samples below and above in its column, and the same pass's in the
/// columns on either side (round a loop, the last column's pass k is
/// followed by the first's k + 1).
fn sample_neighbours(s: &Surface) -> Vec<[u32; 4]> {
    let n = s.columns.len();
    let closed = s.vessel.is_some();
    let at = |c: usize, k: isize| -> u32 {
        let col = &s.columns[c];
        if k < 0 || col.is_empty() {
            return u32::MAX;
        }
        col.first + (k as u32).min(col.len() as u32 - 1)
    };
    let mut out = vec![[u32::MAX; 4]; s.samples.len()];
    for (c, col) in s.columns.iter().enumerate() {
        for (k, i) in col.samples().enumerate() {
            let k = k as isize;
            let mut nb = [u32::MAX; 4];
            if k > 0 {
                nb[0] = i as u32 - 1;
            }
            if (k as usize) + 1 < col.len() {
                nb[1] = i as u32 + 1;
            }
            if c > 0 {
                nb[2] = at(c - 1, k);
            } else if closed && n > 1 {
                nb[2] = at(n - 1, k - 1);
            }
            if c + 1 < n {
                nb[3] = at(c + 1, k);
            } else if closed && n > 1 {
                nb[3] = at(0, k + 1);
            }
            out[i] = nb;
        }
    }
    out
}

/// Adds the textures at the largest amount a ∈ [0, 1] each sample allows
/// (docs/ALGORITHMS.md §11): every step from the sample below must stay
/// within the support-free and overlap limit s_max (times the loop's
/// tightening); a step that would not caps a at both its samples, the
/// caps spread so neighbours differ by at most 0.2, and the surface must
/// not meet itself. Returns a per sample and where it fell short.
fn keep_texture(s: &mut Surface, scale: &[f64]) -> (Vec<f64>, Vec<crate::texture::TextureFix>) {
    use crate::texture::{cap, report, smooth};
    let n = s.samples.len();
    let base: Vec<f64> = s.samples.iter().map(|x| x.xi).collect();
    let d = s.texture.clone();
    let nb = sample_neighbours(s);
    // Each step of a column: (lower sample, upper sample, limit, twist
    // step, why).
    let mut steps = Vec::with_capacity(n);
    // Where a vessel's spiral starts, its first beads are next to nothing
    // high and the step up to them is sized by their width: a bead above
    // widened by the texture would widen every bead under it (the
    // extrusion's top-down walk) down to them. Near the start the texture
    // keeps to steps the narrowest bead covers.
    let m = s.columns.len();
    let near_start = |c: usize| {
        s.vessel.as_ref().is_some_and(|v| {
            let from_start = (c + m - v.start) % m.max(1);
            (from_start as f64) * s.spacing <= 2.0 * s.params.width_max
        })
    };
    let narrow = s.params.width_min * (1.0 - s.params.overlap);
    // `Params::offset_limit`, its tangent taken once.
    let tan = s.params.max_overhang_deg.to_radians().tan();
    let by_width = s.params.width_max * (1.0 - s.params.overlap);
    for (c, col) in s.columns.iter().enumerate() {
        let r = col.samples();
        let start = near_start(c);
        for i in r.start + 1..r.end {
            let (z0, z1) = (s.samples[i - 1].z, s.samples[i].z);
            let by_angle = (z1 - z0) * tan;
            let (lim, by_angle) = if by_angle <= by_width {
                (by_angle, true)
            } else {
                (by_width, false)
            };
            let (lim, by_angle) = if start && narrow < lim {
                (narrow, false)
            } else {
                (lim, by_angle)
            };
            // A textured bead runs across Ψ's direction (a rib's flank),
            // so a step along d overhangs a little more than the
            // untextured rule counts: a margin of TEXTURE_MARGIN.
            let lim = lim * scale.get(c).copied().unwrap_or(1.0) * TEXTURE_MARGIN;
            let why = if by_angle { "overhang" } else { "overlap" };
            steps.push((i - 1, i, lim, col.twist_step(base[i - 1], z0, z1), why));
        }
    }
    let mut caps = vec![1.0f64; n];
    let mut why = vec![""; n];
    let lower = |caps: &mut [f64], why: &mut [&'static str], i: usize, a: f64, w: &'static str| {
        if a < caps[i] - 1e-12 {
            caps[i] = a;
            why[i] = w;
        }
    };
    for &(i0, i1, lim, tw, w) in &steps {
        let b = base[i1] - base[i0] + tw;
        let a = cap(b, d[i1] - d[i0], lim);
        lower(&mut caps, &mut why, i0, a, w);
        lower(&mut caps, &mut why, i1, a, w);
    }
    // A bead much thinner than a layer (a spiral's first turn where it
    // leaves the floor) is widened to carry an offset bead above it, and
    // its step up then piles clay: nothing is offset above such a bead.
    let thin = 0.5 * s.params.layer_height;
    for w in steps.windows(2) {
        let ((a0, a1, ..), (b0, b1, ..)) = (w[0], w[1]);
        if a1 == b0 && s.samples[a1].z - s.samples[a0].z < thin {
            lower(&mut caps, &mut why, b1, 0.0, "overhang");
        }
    }
    // Only a capped sample can lower another.
    let mut a = caps.clone();
    let capped: Vec<usize> = (0..n).filter(|&i| caps[i] < 1.0).collect();
    smooth(&mut a, &nb, capped);
    let apply = |s: &mut Surface, a: &[f64]| {
        for (i, smp) in s.samples.iter_mut().enumerate() {
            smp.xi = base[i] + a[i] * d[i];
        }
    };
    // Neighbours kept at different amounts step differently: tighten
    // where a step still breaks, and again, until none does; after the
    // first round only the steps at samples that changed are looked at.
    // (Spreading only lowers, so a spread from the lowered caps alone
    // equals a spread of all of them again.)
    let mut up_step = vec![u32::MAX; n];
    for (k, st) in steps.iter().enumerate() {
        up_step[st.1] = k as u32;
    }
    let mut look: Vec<usize> = (0..steps.len()).collect();
    for _ in 0..200 {
        let mut lowered = Vec::new();
        for &k in &look {
            let (i0, i1, lim, tw, w) = steps[k];
            let step = base[i1] + a[i1] * d[i1] - base[i0] - a[i0] * d[i0] + tw;
            if step.abs() > lim + 1e-9 {
                let f = cap(base[i1] - base[i0] + tw, a[i1] * d[i1] - a[i0] * d[i0], lim);
                let f = f.min(0.9);
                for i in [i0, i1] {
                    lower(&mut caps, &mut why, i, f * a[i], w);
                    if caps[i] < a[i] {
                        a[i] = caps[i];
                        lowered.push(i);
                    }
                }
            }
        }
        if lowered.is_empty() {
            break;
        }
        let changed = smooth(&mut a, &nb, lowered);
        look.clear();
        for i in changed {
            look.push(up_step[i] as usize);
            if i + 1 < n && up_step[i + 1] != u32::MAX && steps[up_step[i + 1] as usize].0 == i {
                look.push(up_step[i + 1] as usize);
            }
        }
        look.retain(|&k| k < steps.len());
        look.sort_unstable();
        look.dedup();
    }
    apply(s, &a);
    // Where the textured surface meets itself, the texture gives way
    // there (a few places at most, then everywhere).
    let reach = (3.0 * s.params.width_max / s.spacing).ceil() as usize;
    for round in 0..=6 {
        let Some((ca, cb, at)) = find_self_intersection(s) else {
            break;
        };
        let m = s.columns.len();
        let near: Vec<usize> = if round == 6 {
            (0..m).collect()
        } else {
            [ca as usize, cb as usize]
                .into_iter()
                .flat_map(|c| c.saturating_sub(reach)..=(c + reach).min(m - 1))
                .collect()
        };
        let mut lowered = Vec::new();
        for c in near {
            for i in s.columns[c].samples() {
                if round == 6 || (s.samples[i].z - at[2]).abs() < 3.0 * s.params.width_max {
                    lower(&mut caps, &mut why, i, 0.0, "self-intersection");
                    a[i] = 0.0;
                    lowered.push(i);
                }
            }
        }
        smooth(&mut a, &nb, lowered);
        apply(s, &a);
    }
    let items: Vec<(f64, f64, f64, &'static str)> = s
        .columns
        .iter()
        .flat_map(|col| col.samples().map(move |i| (i, col.u)))
        .filter(|&(i, _)| a[i] < 0.99 && d[i].abs() > 0.01)
        .map(|(i, u)| {
            let w = if why[i].is_empty() {
                // Lowered only by a neighbour: the reason nearest it.
                nb[i]
                    .iter()
                    .filter(|&&j| j != u32::MAX)
                    .map(|&j| why[j as usize])
                    .find(|w| !w.is_empty())
                    .unwrap_or("overhang")
            } else {
                why[i]
            };
            (s.samples[i].z, u, a[i], w)
        })
        .collect();
    let gap = 3.0 * s.params.max_layer_height;
    (a, report(items, &s.texture_label.0, gap))
}

/// The sample moved farthest from the design by the corrections, if any
/// moved more than a hundredth of a millimetre.
fn deviation(design: &Surface, out: &Surface, by: &'static str) -> Option<Deviation> {
    let mut worst: Option<(f64, usize, usize)> = None;
    for (c, col) in design.columns.iter().enumerate() {
        for i in col.samples() {
            let d = (out.samples[i].xi - design.samples[i].xi).abs();
            if d > 0.01 && worst.is_none_or(|w| d > w.0) {
                worst = Some((d, c, i));
            }
        }
    }
    let (mm, c, i) = worst?;
    let at = out.position(c, i);
    // A vessel's point that came nearer the loop's middle is narrower.
    let way = if design.vessel.is_some() {
        let m = design.columns.len().max(1) as f64;
        let mid = design.columns.iter().fold([0.0, 0.0], |a, col| {
            [a[0] + col.p[0] / m, a[1] + col.p[1] / m]
        });
        let drawn = design.position(c, i);
        let r = |p: [f64; 3]| (p[0] - mid[0]).hypot(p[1] - mid[1]);
        if r(at) < r(drawn) {
            "narrower"
        } else {
            "wider"
        }
    } else {
        "off"
    };
    Some(Deviation {
        mm,
        at,
        u: design.columns[c].u,
        by,
        way,
    })
}

/// u of the column nearest `p` in plan.
fn nearest_u(s: &Surface, p: [f64; 2]) -> f64 {
    s.columns
        .iter()
        .min_by(|a, b| {
            let d = |c: &&crate::surface::Column| (c.p[0] - p[0]).hypot(c.p[1] - p[1]);
            d(a).total_cmp(&d(b))
        })
        .map_or(0.0, |c| c.u)
}

/// Sets every offset to `c` times the design's.
fn scale_offsets(out: &mut Surface, design: &Surface, c: f64) {
    for (o, d) in out.samples.iter_mut().zip(&design.samples) {
        o.xi = c * d.xi;
    }
}

/// Walks every column upward and shortens steps that overhang too far
/// (s_max times the column's factor in `scale`, if it has one).
fn support_free(s: &mut Surface, scale: &[f64]) -> Vec<SupportFix> {
    let n = s.columns.len();
    let mut fixes = Vec::new();
    for (c, col) in s.columns.iter().enumerate() {
        let range = col.samples();
        let mut carry = 0.0;
        let mut fix: Option<SupportFix> = None;
        let mut prev = s.samples[range.start];
        for i in range.start + 1..range.end {
            let design = s.samples[i];
            let mut xi = design.xi + carry;
            let (limit, by_angle) = s.params.offset_limit(design.z - prev.z);
            let limit = limit * scale.get(c).copied().unwrap_or(1.0);
            // The twist's turn overhangs too, where it crosses the wall.
            let tw = col.twist_step(prev.xi, prev.z, design.z);
            let step = xi - prev.xi + tw;
            if step.abs() > limit + 1e-12 {
                let clamped = prev.xi - tw + limit.copysign(step);
                carry += clamped - xi;
                xi = clamped;
                let f = fix.get_or_insert(SupportFix {
                    curve: if c == 0 {
                        CurveId::ProfileStart
                    } else if c == n - 1 {
                        CurveId::ProfileEnd
                    } else {
                        CurveId::Transition(c as u32)
                    },
                    u: col.u,
                    z_mm: design.z,
                    max_shift_mm: 0.0,
                    steps_shortened: 0,
                    by_overlap: 0,
                });
                f.steps_shortened += 1;
                f.by_overlap += u32::from(!by_angle);
            }
            if let Some(f) = fix.as_mut() {
                f.max_shift_mm = f.max_shift_mm.max(carry.abs());
            }
            s.samples[i].xi = xi;
            prev = s.samples[i];
        }
        fixes.extend(fix);
    }
    fixes
}

/// The first pair of surface points from transition curves far apart along
/// Ψ that are closer than the widest bead: `(curve a, curve b, position)`.
///
/// Every sample of a transition curve lies on one radial segment in plan
/// (p_i + ξ·d_i over the curve's range of ξ), and two points are at least
/// as far apart in 3D as in plan. So a grid of those segments first finds
/// the pairs of curves, far apart along Ψ, whose segments come within
/// w_max in plan; only their samples are compared, each with the samples
/// of the other curve within w_max in height (both curves are sorted by
/// height). A surface that does not meet itself has no such pairs: the
/// cost is one segment query per curve, whatever the sampling density.
fn find_self_intersection(s: &Surface) -> Option<(u32, u32, [f64; 3])> {
    if let Some(fold) = find_fold(s) {
        return Some(fold);
    }
    let w = s.params.width_max;
    // A U-turn of radius w/2 is the tightest curve whose sides do not touch:
    // its opposite points are π·w/2 ≈ 1.57 w apart along Ψ. Sides nearer
    // than 2 w along Ψ (a sharp corner's) are laid in one go, as fresh clay
    // the nozzle rides on (the checker counts them so too).
    let far = ((2.0 * w) / s.spacing).ceil() as usize;
    if s.columns.iter().any(|c| c.twist != 0.0) {
        return find_twisted_contact(s, w, far);
    }
    let segs: Vec<[[f64; 2]; 2]> = s
        .columns
        .iter()
        .map(|col| {
            let (lo, hi) = s.samples[col.samples()]
                .iter()
                .fold((f64::MAX, f64::MIN), |(lo, hi), smp| {
                    (lo.min(smp.xi), hi.max(smp.xi))
                });
            let a = col.point(lo, 0.0);
            let b = col.point(hi, 0.0);
            [[a[0], a[1]], [b[0], b[1]]]
        })
        .collect();
    let mut grid = Grid2::new(w.max(s.spacing));
    for (c, seg) in segs.iter().enumerate() {
        grid.insert_segment(seg[0], seg[1], c as u32);
    }
    let w2 = w * w;
    let mut near: Vec<u32> = Vec::new();
    for (a, seg) in segs.iter().enumerate() {
        near.clear();
        let n = segs.len();
        let closed = s.vessel.is_some();
        grid.for_each_near_segment(seg[0], seg[1], w, |b| {
            // Round a loop, the last curves are the first ones' neighbours.
            let apart = (b as usize) > a + far && (!closed || a + n - b as usize > far);
            if apart && segment_distance(*seg, segs[b as usize]) < w {
                near.push(b);
            }
        });
        near.sort_unstable();
        near.dedup();
        for &b in &near {
            let (ca, cb) = (&s.columns[a], &s.columns[b as usize]);
            let rb = cb.samples();
            let mut start = rb.start;
            let sb = segs[b as usize];
            for i in ca.samples() {
                let p = s.position(a, i);
                // All of b lies on its plan segment: a sample of a farther
                // than a bead from it in plan is farther in 3D.
                if point_segment2([p[0], p[1]], sb) >= w2 {
                    continue;
                }
                while start < rb.end && s.samples[start].z < p[2] - w {
                    start += 1;
                }
                for j in start..rb.end {
                    if s.samples[j].z > p[2] + w {
                        break;
                    }
                    let q = s.position(b as usize, j);
                    let d2 = (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2);
                    // Real contact: not two points of a surface that merely
                    // converges, whose pass between them at that height is
                    // short (an inward-leaning cone's top is small, but its
                    // neighbours are still neighbours).
                    if d2 < w2 && pass_apart(s, a, b as usize, i - ca.first as usize, w) {
                        return Some((a as u32, b, p));
                    }
                }
            }
        }
    }
    None
}

/// [`find_self_intersection`] for a twisted surface, whose curves turn as
/// they rise and so lie on no one plan segment: every sample goes into a
/// grid of cells a bead wide in plan and a layer high, and each is
/// compared with the samples of curves far along Ψ in its own and the
/// neighbouring cells. Only samples within a layer of each other in
/// height count: a twisted wall leans along itself, and points of it a
/// layer or more apart are the wall rising, not meeting itself. Linear in
/// the samples.
fn find_twisted_contact(s: &Surface, w: f64, far: usize) -> Option<(u32, u32, [f64; 3])> {
    let dz = s.params.max_layer_height;
    let n = s.columns.len();
    let closed = s.vessel.is_some();
    let key = |p: [f64; 3]| {
        (
            (p[0] / w).floor() as i64,
            (p[1] / w).floor() as i64,
            (p[2] / dz).floor() as i64,
        )
    };
    // Every sample's position once (a twisted one costs a sine), then
    // the samples sorted by cell, and each cell's range of them.
    let mut at = vec![[0.0; 3]; s.samples.len()];
    let mut by_cell: Vec<((i64, i64, i64), u32, u32)> = Vec::with_capacity(s.samples.len());
    for (c, col) in s.columns.iter().enumerate() {
        for i in col.samples() {
            at[i] = s.position(c, i);
            by_cell.push((key(at[i]), c as u32, i as u32));
        }
    }
    by_cell.sort_unstable_by_key(|e| e.0);
    let mut cells: rustc_hash::FxHashMap<(i64, i64, i64), (usize, usize)> =
        rustc_hash::FxHashMap::default();
    let mut start = 0;
    for k in 1..=by_cell.len() {
        if k == by_cell.len() || by_cell[k].0 != by_cell[start].0 {
            cells.insert(by_cell[start].0, (start, k));
            start = k;
        }
    }
    let w2 = w * w;
    for (a, col) in s.columns.iter().enumerate() {
        for i in col.samples() {
            let p = at[i];
            let (kx, ky, kz) = key(p);
            for k in [
                (-1i64, -1i64),
                (-1, 0),
                (-1, 1),
                (0, -1),
                (0, 0),
                (0, 1),
                (1, -1),
                (1, 0),
                (1, 1),
            ]
            .iter()
            .flat_map(|&(x, y)| (-1..=1).map(move |z| (kx + x, ky + y, kz + z)))
            {
                let Some(&(from, to)) = cells.get(&k) else {
                    continue;
                };
                for &(_, b, j) in &by_cell[from..to] {
                    let b = b as usize;
                    let apart = b > a + far && (!closed || a + n - b > far);
                    if !apart {
                        continue;
                    }
                    if (at[j as usize][2] - p[2]).abs() >= 0.5 * dz {
                        continue;
                    }
                    let q = at_height(s, b, j as usize, p[2]);
                    let d2 = (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2);
                    if d2 < w2 && pass_apart(s, a, b, i - col.first as usize, w) {
                        return Some((a as u32, b as u32, p));
                    }
                }
            }
        }
    }
    None
}

/// The point of column `c` at height `z`, between its sample `j` and
/// the neighbour on `z`'s side (or at the column's end). A twisted wall
/// turns as it rises, so two samples a part of a layer apart in height
/// sit turned apart too: a round vase twisted 720° over 97 mm turns 9°
/// a layer, and a sample of its neck 1.2 mm higher and 24° along came
/// within a bead of another, though the wall there is one round sheet.
/// Compared at one height, only a wall that meets itself is near.
fn at_height(s: &Surface, c: usize, j: usize, z: f64) -> [f64; 3] {
    let range = s.columns[c].samples();
    let zj = s.samples[j].z;
    let k = if z >= zj { j + 1 } else { j.wrapping_sub(1) };
    if !range.contains(&k) || (s.samples[k].z - zj).abs() < 1e-9 {
        return s.position(c, j);
    }
    let (a, b) = (s.samples[j], s.samples[k]);
    let t = ((z - a.z) / (b.z - a.z)).clamp(0.0, 1.0);
    s.columns[c].point(a.xi + t * (b.xi - a.xi), a.z + t * (b.z - a.z))
}

/// Whether two points of columns `a` and `b` closer than a bead (`w`) are
/// apart along the pass that lays sample `k` of column `a` (its pass
/// k + 1): more than 1.6 w of that pass between them (the U-turn of
/// radius w/2, the tightest whose sides do not touch, is π w/2 long), or
/// a pass that turns back on itself between them (a curl tighter than a
/// bead, whose sides touch however short it is). The same pass's samples
/// of the columns between are used (a column with fewer passes
/// contributes its top).
fn pass_apart(s: &Surface, a: usize, b: usize, k: usize, w: f64) -> bool {
    let apart = |(len, turn): (f64, f64)| len > 1.6 * w || turn >= std::f64::consts::PI;
    let n = s.columns.len();
    // Round a loop the pass joins them both ways.
    apart(pass_length(s, a..=b, k))
        && (s.vessel.is_none() || apart(pass_length(s, (b..=a + n).map(|c| c % n), k)))
}

/// Plan length and net turning (radians, signed turns summed, so jitter
/// cancels and a curl counts its whole turn) of the pass that lays sample
/// `k` of the first column of `cols`, through the others in order (see
/// [`pass_apart`]).
fn pass_length(s: &Surface, cols: impl IntoIterator<Item = usize>, k: usize) -> (f64, f64) {
    let at = |c: usize| {
        let col = &s.columns[c];
        let i = col.first as usize + k.min(col.len().saturating_sub(1));
        s.position(c, i)
    };
    let (mut len, mut turn) = (0.0, 0.0);
    let mut cols = cols.into_iter();
    let Some(a) = cols.next() else {
        return (0.0, 0.0);
    };
    let mut prev = at(a);
    let mut heading: Option<f64> = None;
    for c in cols {
        let p = at(c);
        let (dx, dy) = (p[0] - prev[0], p[1] - prev[1]);
        let l = dx.hypot(dy);
        // Steps under 0.01 mm have no direction worth the name.
        if l > 0.01 {
            let h = dy.atan2(dx);
            if let Some(h0) = heading {
                let mut d = h - h0;
                while d > std::f64::consts::PI {
                    d -= std::f64::consts::TAU;
                }
                while d < -std::f64::consts::PI {
                    d += std::f64::consts::TAU;
                }
                turn += d;
            }
            heading = Some(h);
        }
        len += l;
        prev = p;
    }
    (len, turn.abs())
}

/// Where an offset larger than a bend's radius on its inner side folds the
/// surface (a normal offset at a tight bend, a radial one past `o`): two
/// neighbouring transition curves whose points at the same offset follow
/// each other against the direction of Ψ. Checked at each curve's
/// extreme offsets, where a fold starts; one test a curve.
fn find_fold(s: &Surface) -> Option<(u32, u32, [f64; 3])> {
    let n = s.columns.len();
    // A loop's last curve is followed by its first.
    let pairs = n - usize::from(s.vessel.is_none());
    for a in 0..pairs {
        let w = [&s.columns[a], &s.columns[(a + 1) % n]];
        let step = [w[1].p[0] - w[0].p[0], w[1].p[1] - w[0].p[1]];
        for smp in [
            s.samples[w[0].samples().start],
            s.samples[w[0].samples().end - 1],
        ]
        .into_iter()
        .chain(
            s.samples[w[0].samples()]
                .iter()
                .copied()
                .min_by(|x, y| x.xi.total_cmp(&y.xi)),
        )
        .chain(
            s.samples[w[0].samples()]
                .iter()
                .copied()
                .max_by(|x, y| x.xi.total_cmp(&y.xi)),
        ) {
            let (p, q) = (w[0].point(smp.xi, smp.z), w[1].point(smp.xi, smp.z));
            // A twisted layer is turned whole: Ψ's step turns with it.
            let (sn, cs) = w[0].turn(smp.z).sin_cos();
            let along = [cs * step[0] - sn * step[1], sn * step[0] + cs * step[1]];
            if (q[0] - p[0]) * along[0] + (q[1] - p[1]) * along[1] <= 0.0 {
                return Some((a as u32, ((a + 1) % n) as u32, p));
            }
        }
    }
    None
}

/// Squared distance from a point to a segment in the plane.
fn point_segment2(p: [f64; 2], s: [[f64; 2]; 2]) -> f64 {
    let q = crate::plane::closest_on_segment(p, s[0], s[1]);
    (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)
}

/// Distance between two segments in the plane.
fn segment_distance(a: [[f64; 2]; 2], b: [[f64; 2]; 2]) -> f64 {
    if crate::curves::segments_cross(a[0], a[1], b[0], b[1]) {
        return 0.0;
    }
    point_segment2(a[0], b)
        .min(point_segment2(a[1], b))
        .min(point_segment2(b[0], a))
        .min(point_segment2(b[1], a))
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::Design;
    use crate::surface::sample_surface;

    fn design(start: &str, end: &str, traj: &str) -> Design {
        Design::from_json(&format!(
            r#"{{"sweepclay":1,"profile_start":{{"control_points":{start}}},
                "profile_end":{{"control_points":{end}}},"trajectory":{traj}}}"#
        ))
        .unwrap()
    }

    #[test]
    fn overhang_is_limited_and_reported() {
        // C_s leans outward at 45° over 20 mm then goes up: slope 1 > tan 57°? no;
        // use a 70° lean: 27.5 mm out over 10 mm up.
        let d = design(
            "[[0,0],[27.5,10],[27.5,30]]",
            "[[0,0],[0,30]]",
            r#"{"points":[[-40,20],[40,20]]}"#,
        );
        let s = sample_surface(&d).unwrap();
        let c = correct(&s).unwrap();
        assert!(!c.report.support.is_empty());
        assert_eq!(c.report.support[0].curve, CurveId::ProfileStart);
        let p = &c.surface.params;
        for col in &c.surface.columns {
            let r = col.samples();
            for i in r.start + 1..r.end {
                let (a, b) = (c.surface.samples[i - 1], c.surface.samples[i]);
                let s = (b.xi - a.xi).abs();
                assert!(
                    s <= p.max_offset(b.z - a.z) + 1e-9,
                    "step {s} over {}",
                    b.z - a.z
                );
            }
        }
        let summary = c.report.summary().join("\n");
        assert!(summary.contains("support-free"), "{summary}");
    }

    #[test]
    fn the_overhang_angle_and_the_bead_overlap_are_separate_reasons() {
        // A 50° lean: within 57° at any layer height, so at 1.25 mm layers
        // nothing is corrected; at 2 mm layers a step is 2.38 mm, more than
        // the widest bead covers with 2/3 overlap (6 · 1/3 = 2 mm): the
        // bead overlap, not the angle, shortens it, and the report says so.
        let lean = 40.0 * 50f64.to_radians().tan();
        let mut d = design(
            &format!("[[0,0],[{lean},40]]"),
            &format!("[[0,0],[{lean},40]]"),
            r#"{"points":[[-40,40],[40,40]]}"#,
        );
        let c = correct(&sample_surface(&d).unwrap()).unwrap();
        assert!(c.report.support.is_empty(), "{:?}", c.report.summary());
        d.params.layer_height = 2.0;
        d.params.max_layer_height = 3.75;
        let c = correct(&sample_surface(&d).unwrap()).unwrap();
        let f = &c.report.support[0];
        assert!(
            f.steps_shortened > 0 && f.by_overlap == f.steps_shortened,
            "{f:?}"
        );
        let summary = c.report.summary().join("\n");
        assert!(summary.contains("for the bead overlap"), "{summary}");
        // A 70° lean at 1.25 mm layers: the angle.
        let lean = 40.0 * 70f64.to_radians().tan();
        let d = design(
            &format!("[[0,0],[{lean},40]]"),
            "[[0,0],[0,40]]",
            r#"{"points":[[-40,40],[40,40]]}"#,
        );
        let c = correct(&sample_surface(&d).unwrap()).unwrap();
        assert_eq!(c.report.support[0].by_overlap, 0);
        assert!(c.report.summary()[0].contains("for the overhang limit"));
    }

    #[test]
    fn gentle_surface_is_left_alone() {
        let d = design(
            "[[0,0],[2,30]]",
            "[[0,0],[-2,30]]",
            r#"{"points":[[-40,20],[40,20]]}"#,
        );
        let s = sample_surface(&d).unwrap();
        let c = correct(&s).unwrap();
        assert!(c.report.is_empty(), "{:?}", c.report);
        assert_eq!(c.surface, s);
    }

    /// A C of 300° and radius 25 around o whose profiles lean 20 mm
    /// toward it at the top: its ends, 60° apart, close to a chord of
    /// 25 − ξ, and meet (under 6 mm, with 250° of pass between them) once
    /// ξ passes 19 mm.
    fn closing_c() -> Design {
        let cp: Vec<[f64; 2]> = (0..=10)
            .map(|i| {
                let a = (30.0 + 300.0 * f64::from(i) / 10.0).to_radians();
                [25.0 * a.cos(), 25.0 * a.sin()]
            })
            .collect();
        design(
            "[[0,0],[-6.67,10],[-13.33,20],[-20,30]]",
            "[[0,0],[-6.67,10],[-13.33,20],[-20,30]]",
            &format!(r#"{{"points":{}}}"#, serde_json::to_string(&cp).unwrap()),
        )
    }

    #[test]
    fn surface_meeting_itself_is_compressed_as_little_as_needed() {
        let s = sample_surface(&closing_c()).unwrap();
        assert!(find_self_intersection(&s).is_some());
        let c = correct(&s).unwrap();
        let x = c
            .report
            .intersection
            .as_ref()
            .expect("intersection reported");
        // Contact under 6 mm at ξ > 19 mm of 20 (the polygon's chords
        // and the samples' spacing move it a little).
        assert!((x.compression - 0.95).abs() < 0.03, "{}", x.compression);
        assert!(find_self_intersection(&c.surface).is_none());
    }

    #[test]
    fn converging_surfaces_are_left_alone() {
        // An inward-leaning cone: an arc of radius 40 leaning 20 mm in (its
        // opposite walls stay 40 mm apart); a C of radius 20 leaning 15 mm
        // in (walls 10 mm apart at the top). Neither meets itself.
        for (r, lean, span) in [(40.0, 20.0, 270.0), (20.0, 15.0, 180.0)] {
            let cp: Vec<[f64; 2]> = (0..=12)
                .map(|i| {
                    let a = (span * f64::from(i) / 12.0).to_radians();
                    [r * a.cos(), r * a.sin()]
                })
                .collect();
            let l = -lean;
            let d = design(
                &format!("[[0,0],[{},15],[{l},30]]", l / 2.0),
                &format!("[[0,0],[{},15],[{l},30]]", l / 2.0),
                &format!(r#"{{"points":{}}}"#, serde_json::to_string(&cp).unwrap()),
            );
            let c = correct(&sample_surface(&d).unwrap()).unwrap();
            assert!(
                c.report.intersection.is_none(),
                "radius {r}, lean {lean}: {:?}",
                c.report.summary()
            );
        }
    }

    #[test]
    fn compression_is_the_largest_factor_that_clears_within_one_percent() {
        let s = sample_surface(&closing_c()).unwrap();
        let c = correct(&s).unwrap();
        let f = c.report.intersection.as_ref().unwrap().compression;
        // 1 % more compression-free offset meets itself again.
        let mut more = s.clone();
        scale_offsets(&mut more, &s, (f + 0.01).min(1.0));
        support_free(&mut more, &[]);
        assert!(
            find_self_intersection(&more).is_some(),
            "{f} is not the largest"
        );
    }

    #[test]
    fn a_normal_offset_larger_than_a_bend_radius_is_a_fold() {
        // A half circle of radius 10 drawn counter-clockwise, so its normal
        // (to the left) points to the centre; the profiles lean 15 mm
        // toward it at the top. Past an offset of about 10 mm the wall
        // folds, so the compression is at most 10/15; the U's two sides
        // also touch once its radius is under half a bead (10 − ξ < 3),
        // which asks for 7/15.
        let d = design(
            "[[0,0],[5,14],[10,28],[15,42]]",
            "[[0,0],[5,14],[10,28],[15,42]]",
            r#"{"control_points":[[10,0],[9.659,2.588],[8.660,5],[7.071,7.071],[5,8.660],[2.588,9.659],[0,10],[-2.588,9.659],[-5,8.660],[-7.071,7.071],[-8.660,5],[-9.659,2.588],[-10,0]],"offset":"normal"}"#,
        );
        let s = sample_surface(&d).unwrap();
        assert!(find_fold(&s).is_some());
        let c = correct(&s).unwrap();
        let x = c.report.intersection.as_ref().expect("a fold is corrected");
        assert!(
            x.compression <= 10.0 / 15.0 && x.compression > 0.4,
            "compressed to {}",
            x.compression
        );
        assert!(find_fold(&c.surface).is_none());
        assert!(find_self_intersection(&c.surface).is_none());
        // The fold alone: at 0.9 of the offset (13.5 mm) it is there, at
        // 0.5 (7.5 mm) not.
        for (f, folds) in [(0.9, true), (0.5, false)] {
            let mut t = s.clone();
            scale_offsets(&mut t, &s, f);
            assert_eq!(find_fold(&t).is_some(), folds, "at {f}");
        }
    }

    /// The plain definition: every pair of points, far apart along Ψ.
    fn brute_force(s: &Surface) -> bool {
        let w = s.params.width_max;
        let far = ((2.0 * w) / s.spacing).ceil() as usize;
        // Far apart along Ψ, closer than w, and far apart along the pass
        // that lays them (a converging surface is no contact).
        let pts: Vec<(usize, usize, [f64; 3])> = s
            .columns
            .iter()
            .enumerate()
            .flat_map(|(c, col)| col.samples().map(move |i| (c, i - col.first as usize)))
            .map(|(c, k)| (c, k, s.position(c, s.columns[c].first as usize + k)))
            .collect();
        find_fold(s).is_some()
            || pts.iter().any(|(a, k, p)| {
                pts.iter().any(|(b, _, q)| {
                    *b > a + far
                        && (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)
                            < w * w
                        && pass_apart(s, *a, *b, *k, w)
                })
            })
    }

    #[test]
    fn segment_filter_agrees_with_every_pair() {
        // Half circles of shrinking radius with profiles leaning in: from
        // far apart to meeting themselves.
        for (r, lean) in [
            (30.0, 5.0),
            (20.0, 10.0),
            (20.0, 15.0),
            (12.0, 4.0),
            (9.0, 0.0),
            (40.0, 35.0),
        ] {
            let d = design(
                &format!("[[0,0],[{},10],[{},20]]", -lean / 2.0, -lean),
                &format!("[[0,0],[{},10],[{},20]]", -lean / 2.0, -lean),
                &format!(r#"{{"control_points":[[{r},0],[{r},{r}],[-{r},{r}],[-{r},0]]}}"#),
            );
            let Ok(s) = sample_surface(&d) else { continue };
            assert_eq!(
                find_self_intersection(&s).is_some(),
                brute_force(&s),
                "radius {r}, lean {lean}"
            );
        }
    }

    #[test]
    fn trajectory_too_tight_is_an_error() {
        let d = design(
            "[[0,0],[0,20]]",
            "[[0,0],[0,20]]",
            r#"{"points":[[10,40],[60,40],[60,43],[10,43]]}"#,
        );
        let s = sample_surface(&d).unwrap();
        let e = correct(&s).unwrap_err().to_string();
        assert!(e.contains("within one bead width"), "{e}");
    }
}
