//! Triangle meshes in: binary and ASCII STL (through `stl_io`) and OBJ,
//! read from bytes into one indexed [`TriMesh`] in millimetres
//! (docs/MESHES.md). Pure: the caller reads the file.

use crate::error::{Error, Result};

/// An indexed triangle mesh: vertices shared by the triangles that use
/// them, so an edge is the pair of its vertices' indices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions (mm once scaled).
    pub vertices: Vec<[f64; 3]>,
    /// Triangles as indices into `vertices`.
    pub triangles: Vec<[u32; 3]>,
}

/// The most triangles a mesh may have: a scan of a pot at 0.1 mm is a
/// few million; beyond this the cutting's memory is the limit.
pub const MAX_TRIANGLES: usize = 8_000_000;

impl TriMesh {
    /// Reads STL (binary or ASCII) or OBJ, told apart by `name`'s
    /// extension (`.stl`, `.obj`; any case). Errors name the file's
    /// format and what is wrong.
    pub fn read(name: &str, bytes: &[u8]) -> Result<TriMesh> {
        let lower = name.to_ascii_lowercase();
        let mesh = if lower.ends_with(".obj") {
            read_obj(bytes)?
        } else if lower.ends_with(".stl") {
            read_stl(bytes)?
        } else {
            return Err(Error::invalid(
                "mesh",
                format!("`{name}`: not a mesh file this reads (STL or OBJ, by the extension)"),
            ));
        };
        let mut mesh = mesh;
        mesh.check()?;
        mesh.repair();
        Ok(mesh)
    }

    /// The standard repairs that change no surface: vertices at the same
    /// place are one; where that leaves the mesh open (a seam written
    /// with two roundings of one point, a crack no section can close),
    /// vertices less than a hundred-thousandth of the mesh's size apart
    /// are merged too (a micrometre on a 100 mm pot, in whatever unit the
    /// file has: Blender's "Merge by Distance"). A mesh already closed is
    /// not merged by distance: an OpenSCAD export's points a micrometre
    /// apart are its own. Then triangles with a repeated vertex (no area,
    /// they join nothing) and second copies of a triangle (exporters
    /// write some twice) are dropped, and a triangle with a copy wound
    /// the other way goes with it (two faces back to back: a sheet of no
    /// thickness where two bodies of a union touch). Returns how many triangles were.
    pub fn repair(&mut self) -> usize {
        let before = self.triangles.len();
        self.merge(|v| v.map(f64::to_bits));
        if !self.closed() {
            let (lo, hi) = self.bounds();
            let size = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max);
            let step = (1e-5 * size).max(f64::MIN_POSITIVE);
            self.merge(|v| v.map(|x| (x / step).round() as i64 as u64));
        }
        // Each triangle's corners in order, and which way round they run.
        let mut seen: rustc_hash::FxHashMap<[u32; 3], (usize, bool)> =
            rustc_hash::FxHashMap::default();
        let mut keep = vec![true; self.triangles.len()];
        for (i, t) in self.triangles.iter().enumerate() {
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                keep[i] = false;
                continue;
            }
            let mut k = *t;
            k.sort_unstable();
            // A rotation of the sorted corners keeps the winding.
            let way = [k, [k[1], k[2], k[0]], [k[2], k[0], k[1]]].contains(t);
            match seen.entry(k) {
                std::collections::hash_map::Entry::Vacant(v) => {
                    v.insert((i, way));
                }
                std::collections::hash_map::Entry::Occupied(o) => {
                    keep[i] = false;
                    // A copy wound the other way: the two are a sheet of
                    // no thickness (a union's shared face), and both go.
                    let (j, first) = *o.get();
                    if first != way {
                        keep[j] = false;
                    }
                }
            }
        }
        let mut kept = keep.into_iter();
        self.triangles.retain(|_| kept.next().unwrap_or(false));
        before - self.triangles.len()
    }

    /// Makes the vertices with one `key` one vertex.
    fn merge(&mut self, key: impl Fn([f64; 3]) -> [u64; 3]) {
        let mut index: rustc_hash::FxHashMap<[u64; 3], u32> = rustc_hash::FxHashMap::default();
        let mut merged = Vec::with_capacity(self.vertices.len());
        let remap: Vec<u32> = self
            .vertices
            .iter()
            .map(|v| {
                *index.entry(key(*v)).or_insert_with(|| {
                    merged.push(*v);
                    merged.len() as u32 - 1
                })
            })
            .collect();
        self.vertices = merged;
        for t in &mut self.triangles {
            *t = t.map(|i| remap[i as usize]);
        }
    }

    /// Whether every edge joins exactly two triangles.
    fn closed(&self) -> bool {
        let mut count: rustc_hash::FxHashMap<(u32, u32), u32> = rustc_hash::FxHashMap::default();
        for t in &self.triangles {
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                *count.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        count.values().all(|&c| c == 2)
    }

    /// The lowest and highest corner of the mesh's bounding box.
    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for v in &self.vertices {
            for a in 0..3 {
                lo[a] = lo[a].min(v[a]);
                hi[a] = hi[a].max(v[a]);
            }
        }
        (lo, hi)
    }

    /// Scales every vertex by `k` about the origin.
    pub fn scale(&mut self, k: f64) {
        for v in &mut self.vertices {
            *v = v.map(|x| x * k);
        }
    }

    /// Turns the mesh so that its axis `up` (0 x, 1 y, 2 z) points up,
    /// a quarter turn about another axis (a Y-up export stands on its
    /// side otherwise).
    pub fn stand_up(&mut self, up: usize) {
        for v in &mut self.vertices {
            *v = match up {
                0 => [v[1], v[2], v[0]],
                1 => [v[0], -v[2], v[1]],
                _ => *v,
            };
        }
    }

    /// A closed solid standing on z = 0 whose section at height z is the
    /// loop of radius `r(θ, z)` about the z axis: `m` vertices round,
    /// `k + 1` rings up to `h`, capped top and bottom by fans. Closed-form
    /// meshes for tests and benchmarks (a revolved pot, a lofted oval, a
    /// twisted polygon).
    pub fn solid_of(r: impl Fn(f64, f64) -> f64, h: f64, m: usize, k: usize) -> TriMesh {
        TriMesh::solid_under(r, |_| h, m, k)
    }

    /// As [`TriMesh::solid_of`], its wall at angle θ rising to `top(θ)`:
    /// ring i at `top(θ) · i / k`, the top a fan to a vertex at the mean
    /// height over o. A rim that slants or rises to one side, under a cap.
    pub fn solid_under(
        r: impl Fn(f64, f64) -> f64,
        top: impl Fn(f64) -> f64,
        m: usize,
        k: usize,
    ) -> TriMesh {
        let mut vertices = Vec::with_capacity(m * (k + 1) + 2);
        let mut mean = 0.0;
        for i in 0..=k {
            for j in 0..m {
                let a = std::f64::consts::TAU * j as f64 / m as f64;
                let z = top(a) * i as f64 / k as f64;
                let rr = r(a, z);
                vertices.push([rr * a.cos(), rr * a.sin(), z]);
                if i == k {
                    mean += z / m as f64;
                }
            }
        }
        let (bottom, top) = (vertices.len() as u32, vertices.len() as u32 + 1);
        vertices.push([0.0, 0.0, 0.0]);
        vertices.push([0.0, 0.0, mean]);
        let id = |i: usize, j: usize| (i * m + j % m) as u32;
        let mut triangles = Vec::with_capacity(2 * m * (k + 1));
        for i in 0..k {
            for j in 0..m {
                triangles.push([id(i, j), id(i, j + 1), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i + 1, j)]);
            }
        }
        for j in 0..m {
            triangles.push([bottom, id(0, j + 1), id(0, j)]);
            triangles.push([top, id(k, j), id(k, j + 1)]);
        }
        TriMesh {
            vertices,
            triangles,
        }
    }

    /// Moves every vertex by `d`.
    pub fn translate(&mut self, d: [f64; 3]) {
        for v in &mut self.vertices {
            *v = [v[0] + d[0], v[1] + d[1], v[2] + d[2]];
        }
    }

    fn check(&self) -> Result<()> {
        if self.triangles.is_empty() {
            return Err(Error::invalid("mesh", "has no triangles"));
        }
        if self.triangles.len() > MAX_TRIANGLES {
            return Err(Error::invalid(
                "mesh",
                format!(
                    "has {} triangles, over the cap of {MAX_TRIANGLES}; decimate it (Blender's Decimate, MeshLab's Quadric Edge Collapse)",
                    self.triangles.len()
                ),
            ));
        }
        if let Some(v) = self
            .vertices
            .iter()
            .find(|v| v.iter().any(|x| !x.is_finite()))
        {
            return Err(Error::invalid(
                "mesh",
                format!("has a vertex that is not a number: {v:?}"),
            ));
        }
        Ok(())
    }
}

fn read_stl(bytes: &[u8]) -> Result<TriMesh> {
    // A binary STL states its triangle count: refuse a huge one before
    // the reader allocates for it.
    if bytes.len() >= 84 && !bytes.starts_with(b"solid") {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        if n > MAX_TRIANGLES {
            return Err(Error::invalid(
                "mesh",
                format!("states {n} triangles, over the cap of {MAX_TRIANGLES}"),
            ));
        }
    }
    let m = stl_io::read_stl(&mut std::io::Cursor::new(bytes))
        .map_err(|e| Error::invalid("mesh", format!("not a readable STL: {e}")))?;
    Ok(TriMesh {
        vertices: m.vertices.iter().map(|v| v.0.map(f64::from)).collect(),
        triangles: m
            .faces
            .iter()
            .map(|f| f.vertices.map(|i| i as u32))
            .collect(),
    })
}

/// OBJ's `v` and `f` lines (faces of any size, fanned into triangles;
/// `i/t/n` forms and negative indices); everything else is skipped.
fn read_obj(bytes: &[u8]) -> Result<TriMesh> {
    let text = std::str::from_utf8(bytes)
        .map_err(|e| Error::invalid("mesh", format!("an OBJ file must be text: {e}")))?;
    let mut m = TriMesh::default();
    for (k, line) in text.lines().enumerate() {
        let bad = |what: &str| Error::invalid("mesh", format!("OBJ line {}: {what}", k + 1));
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let xyz: Vec<f64> = words
                    .take(3)
                    .map(str::parse)
                    .collect::<std::result::Result<_, _>>()
                    .map_err(|_| bad("a vertex needs three numbers"))?;
                if xyz.len() < 3 {
                    return Err(bad("a vertex needs three numbers"));
                }
                m.vertices.push([xyz[0], xyz[1], xyz[2]]);
            }
            Some("f") => {
                let n = m.vertices.len() as i64;
                let index = |w: &str| {
                    let i: i64 = w
                        .split('/')
                        .next()
                        .unwrap_or("")
                        .parse()
                        .map_err(|_| bad("a face's index is not a number"))?;
                    let i = if i < 0 { n + i } else { i - 1 };
                    if i < 0 || i >= n {
                        return Err(bad("a face names a vertex not yet given"));
                    }
                    Ok(i as u32)
                };
                // Fanned as it is read, the cap checked before each
                // triangle: a face of millions of indices is never held.
                let (first, mut prev, mut count) = (words.next(), None, 0usize);
                let first = first.map(index).transpose()?;
                for w in words {
                    let i = index(w)?;
                    if let (Some(a), Some(b)) = (first, prev) {
                        if m.triangles.len() >= MAX_TRIANGLES {
                            return Err(bad(&format!("over the cap of {MAX_TRIANGLES} triangles")));
                        }
                        m.triangles.push([a, b, i]);
                    }
                    prev = Some(i);
                    count += 1;
                }
                if first.is_none() || count < 2 {
                    return Err(bad("a face needs three vertices"));
                }
            }
            _ => {}
        }
    }
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn obj_faces_are_fanned_and_errors_name_the_line() {
        let m = TriMesh::read(
            "quad.OBJ",
            b"# a square\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1/1 2/2 3/3 -1\n",
        )
        .unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        let e = TriMesh::read("x.obj", b"v 0 0 0\nf 1 2 3\n").unwrap_err();
        assert!(e.to_string().contains("OBJ line 2"), "{e}");
        let e = TriMesh::read("x.obj", b"v 0 0 0\nv 1 0 0\nf 1 2\n").unwrap_err();
        assert!(e.to_string().contains("three vertices"), "{e}");
        let e = TriMesh::read("x.ply", b"").unwrap_err();
        assert!(e.to_string().contains("STL or OBJ"), "{e}");
    }

    #[test]
    fn a_face_of_millions_of_indices_stops_at_the_cap_unexpanded() {
        // Before, the face's indices were collected and fanned whole (a 95
        // MB OBJ took 1.6 GB) before the cap was checked.
        let mut obj = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\nf");
        obj.reserve(2 * (MAX_TRIANGLES + 10));
        for k in 0..MAX_TRIANGLES + 10 {
            obj.push_str(if k % 2 == 0 { " 1" } else { " 2" });
        }
        obj.push('\n');
        let e = TriMesh::read("fan.obj", obj.as_bytes()).unwrap_err();
        assert!(e.to_string().contains("over the cap"), "{e}");
    }

    #[test]
    fn ascii_stl_shares_its_vertices() {
        let stl = b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 1 0 0\nvertex 1 1 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
        let m = TriMesh::read("t.stl", stl).unwrap();
        assert_eq!(m.vertices.len(), 4);
        assert_eq!(m.triangles.len(), 2);
    }

    /// A tetrahedron of size `k`; with `crack`, one face has its first
    /// corner written a second time that far away (a seam rounded twice).
    fn tetra(k: f64, crack: Option<f64>) -> TriMesh {
        let mut m = TriMesh {
            vertices: vec![[0.0, 0.0, 0.0], [k, 0.0, 0.0], [0.0, k, 0.0], [0.0, 0.0, k]],
            triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        };
        if let Some(c) = crack {
            m.vertices.push([c, 0.0, 0.0]);
            m.triangles[2] = [4, 3, 2];
        }
        m
    }

    /// Two tetrahedra joined on a face, each written whole (a union
    /// exported unmerged): the shared face, twice and wound both ways, is
    /// no surface; a face written twice the same way is one.
    #[test]
    fn a_face_back_to_back_goes_and_a_copy_is_one() {
        let mut m = tetra(10.0, None);
        m.vertices.push([10.0, 10.0, 10.0]);
        // The second body, over face [1, 2, 3] wound the other way.
        m.triangles
            .extend([[1, 3, 2], [1, 4, 3], [2, 3, 4], [1, 2, 4]]);
        assert!(!m.closed());
        assert_eq!(m.repair(), 2);
        assert!(m.closed());
        assert_eq!(m.triangles.len(), 6);
        let mut m = tetra(10.0, None);
        m.triangles.push([2, 3, 1]);
        assert_eq!(m.repair(), 1);
        assert!(m.closed());
    }

    #[test]
    fn a_crack_is_closed_at_any_unit_and_a_closed_mesh_keeps_its_points() {
        // 100 mm with a 0.3 µm crack; 0.1 m with 0.3 µm: both closed.
        for (k, crack) in [(100.0, 3e-4), (0.1, 3e-7)] {
            let mut m = tetra(k, Some(crack));
            assert!(!m.closed(), "{k}");
            m.repair();
            assert!(m.closed(), "{k}: merged");
            assert_eq!(m.vertices.len(), 4, "{k}");
        }
        // A closed tetrahedron 0.8 mm across in metres: the old merge (a
        // micrometre in the file's unit, here a millimetre) made it one
        // point; closed, nothing is merged.
        let mut m = tetra(0.0008, None);
        assert!(m.closed());
        assert_eq!(m.repair(), 0);
        assert_eq!((m.vertices.len(), m.triangles.len()), (4, 4));
    }
}
