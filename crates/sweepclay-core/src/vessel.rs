//! Vessels: a closed Ψ printed as a floor and a spiral wall in one
//! continuous path (not in the paper; docs/ALGORITHMS.md §8).
//!
//! The layering ([`VesselPlan::choose`]) gives every column of the loop the
//! same flat base layers (the floor's outer ring, or one ring for a
//! bottomless vessel) and then the same number K of spiral turns: turn k
//! visits column i of n at
//!
//! ```text
//! z = z_base + (k − 1 + (i + 1) / n) · δ_i,    δ_i = (h_i − z_base) / K
//! ```
//!
//! so z rises along every turn with no seam, and a last, partial turn lays
//! the rim level at h_i. The floor inside the base ring is filled by
//! concentric inward offsets ([`floor_rings`], computed with `i_overlay`)
//! whose beads touch with [`FLOOR_OVERLAP`]; [`plan_vessel_path`] joins
//! them, layer by layer, into the path with no travel.

use crate::correct::Corrected;
use crate::curves::signed_area2;
use crate::design::{Params, COLLISION_MARGIN_MM};
use crate::error::{Error, Result};
use crate::toolpath::{PathPoint, PointKind, Toolpath};
use geo::Simplify;
use i_overlay::mesh::outline::offset::OutlineOffset;
use i_overlay::mesh::style::{LineJoin, OutlineStyle};

/// Overlap of a floor bead with its neighbour in the same layer, as a
/// fraction of its width: enough to close the floor, little enough that the
/// clay has room (docs/ALGORITHMS.md §8).
pub const FLOOR_OVERLAP: f64 = 0.15;

/// Most floor rings a layer may have (a floor 5 m across at 3 mm beads,
/// far beyond any printer; the sample cap refuses such designs first):
/// bounds the offsetting work.
pub const MAX_FLOOR_RINGS: usize = 1000;

/// The layering of a vessel.
#[derive(Clone, Debug, PartialEq)]
pub struct VesselPlan {
    /// Floor layers asked for (0: bottomless).
    pub floor_layers: u32,
    /// Flat layers of the base ring under the spiral: the floor's layers,
    /// or one ring for a bottomless vessel.
    pub base_layers: u32,
    /// Height of each base layer (`layer_height`, mm).
    pub base_layer_mm: f64,
    /// K: spiral turns of the wall.
    pub turns: u32,
    /// Thinnest and thickest spiral layer δ_i round the loop (mm).
    pub turn_mm: [f64; 2],
    /// The column each layer and turn begins at (the path's start in
    /// plan, chosen near the floor's centre so the rings join by short
    /// steps; docs/ALGORITHMS.md §8).
    pub start: usize,
    /// The floor's rings as sampling found them, and the base ring they
    /// fill: the path reuses them while the corrections leave that ring
    /// as it was.
    pub floor: FloorOf,
}

/// A base ring and the floor rings that fill it, if computed.
pub type FloorOf = Option<(Vec<[f64; 2]>, Vec<FloorRing>)>;

impl VesselPlan {
    /// z_base: the top of the base layers (mm).
    pub fn base_mm(&self) -> f64 {
        f64::from(self.base_layers) * self.base_layer_mm
    }

    /// Chooses the layering for a loop whose columns are `h` tall: the
    /// most turns (the thinnest layers) that keep every δ_i within
    /// [layer_height, max_layer_height]. Refuses a rim whose height varies
    /// more than that allows, or more than the extruder body clears.
    pub fn choose(h: &[f64], params: &Params, floor_layers: u32) -> Result<VesselPlan> {
        let (dmin, dmax) = (params.layer_height, params.max_layer_height);
        let base_layers = floor_layers.max(1);
        let base = f64::from(base_layers) * dmin;
        let lo = h.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = h.iter().copied().fold(0.0, f64::max);
        if lo < base + dmin - 1e-9 {
            return Err(Error::invalid(
                "profile_start",
                format!(
                    "the vessel is {lo:.2} mm tall at its lowest, less than its {base_layers} base layer(s) ({base:.2} mm) and one turn of wall; make it taller or lower params.floor_layers"
                ),
            ));
        }
        // The spiral's layers under the tall side are thicker; the extruder
        // body passes over the low side while the high side stands.
        let clear = params.nozzle_height - COLLISION_MARGIN_MM - dmax;
        if hi - lo > clear + 1e-9 {
            return Err(Error::invalid(
                "profile_end",
                format!(
                    "the rim's height varies by {:.1} mm round the loop ({lo:.1} to {hi:.1} mm); the extruder body ({} mm high) clears at most {clear:.1} mm: bring the two profiles' heights closer",
                    hi - lo,
                    params.nozzle_height
                ),
            ));
        }
        let most = ((lo - base) / dmin + 1e-9).floor() as u32;
        let fewest = ((hi - base) / dmax - 1e-9).ceil().max(1.0) as u32;
        if most < fewest {
            return Err(Error::invalid(
                "params.max_layer_height",
                format!(
                    "the rim's height varies from {lo:.1} to {hi:.1} mm round the loop: no whole number of spiral turns keeps every layer between {dmin} and {dmax} mm (at most {most} turns of {dmin} mm on the low side, at least {fewest} of {dmax} mm on the high side); raise params.max_layer_height or bring the profiles' heights closer"
                ),
            ));
        }
        let turns = most;
        let k = f64::from(turns);
        Ok(VesselPlan {
            floor_layers,
            base_layers,
            base_layer_mm: dmin,
            turns,
            turn_mm: [(lo - base) / k, (hi - base) / k],
            start: 0,
            floor: None,
        })
    }

    /// The height of spiral turn `k` (1-based) at column `i` of `n`, whose
    /// rim is `h` (mm).
    pub fn spiral_z(&self, k: u32, i: usize, n: usize, h: f64) -> f64 {
        let base = self.base_mm();
        let d = (h - base) / f64::from(self.turns);
        base + (f64::from(k - 1) + (self.order(i, n) + 1) as f64 / n as f64) * d
    }

    /// Where column `i` of `n` comes in a turn (0 for [`VesselPlan::start`]).
    pub fn order(&self, i: usize, n: usize) -> usize {
        (i + n - self.start % n) % n
    }

    /// Whether column `i` of `n` gets a rim bead: where the last turn ends
    /// at least half a layer below the rim (a thinner bead is no bead, as
    /// for the top-edge beads of a wall; the rim is then level to within
    /// half a layer).
    pub fn has_rim(&self, i: usize, n: usize, h: f64) -> bool {
        h - self.spiral_z(self.turns, i, n, h) >= 0.5 * self.base_layer_mm - 1e-9
    }

    /// Which columns get a rim bead: the run from the turn's start while
    /// [`VesselPlan::has_rim`] holds and the nozzle, level at the rim,
    /// clears the last turn's clay within `reach` in plan and the rim
    /// beads laid more than `exempt` columns before (a rim that rises
    /// steeply ahead ends the run early: the rim is then level to within
    /// a layer there). `h` as for [`VesselPlan::body_violation`].
    pub fn rim_beads(&self, near: &Neighbours, h: &[f64], exempt: usize) -> Vec<bool> {
        let n = near.len();
        let mut rim: Vec<bool> = (0..n).map(|i| self.has_rim(i, n, h[i])).collect();
        // The rim turn is one run from the turn's start: once a bead is
        // left out, so are the rest (a gap would be a jump across).
        let mut ended = false;
        for m in 0..n {
            let i = (self.start + m) % n;
            if ended || !rim[i] {
                rim[i] = false;
                ended = true;
                continue;
            }
            let mut clear = true;
            near.each(i, |j| {
                let mut top = self.spiral_z(self.turns, j, n, h[j]);
                let (oi, oj) = (self.order(i, n), self.order(j, n));
                if oj < oi && oi - oj > exempt && rim[j] {
                    top = top.max(h[j]);
                }
                if top - h[i] > BODY_GRAZE_MM {
                    clear = false;
                }
            });
            rim[i] = clear;
            ended = !clear;
        }
        rim
    }

    /// The first column where the extruder body would meet clay already
    /// laid (docs/ALGORITHMS.md §8): for every pair of columns `i`, `j`
    /// within reach in plan (`near`), the turn below at `j` (or, more than
    /// `exempt` columns back along the loop, this turn at `j`) must not
    /// stand more than [`BODY_GRAZE_MM`] above the nozzle at `i`. Checked
    /// at the turns where the difference is largest (it is linear in the
    /// turn). `h` are the columns' rims.
    pub fn body_violation(
        &self,
        near: &Neighbours,
        h: &[f64],
        exempt: usize,
    ) -> Option<(usize, f64)> {
        let n = near.len();
        let turns = [1.max(self.turns.min(2)), self.turns];
        let mut worst: Option<(usize, f64)> = None;
        for i in 0..n {
            near.each(i, |j| {
                if j == i {
                    return;
                }
                for k in turns {
                    let me = self.spiral_z(k, i, n, h[i]);
                    let below = if k > 1 {
                        self.spiral_z(k - 1, j, n, h[j])
                    } else {
                        self.base_mm()
                    };
                    // This turn's clay at j, laid long enough ago to count.
                    let (oi, oj) = (self.order(i, n), self.order(j, n));
                    let same = if oj < oi && oi - oj > exempt {
                        self.spiral_z(k, j, n, h[j])
                    } else {
                        f64::MIN
                    };
                    let over = below.max(same) - me;
                    if over > BODY_GRAZE_MM && worst.is_none_or(|w| over > w.1) {
                        worst = Some((i, over));
                    }
                }
            });
        }
        worst
    }
}

/// The columns of a loop within a reach of each other in plan, found by
/// a grid built once: what the extruder body can touch.
pub struct Neighbours<'a> {
    points: &'a [[f64; 2]],
    grid: crate::grid::Grid2,
    reach: f64,
}

impl<'a> Neighbours<'a> {
    /// The columns at `points` (in plan), `reach` apart or nearer.
    pub fn new(points: &'a [[f64; 2]], reach: f64) -> Neighbours<'a> {
        let mut grid = crate::grid::Grid2::new(reach.max(1e-3));
        for (i, p) in points.iter().enumerate() {
            grid.insert_segment(*p, *p, i as u32);
        }
        Neighbours {
            points,
            grid,
            reach,
        }
    }

    /// The number of columns.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether there are no columns.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Calls `f` with every column within reach of column `i` (`i` too).
    pub fn each(&self, i: usize, mut f: impl FnMut(usize)) {
        let (p, r) = (self.points[i], self.reach);
        self.grid.for_each_near_segment(p, p, r, |j| {
            let q = self.points[j as usize];
            if (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) <= r * r {
                f(j as usize);
            }
        });
    }
}

/// Clay this little above the nozzle tip, near the edge of the extruder
/// body, is a graze on a bead's rounded edge (as the checker allows).
pub const BODY_GRAZE_MM: f64 = 0.2;

/// The concentric rings that fill a closed polygon `outer` (the base ring,
/// counter-clockwise or not) inside it: offsets inward by `pitch`, 2 ·
/// `pitch`, … until nothing is left, each resampled about `spacing` apart
/// and turned the way `outer` turns. An offset that splits (a waist
/// narrower than two beads) gives several rings at one depth; they follow
/// each other outermost first.
///
/// A ring whose two sides come closer than 3/4 of `pitch` (its mean width
/// 2A/P, area over half the perimeter: the last ring of a long ellipse) would lay its beads on each other; it becomes the line
/// down its middle instead, an open [`FloorRing`].
pub fn floor_rings(outer: &[[f64; 2]], pitch: f64, spacing: f64) -> Vec<FloorRing> {
    rings_of(outer, &inward_offsets(outer, pitch), pitch, spacing)
}

/// Why a floor cannot be laid as one continuous path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FloorRefusal {
    /// Its offsets split into `count` islands `depth` mm inside the wall.
    Islands {
        /// Depth (mm) of the first split.
        depth: f64,
        /// Islands at that depth.
        count: usize,
    },
    /// A ring `depth` mm inside the wall lies on itself at `at` (plan,
    /// design coordinates): the region ends in a tail narrower than a bead.
    Tail {
        /// Depth (mm) of the ring.
        depth: f64,
        /// Where its two sides meet.
        at: [f64; 2],
    },
}

/// [`floor_rings`] from one set of offsets, or why the floor is refused.
pub fn floor_plan(
    outer: &[[f64; 2]],
    pitch: f64,
    spacing: f64,
) -> std::result::Result<Vec<FloorRing>, FloorRefusal> {
    let offsets = inward_offsets(outer, pitch);
    if let Some((depth, count)) = split_of(&offsets, pitch) {
        return Err(FloorRefusal::Islands { depth, count });
    }
    let rings = rings_of(outer, &offsets, pitch, spacing);
    for (k, r) in rings.iter().enumerate().filter(|(_, r)| !r.open) {
        if let Some(at) = lies_on_itself(&r.pts, pitch) {
            // One contour a depth: ring k is k + 1 pitches in.
            return Err(FloorRefusal::Tail {
                depth: pitch * (k + 1) as f64,
                at,
            });
        }
    }
    Ok(rings)
}

fn rings_of(
    outer: &[[f64; 2]],
    offsets: &[Vec<Vec<[f64; 2]>>],
    pitch: f64,
    spacing: f64,
) -> Vec<FloorRing> {
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
                if let Some(line) = midline(&ring, spacing) {
                    rings.push(FloorRing {
                        pts: line,
                        open: true,
                    });
                }
            } else {
                rings.push(FloorRing {
                    pts: ring,
                    open: false,
                });
            }
        }
    }
    rings
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
/// contour thinned (Ramer–Douglas–Peucker) to the points that keep it within
/// [`OFFSET_SAG_MM`] of itself: `i_overlay`'s cost grows with the points,
/// and thinning keeps points on the contour where resampling would move
/// them onto its chords, a little farther in at every depth. The rings are
/// resampled to the spacing afterwards.
fn inward_offsets(outer: &[[f64; 2]], pitch: f64) -> Vec<Vec<Vec<[f64; 2]>>> {
    let fine = (0.2 * pitch).max(0.5);
    let mut first = resample_loop(outer, fine);
    if first.len() < 3 {
        first = outer.to_vec();
    }
    if signed_area2(&first) < 0.0 {
        first.reverse();
    }
    let style = OutlineStyle::new(-pitch).line_join(LineJoin::Bevel);
    let mut out = Vec::new();
    let mut current = vec![thinned(&first)];
    for _ in 0..MAX_FLOOR_RINGS {
        let next: Vec<Vec<[f64; 2]>> = current
            .iter()
            .flat_map(|c| c.outline(&style))
            // The first contour of a shape is its outside; an inward
            // offset of a simple polygon has no holes.
            .filter_map(|shape| shape.into_iter().next())
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

/// The first depth (mm inside `outer`) at which its inward offsets by
/// multiples of `pitch` split into separate islands, if they do: one
/// continuous path cannot go from one island to the next without crossing
/// the clay between them, so such a floor is refused (docs/ALGORITHMS.md
/// §8).
fn split_of(offsets: &[Vec<Vec<[f64; 2]>>], pitch: f64) -> Option<(f64, usize)> {
    offsets
        .iter()
        .enumerate()
        .find(|(_, c)| c.len() > 1)
        .map(|(d, c)| (pitch * (d + 1) as f64, c.len()))
}

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
}

/// The line down the middle of a thin closed ring: between the point
/// farthest from its centroid and the point farthest from that, the mean
/// of its two sides, points about `spacing` apart (`None` for a speck).
fn midline(ring: &[[f64; 2]], spacing: f64) -> Option<Vec<[f64; 2]>> {
    let m = ring.len();
    let c = ring.iter().fold([0.0, 0.0], |a, p| {
        [a[0] + p[0] / m as f64, a[1] + p[1] / m as f64]
    });
    let far = |from: [f64; 2]| {
        (0..m)
            .max_by(|&x, &y| {
                let dx = (ring[x][0] - from[0]).hypot(ring[x][1] - from[1]);
                let dy = (ring[y][0] - from[0]).hypot(ring[y][1] - from[1]);
                dx.total_cmp(&dy)
            })
            .unwrap_or(0)
    };
    let a = far(c);
    let b = far(ring[a]);
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
            .map(|(p, q)| [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])])
            .collect(),
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

fn d2(a: [f64; 3], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
}

/// The index of the point of `ring` nearest to `p` in plan.
fn nearest(ring: &[[f64; 2]], p: [f64; 3]) -> usize {
    (0..ring.len())
        .min_by(|&a, &b| d2(p, ring[a]).total_cmp(&d2(p, ring[b])))
        .unwrap_or(0)
}

/// Where each floor element is entered, and the longest step from one to
/// the next (mm; a step into a ring counted at 2/3, as a ring is entered
/// at its nearest point and a line only at an end, and refused above two
/// pitches): each ring nearest the previous one's entry,
/// the first nearest `start` (where the base ring begins); an open line at
/// its nearer end.
pub fn floor_entries(rings: &[FloorRing], start: [f64; 3]) -> (Vec<usize>, f64) {
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
        } else {
            nearest(pts, at)
        };
        // A step into a line counts whole; into a ring, beyond the one
        // pitch the rings lie apart (a ring far from the last entry is
        // reached across the clay of the ring before).
        let step = d2(at, pts[e]).sqrt();
        longest = longest.max(if r.open { step } else { step * 2.0 / 3.0 });
        entry.push(e);
        at = [pts[e][0], pts[e][1], 0.0];
    }
    (entry, longest)
}

/// The toolpath of a vessel: the base layers (floor rings inward on one
/// layer, outward on the next, so the last ends on the base ring), the
/// spiral turns, and the rim. Every sample of the surface is visited once;
/// the floor's inner rings add their own points.
pub fn plan_vessel_path(c: &Corrected, v: &VesselPlan) -> Toolpath {
    let s = &c.surface;
    let n = s.columns.len();
    let base_ring: Vec<[f64; 2]> = (0..n)
        .map(|i| {
            let p = s.position(i, s.columns[i].first as usize);
            [p[0], p[1]]
        })
        .collect();
    let pitch = s.params.width_min * (1.0 - FLOOR_OVERLAP);
    let rings = match &v.floor {
        _ if v.floor_layers == 0 => Vec::new(),
        Some((ring, rings)) if *ring == base_ring => rings.clone(),
        _ => floor_rings(&base_ring, pitch, s.spacing),
    };
    // Where each ring is entered: nearest the previous ring's entry,
    // the first nearest column 0 (where the base ring starts).
    let c0 = &s.columns[v.start];
    let entry = floor_entries(&rings, s.position(v.start, c0.first as usize)).0;
    let floor_points: usize = rings.iter().map(|r| r.pts.len()).sum();
    let total = s.samples.len() + floor_points * v.floor_layers as usize;
    let mut points = Vec::with_capacity(total);
    let mut below = Vec::with_capacity(total);
    // Path index of each column's samples, and of each floor ring's points
    // on the layer below.
    let mut path_of = vec![u32::MAX; s.samples.len()];
    let mut ring_below: Vec<Vec<u32>> = rings.iter().map(|r| vec![u32::MAX; r.pts.len()]).collect();
    let visit_column = |points: &mut Vec<PathPoint>,
                        below: &mut Vec<Option<u32>>,
                        path_of: &mut Vec<u32>,
                        i: usize,
                        local: usize,
                        pass: u32,
                        kind: PointKind| {
        let col = &s.columns[i];
        let si = col.first as usize + local;
        path_of[si] = points.len() as u32;
        below.push((local > 0).then(|| path_of[si - 1]));
        points.push(PathPoint {
            pos: s.position(i, si),
            column: i as u32,
            pass,
            kind,
        });
    };
    // Sample `local` of every column, round the loop from the start.
    let visit_turn = |points: &mut Vec<PathPoint>,
                      below: &mut Vec<Option<u32>>,
                      path_of: &mut Vec<u32>,
                      local: usize,
                      pass: u32| {
        for m in 0..n {
            let i = (v.start + m) % n;
            visit_column(points, below, path_of, i, local, pass, PointKind::Pass);
        }
    };
    let base = v.base_layers;
    for layer in 1..=base {
        let z = f64::from(layer) * v.base_layer_mm;
        let local = layer as usize - 1;
        // The last base layer runs outward, the one before inward, …
        let outward = (base - layer).is_multiple_of(2);
        let mut floor = |points: &mut Vec<PathPoint>, below: &mut Vec<Option<u32>>, r: usize| {
            let ring = &rings[r].pts;
            let m = ring.len();
            for step in 0..m {
                let j = match (rings[r].open, outward == (entry[r] == 0)) {
                    (false, _) => (entry[r] + step) % m,
                    // Open: inward from the entry end, outward back to it.
                    (true, true) => m - 1 - step,
                    (true, false) => step,
                };
                let under = ring_below[r][j];
                below.push((under != u32::MAX).then_some(under));
                ring_below[r][j] = points.len() as u32;
                points.push(PathPoint {
                    pos: [ring[j][0], ring[j][1], z],
                    column: 0,
                    pass: layer,
                    kind: PointKind::Floor,
                });
            }
        };
        // A floor layer that runs inward starts on the base ring; one that
        // runs outward ends on it.
        let floor_order: Vec<usize> = match layer <= v.floor_layers {
            false => Vec::new(),
            true if outward => (0..rings.len()).rev().collect(),
            true => (0..rings.len()).collect(),
        };
        if !outward {
            visit_turn(&mut points, &mut below, &mut path_of, local, layer);
        }
        for r in floor_order {
            floor(&mut points, &mut below, r);
        }
        if outward {
            visit_turn(&mut points, &mut below, &mut path_of, local, layer);
        }
    }
    // The base ring closes on its own height: back over its first point
    // before the spiral rises from there. Ended on the spiral's first
    // point, barely above the ring, the closing bead would be sized for
    // half the ring's height and leave a thin place under the seam.
    if base > 0 {
        let first = path_of[c0.first as usize + base as usize - 1] as usize;
        below.push(below[first]);
        points.push(PathPoint {
            kind: PointKind::Pass,
            ..points[first]
        });
    }
    for k in 1..=v.turns {
        let local = (base + k) as usize - 1;
        visit_turn(&mut points, &mut below, &mut path_of, local, base + k);
    }
    let rim = base + v.turns + 1;
    for i in (0..n).map(|m| (v.start + m) % n) {
        if s.columns[i].top {
            let local = s.columns[i].passes as usize;
            visit_column(
                &mut points,
                &mut below,
                &mut path_of,
                i,
                local,
                rim,
                PointKind::Top,
            );
        }
    }
    debug_assert!(
        path_of.iter().all(|&p| p != u32::MAX),
        "every sample is visited"
    );
    let floor_area = if v.floor_layers > 0 {
        ring_area(&base_ring)
    } else {
        0.0
    };
    Toolpath {
        points,
        below,
        passes: rim,
        stages: 1,
        returning_points: 0,
        vessel: Some(VesselPath {
            floor_layers: v.floor_layers,
            floor_rings: rings.len() as u32,
            floor_area_mm2: floor_area,
            turns: v.turns,
        }),
    }
}

/// What the path of a vessel holds beyond its points.
#[derive(Clone, Debug, PartialEq)]
pub struct VesselPath {
    /// Floor layers (0: bottomless).
    pub floor_layers: u32,
    /// Inner rings of each floor layer (the base ring not counted).
    pub floor_rings: u32,
    /// Area inside the base ring (mm²), 0 for a bottomless vessel.
    pub floor_area_mm2: f64,
    /// Spiral turns of the wall.
    pub turns: u32,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle(r: f64, n: usize) -> Vec<[f64; 2]> {
        (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                [r * a.cos(), r * a.sin()]
            })
            .collect()
    }

    #[test]
    fn a_circle_fills_with_concentric_rings() {
        let rings = floor_rings(&circle(30.0, 200), 2.55, 1.1);
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
    fn a_floor_ring_that_would_lie_on_itself_is_refused() {
        match floor_plan(&lobed_oval(0.1164), 2.55, 1.1) {
            Err(FloorRefusal::Tail { depth, at }) => {
                assert!(depth > 10.0 && at[0].abs() > 15.0, "{depth} {at:?}");
            }
            other => panic!("{other:?}"),
        }
        // Without the lobes the same oval ends in a line down its middle.
        let rings = floor_plan(&lobed_oval(0.0), 2.55, 1.1).unwrap();
        assert!(rings.last().unwrap().open);
        for r in rings.iter().filter(|r| !r.open) {
            assert_eq!(lies_on_itself(&r.pts, 2.55), None);
        }
    }

    #[test]
    fn rings_turn_the_way_the_outline_turns() {
        let mut cw = circle(20.0, 100);
        cw.reverse();
        for ring in floor_rings(&cw, 2.55, 1.1).iter().filter(|r| !r.open) {
            assert!(signed_area2(&ring.pts) < 0.0);
        }
    }

    fn cup(r: f64, h: f64, floor: u32) -> crate::Sliced {
        let cp: Vec<[f64; 2]> = circle(r, 400);
        let d = crate::Design::from_json(
            &serde_json::json!({
                "sweepclay": 1,
                "profile_start": { "control_points": [[0.0, 0.0], [0.0, h]] },
                "profile_end": { "control_points": [[0.0, 0.0], [0.0, h]] },
                "trajectory": { "points": cp, "closed": true },
                "params": { "floor_layers": floor },
            })
            .to_string(),
        )
        .unwrap();
        crate::slice(&d).unwrap()
    }

    #[test]
    fn a_cylinder_is_a_helix_over_a_floor_of_rings() {
        let s = cup(30.0, 40.0, 2);
        let t = &s.toolpath;
        let v = t.vessel.as_ref().unwrap();
        // 40 mm: 2 floor layers of 1.25 mm, then 30 turns of 1.25 mm.
        assert_eq!((v.floor_layers, v.turns), (2, 30));
        // Rings 2.55 mm apart inside a base ring of radius 30.
        assert_eq!(v.floor_rings, 11);
        let wall: Vec<&PathPoint> = t
            .points
            .iter()
            .filter(|p| p.kind == PointKind::Pass && p.pos[2] > 2.5 + 1e-9)
            .collect();
        let per_turn = s.corrected.surface.columns.len() as f64;
        for w in wall.windows(2) {
            let (a, b) = (w[0].pos, w[1].pos);
            // On the cylinder (the polygon's points are within 0.01 mm)...
            assert!((a[0].hypot(a[1]) - 30.0).abs() < 0.02, "{a:?}");
            // ... rising one pitch a turn: 1.25 mm over the loop.
            let rise = b[2] - a[2];
            assert!((rise - 1.25 / per_turn).abs() < 1e-9, "{rise}");
        }
        let top = wall.last().unwrap().pos[2];
        assert!((top - 40.0).abs() < 1e-9, "the spiral ends on the rim");
        // The rim turn is level with the rim.
        for p in t.points.iter().filter(|p| p.kind == PointKind::Top) {
            assert!((p.pos[2] - 40.0).abs() < 1e-9);
        }
    }

    #[test]
    fn the_floor_covers_the_inside_of_the_loop() {
        for r in [12.0, 30.0, 55.0] {
            let s = cup(r, 20.0, 1);
            let t = &s.toolpath;
            // Each floor bead covers the pitch across and the spacing
            // along; the base ring covers half a pitch inward.
            let pitch = 3.0 * (1.0 - FLOOR_OVERLAP);
            let floor: f64 = t
                .points
                .windows(2)
                .filter(|w| w[1].kind == PointKind::Floor && w[0].kind == PointKind::Floor)
                .map(|w| {
                    let (a, b) = (w[0].pos, w[1].pos);
                    (a[0] - b[0])
                        .hypot(a[1] - b[1])
                        .min(2.0 * s.corrected.surface.spacing)
                })
                .sum::<f64>()
                * pitch;
            let base = std::f64::consts::TAU * r * pitch / 2.0;
            let inside = std::f64::consts::PI * r * r;
            let covered = (floor + base) / inside;
            assert!((covered - 1.0).abs() < 0.02, "r = {r}: {covered}");
            // Every point inside lies under a bead: within half a bead
            // width of a floor or base-ring point (points 1.1 mm apart).
            let beads: Vec<[f64; 3]> = t
                .points
                .iter()
                .filter(|p| p.pos[2] < 1.3)
                .map(|p| p.pos)
                .collect();
            let (mut inside, mut under) = (0, 0);
            for gx in -60..=60 {
                for gy in -60..=60 {
                    let q = [gx as f64, gy as f64];
                    if q[0].hypot(q[1]) > r {
                        continue;
                    }
                    inside += 1;
                    let reach = 1.5f64.hypot(0.55);
                    if beads.iter().any(|b| d2(*b, q) <= reach * reach) {
                        under += 1;
                    }
                }
            }
            assert!(
                under as f64 >= 0.98 * inside as f64,
                "r = {r}: {under} of {inside}"
            );
        }
    }

    #[test]
    fn a_bottomless_vessel_stands_on_one_ring() {
        let s = cup(30.0, 20.0, 0);
        let t = &s.toolpath;
        assert!(t.points.iter().all(|p| p.kind != PointKind::Floor));
        assert_eq!(t.vessel.as_ref().unwrap().floor_rings, 0);
        assert_eq!(t.points[0].pos[2], 1.25);
    }

    #[test]
    fn the_base_ring_closes_at_its_own_height() {
        for floor in [0, 2] {
            let s = cup(30.0, 20.0, floor);
            let (t, e) = (&s.toolpath, &s.extrusion);
            let z_base = 1.25 * f64::from(floor.max(1));
            // The spiral's first point, barely above the base ring...
            let i = t
                .points
                .iter()
                .position(|p| p.pos[2] > z_base + 1e-9)
                .unwrap();
            // ... comes after the ring's first point again, at the ring's
            // height, so the ring's closing bead is a whole ring bead.
            let (close, ring) = (&t.points[i - 1], &t.points[i - 2]);
            assert_eq!(close.pos[2], z_base);
            assert_eq!(e.layer_height[i - 1], 1.25);
            let per_mm = |k: usize| {
                let (a, b) = (t.points[k - 1].pos, t.points[k].pos);
                e.volume[k] / (a[0] - b[0]).hypot(a[1] - b[1])
            };
            assert!((per_mm(i - 1) - per_mm(i - 2)).abs() < 1e-6 * per_mm(i - 2));
            assert_eq!(ring.pos[2], z_base);
            // From there the spiral only rises.
            let (a, b) = (close.pos, t.points[i].pos);
            assert!((a[0] - b[0]).hypot(a[1] - b[1]) < 1e-9, "{a:?} {b:?}");
        }
    }

    #[test]
    fn spiral_heights_rise_one_layer_a_turn() {
        let p = Params::default();
        let v = VesselPlan::choose(&[50.0; 10], &p, 2).unwrap();
        // 47.5 mm above the floor in 38 turns of 1.25 mm.
        assert_eq!((v.base_layers, v.turns), (2, 38));
        assert!((v.spiral_z(1, 9, 10, 50.0) - 3.75).abs() < 1e-12);
        assert!((v.spiral_z(38, 9, 10, 50.0) - 50.0).abs() < 1e-12);
        assert!((v.spiral_z(2, 0, 10, 50.0) - v.spiral_z(1, 0, 10, 50.0) - 1.25).abs() < 1e-12);
    }

    #[test]
    fn uneven_rims_spread_over_the_turns_or_are_refused() {
        let p = Params::default();
        let v = VesselPlan::choose(&[40.0, 55.0, 60.0], &p, 2).unwrap();
        assert!(
            v.turn_mm[0] >= 1.25 - 1e-9 && v.turn_mm[1] <= 2.5 + 1e-9,
            "{v:?}"
        );
        // 28 mm of rim against 30 − 1 − 2.5 = 26.5 mm of clearance.
        let e = VesselPlan::choose(&[40.0, 68.0], &p, 2)
            .unwrap_err()
            .to_string();
        assert!(e.contains("varies by 28.0 mm"), "{e}");
        let tight = Params {
            max_layer_height: 1.3,
            nozzle_height: 40.0,
            ..Params::default()
        };
        let e = VesselPlan::choose(&[20.0, 30.0], &tight, 2)
            .unwrap_err()
            .to_string();
        assert!(e.contains("no whole number of spiral turns"), "{e}");
    }
}
