//! A relief: what a mesh has beyond the closest sweep (docs/MESHES.md,
//! "Printed as the mesh is"). A table of offsets over a vessel's loop —
//! rows at heights above the bed, columns at fractions u of Ψ's length —
//! added to the profiles' blend along the same offset direction, read
//! bilinearly (round the loop in u, clamped in z). The surface then
//! passes through the mesh's wall at every row and column, and the
//! stages treat it as drawn: corrected, checked and printed as any design.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// Most rows (heights) a relief may have.
pub const MAX_ROWS: usize = 4000;
/// Most columns (places round the loop) a relief may have.
pub const MAX_COLUMNS: usize = 4000;
/// Most offsets a relief may hold in all.
pub const MAX_VALUES: usize = 2_000_000;
/// The largest offset a relief may add (mm).
pub const MAX_OFFSET_MM: f64 = 500.0;

/// The `relief` key of a design (docs/FORMATS.md, "relief").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Relief {
    /// Heights of the rows above the bed (mm), rising.
    pub z: Vec<f64>,
    /// Places of the columns round the loop: fractions of Ψ's length
    /// from its start, rising, in [0, 1).
    pub u: Vec<f64>,
    /// One row a height, one offset a column (mm, along the trajectory's
    /// offset direction, outward positive).
    pub offsets: Vec<Vec<f64>>,
}

impl Relief {
    /// Checks the table; messages name `relief.z`, `relief.u` or
    /// `relief.offsets[k]`.
    pub fn validate(&self, closed: bool) -> Result<()> {
        if !closed {
            return Err(Error::invalid(
                "relief",
                "a relief goes round a vessel's loop: it needs a closed trajectory (\"closed\": true)",
            ));
        }
        let (rows, cols) = (self.z.len(), self.u.len());
        if rows == 0 || rows > MAX_ROWS {
            return Err(Error::invalid(
                "relief.z",
                format!("must hold 1 to {MAX_ROWS} heights (got {rows})"),
            ));
        }
        if !(3..=MAX_COLUMNS).contains(&cols) {
            return Err(Error::invalid(
                "relief.u",
                format!("must hold 3 to {MAX_COLUMNS} places round the loop (got {cols})"),
            ));
        }
        if rows * cols > MAX_VALUES {
            return Err(Error::invalid(
                "relief",
                format!("holds {} offsets: at most {MAX_VALUES}", rows * cols),
            ));
        }
        let rising = |v: &[f64], lo: f64, hi: f64| {
            v.iter().all(|x| x.is_finite() && (lo..hi).contains(x))
                && v.windows(2).all(|w| w[1] > w[0])
        };
        if !rising(&self.z, 0.0, 1e5) {
            return Err(Error::invalid(
                "relief.z",
                "must be heights from 0 up, each above the last",
            ));
        }
        if !rising(&self.u, 0.0, 1.0) {
            return Err(Error::invalid(
                "relief.u",
                "must be fractions of the loop from 0 to below 1, each above the last",
            ));
        }
        if self.offsets.len() != rows {
            return Err(Error::invalid(
                "relief.offsets",
                format!(
                    "must hold a row for each of the {rows} heights (got {})",
                    self.offsets.len()
                ),
            ));
        }
        for (k, row) in self.offsets.iter().enumerate() {
            if row.len() != cols {
                return Err(Error::invalid(
                    format!("relief.offsets[{k}]"),
                    format!(
                        "must hold an offset for each of the {cols} places (got {})",
                        row.len()
                    ),
                ));
            }
            if let Some(v) = row
                .iter()
                .find(|v| !(v.is_finite() && v.abs() <= MAX_OFFSET_MM))
            {
                return Err(Error::invalid(
                    format!("relief.offsets[{k}]"),
                    format!("holds {v}: offsets are at most {MAX_OFFSET_MM} mm either way"),
                ));
            }
        }
        Ok(())
    }

    /// The offset at `u` round the loop (any real: taken modulo 1) and
    /// height `z` (mm): linear between columns, round the loop from the
    /// last to the first, and between rows; the nearest row outside them.
    pub fn at(&self, u: f64, z: f64) -> f64 {
        let (rows, cols) = (self.z.len(), self.u.len());
        if rows == 0 || cols == 0 {
            return 0.0;
        }
        let u = u.rem_euclid(1.0);
        // The column at or before u, round the loop.
        let j = self.u.partition_point(|&x| x <= u);
        let (a, b) = if j == 0 || j == cols {
            (cols - 1, 0)
        } else {
            (j - 1, j)
        };
        let (ua, ub) = (self.u[a], if b == 0 { self.u[0] + 1.0 } else { self.u[b] });
        let uu = if u < ua { u + 1.0 } else { u };
        let tu = ((uu - ua) / (ub - ua).max(1e-12)).clamp(0.0, 1.0);
        let row = |k: usize| {
            let r = &self.offsets[k];
            r[a] * (1.0 - tu) + r[b] * tu
        };
        let k = self.z.partition_point(|&x| x <= z);
        if k == 0 {
            return row(0);
        }
        if k == rows {
            return row(rows - 1);
        }
        let (za, zb) = (self.z[k - 1], self.z[k]);
        let tz = (z - za) / (zb - za);
        row(k - 1) * (1.0 - tz) + row(k) * tz
    }

    /// The largest offset either way (mm).
    pub fn max_abs(&self) -> f64 {
        self.offsets
            .iter()
            .flatten()
            .fold(0.0, |m: f64, v| m.max(v.abs()))
    }

    /// The relief of a design scaled by `kxy` across and `kz` in height
    /// (firing shrinkage).
    pub fn scaled(&self, kxy: f64, kz: f64) -> Relief {
        Relief {
            z: self.z.iter().map(|z| z * kz).collect(),
            u: self.u.clone(),
            offsets: self
                .offsets
                .iter()
                .map(|r| r.iter().map(|v| v * kxy).collect())
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn relief() -> Relief {
        Relief {
            z: vec![0.0, 10.0],
            u: vec![0.0, 0.25, 0.5, 0.75],
            offsets: vec![vec![0.0, 1.0, 2.0, 3.0], vec![4.0, 5.0, 6.0, 7.0]],
        }
    }

    #[test]
    fn a_relief_is_read_bilinearly_round_the_loop() {
        let r = relief();
        assert_eq!(r.at(0.25, 0.0), 1.0);
        assert_eq!(r.at(0.125, 0.0), 0.5);
        // From the last column back to the first, round the loop.
        assert!((r.at(0.875, 0.0) - 1.5).abs() < 1e-12);
        assert!((r.at(-0.125, 0.0) - 1.5).abs() < 1e-12);
        // Half way up, and clamped above the last row and below the first.
        assert!((r.at(0.25, 5.0) - 3.0).abs() < 1e-12);
        assert_eq!(r.at(0.5, 50.0), 6.0);
        assert_eq!(r.at(0.5, -1.0), 2.0);
        assert_eq!(r.max_abs(), 7.0);
        let s = r.scaled(1.1, 1.2);
        assert!((s.at(0.25, 6.0) - 3.3).abs() < 1e-12);
    }

    #[test]
    fn a_relief_out_of_its_rules_is_refused_by_key() {
        assert!(relief().validate(true).is_ok());
        let e = relief().validate(false).unwrap_err().to_string();
        assert!(e.starts_with("relief:"), "{e}");
        let mut r = relief();
        r.z = vec![10.0, 0.0];
        assert!(r
            .validate(true)
            .unwrap_err()
            .to_string()
            .starts_with("relief.z:"));
        let mut r = relief();
        r.u[3] = 1.0;
        assert!(r
            .validate(true)
            .unwrap_err()
            .to_string()
            .starts_with("relief.u:"));
        let mut r = relief();
        r.offsets[1].pop();
        let e = r.validate(true).unwrap_err().to_string();
        assert!(e.starts_with("relief.offsets[1]:"), "{e}");
        let mut r = relief();
        r.offsets[0][2] = f64::NAN;
        assert!(r.validate(true).is_err());
        let mut r = relief();
        r.offsets.pop();
        assert!(r.validate(true).is_err());
    }
}
