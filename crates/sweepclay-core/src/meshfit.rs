//! A vessel mesh back to an editable design (docs/MESHES.md): the mesh is
//! cut into horizontal sections ([`crate::sections`]); the bottom
//! section's wall is the trajectory Ψ; along rays from Ψ (radial from the
//! centre, or along Ψ's normal) each section's wall lies at an offset
//! D(k, j); and D is fitted by the design's own form — one profile, or two
//! blended round the loop by an interpolation curve, D ≈ S(z) + λ(u)·(T(z)
//! − S(z)) (the paper's §3 sweep, eq. 1–2). The fit's profiles and
//! interpolation are B-splines made to pass through the fitted values,
//! and the largest difference between the fitted design and the mesh's
//! sections is measured and reported with where it lies. A section that
//! splits (a handle, two bodies), a wall a ray meets twice, a mesh with a
//! hole, or a fit beyond the tolerance is refused by name.
//!
//! A solid (one loop a section) is fitted at its outside; a shell (two
//! nested loops: a wall with its thickness, as sweepclay's own STL export
//! writes) at the middle of its wall. Cost: linear in the triangles
//! (cutting) plus sections × rays × loop points (about 0.1 s for a pot).

use crate::bspline::BSpline;
use crate::design::{CurveSpec, Design, Offset, TrajectorySpec};
use crate::error::{Error, Result};
use crate::meshread::TriMesh;
use crate::sections::{self, signed_area2};

/// How a mesh is fitted.
#[derive(Clone, Debug, PartialEq)]
pub struct FitOptions {
    /// The largest difference the fitted design may have from the mesh
    /// (mm).
    pub tolerance_mm: f64,
    /// The design's name.
    pub name: String,
}

impl Default for FitOptions {
    fn default() -> FitOptions {
        FitOptions {
            tolerance_mm: 0.3,
            name: String::new(),
        }
    }
}

/// A fitted mesh.
#[derive(Clone, Debug)]
pub struct Fitted {
    /// The editable design (printer and parameters left to the caller).
    pub design: Design,
    /// The largest difference from the mesh's sections (mm).
    pub deviation_mm: f64,
    /// Where it lies, in the design's frame (mm).
    pub at: [f64; 3],
    /// Solid (fitted at its outside) or shell (at its wall's middle).
    pub kind: &'static str,
    /// How many sections were compared.
    pub sections: usize,
    /// What the fit moved the mesh by to put its foot's centre at o and
    /// its foot on the bed (mm).
    pub moved: [f64; 3],
}

/// A mesh file read and fitted: what `slice pot.stl`, `import` and the
/// modeler's "Open…" share.
#[derive(Clone, Debug)]
pub struct Imported {
    /// The fit.
    pub fitted: Fitted,
    /// Triangles read (after the repairs).
    pub triangles: usize,
    /// What was assumed about the mesh's units, to be said.
    pub units_note: Option<String>,
}

/// Reads a mesh file's bytes (`name` gives the format by its extension
/// and the design's name by its stem), stands it on axis `up` (0 x, 1 y,
/// 2 z), brings it to millimetres ([`units`]) and fits it with `opts`
/// (its name replaced by the file's stem).
pub fn import(
    name: &str,
    bytes: &[u8],
    up: usize,
    scale: Option<f64>,
    opts: &FitOptions,
) -> Result<Imported> {
    let mut mesh = TriMesh::read(name, bytes)?;
    mesh.stand_up(up);
    let (k, units_note) = units(&mesh, scale)?;
    mesh.scale(k);
    let stem = std::path::Path::new(name)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let opts = FitOptions {
        name: stem,
        ..opts.clone()
    };
    Ok(Imported {
        fitted: fit(&mesh, &opts)?,
        triangles: mesh.triangles.len(),
        units_note,
    })
}

/// The factor that brings `mesh` to millimetres, and what to tell the
/// user about it: `scale` if given; else 25.4 for a mesh 0.8 to 16 units
/// tall (a pot drawn in inches: 20 to 400 mm), said so; else 1.
pub fn units(mesh: &TriMesh, scale: Option<f64>) -> Result<(f64, Option<String>)> {
    let (lo, hi) = mesh.bounds();
    let h = hi[2] - lo[2];
    match scale {
        Some(k) if !(k.is_finite() && k > 0.0 && k <= 1e4) => Err(Error::invalid(
            "scale",
            format!("must be a factor above 0 and at most 10000 (got {k})"),
        )),
        Some(k) => Ok((k, None)),
        None if (0.8..16.0).contains(&h) => Ok((
            25.4,
            Some(format!(
                "the mesh is {h:.2} units tall: taken as inches and scaled by 25.4 to {:.1} mm (--scale 1 keeps millimetres)",
                h * 25.4
            )),
        )),
        None => Ok((1.0, None)),
    }
}

/// The top of a wall not fitted: its lip (mm).
const RIM_LIP_MM: f64 = 3.0;

/// Sections compared at most: one every [`SECTION_MM`] up to this many.
const MAX_SECTIONS: usize = 800;
/// The distance between sections (mm): a rim's height is known to half
/// of it.
const SECTION_MM: f64 = 0.25;
/// Rays round the loop.
const RAYS: usize = 360;
/// A profile or interpolation curve keeps at most this many control
/// points (the rest of the detail is below the tolerance).
const MAX_CURVE_POINTS: usize = 160;

/// Fits `mesh` (millimetres, any position) by a design within
/// `opts.tolerance_mm`.
pub fn fit(mesh: &TriMesh, opts: &FitOptions) -> Result<Fitted> {
    let (lo, hi) = mesh.bounds();
    let height = hi[2] - lo[2];
    if !(5.0..=2000.0).contains(&height) {
        return Err(Error::invalid(
            "mesh",
            format!("is {height:.2} mm tall: a vessel is 5 to 2000 mm; give --scale (millimetres are assumed: --scale 1000 for metres, 10 for centimetres, 25.4 for inches)"),
        ));
    }
    let n = ((height / SECTION_MM) as usize).clamp(20, MAX_SECTIONS);
    let dz = height / n as f64;
    let mut cut = sections::cut(mesh, lo[2] + 0.5 * dz, dz, n, lo[2])?;
    // A rim that is not quite level (a helix's last turn, a rim's
    // rounding) leaves sections near the top that do not go round: the
    // rim is where the last whole section is, if that is within 3 mm of
    // the top; else the rim is uneven, which a design's rim key shapes
    // but the fit does not yet find.
    let whole = cut
        .iter()
        .position(|s| {
            !s.loops
                .iter()
                .any(|l| nested(&[centroid(l)], l) && around(l, &s.loops))
        })
        .unwrap_or(cut.len());
    if whole == 0 {
        return Err(Error::invalid(
            "mesh",
            "has no section that goes round its centre at its foot: not a vessel standing on its base (turn it so its opening is up)",
        ));
    }
    if whole < cut.len() {
        let z = cut[whole].z;
        if height - z > RIM_LIP_MM && cut[whole - 1].loops.len() == 2 {
            // A wall with its thickness whose rim rises round the loop.
            return fit_uneven(&cut, whole, dz, opts, lo[2]);
        }
        if height - z > RIM_LIP_MM {
            return Err(Error::invalid(
                "mesh",
                format!(
                    "has an uneven rim: from z = {z:.1} mm up ({:.1} mm below its top) the wall does not go all the way round; a solid's slanted or raised rim is not fitted (a wall with its thickness is; or cut the mesh level there, or draw the rim with the design's `rim` key){}",
                    height - z,
                    if hi[0] - lo[0] > height || hi[1] - lo[1] > height {
                        "; or it lies on its side: --up y (or x) stands it up"
                    } else {
                        ""
                    }
                ),
            ));
        }
        cut.truncate(whole);
    }
    // Each section's wall: its one loop, or two nested (a shell).
    let mut shell = false;
    for s in &cut {
        match s.loops.len() {
            0 => {
                return Err(Error::invalid(
                    "mesh",
                    format!("has nothing at z = {:.1} mm: a vessel's wall runs from its foot to its rim", s.z),
                ))
            }
            1 => {}
            2 if nested(&s.loops[0], &s.loops[1]) || nested(&s.loops[1], &s.loops[0]) => {
                shell = true;
            }
            k => {
                return Err(Error::invalid(
                    "mesh",
                    format!(
                        "splits into {k} parts at z = {:.1} mm (a handle, a knob or two bodies): one loop a height makes a vessel, or two nested for a wall with its thickness",
                        s.z
                    ),
                ))
            }
        }
    }
    let (c, psi) = foot_frame(&cut);
    let loops: Vec<Vec<Vec<[f64; 2]>>> = cut.iter().map(|s| about(s, c)).collect();
    let zs: Vec<f64> = cut.iter().map(|s| s.z).collect();
    let mut best: Option<Candidate> = None;
    let mut why = Vec::new();
    for offset in [Offset::Radial, Offset::Normal] {
        match offsets(&psi, &zs, &loops, offset, shell) {
            Ok((mut d, dirs)) => {
                // Only a profile's change from its foot counts (docs/
                // FORMATS.md): Ψ is the wall at the lowest section (a
                // shell's middle, not the foot's outside), and D is
                // measured from it.
                let base = d[0].clone();
                let psi: Vec<[f64; 2]> = (0..psi.len())
                    .map(|j| {
                        [
                            psi[j][0] + base[j] * dirs[j][0],
                            psi[j][1] + base[j] * dirs[j][1],
                        ]
                    })
                    .collect();
                for row in &mut d {
                    for (x, b) in row.iter_mut().zip(&base) {
                        *x -= b;
                    }
                }
                let cand = fit_offsets(&psi, &zs, &d, offset, height, opts.tolerance_mm);
                if best.as_ref().is_none_or(|b| cand.deviation < b.deviation) {
                    best = Some(cand);
                }
            }
            Err(e) => why.push(e),
        }
    }
    let Some(b) = best else {
        // Neither frame finds one wall a ray: the radial reason says where.
        return Err(Error::invalid(
            "mesh",
            format!("is not a sweep of its foot's loop: {}", why[0]),
        ));
    };
    if b.deviation > opts.tolerance_mm {
        return Err(Error::invalid(
            "mesh",
            format!(
                "is not a sweep of one loop within {} mm: the closest design (a loop, {}, {} offsets) differs from it by {:.2} mm at ({:.1}, {:.1}, {:.1}) mm",
                opts.tolerance_mm,
                if b.two { "two profiles blended round it" } else { "one profile" },
                if b.offset == Offset::Radial { "radial" } else { "normal" },
                b.deviation,
                b.at[0],
                b.at[1],
                b.at[2]
            ),
        ));
    }
    let mut design = Design::from_json(&b.json(&opts.name))?;
    design.name = opts.name.clone();
    Ok(Fitted {
        design,
        deviation_mm: b.deviation,
        at: b.at,
        kind: if shell { "shell" } else { "solid" },
        sections: cut.len(),
        moved: [-c[0], -c[1], -lo[2]],
    })
}

/// A shell whose rim rises round the loop (docs/MESHES.md, "Uneven
/// rims"): sections up to `whole` go round, those above are the wall's
/// higher parts. Along each radial ray the wall's middle is found in
/// every section it reaches and the ray's rim height H_j where it stops;
/// the design's two profiles of heights Z_s = min H and Z_t = max H are
/// blended by λ_j = (H_j − Z_s) / (Z_t − Z_s), at the same fraction of
/// each column's height (as the design's surface is: its offsets blend
/// at t = z / h_i), so the profiles are the regression of each height
/// fraction's offsets on λ.
fn fit_uneven(
    cut: &[sections::Section],
    whole: usize,
    dz: f64,
    opts: &FitOptions,
    bed: f64,
) -> Result<Fitted> {
    let tol = opts.tolerance_mm;
    let (c, psi0) = foot_frame(cut);
    let jj = psi0.len();
    let zs: Vec<f64> = cut.iter().map(|s| s.z).collect();
    // The wall's middle along each ray in each section it reaches.
    let mut d: Vec<Vec<Option<f64>>> = Vec::with_capacity(cut.len());
    let mut half = vec![None::<f64>; jj];
    for (k, sec) in cut.iter().enumerate() {
        let loops = about(sec, c);
        let mut row = Vec::with_capacity(jj);
        for (j, p) in psi0.iter().enumerate() {
            let r = p[0].hypot(p[1]).max(1e-9);
            let dir = [p[0] / r, p[1] / r];
            let mut ts: Vec<f64> = loops
                .iter()
                .flat_map(|l| hits(l, [0.0, 0.0], dir))
                .filter(|&t| t > 0.0)
                .collect();
            ts.sort_by(f64::total_cmp);
            row.push(match ts.len() {
                2 => {
                    if k < whole {
                        half[j] = Some(0.5 * (ts[1] - ts[0]));
                    }
                    Some(0.5 * (ts[0] + ts[1]) - r)
                }
                // A shell's floor slab: its outside only.
                1 if k < whole => Some(ts[0] - r),
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
    // The slab's middle: half the wall's thickness in from its outside.
    for (k, row) in d.iter_mut().enumerate().take(whole) {
        if cut[k].loops.len() == 1 {
            for (v, h) in row.iter_mut().zip(&half) {
                if let (Some(v), Some(h)) = (v.as_mut(), h) {
                    *v -= h;
                }
            }
        }
    }
    // Ψ is the wall's middle at the lowest section; D is from it.
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
    let mut rim = vec![0.0; jj];
    for j in 0..jj {
        let top = (0..d.len())
            .take_while(|&k| d[k][j].is_some())
            .last()
            .unwrap_or(0);
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
        rim[j] = zs[top] + 0.5 * dz;
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
    let start = profile_through(&sv, tol);
    let end = profile_through(&tv, tol);
    let interp = interpolation_through(&lambda);
    // The design as it will be sampled, against every offset found.
    let (sp, ep) = (dense(&start), dense(&end));
    let lc = BSpline::clamped(interp.clone())
        .expect("points")
        .flatten(16);
    let mut worst = (0.0f64, [0.0; 3]);
    for j in 0..jj {
        let l = at_x(&lc, j as f64 / jj as f64);
        let h = (1.0 - l) * zs_lo + l * zt_hi;
        // The rim's height is known to half a section.
        let high = ((h - rim[j]).abs() - 0.5 * dz).max(0.0);
        if high > worst.0 {
            worst = (high, [psi[j][0], psi[j][1], rim[j]]);
        }
        for (k, v) in d.iter().enumerate() {
            let Some(v) = v[j] else { continue };
            let t = (zs[k] / h).min(1.0);
            let fitted = (1.0 - l) * at_z(&sp, t * zs_lo) + l * at_z(&ep, t * zt_hi);
            let e = (fitted - v).abs();
            if e > worst.0 {
                worst = (e, [psi[j][0], psi[j][1], zs[k]]);
            }
        }
    }
    let cand = Candidate {
        offset: Offset::Radial,
        two: true,
        psi,
        start,
        end,
        interp,
        deviation: worst.0,
        at: worst.1,
    };
    if cand.deviation > tol {
        return Err(Error::invalid(
            "mesh",
            format!(
                "is not a sweep of one loop within {tol} mm: the closest design (a loop, two profiles of {:.1} and {:.1} mm blended round it for its uneven rim, radial offsets) differs from it by {:.2} mm at ({:.1}, {:.1}, {:.1}) mm",
                zs_lo, zt_hi, cand.deviation, cand.at[0], cand.at[1], cand.at[2]
            ),
        ));
    }
    let mut design = Design::from_json(&cand.json(&opts.name))?;
    design.name = opts.name.clone();
    Ok(Fitted {
        design,
        deviation_mm: cand.deviation,
        at: cand.at,
        kind: "shell",
        sections: cut.len(),
        moved: [-c[0], -c[1], -bed],
    })
}

/// The foot's wall (the lowest section's) as Ψ: its area centroid, o,
/// and [`RAYS`] points evenly along it, about o.
fn foot_frame(cut: &[sections::Section]) -> ([f64; 2], Vec<[f64; 2]>) {
    let foot = wall_loop(&cut[0].loops);
    let c = centroid(foot);
    let psi = resample(foot, RAYS)
        .into_iter()
        .map(|p| [p[0] - c[0], p[1] - c[1]])
        .collect();
    (c, psi)
}

/// A section's loops about the centre `c`, resampled a point every
/// 0.4 mm (16 to 4,000 a loop): the rays' cost does not grow with the
/// mesh's triangles.
fn about(sec: &sections::Section, c: [f64; 2]) -> Vec<Vec<[f64; 2]>> {
    sec.loops
        .iter()
        .map(|l| {
            let k = (perimeter(l) / 0.4).ceil().clamp(16.0, 4000.0) as usize;
            resample(l, k)
                .into_iter()
                .map(|p| [p[0] - c[0], p[1] - c[1]])
                .collect()
        })
        .collect()
}

/// A fitted form and its largest difference from the mesh.
struct Candidate {
    offset: Offset,
    two: bool,
    psi: Vec<[f64; 2]>,
    start: Vec<[f64; 2]>,
    end: Vec<[f64; 2]>,
    interp: Vec<[f64; 2]>,
    deviation: f64,
    at: [f64; 3],
}

impl Candidate {
    fn json(&self, name: &str) -> String {
        let traj = TrajectorySpec {
            control_points: None,
            points: Some(self.psi.clone()),
            closed: true,
            offset: self.offset,
        };
        let mut v = serde_json::json!({
            "sweepclay": 1,
            "name": name,
            "profile_start": CurveSpec { control_points: self.start.clone(), points: None },
            "trajectory": traj,
        });
        if self.two {
            v["profile_end"] = serde_json::json!(CurveSpec {
                control_points: self.end.clone(),
                points: None,
            });
            v["interpolation"] = serde_json::json!(CurveSpec {
                control_points: self.interp.clone(),
                points: None,
            });
        }
        v.to_string()
    }
}

/// Whether loop `a` lies inside loop `b` (its first point does).
fn nested(a: &[[f64; 2]], b: &[[f64; 2]]) -> bool {
    let p = a[0];
    let mut inside = false;
    for i in 0..b.len() {
        let (q, r) = (b[i], b[(i + 1) % b.len()]);
        if (q[1] > p[1]) != (r[1] > p[1])
            && p[0] < q[0] + (p[1] - q[1]) / (r[1] - q[1]) * (r[0] - q[0])
        {
            inside = !inside;
        }
    }
    inside
}

/// Whether loop `l` is a wall round the section's middle: no other loop
/// of the section holds it (a shell's inner loop is inside the outer).
fn around(l: &[[f64; 2]], all: &[Vec<[f64; 2]>]) -> bool {
    all.iter()
        .all(|o| std::ptr::eq(o.as_slice(), l) || !nested(l, o))
}

/// The loop that stands for a section's wall in plan: the outer of two.
fn wall_loop(loops: &[Vec<[f64; 2]>]) -> &[[f64; 2]] {
    loops
        .iter()
        .max_by(|a, b| signed_area2(a).abs().total_cmp(&signed_area2(b).abs()))
        .expect("a section has a loop")
}

/// The area centroid of a loop.
fn centroid(l: &[[f64; 2]]) -> [f64; 2] {
    let (mut a, mut cx, mut cy) = (0.0, 0.0, 0.0);
    for i in 0..l.len() {
        let (p, q) = (l[i], l[(i + 1) % l.len()]);
        let w = p[0] * q[1] - q[0] * p[1];
        a += w;
        cx += (p[0] + q[0]) * w;
        cy += (p[1] + q[1]) * w;
    }
    [cx / (3.0 * a), cy / (3.0 * a)]
}

fn perimeter(l: &[[f64; 2]]) -> f64 {
    (0..l.len())
        .map(|i| {
            let (p, q) = (l[i], l[(i + 1) % l.len()]);
            (q[0] - p[0]).hypot(q[1] - p[1])
        })
        .sum()
}

/// `k` points evenly spaced along a closed loop, counter-clockwise.
fn resample(l: &[[f64; 2]], k: usize) -> Vec<[f64; 2]> {
    let mut l = l.to_vec();
    if signed_area2(&l) < 0.0 {
        l.reverse();
    }
    let total = perimeter(&l);
    let mut out = Vec::with_capacity(k);
    let (mut i, mut walked) = (0usize, 0.0);
    for m in 0..k {
        let want = total * m as f64 / k as f64;
        loop {
            let (p, q) = (l[i % l.len()], l[(i + 1) % l.len()]);
            let seg = (q[0] - p[0]).hypot(q[1] - p[1]);
            if walked + seg >= want || i >= 2 * l.len() {
                let t = if seg > 0.0 {
                    (want - walked) / seg
                } else {
                    0.0
                };
                out.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
                break;
            }
            walked += seg;
            i += 1;
        }
    }
    out
}

/// Where the ray `o + t·d` crosses the loop: every t.
fn hits(l: &[[f64; 2]], o: [f64; 2], d: [f64; 2]) -> Vec<f64> {
    let mut ts = Vec::new();
    for i in 0..l.len() {
        let (p, q) = (l[i], l[(i + 1) % l.len()]);
        let e = [q[0] - p[0], q[1] - p[1]];
        let den = d[0] * e[1] - d[1] * e[0];
        if den.abs() < 1e-12 {
            continue;
        }
        let w = [p[0] - o[0], p[1] - o[1]];
        let t = (w[0] * e[1] - w[1] * e[0]) / den;
        let s = (w[0] * d[1] - w[1] * d[0]) / den;
        if (-1e-9..1.0 + 1e-9).contains(&s) {
            ts.push(t);
        }
    }
    // A ray through a vertex crosses both its edges at one place.
    ts.sort_by(f64::total_cmp);
    ts.dedup_by(|a, b| (*a - *b).abs() < 1e-6);
    ts
}

/// D(k, j) by section and ray, and each ray's direction.
type Offsets = (Vec<Vec<f64>>, Vec<[f64; 2]>);

/// D(k, j): for each section k and each point j of Ψ, the offset of the
/// section's wall along the ray of the frame (`offset`), and each ray's
/// direction. A ray that meets
/// a solid's loop more than once from its start (radial) is refused: the
/// wall there folds back across the ray.
fn offsets(
    psi: &[[f64; 2]],
    zs: &[f64],
    loops: &[Vec<Vec<[f64; 2]>>],
    offset: Offset,
    shell: bool,
) -> std::result::Result<Offsets, String> {
    let n = psi.len();
    let rays: Vec<([f64; 2], [f64; 2], f64)> = (0..n)
        .map(|j| {
            let p = psi[j];
            match offset {
                Offset::Radial => {
                    let r = p[0].hypot(p[1]).max(1e-9);
                    ([0.0, 0.0], [p[0] / r, p[1] / r], r)
                }
                Offset::Normal => {
                    let (a, b) = (psi[(j + n - 1) % n], psi[(j + 1) % n]);
                    let t = [b[0] - a[0], b[1] - a[1]];
                    let l = t[0].hypot(t[1]).max(1e-12);
                    // Outward, as a loop's normal offsets move (right
                    // of travel on this counter-clockwise Ψ).
                    (p, [t[1] / l, -t[0] / l], 0.0)
                }
            }
        })
        .collect();
    let mut d = Vec::with_capacity(loops.len());
    // Half the wall's thickness along each ray, where a shell's section
    // has both its loops.
    let mut half: Vec<Option<Vec<f64>>> = Vec::with_capacity(loops.len());
    for (k, sec) in loops.iter().enumerate() {
        let mut row = Vec::with_capacity(n);
        let mut halves = Vec::with_capacity(n);
        for &(o, dir, base) in &rays {
            let mut wall = Vec::with_capacity(2);
            for l in sec {
                let ts = hits(l, o, dir);
                let t = match offset {
                    Offset::Radial => {
                        let ahead: Vec<f64> = ts.into_iter().filter(|&t| t > 0.0).collect();
                        if ahead.len() != 1 {
                            return Err(format!(
                                "its wall at z = {:.1} mm does not go once round its foot's centre (a ray from the centre meets it {} times, near ({:.1}, {:.1}) mm)",
                                zs[k],
                                ahead.len(),
                                dir[0] * base,
                                dir[1] * base
                            ));
                        }
                        ahead[0]
                    }
                    Offset::Normal => match ts
                        .into_iter()
                        .min_by(|a, b| a.abs().total_cmp(&b.abs()))
                    {
                        Some(t) => t,
                        None => {
                            return Err(format!(
                                "its wall at z = {:.1} mm is not across the foot's wall near ({:.1}, {:.1}) mm (it leans out beyond where the foot reaches)",
                                zs[k], o[0], o[1]
                            ))
                        }
                    },
                };
                wall.push(t);
            }
            let t = if shell && wall.len() == 2 {
                halves.push(0.5 * (wall[0] - wall[1]).abs());
                0.5 * (wall[0] + wall[1])
            } else {
                wall[0]
            };
            row.push(t - base);
        }
        d.push(row);
        half.push((halves.len() == n).then_some(halves));
    }
    if shell {
        // A shell's floor slab is cut as one loop, its outside: its wall's
        // middle lies half the thickness of the nearest whole section in
        // (toward Ψ's side the inner loop lay on).
        let whole: Vec<usize> = (0..d.len()).filter(|&k| half[k].is_some()).collect();
        for k in 0..d.len() {
            if half[k].is_some() {
                continue;
            }
            let near = whole.iter().min_by_key(|&&w| w.abs_diff(k)).copied();
            if let Some(w) = near {
                let h = half[w].clone().expect("whole");
                for j in 0..n {
                    // Both frames point out: the middle is half the
                    // thickness in from the outside.
                    d[k][j] -= h[j];
                }
            }
        }
    }
    Ok((d, rays.iter().map(|r| r.1).collect()))
}

/// Fits D by one profile, and by two blended round the loop where one
/// does not reach the tolerance of a few hundredths; the better of both.
fn fit_offsets(
    psi: &[[f64; 2]],
    zs: &[f64],
    d: &[Vec<f64>],
    offset: Offset,
    height: f64,
    tol: f64,
) -> Candidate {
    let (kk, jj) = (d.len(), psi.len());
    let mean: Vec<f64> = d
        .iter()
        .map(|r| r.iter().sum::<f64>() / jj as f64)
        .collect();
    // The first singular pair of D less its row means: D ≈ m + a bᵀ.
    let mut b = vec![0.0; jj];
    for (j, v) in b.iter_mut().enumerate() {
        *v = (std::f64::consts::TAU * j as f64 / jj as f64).cos();
    }
    let mut a = vec![0.0; kk];
    for _ in 0..60 {
        for k in 0..kk {
            a[k] = (0..jj).map(|j| (d[k][j] - mean[k]) * b[j]).sum::<f64>();
        }
        let na = a.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-300);
        a.iter_mut().for_each(|x| *x /= na);
        for j in 0..jj {
            b[j] = (0..kk).map(|k| (d[k][j] - mean[k]) * a[k]).sum::<f64>();
        }
    }
    let (bmin, bmax) = b
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        });
    // Ψ starts where λ is 0 (a loop's interpolation starts and ends at 0).
    let j0 = b
        .iter()
        .enumerate()
        .min_by(|x, y| x.1.total_cmp(y.1))
        .map_or(0, |(j, _)| j);
    let spread = (bmax - bmin).max(1e-12);
    let lambda: Vec<f64> = (0..jj)
        .map(|j| (b[(j0 + j) % jj] - bmin) / spread)
        .collect();
    let psi: Vec<[f64; 2]> = (0..jj).map(|j| psi[(j0 + j) % jj]).collect();
    let d: Vec<Vec<f64>> = d
        .iter()
        .map(|r| (0..jj).map(|j| r[(j0 + j) % jj]).collect())
        .collect();
    let s: Vec<f64> = (0..kk).map(|k| mean[k] + a[k] * bmin).collect();
    let t: Vec<f64> = (0..kk).map(|k| s[k] + a[k] * spread).collect();
    // One profile is the simpler design to edit: kept when it is within
    // the tolerance.
    let g = Frame {
        psi: &psi,
        zs,
        offset,
        height,
        tol,
    };
    let one = candidate(&g, &d, &mean, None);
    if one.deviation <= tol {
        return one;
    }
    let two = candidate(&g, &d, &s, Some((&t, &lambda)));
    if two.deviation < one.deviation {
        two
    } else {
        one
    }
}

/// What every candidate of one fit shares: Ψ, the sections' heights,
/// the frame of the offsets, the height and the tolerance.
#[derive(Clone, Copy)]
struct Frame<'a> {
    psi: &'a [[f64; 2]],
    zs: &'a [f64],
    offset: Offset,
    height: f64,
    tol: f64,
}

/// The design of profile values `s` (and `t` blended by `lambda`) at the
/// sections' heights, as B-splines through them, and its largest
/// difference from `d`.
fn candidate(g: &Frame, d: &[Vec<f64>], s: &[f64], two: Option<(&[f64], &[f64])>) -> Candidate {
    let Frame {
        psi,
        zs,
        offset,
        height,
        tol,
    } = *g;
    let profile = |v: &[f64]| -> Vec<[f64; 2]> {
        // From the bed to the rim: the lowest and highest sections'
        // values held to z 0 and the top.
        let mut pts: Vec<[f64; 2]> = vec![[v[0], 0.0]];
        pts.extend(v.iter().zip(zs).map(|(&x, &z)| [x, z]));
        pts.push([v[v.len() - 1], height]);
        profile_through(&pts, tol)
    };
    let start = profile(s);
    let (end, interp) = match two {
        Some((t, lambda)) => (profile(t), interpolation_through(lambda)),
        None => (Vec::new(), Vec::new()),
    };
    // The fitted offsets, as the design will sample them.
    let sp = dense(&start);
    let ep = if two.is_some() {
        dense(&end)
    } else {
        Vec::new()
    };
    let lam: Vec<f64> = if two.is_some() {
        let c = BSpline::clamped(interp.clone())
            .expect("points")
            .flatten(16);
        (0..psi.len())
            .map(|j| at_x(&c, j as f64 / psi.len() as f64))
            .collect()
    } else {
        vec![0.0; psi.len()]
    };
    let mut worst = (0.0f64, [0.0; 3]);
    for (k, &z) in zs.iter().enumerate() {
        let (a, b) = (at_z(&sp, z), if ep.is_empty() { 0.0 } else { at_z(&ep, z) });
        for (j, &l) in lam.iter().enumerate() {
            let fitted = if ep.is_empty() {
                a
            } else {
                (1.0 - l) * a + l * b
            };
            let e = (fitted - d[k][j]).abs();
            if e > worst.0 {
                let p = psi[j];
                worst = (e, [p[0], p[1], z]);
            }
        }
    }
    Candidate {
        offset,
        two: two.is_some(),
        psi: psi.to_vec(),
        start,
        end,
        interp,
        deviation: worst.0,
        at: worst.1,
    }
}

/// A profile's control points through `pts` (`[x, z]`, z rising): as few
/// as keep the curve within a third of the tolerance of the values, a
/// profile a potter can still edit.
fn profile_through(pts: &[[f64; 2]], tol: f64) -> Vec<[f64; 2]> {
    let mut curve = Vec::new();
    for k in [6, 8, 12, 16, 24, 32, 48, 64, 96, 128, MAX_CURVE_POINTS] {
        curve = through(&thin(pts, k));
        let line = dense(&curve);
        let off = pts
            .iter()
            .map(|p| (at_z(&line, p[1]) - p[0]).abs())
            .fold(0.0, f64::max);
        if off <= tol / 3.0 || k >= pts.len() {
            break;
        }
    }
    curve
}

/// An interpolation curve through `lambda` (one value a point of Ψ, from
/// u = 0): from (0, 0) to (1, 0), f in [0, 1], as the design's rules ask.
fn interpolation_through(lambda: &[f64]) -> Vec<[f64; 2]> {
    let jj = lambda.len();
    let mut pts: Vec<[f64; 2]> = (0..jj)
        .map(|j| [j as f64 / jj as f64, lambda[j].clamp(0.0, 1.0)])
        .collect();
    pts.push([1.0, 0.0]);
    pts[0] = [0.0, 0.0];
    let mut c = through(&thin(&pts, MAX_CURVE_POINTS));
    for p in &mut c {
        p[1] = p[1].clamp(0.0, 1.0);
    }
    let last = c.len() - 1;
    c[0] = [0.0, 0.0];
    c[last] = [1.0, 0.0];
    c
}

/// At most `k` of `pts`, evenly chosen, the ends kept.
fn thin(pts: &[[f64; 2]], k: usize) -> Vec<[f64; 2]> {
    if pts.len() <= k {
        return pts.to_vec();
    }
    (0..k)
        .map(|i| pts[(i * (pts.len() - 1) + (k - 1) / 2) / (k - 1)])
        .collect()
}

/// Control points whose clamped B-spline passes (nearly) through `pts` at
/// their Greville abscissae: the points moved by what the curve misses
/// them by, a few times over.
fn through(pts: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let n = pts.len();
    if n < 4 {
        return pts.to_vec();
    }
    let p = 3usize;
    let interior = n - p - 1;
    let knot = |i: usize| -> f64 {
        if i <= p {
            0.0
        } else if i >= n {
            1.0
        } else {
            (i - p) as f64 / (interior + 1) as f64
        }
    };
    let greville: Vec<f64> = (0..n)
        .map(|i| (knot(i + 1) + knot(i + 2) + knot(i + 3)) / 3.0)
        .collect();
    let mut ctrl = pts.to_vec();
    for _ in 0..30 {
        let Some(c) = BSpline::clamped(ctrl.clone()) else {
            break;
        };
        let mut moved = 0.0f64;
        for i in 1..n - 1 {
            let q = c.eval(greville[i]);
            let e = [pts[i][0] - q[0], pts[i][1] - q[1]];
            ctrl[i] = [ctrl[i][0] + e[0], ctrl[i][1] + e[1]];
            moved = moved.max(e[0].abs().max(e[1].abs()));
        }
        if moved < 1e-4 {
            break;
        }
    }
    ctrl
}

/// A profile's curve, densely, as the sampling reads it.
fn dense(ctrl: &[[f64; 2]]) -> Vec<[f64; 2]> {
    BSpline::clamped(ctrl.to_vec()).expect("points").flatten(16)
}

/// x of a polyline at height `z` (its second coordinate), by the first
/// segment spanning it.
fn at_z(poly: &[[f64; 2]], z: f64) -> f64 {
    for w in poly.windows(2) {
        let (a, b) = (w[0], w[1]);
        if (a[1] <= z && z <= b[1]) || (b[1] <= z && z <= a[1]) {
            let t = if (b[1] - a[1]).abs() > 1e-12 {
                (z - a[1]) / (b[1] - a[1])
            } else {
                0.0
            };
            return a[0] + t * (b[0] - a[0]);
        }
    }
    if z <= poly[0][1] {
        poly[0][0]
    } else {
        poly[poly.len() - 1][0]
    }
}

/// The second coordinate of a polyline at first coordinate `x`.
fn at_x(poly: &[[f64; 2]], x: f64) -> f64 {
    let swapped: Vec<[f64; 2]> = poly.iter().map(|p| [p[1], p[0]]).collect();
    at_z(&swapped, x)
}
