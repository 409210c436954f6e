//! A vessel mesh back to an editable design (docs/MESHES.md): the mesh is
//! cut into horizontal sections ([`crate::sections`]); the bottom
//! section's wall is the trajectory Ψ; along rays from Ψ (radial from the
//! centre, or along Ψ's normal) each section's wall lies at an offset
//! D(k, j); and D is fitted by the design's own form — one profile, or two
//! blended round the loop by an interpolation curve, D ≈ S(z) + λ(u)·(T(z)
//! − S(z)) (the paper's §3 sweep, eq. 1–2). The fit's profiles,
//! interpolation and, where it holds, loop are B-splines of the fewest
//! control points that hold the tolerance (least squares, or a
//! polyline's corners; a loop also a polygon), and the
//! largest difference between the fitted design and the mesh's sections
//! is measured and reported with where it lies. What no bead prints
//! (details, drainage holes, a floor's groove, creases, a tilted foot)
//! is taken in and said; a handle, feet, an opened wall, a wall folding
//! back wider than a bead, a mesh with a hole, or a fit beyond the
//! tolerance is refused by name (docs/MESHES.md, "Details").
//!
//! The pot is its outside: a solid (one loop a section) and a shell (two
//! nested loops: a wall with its thickness, as sweepclay's own STL export
//! writes) are both fitted half a bead inside their outside, so the
//! printed bead's outer edge lies on it; a wall thicker than the bead
//! keeps its outside and says how far its inside moved. Cost: linear in the triangles
//! (cutting) plus sections × rays × loop points (about 0.1 s for a pot).

use crate::bspline::BSpline;
use crate::design::{CurveSpec, Design, Offset, TrajectorySpec};
use crate::error::{Error, Result};
use crate::meshread::TriMesh;
use crate::relief::Relief;
use crate::sections::{self, signed_area2};

mod loopfit;
mod rays;
mod relief;
mod ribs;
mod through;
mod twist;
mod uneven;

use rays::*;
use relief::*;
use through::*;
use uneven::*;

/// How a mesh is fitted.
#[derive(Clone, Debug, PartialEq)]
pub struct FitOptions {
    /// The largest difference the fitted design may have from the mesh
    /// (mm).
    pub tolerance_mm: f64,
    /// The design's name.
    pub name: String,
    /// Beyond the tolerance, keep what the mesh has beyond the closest
    /// sweep as the design's relief (printed as the mesh is) rather than
    /// refuse it.
    pub relief: bool,
    /// The bead the pot will be printed with (mm, the design's
    /// `width_min`): the wall's centre line is fitted half of it inside
    /// the mesh's outside, so the printed bead's outer edge is the
    /// mesh's outside (docs/MESHES.md, "The outside is the pot").
    pub bead_mm: f64,
}

impl Default for FitOptions {
    fn default() -> FitOptions {
        FitOptions {
            tolerance_mm: 0.3,
            name: String::new(),
            relief: true,
            bead_mm: crate::design::Params::default().width_min,
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
    /// Solid or shell (a wall with its thickness): either way fitted half
    /// a bead inside its outside.
    pub kind: &'static str,
    /// How many sections were compared.
    pub sections: usize,
    /// What the fit moved the mesh by to put its foot's centre at o and
    /// its foot on the bed (mm).
    pub moved: [f64; 3],
    /// Where the mesh is no sweep within the tolerance and is kept as
    /// its closest sweep and a relief: that sweep's largest difference
    /// from it (mm) and where it lies. `None` for a design that is the
    /// sweep alone.
    pub sweep: Option<(f64, [f64; 3])>,
    /// Details too small for a bead that the fit took into the wall,
    /// said in words (docs/MESHES.md, "Details under a bead").
    pub absorbed: Option<String>,
    /// Where the wall is thicker than a bead: its outside kept and how
    /// far its inside moved out, said in words (docs/MESHES.md, "The
    /// outside is the pot").
    pub inside: Option<String>,
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

/// A loop of a section smaller than this (mm², a 3 mm bead's square) that
/// is not the section's largest is a detail no bead prints: a 0.6 mm cone
/// on the inner floor, a 1 mm island on a shoulder.
pub const DETAIL_AREA_MM2: f64 = 9.0;

/// Fits `mesh` (millimetres, any position) by a design within
/// `opts.tolerance_mm`.
pub fn fit(mesh: &TriMesh, opts: &FitOptions) -> Result<Fitted> {
    let mut absorbed = None;
    fit_with(mesh, opts, &mut absorbed).map(|f| Fitted { absorbed, ..f })
}

/// The walls wider than a bead by more than this (mm) are said to have
/// their inside moved: under it the bead is the wall, as near as a
/// slicer's rounding.
pub(super) const THICKER_MM: f64 = 0.5;

/// Makes each section's wall the centre line of the bead that prints it:
/// its outside (the largest loop) moved in by half a bead, so the bead's
/// outer edge lies on the mesh's outside, whatever the wall's thickness.
/// A shell's inside loop goes; the most its inside moves out (a wall
/// thicker than a bead, by more than [`THICKER_MM`]) is said. A section
/// narrower than a bead inside its outside is refused by name.
fn keep_outside(cut: &mut [sections::Section], bead: f64) -> Result<Option<String>> {
    // A ring at the foot under a section of one loop (a floor slab): a
    // ring foot round a recess, which the floor, laid on the bed, fills.
    let slab = cut.iter().position(|s| s.loops.len() == 1);
    let recess = match slab {
        Some(k) if k > 0 && cut[0].loops.len() == 2 => Some((k, cut[k].z)),
        _ => None,
    };
    let mut moved: Option<(f64, f64)> = None;
    for (k, s) in cut.iter_mut().enumerate() {
        let areas: Vec<f64> = s.loops.iter().map(|l| signed_area2(l).abs()).collect();
        let Some(o) = (0..areas.len()).max_by(|&a, &b| areas[a].total_cmp(&areas[b])) else {
            continue;
        };
        let mut outer = s.loops[o].clone();
        if signed_area2(&outer) < 0.0 {
            outer.reverse();
        }
        if s.loops.len() == 2 && recess.is_none_or(|(top, _)| k >= top) {
            // The wall's mean thickness: the ring's area over its mean
            // length (exact for concentric circles).
            let mean = 0.5 * (perimeter(&s.loops[0]) + perimeter(&s.loops[1]));
            let t = 0.5 * (areas[o] - areas[1 - o]) / mean.max(1e-9);
            if t - bead > THICKER_MM && moved.is_none_or(|m| t - bead > m.0) {
                moved = Some((t - bead, s.z));
            }
        }
        let parts = crate::floor::offset(&outer, 0.5 * bead);
        let Some(mut wall) = parts
            .into_iter()
            .max_by(|a, b| signed_area2(a).abs().total_cmp(&signed_area2(b).abs()))
        else {
            return Err(Error::invalid(
                "mesh",
                format!(
                    "is narrower than a bead ({bead} mm) at z = {:.1} mm: a bead inside its outside leaves nothing to print there",
                    s.z
                ),
            ));
        };
        if signed_area2(&wall) < 0.0 {
            wall.reverse();
        }
        s.up = vec![vec![false; wall.len()]];
        s.loops = vec![wall];
    }
    let notes: Vec<String> = recess
        .map(|(_, z)| {
            format!(
                "the recess under its floor (inside its ring foot, up to z = {z:.1} mm) is filled: the floor is laid on the bed out to the foot's outside"
            )
        })
        .into_iter()
        .chain(moved.map(|(m, z)| {
            format!(
                "the wall is up to {m:.1} mm thicker than a bead ({bead} mm, at z = {z:.1} mm): its outside is kept and its inside moves out by that much"
            )
        }))
        .collect();
    Ok((!notes.is_empty()).then(|| notes.join("; ")))
}

/// Whether a bead `bead` wide fits inside loop `l`: its centre line, half
/// a bead inside the loop, leaves something (docs/MESHES.md, "Details").
fn holds_a_bead(l: &[[f64; 2]], bead: f64) -> bool {
    let mut l = l.to_vec();
    if signed_area2(&l) < 0.0 {
        l.reverse();
    }
    !crate::floor::offset(&l, 0.5 * bead).is_empty()
}

/// Takes the loops of `cut` that no bead prints (never a section's
/// largest) out of their sections: smaller than [`DETAIL_AREA_MM2`], or
/// too narrow for a `bead` wide bead to fit inside (a fin, a thin tab).
/// Says how many, the heights, and where the largest was. A section
/// whose largest loop is itself too narrow (the posts of an openwork
/// wall, as large as each other) keeps its loops, for the refusal to
/// name.
fn absorb_details(cut: &mut [sections::Section], bead: f64) -> Option<String> {
    let (mut n, mut zs, mut largest) = (0usize, (f64::MAX, f64::MIN), (0.0f64, [0.0; 3]));
    for s in cut.iter_mut() {
        let areas: Vec<f64> = s
            .loops
            .iter()
            .map(|l| 0.5 * signed_area2(l).abs())
            .collect();
        let Some(o) = (0..areas.len()).max_by(|&a, &b| areas[a].total_cmp(&areas[b])) else {
            continue;
        };
        let second = (0..areas.len())
            .filter(|&i| i != o)
            .map(|i| areas[i])
            .fold(0.0, f64::max);
        if areas[o] < DETAIL_AREA_MM2
            || (2.0 * second >= areas[o] && !holds_a_bead(&s.loops[o], bead))
        {
            continue;
        }
        let kept: Vec<bool> = (0..areas.len())
            .map(|i| {
                let small =
                    i != o && (areas[i] < DETAIL_AREA_MM2 || !holds_a_bead(&s.loops[i], bead));
                if small {
                    n += 1;
                    zs = (zs.0.min(s.z), zs.1.max(s.z));
                    if areas[i] >= largest.0 {
                        let c = centroid(&s.loops[i]);
                        largest = (areas[i], [c[0], c[1], s.z]);
                    }
                }
                !small
            })
            .collect();
        let mut flags = kept.iter();
        s.loops.retain(|_| *flags.next().unwrap_or(&true));
        let mut flags = kept.iter();
        s.up.retain(|_| *flags.next().unwrap_or(&true));
    }
    (n > 0).then(|| {
        let (a, at) = largest;
        format!(
            "took {n} detail(s) no bead prints into the wall (under {DETAIL_AREA_MM2} mm² in section or narrower than a {bead} mm bead, between z = {:.1} and {:.1} mm; the largest {a:.1} mm² at ({:.1}, {:.1}, {:.1}) mm): they do not print",
            zs.0, zs.1, at[0], at[1], at[2]
        )
    })
}

/// The least share of a section's outside that the opening inside it
/// takes to be its cavity: a wall 30 mm thick round a pot 100 mm across
/// leaves 16 %; a 10 mm drainage hole in its floor is 1 %.
const CAVITY_SHARE: f64 = 0.1;

/// What a section holds besides its outside (its largest loop): parts
/// beside it, the openings inside it beyond its largest (the cavity), and
/// islands inside an opening.
struct Inner {
    /// Loops no other loop holds: a second part (area, centre).
    beside: Vec<(f64, [f64; 2])>,
    /// Openings beyond the cavity (area, centre).
    openings: Vec<(f64, [f64; 2])>,
    /// Loops inside an opening (area, centre).
    islands: Vec<(f64, [f64; 2])>,
}

/// Sorts each section's loops: its outside, its cavity (the largest loop
/// inside it), and the rest ([`Inner`]); the section keeps only its
/// outside and cavity.
fn sort_loops(s: &mut sections::Section) -> Inner {
    let mut inner = Inner {
        beside: vec![],
        openings: vec![],
        islands: vec![],
    };
    let area = |l: &[[f64; 2]]| 0.5 * signed_area2(l).abs();
    let Some(o) = outside(&s.loops) else {
        return inner;
    };
    let depth = |j: usize| {
        (0..s.loops.len())
            .filter(|&i| i != j && nested(&s.loops[j], &s.loops[i]))
            .count()
    };
    let mut holes: Vec<usize> = vec![];
    for j in (0..s.loops.len()).filter(|&j| j != o) {
        let it = (area(&s.loops[j]), centroid(&s.loops[j]));
        match depth(j) {
            0 => inner.beside.push(it),
            1 => holes.push(j),
            _ => inner.islands.push(it),
        }
    }
    holes.sort_by(|&a, &b| area(&s.loops[b]).total_cmp(&area(&s.loops[a])));
    // The cavity: the largest opening, if it is a tenth of the outside's
    // area or more (a drainage hole in a floor is far less).
    let cavity = holes
        .first()
        .copied()
        .filter(|&j| area(&s.loops[j]) >= CAVITY_SHARE * area(&s.loops[o]));
    for &j in holes.iter().skip(usize::from(cavity.is_some())) {
        inner
            .openings
            .push((area(&s.loops[j]), centroid(&s.loops[j])));
    }
    let keep: Vec<usize> = std::iter::once(o).chain(cavity).collect();
    s.loops = keep.iter().map(|&i| s.loops[i].clone()).collect();
    s.up = keep.iter().map(|&i| s.up[i].clone()).collect();
    inner
}

/// The runs of consecutive sections (first, last) that hold some loop
/// of a kind (`per`, section by section).
fn runs_where(per: &[Vec<(f64, [f64; 2])>]) -> Vec<(usize, usize)> {
    let mut out: Vec<(usize, usize)> = vec![];
    for (k, v) in per.iter().enumerate() {
        match out.last_mut() {
            Some(r) if !v.is_empty() && r.1 + 1 == k => r.1 = k,
            _ if !v.is_empty() => out.push((k, k)),
            _ => {}
        }
    }
    out
}

/// The largest of the items of `per` over sections `a..=b`, with its
/// height: (area, [x, y, z]).
fn largest_in(
    per: &[Vec<(f64, [f64; 2])>],
    cut: &[sections::Section],
    (a, b): (usize, usize),
) -> (f64, [f64; 3]) {
    let mut best = (0.0, [0.0; 3]);
    for k in a..=b {
        for &(ar, c) in &per[k] {
            if ar > best.0 {
                best = (ar, [c[0], c[1], cut[k].z]);
            }
        }
    }
    best
}

/// Leaves each section of the wall (`cut`, foot to rim) its outside and
/// its cavity. A part beside the wall bigger than a detail (a handle, a
/// knob, a foot) is refused, saying where it leaves and joins the wall;
/// so is a part standing inside the cavity above its floor. Openings in
/// the floor and a floor top that is not level (a rise of at most
/// [`RIM_LIP_MM`] just above where the cavity starts, a groove round its
/// edge) are filled and said (docs/MESHES.md, "Details").
fn one_wall(cut: &mut [sections::Section], dz: f64) -> Result<Option<String>> {
    // Each kind of loop, section by section.
    let (mut beside, mut openings, mut islands) = (vec![], vec![], vec![]);
    for s in cut.iter_mut() {
        let inner = sort_loops(s);
        beside.push(inner.beside);
        openings.push(inner.openings);
        islands.push(inner.islands);
    }
    let z = |k: usize| cut[k].z;
    if let Some(&(a, b)) = runs_where(&beside).first() {
        let n = beside[a..=b].iter().map(Vec::len).max().unwrap_or(0);
        let (ar, at) = largest_in(&beside, cut, (a, b));
        let from = if a == 0 {
            "standing on the bed".to_string()
        } else {
            format!("leaving the wall at z = {:.1} mm", z(a) - 0.5 * dz)
        };
        let to = if b + 1 == cut.len() {
            "rising to the rim".to_string()
        } else {
            format!("joining it again at z = {:.1} mm", z(b) + 0.5 * dz)
        };
        return Err(Error::invalid(
            "mesh",
            format!(
                "splits into {} parts from z = {:.1} to {:.1} mm: {n} beside its wall (the largest {ar:.0} mm² in section, near ({:.1}, {:.1}, {:.1}) mm), {from} and {to} (a handle, a knob, a foot or two bodies): one loop a height makes a vessel; take it off the mesh and join it by hand, leather-hard",
                n + 1,
                z(a),
                z(b),
                at[0],
                at[1],
                at[2]
            ),
        ));
    }
    let mut notes = vec![];
    let runs = runs_where(&openings);
    if let (Some(&(a, _)), Some(&(_, b))) = (runs.first(), runs.last()) {
        let n = openings[a..=b].iter().map(Vec::len).max().unwrap_or(0);
        let (ar, at) = largest_in(&openings, cut, (a, b));
        notes.push(format!(
            "{n} opening(s) inside its outside besides its cavity (holes through its floor, from z = {:.1} to {:.1} mm; the largest {ar:.0} mm² at ({:.1}, {:.1}, {:.1}) mm) are filled: a clay floor is laid whole (drill them leather-hard)",
            z(a),
            z(b),
            at[0],
            at[1],
            at[2]
        ));
    }
    // Where the cavity starts: the floor's top.
    let floor_top = cut.iter().position(|s| s.loops.len() == 2);
    let mut slivers = vec![];
    for (a, b) in runs_where(&islands) {
        let (ar, at) = largest_in(&islands, cut, (a, b));
        let rise = z(b) - z(a) + dz;
        let on_floor = floor_top.is_some_and(|f| z(a) - z(f) <= RIM_LIP_MM);
        if on_floor && rise <= RIM_LIP_MM {
            notes.push(format!(
                "its floor's top is not level (a rise or a groove {rise:.1} mm deep from z = {:.1} to {:.1} mm, the largest part {ar:.0} mm² at ({:.1}, {:.1}) mm): the floor is printed level",
                z(a),
                z(b),
                at[0],
                at[1]
            ));
        } else if rise <= RIM_LIP_MM {
            // A sliver in the cavity no taller than a lip: where the wall
            // thickens inward over a ledge, the ledge's underside cut by a
            // section or two (brianfoshee's vase at its neck, 0.5 mm).
            // The outside is the pot, and the inside moves.
            slivers.push((rise, z(a), at));
        } else {
            return Err(Error::invalid(
                "mesh",
                format!(
                    "has a part inside it, apart from its wall, from z = {:.1} to {:.1} mm (the largest {ar:.0} mm² in section, near ({:.1}, {:.1}, {:.1}) mm: a divider, a post or an inner pot): one loop a height makes a vessel, or two nested for a wall with its thickness",
                    z(a),
                    z(b),
                    at[0],
                    at[1],
                    at[2]
                ),
            ));
        }
    }
    if let Some(&(rise, z0, at)) = slivers.first() {
        notes.push(format!(
            "{} sliver(s) inside its cavity, none over {RIM_LIP_MM} mm tall (the first {rise:.1} mm tall from z = {z0:.1} mm near ({:.1}, {:.1}) mm: a ledge's underside where the wall thickens inward), are taken into the wall",
            slivers.len(),
            at[0],
            at[1]
        ));
    }
    Ok((!notes.is_empty()).then(|| notes.join("; ")))
}

/// Where a tilted foot becomes whole: the first section within
/// [`RIM_LIP_MM`] of the bed whose outside no longer runs along the
/// mesh's underside (a level face), when the foot's first section is
/// under half its area and off its centre by over a quarter of its
/// radius (a foot that grows round its centre, a bowl's rounded bottom
/// or a chamfer, is left as it is). `None` for a level foot.
fn tilted_foot(cut: &[sections::Section]) -> Option<usize> {
    let read = |s: &sections::Section| {
        outside(&s.loops).map(|i| {
            (
                0.5 * signed_area2(&s.loops[i]).abs(),
                centroid(&s.loops[i]),
                s.up[i].iter().any(|&u| u),
            )
        })
    };
    let k = cut
        .iter()
        .take_while(|s| s.z <= RIM_LIP_MM)
        .position(|s| read(s).is_some_and(|(_, _, under)| !under))?;
    let ((a0, c0, _), (ak, ck, _)) = (read(&cut[0])?, read(&cut[k])?);
    let radius = (ak / std::f64::consts::PI).sqrt();
    (k > 0 && a0 < 0.5 * ak && (c0[0] - ck[0]).hypot(c0[1] - ck[1]) > 0.25 * radius).then_some(k)
}

/// Where a round bottom (a jar turned on a point, a sphere's underside)
/// is cut flat (docs/MESHES.md, "A round bottom"): the lowest section
/// above which the wall's outside, read as the radius of its area, never
/// leans out past the overhang clay holds (`max_overhang_deg`) by more
/// than the corrections move a wall (`max_correction_mm`, the defaults
/// the design gets); `None` when the foot itself is such a section, or
/// is over [`FOOT_POINT_SHARE`] of that section across. A bowl flaring
/// 50°, a foot's rounding or a flange keeps its foot; a jar on a 4 mm
/// point does not. Only the lower half is searched: what leans out
/// further up is the corrections' (or the check's) to say.
fn round_bottom(cut: &[sections::Section]) -> Option<usize> {
    let p = crate::design::Params::default();
    let lean = p.max_overhang_deg.to_radians().tan();
    let r: Vec<Option<f64>> = cut.iter().map(area_radius).collect();
    // How far the outside above section k leans out past the limit: the
    // most r_m − lean·z_m above it less its own, kept as it is read
    // from the top down, so the search is linear in the sections.
    let g: Vec<Option<f64>> = (0..cut.len())
        .map(|k| r[k].map(|rk| rk - lean * cut[k].z))
        .collect();
    let mut above = vec![f64::NEG_INFINITY; cut.len() + 1];
    for k in (0..cut.len()).rev() {
        above[k] = above[k + 1].max(g[k].unwrap_or(f64::NEG_INFINITY));
    }
    let excess =
        |k: usize| -> f64 { g[k].map_or(f64::INFINITY, |gk| (above[k + 1] - gk).max(0.0)) };
    // A bottom that narrows to a point or a small disk is one loop at the
    // bed; feet or a ring foot are the refusals' and the recess's.
    if cut.first().is_none_or(|s| s.loops.len() != 1) || excess(0) <= p.max_correction_mm {
        return None;
    }
    // A round bottom narrows to a point under where it is cut: a foot
    // that is a real base (a flange flaring from it, a pedestal) is the
    // corrections' and the relief's, as before.
    (1..cut.len() / 2)
        .find(|&k| excess(k) <= p.max_correction_mm)
        .filter(|&k| {
            r[0].zip(r[k])
                .is_some_and(|(a, b)| a < FOOT_POINT_SHARE * b)
        })
}

/// The radius of a circle of the area inside a section's outside.
fn area_radius(s: &sections::Section) -> Option<f64> {
    outside(&s.loops).map(|i| (0.5 * signed_area2(&s.loops[i]).abs() / std::f64::consts::PI).sqrt())
}

/// Leaves out the sections under `k` (a foot cut level: tilted, or
/// round), the rest and the pot's `height` and `bed` moved down by where
/// section `k` begins, which it returns (mm).
fn cut_foot_level(
    cut: &mut Vec<sections::Section>,
    k: usize,
    dz: f64,
    height: &mut f64,
    bed: &mut f64,
) -> f64 {
    let z0 = cut[k].z - 0.5 * dz;
    cut.drain(..k);
    for s in cut.iter_mut() {
        s.z -= z0;
    }
    *height -= z0;
    *bed += z0;
    z0
}

/// A round bottom's foot is under this share of the flat foot it is cut
/// to (a jar on a point: 0.09; a ball of 50 mm sectioned every 0.25 mm,
/// its first section 0.125 mm up: 0.29; a vase on a 42 mm base flaring
/// to 80 mm within 3 mm, a flange the corrections shape: 0.53).
const FOOT_POINT_SHARE: f64 = 0.4;

/// Adds `note` to what the fit says it took in or changed.
fn say(absorbed: &mut Option<String>, note: String) {
    *absorbed = Some(match absorbed.take() {
        Some(d) => format!("{d}; {note}"),
        None => note,
    });
}

/// [`fit`], saying in `absorbed` what details it took into the wall.
fn fit_with(mesh: &TriMesh, opts: &FitOptions, absorbed: &mut Option<String>) -> Result<Fitted> {
    let (lo, hi) = mesh.bounds();
    let height = hi[2] - lo[2];
    if !(5.0..=2000.0).contains(&height) {
        return Err(Error::invalid(
            "mesh",
            format!("is {height:.2} mm tall: a vessel is 5 to 2000 mm; give --scale (millimetres are assumed: --scale 1000 for metres, 10 for centimetres, 25.4 for inches)"),
        ));
    }
    let n = ((height / SECTION_MM) as usize).clamp(20, MAX_SECTIONS);
    // Tall, narrow facets cross many heights each: fewer sections keep the
    // cut's work (and memory) bounded by the mesh read (docs/MESHES.md,
    // "Work and memory").
    let n = sections::sections_within(mesh, lo[2], height, n, 20).ok_or_else(|| {
        Error::invalid(
            "mesh",
            format!(
                "has {} triangles, so many of them tall that cutting even 20 sections computes over {} segments; decimate it (Blender's Decimate, MeshLab's Quadric Edge Collapse)",
                mesh.triangles.len(),
                sections::MAX_SEGMENTS
            ),
        )
    })?;
    let dz = height / n as f64;
    let mut cut = sections::cut(mesh, lo[2] + 0.5 * dz, dz, n, lo[2])?;
    // A foot that meets the bed on one side first (an export tilted a
    // degree or two) starts level where its loop is whole.
    let (mut height, mut bed) = (height, lo[2]);
    if let Some(k) = tilted_foot(&cut) {
        let z0 = cut_foot_level(&mut cut, k, dz, &mut height, &mut bed);
        let note = format!(
            "its foot is not level: it meets the bed on one side and is whole {z0:.1} mm up (a tilted export), so the print starts level there, {z0:.1} mm shorter"
        );
        say(absorbed, note);
    }
    if let Some(k) = round_bottom(&cut) {
        let across = |s: &sections::Section| 2.0 * area_radius(s).unwrap_or(0.0);
        let (foot, flat) = (across(&cut[0]), across(&cut[k]));
        let z0 = cut_foot_level(&mut cut, k, dz, &mut height, &mut bed);
        let note = format!(
            "its bottom is round: it meets the bed {foot:.1} mm across under a wall leaning out past the {}° clay holds, so it stands on a flat foot cut at z = {z0:.1} mm, {flat:.0} mm across (the print {z0:.1} mm shorter)",
            crate::design::Params::default().max_overhang_deg
        );
        say(absorbed, note);
    }
    if let Some(note) = absorb_details(&mut cut, opts.bead_mm) {
        say(absorbed, note);
    }
    // A rim that is not quite level (a helix's last turn, a rim's
    // rounding) leaves sections near the top that do not go round: the
    // rim is where the last whole section is, if that is within 3 mm of
    // the top; else the rim is uneven, which a design's rim key shapes
    // but the fit does not yet find.
    // A section goes round its centre when one loop holds the centre of
    // all its loops' areas: a pot's wall does, even leaning; the posts of
    // an openwork wall or feet round the foot do not.
    let centre = |s: &sections::Section| {
        let (mut a, mut c) = (0.0, [0.0; 2]);
        for l in s.loops.iter().filter(|l| around(l, &s.loops)) {
            let (w, m) = (signed_area2(l).abs(), centroid(l));
            a += w;
            c = [c[0] + w * m[0], c[1] + w * m[1]];
        }
        (a > 0.0).then(|| [c[0] / a, c[1] / a])
    };
    let holds = |s: &sections::Section, c: [f64; 2]| {
        s.loops
            .iter()
            .any(|l| nested(&[c], l) && around(l, &s.loops))
    };
    let round = |s: &sections::Section| centre(s).is_some_and(|c| holds(s, c));
    let whole = cut.iter().position(|s| !round(s)).unwrap_or(cut.len());
    if whole == 0 {
        let k = cut[0].loops.len();
        return Err(Error::invalid(
            "mesh",
            if k > 1 {
                format!("stands on {k} parts at its foot (feet, or a base in pieces), none going round its centre: one loop a height makes a vessel; join the feet into a foot ring, or take them off the mesh")
            } else {
                "has no section that goes round its centre at its foot: not a vessel standing on its base (turn it so its opening is up)".to_string()
            },
        ));
    }
    // Sections higher up that go round again: the wall opens in between
    // (posts, windows, slots), which one spiral cannot lay.
    let below = centre(&cut[whole - 1]).unwrap_or_default();
    if let Some(back) = cut[whole..]
        .iter()
        .position(|s| round(s) && holds(s, below))
    {
        let (a, b) = (cut[whole].z, cut[whole + back - 1].z);
        let k = cut[whole..whole + back]
            .iter()
            .map(|s| s.loops.len())
            .max()
            .unwrap_or(0);
        return Err(Error::invalid(
            "mesh",
            if k == 1 {
                // One loop that does not hold its centre: a wall cut
                // along its length, as a pot lying down is.
                format!("its wall from z = {a:.1} to {b:.1} mm does not go round its centre (a slot up its side; or it lies on its side: --up y (or x) stands it up): one spiral lays a closed wall")
            } else {
                format!("its wall opens from z = {a:.1} to {b:.1} mm into {k} parts that do not go round its centre (an openwork wall, windows or slots): one spiral lays a closed wall; close the openings in the mesh")
            },
        ));
    }
    if let Some(note) = one_wall(&mut cut[..whole], dz)? {
        say(absorbed, note);
    }
    // A solid whose top is a cap that slants (or rises to one side):
    // every section from the first the cap cuts up to the top is cut by
    // it along one run of its loop (and by the wall along the rest), or
    // by it alone. A level rim's rounding cuts a section all round alike;
    // a lobed shoulder closing in, or a wall turned steeply by a twist,
    // cuts sections in a run a lobe, and not every one up to the top.
    let cap = |s: &sections::Section| {
        s.loops.len() == 1
            && s.up[0].iter().any(|&u| u)
            && (runs(&s.up[0]) == 1 || s.up[0].iter().all(|&u| u))
    };
    let mut first = whole;
    while first > 0 && cap(&cut[first - 1]) {
        first -= 1;
    }
    let capped = (first < whole).then_some(first);
    let mut whole = whole;
    if let Some(k) = capped.filter(|&k| k > 0 && cut[..k].iter().all(|s| s.loops.len() == 1)) {
        if height - cut[k].z > RIM_LIP_MM {
            return fit_uneven(&cut, k, dz, opts, bed, true);
        }
        // Within the lip the wall ends where the cap begins, as a level
        // rim's rounding ends it: the design's rim is the top.
        whole = k;
    }
    if whole < cut.len() {
        let z = cut[whole].z;
        if height - z > RIM_LIP_MM && cut[whole - 1].loops.len() == 2 {
            // A wall with its thickness whose rim rises round the loop.
            return fit_uneven(&cut, whole, dz, opts, bed, false);
        }
        if height - z > RIM_LIP_MM {
            return Err(Error::invalid(
                "mesh",
                format!(
                    "has an uneven rim: from z = {z:.1} mm up ({:.1} mm below its top) the wall does not go all the way round its centre, and no cap across its top says where its rim is (a solid's slanted top, a wall with its thickness are fitted; cut the mesh level there, or draw the rim with the design's `rim` key){}",
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
    // Each section's wall: its outside, and its cavity (a shell) when
    // `one_wall` kept one.
    if let Some(s) = cut.iter().find(|s| s.loops.is_empty()) {
        return Err(Error::invalid(
            "mesh",
            format!(
                "has nothing at z = {:.1} mm: a vessel's wall runs from its foot to its rim",
                s.z
            ),
        ));
    }
    let shell = cut.iter().any(|s| s.loops.len() == 2);
    // The pot is its outside: the bead's outer edge on it.
    let inside = keep_outside(&mut cut, opts.bead_mm)?;
    let kind = if shell { "shell" } else { "solid" };
    let (c, psi) = foot_frame(&cut);
    let loops: Vec<Vec<Vec<[f64; 2]>>> = cut.iter().map(|s| about(s, c)).collect();
    let zs: Vec<f64> = cut.iter().map(|s| s.z).collect();
    let tol = opts.tolerance_mm;
    let secs = Sections {
        zs: &zs,
        loops: &loops,
        height,
        tol,
        // A crease narrower than a bead in the outside is under two in
        // the centre line: the inset moves its sides apart by a bead.
        fold: 2.0 * opts.bead_mm,
    };
    let mut b = match closest(&psi, &secs) {
        Ok(b) => b,
        // Neither frame finds one wall a ray: the radial reason says where.
        Err(why) => {
            return Err(Error::invalid(
                "mesh",
                format!("is not a sweep of its foot's loop: {why}"),
            ))
        }
    };
    if b.deviation > tol {
        if let Some(t) = twist::twisted(&b.psi, &secs) {
            if t.deviation < b.deviation && twist::holds(&t) {
                b = t;
            }
        }
    }
    // Ribs the sweep could not follow, or that two profiles' blend took
    // up, are a texture: when that brings the design within the
    // tolerance (with one profile, where two were), or takes a quarter
    // off how far it is (a picture's pattern is no rib, and a rib found
    // in it takes next to nothing off).
    if b.deviation > tol || b.two {
        if let Some(t) = ribs::textured(&b, &zs, height, tol) {
            // Two profiles with ribs beat two without when no farther:
            // a printed outside's bead widths vary a little round the
            // loop, which the two profiles take up, and the ribs are then
            // the texture they are (docs/MESHES.md, "Ribs").
            let within = t.deviation <= tol
                && (b.deviation > tol || !t.two || (b.two && t.deviation <= b.deviation));
            if within || (b.deviation > tol && t.deviation < 0.75 * b.deviation) {
                b = t;
            }
        }
    }
    let at = b.turned(b.at, height);
    if let (n, Some(f)) = b.folds {
        let f = b.turned(f, height);
        let note = format!(
            "read its wall at the outside of {n} ray(s) where it folds back across them in creases narrower than a bead (the first near ({:.1}, {:.1}, {:.1}) mm): the bead runs across them",
            f[0], f[1], f[2]
        );
        say(absorbed, note);
    }
    let sweep = (b.deviation > opts.tolerance_mm && opts.relief).then_some((b.deviation, at));
    if b.deviation > opts.tolerance_mm && !opts.relief {
        return Err(Error::invalid(
            "mesh",
            format!(
                "is not a sweep of one loop within {} mm: the closest design (a loop, {}, {} offsets{}) differs from it by {:.2} mm at ({:.1}, {:.1}, {:.1}) mm",
                opts.tolerance_mm,
                if b.two { "two profiles blended round it" } else { "one profile" },
                if b.offset == Offset::Radial { "radial" } else { "normal" },
                if b.twist.1 == 0.0 { String::new() } else { format!(", twisted {:.1}°", b.twist.1.to_degrees()) },
                b.deviation,
                at[0],
                at[1],
                at[2]
            ),
        ));
    }
    // The loop by few control points where they hold the tolerance and
    // make a design the file takes (a curve that keeps clear of o and of
    // itself); else Ψ's points.
    let few = if sweep.is_none() {
        b.few_loop(&zs, tol)
    } else {
        None
    };
    let with_few = few.and_then(|(l, dev, worst)| {
        b.fitted_loop = Some(l);
        let d = Design::from_json(&b.json(&opts.name)).ok();
        match d {
            Some(_) => (b.deviation, b.at) = (dev, worst),
            None => b.fitted_loop = None,
        }
        d
    });
    let mut design = match with_few {
        Some(d) => d,
        None => Design::from_json(&b.json(&opts.name))?,
    };
    design.name = opts.name.clone();
    let (mut deviation, mut at) = (b.deviation, b.at);
    if sweep.is_some() {
        let (relief, worst) = relief_of(&b, &zs, dz, opts.tolerance_mm);
        design.relief = Some(relief);
        (deviation, at) = worst;
    }
    Ok(Fitted {
        absorbed: None,
        inside,
        design,
        deviation_mm: deviation,
        at: b.turned(at, height),
        kind,
        sections: cut.len(),
        moved: [-c[0], -c[1], -bed],
        sweep,
    })
}

/// How many runs of `true` a loop's flags make, round the loop (0 for
/// none or all).
fn runs(up: &[bool]) -> usize {
    (0..up.len())
        .filter(|&i| up[i] && !up[(i + up.len() - 1) % up.len()])
        .count()
}

/// The sections a fit reads, about the foot's centre, and what every
/// fit of them shares.
#[derive(Clone, Copy)]
struct Sections<'a> {
    /// Their heights (mm).
    zs: &'a [f64],
    /// Their loops: one a section, the bead's centre line.
    loops: &'a [Vec<Vec<[f64; 2]>>],
    /// The mesh's height (mm).
    height: f64,
    /// The tolerance (mm).
    tol: f64,
    /// The widest fold read at its outside (mm along the centre line).
    fold: f64,
}

/// The closer of the fits in both frames (radial and normal) of the
/// sections, or why neither frame finds one wall a ray (the radial
/// reason, which says where).
fn closest(psi: &[[f64; 2]], secs: &Sections) -> std::result::Result<Candidate, String> {
    closest_in((&[Offset::Radial, Offset::Normal], false), psi, secs)
}

/// The closest of the fits in the frames `frames.0`, as [`closest`];
/// with `frames.1`, Ψ is the foot's wall already (the sections are
/// turned, the foot with them, and D is measured from Ψ as it is).
fn closest_in(
    (frames, on_wall): (&[Offset], bool),
    psi: &[[f64; 2]],
    secs: &Sections,
) -> std::result::Result<Candidate, String> {
    let Sections {
        zs,
        loops,
        height,
        tol,
        fold,
    } = *secs;
    let mut best: Option<Candidate> = None;
    let mut why = Vec::new();
    for &offset in frames {
        match offsets(psi, zs, loops, offset, fold) {
            Ok((mut d, dirs, folds)) => {
                // Only a profile's change from its foot counts (docs/
                // FORMATS.md): Ψ is the wall at the lowest section (the
                // bead's centre line, half a bead inside the foot's
                // outside), and D is measured from it.
                let base = if on_wall {
                    vec![0.0; psi.len()]
                } else {
                    d[0].clone()
                };
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
                let mut cand = fit_offsets(&psi, zs, &d, offset, height, tol);
                cand.folds = folds;
                if best.as_ref().is_none_or(|b| cand.deviation < b.deviation) {
                    best = Some(cand);
                }
            }
            Err(e) => why.push(e),
        }
    }
    best.ok_or_else(|| why.swap_remove(0))
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
    /// The mesh's offsets less the design's, section by section and ray
    /// by ray (mm).
    residual: Vec<Vec<f64>>,
    /// The offsets fitted, section by section and ray by ray (mm).
    d: Vec<Vec<f64>>,
    /// Ribs taken out of the offsets as the design's texture.
    texture: Option<crate::texture::TextureSpec>,
    /// The angle the loop is turned by and the twist (radians; 0 for
    /// none): the sections were fitted turned back by both, the first
    /// from the foot, the second as the design turns.
    twist: (f64, f64),
    /// Rays read at a fold's outside, and where the widest fold was.
    folds: (usize, Option<[f64; 3]>),
    /// The loop as a closed curve's control points or a polygon's
    /// corners (in the frame the fit measures in), where few hold the
    /// tolerance; else Ψ's points are the design's polyline.
    fitted_loop: Option<loopfit::Loop>,
}

impl Candidate {
    /// A place `at` in the untwisted frame the fit measures in, turned
    /// as the design turns it.
    fn turned(&self, at: [f64; 3], height: f64) -> [f64; 3] {
        let angle = self.twist.0 + twist::turn_at(self.twist.1, at[2], height);
        let [x, y] = turn_by([at[0], at[1]], angle.sin_cos());
        [x, y, at[2]]
    }

    /// The loop the design file gets, in the frame the fit measures in
    /// (before the twist's first turn), and whether it is Ψ as fitted
    /// (`true`) or moved out to the profiles' feet.
    fn design_loop(&self) -> (Vec<[f64; 2]>, bool) {
        // The design reads a profile from its foot (x − x(0),
        // docs/FORMATS.md), the fit from Ψ: where a profile's foot is off
        // Ψ (carried on to the bed as the wall leans), Ψ moves out to it
        // along each ray, by the feet blended as λ blends the profiles
        // there. Left on Ψ, the sprout planter printed 0.4 mm out at every
        // height.
        let foot = |c: &[[f64; 2]]| c.first().map_or(0.0, |p| p[0]);
        let (fs, ft) = (foot(&self.start), foot(&self.end));
        let lam = if self.two {
            lambda_round(&self.interp, self.psi.len())
        } else {
            vec![0.0; self.psi.len()]
        };
        let moved: Vec<[f64; 2]> = (0..self.psi.len())
            .map(|j| {
                let f = (1.0 - lam[j]) * fs + lam[j] * ft;
                let (p, dir) = (self.psi[j], ray(&self.psi, j, self.offset));
                [p[0] + f * dir[0], p[1] + f * dir[1]]
            })
            .collect();
        // Ψ stays, and the profiles keep their feet as fitted, where the
        // move cannot carry the fit: a point taken across o, or to within
        // the millimetre of it the design refuses (the Hand and Machine
        // pot's Ψ lies 0.75 mm from o, its foot 1.85 mm further in: moved,
        // its rays turned round and it printed 4–8 mm inside its mesh), or
        // shifted along the loop by over half the spacing of its points
        // (the fit reads λ and the relief at Ψ's points evenly round it,
        // the design at their share of its length: feet 3.2 mm apart on a
        // succulent pot shifted its points 0.97 mm, 1.8 spacings; the
        // drawer's 0.18 mm, an eighth).
        let crosses = self.offset == Offset::Radial
            && (0..moved.len()).any(|j| {
                let (p, q) = (self.psi[j], moved[j]);
                q[0].hypot(q[1]) < 1.0 || p[0] * q[0] + p[1] * q[1] <= 0.0
            });
        let spacing = perimeter(&self.psi) / self.psi.len().max(1) as f64;
        let keep = self.psi.len() < 3 || crosses || along_shift(&self.psi, &moved) > 0.5 * spacing;
        (if keep { self.psi.clone() } else { moved }, keep)
    }

    /// The loop as the fewest control points (or a polygon's corners)
    /// that keep the design within `tol` ([`loopfit::loop_fewest`]), the
    /// design's new largest difference and where (`zs` the sections'
    /// heights); `None` where neither holds.
    fn few_loop(&self, zs: &[f64], tol: f64) -> Option<(loopfit::Loop, f64, [f64; 3])> {
        let (psi, _) = self.design_loop();
        let dirs: Vec<[f64; 2]> = (0..self.psi.len())
            .map(|j| ray(&self.psi, j, self.offset))
            .collect();
        let (ctrl, dev, (k, j)) = loopfit::loop_fewest(&psi, &dirs, &self.residual, tol)?;
        let z = zs.get(k).copied().unwrap_or(0.0);
        Some((ctrl, dev, [self.psi[j][0], self.psi[j][1], z]))
    }

    fn json(&self, name: &str) -> String {
        // The loop fitted in the frame turned back by the first angle,
        // turned forward: every ray and offset turns with it.
        let forward = self.twist.0.sin_cos();
        let (psi, keep) = self.design_loop();
        let foot = |c: &[[f64; 2]]| c.first().map_or(0.0, |p| p[0]);
        let from_foot = |c: &[[f64; 2]]| -> Vec<[f64; 2]> {
            let f = if keep { 0.0 } else { foot(c) };
            c.iter().map(|p| [p[0] - f, p[1]]).collect()
        };
        let turned =
            |l: &[[f64; 2]]| -> Vec<[f64; 2]> { l.iter().map(|&p| turn_by(p, forward)).collect() };
        let (control_points, points) = match &self.fitted_loop {
            Some(loopfit::Loop::Curve(c)) => (Some(turned(c)), None),
            Some(loopfit::Loop::Polygon(p)) => (None, Some(turned(p))),
            None => (None, Some(turned(&psi))),
        };
        let traj = TrajectorySpec {
            control_points,
            points,
            closed: true,
            offset: self.offset,
        };
        let mut v = serde_json::json!({
            "sweepclay": 1,
            "name": name,
            "profile_start": CurveSpec { control_points: from_foot(&self.start), points: None },
            "trajectory": traj,
        });
        if let Some(t) = &self.texture {
            v["texture"] = serde_json::json!([t]);
        }
        if self.twist.1 != 0.0 {
            // To a hundredth of a degree: 0.01° turns a 100 mm pot's rim
            // by 9 µm.
            v["twist_deg"] = serde_json::json!((self.twist.1.to_degrees() * 100.0).round() / 100.0);
        }
        if self.two {
            v["profile_end"] = serde_json::json!(CurveSpec {
                control_points: from_foot(&self.end),
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
    // A design a potter edits point by point first: one profile of few
    // control points, then two; only then as many points as hold the
    // tolerance (one profile of 160 points is no simpler to edit than two
    // of nine).
    let one = match few_points(&g, &d, &mean, None) {
        Some(c) if c.deviation <= tol => return c,
        other => other,
    };
    let two = match few_points(&g, &d, &s, Some((&t, &lambda))) {
        Some(c) if c.deviation <= tol => return c,
        other => other,
    };
    let through = |s: &[f64], two: Option<(&[f64], &[f64])>| {
        candidate_with(&g, &d, s, two, None).expect("through the values")
    };
    let one = nearer(one, through(&mean, None));
    if one.deviation <= tol {
        return one;
    }
    nearer(Some(one), nearer(two, through(&s, Some((&t, &lambda)))))
}

/// The nearer the mesh of a candidate and maybe another.
fn nearer(a: Option<Candidate>, b: Candidate) -> Candidate {
    match a {
        Some(a) if a.deviation <= b.deviation => a,
        _ => b,
    }
}

/// The shares of the tolerance a profile of few control points is
/// tried within, in turn: the rest is left to what the profiles cannot
/// follow (the wall's changes round the loop).
const FEW_SHARES: [f64; 4] = [2.0 / 3.0, 1.0 / 2.0, 1.0 / 3.0, 1.0 / 6.0];

/// The design whose profiles have the fewest control points (at most
/// [`FEWEST_MAX`]) within the largest share of the tolerance
/// ([`FEW_SHARES`]) that brings the whole design within it; else the
/// nearest of those tried; `None` when no share has so few.
fn few_points(
    g: &Frame,
    d: &[Vec<f64>],
    s: &[f64],
    two: Option<(&[f64], &[f64])>,
) -> Option<Candidate> {
    let mut best: Option<Candidate> = None;
    for share in FEW_SHARES {
        let Some(c) = candidate_with(g, d, s, two, Some(share)) else {
            // A smaller share takes more points still.
            break;
        };
        if c.deviation <= g.tol {
            return Some(c);
        }
        best = Some(nearer(best, c));
    }
    best
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

/// A profile's values `v` at the sections' heights `zs`, from the bed
/// to the rim at `height`: the lowest section's value carried down to
/// z 0 as the lowest two sections lean (held upright there, the curve
/// had to turn a corner a cubic rounds by up to a fifth of a millimetre
/// at a flaring foot, and took four times the points), the highest held
/// up to the top through a lip as far apart as the sections (one far
/// point there let the curve through them turn back down); a rim within
/// half a section of the highest is reached as the wall leans too.
fn bed_to_rim(v: &[f64], zs: &[f64], height: f64) -> Vec<[f64; 2]> {
    let n = v.len();
    let at = |i: usize| [v[i], zs[i]];
    let mut pts: Vec<[f64; 2]> = vec![[lean_to(at(0), at(1.min(n - 1)), 0.0), 0.0]];
    pts.extend((0..n).map(at));
    let step = zs.get(1).map_or(height, |z1| z1 - zs[0]).max(1e-3);
    let (last, top) = (v[n - 1], zs[n - 1]);
    if top + 0.5 * step >= height {
        pts.push([lean_to(at(n - 1), at(n.saturating_sub(2)), height), height]);
        return pts;
    }
    let mut z = top + step;
    while z < height - 0.5 * step {
        pts.push([last, z]);
        z += step;
    }
    pts.push([last, height]);
    pts
}

/// The value at height `z` on the line through `near` and `far` (`[x,
/// z]`): `near`'s own where the two are level.
fn lean_to(near: [f64; 2], far: [f64; 2], z: f64) -> f64 {
    let rise = near[1] - far[1];
    if rise.abs() > 1e-12 {
        near[0] + (near[0] - far[0]) / rise * (z - near[1])
    } else {
        near[0]
    }
}

/// How far (mm) a point of the closed loop `b` lies along it from the
/// share of its length its point in `a` (the same loop moved) has there,
/// at most.
fn along_shift(a: &[[f64; 2]], b: &[[f64; 2]]) -> f64 {
    let ((ua, _), (ub, lb)) = (places(a), places(b));
    ua.iter()
        .zip(&ub)
        .map(|(x, y)| (y - x).abs() * lb)
        .fold(0.0, f64::max)
}

/// λ at each of `n` points evenly round the loop, from the
/// interpolation curve's control points.
fn lambda_round(interp: &[[f64; 2]], n: usize) -> Vec<f64> {
    let c = BSpline::clamped(interp.to_vec())
        .expect("points")
        .flatten(16);
    (0..n).map(|j| at_x(&c, j as f64 / n as f64)).collect()
}

/// The design of profile values `s` (and `t` blended by `lambda`) at the
/// sections' heights, as B-splines through them, and its largest
/// difference from `d`: each profile by [`fewest`] within `few` (a share
/// of the tolerance), or without it through the values within a third
/// (as many points as that takes, docs/MESHES.md, "Few control points").
fn candidate_with(
    g: &Frame,
    d: &[Vec<f64>],
    s: &[f64],
    two: Option<(&[f64], &[f64])>,
    few: Option<f64>,
) -> Option<Candidate> {
    let Frame {
        psi,
        zs,
        offset,
        height,
        tol,
    } = *g;
    let profile = |v: &[f64]| -> Option<Vec<[f64; 2]>> {
        let pts = bed_to_rim(v, zs, height);
        match few {
            Some(share) => fewest(&pts, share * tol),
            None => Some(profile_through(&pts, tol)),
        }
    };
    let start = profile(s)?;
    let (end, interp) = match two {
        Some((t, lambda)) => {
            // λ's error moves the wall by it times the profiles' spread.
            let spread = s
                .iter()
                .zip(t)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
                .max(1e-9);
            let interp = few
                .and_then(|share| interpolation_fewest(lambda, share * tol / spread, false))
                .map(|(c, _)| c)
                .unwrap_or_else(|| interpolation_through(lambda));
            (profile(t)?, interp)
        }
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
        lambda_round(&interp, psi.len())
    } else {
        vec![0.0; psi.len()]
    };
    let mut worst = (0.0f64, [0.0; 3]);
    let mut residual = Vec::with_capacity(zs.len());
    for (k, &z) in zs.iter().enumerate() {
        let (a, b) = (at_z(&sp, z), if ep.is_empty() { 0.0 } else { at_z(&ep, z) });
        let mut row = Vec::with_capacity(lam.len());
        for (j, &l) in lam.iter().enumerate() {
            let fitted = if ep.is_empty() {
                a
            } else {
                (1.0 - l) * a + l * b
            };
            row.push(d[k][j] - fitted);
            let e = (fitted - d[k][j]).abs();
            if e > worst.0 {
                let p = psi[j];
                worst = (e, [p[0], p[1], z]);
            }
        }
        residual.push(row);
    }
    Some(Candidate {
        folds: (0, None),
        fitted_loop: None,
        offset,
        two: two.is_some(),
        psi: psi.to_vec(),
        start,
        end,
        interp,
        deviation: worst.0,
        at: worst.1,
        residual,
        d: d.to_vec(),
        texture: None,
        twist: (0.0, 0.0),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `n` points round o at radius `r(angle)`, from angle 0.
    pub(super) fn ring(r: impl Fn(f64) -> f64, n: usize) -> Vec<[f64; 2]> {
        (0..n)
            .map(|j| {
                let a = std::f64::consts::TAU * j as f64 / n as f64;
                [r(a) * a.cos(), r(a) * a.sin()]
            })
            .collect()
    }

    #[test]
    fn a_loop_moved_evenly_keeps_each_points_share_of_its_length() {
        // A circle moved out by 2 mm all round: every point keeps its
        // share. An oval moved 5 mm further out at its ends only: the
        // points there take a larger share, over a millimetre along the
        // loop at most (1.13), more than half the 0.57 mm between its
        // points, so `json` leaves such a Ψ where it is.
        let circle = ring(|_| 30.0, 360);
        assert!(along_shift(&circle, &ring(|_| 32.0, 360)) < 1e-9);
        let oval = ring(|a| 30.0 + 5.0 * a.cos().powi(2), 360);
        let moved = ring(|a| 30.0 + 10.0 * a.cos().powi(2), 360);
        let d = along_shift(&oval, &moved);
        assert!((1.0..1.3).contains(&d), "{d}");
    }
}
