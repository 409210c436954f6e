//! Floor fill: a closed region in, the bead elements that fill it in one
//! continuous path out (vessels' floors; not in the paper,
//! docs/ALGORITHMS.md §8). Knows nothing of profiles, layers or G-code.
//!
//! The region inside a closed polygon (the base ring's centre line) is
//! filled by its inward offsets one pitch apart, `w_min · (1 −`
//! [`FLOOR_OVERLAP`]`)`, computed with `i_overlay`: each a closed ring
//! whose beads touch the next with the stated overlap. An elongated
//! region's offsets end in a thin core, laid once as the line down its
//! middle; a round one's in a hole narrower than a ring, laid as one short
//! bead across it. The path enters each element
//! at its point nearest the last one's entry and closes every ring on its
//! entry, so the step from one element to the next runs across clay that
//! both already cover: it is a *join* ([`floor_entries`]), laid with
//! almost no clay, never a bead on a bead.

use crate::plane::signed_area2;
use geo::Simplify;
use i_overlay::mesh::outline::offset::OutlineOffset;
use i_overlay::mesh::style::{LineJoin, OutlineStyle};

pub use crate::design::FLOOR_OVERLAP;

/// Most floor rings a layer may have (a floor 5 m across at 3 mm beads,
/// far beyond any printer; the sample cap refuses such designs first):
/// bounds the offsetting work.
pub const MAX_FLOOR_RINGS: usize = 1000;

/// The bead sizes a floor is laid with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FloorBeads {
    /// Width of a floor bead (mm): the design's `width_min`.
    pub width: f64,
    /// Distance between the points of a ring (mm).
    pub spacing: f64,
    /// Widest bead the floor may lay (mm): the design's `width_max`. The
    /// line down a thin ring's middle is laid as wide as the ring's two
    /// sides would have covered, up to this.
    pub widest: f64,
}

impl FloorBeads {
    /// The distance between neighbouring rings: beads touching with
    /// [`FLOOR_OVERLAP`] (mm).
    pub fn pitch(&self) -> f64 {
        self.width * (1.0 - FLOOR_OVERLAP)
    }
}

/// The elements that fill a closed polygon `outer` (the base ring's centre
/// line, counter-clockwise or not) inside it, outermost first: its
/// offsets inward by one pitch, two, … until nothing is left, each
/// resampled about `spacing` apart and turned the way `outer` turns; then
/// the core that fills the hole the last ring leaves, if any. An offset
/// that splits (a waist narrower than two beads) gives several rings at one
/// depth; they follow each other outermost first.
///
/// A ring whose two sides come closer than 3/4 of a pitch (its mean width
/// 2A/P, area over half the perimeter: the last ring of a long ellipse)
/// would lay its beads on each other; it becomes the line down its middle
/// instead, an open [`FloorRing`].
pub fn floor_rings(outer: &[[f64; 2]], beads: FloorBeads) -> Vec<FloorRing> {
    match floor_plan(outer, beads) {
        Ok(rings) => rings,
        Err(_) => rings_of(outer, &inward_offsets(outer, beads.pitch()), beads, true),
    }
}

/// Why a floor cannot be laid as one continuous path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FloorRefusal {
    /// Its islands split more than [`MAX_SPLITS`] times, the last into
    /// `count` islands `depth` mm inside the island before.
    Islands {
        /// Depth (mm) of the last split, inside the island it splits.
        depth: f64,
        /// Islands at that depth.
        count: usize,
    },
}

/// [`floor_rings`] from one set of offsets, or why the floor is refused.
///
/// A floor whose offsets split at a waist into islands is laid ring by
/// ring down to the waist, then island after island, each from its
/// outside in (and its own core), an island that splits again the same
/// way; the first ring of each island is reached by a join that may be
/// long ([`FloorRing::island`]). More than [`MAX_SPLITS`] splits deep is
/// refused.
pub fn floor_plan(
    outer: &[[f64; 2]],
    beads: FloorBeads,
) -> std::result::Result<Vec<FloorRing>, FloorRefusal> {
    let pitch = beads.pitch();
    let offsets = inward_offsets(outer, pitch);
    let mut rings = region_rings(outer, &offsets, beads, 0)?;
    rings.retain(|r| r.pts.len() >= 2);
    // A ring further out that runs into a tail (a deep lobe of a lobed
    // oval) is laid as the innermost one that is fat in the middle: its
    // tail's two sides narrower, down to a U-turn of two pitches.
    for r in rings.iter_mut().filter(|r| !r.open && !r.tail) {
        if lies_on_itself(&r.pts, pitch).is_some() {
            r.widths = narrowed_within(&r.pts, beads.width, 2.0 * pitch);
            r.tail = true;
        }
    }
    Ok(rings)
}

/// Most times a floor's islands may split again (a chain of lobes, each
/// waist narrower than the last): bounds the offsetting work.
pub const MAX_SPLITS: usize = 8;

/// The elements of a region from its inward offsets, depth by depth:
/// rings down to the depth where they split, then each island the same
/// way (its first element entered by a join, [`FloorRing::island`]),
/// down to [`MAX_SPLITS`] splits; a region that does not split ends in
/// its core or tail.
fn region_rings(
    outer: &[[f64; 2]],
    offsets: &[Vec<Vec<[f64; 2]>>],
    beads: FloorBeads,
    splits: usize,
) -> std::result::Result<Vec<FloorRing>, FloorRefusal> {
    let pitch = beads.pitch();
    let Some(s) = offsets.iter().position(|c| c.len() > 1) else {
        let mut rings = rings_of(outer, offsets, beads, true);
        end_in_tail(&mut rings, beads);
        return Ok(rings);
    };
    if splits >= MAX_SPLITS {
        return Err(FloorRefusal::Islands {
            depth: pitch * (s + 1) as f64,
            count: offsets[s].len(),
        });
    }
    let mut rings = rings_of(outer, &offsets[..s], beads, false);
    for inner in by_island(&offsets[s..]) {
        let mut part = region_rings(outer, &inner, beads, splits + 1)?;
        if let Some(first) = part.first_mut() {
            first.island = true;
        }
        rings.extend(part);
    }
    Ok(rings)
}

/// The offsets from a split on, island by island: each island's contour,
/// then the deeper contours that lie inside it (a contour lies wholly
/// inside the one it was offset from, so one of its points tells).
fn by_island(offsets: &[Vec<Vec<[f64; 2]>>]) -> Vec<Vec<Vec<Vec<[f64; 2]>>>> {
    use geo::Contains;
    let islands: Vec<geo::Polygon<f64>> = offsets[0].iter().map(|c| polygon(c)).collect();
    let mut parts: Vec<Vec<Vec<Vec<[f64; 2]>>>> =
        offsets[0].iter().map(|c| vec![vec![c.clone()]]).collect();
    for depth in &offsets[1..] {
        let mut next = vec![Vec::new(); parts.len()];
        for c in depth {
            let p = geo::Point::new(c[0][0], c[0][1]);
            if let Some(i) = islands.iter().position(|isl| isl.contains(&p)) {
                next[i].push(c.clone());
            }
        }
        for (part, cs) in parts.iter_mut().zip(next) {
            if !cs.is_empty() {
                part.push(cs);
            }
        }
    }
    parts
}

/// The innermost ring of a region that ends in a tail (a lens drawn out
/// to a point: the last offset of a long polygon or lobed oval) is laid
/// once, as the line down its middle, instead of the ring and the core
/// inside it; or, fat in the middle, stays a ring whose tail's two sides
/// are laid narrower.
fn end_in_tail(rings: &mut Vec<FloorRing>, beads: FloorBeads) {
    let pitch = beads.pitch();
    if let Some(k) = rings.iter().rposition(|r| !r.open) {
        if lies_on_itself(&rings[k].pts, pitch).is_some() {
            match midline(&rings[k].pts, beads.spacing) {
                // Thin all along: laid once, down its middle.
                Some(m) if m.1.iter().all(|t| t + beads.width <= beads.widest) => {
                    rings.truncate(k);
                    rings.push(line_of(m, beads));
                }
                // Fat in the middle: the ring stays, its tail's two sides
                // laid narrower down to a U-turn of two pitches.
                _ => {
                    let r = &mut rings[k];
                    r.widths = narrowed_within(&r.pts, beads.width, 2.0 * pitch);
                    r.tail = true;
                }
            }
        }
    }
}

fn rings_of(
    outer: &[[f64; 2]],
    offsets: &[Vec<Vec<[f64; 2]>>],
    beads: FloorBeads,
    core: bool,
) -> Vec<FloorRing> {
    let (pitch, spacing) = (beads.pitch(), beads.spacing);
    let ccw = signed_area2(outer) > 0.0;
    let mut rings = Vec::new();
    for contours in offsets {
        for contour in contours {
            let mut ring = resample_loop(contour, spacing);
            if ring.len() < 3 {
                continue;
            }
            if !ccw {
                ring.reverse();
            }
            let perimeter = closed_loop(&ring).1[ring.len()];
            if 2.0 * ring_area(&ring) / perimeter < 0.75 * pitch {
                rings.extend(thin_ring_line(&ring, beads));
            } else {
                let widths = narrowed(&ring, beads.width);
                rings.push(FloorRing {
                    pts: ring,
                    open: false,
                    widths,
                    tail: false,
                    island: false,
                });
            }
        }
    }
    if !core {
        return rings;
    }
    // The hole the innermost ring (or the outline itself) leaves.
    let last = match rings.last() {
        Some(r) if r.open => return rings,
        Some(r) => r.pts.clone(),
        None => outer.to_vec(),
    };
    rings.extend(core_of(&last, beads));
    rings
}

/// The bead that fills the hole a closed ring `ring` leaves inside it:
/// where the region the ring's beads leave bare (the ring offset inward
/// by half a bead) is wider than 2/5 of a bead, so that a bead down its
/// middle overlaps the ring's by less than 30 % of its width (narrower,
/// the squeeze of the ring's own beads closes it). The bead runs down the
/// middle of that region's core (offset 1/5 of a bead further in), or a
/// spacing across its centroid when the core is round.
fn core_of(ring: &[[f64; 2]], beads: FloorBeads) -> Option<FloorRing> {
    let w = beads.width;
    let mut contour = ring.to_vec();
    if signed_area2(&contour) < 0.0 {
        contour.reverse();
    }
    let bare = shrink(&contour, 0.5 * w);
    let core = bare
        .iter()
        .flat_map(|c| shrink(c, 0.2 * w))
        .max_by(|a, b| ring_area(a).total_cmp(&ring_area(b)))?;
    let half = 0.5 * beads.spacing;
    let dense = resample_loop(&core, half);
    let pts = match (dense.len() >= 3).then(|| midline(&dense, beads.spacing)) {
        Some(Some((line, _))) if line.len() >= 2 => line,
        _ => {
            let c = centroid(&core);
            vec![[c[0] - half, c[1]], [c[0] + half, c[1]]]
        }
    };
    Some(FloorRing {
        pts,
        open: true,
        widths: None,
        tail: false,
        island: false,
    })
}

/// The widths a closed ring's beads are laid at where its far side comes
/// closer than a pitch: two beads `d` apart overlap by the stated fraction
/// when they are `d / (1 − FLOOR_OVERLAP)` wide. "Far" is more than four
/// beads along the ring either way: nearer, round a U-turn, the nozzle
/// lays the two sides in one go. `None` where no point needs it.
fn narrowed(ring: &[[f64; 2]], width: f64) -> Option<Vec<f64>> {
    narrowed_within(ring, width, 4.0 * width)
}

/// [`narrowed`], "far" being more than `far` along the ring.
fn narrowed_within(ring: &[[f64; 2]], width: f64, far: f64) -> Option<Vec<f64>> {
    let m = ring.len();
    let cum = closed_loop(ring).1;
    let perimeter = cum[m];
    let reach = width * (1.0 - FLOOR_OVERLAP);
    let mut grid = crate::grid::Grid2::new(reach);
    for (i, p) in ring.iter().enumerate() {
        grid.insert_segment(*p, *p, i as u32);
    }
    let mut widths = vec![width; m];
    let mut any = false;
    for (i, &p) in ring.iter().enumerate() {
        let mut d = f64::INFINITY;
        grid.for_each_near_segment(p, p, reach, |j| {
            let along = (cum[i] - cum[j as usize]).abs();
            if along.min(perimeter - along) > far {
                let q = ring[j as usize];
                d = d.min((p[0] - q[0]).hypot(p[1] - q[1]));
            }
        });
        if d < reach {
            widths[i] = d / (1.0 - FLOOR_OVERLAP);
            any = true;
        }
    }
    any.then_some(widths)
}

/// The contours of a counter-clockwise closed contour offset inward by
/// `d` (none when nothing is left; several where it splits).
fn shrink(contour: &[[f64; 2]], d: f64) -> Vec<Vec<[f64; 2]>> {
    let style = OutlineStyle::new(-d).line_join(LineJoin::Bevel);
    // The first contour of a shape is its outside; an inward offset of a
    // simple polygon has no holes.
    contour
        .outline(&style)
        .into_iter()
        .filter_map(|shape| shape.into_iter().next())
        .collect()
}

/// The mean of a list of points (of a ring's: near its centroid when they
/// lie evenly spaced).
pub fn centroid(pts: &[[f64; 2]]) -> [f64; 2] {
    let m = pts.len().max(1) as f64;
    pts.iter()
        .fold([0.0, 0.0], |a, p| [a[0] + p[0] / m, a[1] + p[1] / m])
}

/// The index of the point of `pts` farthest from `from`.
fn farthest(pts: &[[f64; 2]], from: [f64; 2]) -> usize {
    let d = |p: [f64; 2]| (p[0] - from[0]).hypot(p[1] - from[1]);
    (0..pts.len())
        .max_by(|&x, &y| d(pts[x]).total_cmp(&d(pts[y])))
        .unwrap_or(0)
}

/// Where a closed floor ring lies on itself, if it does: a ring round a
/// region that ends in a tail narrower than a bead (a lobed oval's, near
/// the ends of its long axis) runs down the tail and back, and its two
/// sides would be one bead laid twice. One continuous path cannot lay the
/// tail once (it would have to come back along it), so such a floor is
/// refused (docs/ALGORITHMS.md §8). A grid of the ring's points makes it
/// linear.
fn lies_on_itself(ring: &[[f64; 2]], pitch: f64) -> Option<[f64; 2]> {
    let m = ring.len();
    let cum = closed_loop(ring).1;
    let perimeter = cum[m];
    // Two points on opposite sides of a tail: nearer than half a pitch in
    // the plane, farther along the ring than round a U-turn of two beads.
    let (near, far) = (0.5 * pitch, 2.0 * pitch);
    let mut grid = crate::grid::Grid2::new(near);
    for (i, p) in ring.iter().enumerate() {
        grid.insert_segment(*p, *p, i as u32);
    }
    ring.iter().enumerate().find_map(|(i, &p)| {
        let mut hit = None;
        grid.for_each_near_segment(p, p, near, |j| {
            let j = j as usize;
            let along = (cum[i] - cum[j]).abs();
            if hit.is_none()
                && along.min(perimeter - along) > far
                && (p[0] - ring[j][0]).hypot(p[1] - ring[j][1]) < near
            {
                hit = Some(p);
            }
        });
        hit
    })
}

/// The contours (counter-clockwise, specks dropped) of the inward offsets
/// of `outer` by `pitch`, 2 · `pitch`, … until nothing is left, one list a
/// depth. Each depth is offset by one pitch from the one before, every
/// contour thinned (Ramer–Douglas–Peucker) to the points that keep it
/// within [`OFFSET_SAG_MM`] of itself: `i_overlay`'s cost grows with the
/// points, and thinning keeps points on the contour where resampling would
/// move them onto its chords, a little farther in at every depth. The
/// rings are resampled to the spacing afterwards.
fn inward_offsets(outer: &[[f64; 2]], pitch: f64) -> Vec<Vec<Vec<[f64; 2]>>> {
    let fine = (0.2 * pitch).max(0.5);
    let mut first = resample_loop(outer, fine);
    if first.len() < 3 {
        first = outer.to_vec();
    }
    if signed_area2(&first) < 0.0 {
        first.reverse();
    }
    let mut out = Vec::new();
    let mut current = vec![thinned(&first)];
    for _ in 0..MAX_FLOOR_RINGS {
        let next: Vec<Vec<[f64; 2]>> = current
            .iter()
            .flat_map(|c| shrink(c, pitch))
            .filter(|c| !is_speck(c, pitch))
            .map(|c| thinned(&c))
            .collect();
        if next.is_empty() {
            break;
        }
        out.push(next.clone());
        current = next;
    }
    out
}

/// A closed contour as a `geo` polygon.
fn polygon(contour: &[[f64; 2]]) -> geo::Polygon<f64> {
    let ring: geo::LineString<f64> = contour
        .iter()
        .chain(std::iter::once(&contour[0]))
        .map(|p| geo::Coord { x: p[0], y: p[1] })
        .collect();
    geo::Polygon::new(ring, vec![])
}

/// A closed contour without the points its neighbours' chord passes within
/// [`OFFSET_SAG_MM`] of (counter-clockwise stays counter-clockwise).
fn thinned(contour: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let simple = polygon(contour).simplify(OFFSET_SAG_MM);
    let pts: Vec<[f64; 2]> = simple.exterior().coords().map(|c| [c.x, c.y]).collect();
    // A closed ring repeats its first point; fewer than three is a speck
    // the thinning cannot be trusted with.
    if pts.len() < 4 {
        return contour.to_vec();
    }
    pts[..pts.len() - 1].to_vec()
}

/// The farthest a thinned contour's chords may stray from the curve it
/// stands for (mm): well inside the 0.05 mm the rings are held to.
const OFFSET_SAG_MM: f64 = 0.01;

/// Whether an offset contour encloses less than a pitch squared: a speck
/// the squeeze of the beads round it fills (docs/ALGORITHMS.md §8).
fn is_speck(contour: &[[f64; 2]], pitch: f64) -> bool {
    ring_area(contour) < pitch * pitch
}

/// One element of a floor layer: a closed ring, or the open line down the
/// middle of a ring too thin to lay as one.
#[derive(Clone, Debug, PartialEq)]
pub struct FloorRing {
    /// Points about `spacing` apart.
    pub pts: Vec<[f64; 2]>,
    /// An open line (laid end to end), not a ring.
    pub open: bool,
    /// Where a ring's far side comes closer than a pitch (a thin ring's
    /// two long sides), the narrower width its beads are laid at there;
    /// along a line down a thin ring's middle, the wider width that covers
    /// both its sides: point by point (mm); `None` where every bead is the
    /// floor's.
    pub widths: Option<Vec<f64>>,
    /// The innermost ring of a region that ends in a tail, laid with its
    /// tail's two sides side by side (docs/ALGORITHMS.md §8).
    pub tail: bool,
    /// The first element of an island (a floor whose offsets split at a
    /// waist): the path reaches it by a join that may be long, across the
    /// clay of the ring round the islands or of the island before
    /// (docs/ALGORITHMS.md §8, "Islands").
    pub island: bool,
}

/// The open element that lays a thin closed ring once: the line down
/// its middle, each bead as wide as the ring's two sides' beads would
/// have covered together (the sides' distance plus a bead), from the
/// floor's bead up to the widest, so that it meets the ring outside it
/// with the stated overlap (docs/ALGORITHMS.md §8).
fn thin_ring_line(ring: &[[f64; 2]], beads: FloorBeads) -> Option<FloorRing> {
    midline(ring, beads.spacing).map(|m| line_of(m, beads))
}

/// The open element of a [`midline`]: its points, each bead the sides'
/// distance plus a bead wide, from the floor's bead up to the widest.
fn line_of((pts, apart): (Vec<[f64; 2]>, Vec<f64>), beads: FloorBeads) -> FloorRing {
    let widths: Vec<f64> = apart
        .iter()
        .map(|t| (t + beads.width).clamp(beads.width, beads.widest.max(beads.width)))
        .collect();
    let wider = widths.iter().any(|&w| w > beads.width + 1e-9);
    FloorRing {
        pts,
        open: true,
        widths: wider.then_some(widths),
        tail: false,
        island: false,
    }
}

/// The line down the middle of a thin closed ring: between the point
/// farthest from its centroid and the point farthest from that, the mean
/// of its two sides, points about `spacing` apart, with the distance
/// between the two sides at each (`None` for a speck).
fn midline(ring: &[[f64; 2]], spacing: f64) -> Option<(Vec<[f64; 2]>, Vec<f64>)> {
    let m = ring.len();
    let a = farthest(ring, centroid(ring));
    let b = farthest(ring, ring[a]);
    let side = |forward: bool| -> Vec<[f64; 2]> {
        let mut v = vec![ring[a]];
        let mut i = a;
        while i != b {
            i = if forward {
                (i + 1) % m
            } else {
                (i + m - 1) % m
            };
            v.push(ring[i]);
        }
        v
    };
    let (s1, s2) = (side(true), side(false));
    let (c1, c2) = (
        crate::curves::arc_lengths(&s1),
        crate::curves::arc_lengths(&s2),
    );
    let length = 0.5 * (c1[c1.len() - 1] + c2[c2.len() - 1]);
    if length < spacing || s1.len() < 2 || s2.len() < 2 {
        return None;
    }
    let k = ((length / spacing).round() as usize).max(2);
    let (r1, r2) = (
        crate::curves::resample_polyline(&s1, &c1, k),
        crate::curves::resample_polyline(&s2, &c2, k),
    );
    Some(
        r1.iter()
            .zip(&r2)
            .map(|(p, q)| {
                (
                    [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])],
                    (p[0] - q[0]).hypot(p[1] - q[1]),
                )
            })
            .unzip(),
    )
}

/// A loop of points with its first point again at the end, and the arc
/// lengths along it (the last is the perimeter).
fn closed_loop(ring: &[[f64; 2]]) -> (Vec<[f64; 2]>, Vec<f64>) {
    let mut closed = ring.to_vec();
    closed.push(ring[0]);
    let cum = crate::curves::arc_lengths(&closed);
    (closed, cum)
}

/// A closed polygon resampled into points about `spacing` apart (at least
/// three when it is longer than a few spacings, none when it is a speck).
fn resample_loop(poly: &[[f64; 2]], spacing: f64) -> Vec<[f64; 2]> {
    let (closed, cum) = closed_loop(poly);
    let length = cum[cum.len() - 1];
    if length < 3.0 * spacing {
        return Vec::new();
    }
    let n = ((length / spacing).round() as usize).max(3);
    let mut pts = crate::curves::resample_polyline(&closed, &cum, n + 1);
    pts.pop();
    pts
}

/// Area of the region a ring of points encloses (mm²).
pub fn ring_area(ring: &[[f64; 2]]) -> f64 {
    0.5 * signed_area2(ring).abs()
}

fn d2(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
}

/// The index of the point of `pts` nearest to `p`.
pub fn nearest(pts: &[[f64; 2]], p: [f64; 2]) -> usize {
    (0..pts.len())
        .min_by(|&a, &b| d2(p, pts[a]).total_cmp(&d2(p, pts[b])))
        .unwrap_or(0)
}

/// Where a closed ring may begin and end: the point nearest `e` (either
/// way round) where the ring's last beads, laid a whole ring after its
/// first, keep off them: no middle of the last beads lies within half a
/// bead of one of the first beads, beside it (a straight seam's closing
/// bead only meets the first bead's end). At the tip of a thin ring the
/// last beads would come back alongside the first: a bead on a bead. `e`
/// if the ring has no such place.
pub fn seam_at(ring: &[[f64; 2]], e: usize, width: f64) -> usize {
    let m = ring.len();
    let spacing = closed_loop(ring).1[m] / m as f64;
    let near = ((2.0 * width / spacing).ceil() as usize).min(m / 2);
    let at = |i: usize| ring[i % m];
    let clear = |c: usize| {
        let c = c + m;
        (0..near).all(|a| {
            let (p, q) = (at(c - a - 1), at(c - a));
            let mid = [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])];
            (0..near).all(|b| beside(mid, at(c + b), at(c + b + 1)) >= 0.5 * width)
        })
    };
    (0..=m / 2)
        .flat_map(|j| [(e + j) % m, (e + m - j) % m])
        .find(|&c| clear(c))
        .unwrap_or(e)
}

/// The distance from `p` to the segment `a`–`b` where its foot falls
/// inside the segment or within 0.3 of its length before it, else
/// infinity (`p` lies beyond an end): the margin keeps a seam off a
/// corner whose angle the path's points, moved a little by the
/// corrections, may sharpen.
fn beside(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let t = ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2;
    if l2 <= 0.0 || !(-0.3..=1.0).contains(&t) {
        return f64::INFINITY;
    }
    (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dy)
}

/// Where each floor element is entered, and the longest step from one to
/// the next (mm; a step into a ring counted at 2/3, as a ring is entered
/// at its nearest point and a line only at an end, and refused above two
/// pitches): each ring nearest the previous one's entry,
/// the first nearest `start` (where the base ring begins); an open line at
/// its nearer end.
pub fn floor_entries(rings: &[FloorRing], start: [f64; 2], width: f64) -> (Vec<usize>, f64) {
    let mut entry = Vec::with_capacity(rings.len());
    let mut at = start;
    let mut longest = 0.0f64;
    for r in rings {
        let pts = &r.pts;
        // An open line is entered at an end; inward layers leave it at
        // the other end, where the next (outward) layer comes back.
        let e = if r.open {
            if d2(at, pts[0]) <= d2(at, pts[pts.len() - 1]) {
                0
            } else {
                pts.len() - 1
            }
        } else if r.island {
            // An island is entered on the side nearest its middle, where
            // its inner rings lie a pitch apart (not at a tip pointing to
            // the waist, which they recede from).
            seam_at(pts, nearest(pts, centroid(pts)), width)
        } else {
            seam_at(pts, nearest(pts, at), width)
        };
        // A step into a line counts whole; into a ring, beyond the one
        // pitch the rings lie apart (a ring far from the last entry is
        // reached across the clay of the ring before).
        let step = d2(at, pts[e]).sqrt();
        // The join into the next island crosses the island before: long
        // by design, laid with next to no clay.
        if !r.island {
            longest = longest.max(if r.open { step } else { step * 2.0 / 3.0 });
        }
        entry.push(e);
        at = pts[e];
    }
    (entry, longest)
}

#[cfg(test)]
mod tests {
    use super::*;

    const BEADS: FloorBeads = FloorBeads {
        width: 3.0,
        spacing: 1.1,
        widest: 6.0,
    };

    fn circle(r: f64, n: usize) -> Vec<[f64; 2]> {
        ellipse(r, r, n)
    }

    fn ellipse(rx: f64, ry: f64, n: usize) -> Vec<[f64; 2]> {
        (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                [rx * a.cos(), ry * a.sin()]
            })
            .collect()
    }

    /// The points of a polyline `step` apart or closer (its vertices and
    /// points between them).
    fn dense(pts: &[[f64; 2]], closed: bool, step: f64) -> Vec<[f64; 2]> {
        let mut out = Vec::new();
        let m = pts.len();
        let segs = if closed { m } else { m.saturating_sub(1) };
        for i in 0..segs {
            let (a, b) = (pts[i], pts[(i + 1) % m]);
            let k = ((a[0] - b[0]).hypot(a[1] - b[1]) / step).ceil().max(1.0) as usize;
            for j in 0..k {
                let t = j as f64 / k as f64;
                out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
            }
        }
        if !closed || m == 1 {
            out.extend(pts.last());
        }
        out
    }

    /// The share of the points of a 0.25 mm grid inside `outer` and at
    /// least `margin` from it that lie within half a bead of the base ring
    /// or an element: the floor's coverage.
    fn coverage(outer: &[[f64; 2]], rings: &[FloorRing], margin: f64) -> f64 {
        let mut beads: Vec<[f64; 2]> = dense(outer, true, 0.25);
        for r in rings {
            beads.extend(dense(&r.pts, !r.open, 0.25));
        }
        let mut grid = crate::grid::Grid2::new(1.0);
        for (i, p) in beads.iter().enumerate() {
            grid.insert_segment(*p, *p, i as u32);
        }
        let edge = dense(outer, true, 0.25);
        let (lo, hi) = outer
            .iter()
            .fold(([f64::MAX; 2], [f64::MIN; 2]), |(l, h), p| {
                (
                    [l[0].min(p[0]), l[1].min(p[1])],
                    [h[0].max(p[0]), h[1].max(p[1])],
                )
            });
        let (mut inside, mut covered) = (0usize, 0usize);
        let mut y = lo[1];
        while y <= hi[1] {
            let mut x = lo[0];
            while x <= hi[0] {
                let p = [x, y];
                let near_edge = edge
                    .iter()
                    .any(|q| (p[0] - q[0]).hypot(p[1] - q[1]) < margin);
                if contains(outer, p) && !near_edge {
                    inside += 1;
                    let mut hit = false;
                    grid.for_each_near_segment(p, p, 0.5 * BEADS.width, |j| {
                        let q = beads[j as usize];
                        hit |= (p[0] - q[0]).hypot(p[1] - q[1]) <= 0.5 * BEADS.width;
                    });
                    covered += usize::from(hit);
                }
                x += 0.25;
            }
            y += 0.25;
        }
        covered as f64 / inside.max(1) as f64
    }

    /// Even-odd point in polygon.
    fn contains(poly: &[[f64; 2]], p: [f64; 2]) -> bool {
        let mut inside = false;
        let m = poly.len();
        for i in 0..m {
            let (a, b) = (poly[i], poly[(i + 1) % m]);
            if (a[1] > p[1]) != (b[1] > p[1])
                && p[0] < a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0])
            {
                inside = !inside;
            }
        }
        inside
    }

    /// The closest two elements (or the base ring and an element) come
    /// (mm): beads this far apart overlap by w − d.
    fn closest_elements(outer: &[[f64; 2]], rings: &[FloorRing]) -> f64 {
        let mut all = vec![dense(outer, true, 0.25)];
        all.extend(rings.iter().map(|r| dense(&r.pts, !r.open, 0.25)));
        let mut best = f64::MAX;
        for (a, pa) in all.iter().enumerate() {
            for pb in &all[a + 1..] {
                for p in pa {
                    for q in pb {
                        best = best.min((p[0] - q[0]).hypot(p[1] - q[1]));
                    }
                }
            }
        }
        best
    }

    #[test]
    fn a_circle_fills_with_concentric_rings() {
        let rings = floor_rings(&circle(30.0, 200), BEADS);
        // Radii 30 − 2.55 k; the last (1.95 mm) is a line across the middle.
        assert_eq!(rings.len(), 11, "{}", rings.len());
        assert!(rings[..10].iter().all(|r| !r.open));
        for (k, ring) in rings.iter().enumerate().take(10) {
            let want = 30.0 - 2.55 * (k + 1) as f64;
            for p in &ring.pts {
                assert!((p[0].hypot(p[1]) - want).abs() < 0.05, "ring {k}: {p:?}");
            }
        }
    }

    #[test]
    fn a_hole_in_the_middle_gets_a_bead_across_it() {
        // Rings at 29 − 2.55 k: the last at 3.5 mm leaves a hole 4 mm
        // across inside its beads.
        let outer = circle(29.0, 200);
        let rings = floor_rings(&outer, BEADS);
        let core = rings.last().unwrap();
        assert!(core.open && core.pts.len() >= 2, "{core:?}");
        let c = centroid(&core.pts);
        assert!(c[0].hypot(c[1]) < 0.1, "the core lies on the centre: {c:?}");
        let before = &rings[rings.len() - 2];
        let r = before.pts[0][0].hypot(before.pts[0][1]);
        assert!((r - (29.0 - 2.55 * 10.0)).abs() < 0.05, "{r}");
        assert!(coverage(&outer, &rings, 1.5) > 0.99);
        // Without it, the middle is bare.
        assert!(coverage(&outer, &rings[..rings.len() - 1], 1.5) < coverage(&outer, &rings, 1.5));
    }

    /// A peanut: two lobes 64 mm across joined by a waist, 110 mm long.
    fn peanut(n: usize) -> Vec<[f64; 2]> {
        (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                let y = 32.0 * a.sin() * (0.35 + 0.65 * a.cos().abs());
                [55.0 * a.cos(), y]
            })
            .collect()
    }

    #[test]
    fn a_floor_that_splits_at_a_waist_is_laid_island_by_island() {
        // Once refused ("the floor's rings would split into 2 separate
        // islands"): the rings round both lobes down to the waist, then
        // each island from its outside in, each entered by a join.
        let outer = peanut(240);
        let rings = floor_plan(&outer, BEADS).unwrap();
        let islands: Vec<usize> = (0..rings.len()).filter(|&k| rings[k].island).collect();
        assert_eq!(islands.len(), 2, "{:?}", islands);
        // The islands lie either side of the waist, and every element of
        // an island after its first lies inside it.
        let mid = |k: usize| centroid(&rings[k].pts)[0];
        assert!(mid(islands[0]) * mid(islands[1]) < 0.0);
        for (n, &k) in islands.iter().enumerate() {
            let end = islands.get(n + 1).copied().unwrap_or(rings.len());
            for j in k + 1..end {
                assert!(mid(j) * mid(k) > 0.0, "element {j} of island {n}");
            }
        }
        // Entered at its middle side, each island's rings follow a pitch
        // apart; only the joins into the islands are long.
        let start = outer[0];
        let (entries, longest) = floor_entries(&rings, start, BEADS.width);
        assert!(longest <= 2.0 * BEADS.pitch(), "{longest}");
        assert_eq!(entries.len(), rings.len());
        let cov = coverage(&outer, &rings, 1.5);
        assert!(cov > 0.95, "{cov}");
        let d = closest_elements(&outer, &rings);
        assert!(d > 0.75 * BEADS.pitch(), "{d}");
    }

    /// Three smooth lobes in a row, 64 mm across, 60 and 66 mm apart: the
    /// waist between the first two about 41 mm across, the other 32 mm.
    fn three_lobes() -> Vec<[f64; 2]> {
        let centres = [-60.0, 0.0, 66.0];
        let half = |x: f64| {
            centres
                .iter()
                .map(|c: &f64| 32.0 * (-((x - c) / 28.0).powi(2)).exp())
                .sum::<f64>()
        };
        let n = 240;
        let (a, b) = (-110.0, 116.0);
        let xs: Vec<f64> = (0..=n).map(|i| a + (b - a) * i as f64 / n as f64).collect();
        let mut pts: Vec<[f64; 2]> = xs.iter().map(|&x| [x, -half(x)]).collect();
        pts.extend(xs.iter().rev().skip(1).take(n - 1).map(|&x| [x, half(x)]));
        pts
    }

    #[test]
    fn islands_that_split_again_are_laid_island_in_island() {
        // The narrower waist splits the floor first (one lobe, and two
        // still joined); the wider one splits those two later. It was
        // refused as islands that split again.
        let outer = three_lobes();
        let rings = floor_plan(&outer, BEADS).unwrap();
        let islands = rings.iter().filter(|r| r.island).count();
        assert!(islands >= 4, "{islands}");
        // Started at the middle lobe's side (the tapered ends are no
        // place to start a floor from: the pipeline picks a start column
        // the same way, docs/ALGORITHMS.md §8).
        let (_, longest) = floor_entries(&rings, outer[120], BEADS.width);
        assert!(longest <= 2.0 * BEADS.pitch(), "{longest}");
        let cov = coverage(&outer, &rings, 1.5);
        assert!(cov > 0.95, "{cov}");
        let d = closest_elements(&outer, &rings);
        assert!(d > 0.75 * BEADS.pitch(), "{d}");
    }

    #[test]
    fn ovals_fill_to_their_thin_core() {
        // 100 × 70 mm (once refused: "the floor's innermost ring is a
        // sliver"), and longer ones: the offsets end in a thin ring or the
        // line down the middle of one, along the long axis.
        for ry in [35.0, 28.0, 20.0, 14.0] {
            let outer = ellipse(50.0, ry, 240);
            let rings = floor_plan(&outer, BEADS).unwrap();
            let last = rings.last().unwrap();
            let (lo, hi) = last
                .pts
                .iter()
                .fold(([f64::MAX; 2], [f64::MIN; 2]), |(l, h), p| {
                    (
                        [l[0].min(p[0]), l[1].min(p[1])],
                        [h[0].max(p[0]), h[1].max(p[1])],
                    )
                });
            assert!(
                hi[0] - lo[0] > 2.0 * (hi[1] - lo[1]),
                "ry {ry}: {lo:?} {hi:?}"
            );
            let cov = coverage(&outer, &rings, 1.5);
            assert!(cov > 0.97, "ry {ry}: {cov}");
            // Neighbouring beads overlap by the stated fraction, never
            // more (a thin core lies between its ring's sides).
            let d = closest_elements(&outer, &rings);
            assert!(d > 0.75 * BEADS.pitch(), "ry {ry}: {d}");
        }
    }

    #[test]
    fn rounded_squares_and_lobes_cover_their_floor_without_beads_on_beads() {
        let square: Vec<[f64; 2]> = (0..4)
            .flat_map(|c| {
                let (cx, cy) = [(30.0, 30.0), (-30.0, 30.0), (-30.0, -30.0), (30.0, -30.0)][c];
                (0..10).map(move |k| {
                    let a = std::f64::consts::FRAC_PI_2 * (c as f64 + k as f64 / 9.0);
                    [cx + 10.0 * a.cos(), cy + 10.0 * a.sin()]
                })
            })
            .collect();
        let lobed: Vec<[f64; 2]> = (0..240)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / 240.0;
                let r = 35.0 * (1.0 + 0.12 * (5.0 * t).cos());
                [r * t.cos(), r * t.sin()]
            })
            .collect();
        for outer in [square, lobed] {
            let rings = floor_plan(&outer, BEADS).unwrap();
            let cov = coverage(&outer, &rings, 1.5);
            assert!(cov > 0.97, "{cov}");
            let d = closest_elements(&outer, &rings);
            assert!(d > 0.75 * BEADS.pitch(), "{d}");
        }
    }

    /// A long oval with five shallow lobes (a random vessel that once
    /// failed its check): deep inside, its floor ends in a tail.
    fn lobed_oval(depth: f64) -> Vec<[f64; 2]> {
        (0..240)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / 240.0;
                let r = 1.0 + depth * (5.0 * t).cos();
                [51.86 * r * t.cos(), 19.14 * r * t.sin()]
            })
            .collect()
    }

    #[test]
    fn a_ring_further_out_that_runs_into_a_tail_is_laid_narrower_there() {
        // A ring some way in runs out into a tail between two lobes (once
        // refused: "the floor narrows to a sliver thinner than a bead"):
        // it is laid as a fat innermost ring is, its tail's two sides
        // narrower down to a U-turn, and the floor still covers.
        let outer = lobed_oval(0.1164);
        let rings = floor_plan(&outer, BEADS).unwrap();
        let tails: Vec<&FloorRing> = rings.iter().filter(|r| r.tail).collect();
        assert!(!tails.is_empty());
        for r in &tails {
            let w = r.widths.as_ref().expect("narrowed where the sides meet");
            assert!(w.iter().any(|&w| w < BEADS.width - 1e-9));
            assert!(w.iter().all(|&w| w <= BEADS.width + 1e-9));
        }
        let cov = coverage(&outer, &rings, 1.5);
        assert!(cov > 0.95, "{cov}");
        let d = closest_elements(&outer, &rings);
        assert!(d > 0.75 * BEADS.pitch(), "{d}");
        // Without the lobes the same oval ends in a line down its middle.
        let rings = floor_plan(&lobed_oval(0.0), BEADS).unwrap();
        assert!(rings.last().unwrap().open);
        for r in rings.iter().filter(|r| !r.open) {
            assert_eq!(lies_on_itself(&r.pts, BEADS.pitch()), None);
        }
    }

    /// An oval `rx` × `ry` with `n` lobes `depth` deep.
    fn lobes(rx: f64, ry: f64, n: f64, depth: f64) -> Vec<[f64; 2]> {
        (0..240)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / 240.0;
                let r = 1.0 + depth * (n * t).cos();
                [rx * r * t.cos(), ry * r * t.sin()]
            })
            .collect()
    }

    #[test]
    fn a_floor_that_ends_in_a_point_is_laid_without_beads_on_beads() {
        // The innermost ring of a lobed oval runs out to points whose sides
        // lie on each other (once refused: "the floor narrows to a sliver
        // thinner than a bead"). Thin all along, it is laid once down its
        // middle, as wide as its two sides would have covered; fatter in
        // its middle, it stays a ring whose tail's two sides are laid
        // narrower, touching with the stated overlap.
        for (rx, ry, n, depth) in [
            (40.0, 20.0, 5.0, 0.05),
            (50.0, 20.0, 3.0, 0.05),
            (60.0, 20.0, 5.0, 0.1),
        ] {
            let outer = lobes(rx, ry, n, depth);
            let plain = floor_rings(&outer, BEADS);
            let innermost = plain.iter().rfind(|r| !r.open).unwrap();
            assert!(lies_on_itself(&innermost.pts, BEADS.pitch()).is_some());
            let rings = floor_plan(&outer, BEADS).unwrap();
            let cov = coverage(&outer, &rings, 1.5);
            assert!(cov > 0.95, "{rx} × {ry}: {cov}");
            let tail = rings.iter().find(|r| r.tail).expect("a tail ring");
            let w = tail.widths.as_ref().expect("narrowed");
            let (m, cum) = (tail.pts.len(), closed_loop(&tail.pts).1);
            for i in 0..m {
                for j in 0..m {
                    let along = (cum[i] - cum[j]).abs();
                    let d = d2(tail.pts[i], tail.pts[j]).sqrt();
                    if along.min(cum[m] - along) > 2.0 * BEADS.pitch() && d < BEADS.pitch() {
                        let overlap = 0.5 * (w[i] + w[j]) - d;
                        assert!(
                            overlap <= FLOOR_OVERLAP * w[i].max(w[j]) + 1e-6,
                            "{overlap} at {i} {j}"
                        );
                    }
                }
            }
        }
        // A thin ring of the same kind is one line down its middle.
        let thin = vec![[0.0, 0.0], [30.0, -1.0], [34.0, 0.0], [30.0, 1.0]];
        let line = thin_ring_line(&resample_loop(&thin, 0.5), BEADS).unwrap();
        assert!(line.open);
        let widest = line.widths.unwrap().into_iter().fold(0.0, f64::max);
        assert!((widest - (2.0 + BEADS.width)).abs() < 0.1, "{widest}");
    }

    #[test]
    fn rings_turn_the_way_the_outline_turns() {
        let mut cw = circle(20.0, 100);
        cw.reverse();
        for ring in floor_rings(&cw, BEADS).iter().filter(|r| !r.open) {
            assert!(signed_area2(&ring.pts) < 0.0);
        }
    }

    #[test]
    fn each_element_is_entered_a_short_step_from_the_last() {
        let rings = floor_rings(&ellipse(50.0, 35.0, 240), BEADS);
        // From the end of the long axis the rings' nearest points lead
        // down it to the core's end.
        let (entry, longest) = floor_entries(&rings, [50.0, 0.0], BEADS.width);
        assert_eq!(entry.len(), rings.len());
        assert!(longest <= 2.0 * BEADS.pitch(), "{longest}");
    }
}
