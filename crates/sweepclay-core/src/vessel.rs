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
}

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
        })
    }

    /// The height of spiral turn `k` (1-based) at column `i` of `n`, whose
    /// rim is `h` (mm).
    pub fn spiral_z(&self, k: u32, i: usize, n: usize, h: f64) -> f64 {
        let base = self.base_mm();
        let d = (h - base) / f64::from(self.turns);
        base + (f64::from(k - 1) + (i + 1) as f64 / n as f64) * d
    }

    /// Whether column `i` of `n` gets a rim bead: where the last turn ends
    /// at least half a layer below the rim (a thinner bead is no bead, as
    /// for the top-edge beads of a wall; the rim is then level to within
    /// half a layer).
    pub fn has_rim(&self, i: usize, n: usize, h: f64) -> bool {
        h - self.spiral_z(self.turns, i, n, h) >= 0.5 * self.base_layer_mm - 1e-9
    }

    /// The first column where the extruder body would meet clay already
    /// laid (docs/ALGORITHMS.md §8): for every pair of columns `i`, `j`
    /// within `reach` in plan, the turn below at `j` (or, more than
    /// `exempt` columns back along the loop, this turn at `j`) must not
    /// stand more than [`BODY_GRAZE_MM`] above the nozzle at `i`. Checked
    /// at the turns where the difference is largest (it is linear in the
    /// turn). `points` are the columns in plan, `h` their rims.
    pub fn body_violation(
        &self,
        points: &[[f64; 2]],
        h: &[f64],
        reach: f64,
        exempt: usize,
    ) -> Option<(usize, f64)> {
        let n = points.len();
        let mut grid = crate::grid::Grid2::new(reach.max(1e-3));
        for (i, p) in points.iter().enumerate() {
            grid.insert_segment(*p, *p, i as u32);
        }
        let turns = [1.max(self.turns.min(2)), self.turns];
        let mut worst: Option<(usize, f64)> = None;
        for (i, p) in points.iter().enumerate() {
            grid.for_each_near_segment(*p, *p, reach, |j| {
                let j = j as usize;
                let q = points[j];
                if (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) > reach * reach || j == i {
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
                    let back = (i + n - j) % n;
                    let same = if j < i && back > exempt {
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

/// Clay this little above the nozzle tip, near the edge of the extruder
/// body, is a graze on a bead's rounded edge (as the checker allows).
pub const BODY_GRAZE_MM: f64 = 0.2;

/// The concentric rings that fill a closed polygon `outer` (the base ring,
/// counter-clockwise or not) inside it: offsets inward by `pitch`, 2 ·
/// `pitch`, … until nothing is left, each resampled about `spacing` apart
/// and turned the way `outer` turns. An offset that splits (a waist
/// narrower than two beads) gives several rings at one depth; they follow
/// each other outermost first.
pub fn floor_rings(outer: &[[f64; 2]], pitch: f64, spacing: f64) -> Vec<Vec<[f64; 2]>> {
    let ccw = signed_area2(outer) > 0.0;
    let mut contour: Vec<[f64; 2]> = outer.to_vec();
    if !ccw {
        contour.reverse();
    }
    let mut rings = Vec::new();
    for depth in 1..=MAX_FLOOR_RINGS {
        let style = OutlineStyle::new(-pitch * depth as f64).line_join(LineJoin::Round(0.25));
        let shapes = contour.outline(&style);
        let mut found = false;
        for shape in &shapes {
            // The first contour of a shape is its outside; an inward
            // offset of a simple polygon has no holes.
            let Some(ring) = shape.first() else { continue };
            let mut ring = resample_loop(ring, spacing);
            if ring.len() < 3 {
                continue;
            }
            if !ccw {
                ring.reverse();
            }
            rings.push(ring);
            found = true;
        }
        if !found {
            break;
        }
    }
    rings
}

/// A closed polygon resampled into points about `spacing` apart (at least
/// three when it is longer than a few spacings, none when it is a speck).
fn resample_loop(poly: &[[f64; 2]], spacing: f64) -> Vec<[f64; 2]> {
    let mut closed = poly.to_vec();
    closed.push(poly[0]);
    let cum = crate::curves::arc_lengths(&closed);
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
    let rings = if v.floor_layers > 0 {
        floor_rings(&base_ring, pitch, s.spacing)
    } else {
        Vec::new()
    };
    // Where each ring is entered: nearest the previous ring's entry,
    // the first nearest column 0 (where the base ring starts).
    let mut entry = Vec::with_capacity(rings.len());
    let mut at = s.position(0, s.columns[0].first as usize);
    for r in &rings {
        let e = nearest(r, at);
        entry.push(e);
        at = [r[e][0], r[e][1], 0.0];
    }
    let floor_points: usize = rings.iter().map(Vec::len).sum();
    let total = s.samples.len() + floor_points * v.floor_layers as usize;
    let mut points = Vec::with_capacity(total);
    let mut below = Vec::with_capacity(total);
    // Path index of each column's samples, and of each floor ring's points
    // on the layer below.
    let mut path_of = vec![u32::MAX; s.samples.len()];
    let mut ring_below: Vec<Vec<u32>> = rings.iter().map(|r| vec![u32::MAX; r.len()]).collect();
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
    let base = v.base_layers;
    for layer in 1..=base {
        let z = f64::from(layer) * v.base_layer_mm;
        let local = layer as usize - 1;
        // The last base layer runs outward, the one before inward, …
        let outward = (base - layer).is_multiple_of(2);
        let mut floor = |points: &mut Vec<PathPoint>, below: &mut Vec<Option<u32>>, r: usize| {
            let ring = &rings[r];
            for step in 0..ring.len() {
                let j = (entry[r] + step) % ring.len();
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
        let floor_here = layer <= v.floor_layers;
        if outward {
            if floor_here {
                for r in (0..rings.len()).rev() {
                    floor(&mut points, &mut below, r);
                }
            }
            for i in 0..n {
                visit_column(
                    &mut points,
                    &mut below,
                    &mut path_of,
                    i,
                    local,
                    layer,
                    PointKind::Pass,
                );
            }
        } else {
            for i in 0..n {
                visit_column(
                    &mut points,
                    &mut below,
                    &mut path_of,
                    i,
                    local,
                    layer,
                    PointKind::Pass,
                );
            }
            if floor_here {
                for r in 0..rings.len() {
                    floor(&mut points, &mut below, r);
                }
            }
        }
    }
    for k in 1..=v.turns {
        for i in 0..n {
            let local = (base + k) as usize - 1;
            visit_column(
                &mut points,
                &mut below,
                &mut path_of,
                i,
                local,
                base + k,
                PointKind::Pass,
            );
        }
    }
    let rim = base + v.turns + 1;
    for i in 0..n {
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
    let floor_area = rings.first().map_or(0.0, |_| ring_area(&base_ring));
    Toolpath {
        points,
        below,
        passes: rim,
        stages: 1,
        returning_points: 0,
        vessel: Some(VesselPath {
            floor_layers: v.floor_layers,
            floor_rings: rings.len() as u32,
            floor_points: (floor_points * v.floor_layers as usize) as u32,
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
    /// Points of the floor's inner rings, all layers.
    pub floor_points: u32,
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
        // Radii 30 − 2.55 k down to the last ring longer than 3.3 mm.
        assert_eq!(rings.len(), 11, "{}", rings.len());
        for (k, ring) in rings.iter().enumerate() {
            let want = 30.0 - 2.55 * (k + 1) as f64;
            for p in ring {
                assert!((p[0].hypot(p[1]) - want).abs() < 0.05, "ring {k}: {p:?}");
            }
        }
    }

    #[test]
    fn rings_turn_the_way_the_outline_turns() {
        let mut cw = circle(20.0, 100);
        cw.reverse();
        for ring in floor_rings(&cw, 2.55, 1.1) {
            assert!(signed_area2(&ring) < 0.0);
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
