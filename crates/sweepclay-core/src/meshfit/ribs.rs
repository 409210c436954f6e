//! Ribs found in a mesh (docs/MESHES.md, "Ribs"): flutes (ribs
//! standing upright) and spirals (ribs that turn as they rise) are the
//! design's `flute` and `spiral` textures. What each section's offsets
//! change round the loop, less their mean, is read harmonic by harmonic
//! (the loop's arc length as the angle); the count whose harmonic holds
//! the most, over half of that change and at least [`LEAST_MM`] deep, is
//! the ribs. Its phase section by section says whether they stand (a
//! flute) or turn (a spiral, its pitch the phase's least-squares slope).
//! Rings (a ripple) change with height alone: the profile carries them.

use super::*;
use crate::texture::{Kind, TextureSpec};
use std::f64::consts::{PI, TAU};

/// The shallowest ribs taken as a texture (mm).
const LEAST_MM: f64 = 0.15;
/// The fewest ribs: fewer are the loop's own shape (an oval's two, a
/// trefoil's three), which two profiles blend.
const FEWEST: usize = 4;
/// The narrowest rib along the loop (mm): a texture needs 8 samples a
/// period, and narrower ribs would make the sampling too fine to plan.
const NARROWEST_MM: f64 = 4.0;
/// A turn of the phase over the wall's height under this (radians) is a
/// flute, not a spiral.
const STANDING: f64 = 0.5;

/// The ribs the offsets `d` (sections at `zs`, rays at arc-length
/// fractions `u` of a loop `perimeter` mm long, a wall `height` mm tall)
/// hold above `base`, if any: a flute or spiral texture, its phase from
/// u = 0 and z = 0, its depth where it is deepest, and its fades where
/// it is half as deep (a fade is half a cosine, half way up at half its
/// length).
pub(super) fn find(
    d: &[Vec<f64>],
    zs: &[f64],
    u: &[f64],
    (base, height): (f64, f64),
    perimeter: f64,
) -> Option<TextureSpec> {
    let jj = u.len();
    let rows: Vec<usize> = (0..zs.len()).filter(|&k| zs[k] > base + 0.5).collect();
    if rows.len() < 4 || jj < 16 {
        return None;
    }
    // Each ray's share of the loop (trapezoids, round the loop).
    let w: Vec<f64> = (0..jj)
        .map(|j| {
            let (a, b) = (u[(j + jj - 1) % jj], u[(j + 1) % jj]);
            0.5 * (b - a).rem_euclid(1.0)
        })
        .collect();
    let change: Vec<Vec<f64>> = rows
        .iter()
        .map(|&k| {
            let m = (0..jj).map(|j| d[k][j] * w[j]).sum::<f64>();
            d[k].iter().map(|v| v - m).collect()
        })
        .collect();
    let total: f64 = change
        .iter()
        .map(|e| e.iter().zip(&w).map(|(v, w)| v * v * w).sum::<f64>())
        .sum();
    let most = ((perimeter / NARROWEST_MM) as usize).min(jj / 4);
    // Each row's coefficient of harmonic n: Σ e(u) e^{−i 2π n u} du.
    let coeffs = |n: usize| -> Vec<(f64, f64)> {
        change
            .iter()
            .map(|e| {
                (0..jj).fold((0.0, 0.0), |(re, im), j| {
                    let (s, c) = (TAU * n as f64 * u[j]).sin_cos();
                    (re + e[j] * c * w[j], im - e[j] * s * w[j])
                })
            })
            .collect()
    };
    let (n, energy) = (FEWEST..=most)
        .map(|n| (n, coeffs(n).iter().map(|(a, b)| a * a + b * b).sum::<f64>()))
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    // A sine of amplitude A has ∫ e² = A²/2 and |c|² = A²/4.
    if 2.0 * energy < 0.5 * total {
        return None;
    }
    let c = coeffs(n);
    let depth: Vec<f64> = c.iter().map(|(a, b)| 2.0 * a.hypot(*b)).collect();
    // Its depth: the median of the middle half of the sections' (fades
    // and places the corrections kept less of lie at the ends).
    let mut mid: Vec<f64> = depth[depth.len() / 4..depth.len() * 3 / 4].to_vec();
    mid.sort_by(f64::total_cmp);
    let amplitude = mid[mid.len() / 2];
    if amplitude < LEAST_MM {
        return None;
    }
    let z_at = |i: usize| zs[rows[i]];
    let half = |i: &usize| depth[*i] >= 0.5 * amplitude;
    let fade_in = (0..depth.len())
        .find(half)
        .map_or(0.0, |i| 2.0 * (z_at(i) - base));
    let fade_out = (0..depth.len())
        .rev()
        .find(half)
        .map_or(0.0, |i| 2.0 * (height - z_at(i)));
    // A sin(θ + φ) has c = (A / 2i) e^{iφ}: φ = arg c + π/2, unwrapped
    // section by section.
    let mut phase: Vec<f64> = Vec::with_capacity(c.len());
    for (re, im) in &c {
        let p = im.atan2(*re) + 0.5 * PI;
        let p = match phase.last() {
            Some(&q) => q + (p - q + PI).rem_euclid(TAU) - PI,
            None => p,
        };
        phase.push(p);
    }
    let z: Vec<f64> = rows.iter().map(|&k| zs[k]).collect();
    let nf = z.len() as f64;
    let (mz, mp) = (z.iter().sum::<f64>() / nf, phase.iter().sum::<f64>() / nf);
    let (sxy, sxx) = z.iter().zip(&phase).fold((0.0, 0.0), |(a, b), (z, p)| {
        (a + (z - mz) * (p - mp), b + (z - mz).powi(2))
    });
    let slope = sxy / sxx.max(1e-12);
    let span = z[z.len() - 1] - z[0];
    // A fade under a millimetre is the sections' spacing, not a fade.
    let fade = |f: f64| if f < 1.0 { 0.0 } else { round(f, 10.0) };
    let mut spec: TextureSpec = serde_json::from_value(serde_json::json!({
        "kind": "flute",
        "amplitude": round(amplitude, 100.0),
        "count": n as f64,
        "fade_in": fade(fade_in),
        "fade_out": fade(fade_out),
    }))
    .expect("a flute");
    let start = if (slope * span).abs() < STANDING {
        mp
    } else {
        // sin(2π (n u + z / pitch) + φ): the phase rises 2π a pitch.
        spec.kind = Kind::Spiral;
        spec.pitch = Some(round(TAU / slope, 100.0));
        mp - slope * mz
    };
    spec.phase_deg = phase_deg(start.to_degrees());
    Some(spec)
}

/// `v` to the nearest 1/`k`.
fn round(v: f64, k: f64) -> f64 {
    (v * k).round() / k
}

/// A phase in degrees brought within −180 to 180, to a tenth.
fn phase_deg(a: f64) -> f64 {
    round((a + 180.0).rem_euclid(360.0) - 180.0, 10.0)
}

/// The candidate's fit again with ribs taken out of its offsets as the
/// design's texture ([`find`]): the ribs its offsets hold, and
/// those left in what it does not fit (where two profiles' blend took
/// up the loop's own change); the closer of the two fits, one profile
/// first. `None` where there are none.
pub(super) fn textured(b: &Candidate, zs: &[f64], height: f64, tol: f64) -> Option<Candidate> {
    let (u, perimeter) = places(&b.psi);
    let base = super::twist::twist_base();
    let refit = |spec: TextureSpec| -> Candidate {
        let field = crate::texture::Field::new(
            std::slice::from_ref(&spec),
            perimeter,
            height,
            true,
            1.0,
            1.0,
        );
        let d: Vec<Vec<f64>> =
            b.d.iter()
                .zip(zs)
                .map(|(row, &z)| {
                    row.iter()
                        .zip(&u)
                        .map(|(v, &u)| v - field.at(u, z, height, base))
                        .collect()
                })
                .collect();
        let mut c = fit_offsets(&b.psi, zs, &d, b.offset, height, tol);
        // The refit may start Ψ elsewhere (where its blend is 0): the
        // ribs' phase moves with it.
        let start = b.psi.iter().position(|p| *p == c.psi[0]).unwrap_or(0);
        let mut spec = spec;
        let turns = spec.count.unwrap_or(0.0) * u[start];
        spec.phase_deg = phase_deg(spec.phase_deg + 360.0 * turns);
        c.twist = b.twist;
        c.folds = b.folds;
        c.texture = Some(spec);
        c
    };
    [&b.d, &b.residual]
        .into_iter()
        .filter_map(|d| find(d, zs, &u, (base, height), perimeter))
        .map(refit)
        .min_by(|x, y| {
            let rank = |c: &Candidate| (c.deviation > tol, c.two, c.deviation);
            let (a, b) = (rank(x), rank(y));
            (a.0, a.1).cmp(&(b.0, b.1)).then(a.2.total_cmp(&b.2))
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn offsets(f: impl Fn(f64, f64) -> f64) -> (Vec<Vec<f64>>, Vec<f64>, Vec<f64>) {
        let u: Vec<f64> = (0..360).map(|j| f64::from(j) / 360.0).collect();
        let zs: Vec<f64> = (0..160).map(|k| 0.125 + 0.25 * f64::from(k)).collect();
        let d = zs
            .iter()
            .map(|&z| u.iter().map(|&u| f(u, z)).collect())
            .collect();
        (d, zs, u)
    }

    #[test]
    fn twelve_flutes_on_a_flaring_wall_are_found_with_their_phase() {
        let (d, zs, u) = offsets(|u, z| 0.1 * z + 1.2 * (TAU * 12.0 * u + 0.7).sin());
        let t = find(&d, &zs, &u, (2.5, 40.0), 250.0).unwrap();
        assert_eq!((t.kind, t.count), (Kind::Flute, Some(12.0)));
        assert!((t.amplitude - 1.2).abs() < 0.02, "{}", t.amplitude);
        assert!(
            (t.phase_deg - 0.7f64.to_degrees()).abs() < 1.0,
            "{}",
            t.phase_deg
        );
        // Read back as the design reads it.
        let f = crate::texture::Field::new(&[t], 250.0, 40.0, true, 1.0, 1.0);
        assert!((f.at(0.3, 10.0, 40.0, 2.5) - 1.2 * (TAU * 3.6 + 0.7).sin()).abs() < 0.03);
    }

    #[test]
    fn a_spiral_is_found_with_its_pitch() {
        let (d, zs, u) = offsets(|u, z| 0.8 * (TAU * (8.0 * u + z / 60.0) - 1.0).sin());
        let t = find(&d, &zs, &u, (2.5, 40.0), 250.0).unwrap();
        assert_eq!((t.kind, t.count), (Kind::Spiral, Some(8.0)));
        assert!((t.pitch.unwrap() - 60.0).abs() < 0.5, "{:?}", t.pitch);
        assert!(
            (t.phase_deg + 1f64.to_degrees()).abs() < 2.0,
            "{}",
            t.phase_deg
        );
    }

    #[test]
    fn an_oval_blend_or_a_shallow_wave_is_no_texture() {
        let (d, zs, u) = offsets(|u, z| 0.2 * z * (TAU * 2.0 * u).cos());
        assert!(find(&d, &zs, &u, (2.5, 40.0), 250.0).is_none());
        let (d, zs, u) = offsets(|u, _| 0.05 * (TAU * 10.0 * u).sin());
        assert!(find(&d, &zs, &u, (2.5, 40.0), 250.0).is_none());
    }
}
