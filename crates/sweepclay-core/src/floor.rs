//! Floor fill: a closed region in, one spiral bead path that fills it out
//! (vessels' floors; not in the paper, docs/ALGORITHMS.md §8). Knows
//! nothing of profiles, layers or G-code.
//!
//! The region is the inside of a closed polygon (the wall's centre line
//! where it stands on the floor). Every polygon point sends a straight
//! *ray* inward to a *spine*: a segment along the region's long axis
//! (a point for a round region), chosen so that the rays are as even in
//! length as can be (an ellipse's spine runs between its ends' centres of
//! curvature, making every ray about as long as its half width). The
//! spiral visits the rays in turn, moving inward along each by one turn's
//! share of its length every turn (Held & Spielberger's contour-parallel
//! spiral, with the rays instead of offset curves blending one turn into
//! the next): neighbouring turns lie about one pitch apart, nothing
//! closes on itself, and the spiral ends half a pitch from the spine, so
//! the beads beside the spine cover it.
//!
//! The outermost turn runs from half a pitch outside the polygon to half
//! a pitch inside: the wall's first turn, standing on the polygon, then
//! has a floor bead within half a pitch of its middle all round, and
//! rests on it with more than half its width.
//!
//! Each bead is as wide as its neighbours' mean distance needs for them
//! to touch with [`FLOOR_OVERLAP`], within `[width, widest]`. A region so
//! uneven that some turns would come closer than [`MIN_GAP`] pitches
//! while others part further than the widest bead covers is refused
//! ([`FloorRefusal`]); so is a region narrower than a bead.
//!
//! Limitations: the rays are straight, so a region whose long axis bends
//! (a deep kidney) or that pinches at a waist narrower than about half its
//! widest part is refused rather than filled by connected Fermat spirals.

use crate::grid::Grid2;
use crate::plane::{closest_on_segment as project, signed_area2};

pub use crate::design::FLOOR_OVERLAP;

/// The closest two neighbouring turns may come, in pitches: a little
/// nearer than a pitch is clay pressed a little wider, not a bead on a
/// bead.
pub const MIN_GAP: f64 = 0.85;

/// Where the outermost turn starts, in pitches outside the polygon (it
/// ends one pitch further in, half a pitch inside).
pub const OUTER_START: f64 = 0.5;

/// Most turns a floor may have (a floor 5 m across at 3 mm beads, far
/// beyond any printer; the sample cap refuses such designs first): bounds
/// the work.
pub const MAX_FLOOR_TURNS: usize = 1000;

/// The bead sizes a floor is laid with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FloorBeads {
    /// Narrowest floor bead (mm): the design's `width_min`.
    pub width: f64,
    /// Distance between the points of the outermost turn (mm).
    pub spacing: f64,
    /// Widest floor bead (mm): the design's `width_max`.
    pub widest: f64,
}

impl FloorBeads {
    /// The distance between neighbouring turns: beads `width` wide
    /// touching with [`FLOOR_OVERLAP`] (mm).
    pub fn pitch(&self) -> f64 {
        self.width * (1.0 - FLOOR_OVERLAP)
    }

    /// The farthest apart two turns may lie: beads `widest` wide still
    /// touching with [`FLOOR_OVERLAP`] (mm).
    pub fn widest_gap(&self) -> f64 {
        self.widest * (1.0 - FLOOR_OVERLAP)
    }
}

/// One floor layer's path, from the polygon inward.
#[derive(Clone, Debug, PartialEq)]
pub struct FloorSpiral {
    /// The points, outermost first (the first near polygon point 0).
    pub pts: Vec<[f64; 2]>,
    /// Bead width at each point (mm).
    pub widths: Vec<f64>,
    /// Turns round the spine.
    pub turns: u32,
    /// Closest (mm) any two neighbouring turns come.
    pub min_gap: f64,
    /// Farthest (mm) any two neighbouring turns part.
    pub max_gap: f64,
}

/// Why a region cannot be filled by one spiral.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FloorRefusal {
    /// The region is narrower than a bead somewhere it would need a turn.
    TooNarrow {
        /// Its narrowest half width from the spine (mm).
        half_width: f64,
    },
    /// No spine keeps the turns between [`MIN_GAP`] pitches and the
    /// widest bead's reach: the region pinches or bends too much.
    Uneven {
        /// Where the turns come too close or part too far.
        at: [f64; 2],
        /// The turns' gap there (mm).
        gap: f64,
        /// The least (`MIN_GAP` pitches) and most (widest bead) gap (mm).
        allowed: [f64; 2],
    },
}

impl std::fmt::Display for FloorRefusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            FloorRefusal::TooNarrow { half_width } => write!(
                f,
                "the floor is too narrow for a spiral: {:.1} mm from its middle to its edge at the narrowest, less than a bead",
                half_width
            ),
            FloorRefusal::Uneven { at, gap, allowed } => write!(
                f,
                "no single spiral fills the floor evenly: near ({:.1}, {:.1}) mm its turns would lie {gap:.1} mm apart, outside {:.1}–{:.1} mm (the floor pinches at a waist or bends too much for one spiral)",
                at[0], at[1], allowed[0], allowed[1]
            ),
        }
    }
}

/// Fills the inside of the closed polygon `outer` (any orientation; its
/// point 0 is where the spiral starts) with one spiral, outermost turn
/// first, running against the polygon's order (so the same path reversed,
/// run outward, ends at point 0 heading along the polygon's order).
pub fn spiral_floor(outer: &[[f64; 2]], beads: FloorBeads) -> Result<FloorSpiral, FloorRefusal> {
    spiral_floor_covering(outer, beads, MIN_COVER, true)
}

/// [`spiral_floor`], taking the spiral that covers most of the region
/// whenever it covers at least `min_cover` of it (0: any spiral whose
/// turns keep their distance; the path stage lays the best there is
/// where the corrections bent the outline after sampling checked it).
/// `flush`: try stepped rings whose outermost lies on the outline first
/// (a flush foot); else only the turns blended from half a pitch outside.
pub fn spiral_floor_covering(
    outer: &[[f64; 2]],
    beads: FloorBeads,
    min_cover: f64,
    flush: bool,
) -> Result<FloorSpiral, FloorRefusal> {
    let n = outer.len();
    let pitch = beads.pitch();
    if n < 3 || signed_area2(outer).abs() < 1e-9 {
        return Err(FloorRefusal::TooNarrow { half_width: 0.0 });
    }
    let mut last_refusal = FloorRefusal::TooNarrow { half_width: 0.0 };
    let mut best: Option<(f64, Measured)> = None;
    // Keeps a spiral whose turns keep their distance; whether it covers
    // enough to stop looking.
    let consider = |m: Measured, best: &mut Option<(f64, Measured)>| {
        if m.closest.1 < MIN_GAP * pitch {
            return false;
        }
        let cover = coverage(outer, &m.spiral, 1.0);
        let enough = cover >= min_cover.max(MIN_COVER);
        if best.as_ref().is_none_or(|(c, _)| cover > *c) {
            *best = Some((cover, m));
        }
        enough
    };
    // Offsets of the outline, one pitch apart, blended into a spiral:
    // exact spacing along straight sides and into corners; unusable where
    // the offsets split. Then the rays to each candidate spine, nearest
    // and along the normals: a region that pinches at a waist.
    // First stepped rings, the outermost on the outline (a flush foot),
    // stepping in over a short step, then over a longer one should the
    // short one's turns come too close; then the offsets blended over
    // whole turns, the outermost from half a pitch outside the outline.
    // The inner steps' length is tried again longer where the first cuts
    // the spiral short: neighbouring turns' steps lie about the least gap
    // apart, and which side of it turns on a fraction of a millimetre
    // (a cone leaning 46° from its foot kept 555 of 1,364 mm).
    let steps = INNER_STEP_WIDTHS
        .iter()
        .flat_map(|&inner| STEP_WIDTHS.map(|outer| Step { outer, inner }.times(beads.width)));
    let covers = |best: &Option<(f64, Measured)>, share: f64| {
        best.as_ref().is_some_and(|(c, _)| *c >= share)
    };
    // The rays to each candidate spine, nearest and along the normals,
    // found once and only if the rings' steps do not serve.
    let ray_families = std::cell::OnceCell::new();
    let families = || {
        ray_families.get_or_init(|| {
            spines(outer)
                .into_iter()
                .flat_map(|spine| [rays_to(outer, spine), normal_rays_to(outer, spine)])
                .collect::<Vec<Vec<Ray>>>()
        })
    };
    if flush {
        // The offsets cost most (i_overlay): the rings on the outline
        // serve every step length.
        if let Some(rings) = offset_rings(outer, beads, 0.0) {
            for step in steps {
                let Some(m) = offset_spiral(outer, beads, &rings, Some(step)) else {
                    continue;
                };
                // The steps differ only in their length: once one keeps
                // its turns apart, the others cover the same.
                let kept = m.closest.1 >= MIN_GAP * pitch;
                if consider(m, &mut best) && covers(&best, WHOLE) {
                    return Ok(best.expect("just kept").1.spiral);
                }
                if kept {
                    break;
                }
            }
        }
        // Where the rings' steps did not serve (an elongated oval's
        // offsets end in thin lenses whose sides meet, and the walk is cut
        // there), the rays to a spine are stepped the same way: flush at
        // the foot.
        if !covers(&best, FLUSH_ENOUGH) {
            for rays in families() {
                for outer_step in STEP_WIDTHS {
                    let step = Step {
                        outer: outer_step,
                        inner: INNER_STEP_WIDTHS[0],
                    };
                    if let Some(m) = ray_floor(rays, beads, Some(step.times(beads.width))) {
                        consider(m, &mut best);
                    }
                }
            }
        }
    }
    // A flush spiral that covers nearly all is kept over a blended one
    // that covers a little more.
    if covers(&best, FLUSH_ENOUGH) {
        return Ok(best.expect("just kept").1.spiral);
    }
    // An offset spiral ends round its last offset: a thin lens there (an
    // oval's) stays bare, a hole under 1 % of the floor. Where it covers
    // less than all, the rays, which close over their spine, are tried
    // too.
    let blended =
        offset_rings(outer, beads, OUTER_START).and_then(|r| offset_spiral(outer, beads, &r, None));
    if let Some(m) = blended {
        if consider(m, &mut best) && covers(&best, WHOLE) {
            return Ok(best.expect("just kept").1.spiral);
        }
    }
    for rays in families() {
        let Some(m) = ray_floor(rays, beads, None) else {
            let half_width = rays.iter().map(|r| r.len).fold(f64::INFINITY, f64::min);
            last_refusal = FloorRefusal::TooNarrow { half_width };
            continue;
        };
        if consider(m, &mut best) && covers(&best, WHOLE) {
            return Ok(best.expect("just kept").1.spiral);
        }
    }
    match best {
        Some((cover, m)) if cover >= min_cover => Ok(m.spiral),
        Some((_, m)) => Err(FloorRefusal::Uneven {
            at: m.farthest.0,
            gap: m.farthest.1,
            allowed: [MIN_GAP * pitch, beads.widest_gap()],
        }),
        None => Err(last_refusal),
    }
}

/// How long the outermost ring's step to the next ring is, in bead
/// widths, tried in turn: neighbouring steps' diagonals lie a pitch apart
/// radially, a little less square to them (docs/ALGORITHMS.md §8). The
/// short step keeps the notch it leaves at the foot short.
pub const STEP_WIDTHS: [f64; 2] = [1.5, 3.0];

/// How long the inner rings' steps are, in bead widths, tried in turn:
/// on small rings and an oval's sharp ends a short step spans much of
/// the turn, and the turns met across the jogs (docs/ALGORITHMS.md §8).
pub const INNER_STEP_WIDTHS: [f64; 2] = [3.0, 4.0];

/// A stepped spiral's step lengths (mm, or bead widths before `times`):
/// the outermost ring's and the inner rings'.
#[derive(Clone, Copy, Debug)]
struct Step {
    outer: f64,
    inner: f64,
}

impl Step {
    /// Turn k's step: the outermost's, the inner ones' at least as long.
    fn of_turn(self, k: usize) -> f64 {
        if k == 0 {
            self.outer
        } else {
            self.outer.max(self.inner)
        }
    }

    fn times(self, k: f64) -> Step {
        Step {
            outer: self.outer * k,
            inner: self.inner * k,
        }
    }
}

/// How far a widened step bead reaches inward, in pitches: short of the
/// next turn's middle.
const STEP_REACH: f64 = 0.95;

/// The least share of the floor a spiral must cover.
pub const MIN_COVER: f64 = 0.97;

/// The share of the floor a flush (stepped) spiral must cover to be laid
/// without looking further: the foot shows on every piece, while the
/// slit an oval's last ring leaves along its middle (0.27 % of a
/// 50 × 35 mm oval, which the blended spiral covers) lies within the 3 %
/// a floor may leave bare (docs/ALGORITHMS.md §8).
pub const FLUSH_ENOUGH: f64 = 0.995;

/// A share of the floor that counts as all of it (on the 1 mm grid the
/// cover is measured on): a spiral that covers it ends the search.
const WHOLE: f64 = 0.999;

/// The inward offsets of `outer` a pitch apart, the outermost
/// `outer_start` pitches outside it (0: on it, for stepped rings), each
/// against the outline's order, as the spiral runs. `None` where the
/// offsets split into islands, or fewer than two fit.
fn offset_rings(
    outer: &[[f64; 2]],
    beads: FloorBeads,
    outer_start: f64,
) -> Option<Vec<Vec<[f64; 2]>>> {
    let pitch = beads.pitch();
    let ccw = signed_area2(outer) > 0.0;
    // Points closer than 0.45 of the floor's spacing add offsetting work,
    // not shape.
    let thin_to = (0.45 * beads.spacing).max(0.3);
    let mut base = spaced(outer, thin_to);
    if !ccw {
        base.reverse();
    }
    let fine = (0.4 * beads.spacing).max(0.2);
    let mut rings: Vec<Vec<[f64; 2]>> = Vec::new();
    // Each offset from the one before, a pitch in (i_overlay's cost grows
    // with the depth), that one thinned like the outline: offsets
    // of offsets gain points at every concave turn, doubling each time
    // (a kidney's 13th had 29,000 and took 9 s).
    let mut last = base.clone();
    for k in 0..MAX_FLOOR_TURNS {
        let (from, d) = match k {
            0 => (&base, -outer_start * pitch),
            1 => (&base, (1.0 - outer_start) * pitch),
            _ => (&last, pitch),
        };
        // Nothing is left of the last offset shrunk by a pitch more than
        // its inradius (at most twice its area over its perimeter), next
        // to nothing if by nearly that: asking i_overlay for such an offset
        // costs it a thousand times an ordinary one. The last offset's
        // turn winds in toward its centroid instead.
        let perimeter = (0..from.len())
            .map(|i| dist(from[i], from[(i + 1) % from.len()]))
            .sum::<f64>();
        if k > 1 && pitch + 0.25 * pitch >= 2.0 * ring_area(from) / perimeter.max(1e-12) {
            break;
        }
        let mut parts: Vec<Vec<[f64; 2]>> = offset(from, d)
            .into_iter()
            .filter(|c| ring_area(c) >= 0.25 * pitch * pitch)
            .collect();
        if parts.len() > 1 {
            return None;
        }
        let Some(mut ring) = parts.pop() else {
            break;
        };
        if signed_area2(&ring) < 0.0 {
            ring.reverse();
        }
        if k > 0 {
            last = spaced(&ring, thin_to);
        }
        // Against the outline's order, as the ray spiral runs.
        if ccw {
            ring.reverse();
        }
        rings.push(densified(&ring, fine));
    }
    (rings.len() >= 2).then_some(rings)
}

/// The offsets of [`offset_rings`] walked into one spiral (Held &
/// Spielberger): each point of ring k moves toward its nearest point on
/// ring k + 1 by the share of the turn done (blended), or of the ring's
/// last `step.outer` mm (stepped; the inner rings' over their last
/// `step.inner` mm at least), so turn k ends where turn k + 1 begins. The
/// last ring winds in toward its centroid, and the spiral ends before it
/// would come within [`MIN_GAP`] pitches of its own earlier turns.
fn offset_spiral(
    outer: &[[f64; 2]],
    beads: FloorBeads,
    rings: &[Vec<[f64; 2]>],
    step: Option<Step>,
) -> Option<Measured> {
    let pitch = beads.pitch();
    let turns = rings.len();
    let mut pts = Vec::new();
    let mut turn_of = Vec::new();
    let mut entry = nearest_on(&rings[0], outer[0]).1;
    for k in 0..turns {
        let ring = rotated(&rings[k], entry);
        let next = rings.get(k + 1);
        // Walking along the next offset as this one is walked: the
        // nearest point moves on monotonically, a few segments a point.
        // Started where the blend starts: a stepped ring's points before
        // its step need no goal (the walk was most of a floor's time).
        let mut walker: Option<Walker> = None;
        let c = centroid(&ring);
        let total = perimeter(&ring);
        // Stepped, each ring goes over to the next over its last `step`
        // mm (the inner ones over a longer step: a short one on a small
        // ring spans much of its turn and cut the spiral short): the
        // outermost lies on the outline all round but there. (The
        // same share of each ring instead measured gaps of 1.9 pitches
        // across the jogs, which lie end to end.)
        let blend = match step {
            Some(s) => s.of_turn(k),
            None => total,
        }
        .min(total);
        let mut acc = 0.0;
        for (j, &a) in ring.iter().enumerate() {
            if j > 0 {
                acc += dist(a, ring[j - 1]);
            }
            let sigma = ((acc - (total - blend)) / blend).clamp(0.0, 1.0);
            if sigma == 0.0 {
                pts.push(a);
                turn_of.push(k as u32);
                continue;
            }
            let goal = match next {
                Some(r) => walker
                    .get_or_insert_with(|| Walker {
                        at: nearest_on(r, a).0,
                        ring: r,
                    })
                    .nearest(a),
                None => {
                    let d = dist(a, c);
                    let step = pitch.min(d);
                    [
                        a[0] + (c[0] - a[0]) * step / d.max(1e-12),
                        a[1] + (c[1] - a[1]) * step / d.max(1e-12),
                    ]
                }
            };
            pts.push([
                a[0] + sigma * (goal[0] - a[0]),
                a[1] + sigma * (goal[1] - a[1]),
            ]);
            turn_of.push(k as u32);
        }
        if let Some(r) = next {
            entry = nearest_on(r, ring[0]).1;
        }
    }
    thin(&mut pts, &mut turn_of, 0.6 * beads.spacing);
    let walked = path_length(&pts);
    truncate_where_close(&mut pts, &mut turn_of, MIN_GAP * pitch, 2.5 * pitch);
    // A floor's area is its path's length times the pitch: a stepped
    // spiral cut short by more than the hole allowed cannot be kept, and
    // measuring it cost as much as walking it.
    if pts.len() < 2 || (step.is_some() && path_length(&pts) < MIN_COVER * walked) {
        return None;
    }
    Some(measure_widened(
        pts,
        turn_of,
        turns,
        beads,
        step.map(|_| outer),
    ))
}

/// Where the outermost turn steps in to the next, its beads widen to
/// keep their outer edge on the outline's (up to the widest bead): the
/// wall's first turn above rests on them all round (docs/ALGORITHMS.md
/// §8). `deep`: each point of the outermost turn, its depth inside the
/// outline and its distance from the next turn's middle.
fn widen_steps(m: &mut Measured, deep: Vec<(usize, f64, f64)>, beads: FloorBeads) {
    // A bead's inner edge stops short of the next turn's middle: a wider
    // bead would lie under that turn, on clay of its own layer. Nor does
    // any bead, widened to touch its inner neighbour, reach past the
    // outline's outer edge: a ledge at the foot. The next turn's middle
    // is measured, not taken as a pitch in: where the step begins it
    // lies up to 1.5 pitches in, and a bead capped at a pitch left a
    // notch 0.4 mm deep in the foot at every seam.
    for (i, depth, next) in deep {
        let cap = beads.widest.min(2.0 * STEP_REACH * next);
        let flush = beads.width + 2.0 * depth;
        let w = &mut m.spiral.widths[i];
        *w = w.max(flush.min(cap)).min(flush);
    }
}

/// The points of the outermost turn with their distance inside the
/// outline (0 on it; more on its step to the next ring) and from the
/// next turn's middle (at most two pitches is looked for).
fn outermost_depths(
    pts: &[[f64; 2]],
    turn_of: &[u32],
    outer: &[[f64; 2]],
    beads: FloorBeads,
) -> Vec<(usize, f64, f64)> {
    let pitch = beads.pitch();
    let mut grid = Grid2::new(pitch.max(1.0));
    let n = outer.len();
    for i in 0..n {
        grid.insert_segment(outer[i], outer[(i + 1) % n], i as u32);
    }
    let mut second = Grid2::new(pitch.max(1.0));
    for i in 1..pts.len() {
        if turn_of[i - 1] == 1 && turn_of[i] == 1 {
            second.insert_segment(pts[i - 1], pts[i], i as u32);
        }
    }
    let mut out = vec![];
    for (i, &p) in pts.iter().enumerate().take_while(|&(i, _)| turn_of[i] == 0) {
        let mut depth = f64::INFINITY;
        grid.for_each_near_segment(p, p, 1.5 * pitch, |j| {
            let j = j as usize;
            depth = depth.min(segment_distance(p, outer[j], outer[(j + 1) % n]));
        });
        if !depth.is_finite() {
            continue;
        }
        let mut next = 2.0 * pitch;
        second.for_each_near_segment(p, p, 2.0 * pitch, |j| {
            let j = j as usize;
            next = next.min(segment_distance(p, pts[j - 1], pts[j]));
        });
        out.push((i, depth, next.max(pitch)));
    }
    out
}

/// The contours of a counter-clockwise closed contour offset inward by
/// `d` (outward where negative): none when nothing is left, several
/// where it splits.
pub(crate) fn offset(contour: &[[f64; 2]], d: f64) -> Vec<Vec<[f64; 2]>> {
    use i_overlay::mesh::outline::offset::OutlineOffset;
    use i_overlay::mesh::style::{LineJoin, OutlineStyle};
    // Round where the outline grows (its convex corners), bevelled where
    // it shrinks (only concave ones get joins there).
    let join = if d < 0.0 {
        LineJoin::Round(0.2)
    } else {
        LineJoin::Bevel
    };
    let style = OutlineStyle::new(-d).line_join(join);
    // The first contour of a shape is its outside.
    contour
        .outline(&style)
        .into_iter()
        .filter_map(|shape| shape.into_iter().next())
        .collect()
}

/// A closed ring without the points nearer than `gap` to the last one
/// kept (its first point kept).
fn spaced(ring: &[[f64; 2]], gap: f64) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = Vec::with_capacity(ring.len());
    for &p in ring {
        if out.last().is_none_or(|&q| dist(p, q) >= gap) {
            out.push(p);
        }
    }
    if out.len() < 3 {
        return ring.to_vec();
    }
    out
}

/// A closed ring with points added so none is farther than `step` from
/// the next.
fn densified(ring: &[[f64; 2]], step: f64) -> Vec<[f64; 2]> {
    let n = ring.len();
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let (a, b) = (ring[i], ring[(i + 1) % n]);
        let k = (dist(a, b) / step).ceil().max(1.0) as usize;
        for j in 0..k {
            let t = j as f64 / k as f64;
            out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
        }
    }
    out
}

/// The closed ring starting at `p` (which lies on it), in the same order.
fn rotated(ring: &[[f64; 2]], p: [f64; 2]) -> Vec<[f64; 2]> {
    let (seg, _) = nearest_on(ring, p);
    let n = ring.len();
    let mut out = Vec::with_capacity(n + 2);
    out.push(p);
    for j in 1..=n {
        let q = ring[(seg + j) % n];
        if j < n || dist(q, p) > 1e-9 {
            out.push(q);
        }
    }
    // Closed: the turn ends where it began.
    out.push(p);
    out
}

/// The segment of a closed ring nearest `p`, and the nearest point on it.
fn nearest_on(ring: &[[f64; 2]], p: [f64; 2]) -> (usize, [f64; 2]) {
    let n = ring.len();
    let mut best = (0, ring[0], f64::INFINITY);
    for i in 0..n {
        let (a, b) = (ring[i], ring[(i + 1) % n]);
        let q = project(p, a, b);
        let d = dist(p, q);
        if d < best.2 {
            best = (i, q, d);
        }
    }
    (best.0, best.1)
}

/// The nearest point of a closed ring to points that move along beside
/// it: each look-up searches a window of segments from the last one.
struct Walker<'a> {
    ring: &'a [[f64; 2]],
    at: usize,
}

impl Walker<'_> {
    /// Segments searched ahead of the last nearest one (and a few behind):
    /// more than a bevel of an offset spans for one point of the ring
    /// outside it.
    const AHEAD: usize = 64;

    fn nearest(&mut self, p: [f64; 2]) -> [f64; 2] {
        let n = self.ring.len();
        let mut best = (f64::INFINITY, self.at, p);
        for k in 0..Self::AHEAD.min(n) {
            let i = (self.at + n + k - 4.min(n)) % n;
            let q = project(p, self.ring[i], self.ring[(i + 1) % n]);
            let d = dist(p, q);
            if d < best.0 {
                best = (d, i, q);
            }
        }
        self.at = best.1;
        best.2
    }
}

/// Drops points nearer than `keep` to the last one kept (not the last).
fn thin(pts: &mut Vec<[f64; 2]>, turn_of: &mut Vec<u32>, keep: f64) {
    let mut out = Vec::with_capacity(pts.len());
    let mut turns = Vec::with_capacity(pts.len());
    for (i, &p) in pts.iter().enumerate() {
        let last = i + 1 == pts.len();
        if last || out.last().is_none_or(|&q| dist(p, q) >= keep) {
            out.push(p);
            turns.push(turn_of[i]);
        }
    }
    *pts = out;
    *turn_of = turns;
}

/// Ends the path before its first point within `gap` of an earlier point
/// more than `local` mm of path before it.
fn truncate_where_close(pts: &mut Vec<[f64; 2]>, turn_of: &mut Vec<u32>, gap: f64, local: f64) {
    let mut grid = Grid2::new(gap.max(1e-3));
    let mut arc = Vec::with_capacity(pts.len());
    let mut acc = 0.0;
    for i in 0..pts.len() {
        if i > 0 {
            acc += dist(pts[i], pts[i - 1]);
        }
        arc.push(acc);
        let p = pts[i];
        let mut close = false;
        grid.for_each_near_segment(p, p, gap, |j| {
            let j = j as usize;
            close |= arc[i] - arc[j] > local && dist(p, pts[j]) < gap;
        });
        if close {
            pts.truncate(i);
            turn_of.truncate(i);
            return;
        }
        grid.insert_segment(p, p, i as u32);
    }
}

/// The length of (x, y): a square root, not `f64::hypot`, whose guard
/// against overflow took half the floor's time (coordinates here are
/// millimetres, far from overflow).
fn norm(x: f64, y: f64) -> f64 {
    (x * x + y * y).sqrt()
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    norm(a[0] - b[0], a[1] - b[1])
}

/// The length of an open path.
fn path_length(pts: &[[f64; 2]]) -> f64 {
    pts.windows(2).map(|w| dist(w[0], w[1])).sum()
}

/// The length of a ring given with its first point again at its end
/// (never 0: it divides).
fn perimeter(ring: &[[f64; 2]]) -> f64 {
    path_length(ring).max(1e-12)
}

/// A ray from a polygon point inward to its foot on the spine.
#[derive(Clone, Copy, Debug)]
struct Ray {
    from: [f64; 2],
    /// Unit direction, inward.
    dir: [f64; 2],
    len: f64,
    /// The cosine between the ray and the polygon's inward normal (at
    /// least 0.3).
    cos: f64,
}

/// Candidate spines, the most even first: segments along the region's
/// principal axis through points near its centroid, of lengths that make
/// the rays to them most nearly equal.
fn spines(outer: &[[f64; 2]]) -> Vec<[[f64; 2]; 2]> {
    let c = centroid(outer);
    let n = outer.len() as f64;
    let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
    for p in outer {
        let (x, y) = (p[0] - c[0], p[1] - c[1]);
        sxx += x * x;
        syy += y * y;
        sxy += x * y;
    }
    let angle = 0.5 * (2.0 * sxy / n).atan2((sxx - syy) / n);
    let e1 = [angle.cos(), angle.sin()];
    let e2 = [-e1[1], e1[0]];
    let proj = |p: [f64; 2], e: [f64; 2]| (p[0] - c[0]) * e[0] + (p[1] - c[1]) * e[1];
    let (mut a0, mut a1, mut b0, mut b1) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for &p in outer {
        a0 = a0.min(proj(p, e1));
        a1 = a1.max(proj(p, e1));
        b0 = b0.min(proj(p, e2));
        b1 = b1.max(proj(p, e2));
    }
    let mid_a = 0.5 * (a0 + a1);
    let mid_b = 0.5 * (b0 + b1);
    let (half_a, half_b) = (0.5 * (a1 - a0), 0.5 * (b1 - b0));
    let mut scored = Vec::new();
    for ia in 0..5 {
        let ca = mid_a + (ia as f64 - 2.0) * 0.08 * half_a;
        for ib in 0..5 {
            let cb = mid_b + (ib as f64 - 2.0) * 0.08 * half_b;
            for il in 0..=16 {
                let half = (half_a - half_b).max(0.0) * il as f64 / 12.0;
                let centre = [
                    c[0] + ca * e1[0] + cb * e2[0],
                    c[1] + ca * e1[1] + cb * e2[1],
                ];
                let spine = [
                    [centre[0] - half * e1[0], centre[1] - half * e1[1]],
                    [centre[0] + half * e1[0], centre[1] + half * e1[1]],
                ];
                let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
                for &p in outer {
                    let l = dist(p, project(p, spine[0], spine[1]));
                    lo = lo.min(l);
                    hi = hi.max(l);
                }
                if lo <= 0.0 {
                    continue;
                }
                scored.push((hi / lo, spine));
            }
        }
    }
    scored.sort_by(|a, b| a.0.total_cmp(&b.0));
    scored.truncate(3);
    scored.into_iter().map(|(_, s)| s).collect()
}

/// The unit inward normal of closed polygon `outer` at point `i`, from
/// its neighbours' chord (`sign`: 1 counter-clockwise, −1 clockwise).
fn inward_normal(outer: &[[f64; 2]], i: usize, sign: f64) -> [f64; 2] {
    let n = outer.len();
    let (a, b) = (outer[(i + n - 1) % n], outer[(i + 1) % n]);
    let t = [b[0] - a[0], b[1] - a[1]];
    let tl = norm(t[0], t[1]).max(1e-12);
    [-t[1] * sign / tl, t[0] * sign / tl]
}

/// The orientation sign [`inward_normal`] takes.
fn turning(outer: &[[f64; 2]]) -> f64 {
    if signed_area2(outer) > 0.0 {
        1.0
    } else {
        -1.0
    }
}

/// A ray from `from` to `foot`, its cosine with the inward `normal`.
fn ray(from: [f64; 2], foot: [f64; 2], normal: [f64; 2]) -> Ray {
    let d = [foot[0] - from[0], foot[1] - from[1]];
    let len = norm(d[0], d[1]);
    let dir = if len > 0.0 {
        [d[0] / len, d[1] / len]
    } else {
        [0.0, 0.0]
    };
    Ray {
        from,
        dir,
        len,
        cos: (dir[0] * normal[0] + dir[1] * normal[1]).max(0.3),
    }
}

/// The rays from each polygon point to its nearest point on the spine.
fn rays_to(outer: &[[f64; 2]], spine: [[f64; 2]; 2]) -> Vec<Ray> {
    let sign = turning(outer);
    outer
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            ray(
                p,
                project(p, spine[0], spine[1]),
                inward_normal(outer, i, sign),
            )
        })
        .collect()
}

/// The rays from each polygon point along its inward normal to where
/// that meets the spine (clamped to the spine's ends; the nearest point
/// where the normal runs along the spine or away from it): straight
/// normals keep neighbouring turns square to the outline a pitch apart
/// where a region pinches at a waist, where rays to the nearest point of
/// the spine slant across the turns.
fn normal_rays_to(outer: &[[f64; 2]], spine: [[f64; 2]; 2]) -> Vec<Ray> {
    let sign = turning(outer);
    let [a, b] = spine;
    let e = [b[0] - a[0], b[1] - a[1]];
    let el = norm(e[0], e[1]);
    outer
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            let normal = inward_normal(outer, i, sign);
            // p + s·normal = a + w·e, for s and w; the nearest point where
            // the spine is a point, or the normal runs along it or away.
            let det = normal[0] * (-e[1]) - normal[1] * (-e[0]);
            let d = [a[0] - p[0], a[1] - p[1]];
            let along = (d[0] * (-e[1]) - d[1] * (-e[0])) / det;
            let foot = if el < 1e-9 || det.abs() < 1e-9 * el || along <= 0.0 {
                project(p, a, b)
            } else {
                let w = ((normal[0] * d[1] - normal[1] * d[0]) / det).clamp(0.0, 1.0);
                [a[0] + w * e[0], a[1] + w * e[1]]
            };
            if dist(p, foot) < 1e-9 {
                return ray(p, project(p, a, b), normal);
            }
            ray(p, foot, normal)
        })
        .collect()
}

/// A spiral with its gaps measured.
struct Measured {
    spiral: FloorSpiral,
    closest: ([f64; 2], f64),
    farthest: ([f64; 2], f64),
}

/// The spiral of `turns` turns along `rays`, its points thinned to about
/// the outer turn's spacing, its gaps and widths measured.
/// `outline`: the rays' feet, where a stepped spiral's outermost turn
/// lies.
fn measure(
    rays: &[Ray],
    turns: usize,
    beads: FloorBeads,
    step: Option<Step>,
    outline: Option<&[[f64; 2]]>,
) -> Measured {
    let (pts, turn_of) = ray_spiral(rays, turns, beads, step);
    measure_widened(pts, turn_of, turns + 1, beads, outline)
}

/// [`measure_path`], the outermost turn's step beads widened to keep
/// their outer edge on the outline's where a stepped spiral's outermost
/// turn lies on it (`outline` given).
fn measure_widened(
    pts: Vec<[f64; 2]>,
    turn_of: Vec<u32>,
    turns: usize,
    beads: FloorBeads,
    outline: Option<&[[f64; 2]]>,
) -> Measured {
    let deep = match outline {
        Some(o) => outermost_depths(&pts, &turn_of, o, beads),
        None => vec![],
    };
    let mut m = measure_path(pts, turn_of, turns, beads);
    widen_steps(&mut m, deep, beads);
    m
}

/// The spiral along `rays` of the most turns whose closest neighbours
/// keep [`MIN_GAP`] pitches apart; none where a ray is shorter than a
/// pitch.
fn ray_floor(rays: &[Ray], beads: FloorBeads, step: Option<Step>) -> Option<Measured> {
    let pitch = beads.pitch();
    // A stepped walk's last step runs along the rays by the wall's start:
    // slanting there (round a spine's end), it ends a bead or more along
    // the wall from where it began, and the wall's first beads rested on
    // less than half their width (docs/ALGORITHMS.md §8).
    if let Some(st) = step {
        // The step runs over rays 1, 2, … up to ray 0 (the walk visits
        // them against the polygon's order).
        let mut along = 0.0;
        for w in rays.windows(2) {
            if w[0].cos < SQUARE_STEP {
                return None;
            }
            along += dist(w[0].from, w[1].from);
            if along > st.outer + beads.width {
                break;
            }
        }
    }
    let span = |r: &Ray| r.len + (OUTER_START - 0.5) * pitch;
    let short = rays.iter().map(span).fold(f64::INFINITY, f64::min);
    if short < pitch {
        return None;
    }
    let outline: Option<Vec<[f64; 2]>> = step.map(|_| rays.iter().map(|r| r.from).collect());
    let mut turns = ((short / pitch).floor() as usize).clamp(1, MAX_FLOOR_TURNS);
    loop {
        let m = measure(rays, turns, beads, step, outline.as_deref());
        if m.closest.1 < MIN_GAP * pitch && turns > 1 {
            turns -= 1;
            continue;
        }
        return Some(m);
    }
}

/// The least cosine between a ray and the wall's normal along a stepped
/// walk's last step.
const SQUARE_STEP: f64 = 0.95;

/// The points of the spiral of `turns` turns along `rays`, thinned to
/// about the outer turn's spacing, and the turn of each. Blended (no
/// `step`), each turn moves in along the rays as it goes round; stepped,
/// each lies at one depth all round but its last `step` mm (the
/// outermost on the outline: a flush foot), as [`offset_spiral`]'s rings
/// do, and the rays still carry it in to their spine.
fn ray_spiral(
    rays: &[Ray],
    turns: usize,
    beads: FloorBeads,
    step: Option<Step>,
) -> (Vec<[f64; 2]>, Vec<u32>) {
    let n = rays.len();
    let pitch = beads.pitch();
    let keep = 0.6 * beads.spacing;
    // Turn k's depth along a ray before its step (stepped), and the share
    // of the turn its step takes: its length over the turn's.
    let depth = |r: &Ray, k: usize| {
        let first = pitch / r.cos;
        let end = r.len - 0.5 * pitch;
        match k {
            0 => 0.0,
            _ if turns == 1 => end,
            _ => first + (k - 1) as f64 * (end - first) / (turns - 1) as f64,
        }
    };
    let shares: Vec<f64> = match step {
        None => vec![],
        Some(st) => (0..turns)
            .map(|k| {
                let at = |j: usize| {
                    let r = &rays[j % n];
                    let d = depth(r, k);
                    [r.from[0] + d * r.dir[0], r.from[1] + d * r.dir[1]]
                };
                let length: f64 = (0..n).map(|j| dist(at(j), at(j + 1))).sum();
                (st.of_turn(k) / length.max(1e-9)).min(1.0)
            })
            .collect(),
    };
    let mut pts: Vec<[f64; 2]> = Vec::with_capacity(n * turns / 2 + 2);
    let mut turn_of: Vec<u32> = Vec::with_capacity(pts.capacity());
    let total = turns * n;
    for at in 0..=total {
        let (k, j) = (at / n, at % n);
        // Against the polygon's order: ray 0, n − 1, n − 2, …
        let r = &rays[(n - j) % n];
        let sigma = j as f64 / n as f64;
        // The outermost turn runs from OUTER_START pitches outside the
        // polygon to one pitch further in, measured square to it (the
        // wall stands on it); the others share the rest of the ray.
        let first = pitch / r.cos;
        let start = -OUTER_START * first;
        let end = r.len - 0.5 * pitch;
        let s = if let Some(&q) = shares.get(k) {
            let ramp = ((sigma - (1.0 - q)) / q).clamp(0.0, 1.0);
            let (here, next) = (
                depth(r, k),
                if k + 1 < turns { depth(r, k + 1) } else { end },
            );
            here + ramp * (next - here)
        } else if step.is_some() {
            // The last point, where the closing half turn begins.
            end
        } else if k == 0 || turns == 1 {
            start + sigma * first
        } else {
            start + first + (k as f64 - 1.0 + sigma) * (end - start - first) / (turns - 1) as f64
        };
        let p = [r.from[0] + s * r.dir[0], r.from[1] + s * r.dir[1]];
        let far_enough = pts
            .last()
            .is_none_or(|q| norm(p[0] - q[0], p[1] - q[1]) >= keep);
        if far_enough || at == total {
            pts.push(p);
            turn_of.push(k as u32);
        }
    }
    // The last turn lies a turn's share farther from the spine where it
    // began than where it ends: along a spine (an oval's, a peanut's) its
    // two sides were a pitch and a turn apart, a slit no bead covers.
    // Half a pitch from the spine, the path goes on round until it would
    // come near the last turn.
    let before = pts.len();
    for j in 1..n {
        let r = &rays[(n - j) % n];
        let s = r.len - 0.5 * pitch;
        let p = [r.from[0] + s * r.dir[0], r.from[1] + s * r.dir[1]];
        if pts
            .last()
            .is_none_or(|q| norm(p[0] - q[0], p[1] - q[1]) >= keep)
        {
            pts.push(p);
            turn_of.push(turns as u32);
        }
    }
    if pts.len() > before {
        truncate_where_close(&mut pts, &mut turn_of, MIN_GAP * pitch, 2.5 * pitch);
    }
    (pts, turn_of)
}

/// A spiral's gaps and widths measured: each point's nearest clay on
/// either side, beyond the stretch of path it belongs to.
fn measure_path(
    pts: Vec<[f64; 2]>,
    turn_of: Vec<u32>,
    turns: usize,
    beads: FloorBeads,
) -> Measured {
    let pitch = beads.pitch();
    // Each point's nearest clay on either side, beyond the stretch of
    // path it belongs to: its neighbouring turns (or, beside the spine,
    // the far side of its own turn).
    let mut arc = Vec::with_capacity(pts.len());
    let mut acc = 0.0;
    for (i, p) in pts.iter().enumerate() {
        if i > 0 {
            acc += norm(p[0] - pts[i - 1][0], p[1] - pts[i - 1][1]);
        }
        arc.push(acc);
    }
    // A neighbouring turn farther than the widest bead covers is a gap
    // the cover measure finds; looking no farther keeps this linear with
    // a small constant.
    let reach = 1.25 * beads.widest_gap();
    let mut grid = Grid2::new(0.5 * reach);
    for (i, p) in pts.iter().enumerate() {
        grid.insert_segment(*p, *p, i as u32);
    }
    let local = 2.5 * pitch;
    let mut widths = Vec::with_capacity(pts.len());
    let mut closest = ([0.0, 0.0], f64::INFINITY);
    let mut farthest = ([0.0, 0.0], 0.0f64);
    for i in 0..pts.len() {
        let p = pts[i];
        let a = pts[i.saturating_sub(1)];
        let b = pts[(i + 1).min(pts.len() - 1)];
        let t = [b[0] - a[0], b[1] - a[1]];
        let tl = norm(t[0], t[1]).max(1e-12);
        // Squared distances: each side's nearest and the next turn's.
        let scan = |pad: f64| {
            let mut side = [f64::INFINITY; 2];
            let mut inward = f64::INFINITY;
            grid.for_each_near_segment(p, p, pad, |j| {
                let j = j as usize;
                if (arc[j] - arc[i]).abs() < local {
                    return;
                }
                let q = pts[j];
                let d = [q[0] - p[0], q[1] - p[1]];
                let d2 = d[0] * d[0] + d[1] * d[1];
                if turn_of[j] == turn_of[i] + 1 {
                    inward = inward.min(d2);
                }
                // Only what lies across the path, not ahead or behind.
                let along = (d[0] * t[0] + d[1] * t[1]) / tl;
                if along * along > 0.49 * d2 {
                    return;
                }
                let left = usize::from(t[0] * d[1] - t[1] * d[0] > 0.0);
                side[left] = side[left].min(d2);
            });
            (side.map(f64::sqrt), inward.sqrt())
        };
        // Most points have both neighbouring turns within a pitch and a
        // half: look farther only where one is missing.
        let near = 1.5 * pitch;
        let (mut side, mut inward) = scan(near);
        let innermost = turn_of[i] as usize + 1 >= turns;
        if side.iter().any(|g| !g.is_finite()) || (!inward.is_finite() && !innermost) {
            (side, inward) = scan(reach);
        }
        let mut gaps = [0.0; 2];
        let mut found = 0;
        for g in side.into_iter().filter(|g| g.is_finite()) {
            gaps[found] = g;
            found += 1;
            if g < closest.1 {
                closest = (p, g);
            }
        }
        let gaps = &gaps[..found];
        // How far the next turn in lies, measured once for each pair of
        // neighbouring turns (the outermost turn has nothing outside it,
        // the innermost the spine's far side).
        if inward.is_finite() && inward > farthest.1 && !innermost {
            farthest = (p, inward);
        }
        let gap = match gaps.len() {
            0 => pitch,
            1 => gaps[0].min(beads.widest_gap()),
            _ => 0.5 * (gaps[0].min(reach) + gaps[1].min(reach)),
        };
        widths.push((gap / (1.0 - FLOOR_OVERLAP)).clamp(beads.width, beads.widest));
    }
    Measured {
        spiral: FloorSpiral {
            pts,
            widths,
            turns: turns as u32,
            min_gap: closest.1,
            max_gap: farthest.1,
        },
        closest,
        farthest,
    }
}

/// The fraction of the inside of `outer` that the beads of `spiral` cover,
/// on a grid of `cell` mm (for tests and reports).
pub fn coverage(outer: &[[f64; 2]], spiral: &FloorSpiral, cell: f64) -> f64 {
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for p in outer {
        x0 = x0.min(p[0]);
        x1 = x1.max(p[0]);
        y0 = y0.min(p[1]);
        y1 = y1.max(p[1]);
    }
    let nx = (((x1 - x0) / cell).ceil() as usize).clamp(1, 1 << 14);
    let ny = (((y1 - y0) / cell).ceil() as usize).clamp(1, 1 << 14);
    let centre = |i: usize, j: usize| [x0 + (i as f64 + 0.5) * cell, y0 + (j as f64 + 0.5) * cell];
    // Each bead marks the cells whose centres it covers: linear in the
    // path, where asking every cell for its beads was not.
    let mut under = vec![false; nx * ny];
    for k in 1..spiral.pts.len() {
        let (a, b) = (spiral.pts[k - 1], spiral.pts[k]);
        let half = 0.25 * (spiral.widths[k - 1] + spiral.widths[k]);
        let cells = |lo: f64, hi: f64, o: f64, n: usize| {
            let first = (((lo - half - o) / cell - 0.5).ceil().max(0.0)) as usize;
            let last = (((hi + half - o) / cell - 0.5).floor().max(-1.0) + 1.0) as usize;
            first..last.min(n)
        };
        for j in cells(a[1].min(b[1]), a[1].max(b[1]), y0, ny) {
            for i in cells(a[0].min(b[0]), a[0].max(b[0]), x0, nx) {
                if !under[j * nx + i] && segment_distance(centre(i, j), a, b) <= half {
                    under[j * nx + i] = true;
                }
            }
        }
    }
    // The cells inside, row by row from where the outline crosses it.
    let (mut inside, mut covered) = (0usize, 0usize);
    let n = outer.len();
    let mut xs = Vec::new();
    for j in 0..ny {
        let y = centre(0, j)[1];
        xs.clear();
        for e in 0..n {
            let (a, b) = (outer[e], outer[(e + 1) % n]);
            if (a[1] > y) != (b[1] > y) {
                xs.push(a[0] + (y - a[1]) / (b[1] - a[1]) * (b[0] - a[0]));
            }
        }
        xs.sort_by(f64::total_cmp);
        for span in xs.chunks_exact(2) {
            let first = ((span[0] - x0) / cell - 0.5).ceil().max(0.0) as usize;
            let last = (((span[1] - x0) / cell - 0.5).floor() + 1.0).max(0.0) as usize;
            for i in first..last.min(nx) {
                inside += 1;
                covered += usize::from(under[j * nx + i]);
            }
        }
    }
    covered as f64 / inside.max(1) as f64
}

/// Distance from `p` to the segment `a`–`b`.
pub fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    dist(p, project(p, a, b))
}

/// The centroid of a closed polygon's area (its vertices' mean if it has
/// none).
pub fn centroid(pts: &[[f64; 2]]) -> [f64; 2] {
    let n = pts.len();
    let (mut cx, mut cy, mut a2) = (0.0, 0.0, 0.0);
    for i in 0..n {
        let (p, q) = (pts[i], pts[(i + 1) % n]);
        let cross = p[0] * q[1] - q[0] * p[1];
        a2 += cross;
        cx += (p[0] + q[0]) * cross;
        cy += (p[1] + q[1]) * cross;
    }
    if a2.abs() < 1e-12 {
        let k = n.max(1) as f64;
        return [
            pts.iter().map(|p| p[0]).sum::<f64>() / k,
            pts.iter().map(|p| p[1]).sum::<f64>() / k,
        ];
    }
    [cx / (3.0 * a2), cy / (3.0 * a2)]
}

/// The area inside a closed ring (mm²).
pub fn ring_area(ring: &[[f64; 2]]) -> f64 {
    0.5 * signed_area2(ring).abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    const BEADS: FloorBeads = FloorBeads {
        width: 3.0,
        spacing: 1.1,
        widest: 6.0,
    };

    fn ellipse(a: f64, b: f64, n: usize) -> Vec<[f64; 2]> {
        (0..n)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / n as f64;
                [a * t.cos(), b * t.sin()]
            })
            .collect()
    }

    fn length(s: &FloorSpiral) -> f64 {
        s.pts
            .windows(2)
            .map(|w| (w[0][0] - w[1][0]).hypot(w[0][1] - w[1][1]))
            .sum()
    }

    /// Whether any bead's middle lies on an earlier bead of the same layer
    /// (within half that bead's width, beyond the stretch it follows).
    fn lies_on_itself(s: &FloorSpiral) -> Option<usize> {
        let mut arc = vec![0.0];
        for w in s.pts.windows(2) {
            arc.push(arc.last().unwrap() + (w[0][0] - w[1][0]).hypot(w[0][1] - w[1][1]));
        }
        (1..s.pts.len()).find(|&i| {
            let mid = [
                0.5 * (s.pts[i - 1][0] + s.pts[i][0]),
                0.5 * (s.pts[i - 1][1] + s.pts[i][1]),
            ];
            (1..i).any(|j| {
                arc[i] - arc[j] > 2.0 * BEADS.widest
                    && segment_distance(mid, s.pts[j - 1], s.pts[j]) < 0.5 * s.widths[j]
            })
        })
    }

    #[test]
    fn a_circles_spiral_has_rings_a_pitch_apart_and_its_area_over_the_pitch_as_length() {
        let r = 40.0;
        let ring = ellipse(r, r, 228);
        let s = spiral_floor(&ring, BEADS).unwrap();
        let p = BEADS.pitch();
        // Rings a pitch apart from the outline itself in (the flush foot):
        // r / p turns, the last winding in to the centre.
        let whole = r / p;
        assert!(
            (f64::from(s.turns) - whole).abs() < 1.0,
            "{} turns, {whole:.2} expected",
            s.turns
        );
        // Neighbouring rings a pitch apart within 13 %; the outermost
        // steps in over 1.5 bead widths, the next over 3, so where the
        // outermost's step begins the next is already half way down its
        // own, 1.5 pitches away, which the beads there widen to fill.
        assert!(
            (s.min_gap - p).abs() < 0.13 * p && s.max_gap < 1.5 * p,
            "gaps {}–{} mm, expected {p:.3}",
            s.min_gap,
            s.max_gap
        );
        // Rings at r, r − p, … to the centre: Σ 2π (r − k p) over r / p
        // rings, π r (r / p + 1) (the area over the pitch, plus half the
        // outline: the outermost ring lies on it, not half a pitch in).
        let closed = std::f64::consts::PI * r * (r / p + 1.0);
        let l = length(&s);
        assert!(
            (l - closed).abs() < 0.03 * closed,
            "length {l:.1} mm, expected {closed:.1}"
        );
        assert_eq!(lies_on_itself(&s), None);
        let cover = coverage(&ring, &s, 0.25);
        assert!(cover > 0.995, "covered {cover}");
    }

    #[test]
    fn an_ellipse_is_covered_with_no_bead_on_its_own_layers_clay() {
        let ring = ellipse(50.0, 35.0, 300);
        let s = spiral_floor(&ring, BEADS).unwrap();
        let cover = coverage(&ring, &s, 0.25);
        assert!(cover >= 0.97, "covered {cover}");
        assert_eq!(lies_on_itself(&s), None);
        assert!(s.min_gap >= MIN_GAP * BEADS.pitch(), "{}", s.min_gap);
        assert!(s.widths.iter().all(|&w| (3.0..=6.0).contains(&w)));
    }

    /// A peanut: r = 40 (1 + cos(2θ)/2), 120 mm long, its lobes about
    /// 56 mm across and its waist 40 mm.
    fn peanut() -> Vec<[f64; 2]> {
        (0..320)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / 320.0;
                let r = 40.0 * (1.0 + 0.5 * (2.0 * t).cos());
                [r * t.cos(), r * t.sin()]
            })
            .collect()
    }

    #[test]
    fn a_peanut_is_covered_with_no_bead_on_its_own_layers_clay() {
        let ring = peanut();
        let s = spiral_floor(&ring, BEADS).unwrap();
        let cover = coverage(&ring, &s, 0.25);
        assert!(cover >= 0.97, "covered {cover}");
        assert_eq!(lies_on_itself(&s), None);
    }

    #[test]
    fn the_outermost_ring_is_the_outline_and_its_step_keeps_the_outer_edge() {
        let ring = ellipse(30.0, 30.0, 120);
        let s = spiral_floor(&ring, BEADS).unwrap();
        let p = BEADS.pitch();
        // On point 0 of the outline: the wall's first turn stands on it...
        let d = (s.pts[0][0] - 30.0).hypot(s.pts[0][1]);
        assert!(d < 0.01, "starts {d} mm out");
        // ... turning clockwise round a counter-clockwise polygon ...
        assert!(s.pts[1][1] < 0.0, "{:?}", s.pts[1]);
        // ... on the outline all round but its step to the next ring,
        // where its beads widen to keep their outer edge on the outline's
        // (short of the next ring's middle, a pitch in).
        let first = s
            .pts
            .iter()
            .take_while(|q| q[0].hypot(q[1]) > 30.0 - p + 0.05)
            .count();
        let outer_edge = |i: usize| s.pts[i][0].hypot(s.pts[i][1]) + 0.5 * s.widths[i];
        let on = (0..first)
            .filter(|&i| (s.pts[i][0].hypot(s.pts[i][1]) - 30.0).abs() < 0.05)
            .count();
        let around = std::f64::consts::TAU * 30.0;
        assert!(
            (first - on) as f64 * BEADS.spacing < STEP_WIDTHS[1] * BEADS.width + 1.0,
            "{} of {first} outermost points off the outline, {around:.0} mm round",
            first - on
        );
        let low = (0..first).map(outer_edge).fold(f64::INFINITY, f64::min);
        let flush = 30.0 + 0.5 * BEADS.width;
        // Flush but at the step's end, where the widest bead short of the
        // next ring (1.9 p) leaves its edge 1.9 p / 2 − p + w/2 inside.
        assert!(
            flush - low < 0.5 * BEADS.width,
            "outer edge {low:.2}, flush {flush:.2}"
        );
        // ... and ending within a pitch of the centre.
        let e = s.pts.last().unwrap();
        assert!(e[0].hypot(e[1]) < p, "{e:?}");
    }

    #[test]
    fn the_step_beads_widen_as_far_as_the_next_turn_lets_them() {
        // Where the outermost ring steps in, the next turn lies up to 1.5
        // pitches in; beads capped as if it lay a pitch in left the foot
        // notched more than 0.3 mm over 2.2 mm of the step (1.5 mm now:
        // its last points, where it meets the next turn's start).
        let ring = ellipse(38.56, 38.56, 240);
        let s = spiral_floor(&ring, BEADS).unwrap();
        let p = BEADS.pitch();
        let flush = 38.56 + 0.5 * BEADS.width;
        let outermost = s
            .pts
            .iter()
            .take_while(|q| q[0].hypot(q[1]) > 38.56 - p + 0.05)
            .count();
        let notched: f64 = (1..outermost)
            .filter(|&i| flush - (s.pts[i][0].hypot(s.pts[i][1]) + 0.5 * s.widths[i]) > 0.3)
            .map(|i| dist(s.pts[i], s.pts[i - 1]))
            .sum();
        assert!(notched < 1.8, "notched over {notched:.2} mm");
    }

    #[test]
    fn corners_kidneys_and_lobes_are_covered_with_no_bead_on_its_own_layers_clay() {
        let tau = std::f64::consts::TAU;
        let polygon = |k: usize, r: f64| -> Vec<[f64; 2]> {
            // Sampled along the sides, as the columns of a vessel are.
            let corners: Vec<[f64; 2]> = (0..k)
                .map(|i| {
                    [
                        r * (tau * i as f64 / k as f64).cos(),
                        r * (tau * i as f64 / k as f64).sin(),
                    ]
                })
                .collect();
            densified(&corners, 1.1)
        };
        let polar = |f: &dyn Fn(f64) -> f64| -> Vec<[f64; 2]> {
            (0..300)
                .map(|i| {
                    let t = tau * i as f64 / 300.0;
                    [f(t) * t.cos(), f(t) * t.sin()]
                })
                .collect()
        };
        let shapes: Vec<(&str, Vec<[f64; 2]>)> = vec![
            ("triangle", polygon(3, 45.0)),
            ("square", polygon(4, 40.0)),
            ("hexagon", polygon(6, 30.0)),
            (
                "kidney",
                polar(&|t| 40.0 * (1.0 - 0.3 * (-(t - 1.57f64).powi(2) / 0.3).exp())),
            ),
            ("lobes", polar(&|t| 35.0 * (1.0 + 0.15 * (5.0 * t).cos()))),
        ];
        for (name, ring) in shapes {
            let s = spiral_floor(&ring, BEADS).unwrap_or_else(|e| panic!("{name}: {e}"));
            let cover = coverage(&ring, &s, 0.25);
            assert!(cover >= 0.97, "{name}: covered {cover}");
            assert_eq!(lies_on_itself(&s), None, "{name}");
        }
    }

    #[test]
    fn a_sliver_is_refused_by_name() {
        let ring = ellipse(40.0, 1.0, 200);
        let e = spiral_floor(&ring, BEADS).unwrap_err();
        assert!(e.to_string().contains("too narrow"), "{e}");
    }
}
