//! Uneven rims (docs/MESHES.md, "Uneven rims"): a wall with its
//! thickness, or a solid under a slanted cap, whose rim rises round the
//! loop, fitted along radial rays by two profiles of different heights
//! blended by the rim's own height, and, beyond the tolerance, the
//! wall's difference kept as a relief.

use super::*;
/// A shell (or, `solid`, a solid) whose rim rises round the loop
/// (docs/MESHES.md, "Uneven rims"): sections up to `whole` go round,
/// those above are the wall's higher parts. Along each radial ray the
/// bead's centre line, half a bead inside the wall's outside (where it
/// is not the cap across a solid's top), is found in every section it
/// reaches and the ray's rim height
/// H_j where it stops;
/// the design's two profiles of heights Z_s = min H and Z_t = max H are
/// blended by λ_j = (H_j − Z_s) / (Z_t − Z_s), at the same fraction of
/// each column's height (as the design's surface is: its offsets blend
/// at t = z / h_i), so the profiles are the regression of each height
/// fraction's offsets on λ.
pub(super) fn fit_uneven(
    cut: &[sections::Section],
    whole: usize,
    dz: f64,
    opts: &FitOptions,
    bed: f64,
    solid: bool,
) -> Result<Fitted> {
    let tol = opts.tolerance_mm;
    let (c, psi0) = foot_frame(cut);
    let jj = psi0.len();
    let zs: Vec<f64> = cut.iter().map(|s| s.z).collect();
    // Half a bead inside the outside along each ray in each section it
    // reaches.
    let mut d: Vec<Vec<Option<f64>>> = Vec::with_capacity(cut.len());
    // The bead's centre line half a bead inside the outside, along the
    // ray (docs/MESHES.md, "The outside is the pot"); the thickest wall.
    let half_bead = 0.5 * opts.bead_mm;
    let mut thick = 0.0f64;
    for (k, sec) in cut.iter().enumerate() {
        let loops = about(sec, c);
        let mut row = Vec::with_capacity(jj);
        for p in &psi0 {
            let r = p[0].hypot(p[1]).max(1e-9);
            let dir = [p[0] / r, p[1] / r];
            if solid {
                // Its outside is where the ray leaves the section last;
                // on a face lying level, that is the cap, above the rim.
                let far = sec
                    .loops
                    .iter()
                    .zip(&sec.up)
                    .filter_map(|(l, up)| {
                        crossings(l, c, dir)
                            .into_iter()
                            .rfind(|&(t, _)| t > 0.0)
                            .map(|(t, i)| (t, up[i]))
                    })
                    .max_by(|a, b| a.0.total_cmp(&b.0));
                row.push(match far {
                    Some((t, false)) => Some(t - half_bead - r),
                    // The cap, where it reaches lower than the section
                    // that starts it all round (a faceted dome's).
                    Some((_, true)) => None,
                    None if k >= whole => None,
                    _ => {
                        return Err(Error::invalid(
                            "mesh",
                            format!("is not a sweep of its foot's loop: its wall at z = {:.1} mm does not go round its foot's centre", zs[k]),
                        ))
                    }
                });
                continue;
            }
            let mut ts: Vec<f64> = loops
                .iter()
                .flat_map(|l| hits(l, [0.0, 0.0], dir))
                .filter(|&t| t > 0.0)
                .collect();
            ts.sort_by(f64::total_cmp);
            row.push(match ts.len() {
                2 => {
                    if k < whole {
                        thick = thick.max(ts[1] - ts[0]);
                    }
                    Some(ts[1] - half_bead - r)
                }
                // A shell's floor slab: its outside only.
                1 if k < whole => Some(ts[0] - half_bead - r),
                0 if k >= whole => None,
                n if k < whole => {
                    return Err(Error::invalid(
                        "mesh",
                        format!("is not a sweep of its foot's loop: its wall at z = {:.1} mm does not go once round its foot's centre (a ray from the centre meets it {n} times)", zs[k]),
                    ))
                }
                // A ray grazing the end of a higher part of the wall.
                _ => None,
            });
        }
        d.push(row);
    }
    // Ψ is the bead's centre line at the lowest section; D is from it.
    let base: Vec<f64> = d[0].iter().map(|v| v.unwrap_or(0.0)).collect();
    let psi: Vec<[f64; 2]> = (0..jj)
        .map(|j| {
            let p = psi0[j];
            let r = p[0].hypot(p[1]).max(1e-9);
            [p[0] * (1.0 + base[j] / r), p[1] * (1.0 + base[j] / r)]
        })
        .collect();
    for row in &mut d {
        for (v, b) in row.iter_mut().zip(&base) {
            if let Some(v) = v.as_mut() {
                *v -= b;
            }
        }
    }
    // Each ray's rim: the top of the highest section it reaches, with no
    // gap below it.
    let tops: Vec<usize> = (0..jj)
        .map(|j| {
            (0..d.len())
                .take_while(|&k| d[k][j].is_some())
                .last()
                .unwrap_or(0)
        })
        .collect();
    let fine = rim_between_sections(&tops, &zs);
    let mut rim = vec![0.0; jj];
    for j in 0..jj {
        let top = tops[j];
        if let Some(k) = (top + 1..d.len()).find(|&k| d[k][j].is_some()) {
            let p = psi[j];
            return Err(Error::invalid(
                "mesh",
                format!(
                    "has a gap in its wall near ({:.1}, {:.1}) mm between z = {:.1} and {:.1} mm (a window or a cut-out): one wall from the foot to the rim is a vessel",
                    p[0], p[1], zs[top], zs[k]
                ),
            ));
        }
        rim[j] = fine[j].unwrap_or(zs[top] + 0.5 * dz);
        // The top 3 mm under the rim are its lip: a rim's rounding, the
        // end caps where a rim rises (a ray there can cross a cap, not
        // the wall), a printed wall's last bead standing above its
        // design. Not measured, as a level rim's top 3 mm are not.
        for (k, row) in d.iter_mut().enumerate().skip(1) {
            if zs[k] > rim[j] - RIM_LIP_MM {
                row[j] = None;
            }
        }
    }
    let (zs_lo, zt_hi) = rim
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &h| {
            (a.min(h), b.max(h))
        });
    let top = zs[zs.len() - 1] + 0.5 * dz;
    if solid && top - zt_hi > RIM_LIP_MM {
        // A cap that rises well above the wall's highest rim is no
        // opening but a top closing over (a dome, a shoulder leaning in):
        // taking its wall alone would leave that top out unsaid.
        return Err(Error::invalid(
            "mesh",
            format!(
                "closes over its top: from z = {:.1} mm its faces turn within 26° of level and rise to {top:.1} mm, {:.1} mm above where its wall stops at the highest; a vessel is open at its rim (cut the mesh where its opening is)",
                cut[whole].z,
                top - zt_hi
            ),
        ));
    }
    // Ψ starts at the lowest rim: λ = 0 there.
    let j0 = (0..jj)
        .min_by(|&a, &b| rim[a].total_cmp(&rim[b]))
        .unwrap_or(0);
    let turn = |v: &[f64]| -> Vec<f64> { (0..jj).map(|j| v[(j0 + j) % jj]).collect() };
    let rim = turn(&rim);
    let psi: Vec<[f64; 2]> = (0..jj).map(|j| psi[(j0 + j) % jj]).collect();
    let d: Vec<Vec<Option<f64>>> = d
        .iter()
        .map(|row| (0..jj).map(|j| row[(j0 + j) % jj]).collect())
        .collect();
    let lambda: Vec<f64> = rim.iter().map(|h| (h - zs_lo) / (zt_hi - zs_lo)).collect();
    // The offsets at each fraction t of each column's height.
    let m = ((zt_hi / 0.5) as usize).clamp(20, MAX_SECTIONS);
    let column_at = |j: usize, z: f64| -> f64 {
        let ks: Vec<usize> = (0..d.len()).filter(|&k| d[k][j].is_some()).collect();
        let v = |k: usize| d[k][j].expect("some");
        let first = ks[0];
        let last = *ks.last().expect("a section");
        if z <= zs[first] {
            return v(first);
        }
        if z >= zs[last] {
            // The lip (not measured) goes on as the wall below it leans.
            let prev = ks[ks.len().saturating_sub(9)];
            if prev == last {
                return v(last);
            }
            let slope = (v(last) - v(prev)) / (zs[last] - zs[prev]);
            return v(last) + slope * (z - zs[last]);
        }
        let i = ks.partition_point(|&k| zs[k] <= z);
        let (a, b) = (ks[i - 1], ks[i]);
        let f = (z - zs[a]) / (zs[b] - zs[a]);
        v(a) + f * (v(b) - v(a))
    };
    let mean_l = lambda.iter().sum::<f64>() / jj as f64;
    let var_l = lambda
        .iter()
        .map(|l| (l - mean_l).powi(2))
        .sum::<f64>()
        .max(1e-12);
    let (mut sv, mut tv) = (Vec::with_capacity(m), Vec::with_capacity(m));
    for i in 0..m {
        let t = i as f64 / (m - 1) as f64;
        let y: Vec<f64> = (0..jj).map(|j| column_at(j, t * rim[j])).collect();
        let mean_y = y.iter().sum::<f64>() / jj as f64;
        let slope = (0..jj)
            .map(|j| (lambda[j] - mean_l) * (y[j] - mean_y))
            .sum::<f64>()
            / var_l;
        let a = mean_y - slope * mean_l;
        sv.push([a, t * zs_lo]);
        tv.push([a + slope, t * zt_hi]);
    }
    // λ sets the rim's height and blends the profiles: its error moves
    // either by it times their spread; within a third of the tolerance.
    let spread = sv
        .iter()
        .zip(&tv)
        .map(|(a, b)| (a[0] - b[0]).abs())
        .fold(zt_hi - zs_lo, f64::max)
        .max(1e-9);
    let (interp, peak) = interpolation_fewest(&lambda, tol / (3.0 * spread), true)
        .unwrap_or_else(|| (interpolation_through(&lambda), 1.0));
    // A curve that reaches the highest rim only with control points above
    // 1 blends toward an end profile that far beyond (the surface is
    // linear in λ, so it is the same surface): the end profile taller by
    // that share of the spread, λ divided by it.
    let zt_hi = zs_lo + peak * (zt_hi - zs_lo);
    for (i, (a, b)) in sv.iter().zip(tv.iter_mut()).enumerate() {
        b[0] = a[0] + peak * (b[0] - a[0]);
        b[1] = i as f64 / (m - 1) as f64 * zt_hi;
    }
    let start = profile_through(&sv, tol);
    let end = profile_through(&tv, tol);
    // The design as it will be sampled, against every offset found.
    let (sp, ep) = (dense(&start), dense(&end));
    let lc = BSpline::clamped(interp.clone())
        .expect("points")
        .flatten(16);
    // The rims' heights and the wall's offsets apart: a relief can take
    // the wall's difference, not a rim's height.
    let mut rim_worst = (0.0f64, [0.0; 3]);
    let mut wall_worst = (0.0f64, [0.0; 3]);
    let mut residual = vec![vec![0.0; jj]; d.len()];
    for j in 0..jj {
        let l = at_x(&lc, j as f64 / jj as f64);
        let h = (1.0 - l) * zs_lo + l * zt_hi;
        // The rim's height is known to half a section.
        let high = ((h - rim[j]).abs() - 0.5 * dz).max(0.0);
        if high > rim_worst.0 {
            rim_worst = (high, [psi[j][0], psi[j][1], rim[j]]);
        }
        let mut held = 0.0;
        for (k, v) in d.iter().enumerate() {
            // Above what was measured (the lip, the rim), the relief
            // holds the last difference found below.
            let Some(v) = v[j] else {
                residual[k][j] = held;
                continue;
            };
            let t = (zs[k] / h).min(1.0);
            let fitted = (1.0 - l) * at_z(&sp, t * zs_lo) + l * at_z(&ep, t * zt_hi);
            held = v - fitted;
            residual[k][j] = held;
            let e = (fitted - v).abs();
            if e > wall_worst.0 {
                wall_worst = (e, [psi[j][0], psi[j][1], zs[k]]);
            }
        }
    }
    let worst = if rim_worst.0 >= wall_worst.0 {
        rim_worst
    } else {
        wall_worst
    };
    let cand = Candidate {
        folds: (0, None),
        fitted_loop: None,
        offset: Offset::Radial,
        two: true,
        psi,
        start,
        end,
        interp,
        deviation: worst.0,
        at: worst.1,
        residual,
        d: Vec::new(),
        texture: None,
        twist: (0.0, 0.0),
    };
    let sweep = (cand.deviation > tol && opts.relief && rim_worst.0 <= tol)
        .then_some((cand.deviation, cand.at));
    if cand.deviation > tol && sweep.is_none() {
        let why = if rim_worst.0 > tol {
            format!(
                "; its rim's height differs by {:.2} mm at ({:.1}, {:.1}, {:.1}) mm, which no relief takes",
                rim_worst.0, rim_worst.1[0], rim_worst.1[1], rim_worst.1[2]
            )
        } else {
            String::new()
        };
        return Err(Error::invalid(
            "mesh",
            format!(
                "is not a sweep of one loop within {tol} mm: the closest design (a loop, two profiles of {:.1} and {:.1} mm blended round it for its uneven rim, radial offsets) differs from it by {:.2} mm at ({:.1}, {:.1}, {:.1}) mm{why}",
                zs_lo, zt_hi, cand.deviation, cand.at[0], cand.at[1], cand.at[2]
            ),
        ));
    }
    let mut design = Design::from_json(&cand.json(&opts.name))?;
    design.name = opts.name.clone();
    let (mut deviation, mut at) = (cand.deviation, cand.at);
    if sweep.is_some() {
        let (relief, wall) = relief_of(&cand, &zs, dz, tol);
        design.relief = Some(relief);
        (deviation, at) = if rim_worst.0 >= wall.0 {
            rim_worst
        } else {
            wall
        };
    }
    Ok(Fitted {
        absorbed: None,
        inside: (thick - opts.bead_mm > THICKER_MM).then(|| {
            format!(
                "the wall is up to {:.1} mm thicker than a bead ({} mm): its outside is kept and its inside moves out by that much",
                thick - opts.bead_mm,
                opts.bead_mm
            )
        }),
        design,
        deviation_mm: deviation,
        at,
        kind: if solid { "solid" } else { "shell" },
        sections: cut.len(),
        moved: [-c[0], -c[1], -bed],
        sweep,
    })
}

/// Each ray's rim height between the sections, from where the rim
/// crosses them (docs/MESHES.md, "Uneven rims"): a ray reaching section
/// `top` but not the next has its rim somewhere in that section's
/// thickness, and read so a slanted rim is a staircase whose half-section
/// steps round the loop would tilt the spiral up and down a bead's
/// height within a few millimetres (the nozzle's body then meets the
/// clay just laid). Where neighbouring rays reach different sections the
/// rim crosses the levels between them half-way; each ray is read
/// linearly between those crossings, a peak or a valley (crossings of
/// one level on both sides) as a parabola leaving them as steeply as the
/// rim reached them, and always within the section its ray reaches.
/// `None` for a level rim (no crossing).
fn rim_between_sections(tops: &[usize], zs: &[f64]) -> Vec<Option<f64>> {
    let jj = tops.len();
    let level = |k: usize| zs[k.min(zs.len() - 1)];
    let dz = if zs.len() > 1 { zs[1] - zs[0] } else { 0.0 };
    let crossings: Vec<(f64, f64)> = (0..jj)
        .filter_map(|j| {
            let (a, b) = (tops[j], tops[(j + 1) % jj]);
            (a != b).then(|| {
                let (lo, hi) = (a.min(b), a.max(b));
                (j as f64 + 0.5, 0.5 * (level(lo + 1) + level(hi)))
            })
        })
        .collect();
    if crossings.is_empty() {
        return vec![None; jj];
    }
    let n = crossings.len();
    (0..jj)
        .map(|j| {
            let x = j as f64;
            // The crossings either side of the ray, round the loop.
            let i = crossings.partition_point(|c| c.0 < x);
            let (pa, ha) = if i == 0 {
                (crossings[n - 1].0 - jj as f64, crossings[n - 1].1)
            } else {
                crossings[i - 1]
            };
            let (pb, hb) = if i == n {
                (crossings[0].0 + jj as f64, crossings[0].1)
            } else {
                crossings[i]
            };
            let s = (x - pa) / (pb - pa);
            let mut h = ha + s * (hb - ha);
            if (ha - hb).abs() < 1e-9 {
                // A peak or a valley between crossings of one level: a
                // parabola leaving them as steeply as the rim reached
                // them (the crossings beyond, either side), within the
                // section.
                let (ia, ib) = ((i + n - 1) % n, i % n);
                let before = crossings[(ia + n - 1) % n];
                let after = crossings[(ib + 1) % n];
                let w = pb - pa;
                // A parabola's mean slope over a run beyond its crossing
                // is its slope there times (w + run) / w.
                let at = |h: f64, p: f64, q: f64| {
                    let run = (q - p).rem_euclid(jj as f64).max(1.0);
                    (ha - h).abs() / run * w / (w + run)
                };
                let slope = if n > 2 {
                    0.5 * (at(before.1, before.0, crossings[ia].0)
                        + at(after.1, crossings[ib].0, after.0))
                } else {
                    2.0 * dz / w
                };
                let rise = (slope * w / 4.0).min(dz);
                let mid = zs[tops[j]] + 0.5 * dz;
                h += (mid - ha).signum() * rise * 4.0 * s * (1.0 - s);
            }
            Some(h.clamp(zs[tops[j]], zs[tops[j]] + dz))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::rim_between_sections;

    #[test]
    fn a_slanted_rim_is_read_between_the_sections_it_crosses() {
        // A rim cut by a tilted plane round a cylinder, H = 50.1 + 10 cos θ,
        // sectioned every 0.5 mm: each ray reaches the highest section
        // at or under its rim.
        let dz = 0.5;
        let zs: Vec<f64> = (0..200).map(|k| k as f64 * dz).collect();
        let jj = 360;
        let truth: Vec<f64> = (0..jj)
            .map(|j| 50.1 + 10.0 * (std::f64::consts::TAU * j as f64 / jj as f64).cos())
            .collect();
        let tops: Vec<usize> = truth.iter().map(|h| (h / dz).floor() as usize).collect();
        let fine = rim_between_sections(&tops, &zs);
        let worst =
            |f: &dyn Fn(usize) -> f64| (0..jj).map(|j| (f(j) - truth[j]).abs()).fold(0.0, f64::max);
        let staircase = worst(&|j| zs[tops[j]] + 0.5 * dz);
        let read = worst(&|j| fine[j].expect("a slanted rim"));
        assert!(staircase > 0.24, "{staircase}");
        assert!(
            read < 0.08,
            "read {read} mm off (the staircase {staircase})"
        );
        let step = (0..jj)
            .map(|j| (fine[(j + 1) % jj].unwrap() - fine[j].unwrap()).abs())
            .fold(0.0, f64::max);
        // The rim rises 0.17 mm a ray at most; the staircase 0.5 mm.
        assert!(step < 0.26, "{step}");
        // A level rim is left as the sections read it.
        assert!(rim_between_sections(&[40; 8], &zs)
            .iter()
            .all(Option::is_none));
    }
}
