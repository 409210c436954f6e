//! Horizontal sections of a triangle mesh (docs/MESHES.md): at evenly
//! spaced heights, every triangle that spans a height gives a segment
//! between two of its edges, and segments sharing an edge are chained
//! into loops. Edges are named by their vertices' indices, so the chaining
//! is exact (no tolerance): a loop that cannot close is a hole in the
//! mesh, refused naming the height. An edge with four or six segments
//! (bodies of a union touching along it) is chained body by body by the
//! faces' winding; one whose segments do not pair is refused as
//! non-manifold. Linear in the triangles and the segments,
//! with the segments capped ([`MAX_SEGMENTS`]) and each section thinned
//! as it is cut, so memory follows the mesh read, not its facets' height.

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
    /// Its triangle: where four faces share an edge, its winding tells
    /// which way the segment runs ([`runs_forward`]).
    tri: u32,
}

/// The most segments one cut computes: the sum over triangles of the
/// heights each spans. A mesh whose facets are tall and narrow (a
/// cylinder of 40,000 facets round, each the pot's height) crosses every
/// height with every facet; [`sections_within`] thins the heights so the
/// work stays under this (docs/MESHES.md, "Work and memory").
pub const MAX_SEGMENTS: u64 = 24_000_000;

/// Points of a section closer than this to the chord that replaces them
/// are dropped as they are cut (mm): far below any fit's tolerance, and
/// it keeps a finely faceted mesh's sections (and the memory they take)
/// to the points their shape needs.
pub const SIMPLIFY_MM: f64 = 0.002;

/// Loops of at most this many points are kept as cut: a mesh people model
/// has far fewer a section, and the fits were tuned on its own points
/// (thinning the bundled pitcher's sections moved its rim's fit by 0.02
/// mm); only a loop this dense is thinned.
pub const THIN_ABOVE: usize = 4096;

/// The triangle's lowest and highest height indices among `n` heights
/// `z0 + k·dz` (empty when `first > last`).
fn span(zs: [f64; 3], z0: f64, dz: f64, n: usize) -> (i64, i64) {
    let lo = zs.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = zs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    // The range starts a height early: a vertex a rounding below z_k gave
    // (lo − z0) / dz = k exactly, and the floor + 1 skipped the height its
    // triangles cross (a ring of a mesh at half a pot's height left that
    // section empty). The exact test is in `segment`.
    let first = (((lo - z0) / dz).floor() as i64).max(0);
    let last = (((hi - z0) / dz).ceil() as i64).min(n as i64 - 1);
    (first, last)
}

/// How many segments cutting `mesh` at `n` heights computes.
pub fn work(mesh: &TriMesh, z0: f64, dz: f64, n: usize) -> u64 {
    let v = &mesh.vertices;
    mesh.triangles
        .iter()
        .map(|t| {
            let (a, b) = span(t.map(|i| v[i as usize][2]), z0, dz, n);
            (b - a + 1).max(0) as u64
        })
        .sum()
}

/// The most of `n` heights over `height` (from `z0` = half a spacing up)
/// that keeps the cut's work within [`MAX_SEGMENTS`], and at least
/// `min`; `None` when even `min` heights are over it.
pub fn sections_within(
    mesh: &TriMesh,
    bottom: f64,
    height: f64,
    n: usize,
    min: usize,
) -> Option<usize> {
    let at = |n: usize| {
        let dz = height / n as f64;
        work(mesh, bottom + 0.5 * dz, dz, n)
    };
    let w = at(n);
    if w <= MAX_SEGMENTS {
        return Some(n);
    }
    // Work grows about linearly with the heights: scale, then step down.
    let mut m = ((n as f64 * MAX_SEGMENTS as f64 / w as f64) as usize).clamp(min, n);
    while m > min && at(m) > MAX_SEGMENTS {
        m = (m * 9 / 10).max(min);
    }
    (at(m) <= MAX_SEGMENTS).then_some(m)
}

/// The segment a triangle `t` cuts at height `z`, if it crosses it.
fn segment(mesh: &TriMesh, tri: u32, z: f64, up: bool) -> Option<Seg> {
    let v = &mesh.vertices;
    let t = mesh.triangles[tri as usize];
    let below = t.map(|i| v[i as usize][2] < z);
    if below.iter().all(|&b| b) || below.iter().all(|&b| !b) {
        return None;
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
    Some(Seg { ends, at, up, tri })
}

/// Whether `g`'s face's winding runs it from `at[0]` to `at[1]` with the
/// solid on its left (an outward normal). Asked only at an edge more
/// than two faces share, so the cut's every segment does not pay for it.
fn runs_forward(mesh: &TriMesh, g: &Seg) -> bool {
    // The solid lies away from the normal: along (−n_y, n_x), on the left.
    let n = normal(mesh, mesh.triangles[g.tri as usize]);
    let d = [g.at[1][0] - g.at[0][0], g.at[1][1] - g.at[0][1]];
    -n[1] * d[0] + n[0] * d[1] >= 0.0
}

/// Whether a triangle lies within 26° of level ([`UP`]), either way up: a
/// mesh whose faces are flipped (or wound inside out) has its cap facing
/// down.
fn level(mesh: &TriMesh, t: [u32; 3]) -> bool {
    let n = normal(mesh, t);
    n[2].abs() > UP * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt()
}

/// A triangle's normal by its winding (not of unit length).
fn normal(mesh: &TriMesh, t: [u32; 3]) -> [f64; 3] {
    let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
    let (e, f) = (
        [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
        [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
    );
    [
        e[1] * f[2] - e[2] * f[1],
        e[2] * f[0] - e[0] * f[2],
        e[0] * f[1] - e[1] * f[0],
    ]
}

/// Cuts `mesh` at `n` heights `z0`, `z0 + dz`, …. A vertex exactly at a
/// height counts as above it, so no crossing falls on a vertex. Errors
/// and sections give heights above `bed` (the mesh's lowest point, for
/// the user; 0 keeps the mesh's own).
///
/// The heights are swept upward with the set of triangles spanning the
/// current one, and each section is chained and thinned
/// ([`SIMPLIFY_MM`]) before the next is cut: memory is the triangles, one
/// section's segments and the thinned loops, never every segment at once.
/// A cut whose work is over [`MAX_SEGMENTS`] is refused naming the cap
/// ([`sections_within`] chooses heights that keep under it).
pub fn cut(mesh: &TriMesh, z0: f64, dz: f64, n: usize, bed: f64) -> Result<Vec<Section>> {
    let v = &mesh.vertices;
    let spans: Vec<(i64, i64)> = mesh
        .triangles
        .iter()
        .map(|t| span(t.map(|i| v[i as usize][2]), z0, dz, n))
        .collect();
    let w: u64 = spans.iter().map(|&(a, b)| (b - a + 1).max(0) as u64).sum();
    if w > MAX_SEGMENTS {
        return Err(Error::invalid(
            "mesh",
            format!("cutting it at {n} heights would compute {w} segments, over the cap of {MAX_SEGMENTS}: its facets are very many and tall; decimate it (Blender's Decimate, MeshLab's Quadric Edge Collapse)"),
        ));
    }
    // Triangles by the first height they span (a counting sort).
    let mut starts = vec![0u32; n + 1];
    for &(a, b) in &spans {
        if a <= b {
            starts[a as usize + 1] += 1;
        }
    }
    for k in 0..n {
        starts[k + 1] += starts[k];
    }
    let mut fill = starts.clone();
    let mut order = vec![0u32; starts[n] as usize];
    for (i, &(a, b)) in spans.iter().enumerate() {
        if a <= b {
            order[fill[a as usize] as usize] = i as u32;
            fill[a as usize] += 1;
        }
    }
    drop(fill);
    let mut active: Vec<(u32, bool)> = Vec::new();
    let mut segs: Vec<Seg> = Vec::new();
    let mut out = Vec::with_capacity(n);
    for k in 0..n {
        active.retain(|&(i, _)| spans[i as usize].1 >= k as i64);
        for &i in &order[starts[k] as usize..starts[k + 1] as usize] {
            active.push((i, level(mesh, mesh.triangles[i as usize])));
        }
        let z = z0 + k as f64 * dz;
        segs.clear();
        segs.extend(active.iter().filter_map(|&(i, up)| segment(mesh, i, z, up)));
        let zb = z - bed;
        let (loops, up) = chain(mesh, &segs, zb)?
            .into_iter()
            .map(|(p, u)| thin(p, u, SIMPLIFY_MM))
            .unzip();
        out.push(Section { z: zb, loops, up });
    }
    Ok(out)
}

/// Drops the points of a closed loop that lie within `eps` of the chord
/// that replaces them, in one pass (the wedge of directions from the last
/// kept point that passes within `eps` of every point since narrows with
/// each point; where it closes, the point before is kept). A point where
/// the segments' level flag changes is kept, so each kept segment carries
/// one flag. Linear in the points.
fn thin(pts: Vec<[f64; 2]>, up: Vec<bool>, eps: f64) -> Loop {
    let n = pts.len();
    if n < 8 || n <= THIN_ABOVE {
        return (pts, up);
    }
    let mut keep = vec![0usize];
    let mut anchor = 0usize;
    // The wedge: angles relative to `reference`, and the farthest reach.
    let mut wedge: Option<(f64, f64)> = None;
    let mut reference = [0.0f64; 2];
    let mut reach = 0.0f64;
    let mut i = 1;
    while i <= n {
        let p = pts[i % n];
        let a = pts[anchor];
        let d = [p[0] - a[0], p[1] - a[1]];
        let len = d[0].hypot(d[1]);
        let must = i < n && up[i] != up[i - 1];
        if len > eps && wedge.is_none() {
            reference = [d[0] / len, d[1] / len];
            wedge = Some((-std::f64::consts::PI, std::f64::consts::PI));
        }
        let fits = match wedge {
            None => true,
            Some((lo, hi)) => {
                let ang = (reference[0] * d[1] - reference[1] * d[0])
                    .atan2(reference[0] * d[0] + reference[1] * d[1]);
                lo <= ang && ang <= hi && len >= reach - eps
            }
        };
        if !fits && i - 1 > anchor {
            // The chord to here would pass too far from a point since the
            // anchor: the point before is kept and starts a new chord.
            anchor = i - 1;
            keep.push(anchor);
            wedge = None;
            reach = 0.0;
            continue;
        }
        if let Some((lo, hi)) = wedge.as_mut() {
            if len > eps {
                let ang = (reference[0] * d[1] - reference[1] * d[0])
                    .atan2(reference[0] * d[0] + reference[1] * d[1]);
                let half = (eps / len).asin();
                *lo = lo.max(ang - half);
                *hi = hi.min(ang + half);
            }
            reach = reach.max(len);
        }
        if must {
            anchor = i;
            keep.push(anchor);
            wedge = None;
            reach = 0.0;
        }
        i += 1;
    }
    if keep.len() < 3 {
        return (pts, up);
    }
    let kept_up = keep.iter().map(|&k| up[k]).collect();
    (keep.into_iter().map(|k| pts[k]).collect(), kept_up)
}

/// A loop and whether each of its segments lies on a level face.
type Loop = (Vec<[f64; 2]>, Vec<bool>);

/// Chains the segments of one section into closed loops.
fn chain(mesh: &TriMesh, segs: &[Seg], z: f64) -> Result<Vec<Loop>> {
    let mut by_edge: FxHashMap<u64, [u32; 2]> = FxHashMap::default();
    // Edges shared by more than two faces: all their segments.
    let mut shared: FxHashMap<u64, Vec<u32>> = FxHashMap::default();
    for (s, g) in segs.iter().enumerate() {
        for e in g.ends {
            let slot = by_edge.entry(e).or_insert([u32::MAX; 2]);
            if slot[0] == u32::MAX {
                slot[0] = s as u32;
            } else if slot[1] == u32::MAX {
                slot[1] = s as u32;
            } else {
                shared
                    .entry(e)
                    .or_insert_with(|| slot.to_vec())
                    .push(s as u32);
            }
        }
    }
    // Where two bodies touch along an edge (a union exported without
    // merging), each segment arriving there goes on with the one leaving
    // nearest clockwise: each body's loop keeps to itself.
    let mut paired: FxHashMap<(u64, u32), u32> = FxHashMap::default();
    for (&e, list) in &shared {
        pair_at_edge(mesh, segs, e, list, &mut paired).ok_or_else(|| {
            Error::invalid(
                "mesh",
                format!("an edge at z = {z:.2} mm is shared by {} faces (a non-manifold mesh) that do not pair into closed surfaces: repair it (MeshLab, Blender's 3D-Print toolbox)", list.len()),
            )
        })?;
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
            let next = match paired.get(&(e, s as u32)) {
                Some(&n) => n,
                None if a as usize == s => b,
                None => a,
            };
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

/// Pairs the segments `list` that meet at edge `e` (more than two):
/// each arriving one (running into the edge with the solid on its left)
/// with the leaving one first met turning clockwise from where it came
/// from, both ways in `paired`. `None` when they do not pair (an odd
/// count, a face wound against its neighbours).
fn pair_at_edge(
    mesh: &TriMesh,
    segs: &[Seg],
    e: u64,
    list: &[u32],
    paired: &mut FxHashMap<(u64, u32), u32>,
) -> Option<()> {
    // Each segment's far end seen from the edge's crossing.
    let from_edge = |s: u32| {
        let g = &segs[s as usize];
        let (here, far) = if g.ends[0] == e { (0, 1) } else { (1, 0) };
        let arrives = (here == 1) == runs_forward(mesh, g);
        (
            arrives,
            [g.at[far][0] - g.at[here][0], g.at[far][1] - g.at[here][1]],
        )
    };
    let (arriving, leaving): (Vec<_>, Vec<_>) = list
        .iter()
        .map(|&s| (s, from_edge(s)))
        .partition(|(_, (arrives, _))| *arrives);
    if arriving.len() != leaving.len() {
        return None;
    }
    let mut taken = vec![false; leaving.len()];
    for (a, (_, back)) in arriving {
        let cw = |o: [f64; 2]| {
            let ccw = (back[0] * o[1] - back[1] * o[0]).atan2(back[0] * o[0] + back[1] * o[1]);
            (-ccw).rem_euclid(std::f64::consts::TAU)
        };
        let k = (0..leaving.len())
            .filter(|&k| !taken[k])
            .min_by(|&i, &j| cw(leaving[i].1 .1).total_cmp(&cw(leaving[j].1 .1)))?;
        taken[k] = true;
        let l = leaving[k].0;
        paired.insert((e, a), l);
        paired.insert((e, l), a);
    }
    Some(())
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

    /// Two boxes touching along an edge (a union exported unmerged): the
    /// edge is shared by four faces, and each box's loop keeps to itself.
    #[test]
    fn boxes_touching_along_an_edge_cut_into_two_loops() {
        let mut m = cube(10.0, 20.0);
        let b = cube(10.0, 20.0);
        let n = m.vertices.len() as u32;
        m.vertices
            .extend(b.vertices.iter().map(|v| [v[0] + 10.0, v[1] + 10.0, v[2]]));
        m.triangles
            .extend(b.triangles.iter().map(|t| t.map(|i| i + n)));
        m.repair();
        let s = cut(&m, 0.5, 1.0, 19, 0.0).unwrap();
        for sec in &s {
            assert_eq!(sec.loops.len(), 2, "at {}", sec.z);
            for l in &sec.loops {
                assert!((signed_area2(l).abs() - 200.0).abs() < 1e-9, "{l:?}");
            }
        }
        // Wound against its neighbours, the fourth face does not pair.
        let flipped = m
            .triangles
            .iter()
            .position(|t| t.contains(&3) && t.contains(&7))
            .unwrap();
        m.triangles[flipped].swap(0, 1);
        let e = cut(&m, 0.5, 1.0, 19, 0.0).unwrap_err().to_string();
        assert!(e.contains("non-manifold"), "{e}");
    }

    #[test]
    fn a_hole_is_named_by_its_height() {
        let mut m = cube(10.0, 20.0);
        m.triangles.remove(4);
        let e = cut(&m, 0.5, 1.0, 19, 0.0).unwrap_err().to_string();
        assert!(e.contains("has a hole") && e.contains("z = 0.50 mm"), "{e}");
    }

    /// The distance from `p` to the segment `a`–`b`.
    fn to_segment(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
        let (d, e) = ([b[0] - a[0], b[1] - a[1]], [p[0] - a[0], p[1] - a[1]]);
        let l2 = d[0] * d[0] + d[1] * d[1];
        let t = if l2 > 0.0 {
            ((e[0] * d[0] + e[1] * d[1]) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (e[0] - t * d[0]).hypot(e[1] - t * d[1])
    }

    #[test]
    fn thinning_keeps_every_point_within_its_tolerance() {
        // A circle of 40,000 facets keeps a few hundred points; a square
        // drawn with 1,100 points a side keeps its corners; every point
        // dropped lies within eps of the kept loop.
        let circle: Vec<[f64; 2]> = (0..40_000)
            .map(|i| {
                let a = i as f64 / 40_000.0 * std::f64::consts::TAU;
                [50.0 * a.cos(), 50.0 * a.sin()]
            })
            .collect();
        let mut square = Vec::new();
        for side in 0..4 {
            for j in 0..1100 {
                let t = j as f64 / 1100.0 * 20.0 - 10.0;
                square.push(match side {
                    0 => [t, -10.0],
                    1 => [10.0, t],
                    2 => [-t, 10.0],
                    _ => [-10.0, -t],
                });
            }
        }
        for (pts, most) in [(circle, 1000), (square, 4)] {
            let up: Vec<bool> = vec![false; pts.len()];
            let (kept, _) = thin(pts.clone(), up, 0.002);
            assert!(kept.len() <= most && kept.len() >= 4, "{}", kept.len());
            let worst = pts
                .iter()
                .map(|&p| {
                    (0..kept.len())
                        .map(|k| to_segment(p, kept[k], kept[(k + 1) % kept.len()]))
                        .fold(f64::INFINITY, f64::min)
                })
                .fold(0.0, f64::max);
            assert!(worst <= 0.002 + 1e-9, "{worst}");
        }
        // A change of the level flag keeps its point.
        let pts: Vec<[f64; 2]> = (0..100)
            .map(|i| {
                let a = i as f64 / 100.0 * std::f64::consts::TAU;
                [a.cos(), a.sin()]
            })
            .collect();
        let up: Vec<bool> = (0..100).map(|i| (30..60).contains(&i)).collect();
        let (kept, kept_up) = thin(pts.clone(), up, 0.5);
        assert!(kept.contains(&pts[30]) && kept.contains(&pts[60]));
        assert!(kept_up.iter().any(|&u| u));
    }

    #[test]
    fn tall_facets_are_cut_within_the_work_cap() {
        // A cylinder of 40,000 facets round, each the whole height: 800
        // sections would compute 64 million segments.
        let m = 40_000u32;
        let mut vertices = Vec::new();
        for z in [0.0, 100.0] {
            for i in 0..m {
                let a = f64::from(i) / f64::from(m) * std::f64::consts::TAU;
                vertices.push([50.0 * a.cos(), 50.0 * a.sin(), z]);
            }
        }
        vertices.push([0.0, 0.0, 0.0]);
        let mut triangles = Vec::new();
        for i in 0..m {
            let j = (i + 1) % m;
            triangles.push([i, j, m + j]);
            triangles.push([i, m + j, m + i]);
            triangles.push([2 * m, j, i]);
        }
        let mesh = TriMesh {
            vertices,
            triangles,
        };
        assert!(work(&mesh, 0.0625, 0.125, 800) > MAX_SEGMENTS);
        let e = cut(&mesh, 0.0625, 0.125, 800, 0.0).unwrap_err().to_string();
        assert!(e.contains("over the cap"), "{e}");
        let n = sections_within(&mesh, 0.0, 100.0, 800, 20).unwrap();
        assert!((20..800).contains(&n), "{n}");
        let dz = 100.0 / n as f64;
        let s = cut(&mesh, 0.5 * dz, dz, n, 0.0).unwrap();
        assert_eq!(s.len(), n);
        assert!(s
            .iter()
            .all(|sec| sec.loops.len() == 1 && sec.loops[0].len() < 2000));
    }
}
