//! Layering: which heights each transition curve is visited at, and by
//! which pass (paper §5.2, Algorithm 2; docs/ALGORITHMS.md §3). The full derivation
//! and the proofs of the invariants are in `docs/ALGORITHMS.md`.
//!
//! Columns (transition curves) are ordered from the short end (index 0) to
//! the tall end. With h the column's height, N' the number of "lower"
//! passes, T_k the tall column's k-th height (layers of δ_low up to pass N',
//! then of δ_up ≈ `layer_height`) and H_s the allowed height spread within
//! one pass, pass k would put column h at
//!
//! ```text
//! g_k(h) = max(min(k · h / N', T_k),  T_k − H_s)
//! ```
//!
//! Columns with `h ≤ T_N'` finish exactly on their top edge at pass N' (the
//! paper's lower stage, layers tilted between the two ends); taller columns
//! follow the tall column in flat layers T_k and the pass turns at the first
//! column whose top edge it reaches (the paper's upper stage and returning
//! points). The second term lifts lagging columns so that no pass spans more
//! than H_s.

use crate::design::{Params, COLLISION_MARGIN_MM};
use crate::error::{Error, Result};

/// Clay of the same pass this little above the nozzle tip, at the edge of
/// the extruder body's reach, is a graze on a rounded bead edge (mm).
const SAME_PASS_GRAZE_MM: f64 = 0.1;

/// The layering of one design.
#[derive(Clone, Debug, PartialEq)]
pub struct LayerPlan {
    /// K: number of passes (the tall column's layer count).
    pub passes: u32,
    /// N': passes of the lower (tilted) stage; equals `passes` for a single
    /// stage path.
    pub lower_passes: u32,
    /// δ_low: layer height of the tall column in the lower stage (mm).
    pub lower_layer_mm: f64,
    /// δ_up: layer height of the upper stage (mm); equals `lower_layer_mm`
    /// for a single stage path.
    pub upper_layer_mm: f64,
    /// H_s: largest height difference allowed within one pass (mm).
    pub spread_mm: f64,
    /// Whether pass 1 runs from the short end toward the tall end.
    pub first_toward_tall: bool,
    /// Thinnest top-edge bead laid by a returning turn (mm).
    pub min_top_bead_mm: f64,
}

/// How one column is visited.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColumnLayers {
    /// Passes 1..=q visit the column.
    pub passes: u32,
    /// The last visit lands exactly on the top edge.
    pub exact_top: bool,
    /// Height of the top-edge bead a returning turn lays on it, if any.
    pub top_bead: Option<f64>,
}

impl LayerPlan {
    /// Whether the path has an upper stage with returning points.
    pub fn two_stage(&self) -> bool {
        self.passes > self.lower_passes
    }

    /// Whether pass `k` (1-based) runs toward the tall end.
    pub fn toward_tall(&self, k: u32) -> bool {
        (k % 2 == 1) == self.first_toward_tall
    }

    /// T_k: the tall column's height after pass `k`.
    pub fn tall(&self, k: u32) -> f64 {
        let n = self.lower_passes;
        if k <= n {
            k as f64 * self.lower_layer_mm
        } else {
            n as f64 * self.lower_layer_mm + (k - n) as f64 * self.upper_layer_mm
        }
    }

    /// g_k(h): the nominal height of pass `k` on a column of height `h`.
    pub fn nominal(&self, k: u32, h: f64) -> f64 {
        let t = self.tall(k);
        (k as f64 * h / self.lower_passes as f64)
            .min(t)
            .max(t - self.spread_mm)
    }

    fn eps(h: f64) -> f64 {
        1e-7 * h.max(1.0)
    }

    /// The height pass `k` visits a column of height `h` at (the top edge
    /// when the pass finishes the column exactly there).
    pub fn height(&self, k: u32, h: f64) -> f64 {
        let g = self.nominal(k, h);
        if (g - h).abs() <= Self::eps(h) {
            h
        } else {
            g
        }
    }

    /// Which passes visit a column of height `h`. A toward-tall pass (or the
    /// last pass) may finish a column exactly on its top edge; a
    /// toward-short pass only visits columns it leaves room above, and the
    /// returning turn that follows it lays their top-edge bead.
    pub fn column(&self, h: f64) -> ColumnLayers {
        let eps = Self::eps(h);
        let mut q = 0;
        let mut exact = false;
        for k in 1..=self.passes {
            let g = self.nominal(k, h);
            if self.toward_tall(k) || k == self.passes {
                if g > h + eps {
                    break;
                }
                q = k;
                if g >= h - eps {
                    exact = true;
                    break;
                }
            } else {
                if g >= h - eps {
                    break;
                }
                q = k;
            }
        }
        let top_bead = (!exact && q > 0 && q < self.passes && !self.toward_tall(q))
            .then(|| h.max(self.nominal(q, h) + self.min_top_bead_mm));
        ColumnLayers {
            passes: q,
            exact_top: exact,
            top_bead,
        }
    }

    /// Chooses the layering for columns of heights `h` (ordered short end
    /// first, non-decreasing), with the tallest columns within reach of the
    /// extruder body around each (see [`reach_max`]).
    ///
    /// Tries the paper's layering first (N' = ⌊h_short/Δz_min⌋ tilted
    /// passes, with an upper stage where the tall end needs one). Where the
    /// nozzle body would not clear the layer below (the slope condition),
    /// fewer tilted passes would thicken the short end's layers, so the next
    /// candidate is flat layers of about Δz_min from the bed up, the paper's
    /// upper stage throughout; only then fewer tilted passes (see
    /// `docs/ALGORITHMS.md`, "Choosing N'" and "slope condition").
    pub fn choose(h: &[f64], reach: &Reach, params: &Params) -> Result<LayerPlan> {
        let (dmin, dmax) = (params.layer_height, params.max_layer_height);
        let h_short = h[0];
        let h_tall = *h.last().expect("at least one column");
        let spread = params.nozzle_height - COLLISION_MARGIN_MM - dmax;
        let n = ((h_short / dmin + 1e-9).floor() as u32).max(1);
        let tilted = |lower: u32| (lower, dmax.min((h_short + spread) / f64::from(lower)));
        // Flat from the bed: one lower pass of Δz_min, then the upper stage.
        let flat = (n >= 2).then_some((1, dmin));
        let candidates = std::iter::once(tilted(n))
            .chain(flat)
            .chain((1..n).rev().map(tilted));
        let mut last_err = None;
        for (lower, cap) in candidates {
            let Some((k, low, up)) = Self::tall_layers(h_tall, lower, cap, dmin, dmax) else {
                last_err = Some(format!(
                    "the {h_tall:.2} mm tall end cannot be split into layers between {dmin} and {dmax} mm; raise params.max_layer_height"
                ));
                continue;
            };
            let plan = LayerPlan {
                passes: k,
                lower_passes: lower,
                lower_layer_mm: low,
                upper_layer_mm: up,
                spread_mm: spread,
                first_toward_tall: k == lower || lower % 2 == 1,
                min_top_bead_mm: 0.5 * dmin,
            };
            match plan.slope_violation(h, reach) {
                None => return Ok(plan),
                Some(at) => {
                    last_err = Some(format!(
                        "no layering keeps the extruder body clear of the layer below; the top edge rises too steeply near column {at}"
                    ))
                }
            }
        }
        Err(Error::Layering(last_err.unwrap_or_default()))
    }

    /// The tall column's layering for `lower` tilted passes whose tall-end
    /// layers are at most `cap`: `(K, δ_low, δ_up)`. With the paper's cap
    /// min(Δz_max, (h_short + H_s) / N') the lower stage reaches at most
    /// h_short + H_s (so its tilted passes span at most H_s); the rest is
    /// split into upper layers as close to Δz_min as divides it.
    fn tall_layers(
        h_tall: f64,
        lower: u32,
        cap: f64,
        dmin: f64,
        dmax: f64,
    ) -> Option<(u32, f64, f64)> {
        let n = lower as f64;
        if h_tall <= n * cap + 1e-9 {
            // Single stage: every column in N' tilted layers.
            let d = h_tall / n;
            return (d >= dmin - 1e-9 && d <= dmax + 1e-9).then_some((lower, d, d));
        }
        let mut low = cap;
        let mut rest = h_tall - n * low;
        if rest < dmin {
            // Leave one full upper layer.
            low = (h_tall - dmin) / n;
            rest = dmin;
        }
        let mut m = ((rest / dmin) + 1e-9).floor().max(1.0);
        let mut up = rest / m;
        if up > dmax + 1e-9 {
            m = (rest / dmax - 1e-9).ceil();
            up = rest / m;
        }
        let ok = low >= dmin - 1e-9 && low <= dmax + 1e-9 && up >= dmin - 1e-9 && up <= dmax + 1e-9;
        ok.then_some((lower + m as u32, low, up))
    }

    /// The first column where a pass would bring the nozzle lower than clay
    /// within reach of the body (the slope condition): the previous pass's
    /// clay at any column near in plan, or this pass's clay at columns near
    /// in plan but far along Ψ (round a sharp corner).
    fn slope_violation(&self, h: &[f64], reach: &Reach) -> Option<usize> {
        for (j, &hj) in h.iter().enumerate() {
            let (near, far) = (reach.near[j], reach.far[j]);
            if near <= hj && far <= hj {
                continue;
            }
            let q = self.column(hj).passes;
            for k in 1..=q {
                let mine = self.height(k, hj).min(hj);
                let previous = if k > 1 {
                    self.nominal(k - 1, near).min(near)
                } else {
                    0.0
                };
                // Only a pass toward the short end has laid its taller
                // columns before this one. A graze of ≤ 0.1 mm on a bead's
                // rounded edge is allowed (the checker allows 0.2 mm).
                let same = if far > f64::MIN && !self.toward_tall(k) {
                    self.nominal(k, far).min(far)
                } else {
                    f64::MIN
                };
                if previous > mine + 1e-9 || same > mine + SAME_PASS_GRAZE_MM {
                    return Some(j);
                }
            }
        }
        None
    }
}

/// The tallest columns within reach of each column's extruder body.
#[derive(Clone, Debug, PartialEq)]
pub struct Reach {
    /// Largest height among the columns within reach in plan (itself
    /// included): the clay of the previous pass the body can touch.
    pub near: Vec<f64>,
    /// Largest height among the columns within reach in plan but more than
    /// `exempt` columns away along Ψ (or `f64::MIN`): clay of the same pass
    /// laid long enough ago to count, round a sharp corner.
    pub far: Vec<f64>,
}

/// [`Reach`] for points evenly spaced along Ψ: `reach` is the body's reach
/// in plan (mm), `exempt` how many neighbours along Ψ count as just laid.
/// A grid of cells `reach` wide: linear time.
pub fn reach_max(points: &[[f64; 2]], h: &[f64], reach: f64, exempt: usize) -> Reach {
    let mut grid = crate::grid::Grid2::new(reach.max(1e-3));
    for (i, p) in points.iter().enumerate() {
        grid.insert_segment(*p, *p, i as u32);
    }
    let r2 = reach * reach;
    let mut near = Vec::with_capacity(points.len());
    let mut far = Vec::with_capacity(points.len());
    for (i, p) in points.iter().enumerate() {
        let (mut n, mut f) = (h[i], f64::MIN);
        grid.for_each_near_segment(*p, *p, reach, |j| {
            let q = points[j as usize];
            if (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) <= r2 {
                n = n.max(h[j as usize]);
                if (j as usize).abs_diff(i) > exempt {
                    f = f.max(h[j as usize]);
                }
            }
        });
        near.push(n);
        far.push(f);
    }
    Reach { near, far }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn heights(a: f64, b: f64, n: usize) -> Vec<f64> {
        (0..n)
            .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
            .collect()
    }

    /// The layering of columns 1.1 mm apart on a straight line.
    fn choose(h: &[f64], p: &Params) -> Result<LayerPlan> {
        let pts: Vec<[f64; 2]> = (0..h.len()).map(|i| [1.1 * i as f64, 0.0]).collect();
        LayerPlan::choose(h, &reach_max(&pts, h, 9.6, 9), p)
    }

    #[test]
    fn reach_is_measured_in_plan() {
        // A hairpin: the two arms 5 mm apart; the far arm is taller.
        let pts = [[0.0, 0.0], [20.0, 0.0], [20.0, 5.0], [0.0, 5.0]];
        let h = [1.0, 2.0, 3.0, 4.0];
        let r = reach_max(&pts, &h, 6.0, 1);
        assert_eq!(r.near, vec![4.0, 3.0, 3.0, 4.0]);
        assert_eq!(r.far, vec![4.0, f64::MIN, f64::MIN, 1.0]);
    }

    #[test]
    fn equal_heights_give_the_papers_single_stage() {
        let p = Params::default();
        let plan = choose(&heights(50.0, 50.0, 100), &p).unwrap();
        assert_eq!(plan.passes, 40, "⌊50 / 1.25⌋ = 40 passes");
        assert!(!plan.two_stage());
        let c = plan.column(50.0);
        assert_eq!(c.passes, 40);
        assert!(c.exact_top && c.top_bead.is_none());
        assert_eq!(plan.height(40, 50.0), 50.0);
        assert!((plan.height(1, 50.0) - 1.25).abs() < 1e-12);
    }

    #[test]
    fn small_difference_tilts_layers_between_the_ends() {
        let p = Params::default();
        let plan = choose(&heights(40.0, 50.0, 400), &p).unwrap();
        assert_eq!((plan.passes, plan.lower_passes), (32, 32));
        // Pass k at k/N of each column's height.
        assert!((plan.height(16, 40.0) - 20.0).abs() < 1e-12);
        assert!((plan.height(16, 50.0) - 25.0).abs() < 1e-12);
    }

    #[test]
    fn large_difference_needs_two_stages() {
        let p = Params::default();
        let h = heights(20.0, 60.0, 2000);
        let plan = choose(&h, &p).unwrap();
        assert!(plan.two_stage(), "{plan:?}");
        for d in [plan.lower_layer_mm, plan.upper_layer_mm] {
            assert!(d >= p.layer_height && d <= p.max_layer_height, "{plan:?}");
        }
        // The upper stage is printed near the minimum layer height, as in the paper.
        assert!(plan.upper_layer_mm < 1.5 * p.layer_height, "{plan:?}");
        assert!((plan.tall(plan.passes) - 60.0).abs() < 1e-9);
        // Pass N' runs toward the tall end, so the lower stage can finish.
        assert!(plan.toward_tall(plan.lower_passes));
        // Steps per column stay within bounds; the short end finishes on top.
        for &hj in h.iter().step_by(50) {
            let c = plan.column(hj);
            let mut last = 0.0;
            for k in 1..=c.passes {
                let z = plan.height(k, hj);
                let step = z - last;
                assert!(
                    step >= p.layer_height - 1e-9 && step <= p.max_layer_height + 1e-9,
                    "h = {hj}: pass {k} step {step}"
                );
                last = z;
            }
            assert!(
                hj - last < p.max_layer_height + 1e-9,
                "h = {hj}: {last} leaves a gap"
            );
        }
        assert!(plan.column(20.0).exact_top);
    }

    #[test]
    fn spread_within_a_pass_is_bounded() {
        let p = Params::default();
        let h = heights(10.0, 90.0, 3000);
        let plan = choose(&h, &p).unwrap();
        for k in 1..=plan.passes {
            let zs: Vec<f64> = h
                .iter()
                .filter(|&&hj| plan.column(hj).passes >= k)
                .map(|&hj| plan.height(k, hj))
                .collect();
            let (lo, hi) = zs
                .iter()
                .fold((f64::MAX, f64::MIN), |(a, b), &z| (a.min(z), b.max(z)));
            assert!(
                hi - lo <= plan.spread_mm + 1e-9,
                "pass {k}: spread {}",
                hi - lo
            );
        }
    }

    #[test]
    fn steep_top_edges_fall_back_to_flat_layers() {
        let p = Params::default();
        // 20 mm of rise over 22 mm of trajectory.
        let h = heights(30.0, 50.0, 21);
        let plan = choose(&h, &p).unwrap();
        // Flat layers of Δz_min from the bed: 1.25 mm, then 48.75 mm in 39
        // layers of 1.25 mm; no layer thicker than asked.
        assert_eq!(plan.lower_passes, 1, "{plan:?}");
        assert_eq!(plan.passes, 40, "{plan:?}");
        assert!((plan.lower_layer_mm - 1.25).abs() < 1e-12, "{plan:?}");
        assert!((plan.upper_layer_mm - 1.25).abs() < 1e-12, "{plan:?}");
        for &hj in &h {
            let c = plan.column(hj);
            let mut last = 0.0;
            for k in 1..=c.passes {
                let z = plan.height(k, hj);
                assert!((z - last - 1.25).abs() < 1e-9, "h = {hj}: pass {k} at {z}");
                last = z;
            }
        }
        let pts: Vec<[f64; 2]> = (0..h.len()).map(|i| [1.1 * i as f64, 0.0]).collect();
        assert!(plan
            .slope_violation(&h, &reach_max(&pts, &h, 9.6, 9))
            .is_none());
    }
}
