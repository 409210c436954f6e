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
}

impl Surface {
    /// ξ_i(t) of the design (before corrections), scaled by `compression`.
    pub fn design_offset(&self, col: &Column, z: f64, compression: f64) -> f64 {
        let t = (z / col.height).min(1.0);
        compression * ((1.0 - col.lambda) * self.start.offset(t) + col.lambda * self.end.offset(t))
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

/// How much nearer the textures can bring the wall to the extruder body
/// (mm): their amplitudes summed, each way.
fn texture_reach(design: &Design) -> f64 {
    2.0 * design
        .texture
        .iter()
        .map(|t| t.amplitude.abs())
        .sum::<f64>()
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
    let reach = 1.2 * (printer.nozzle_radius + params.width_max / 2.0) + texture_reach(design);
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

/// Where a spiral may begin on a loop whose columns' rims are `h`: just
/// past the lowest rim (the first turn then ends where its rise is least,
/// docs/ALGORITHMS.md §8), Ψ's start, then seven more evenly round the
/// loop.
fn spiral_starts(h: &[f64]) -> Vec<usize> {
    let n = h.len();
    let lowest = (0..n).min_by(|&a, &b| h[a].total_cmp(&h[b])).unwrap_or(0);
    let mut starts = vec![(lowest + 1) % n];
    for c in (0..8).map(|m| m * n / 8).filter(|&c| c < n) {
        if !starts.contains(&c) {
            starts.push(c);
        }
    }
    starts
}

/// A vessel's layering whose extruder body meets clay, by the sampling's
/// estimate: at which column, and how high above the nozzle (mm).
type Colliding = (VesselPlan, usize, f64);

/// The layering with the most turns, from `v.turns` down to
/// `v.fewest_turns`, and the first of `starts`, whose first turn fits
/// and whose spiral the extruder body clears; else the one whose first
/// turn fits with the least collision (column, mm above the nozzle), if
/// any first turn fits.
fn clear_layering(
    v: &VesselPlan,
    starts: &[usize],
    near: &crate::vessel::Neighbours,
    heights: &[f64],
    exempt: f64,
    params: &Params,
) -> std::result::Result<VesselPlan, Option<Box<Colliding>>> {
    let mut least: Option<Box<Colliding>> = None;
    for turns in (v.fewest_turns..=v.turns).rev() {
        for &st in starts {
            let w = v.with(turns, st, params);
            if !w.first_fits(params) {
                continue;
            }
            match w.body_violation(near, heights, exempt) {
                None => return Ok(w),
                Some((i, over)) => {
                    if least.as_ref().is_none_or(|l| over < l.2) {
                        least = Some(Box::new((w, i, over)));
                    }
                }
            }
        }
    }
    Err(least)
}

/// The rim's lowest and highest heights, and the largest share f of its
/// spread for which `holds` is true of the heights drawn toward the
/// lowest, lo + f·(h − lo), by bisection over `steps` halvings (0 if
/// none holds): how far a refused rim's heights must come together.
fn largest_share(heights: &[f64], steps: u32, holds: impl Fn(&[f64]) -> bool) -> (f64, f64, f64) {
    let lo = heights.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = heights.iter().copied().fold(0.0, f64::max);
    let (mut ok, mut bad) = (0.0f64, 1.0f64);
    for _ in 0..steps {
        let f = 0.5 * (ok + bad);
        let h: Vec<f64> = heights.iter().map(|&h| lo + f * (h - lo)).collect();
        if holds(&h) {
            ok = f;
        } else {
            bad = f;
        }
    }
    (lo, hi, ok)
}

/// The samples of a vessel (docs/ALGORITHMS.md §8): each column's spiral
/// turns and, where the last turn ends half a layer or more below the
/// rim, the rim bead. The floor is not sampled: the path stage fills the
/// first turn's inside.
fn sample_vessel(
    design: &Design,
    columns: Vec<Column>,
    length: f64,
    params: Params,
    printer: Printer,
    start: Profile,
    end: Profile,
) -> Result<Surface> {
    let heights: Vec<f64> = columns.iter().map(|c| c.height).collect();
    let floor = params
        .floor_layers
        .unwrap_or(crate::design::DEFAULT_FLOOR_LAYERS);
    let chosen = VesselPlan::choose(&heights, &params, floor);
    let starts = spiral_starts(&heights);
    // The extruder body's reach, and the clay just laid along the loop
    // that it may touch, as the checker counts them; columns where the
    // rim is, where collisions happen (docs/ALGORITHMS.md §8).
    let reach = printer.nozzle_radius + params.width_max / 2.0 + texture_reach(design);
    let exempt = printer.nozzle_radius + params.width_max;
    let offset = |c: &Column| {
        let t = 1.0;
        (1.0 - c.lambda) * start.offset(t) + c.lambda * end.offset(t)
    };
    let points: Vec<[f64; 2]> = columns
        .iter()
        .map(|c| {
            let q = c.point(offset(c), 0.0);
            [q[0], q[1]]
        })
        .collect();
    let near = crate::vessel::Neighbours::new(&points, reach);
    // The most turns (the thinnest layers) whose spiral the extruder body
    // clears, from the first start whose seam it clears; where a rim rises
    // and falls, thicker layers keep the turn below out of its way.
    let full = chosen
        .as_ref()
        .ok()
        .map(|v| clear_layering(v, &starts, &near, &heights, exempt, &params));
    // Where no spiral carries the whole rim, the spiral carries it up to
    // a level and the part above is laid as partial layers.
    let mut peaks = None;
    let (v, rim) = 'plan: {
        if !matches!(full, Some(Ok(_))) {
            match raised_arc(&heights, &columns, floor, &near, exempt, &params) {
                Ok(Some(v)) => break 'plan (v, None),
                Ok(None) => {}
                // Two raised parts: the spiral over the whole rim may still
                // print (the replay judges); where it cannot, this says why.
                Err(why) => peaks = Some(why),
            }
        }
        if let (Err(_), Some(why)) = (&chosen, &peaks) {
            return Err(Error::invalid("profile_end", why.clone()));
        }
        // Where the rim is highest and lowest, for a refusal of its spread.
        let places = || {
            let at = |best: fn(f64, f64) -> bool| {
                let i = (0..heights.len())
                    .reduce(|a, b| if best(heights[b], heights[a]) { b } else { a })
                    .unwrap_or(0);
                columns[i].p
            };
            let (hi, lo) = (at(|a, b| a > b), at(|a, b| a < b));
            format!(
                " (the rim is highest near ({:.0}, {:.0}) mm and lowest near ({:.0}, {:.0}) mm; no level of it leaves one raised part above what one spiral carries)",
                hi[0], hi[1], lo[0], lo[1]
            )
        };
        if let Err(Error::Invalid { key, reason }) = &chosen {
            return Err(Error::invalid(key.clone(), format!("{reason}{}", places())));
        }
        chosen?;
        let v = match full.expect("a layering was chosen") {
            Ok(clear) => clear,
            Err(None) => {
                // The most the rim may rise: the largest share of its spread
                // whose first turn fits somewhere (to 1/1000 of it).
                let (lo, hi, ok) = largest_share(&heights, 10, |hs| {
                    VesselPlan::choose(hs, &params, floor).is_ok_and(|v| {
                        (v.fewest_turns..=v.turns).any(|t| {
                            starts
                                .iter()
                                .any(|&st| v.with(t, st, &params).first_fits(&params))
                        })
                    })
                });
                return Err(Error::invalid(
                "params.max_layer_height",
                format!(
                    "the rim's height varies from {lo:.1} to {hi:.1} mm round the loop: the wall's first turn, starting a layer above the floor, would end more than {} mm above it wherever it starts; bring the rim's highest point to {:.1} mm or less, or raise params.max_layer_height{}",
                    params.max_layer_height,
                    lo + ok * (hi - lo),
                    places()
                ),
            ));
            }
            Err(Some(least)) => {
                let (least, i, over) = *least;
                // No layering clears by this estimate: print the thickest and
                // let the replay of the path judge (the checker names where the
                // body meets clay, and `--force` writes it); the estimate says
                // how far the rim's heights must come together.
                // The largest share of today's spread whose spiral clears.
                let (lo, hi, ok) = largest_share(&heights, 12, |h| {
                    VesselPlan::choose(h, &params, floor).is_ok_and(|w| {
                        clear_layering(&w, &starts, &near, h, exempt, &params).is_ok()
                    })
                });
                let c = &columns[i];
                let mut v = least;
                v.uneven = Some(crate::vessel::Uneven {
                    at: [c.p[0], c.p[1]],
                    over_mm: over,
                    spread_mm: hi - lo,
                    most_mm: ok * (hi - lo),
                    peaks,
                });
                v
            }
        };
        let rim = v.rim_beads(&near, &heights, exempt);
        (v, Some(rim))
    };
    Ok(vessel_samples(
        design,
        columns,
        length,
        params,
        printer,
        (start, end),
        v,
        rim,
    ))
}

/// The surface of a vessel laid out by `v` (docs/ALGORITHMS.md §8): each
/// column's spiral turns, its rim bead (where `rim` says, or, with a
/// raised arc, on every column: at its rim or the arc's level, half a
/// layer above the last turn at least), and a raised arc's passes and
/// top beads above.
#[allow(clippy::too_many_arguments)]
fn vessel_samples(
    design: &Design,
    mut columns: Vec<Column>,
    length: f64,
    params: Params,
    printer: Printer,
    (start, end): (Profile, Profile),
    v: VesselPlan,
    rim: Option<Vec<bool>>,
) -> Surface {
    let n = columns.len();
    let layers = v.turns;
    let plan = LayerPlan {
        passes: layers + 1,
        lower_passes: layers + 1,
        lower_layer_mm: v.turn_mm[0],
        upper_layer_mm: v.turn_mm[1],
        spread_mm: 0.0,
        first_toward_tall: true,
        min_top_bead_mm: 0.0,
    };
    let mut surface = Surface {
        name: design.name.clone(),
        columns: Vec::new(),
        samples: Vec::with_capacity(n * (layers as usize + 1)),
        plan,
        vessel: None,
        tall_at_end: true,
        start,
        end,
        trajectory_length: length,
        spacing: length / n as f64,
        params,
        printer,
        corners: Vec::new(),
        texture: Vec::new(),
        texture_label: (String::new(), 0.0),
    };
    // Each arc column's place in the arc.
    let mut in_arc = vec![usize::MAX; n];
    if let Some(a) = &v.arc {
        for (j, &c) in a.columns.iter().enumerate() {
            in_arc[c] = j;
        }
    }
    let half = 0.5 * v.base_layer_mm;
    for (i, col) in columns.iter_mut().enumerate() {
        col.first = surface.samples.len() as u32;
        col.passes = layers;
        let h = v.heights[i];
        let last = v.spiral_z(v.turns, i, n, h);
        let (rim_z, arc_z): (Option<f64>, Vec<f64>) = match (&v.arc, &rim) {
            (Some(a), _) if in_arc[i] != usize::MAX => {
                let j = in_arc[i];
                let passes = (1..=a.passes[j]).map(|k| a.level_mm + f64::from(k) * a.layer_mm);
                let top = a.has_top(j).then_some(a.top_z[j]);
                (Some(a.rim[j]), passes.chain(top).collect())
            }
            (Some(_), _) => (Some(col.height.max(last + half)), Vec::new()),
            (None, Some(r)) => (r[i].then_some(col.height), Vec::new()),
            (None, None) => (None, Vec::new()),
        };
        col.top = rim_z.is_some();
        col.extra = arc_z.len() as u32;
        let spiral = (1..=v.turns).map(|k| v.spiral_z(k, i, n, h));
        for z in spiral.chain(rim_z).chain(arc_z) {
            let xi = surface.design_offset(col, z, 1.0);
            surface.samples.push(Sample { z, xi });
        }
    }
    surface.columns = columns;
    surface.vessel = Some(v);
    surface
}

/// The layering of a vessel whose rim rises above what one spiral
/// carries: the highest level H (in steps of a quarter layer, at most
/// 200) at which the spiral over the rim cut at H clears the extruder
/// body by the sampling's estimate and the rim above H is one raised arc
/// ([`crate::vessel::RaisedArc`]); the spiral then starts just past the
/// arc, so that its rim turn ends at the arc's end. `None` where no level
/// serves; why not, where the rim rises in two or more places above
/// every level the spiral carries (one continuous path reaches only one).
fn raised_arc(
    h: &[f64],
    columns: &[Column],
    floor: u32,
    near: &crate::vessel::Neighbours,
    exempt: f64,
    params: &Params,
) -> std::result::Result<Option<VesselPlan>, String> {
    let n = h.len();
    let da = params.layer_height.min(0.5 * params.max_layer_height);
    let half = 0.5 * params.layer_height;
    let lo = h.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = h.iter().copied().fold(0.0, f64::max);
    if hi - lo < da {
        return Ok(None);
    }
    // Why a level does not serve, where the rim rises twice there: which
    // rise to lower, and to what.
    let attempt = |level: f64| -> std::result::Result<VesselPlan, Option<String>> {
        let runs = raised_runs(h, level + 0.5 * da);
        if runs.is_empty() {
            return Err(None);
        }
        let hp: Vec<f64> = h.iter().map(|&x| x.min(level)).collect();
        let w = VesselPlan::choose(&hp, params, floor).map_err(|_| None)?;
        if runs.len() > 1 {
            return Err(Some(several_rises(h, columns, level, da, runs)));
        }
        let (a, len) = runs[0];
        let end = (a + len - 1) % n;
        let mut plan =
            clear_layering(&w, &[(end + 1) % n], near, &hp, exempt, params).map_err(|_| None)?;
        let cols: Vec<usize> = (0..len).map(|j| (a + j) % n).collect();
        let last: Vec<f64> = cols
            .iter()
            .map(|&i| plan.spiral_z(plan.turns, i, n, hp[i]))
            .collect();
        let rims: Vec<f64> = cols.iter().map(|&i| h[i]).collect();
        let arc = crate::vessel::RaisedArc::new(level, da, cols, &rims, &last, half).map_err(
            |(j, most)| {
                let i = (a + j) % n;
                Some(format!(
                    "the rim rises twice above the {level:.1} mm one spiral carries round the loop, and one continuous path can print only one raised part: near ({:.0}, {:.0}) mm it rises again, to {:.1} mm; lower it there to {most:.1} mm or less",
                    columns[i].p[0], columns[i].p[1], h[i]
                ))
            },
        )?;
        // The rim turn, every column's bead as `vessel_samples` lays it,
        // must pass under no clay: a lower level flattens the rim the
        // spiral carries.
        let mut rim: Vec<f64> = (0..n)
            .map(|i| h[i].max(plan.spiral_z(plan.turns, i, n, hp[i]) + half))
            .collect();
        for (j, &c) in arc.columns.iter().enumerate() {
            rim[c] = arc.rim[j];
        }
        if !plan.rim_turn_clears(near, &hp, &rim, exempt) || !arc.body_clears(near, exempt) {
            return Err(None);
        }
        plan.arc = Some(arc);
        Ok(plan)
    };
    // From the top down in steps of two layers, then the quarter layers
    // above the first that serves (each level costs a layering's body
    // check; 200 quarter layers took 33 ms on a pitcher).
    let fine = (0.25 * da).max((hi - lo) / 200.0);
    let coarse = 8.0 * fine;
    let top = hi - 0.5 * da;
    let mut why: Option<String> = None;
    let mut level = top;
    loop {
        level -= coarse;
        if level < lo {
            break;
        }
        match attempt(level) {
            Ok(plan) => {
                let mut finer = (level + coarse - fine).min(top - fine);
                while finer > level + 0.5 * fine {
                    if let Ok(better) = attempt(finer) {
                        return Ok(Some(better));
                    }
                    finer -= fine;
                }
                return Ok(Some(plan));
            }
            Err(Some(w)) => why = Some(w),
            Err(None) => {}
        }
    }
    // The quarter layers under the lowest two-layer step, down to the
    // lowest rim, where the spiral's rim is nearly level.
    level += coarse;
    loop {
        level -= fine;
        if level < lo {
            break;
        }
        match attempt(level) {
            Ok(plan) => return Ok(Some(plan)),
            Err(Some(w)) => why = Some(w),
            Err(None) => {}
        }
    }
    why.map_or(Ok(None), Err)
}

/// Why a rim that rises above `level` in the `runs` of columns does not
/// print as one raised part: the second highest, and the most it may
/// rise (`da`: the passes' layer).
fn several_rises(
    h: &[f64],
    columns: &[Column],
    level: f64,
    da: f64,
    mut runs: Vec<(usize, usize)>,
) -> String {
    let n = h.len();
    let peak = |&(a, len): &(usize, usize)| {
        (0..len)
            .map(|j| (a + j) % n)
            .max_by(|&x, &y| h[x].total_cmp(&h[y]))
            .unwrap_or(a)
    };
    runs.sort_by(|x, y| h[peak(y)].total_cmp(&h[peak(x)]));
    let second = peak(&runs[1]);
    let c = &columns[second];
    format!(
        "the rim rises in {} places above the {level:.1} mm one spiral carries round the loop, and one continuous path can print only one raised part: the second, near ({:.0}, {:.0}) mm, rises to {:.1} mm; lower it to {:.1} mm or less, or raise the rim between the raised parts above {level:.1} mm so that they become one",
        runs.len(),
        c.p[0],
        c.p[1],
        h[second],
        level + 0.5 * da
    )
}

/// The runs of columns (first, count) round a loop whose rims `h` stand
/// above `above`.
fn raised_runs(h: &[f64], above: f64) -> Vec<(usize, usize)> {
    let n = h.len();
    let up: Vec<bool> = h.iter().map(|&x| x > above).collect();
    let Some(low) = up.iter().position(|&u| !u) else {
        return vec![(0, n)];
    };
    let mut runs = Vec::new();
    let mut m = 0;
    while m < n {
        let i = (low + m) % n;
        if up[i] {
            let first = i;
            let mut len = 0;
            while m < n && up[(low + m) % n] {
                len += 1;
                m += 1;
            }
            runs.push((first, len));
        } else {
            m += 1;
        }
    }
    runs
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
