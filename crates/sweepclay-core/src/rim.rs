//! A vessel's rim shaped round the loop (not in the paper; docs/FORMATS.md,
//! "rim"; docs/ALGORITHMS.md §8): the design's one profile carried on
//! above its top toward a taller rim — on one side (a slanted cut), in
//! waves, or over one raised arc (a pitcher's back, a spout); the body
//! below the profile's top keeps its shape. A potter shapes the
//! rim by how high it rises and toward where, not by a second profile and
//! an interpolation; the sampling reads, for each column, how far toward
//! the highest rim it is by the column's angle about o, and lays the
//! profile up to its top and its continuation above it
//! (`surface::continued`).

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// How the rim rises round the loop.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RimShape {
    /// Highest toward one angle, lowest opposite, in a cosine between: a
    /// slanted cut.
    Slant,
    /// `peaks` waves round the loop, one crest toward the angle.
    Wave,
    /// One raised arc `width_deg` wide centred on the angle, level
    /// elsewhere: a pitcher's back, a spout.
    Raised,
}

/// The `rim` of a design file (docs/FORMATS.md).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RimSpec {
    /// How the rim rises round the loop.
    pub shape: RimShape,
    /// How much taller the rim is where it is highest than the profile
    /// (mm).
    pub rise: f64,
    /// The angle about o, counter-clockwise from +x seen from above, the
    /// rim is highest toward (degrees).
    #[serde(default)]
    pub toward_deg: f64,
    /// A wave's crests round the loop.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peaks: Option<u32>,
    /// A raised arc's width about o (degrees; 120 if left out).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub width_deg: Option<f64>,
}

/// The most a rim may rise (mm): taller than any printer here.
pub const MAX_RISE_MM: f64 = 1000.0;

/// The most crests a wave may have.
pub const MAX_PEAKS: u32 = 12;

/// A raised arc's width where the file gives none (degrees).
pub const DEFAULT_WIDTH_DEG: f64 = 120.0;

impl RimSpec {
    /// Refuses a rim that cannot be read as one, naming the key: it
    /// shapes a vessel's rim (a closed trajectory) from its one profile,
    /// so it takes the place of `profile_end` and `interpolation`.
    pub fn check(&self, closed: bool, has_end: bool, has_interpolation: bool) -> Result<()> {
        if !closed {
            return Err(Error::invalid(
                "rim",
                "shapes a vessel's rim: it needs a closed trajectory (\"closed\": true)",
            ));
        }
        if has_end {
            return Err(Error::invalid(
                "rim",
                "stretches the one profile toward a taller rim: remove profile_end, or remove rim and shape the rim with the two profiles",
            ));
        }
        if has_interpolation {
            return Err(Error::invalid(
                "rim",
                "says how the rim rises round the loop itself: remove interpolation",
            ));
        }
        if !self.rise.is_finite() || !(0.0..=MAX_RISE_MM).contains(&self.rise) {
            return Err(Error::invalid(
                "rim.rise",
                format!("must be 0 to {MAX_RISE_MM} mm (got {})", self.rise),
            ));
        }
        if !self.toward_deg.is_finite() {
            return Err(Error::invalid(
                "rim.toward_deg",
                "must be a number of degrees",
            ));
        }
        match (self.shape, self.peaks, self.width_deg) {
            (RimShape::Wave, None, _) => Err(Error::invalid(
                "rim.peaks",
                format!("a wave needs its number of crests, 1 to {MAX_PEAKS}"),
            )),
            (RimShape::Wave, Some(k), _) if !(1..=MAX_PEAKS).contains(&k) => Err(Error::invalid(
                "rim.peaks",
                format!("must be 1 to {MAX_PEAKS} (got {k})"),
            )),
            (RimShape::Raised, _, Some(w)) if !(w.is_finite() && w > 0.0 && w <= 360.0) => {
                Err(Error::invalid(
                    "rim.width_deg",
                    format!("must be more than 0 and at most 360 degrees (got {w})"),
                ))
            }
            (RimShape::Slant | RimShape::Raised, Some(_), _) => Err(Error::invalid(
                "rim.peaks",
                "only a wave has crests: remove peaks, or set \"shape\": \"wave\"",
            )),
            (RimShape::Slant | RimShape::Wave, _, Some(_)) => Err(Error::invalid(
                "rim.width_deg",
                "only a raised arc has a width: remove width_deg, or set \"shape\": \"raised\"",
            )),
            _ => Ok(()),
        }
    }

    /// How far toward the highest rim a point of the loop is, 0 to 1, by
    /// its angle about o (`p` relative to o).
    pub fn lambda(&self, p: [f64; 2]) -> f64 {
        let off = p[1].atan2(p[0]) - self.toward_deg.to_radians();
        match self.shape {
            RimShape::Slant => 0.5 * (1.0 + off.cos()),
            RimShape::Wave => 0.5 * (1.0 + (f64::from(self.peaks.unwrap_or(1)) * off).cos()),
            RimShape::Raised => {
                let w = self.width_deg.unwrap_or(DEFAULT_WIDTH_DEG).to_radians();
                // The angle from the arc's middle, in (−π, π].
                let d = off.sin().atan2(off.cos());
                if d.abs() >= 0.5 * w {
                    0.0
                } else {
                    0.5 * (1.0 + (std::f64::consts::TAU * d / w).cos())
                }
            }
        }
    }

    /// The control points of a profile as tall as the rim where it is
    /// highest: the profile's `points` (`[x, z]`) stretched in height by
    /// its top's (h + rise) / h. It gives the columns their heights; their
    /// shape is the one profile carried on above its top
    /// (`surface::continued`).
    pub fn stretched(&self, points: &[[f64; 2]]) -> Vec<[f64; 2]> {
        let top = points.iter().map(|p| p[1]).fold(0.0, f64::max);
        let k = if top > 0.0 {
            (top + self.rise) / top
        } else {
            1.0
        };
        points.iter().map(|p| [p[0], p[1] * k]).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rim(shape: RimShape, toward: f64) -> RimSpec {
        RimSpec {
            shape,
            rise: 20.0,
            toward_deg: toward,
            peaks: None,
            width_deg: None,
        }
    }

    fn at(deg: f64) -> [f64; 2] {
        let a = deg.to_radians();
        [40.0 * a.cos(), 40.0 * a.sin()]
    }

    #[test]
    fn a_slant_is_highest_toward_its_angle_and_level_across() {
        let r = rim(RimShape::Slant, 90.0);
        assert!((r.lambda(at(90.0)) - 1.0).abs() < 1e-12);
        assert!(r.lambda(at(270.0)).abs() < 1e-12);
        // Half way between, half way up: (1 + cos 90°) / 2.
        assert!((r.lambda(at(0.0)) - 0.5).abs() < 1e-12);
        assert!((r.lambda(at(180.0)) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn a_wave_has_its_crests_evenly_round_from_its_angle() {
        let r = RimSpec {
            peaks: Some(3),
            ..rim(RimShape::Wave, 30.0)
        };
        for crest in [30.0, 150.0, 270.0] {
            assert!((r.lambda(at(crest)) - 1.0).abs() < 1e-12, "{crest}");
            assert!(r.lambda(at(crest + 60.0)).abs() < 1e-12, "{crest}");
        }
    }

    #[test]
    fn a_raised_arc_rises_within_its_width_only() {
        let r = RimSpec {
            width_deg: Some(90.0),
            ..rim(RimShape::Raised, 180.0)
        };
        assert!((r.lambda(at(180.0)) - 1.0).abs() < 1e-12);
        // A quarter of the width from the middle: (1 + cos 90°) / 2.
        assert!((r.lambda(at(180.0 + 22.5)) - 0.5).abs() < 1e-12);
        for outside in [0.0, 90.0, 134.0, 226.0, 300.0] {
            assert_eq!(r.lambda(at(outside)), 0.0, "{outside}");
        }
    }

    #[test]
    fn the_profile_is_stretched_to_the_taller_rim() {
        let start = [[0.0, 0.0], [8.0, 30.0], [2.0, 60.0]];
        let end = rim(RimShape::Slant, 0.0).stretched(&start);
        assert_eq!(end, vec![[0.0, 0.0], [8.0, 40.0], [2.0, 80.0]]);
    }

    #[test]
    fn a_rim_that_cannot_be_read_is_refused_by_key() {
        let r = rim(RimShape::Slant, 0.0);
        let key = |e: Error| match e {
            Error::Invalid { key, .. } => key,
            other => panic!("{other}"),
        };
        assert_eq!(key(r.check(false, false, false).unwrap_err()), "rim");
        assert_eq!(key(r.check(true, true, false).unwrap_err()), "rim");
        assert_eq!(key(r.check(true, false, true).unwrap_err()), "rim");
        assert!(r.check(true, false, false).is_ok());
        let bad = RimSpec {
            rise: -1.0,
            ..r.clone()
        };
        assert_eq!(key(bad.check(true, false, false).unwrap_err()), "rim.rise");
        let wave = rim(RimShape::Wave, 0.0);
        assert_eq!(
            key(wave.check(true, false, false).unwrap_err()),
            "rim.peaks"
        );
        let wide = RimSpec {
            width_deg: Some(400.0),
            ..rim(RimShape::Raised, 0.0)
        };
        assert_eq!(
            key(wide.check(true, false, false).unwrap_err()),
            "rim.width_deg"
        );
        let crests = RimSpec {
            peaks: Some(2),
            ..r
        };
        assert_eq!(
            key(crests.check(true, false, false).unwrap_err()),
            "rim.peaks"
        );
    }
}
