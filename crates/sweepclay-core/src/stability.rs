//! Whether the wet piece stands (not in the paper, which leaves
//! "mechanical constraints" open in §6; docs/ALGORITHMS.md §9). Two
//! warnings, never failures, each saying where:
//!
//! - **Topple.** At every layer, the clay above it must have its centre
//!   of mass over the clay it stands on: within the convex hull of that
//!   layer's path, widened by half its beads' width. Otherwise the part
//!   above leans off its support and the wet clay tips or tears there.
//! - **Slender.** A piece taller than [`SLENDER`] times the narrowest
//!   dimension of its first layer's footprint (the short side of its
//!   smallest enclosing rectangle, bead width included) sways and sags
//!   while wet, however well its layers sit.
//!
//! One pass over the path weighs the bands and keeps each band's farthest
//! points in eight directions, whose octagon lies inside the band's hull:
//! a centre of mass inside it needs no hull. A second pass gathers the
//! points outside their octagon of the bands that need a hull (the first,
//! for its footprint, and those the octagon cannot answer for), and only
//! those hulls are built (Graham's scan): linear in the path's points but
//! for those few hulls.

use crate::extrude::Extrusion;
use crate::toolpath::Toolpath;
use geo::convex_hull::graham_hull;
use geo::{Coord, Distance, Euclidean, MinimumRotatedRect, Point, Polygon, Simplify};

/// How many times its narrowest base dimension a piece may be tall before
/// it is warned of as slender: a rule of thumb for wet clay, which a
/// thrown cylinder also keeps (a potter's tall vase is about 3–4 × its
/// foot).
pub const SLENDER: f64 = 5.0;

/// The clay of one band: its mass moment, its path in plan and its
/// beads' mean width.
#[derive(Default)]
struct Band {
    volume: f64,
    moment: [f64; 2],
    /// Points of the band that may be corners of its hull, gathered only
    /// for the bands whose hull is needed.
    points: Vec<Coord<f64>>,
    count: usize,
    /// The farthest points along x, x + y, y, −x + y, −x, … (45° apart):
    /// an octagon inside the band's hull, which answers most questions
    /// without the hull.
    far: [(f64, [f64; 2]); 8],
    width_sum: f64,
    z: f64,
}

impl Band {
    /// Whether `c` lies inside the octagon of the farthest points (so
    /// inside the hull), by more than `margin` of cross product.
    fn inside(&self, c: [f64; 2], margin: f64) -> bool {
        (0..8).all(|k| {
            let (a, b) = (self.far[k].1, self.far[(k + 1) % 8].1);
            (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) >= margin
        })
    }

    /// Inside the octagon or on it: inside the hull.
    fn surely_holds(&self, c: [f64; 2]) -> bool {
        self.inside(c, 0.0)
    }

    /// Strictly inside the octagon: no corner of the hull.
    fn strictly_holds(&self, c: [f64; 2]) -> bool {
        self.inside(c, 1e-9)
    }
}

/// The stability warnings of a sliced path, weighed in horizontal bands
/// `band` mm high: the thickest layer, so that every column reaching a
/// band has a point in it (a tilted pass crosses the bands; a band as
/// thin as the thinnest layer would hold only some columns of it).
pub fn warnings(t: &Toolpath, e: &Extrusion, band: f64) -> Vec<String> {
    let mut out = Vec::new();
    let Some(top) = t.points.iter().map(|p| p.pos[2]).reduce(f64::max) else {
        return out;
    };
    let layer = band.max(0.1);
    let bins = ((top / layer).ceil() as usize).clamp(1, 1 << 16);
    // The clay of the move ending at a point lies at its height.
    let band_of = |z: f64| ((z / layer).ceil() as usize).clamp(1, bins) - 1;
    let mut layers: Vec<Band> = (0..bins)
        .map(|_| Band {
            far: [(f64::NEG_INFINITY, [0.0; 2]); 8],
            ..Band::default()
        })
        .collect();
    // First pass: weigh the bands and find their octagons.
    for (i, p) in t.points.iter().enumerate() {
        let l = &mut layers[band_of(p.pos[2])];
        let v = e.volume.get(i).copied().unwrap_or(0.0);
        l.volume += v;
        l.moment[0] += v * p.pos[0];
        l.moment[1] += v * p.pos[1];
        // Along x, x + y, y, y − x, −x, … (45° apart, counter-clockwise;
        // unnormalised, which changes no maximum), without multiplying.
        let (x, y) = (p.pos[0], p.pos[1]);
        let along = [x, x + y, y, y - x, -x, -x - y, -y, x - y];
        for (f, a) in l.far.iter_mut().zip(along) {
            if a > f.0 {
                *f = (a, [x, y]);
            }
        }
        l.width_sum += e.width.get(i).copied().unwrap_or(0.0);
        l.count += 1;
        l.z = l.z.max(p.pos[2]);
    }
    // From the top down, the centre of mass of the clay above each band;
    // the bands whose octagon cannot say it stands over them need their
    // hull, as does the first (for its footprint).
    let (mut vol, mut mom) = (0.0, [0.0, 0.0]);
    let mut above = vec![None; bins];
    for b in (0..bins.saturating_sub(1)).rev() {
        let l = &layers[b + 1];
        vol += l.volume;
        mom[0] += l.moment[0];
        mom[1] += l.moment[1];
        let c = [mom[0] / vol, mom[1] / vol];
        if vol > 0.0 && layers[b].count > 0 && !layers[b].surely_holds(c) {
            above[b] = Some(c);
        }
    }
    let needs = |b: usize| b == 0 || above[b].is_some();
    // Second pass: the points of those bands, but those strictly inside
    // their octagon, which are no hull's corners (Akl and Toussaint).
    for p in &t.points {
        let b = band_of(p.pos[2]);
        if needs(b) && !layers[b].strictly_holds([p.pos[0], p.pos[1]]) {
            layers[b].points.push(Coord {
                x: p.pos[0],
                y: p.pos[1],
            });
        }
    }
    // A band's hull (Graham's scan, `geo`'s) and its mean bead width.
    let hull = |l: &mut Band| -> Option<(Polygon<f64>, f64)> {
        (l.count > 0 && !l.points.is_empty()).then(|| {
            let ring = graham_hull(&mut l.points, false);
            (Polygon::new(ring, vec![]), l.width_sum / l.count as f64)
        })
    };
    // Topple: the clay above a band off its hull.
    let mut off: Option<(f64, f64, f64)> = None; // lowest z, highest z, worst mm
    for b in (0..bins).rev() {
        let Some(c) = above[b] else {
            continue;
        };
        let Some((poly, w)) = hull(&mut layers[b]) else {
            continue;
        };
        let beyond = Euclidean.distance(&Point::new(c[0], c[1]), &poly) - w / 2.0;
        if beyond > 0.0 {
            let z = layers[b].z;
            off = Some(match off {
                None => (z, z, beyond),
                Some((lo, hi, worst)) => (lo.min(z), hi.max(z), worst.max(beyond)),
            });
        }
    }
    if let Some((lo, hi, worst)) = off {
        out.push(format!(
            "may topple while wet: from z = {lo:.1} to {hi:.1} mm the clay above lies off the layer it stands on (its centre of mass up to {worst:.1} mm beyond that layer's edge); lean it less, or widen it below"
        ));
    }
    // Slender: the height against the first band's footprint.
    if let Some((poly, w)) = hull(&mut layers[0]) {
        // The hull simplified to within 0.05 mm first: a finely sampled
        // curve gives it thousands of corners, and the rectangle's search
        // is quadratic in them.
        let narrow = poly
            .simplify(0.05)
            .minimum_rotated_rect()
            .map(|r| {
                let c: Vec<_> = r.exterior().points().collect();
                let side = |a: usize, b: usize| {
                    let d = c[a] - c[b];
                    d.x().hypot(d.y())
                };
                side(0, 1).min(side(1, 2))
            })
            .unwrap_or(0.0)
            + w;
        if top > SLENDER * narrow {
            out.push(format!(
                "slender: {top:.0} mm tall on a base {narrow:.0} mm across at its narrowest, {:.1} × (more than {SLENDER} ×): wet clay may sway or sag; widen the base or print it lower",
                top / narrow
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use crate::{slice, Design};

    fn wall(lean_deg: f64, height: f64) -> Vec<String> {
        // A straight wall along x, 60 mm long, its profiles leaning
        // sideways (normal offset) by `lean_deg` from vertical.
        let top = height * lean_deg.to_radians().tan();
        let d = Design::from_json(&format!(
            r#"{{"sweepclay":1,
                "profile_start":{{"control_points":[[0,0],[{top},{height}]]}},
                "profile_end":{{"control_points":[[0,0],[{top},{height}]]}},
                "trajectory":{{"control_points":[[-30,0],[30,0]],"offset":"normal"}}}}"#
        ))
        .unwrap();
        slice(&d).unwrap().stats.warnings
    }

    /// The heights of "from z = A to B mm" in a topple warning.
    fn span(w: &str) -> (f64, f64) {
        let nums: Vec<f64> = w
            .split(|c: char| !(c.is_ascii_digit() || c == '.'))
            .filter_map(|s| s.parse().ok())
            .collect();
        (nums[0], nums[1])
    }

    #[test]
    fn a_leaning_wall_topples_where_the_clay_above_leaves_its_layer() {
        // Leaning 30°, layers of 1.25 mm up to H = 40, 3 mm beads: the
        // clay above a layer at z has its centre of mass at the mean of
        // the layers above, (z + 1.25 + H)/2 · tan 30° sideways; the layer
        // at z lies at z · tan 30° ± 1.5 mm. Off it while z < H + 1.25 −
        // 3 / tan 30° = 36.05 mm: the last band weighed (2.5 mm high) that
        // tops out below that is the one that says so.
        let w = wall(30.0, 40.0);
        let topple: Vec<_> = w.iter().filter(|w| w.contains("topple")).collect();
        assert_eq!(topple.len(), 1, "{w:?}");
        let (lo, hi) = span(topple[0]);
        let edge = 40.0 + 1.25 - 3.0 / 30f64.to_radians().tan();
        assert!(lo <= 2.5, "{lo}");
        assert!(hi < edge && hi > edge - 2.5, "{hi} {edge}");
        // Lower than 3 / tan 30° = 5.2 mm it stands.
        assert!(!wall(30.0, 5.0).iter().any(|w| w.contains("topple")));
    }

    #[test]
    fn a_straight_thin_wall_is_slender_and_a_cylinder_stands() {
        // Upright: nothing topples, but 40 mm on a 3 mm base is slender.
        let w = wall(0.0, 40.0);
        assert!(!w.iter().any(|w| w.contains("topple")), "{w:?}");
        assert!(w.iter().any(|w| w.contains("slender")), "{w:?}");
        assert!(wall(0.0, 14.0).is_empty());
        // A cylinder 60 mm across and 60 mm tall, upright: no warning.
        let ring: Vec<String> = (0..48)
            .map(|k| {
                let a = std::f64::consts::TAU * f64::from(k) / 48.0;
                format!("[{:.5},{:.5}]", 30.0 * a.cos(), 30.0 * a.sin())
            })
            .collect();
        let d = Design::from_json(&format!(
            r#"{{"sweepclay":1,"profile_start":{{"control_points":[[0,0],[0,60]]}},
                "profile_end":{{"control_points":[[0,0],[0,60]]}},
                "trajectory":{{"points":[{}],"closed":true}}}}"#,
            ring.join(",")
        ))
        .unwrap();
        let st = slice(&d).unwrap().stats;
        assert!(st.warnings.is_empty(), "{:?}", st.warnings);
    }
}
