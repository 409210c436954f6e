//! Horizontal sections of a triangle mesh (docs/MESHES.md): at evenly
//! spaced heights, every triangle that spans a height gives a segment
//! between two of its edges, and segments sharing an edge are chained
//! into loops. Edges are named by their vertices' indices, so the chaining
//! is exact (no tolerance): a loop that cannot close is a hole in the
//! mesh, an edge with three or more segments a non-manifold one, each
//! refused naming the height. Linear in the triangles and the segments.

use crate::error::{Error, Result};
use crate::meshread::TriMesh;
use rustc_hash::FxHashMap;

/// The loops of one horizontal section.
#[derive(Clone, Debug, PartialEq)]
pub struct Section {
    /// Height (mm).
    pub z: f64,
    /// Closed loops in plan (the last point does not repeat the first).
    pub loops: Vec<Vec<[f64; 2]>>,
    /// For each loop, whether the segment from each point to the next
    /// lies on a face within 26° of level ([`UP`]), whichever way its
    /// normal points: a cap across a solid's top, not its wall.
    pub up: Vec<Vec<bool>>,
}

/// A face whose unit normal's vertical part exceeds this (either sign)
/// lies within 26° of level: a wall leaning over 64° from upright, beyond
/// the default overhang limit (57°) by a margin; a cap across a solid's
/// top slants less (docs/MESHES.md, "Uneven rims").
pub const UP: f64 = 0.9;

/// One segment of a section: between the crossings of two edges.
#[derive(Clone, Copy)]
struct Seg {
    ends: [u64; 2],
    at: [[f64; 2]; 2],
    /// Its face lies within 26° of level ([`UP`]).
    up: bool,
}

/// Cuts `mesh` at `n` heights `z0`, `z0 + dz`, …. A vertex exactly at a
/// height counts as above it, so no crossing falls on a vertex. Errors
/// and sections give heights above `bed` (the mesh's lowest point, for
/// the user; 0 keeps the mesh's own).
pub fn cut(mesh: &TriMesh, z0: f64, dz: f64, n: usize, bed: f64) -> Result<Vec<Section>> {
    let mut buckets: Vec<Vec<Seg>> = vec![Vec::new(); n];
    let v = &mesh.vertices;
    for t in &mesh.triangles {
        let zs = t.map(|i| v[i as usize][2]);
        let lo = zs.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = zs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        // Heights k with lo < z_k ≤ hi... strictly: some vertex below
        // (z < z_k) and some at or above, which the test below decides
        // exactly. The range starts a height early: a vertex a rounding
        // below z_k gave (lo − z0) / dz = k exactly, and the floor + 1
        // skipped the height its triangles cross (a ring of a mesh at
        // half a pot's height left that section empty).
        let first = (((lo - z0) / dz).floor() as i64).max(0);
        let last = (((hi - z0) / dz).ceil() as i64).min(n as i64 - 1);
        let up = {
            let [a, b, c] = t.map(|i| v[i as usize]);
            let (e, f) = (
                [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
                [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
            );
            let n = [
                e[1] * f[2] - e[2] * f[1],
                e[2] * f[0] - e[0] * f[2],
                e[0] * f[1] - e[1] * f[0],
            ];
            // Either way up: a mesh whose faces are flipped (or wound
            // inside out) has its cap facing down.
            n[2].abs() > UP * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt()
        };
        for k in first..=last {
            let z = z0 + k as f64 * dz;
            let below = zs.map(|q| q < z);
            if below.iter().all(|&b| b) || below.iter().all(|&b| !b) {
                continue;
            }
            let mut ends = [0u64; 2];
            let mut at = [[0.0; 2]; 2];
            let mut m = 0;
            for (a, b) in [(0, 1), (1, 2), (2, 0)] {
                if below[a] != below[b] && m < 2 {
                    let (i, j) = (t[a].min(t[b]), t[a].max(t[b]));
                    let (p, q) = (v[i as usize], v[j as usize]);
                    let s = (z - p[2]) / (q[2] - p[2]);
                    ends[m] = (u64::from(i) << 32) | u64::from(j);
                    at[m] = [p[0] + s * (q[0] - p[0]), p[1] + s * (q[1] - p[1])];
                    m += 1;
                }
            }
            buckets[k as usize].push(Seg { ends, at, up });
        }
    }
    buckets
        .into_iter()
        .enumerate()
        .map(|(k, segs)| {
            let z = z0 + k as f64 * dz - bed;
            let (loops, up) = chain(&segs, z)?.into_iter().unzip();
            Ok(Section { z, loops, up })
        })
        .collect()
}

/// A loop and whether each of its segments lies on a level face.
type Loop = (Vec<[f64; 2]>, Vec<bool>);

/// Chains the segments of one section into closed loops.
fn chain(segs: &[Seg], z: f64) -> Result<Vec<Loop>> {
    let mut by_edge: FxHashMap<u64, [u32; 2]> = FxHashMap::default();
    for (s, g) in segs.iter().enumerate() {
        for e in g.ends {
            let slot = by_edge.entry(e).or_insert([u32::MAX; 2]);
            if slot[0] == u32::MAX {
                slot[0] = s as u32;
            } else if slot[1] == u32::MAX {
                slot[1] = s as u32;
            } else {
                return Err(Error::invalid(
                    "mesh",
                    format!("an edge at z = {z:.2} mm is shared by three or more faces (a non-manifold mesh): repair it (MeshLab, Blender's 3D-Print toolbox)"),
                ));
            }
        }
    }
    let mut used = vec![false; segs.len()];
    let mut loops = Vec::new();
    for start in 0..segs.len() {
        if used[start] {
            continue;
        }
        let mut pts = vec![segs[start].at[0]];
        // The segment from each point on is the one that starts there.
        let mut up = vec![segs[start].up];
        let (mut s, mut e) = (start, segs[start].ends[1]);
        used[start] = true;
        loop {
            let [a, b] = by_edge[&e];
            let next = if a as usize == s { b } else { a };
            if next == u32::MAX {
                let p = segs[s].at[1];
                return Err(Error::invalid(
                    "mesh",
                    format!("has a hole: the section at z = {z:.2} mm does not close near ({:.1}, {:.1}) mm; close the mesh (MeshLab's Close Holes, Blender's Fill)", p[0], p[1]),
                ));
            }
            let next = next as usize;
            let g = segs[next];
            let (here, far) = if g.ends[0] == e { (0, 1) } else { (1, 0) };
            pts.push(g.at[here]);
            up.push(g.up);
            if next == start {
                break;
            }
            used[next] = true;
            s = next;
            e = g.ends[far];
        }
        pts.pop();
        up.pop();
        // A point a rounding from the one before ends a segment of no
        // length: the one before starts the point's own segment.
        let (mut kept, mut kept_up): (Vec<[f64; 2]>, Vec<bool>) = (Vec::new(), Vec::new());
        for (p, u) in pts.into_iter().zip(up) {
            match kept.last() {
                Some(q) if (p[0] - q[0]).hypot(p[1] - q[1]) < 1e-9 => {
                    let last = kept_up.len() - 1;
                    kept_up[last] = u;
                }
                _ => {
                    kept.push(p);
                    kept_up.push(u);
                }
            }
        }
        if kept.len() >= 3 {
            loops.push((kept, kept_up));
        }
    }
    Ok(loops)
}

/// Twice the signed area of a loop (positive counter-clockwise).
pub fn signed_area2(l: &[[f64; 2]]) -> f64 {
    (0..l.len())
        .map(|i| {
            let (a, b) = (l[i], l[(i + 1) % l.len()]);
            a[0] * b[1] - a[1] * b[0]
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed box `w` × `w` × `h`, twelve triangles.
    fn cube(w: f64, h: f64) -> TriMesh {
        let v: Vec<[f64; 3]> = (0..8)
            .map(|i| {
                [
                    if i & 1 == 0 { 0.0 } else { w },
                    if i & 2 == 0 { 0.0 } else { w },
                    if i & 4 == 0 { 0.0 } else { h },
                ]
            })
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let triangles = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        TriMesh {
            vertices: v,
            triangles,
        }
    }

    #[test]
    fn a_box_cuts_into_one_square_a_height() {
        let s = cut(&cube(10.0, 20.0), 0.5, 1.0, 19, 0.0).unwrap();
        assert_eq!(s.len(), 19);
        for sec in &s {
            assert_eq!(sec.loops.len(), 1, "at {}", sec.z);
            assert!((signed_area2(&sec.loops[0]).abs() - 200.0).abs() < 1e-9);
            // Its sides stand: no segment lies on a level face.
            assert_eq!(sec.up[0].len(), sec.loops[0].len());
            assert!(sec.up[0].iter().all(|&u| !u));
        }
        // The top face's height counts as above: a cut there meets the
        // side faces' top edges only and still closes.
        let top = cut(&cube(10.0, 20.0), 20.0, 1.0, 1, 0.0).unwrap();
        assert!(top[0].loops.len() <= 1);
    }

    #[test]
    fn a_hole_is_named_by_its_height() {
        let mut m = cube(10.0, 20.0);
        m.triangles.remove(4);
        let e = cut(&m, 0.5, 1.0, 19, 0.0).unwrap_err().to_string();
        assert!(e.contains("has a hole") && e.contains("z = 0.50 mm"), "{e}");
    }
}
