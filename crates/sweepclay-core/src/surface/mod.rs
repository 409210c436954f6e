//! Stage 1: design → sampled sweeping surface (paper §4 "Sample points
//! generation", docs/ALGORITHMS.md §2).
//!
//! Ψ is resampled by arc length into columns p_i; each column carries the
//! transition curve T_i between the two profiles, λ_i = f(u_i), evaluated
//! at exactly the heights the toolpath will visit (the [`LayerPlan`]), so a
//! sample *is* a path point, as in the paper.

use crate::curves::{Interpolation, Profile, Trajectory};
use crate::design::{Design, Offset, Params};
use crate::error::{Error, Result};
use crate::layers::LayerPlan;
use crate::printer::Printer;
use crate::vessel::VesselPlan;

mod vessel;
use vessel::sample_vessel;

/// One transition curve, at trajectory sample p_i.
#[derive(Clone, Debug, PartialEq)]
pub struct Column {
    /// p_i, relative to the centre `o` (mm).
    pub p: [f64; 2],
    /// d_i = (p_i − o)/|p_i − o|: direction of the radial offset.
    pub dir: [f64; 2],
    /// u_i: normalised arc length along Ψ.
    pub u: f64,
    /// λ_i = f(u_i).
    pub lambda: f64,
    /// h_i = (1 − λ_i)·Z_s + λ_i·Z_t: the column's designed height (mm).
    pub height: f64,
    /// Index of the column's first sample in [`Surface::samples`].
    pub first: u32,
    /// Passes 1..=`passes` visit the column (one sample each, bottom up).
    pub passes: u32,
    /// A top-edge bead sample follows the pass samples.
    pub top: bool,
    /// Samples after those: a vessel's raised arc's passes and top bead
    /// above its rim turn ([`crate::vessel::RaisedArc`]).
    pub extra: u32,
    /// The design's twist (radians): the cross-section at height z is
    /// turned about o by `twist · z / height` (docs/ALGORITHMS.md §11).
    pub twist: f64,
    /// Ψ's unit normal at p (either side), for the twist's overhang.
    pub normal: [f64; 2],
    /// The height the twist starts from (mm): a vessel's floor layers
    /// stand untwisted, as the floor's rings were laid out.
    pub twist_from: f64,
}

impl Column {
    /// Number of samples of this column.
    pub fn len(&self) -> usize {
        self.passes as usize + usize::from(self.top) + self.extra as usize
    }

    /// Whether the column has no samples (never for a valid surface).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The range of this column's samples.
    pub fn samples(&self) -> std::ops::Range<usize> {
        self.first as usize..self.first as usize + self.len()
    }

    /// The position of a point at radial offset `xi` and height `z`,
    /// turned by the twist at that height.
    pub fn point(&self, xi: f64, z: f64) -> [f64; 3] {
        let q = [self.p[0] + xi * self.dir[0], self.p[1] + xi * self.dir[1]];
        if self.twist == 0.0 {
            return [q[0], q[1], z];
        }
        let (s, c) = self.turn(z).sin_cos();
        [c * q[0] - s * q[1], s * q[0] + c * q[1], z]
    }

    /// The twist's angle at height `z` (radians).
    pub fn turn(&self, z: f64) -> f64 {
        let span = (self.height - self.twist_from).max(1e-9);
        self.twist * ((z - self.twist_from) / span).clamp(0.0, 1.0)
    }

    /// How far the twist moves the point at offset `xi` of this column
    /// across the wall between heights `z0` and `z1`, in ξ's units (mm
    /// along `dir`): the part of its turn that overhangs. Exact for any
    /// turn: in the frame turned with the upper layer, the point below
    /// sits turned back by the difference (a radial offset on a circle
    /// gets none; the rest runs along the bead).
    pub fn twist_step(&self, xi: f64, z0: f64, z1: f64) -> f64 {
        if self.twist == 0.0 {
            return 0.0;
        }
        let q = [self.p[0] + xi * self.dir[0], self.p[1] + xi * self.dir[1]];
        let turn = self.turn(z0) - self.turn(z1);
        let (s, c) = turn.sin_cos();
        let back = [c * q[0] - s * q[1], s * q[0] + c * q[1]];
        // Across the wall as it runs between the two: the normal turned
        // half way (with the normal at either end, a circle's twist, which
        // moves nothing, would count its chord's sagitta, r·θ²/2, as an
        // overhang every layer).
        let (s, c) = (0.5 * turn).sin_cos();
        let m = self.normal;
        let n = [c * m[0] - s * m[1], s * m[0] + c * m[1]];
        let dn = m[0] * self.dir[0] + m[1] * self.dir[1];
        let across = n[0] * (q[0] - back[0]) + n[1] * (q[1] - back[1]);
        across / dn.abs().max(0.2).copysign(dn)
    }
}

/// One surface sample: a height on a transition curve and its radial offset.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Height above the bed (mm).
    pub z: f64,
    /// ξ: horizontal offset along the column's direction (mm).
    pub xi: f64,
}

/// The sampled sweeping surface.
#[derive(Clone, Debug, PartialEq)]
pub struct Surface {
    /// Design name.
    pub name: String,
    /// Columns in trajectory order.
    pub columns: Vec<Column>,
    /// All samples, column by column, bottom up.
    pub samples: Vec<Sample>,
    /// The layering the samples follow. For a vessel, a single stage of
    /// all its layers and turns; [`Surface::vessel`] holds its layering.
    pub plan: LayerPlan,
    /// A vessel's layering (closed Ψ), else `None`.
    pub vessel: Option<VesselPlan>,
    /// Whether the tall end is the end of Ψ (else its start).
    pub tall_at_end: bool,
    /// C_s sampled.
    pub start: Profile,
    /// C_t sampled.
    pub end: Profile,
    /// Arc length of Ψ (mm).
    pub trajectory_length: f64,
    /// Distance between columns along Ψ (mm).
    pub spacing: f64,
    /// The parameters.
    pub params: Params,
    /// The printer.
    pub printer: Printer,
    /// The corners of a polyline Ψ rounded before sampling.
    pub corners: Vec<crate::curves::CornerFix>,
    /// The textures' displacement D per sample (mm, along the offset
    /// direction) at full amplitude; empty without textures.
    pub texture: Vec<f64>,
    /// The textures' labels and their summed amplitude (mm), for reports.
    pub texture_label: (String, f64),
    /// A mesh's relief over the profiles' blend, as printed
    /// ([`crate::relief`]); part of the drawn form.
    pub relief: Option<crate::relief::Relief>,
    /// A shaped rim (the design's `rim`): every column is the one profile
    /// up to its top, and where the rim rises higher the wall continues
    /// from there ([`continued`]); the body is never stretched.
    pub rim_continues: bool,
}

/// The one profile's offset at height `z` (mm) for a shaped rim: the
/// profile itself up to its top, and above it the profile's top carried
/// on along its last 2 % (docs/FORMATS.md, "rim"). A pitcher raised 30 mm
/// at the back keeps the widths typed below its top all round; stretched,
/// it stood 48.8 mm from the centre at z 100 where 40 was typed.
pub fn continued(start: &Profile, z: f64) -> f64 {
    let h = start.height;
    if z <= h {
        return start.offset((z / h).max(0.0));
    }
    let d = 0.02;
    let slope = (start.offset(1.0) - start.offset(1.0 - d)) / (h * d);
    start.offset(1.0) + slope * (z - h)
}

impl Surface {
    /// ξ_i(t) of the design (before corrections), scaled by `compression`.
    pub fn design_offset(&self, col: &Column, z: f64, compression: f64) -> f64 {
        let relief = self.relief.as_ref().map_or(0.0, |r| r.at(col.u, z));
        if self.rim_continues {
            return compression * (continued(&self.start, z.min(col.height)) + relief);
        }
        let t = (z / col.height).min(1.0);
        compression
            * ((1.0 - col.lambda) * self.start.offset(t) + col.lambda * self.end.offset(t) + relief)
    }

    /// Column index for position `m` counted from the short end.
    pub fn ordered(&self, m: usize) -> usize {
        if self.tall_at_end {
            m
        } else {
            self.columns.len() - 1 - m
        }
    }

    /// The position of a column's first sample (its base, on the bed).
    pub fn position_of(&self, col: &Column) -> [f64; 3] {
        let smp = self.samples[col.first as usize];
        col.point(smp.xi, smp.z)
    }

    /// The position of sample `s` of column `c`.
    pub fn position(&self, c: usize, s: usize) -> [f64; 3] {
        let smp = self.samples[s];
        self.columns[c].point(smp.xi, smp.z)
    }
}

/// The unit normal of the polyline `pts` at point `i`, to the left of the
/// direction of travel: from the chord of its neighbours (one-sided at the
/// ends), so a straight wall has one normal and a bend turns it smoothly.
fn normal(pts: &[[f64; 2]], i: usize, closed: bool) -> [f64; 2] {
    let n = pts.len();
    let (a, b) = if closed {
        (pts[(i + n - 1) % n], pts[(i + 1) % n])
    } else {
        (pts[i.saturating_sub(1)], pts[(i + 1).min(n - 1)])
    };
    let (tx, ty) = (b[0] - a[0], b[1] - a[1]);
    let l = tx.hypot(ty);
    if l > 0.0 {
        [-ty / l, tx / l]
    } else {
        [0.0, 1.0]
    }
}

/// Samples the design's surface. Validates every part of the design first.
/// Textures refine the sampling ([`Design::printed`]) and give each sample
/// its displacement D; the twist turns each column's cross-sections
/// (docs/ALGORITHMS.md §11).
pub fn sample_surface(design: &Design) -> Result<Surface> {
    design.params.validate()?;
    design.check_texture()?;
    // What is printed: the design enlarged for the kiln's shrinkage, its
    // sampling refined for its textures.
    let printed = design.printed();
    let mut s = sample_plain(&printed)?;
    let twist = design.twist_deg.to_radians();
    // A vessel's floor layers are laid plain and untwisted: the floor
    // fills the plain ring, and texture and twist start above it.
    let base = s
        .vessel
        .as_ref()
        .filter(|v| v.floor_layers > 0)
        .map_or(0.0, |v| f64::from(v.base_layers) * v.base_layer_mm);
    if twist != 0.0 {
        // A turn moves a point across Ψ's direction (the wall's normal
        // n) by n · (ẑ × p); ξ moves it by d · n a millimetre.
        let pts: Vec<[f64; 2]> = s.columns.iter().map(|c| c.p).collect();
        let closed = s.vessel.is_some();
        if !closed {
            twist_fits_open_ends(&s, &pts, twist)?;
        }
        for (i, col) in s.columns.iter_mut().enumerate() {
            col.twist = twist;
            col.normal = normal(&pts, i, closed);
            col.twist_from = base;
        }
        twist_leans_within_limit(&s, twist)?;
    }
    if design.texture.iter().all(|t| t.amplitude == 0.0) {
        return Ok(s);
    }
    let height = s.columns.iter().map(|c| c.height).fold(0.0, f64::max);
    let field = crate::texture::Field::new(
        &printed.texture,
        s.trajectory_length,
        height,
        s.vessel.is_some(),
        s.spacing,
        s.params.max_layer_height,
    );
    let mut d = Vec::with_capacity(s.samples.len());
    for col in &s.columns {
        for smp in &s.samples[col.samples()] {
            d.push(field.at(col.u, smp.z, col.height, base));
        }
    }
    s.texture = d;
    s.texture_label = (field.label(), field.peak());
    Ok(s)
}

/// Refuses a twist that leans an open wall's ends out over the layers
/// below: a turn moves an end along the wall by |t · (ẑ × p)| a radian
/// (t: Ψ's direction there), and over a layer that must stay within the
/// overhang limit (with the texture's margin, 0.85) and half a sample
/// spacing — a wall's end has nothing beyond it to rest on.
fn twist_fits_open_ends(s: &Surface, pts: &[[f64; 2]], twist: f64) -> Result<()> {
    let n = pts.len();
    if n < 2 {
        return Ok(());
    }
    let tan = s.params.max_overhang_deg.to_radians().tan();
    for (i, j) in [(0, 1), (n - 1, n - 2)] {
        let (p, q) = (pts[i], pts[j]);
        let l = (q[0] - p[0]).hypot(q[1] - p[1]).max(1e-9);
        let t = [(q[0] - p[0]) / l, (q[1] - p[1]) / l];
        let along = (t[1] * p[0] - t[0] * p[1]).abs();
        let h = s.columns[i].height;
        // Per mm of height the end moves along the wall by
        // |twist| · along / h: within the overhang limit, and by at most
        // half a sample spacing a layer, so the end bead keeps clay
        // under it.
        let rate = (0.85 * tan).min(0.5 * s.spacing / s.params.max_layer_height);
        let allowed = rate * h / along.max(1e-9);
        if twist.abs() > allowed {
            return Err(Error::invalid(
                "twist_deg",
                format!(
                    "turns the wall's {} end ({:.1}, {:.1}) mm along the wall faster than the layer below can hold it (overhang limit {}°, half a sample spacing a layer): its end would lean out over nothing; at most {:.0}° of twist for this wall, or close the trajectory into a vessel",
                    if i == 0 { "start" } else { "far" },
                    p[0],
                    p[1],
                    s.params.max_overhang_deg,
                    allowed.to_degrees().floor()
                ),
            ));
        }
    }
    Ok(())
}

/// Refuses a twist that by itself leans the wall across its own
/// direction beyond the overhang limit somewhere (with the texture's
/// margin, 0.85): a turn moves the wall at p across itself by
/// |n · (ẑ × p)| a radian, which only a shape round o escapes. The
/// support-free correction would have to undo it by reshaping the wall.
fn twist_leans_within_limit(s: &Surface, twist: f64) -> Result<()> {
    let tan = 0.85 * s.params.max_overhang_deg.to_radians().tan();
    let mut worst: Option<(f64, &Column)> = None;
    for col in &s.columns {
        let across = (col.normal[1] * col.p[0] - col.normal[0] * col.p[1]).abs();
        let allowed = tan * (col.height - col.twist_from) / across.max(1e-9);
        if worst.is_none_or(|(w, _)| allowed < w) {
            worst = Some((allowed, col));
        }
    }
    match worst {
        Some((allowed, col)) if twist.abs() > allowed => Err(Error::invalid(
            "twist_deg",
            format!(
                "turns the wall at ({:.1}, {:.1}) mm (u = {:.2}) across itself faster than the overhang limit ({}°) allows: at most {:.0}° of twist for this shape (a rounder loop, about o, takes more)",
                col.p[0],
                col.p[1],
                col.u,
                s.params.max_overhang_deg,
                allowed.to_degrees().floor()
            ),
        )),
        _ => Ok(()),
    }
}

/// How much nearer the textures and a relief can bring the wall to the
/// extruder body (mm): the textures' amplitudes summed, each way, and
/// the relief's largest offset.
fn displacement_reach(design: &Design) -> f64 {
    2.0 * design
        .texture
        .iter()
        .map(|t| t.amplitude.abs())
        .sum::<f64>()
        + design.relief.as_ref().map_or(0.0, |r| r.max_abs())
}

/// [`sample_surface`] of the design as printed ([`Design::printed`]),
/// without textures and twist.
fn sample_plain(design: &Design) -> Result<Surface> {
    let params = design.params.clone();
    let printer = design.printer.resolve()?;
    let start = Profile::new("profile_start", &design.profile_start)?;
    let end = Profile::new("profile_end", &design.end_profile())?;
    for (key, prof) in [("profile_start", &start), ("profile_end", &end)] {
        if prof.height < params.layer_height {
            return Err(Error::invalid(
                key,
                format!(
                    "is {:.2} mm tall, less than one layer (params.layer_height = {})",
                    prof.height, params.layer_height
                ),
            ));
        }
    }
    let closed = design.trajectory.closed;
    if !closed && params.floor_layers.is_some() {
        return Err(Error::invalid(
            "params.floor_layers",
            "a floor needs a closed trajectory (\"closed\": true in the trajectory): an open wall has no inside",
        ));
    }
    let interp = if closed {
        Interpolation::new_closed(design.interpolation.as_ref())?
    } else {
        Interpolation::new(design.interpolation.as_ref())?
    };
    let traj = Trajectory::new(&design.trajectory, params.spacing, params.width_max)?;
    let n = traj.points.len();
    // "Outward" for a loop: right of travel on a counter-clockwise one.
    let outward = if closed && crate::plane::signed_area2(&traj.points) > 0.0 {
        -1.0
    } else {
        1.0
    };
    let mut columns = Vec::with_capacity(n);
    for (i, &p) in traj.points.iter().enumerate() {
        let u = if closed {
            i as f64 / n as f64
        } else {
            i as f64 / (n - 1) as f64
        };
        let dir = match design.trajectory.offset {
            Offset::Radial => {
                let r = p[0].hypot(p[1]);
                if r < 1.0 {
                    return Err(Error::invalid(
                        "trajectory",
                        format!(
                            "passes within 1 mm of the centre o at ({:.2}, {:.2}), u = {u:.3}, where the radial direction is undefined; set \"offset\": \"normal\" in the trajectory to offset the profiles perpendicular to it instead, or move the curve away from o",
                            p[0], p[1]
                        ),
                    ));
                }
                [p[0] / r, p[1] / r]
            }
            Offset::Normal => normal(&traj.points, i, closed).map(|v| outward * v),
        };
        // A shaped rim says how high each column stands by its angle
        // about o (docs/FORMATS.md, "rim").
        let lambda = design
            .rim
            .as_ref()
            .map_or_else(|| interp.eval(u), |r| r.lambda(p));
        columns.push(Column {
            p,
            dir,
            u,
            lambda,
            height: (1.0 - lambda) * start.height + lambda * end.height,
            first: 0,
            passes: 0,
            top: false,
            extra: 0,
            twist: 0.0,
            normal: [0.0, 0.0],
            twist_from: 0.0,
        });
    }
    if closed {
        let corners = traj.corners.clone();
        return sample_vessel(design, columns, traj.length, params, printer, start, end)
            .map(|s| Surface { corners, ..s });
    }
    let tall_at_end = end.height >= start.height;
    // Columns from the short end (the order the layering works in).
    let mut short_first: Vec<&Column> = columns.iter().collect();
    if !tall_at_end {
        short_first.reverse();
    }
    let ordered: Vec<f64> = short_first.iter().map(|c| c.height).collect();
    let ordered_points: Vec<[f64; 2]> = short_first.iter().map(|c| c.p).collect();
    let spacing = traj.length / (n - 1) as f64;
    // The extruder body reaches r + w_max/2 around the nozzle; 20 % more
    // for the profiles' radial offsets, which move columns in plan.
    let reach = 1.2 * (printer.nozzle_radius + params.width_max / 2.0) + displacement_reach(design);
    // Clay laid within r + w_max of path is the bead just laid (exempt, as
    // in the checker); one column less for safety.
    let exempt =
        (((printer.nozzle_radius + params.width_max) / spacing) as usize).saturating_sub(1);
    let reach = crate::layers::reach_max(&ordered_points, &ordered, reach, exempt);
    let plan = LayerPlan::choose(&ordered, &reach, &params)?;
    let mut surface = Surface {
        name: design.name.clone(),
        columns,
        samples: Vec::new(),
        plan,
        vessel: None,
        tall_at_end,
        start,
        end,
        trajectory_length: traj.length,
        spacing,
        params,
        printer,
        corners: traj.corners.clone(),
        texture: Vec::new(),
        texture_label: (String::new(), 0.0),
        relief: design.relief.clone(),
        rim_continues: design.rim.is_some(),
    };
    let mut samples = Vec::new();
    let mut columns = std::mem::take(&mut surface.columns);
    for col in &mut columns {
        let layers = surface.plan.column(col.height);
        col.first = samples.len() as u32;
        col.passes = layers.passes;
        col.top = layers.top_bead.is_some();
        for k in 1..=layers.passes {
            let z = surface.plan.height(k, col.height);
            samples.push(Sample {
                z,
                xi: surface.design_offset(col, z, 1.0),
            });
        }
        if let Some(z) = layers.top_bead {
            samples.push(Sample {
                z,
                xi: surface.design_offset(col, z, 1.0),
            });
        }
    }
    surface.columns = columns;
    surface.samples = samples;
    Ok(surface)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A circular arc of radius 40 with vertical profiles: a cylinder piece.
    fn cylinder(hs: f64, ht: f64) -> Design {
        let pts: Vec<[f64; 2]> = (0..=60)
            .map(|i| {
                let a = std::f64::consts::PI * i as f64 / 60.0;
                [40.0 * a.cos(), 40.0 * a.sin()]
            })
            .collect();
        Design::from_json(&format!(
            r#"{{"sweepclay":1,
                "profile_start":{{"control_points":[[0,0],[0,{hs}]]}},
                "profile_end":{{"control_points":[[0,0],[0,{ht}]]}},
                "trajectory":{{"points":{}}}}}"#,
            serde_json::to_string(&pts).unwrap()
        ))
        .unwrap()
    }

    #[test]
    fn vertical_profiles_on_a_circle_give_a_cylinder() {
        let s = sample_surface(&cylinder(50.0, 50.0)).unwrap();
        assert_eq!(s.plan.passes, 40);
        for (c, col) in s.columns.iter().enumerate() {
            assert_eq!(col.len(), 40);
            for i in col.samples() {
                let p = s.position(c, i);
                let r = p[0].hypot(p[1]);
                // Ψ is a 60-gon: chord sagitta 40·(1 − cos(π/120)) = 0.014 mm.
                assert!(
                    (r - 40.0).abs() < 0.015,
                    "sample at radius {r}, expected 40"
                );
            }
            let top = s.samples[col.samples().end - 1].z;
            assert!((top - 50.0).abs() < 1e-9, "top {top}");
        }
        // Arc length π·40 ≈ 125.6 mm at 1.1 mm → 115 columns.
        assert_eq!(s.columns.len(), 115);
    }

    #[test]
    fn a_twist_moves_a_circle_about_o_along_itself_only() {
        // Turned about o, a circle is itself: no step across it, however
        // far a layer turns (12° over the arc's 50 mm; an open end holds no
        // more) (the normal at either end would count the
        // chord's sagitta, 40·(1 − cos θ)). A point 10 mm out from it is
        // on a circle of 50 mm: none either.
        let mut d = cylinder(50.0, 50.0);
        d.twist_deg = 12.0;
        let s = sample_surface(&d).unwrap();
        let n = s.columns.len();
        for col in &s.columns[1..n - 1] {
            for (z0, z1) in [(0.0, 1.25), (10.0, 12.5), (0.0, 50.0)] {
                for xi in [0.0, 10.0] {
                    let step = col.twist_step(xi, z0, z1);
                    // The normal is Ψ's 60-gon's, between neighbours
                    // (one-sided at the ends, left out): 0.01 mm off over
                    // the whole 12°, where the sagitta would be
                    // 50·(1 − cos 12°) = 1.09 mm.
                    assert!(step.abs() < 0.02, "{step} at {:?}", col.p);
                }
            }
        }
    }

    #[test]
    fn leaning_profiles_offset_radially() {
        let mut d = cylinder(40.0, 40.0);
        d.profile_start.control_points = vec![[0.0, 0.0], [10.0, 40.0]];
        d.profile_end = Some(crate::design::CurveSpec {
            control_points: vec![[5.0, 0.0], [5.0, 40.0]],
            points: None,
        });
        let s = sample_surface(&d).unwrap();
        let first = &s.columns[0];
        let top = s.samples[first.samples().end - 1];
        assert!(
            (top.xi - 10.0).abs() < 1e-6,
            "start column leans 10 mm, got {}",
            top.xi
        );
        // Halfway along Ψ with linear f: the mean profile, 5 mm at the top.
        let mid = &s.columns[s.columns.len() / 2];
        let top = s.samples[mid.samples().end - 1];
        assert!((top.xi - 10.0 * (1.0 - mid.lambda)).abs() < 1e-6);
        assert!((mid.lambda - 0.5).abs() < 0.01);
    }

    #[test]
    fn trajectory_through_the_centre_is_refused() {
        let mut d = cylinder(20.0, 20.0);
        d.trajectory.points = Some(vec![[-30.0, 0.0], [30.0, 0.0]]);
        let e = sample_surface(&d).unwrap_err().to_string();
        assert!(e.contains("within 1 mm of the centre"), "{e}");
    }

    #[test]
    fn a_straight_wall_through_the_centre_with_normal_offset_is_a_flat_wall() {
        // 60 mm through o, vertical profiles 20 mm: a flat wall, every
        // sample on the line y = 0, as long and as tall as drawn; the
        // radial error names the way out.
        let mut d = cylinder(20.0, 20.0);
        d.trajectory.points = Some(vec![[-30.0, 0.0], [30.0, 0.0]]);
        let e = sample_surface(&d).unwrap_err().to_string();
        assert!(e.contains(r#""offset": "normal""#), "{e}");
        d.trajectory.offset = Offset::Normal;
        let s = sample_surface(&d).unwrap();
        let (mut xmin, mut xmax, mut zmax) = (f64::MAX, f64::MIN, 0.0f64);
        for (c, col) in s.columns.iter().enumerate() {
            assert_eq!(col.dir, [0.0, 1.0], "normal to the left of +x");
            for i in col.samples() {
                let p = s.position(c, i);
                assert!(p[1].abs() < 1e-12, "off the wall: {p:?}");
                xmin = xmin.min(p[0]);
                xmax = xmax.max(p[0]);
                zmax = zmax.max(p[2]);
            }
        }
        assert!(
            (xmin + 30.0).abs() < 1e-9 && (xmax - 30.0).abs() < 1e-9,
            "{xmin}..{xmax}"
        );
        assert!((zmax - 20.0).abs() < 1e-9, "{zmax}");
    }

    #[test]
    fn a_normal_offset_moves_a_wall_sideways_by_the_profile_offset() {
        // The profiles lean 5 mm over 20: at the top the wall stands 5 mm
        // to the left of Ψ (+y for a wall drawn along +x).
        let mut d = cylinder(20.0, 20.0);
        d.trajectory.points = Some(vec![[-30.0, 0.0], [30.0, 0.0]]);
        d.trajectory.offset = Offset::Normal;
        d.profile_start.control_points = vec![[0.0, 0.0], [5.0, 20.0]];
        d.profile_end = Some(crate::design::CurveSpec {
            control_points: vec![[0.0, 0.0], [5.0, 20.0]],
            points: None,
        });
        d.params.max_overhang_deg = 60.0;
        let s = sample_surface(&d).unwrap();
        let col = &s.columns[s.columns.len() / 2];
        let top = s.position(s.columns.len() / 2, col.samples().end - 1);
        assert!((top[1] - 5.0).abs() < 1e-9, "{top:?}");
    }

    #[test]
    fn too_short_profile_is_refused() {
        let e = sample_surface(&cylinder(1.0, 20.0))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("profile_start: is 1.00 mm tall"), "{e}");
    }
}
