//! How much of a texture the clay kept (docs/ALGORITHMS.md §11): the
//! amount kept smoothed between neighbours and capped by the overhang
//! limit, and the report of where it was reduced and on what share of
//! the wall.

use super::*;

/// Where a texture was kept at less than its full amplitude.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TextureFix {
    /// The textures (their labels).
    pub texture: String,
    /// The least amount kept there, 0–1.
    pub kept: f64,
    /// The share of the textured wall reduced here, 0–1 (samples with a
    /// texture to keep): the rest of the band may be kept whole, as the
    /// modeler's "texture kept" colouring shows it.
    pub share: f64,
    /// The heights between which it was reduced (mm).
    pub z_mm: [f64; 2],
    /// The normalised arc lengths between which it was reduced.
    pub u: [f64; 2],
    /// Why: `overhang` (the step from the bead below), `overlap` (the
    /// widest bead could not cover the step) or `self-intersection`.
    pub why: &'static str,
}

impl TextureFix {
    /// "ripple 2 mm reduced on 4 % of the wall, between z 40 and 55 mm, u
    /// 0.10–0.30, to 60 % at the least (1.2 mm of 2 mm): overhang". The
    /// share comes first: a band where a few spots lose the texture is not
    /// a band without it.
    pub fn summary(&self, peak: f64) -> String {
        format!(
            "texture {} reduced on {} of the wall, between z {:.0} and {:.0} mm, u {:.2}–{:.2}, to {:.0} % at the least ({} mm of {} mm): {}",
            self.texture,
            percent(self.share),
            self.z_mm[0],
            self.z_mm[1],
            self.u[0],
            self.u[1],
            100.0 * self.kept,
            fmt_mm(self.kept * peak),
            fmt_mm(peak),
            self.why
        )
    }
}

/// A share as a percentage that never rounds a reduction away: "0.4 %"
/// below 1 %, whole percent above.
pub(super) fn percent(share: f64) -> String {
    let p = 100.0 * share;
    if p < 1.0 {
        format!("{p:.1} %")
    } else {
        format!("{p:.0} %")
    }
}

/// Spreads caps so neighbouring values differ by at most [`MAX_A_STEP`]:
/// a(s) = min over samples of cap + [`MAX_A_STEP`] per step between
/// them. Lowers `a` in place from the samples `seeds` (those lowered
/// since `a` was last spread; all of them the first time), each lowering
/// passed on to the neighbours it lowers: a work list, so a second
/// spread after a few caps fall costs only what they change.
/// Returns the samples it lowered, the seeds among them.
pub fn smooth(
    a: &mut [f64],
    neighbours: &[[u32; 4]],
    seeds: impl IntoIterator<Item = usize>,
) -> Vec<usize> {
    let mut queued = vec![false; a.len()];
    let mut work: std::collections::VecDeque<usize> = seeds
        .into_iter()
        .filter(|&s| !std::mem::replace(&mut queued[s], true))
        .collect();
    let mut changed: Vec<usize> = work.iter().copied().collect();
    while let Some(s) = work.pop_front() {
        queued[s] = false;
        let lim = a[s] + MAX_A_STEP;
        for &nb in &neighbours[s] {
            if nb == u32::MAX {
                continue;
            }
            let nb = nb as usize;
            if a[nb] > lim + 1e-12 {
                a[nb] = lim;
                changed.push(nb);
                if !queued[nb] {
                    queued[nb] = true;
                    work.push_back(nb);
                }
            }
        }
    }
    changed
}

/// The largest a ∈ [0, 1] with |b + a · d| ≤ `limit`, given |b| ≤ limit.
pub fn cap(b: f64, d: f64, limit: f64) -> f64 {
    if (b + d).abs() <= limit + 1e-12 {
        return 1.0;
    }
    let a = if d > 0.0 {
        (limit - b) / d
    } else if d < 0.0 {
        (limit + b) / -d
    } else {
        1.0
    };
    a.clamp(0.0, 1.0)
}

/// Groups the samples kept below full amplitude into reports: sorted by
/// height, a new group where two reduced samples are more than `gap` mm
/// apart in height; each group names the commonest reason and its share
/// of the `textured` samples (those with a texture to keep). `items` are
/// (z, u, a, why).
pub fn report(
    mut items: Vec<(f64, f64, f64, &'static str)>,
    label: &str,
    gap: f64,
    textured: usize,
) -> Vec<TextureFix> {
    items.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out: Vec<(TextureFix, [u32; 3])> = Vec::new();
    let mut last_z = f64::NEG_INFINITY;
    for (z, u, a, why) in items {
        if out.is_empty() || z - last_z > gap {
            out.push((
                TextureFix {
                    texture: label.to_string(),
                    kept: a,
                    share: 0.0,
                    z_mm: [z, z],
                    u: [u, u],
                    why,
                },
                [0; 3],
            ));
        }
        let (f, counts) = out.last_mut().expect("pushed");
        f.kept = f.kept.min(a);
        f.share += 1.0 / textured.max(1) as f64;
        f.z_mm[1] = z;
        f.u = [f.u[0].min(u), f.u[1].max(u)];
        counts[match why {
            "overhang" => 0,
            "overlap" => 1,
            _ => 2,
        }] += 1;
        last_z = z;
    }
    out.into_iter()
        .map(|(mut f, c)| {
            let best = (0..3).max_by_key(|&k| c[k]).unwrap_or(0);
            f.why = ["overhang", "overlap", "self-intersection"][best];
            f
        })
        .collect()
}
