//! Keeping a texture within the clay's limits (docs/ALGORITHMS.md §11):
//! the share of each sample's texture the overhang and overlap allow,
//! smoothed so the kept texture fades rather than steps.

use super::contact::find_self_intersection;
use crate::surface::Surface;

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
pub(super) fn keep_texture(
    s: &mut Surface,
    scale: &[f64],
) -> (Vec<f64>, Vec<crate::texture::TextureFix>) {
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
    let textured = d.iter().filter(|v| v.abs() > 0.01).count();
    (a, report(items, &s.texture_label.0, gap, textured))
}
