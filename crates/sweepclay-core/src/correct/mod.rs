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

mod contact;
mod report;
mod support;
mod texture;

use crate::error::{Error, Result};
use crate::surface::Surface;
use contact::find_self_intersection;
#[cfg(test)]
use contact::{find_fold, pass_apart};
pub use report::{CorrectionReport, CurveId, Deviation, IntersectionFix, SupportFix};
use support::support_free;
use texture::keep_texture;

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
    /// The floor is laid blended, not flush ([`Tightening::blended_floor`]).
    pub blended_floor: bool,
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
    /// Lay the floor's outermost turn from half a pitch outside the foot
    /// over a whole turn, not as stepped rings flush with the wall: the
    /// loop's answer when the wall's first turn does not rest on the
    /// stepped floor's step (docs/ALGORITHMS.md §8, "A flush foot").
    pub blended_floor: bool,
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
    // A correction at one curve spreads to its neighbours, fading by at
    // most FAIR_PER_MM a millimetre along Ψ: a column pulled in alone
    // left a notch (or a fin where its neighbours followed the drawing);
    // whatever the spreading leaves steeper than the limit is corrected
    // again.
    if fair(&mut out, surface, FAIR_PER_MM) {
        let again = support_free(&mut out, scale);
        for f in again {
            if !support.iter().any(|g| g.curve == f.curve) {
                support.push(f);
            }
        }
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
        blended_floor: tight.blended_floor,
    })
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

/// How fast a correction fades along Ψ (mm of correction a mm): a 6 mm
/// correction reaches 60 mm to either side.
const FAIR_PER_MM: f64 = 0.1;

/// Spreads each sample's correction (its offset less the design's) to
/// the same sample of the neighbouring curves, fading by `per_mm` a
/// millimetre along Ψ (round a loop, both ways): no correction changes
/// faster along the wall than that. Returns whether any moved.
fn fair(out: &mut Surface, design: &Surface, per_mm: f64) -> bool {
    let n = out.columns.len();
    if n < 2 {
        return false;
    }
    let closed = out.vessel.is_some();
    let step = per_mm * out.spacing;
    let mut c: Vec<f64> = out
        .samples
        .iter()
        .zip(&design.samples)
        .map(|(o, d)| o.xi - d.xi)
        .collect();
    if c.iter().all(|x| x.abs() < 1e-9) {
        return false;
    }
    let mut moved = false;
    let mut relax = |c: &mut Vec<f64>, a: usize, b: usize| {
        let (ca, cb) = (&out.columns[a], &out.columns[b]);
        for m in 0..ca.len().min(cb.len()) {
            let (i, j) = (ca.first as usize + m, cb.first as usize + m);
            let want = c[i].abs() - step;
            if want > c[j].abs() + 1e-9 && (c[j] == 0.0 || c[j].signum() == c[i].signum()) {
                c[j] = want.copysign(c[i]);
                moved = true;
            }
        }
    };
    for _ in 0..if closed { 2 } else { 1 } {
        for k in 1..n + usize::from(closed) {
            relax(&mut c, (k - 1) % n, k % n);
        }
        for k in (0..n - 1 + usize::from(closed)).rev() {
            relax(&mut c, (k + 1) % n, k);
        }
    }
    if moved {
        for ((o, d), x) in out.samples.iter_mut().zip(&design.samples).zip(&c) {
            o.xi = d.xi + x;
        }
    }
    moved
}

/// Sets every offset to `c` times the design's.
fn scale_offsets(out: &mut Surface, design: &Surface, c: f64) {
    for (o, d) in out.samples.iter_mut().zip(&design.samples) {
        o.xi = c * d.xi;
    }
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
