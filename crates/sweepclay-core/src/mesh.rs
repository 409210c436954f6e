//! Triangle meshes of the sampled surface: the thin surface the modeler
//! previews, and the surface thickened to the bead width that it exports as
//! STL (for rendering, for a slicer's preview, or for checking the design in
//! a CAD tool). Pure: the STL is written to any `Write`.
//!
//! Adjacent transition curves are zipped into a strip of triangles by
//! always advancing along the curve whose next sample is lower, so the
//! samples themselves are the vertices (no resampling). Each column is
//! triangulated bottom up, as the samples are stored (docs/ALGORITHMS.md §2).

use crate::surface::Surface;
use crate::toolpath::PointKind;
use crate::Sliced;
use std::io::{self, Write};

/// Triangles over [`Surface::samples`] (indices into it), zipping each pair
/// of adjacent transition curves.
pub fn surface_triangles(s: &Surface) -> Vec<[u32; 3]> {
    let mut tris = Vec::with_capacity(2 * s.samples.len());
    for (ca, cb) in column_pairs(s) {
        let (a, b) = (s.columns[ca].samples(), s.columns[cb].samples());
        let (mut i, mut j) = (a.start, b.start);
        while i + 1 < a.end || j + 1 < b.end {
            let advance_a = if i + 1 >= a.end {
                false
            } else if j + 1 >= b.end {
                true
            } else {
                s.samples[i + 1].z <= s.samples[j + 1].z
            };
            if advance_a {
                tris.push([i as u32, j as u32, i as u32 + 1]);
                i += 1;
            } else {
                tris.push([i as u32, j as u32, j as u32 + 1]);
                j += 1;
            }
        }
    }
    tris
}

/// Neighbouring columns `(a, b)`: along Ψ, and round a vessel's loop the
/// last with the first.
fn column_pairs(s: &Surface) -> impl Iterator<Item = (usize, usize)> {
    let n = s.columns.len();
    let pairs = if s.vessel.is_some() { n } else { n - 1 };
    (0..pairs).map(move |a| (a, (a + 1) % n))
}

/// For each surface sample, the index of the toolpath point that prints it.
pub fn path_index_of_samples(s: &Sliced) -> Vec<u32> {
    let surface = &s.corrected.surface;
    let mut of = vec![0u32; surface.samples.len()];
    for (i, p) in s.toolpath.points.iter().enumerate() {
        if let Some(si) = sample_of_point(surface, p) {
            of[si] = i as u32;
        }
    }
    of
}

/// The surface sample a toolpath point visits (`None` for a vessel's
/// floor beads, which are not surface samples).
pub fn sample_of_point(s: &Surface, p: &crate::toolpath::PathPoint) -> Option<usize> {
    let col = &s.columns[p.column as usize];
    let local = match p.kind {
        // A vessel's wall passes are numbered on from its floor layers.
        PointKind::Pass => (p.pass - s.vessel.as_ref().map_or(0, |v| v.base_layers)) as usize - 1,
        PointKind::Top => col.passes as usize,
        PointKind::Floor => return None,
    };
    Some(col.first as usize + local)
}

/// The closed solid of the surface thickened to the bead width: each sample
/// is pushed ±w/2 across Ψ (horizontally, perpendicular to the trajectory),
/// where w is the width of the bead printed there, from the bed (z = 0) to
/// the top of the last bead. A vessel with a floor is one solid, the wall
/// standing on the floor (one watertight shell, as slicers read a piece).
/// Triangles are consistently oriented with their normals pointing out.
pub fn solid(s: &Sliced) -> Vec<[[f64; 3]; 3]> {
    let surface = &s.corrected.surface;
    let cols = &surface.columns;
    let width_of = path_index_of_samples(s);
    let n = surface.samples.len();
    // Vertices: outer (0..n) then inner (n..2n).
    let mut v = vec![[0.0; 3]; 2 * n];
    let closed = surface.vessel.is_some();
    let m = cols.len();
    for (c, col) in cols.iter().enumerate() {
        let (prev, next) = if closed {
            (cols[(c + m - 1) % m].p, cols[(c + 1) % m].p)
        } else {
            (cols[c.saturating_sub(1)].p, cols[(c + 1).min(m - 1)].p)
        };
        let (tx, ty) = (next[0] - prev[0], next[1] - prev[1]);
        let len = tx.hypot(ty).max(1e-12);
        let normal = [ty / len, -tx / len];
        for si in col.samples() {
            let mut p = surface.position(c, si);
            if si == col.first as usize {
                // The first bead stands on the bed.
                p[2] = 0.0;
            }
            let half = s.extrusion.width[width_of[si] as usize] / 2.0;
            v[si] = [p[0] + half * normal[0], p[1] + half * normal[1], p[2]];
            v[n + si] = [p[0] - half * normal[0], p[1] - half * normal[1], p[2]];
        }
    }
    let (o, inner) = (|i: usize| i, |i: usize| n + i);
    // A vessel with a floor is one solid: its wall's inside stands on the
    // floor's top, and the bottom is one face across the outside ring. The
    // wall's inside below the floor's top, and its bottom strip, go.
    let floor = surface
        .vessel
        .as_ref()
        .filter(|v| v.floor_layers > 0)
        .map(|v| v.base_mm());
    // A ring of vertices round the loop: `side` 0 is the outer (o), n the
    // inner, at the samples `local` up their columns.
    let ring_at = |side: usize, local: usize| -> Vec<usize> {
        cols.iter()
            .map(|c| side + c.first as usize + local)
            .collect()
    };
    let area = |ring: &[usize]| {
        let pts: Vec<[f64; 2]> = ring.iter().map(|&i| [v[i][0], v[i][1]]).collect();
        crate::plane::signed_area2(&pts).abs()
    };
    // Which of the two sides is the vessel's inside.
    let (outside, inside) = if floor.is_some() && area(&ring_at(n, 0)) < area(&ring_at(0, 0)) {
        (0, n)
    } else {
        (n, 0)
    };
    if let Some(top) = floor {
        // The inside starts at the floor's top.
        for c in cols {
            v[inside + c.first as usize][2] = top;
        }
    }
    let mut idx: Vec<[usize; 3]> = Vec::with_capacity(4 * n + 4 * cols.len());
    let quad = |idx: &mut Vec<[usize; 3]>, a: usize, b: usize, c: usize, d: usize| {
        idx.push([a, b, c]);
        idx.push([a, c, d]);
    };
    for t in surface_triangles(surface) {
        let [a, b, c] = t.map(|i| i as usize);
        idx.push([o(a), o(b), o(c)]);
        idx.push([inner(c), inner(b), inner(a)]);
    }
    for (ca, cb) in column_pairs(surface) {
        let (a, b) = (cols[ca].samples(), cols[cb].samples());
        // Bottom and top edges.
        if floor.is_none() {
            quad(
                &mut idx,
                o(b.start),
                o(a.start),
                inner(a.start),
                inner(b.start),
            );
        }
        let (ta, tb) = (a.end - 1, b.end - 1);
        quad(&mut idx, o(ta), o(tb), inner(tb), inner(ta));
    }
    if !closed {
        // The two end walls.
        let first = cols[0].samples();
        for s in first.start..first.end - 1 {
            quad(&mut idx, o(s), o(s + 1), inner(s + 1), inner(s));
        }
        let last = cols[cols.len() - 1].samples();
        for s in last.start..last.end - 1 {
            quad(&mut idx, o(s + 1), o(s), inner(s), inner(s + 1));
        }
    }
    if floor.is_some() {
        // The bottom across the outside ring, the floor's top across the
        // inside ring where the wall's inside stands on it.
        idx.extend(cap(&v, &ring_at(outside, 0)));
        idx.extend(cap(&v, &ring_at(inside, 0)));
    }
    orient(&mut idx);
    let mut tris: Vec<[[f64; 3]; 3]> = idx.iter().map(|t| t.map(|i| v[i])).collect();
    outward(&mut tris);
    tris
}

/// The triangles (vertex indices) of the flat face across a ring of
/// vertices, by `earcut` (non-convex rings of lobed and cornered pots).
fn cap(v: &[[f64; 3]], ring: &[usize]) -> Vec<[usize; 3]> {
    let mut idx: Vec<u32> = Vec::new();
    earcut::Earcut::new().earcut(
        ring.iter().map(|&i| [v[i][0], v[i][1]]),
        &[] as &[u32],
        &mut idx,
    );
    idx.chunks_exact(3)
        .map(|t| {
            [
                ring[t[0] as usize],
                ring[t[1] as usize],
                ring[t[2] as usize],
            ]
        })
        .collect()
}

/// Turns the triangles of a closed mesh so that each shares its edges
/// with its neighbours the opposite way round (a consistent orientation),
/// walking from the first triangle across shared edges.
fn orient(tris: &mut [[usize; 3]]) {
    let mut by_edge: rustc_hash::FxHashMap<(usize, usize), Vec<usize>> = Default::default();
    for (k, t) in tris.iter().enumerate() {
        for e in 0..3 {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            by_edge.entry((a.min(b), a.max(b))).or_default().push(k);
        }
    }
    let mut done = vec![false; tris.len()];
    for start in 0..tris.len() {
        if done[start] {
            continue;
        }
        done[start] = true;
        let mut stack = vec![start];
        while let Some(k) = stack.pop() {
            let t = tris[k];
            for e in 0..3 {
                let (a, b) = (t[e], t[(e + 1) % 3]);
                for &j in &by_edge[&(a.min(b), a.max(b))] {
                    if done[j] {
                        continue;
                    }
                    // The neighbour must run the shared edge b → a.
                    let u = tris[j];
                    let same = (0..3).any(|f| u[f] == a && u[(f + 1) % 3] == b);
                    if same {
                        tris[j].swap(1, 2);
                    }
                    done[j] = true;
                    stack.push(j);
                }
            }
        }
    }
}

/// Turns a closed shell's triangles so that their normals point out.
fn outward(tris: &mut [[[f64; 3]; 3]]) {
    if signed_volume(tris) < 0.0 {
        for t in tris.iter_mut() {
            t.swap(1, 2);
        }
    }
}

/// The volume enclosed by a closed, consistently oriented triangle mesh
/// (positive when the normals point out).
pub fn signed_volume(tris: &[[[f64; 3]; 3]]) -> f64 {
    tris.iter()
        .map(|[a, b, c]| {
            let cross = [
                b[1] * c[2] - b[2] * c[1],
                b[2] * c[0] - b[0] * c[2],
                b[0] * c[1] - b[1] * c[0],
            ];
            (a[0] * cross[0] + a[1] * cross[1] + a[2] * cross[2]) / 6.0
        })
        .sum()
}

fn normal(t: &[[f64; 3]; 3]) -> [f32; 3] {
    let u = [t[1][0] - t[0][0], t[1][1] - t[0][1], t[1][2] - t[0][2]];
    let w = [t[2][0] - t[0][0], t[2][1] - t[0][1], t[2][2] - t[0][2]];
    let n = [
        u[1] * w[2] - u[2] * w[1],
        u[2] * w[0] - u[0] * w[2],
        u[0] * w[1] - u[1] * w[0],
    ];
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if len > 0.0 {
        n.map(|x| (x / len) as f32)
    } else {
        [0.0; 3]
    }
}

/// Writes [`solid`] as a binary STL, in millimetres, in the design frame
/// (`o` at the origin, the bed at z = 0).
pub fn write_stl<W: Write>(s: &Sliced, out: &mut W) -> io::Result<()> {
    let tris = solid(s);
    let mesh = tris.iter().map(|t| stl_io::Triangle {
        normal: stl_io::Normal::new(normal(t)),
        vertices: t.map(|p| stl_io::Vertex::new(p.map(|x| x as f32))),
    });
    stl_io::write_stl(out, mesh)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rustc_hash::FxHashMap;

    fn sliced(name: &str) -> Sliced {
        let d = crate::Design::from_json(crate::examples::example(name).unwrap()).unwrap();
        crate::slice(&d).unwrap()
    }

    #[test]
    fn surface_strips_use_every_sample_and_twice_as_many_triangles() {
        let s = sliced("t2");
        let surf = &s.corrected.surface;
        let tris = surface_triangles(surf);
        // A strip between curves of na and nb samples has na + nb − 2 triangles.
        let expected: usize = surf
            .columns
            .windows(2)
            .map(|p| p[0].len() + p[1].len() - 2)
            .sum();
        assert_eq!(tris.len(), expected);
        let mut used = vec![false; surf.samples.len()];
        for t in &tris {
            for &i in t {
                used[i as usize] = true;
            }
        }
        assert!(used.iter().all(|&u| u));
    }

    #[test]
    fn path_points_map_onto_their_samples() {
        let s = sliced("t3");
        let of = path_index_of_samples(&s);
        let surf = &s.corrected.surface;
        for (si, &pi) in of.iter().enumerate() {
            let p = s.toolpath.points[pi as usize];
            let c = p.column as usize;
            assert_eq!(surf.position(c, si), p.pos);
        }
    }

    #[test]
    fn the_thickened_solid_is_closed_and_outward() {
        for name in ["t1", "t3", "t5", "cup", "flower"] {
            let s = sliced(name);
            let tris = solid(&s);
            // Every directed edge is matched by its reverse exactly once.
            let key = |p: [f64; 3]| p.map(|x| (x * 1e6).round() as i64);
            let mut edges: FxHashMap<([i64; 3], [i64; 3]), i32> = FxHashMap::default();
            for t in &tris {
                for e in 0..3 {
                    let (a, b) = (key(t[e]), key(t[(e + 1) % 3]));
                    *edges.entry((a, b)).or_default() += 1;
                }
            }
            for (&(a, b), &count) in &edges {
                assert_eq!(count, 1, "{name}: edge {a:?}→{b:?} used {count} times");
                assert_eq!(
                    edges.get(&(b, a)),
                    Some(&1),
                    "{name}: edge {a:?}→{b:?} has no reverse"
                );
            }
            // The solid's volume is about the clay volume (bead widths ×
            // layer heights), within the zig-zag's approximations.
            let vol = signed_volume(&tris) / 1000.0;
            let clay = s.stats.volume_ml;
            assert!(vol > 0.0, "{name}: normals point in");
            assert!(
                (vol / clay - 1.0).abs() < 0.25,
                "{name}: solid {vol:.1} ml vs clay {clay:.1} ml"
            );
        }
    }

    #[test]
    fn a_vessel_is_one_solid_standing_on_its_floor() {
        // Slicers read overlapping shells as holes: a vessel's wall and
        // floor are one shell (every triangle reached from every other
        // across shared edges; closed and outward as tested above).
        for name in ["cup", "flower", "vase"] {
            let s = sliced(name);
            let tris = solid(&s);
            let key = |p: [f64; 3]| p.map(|x| (x * 1e6).round() as i64);
            let mut by_edge: FxHashMap<([i64; 3], [i64; 3]), Vec<usize>> = FxHashMap::default();
            for (k, t) in tris.iter().enumerate() {
                for e in 0..3 {
                    let (a, b) = (key(t[e]), key(t[(e + 1) % 3]));
                    by_edge.entry((a.min(b), a.max(b))).or_default().push(k);
                }
            }
            let mut seen = vec![false; tris.len()];
            let mut stack = vec![0];
            seen[0] = true;
            while let Some(k) = stack.pop() {
                for e in 0..3 {
                    let (a, b) = (key(tris[k][e]), key(tris[k][(e + 1) % 3]));
                    for &j in &by_edge[&(a.min(b), a.max(b))] {
                        if !seen[j] {
                            seen[j] = true;
                            stack.push(j);
                        }
                    }
                }
            }
            let reached = seen.iter().filter(|&&x| x).count();
            assert_eq!(reached, tris.len(), "{name}: more than one shell");
        }
    }

    #[test]
    fn stl_has_the_binary_layout() {
        let s = sliced("t5");
        let mut bytes = Vec::new();
        write_stl(&s, &mut bytes).unwrap();
        let n = u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as usize;
        assert_eq!(n, solid(&s).len());
        assert_eq!(bytes.len(), 84 + 50 * n);
        let back = stl_io::read_stl(&mut std::io::Cursor::new(&bytes)).unwrap();
        assert_eq!(back.faces.len(), n);
    }
}
