//! A mesh kept as it is (docs/MESHES.md, "Printed as the mesh is"): what
//! the closest sweep leaves, section by section and ray by ray, as the
//! design's relief, its rows as far apart as it stays within the
//! tolerance.

use super::*;

/// Most rows a fitted relief keeps (and the top section): one every
/// [`RELIEF_ROW_MM`] or more, so a design file stays a few hundred
/// kilobytes.
const MAX_RELIEF_ROWS: usize = 120;
/// The least height between a relief's rows (mm): a twisted square's
/// corner, 1 mm apart, left the surface 0.32 mm off its mesh between
/// rows; 0.5 mm holds it within 0.3.
const RELIEF_ROW_MM: f64 = 0.5;

/// A candidate's residual as a relief (docs/MESHES.md, "Printed as the
/// mesh is"): rows at every few sections (at least [`RELIEF_ROW_MM`]
/// apart, at most [`MAX_RELIEF_ROWS`], the lowest and highest kept;
/// closer, down to every section, while the design is farther than
/// `tol` from a section between them), a column at each ray, placed by
/// its arc length along Ψ, offsets to 0.01 mm. With it, the design's
/// largest difference from every section and where it lies.
pub(super) fn relief_of(b: &Candidate, zs: &[f64], dz: f64, tol: f64) -> (Relief, (f64, [f64; 3])) {
    let n = zs.len();
    // Ψ is the design's closed polyline: each ray's place is its arc
    // length from the first point, as the design's columns are placed.
    let (u, _) = places(&b.psi);
    let round = |v: f64| (v * 100.0).round() / 100.0;
    let mut step = ((RELIEF_ROW_MM / dz).ceil() as usize)
        .max(n.div_ceil(MAX_RELIEF_ROWS))
        .max(1);
    loop {
        let mut rows: Vec<usize> = (0..n).step_by(step).collect();
        if rows.last() != Some(&(n - 1)) {
            rows.push(n - 1);
        }
        let relief = Relief {
            z: rows.iter().map(|&k| zs[k]).collect(),
            u: u.clone(),
            offsets: rows
                .iter()
                .map(|&k| b.residual[k].iter().map(|&v| round(v)).collect())
                .collect(),
        };
        let mut worst = (0.0f64, [0.0; 3]);
        for (k, &z) in zs.iter().enumerate() {
            for (j, &r) in b.residual[k].iter().enumerate() {
                let e = (r - relief.at(u[j], z)).abs();
                if e > worst.0 {
                    worst = (e, [b.psi[j][0], b.psi[j][1], z]);
                }
            }
        }
        // A form that changes faster than the rows (a low-poly mesh's
        // facets) keeps rows closer, down to every section.
        if worst.0 <= tol || step == 1 {
            return (relief, worst);
        }
        step = step.div_ceil(2);
    }
}
