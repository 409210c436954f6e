//! A twist found in a mesh (docs/MESHES.md, "Twist"): a cross-section
//! that turns about o as it rises is the design's `twist_deg`. Each
//! section's shape round o (its distance from o at every whole degree)
//! is matched against the one about a millimetre below it; the turns add
//! up to each section's angle, and the twist is the least-squares line
//! of those angles against the design's own turn, which runs from the
//! floor's top to the rim: its slope the twist, its intercept the angle
//! the design's loop is turned by. A few fits of the untwisted sections
//! round that estimate keep the twist whose sweep lies closest to the
//! mesh.

use super::*;
use crate::design::{Params, DEFAULT_FLOOR_LAYERS};

/// Where the fitted design's twist starts (mm): it stands untwisted
/// through its floor's layers, which the design's default parameters
/// make two of 1.25 mm (docs/FORMATS.md, `twist_deg`).
pub(super) fn twist_base() -> f64 {
    f64::from(DEFAULT_FLOOR_LAYERS) * Params::default().layer_height
}

/// The design's turn at height `z` for a twist of `tau` radians over a
/// wall `height` tall: linear from [`twist_base`] to the top.
pub(super) fn turn_at(tau: f64, z: f64, height: f64) -> f64 {
    let base = twist_base();
    tau * ((z - base) / (height - base).max(1e-9)).clamp(0.0, 1.0)
}

/// The sections' loops turned back by `turn0` and the design's turn at
/// their heights: what a twisted sweep's sections are before its twist.
pub(super) fn untwisted(
    loops: &[Vec<Vec<[f64; 2]>>],
    zs: &[f64],
    (turn0, tau): (f64, f64),
    height: f64,
) -> Vec<Vec<Vec<[f64; 2]>>> {
    loops
        .iter()
        .zip(zs)
        .map(|(sec, &z)| {
            let back = (-turn0 - turn_at(tau, z, height)).sin_cos();
            sec.iter()
                .map(|l| l.iter().map(|&p| turn_by(p, back)).collect())
                .collect()
        })
        .collect()
}

/// Rays of a shape's signature, one a degree.
const SIGNATURE: usize = 360;
/// The most a section may turn from the one compared below it (degrees):
/// half a six-lobed loop's period, so a lobe is never taken for its
/// neighbour.
const MOST_STEP_DEG: i32 = 29;
/// The distance between the sections compared (mm).
const STEP_MM: f64 = 1.0;

/// A loop's distance from o at each whole degree, its farthest crossing
/// (linear between the loop's points, which lie 0.4 mm apart); `None`
/// when a degree has no crossing (a loop that does not go round o).
fn signature(l: &[[f64; 2]]) -> Option<Vec<f64>> {
    let step = std::f64::consts::TAU / SIGNATURE as f64;
    let mut sig = vec![f64::NAN; SIGNATURE];
    for i in 0..l.len() {
        let (p, q) = (l[i], l[(i + 1) % l.len()]);
        let a0 = p[1].atan2(p[0]);
        let mut da = q[1].atan2(q[0]) - a0;
        if da > std::f64::consts::PI {
            da -= std::f64::consts::TAU;
        } else if da < -std::f64::consts::PI {
            da += std::f64::consts::TAU;
        }
        let (lo, hi) = if da >= 0.0 {
            (a0, a0 + da)
        } else {
            (a0 + da, a0)
        };
        let (r0, r1) = (p[0].hypot(p[1]), q[0].hypot(q[1]));
        let mut k = (lo / step).ceil() as i64;
        while (k as f64) * step <= hi {
            let t = if da.abs() > 1e-15 {
                ((k as f64) * step - a0) / da
            } else {
                0.0
            };
            let r = r0 + t.clamp(0.0, 1.0) * (r1 - r0);
            let slot = &mut sig[k.rem_euclid(SIGNATURE as i64) as usize];
            if slot.is_nan() || r > *slot {
                *slot = r;
            }
            k += 1;
        }
    }
    if sig.iter().any(|r| r.is_nan()) {
        return None;
    }
    let mean = sig.iter().sum::<f64>() / SIGNATURE as f64;
    Some(sig.into_iter().map(|r| r - mean).collect())
}

/// How far `b` is turned from `a` (radians, counter-clockwise): the
/// shift of the best circular correlation within [`MOST_STEP_DEG`],
/// refined between degrees by a parabola through the peak.
fn turn_between(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as i32;
    let corr = |s: i32| -> f64 {
        (0..n)
            .map(|i| a[i as usize] * b[(i + s).rem_euclid(n) as usize])
            .sum()
    };
    let (best, _) = (-MOST_STEP_DEG..=MOST_STEP_DEG)
        .map(|s| (s, corr(s)))
        .max_by(|x, y| x.1.total_cmp(&y.1))
        .expect("shifts");
    let (l, m, r) = (corr(best - 1), corr(best), corr(best + 1));
    let den = l - 2.0 * m + r;
    let frac = if den < 0.0 {
        (0.5 * (l - r) / den).clamp(-0.5, 0.5)
    } else {
        0.0
    };
    (f64::from(best) + frac).to_radians() * 360.0 / SIGNATURE as f64
}

/// How the sections' shapes turn: each compared section's height and
/// angle from the foot (radians, counter-clockwise).
#[derive(Clone, Debug)]
pub(super) struct Turns {
    heights: Vec<f64>,
    angles: Vec<f64>,
    height: f64,
}

impl Turns {
    /// The angle the design's loop is turned by for a twist `tau`: the
    /// mean of what the design's turn leaves of the sections' angles
    /// above its floor's top. A mesh that turns from its foot is turned
    /// there already, where the design stands untwisted.
    pub(super) fn turn0(&self, tau: f64) -> f64 {
        let (sum, n) = self
            .heights
            .iter()
            .zip(&self.angles)
            .filter(|(&z, _)| z > twist_base())
            .fold((0.0, 0usize), |(s, n), (&z, &a)| {
                (s + a - turn_at(tau, z, self.height), n + 1)
            });
        sum / n.max(1) as f64
    }

    /// The twist (radians) that, with its [`Turns::turn0`], fits the
    /// angles above the floor's top best (least squares); `None` for a
    /// turn under half a degree.
    pub(super) fn twist(&self) -> Option<f64> {
        let pts: Vec<(f64, f64)> = self
            .heights
            .iter()
            .zip(&self.angles)
            .filter(|(&z, _)| z > twist_base())
            .map(|(&z, &a)| (turn_at(1.0, z, self.height), a))
            .collect();
        let n = pts.len() as f64;
        if n < 2.0 {
            return None;
        }
        let (mw, ma) = pts
            .iter()
            .fold((0.0, 0.0), |(w, a), p| (w + p.0 / n, a + p.1 / n));
        let (num, den) = pts.iter().fold((0.0, 0.0), |(u, v), p| {
            (u + (p.0 - mw) * (p.1 - ma), v + (p.0 - mw).powi(2))
        });
        let tau = num / den.max(1e-12);
        (tau.abs() >= 0.5f64.to_radians()).then_some(tau)
    }
}

/// How the sections' shapes turn round o, one section about every
/// [`STEP_MM`]; `None` for a loop too round to show a turn (its shape's
/// spread round o under 0.2 mm).
pub(super) fn turns(loops: &[Vec<Vec<[f64; 2]>>], zs: &[f64], height: f64) -> Option<Turns> {
    let stride = ((STEP_MM / (zs.get(1)? - zs[0]).max(1e-9)).round() as usize).max(1);
    let mut prev: Option<Vec<f64>> = None;
    let mut t = Turns {
        heights: Vec::new(),
        angles: Vec::new(),
        height,
    };
    let mut angle = 0.0;
    for k in (0..zs.len()).step_by(stride) {
        let sig = signature(wall_loop(&loops[k]))?;
        let spread = sig.iter().fold(0.0f64, |m, r| m.max(r.abs()));
        if spread < 0.2 {
            return None;
        }
        if let Some(p) = &prev {
            angle += turn_between(p, &sig);
        }
        prev = Some(sig);
        t.heights.push(zs[k]);
        t.angles.push(angle);
    }
    Some(t)
}

/// The closest twisted sweep (docs/MESHES.md, "Twist"): the twist the
/// sections' shapes turn by ([`twist::turns`]), then a golden-section
/// search within 12 % of it for the twist whose untwisted sections the
/// closest sweep fits best, fitted again on every section in the frame
/// the estimate fitted best. `None` for a loop that shows no turn.
pub(super) fn twisted(psi: &[[f64; 2]], secs: &Sections) -> Option<Candidate> {
    let Sections {
        zs, loops, height, ..
    } = *secs;
    let turns = turns(loops, zs, height)?;
    let tau = turns.twist()?;
    // Ψ is the foot's wall as the untwisted fit found it: the design
    // turns it by `turn0` and its twist, so the sections turned back by
    // both lie on it above the floor's top. Where the mesh turns from its
    // foot, the foot turned back by `turn0` is off Ψ: what the relief
    // takes.
    let fit_at = |t: f64, frames: &[Offset], every: usize| -> Option<Candidate> {
        let zs: Vec<f64> = zs.iter().copied().step_by(every).collect();
        let loops: Vec<_> = loops.iter().step_by(every).cloned().collect();
        let turn0 = turns.turn0(t);
        let back = untwisted(&loops, &zs, (turn0, t), height);
        let turned = Sections {
            zs: &zs,
            loops: &back,
            ..*secs
        };
        let mut c = closest_in((frames, true), psi, &turned).ok()?;
        c.twist = (turn0, t);
        Some(c)
    };
    // The search reads every eighth section in the frame the estimate
    // fits best, and weighs how far the sections, turned back, are from
    // the foot's loop moved out or in: the offsets' spread round each
    // section (their root mean square about its mean), above a millimetre
    // over the floor's top. It needs no curves (a fit's curves and its
    // two profiles' blend take up part of a wrong twist, unevenly from
    // one twist to the next), and it runs smoothly with the twist.
    let frame = fit_at(tau, &[Offset::Radial, Offset::Normal], 8)?.offset;
    let sub: Vec<usize> = (0..zs.len())
        .step_by(8)
        .filter(|&k| zs[k] > twist_base() + 1.0)
        .collect();
    let dev = |t: f64| -> f64 {
        let zs: Vec<f64> = sub.iter().map(|&k| zs[k]).collect();
        let loops: Vec<_> = sub.iter().map(|&k| loops[k].clone()).collect();
        let back = untwisted(&loops, &zs, (turns.turn0(t), t), height);
        let Ok((d, _, _)) = offsets(psi, &zs, &back, frame, secs.fold) else {
            return f64::INFINITY;
        };
        let (sum, n) = d.iter().fold((0.0, 0usize), |(sum, n), row| {
            let m = row.iter().sum::<f64>() / row.len() as f64;
            (
                sum + row.iter().map(|v| (v - m).powi(2)).sum::<f64>(),
                n + row.len(),
            )
        });
        (sum / n.max(1) as f64).sqrt()
    };
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut a, mut b) = (tau * 0.88, tau * 1.12);
    let (mut x1, mut x2) = (b - g * (b - a), a + g * (b - a));
    let (mut f1, mut f2) = (dev(x1), dev(x2));
    let mut best = (dev(tau), tau);
    // Seven narrowings leave a thirtieth of the bracket: under 0.4 % of
    // the twist.
    for _ in 0..7 {
        best = lower(lower(best, (f1, x1)), (f2, x2));
        if f1 <= f2 {
            (b, x2, f2) = (x2, x1, f1);
            x1 = b - g * (b - a);
            f1 = dev(x1);
        } else {
            (a, x1, f1) = (x1, x2, f2);
            x2 = a + g * (b - a);
            f2 = dev(x2);
        }
    }
    best = lower(lower(best, (f1, x1)), (f2, x2));
    fit_at(best.1, &[frame], 1)
}

/// The pair of lower deviation (the first of equal ones).
fn lower(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    if b.0 < a.0 {
        b
    } else {
        a
    }
}

/// Whether the design's own rules take the fitted twist: one that leans
/// the wall across itself beyond the overhang limit is refused by
/// `twist_deg`, and the mesh is fitted untwisted instead.
pub(super) fn holds(c: &Candidate) -> bool {
    let Ok(d) = Design::from_json(&c.json("twist")) else {
        return false;
    };
    !matches!(
        crate::surface::sample_surface(&d),
        Err(Error::Invalid { ref key, .. }) if key == "twist_deg"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(a0: f64) -> Vec<[f64; 2]> {
        (0..400)
            .map(|i| {
                let a = std::f64::consts::TAU * f64::from(i) / 400.0;
                let t = a - a0;
                let r = 30.0 / t.cos().abs().max(t.sin().abs());
                [r * a.cos(), r * a.sin()]
            })
            .collect()
    }

    #[test]
    fn a_square_turned_by_seven_degrees_is_found_turned_by_them() {
        let (a, b) = (
            signature(&square(0.0)).unwrap(),
            signature(&square(7.3f64.to_radians())).unwrap(),
        );
        let t = turn_between(&a, &b).to_degrees();
        assert!((t - 7.3).abs() < 0.1, "{t}");
        let t = turn_between(&b, &a).to_degrees();
        assert!((t + 7.3).abs() < 0.1, "{t}");
    }

    #[test]
    fn a_square_turning_from_its_foot_is_a_twist_from_the_floor_turned() {
        // Turning 30° from z = 0 to 60 is, above the floor's top, a twist
        // of 30° · 57.5 / 60 from it on a loop turned by 30° · 2.5 / 60.
        let h = 60.0;
        let zs: Vec<f64> = (0..240).map(|k| 0.125 + 0.25 * f64::from(k)).collect();
        let loops: Vec<Vec<Vec<[f64; 2]>>> = zs
            .iter()
            .map(|&z| vec![square(30f64.to_radians() * z / h)])
            .collect();
        let turns = turns(&loops, &zs, h).unwrap();
        let t = turns.twist().unwrap();
        assert!((t.to_degrees() - 28.75).abs() < 0.3, "{}", t.to_degrees());
        let t0 = turns.turn0(t).to_degrees();
        assert!((t0 - 1.25).abs() < 0.1, "{t0}");
    }

    #[test]
    fn a_circle_shows_no_turn() {
        let c: Vec<[f64; 2]> = (0..300)
            .map(|i| {
                let a = std::f64::consts::TAU * f64::from(i) / 300.0;
                [25.0 * a.cos(), 25.0 * a.sin()]
            })
            .collect();
        let zs: Vec<f64> = (0..40).map(|k| 0.25 + 0.5 * f64::from(k)).collect();
        let loops = vec![vec![c]; zs.len()];
        assert!(turns(&loops, &zs, 20.0).is_none());
    }

    #[test]
    fn a_square_turning_as_the_design_turns_gives_that_twist() {
        let h = 60.0;
        let zs: Vec<f64> = (0..240).map(|k| 0.125 + 0.25 * f64::from(k)).collect();
        let tau = 40f64.to_radians();
        let loops: Vec<Vec<Vec<[f64; 2]>>> = zs
            .iter()
            .map(|&z| vec![square(turn_at(tau, z, h))])
            .collect();
        let turns = turns(&loops, &zs, h).unwrap();
        let t = turns.twist().unwrap();
        assert!((t.to_degrees() - 40.0).abs() < 0.3, "{}", t.to_degrees());
        assert!(turns.turn0(t).to_degrees().abs() < 0.1);
        // Turned back, every section is the unturned square.
        let back = untwisted(&loops, &zs, (0.0, tau), h);
        for p in &back[200][0] {
            let a = p[1].atan2(p[0]);
            let r = 30.0 / a.cos().abs().max(a.sin().abs());
            assert!((p[0].hypot(p[1]) - r).abs() < 1e-6, "{p:?}");
        }
    }
}
