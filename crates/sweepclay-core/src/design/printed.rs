//! The design as printed (docs/FORMATS.md, "shrinkage" and "texture"):
//! enlarged for the kiln, its sampling refined for its textures, its
//! textures and its size checked against the printer.

use super::*;

impl Design {
    /// The piece as printed: the geometry enlarged by 1 / (1 − s) across
    /// (profiles' offsets, Ψ) and in height (profiles' z) for the firing
    /// shrinkages `params.shrinkage_xy` and `shrinkage_z`, so that it has
    /// the designed size after the kiln (docs/ALGORITHMS.md §6). Layer
    /// heights, bead widths and the printer are not scaled: they are the
    /// process, not the piece. Without shrinkage, the design itself.
    pub fn printed(&self) -> Design {
        let mut d = self.scaled_for_firing();
        d.params = d.texture_params();
        d
    }

    /// The sampling the textures ask for: the spacing and the thickest
    /// layer that give each texture 8 samples a period (never under the
    /// thinnest layer [`Params::validate`] allows; [`Design::check_texture`]
    /// refuses a texture that would need less).
    pub(crate) fn texture_params(&self) -> Params {
        let mut p = self.params.clone();
        if self.texture.is_empty() {
            return p;
        }
        let length = crate::trajectory_length(self);
        let [along, up] = crate::texture::needs(&self.texture, length, self.trajectory.closed);
        if let Some((s, _)) = along.filter(|(s, _)| s.is_finite() && *s > 0.0) {
            p.spacing = p.spacing.min(s.max(MIN_SPACING));
        }
        if let Some((z, _)) = up.filter(|(z, _)| z.is_finite()) {
            p.max_layer_height = p.max_layer_height.min(z.max(MIN_LAYER));
            // Room below it, so a column's height splits into whole layers.
            p.layer_height = p
                .layer_height
                .min((0.6 * p.max_layer_height).max(MIN_LAYER))
                .min(p.max_layer_height);
        }
        p
    }

    /// Checks the textures and the twist, and refuses a texture whose
    /// period is too short to sample (it would need layers thinner than
    /// [`MIN_LAYER`] or a spacing under [`MIN_SPACING`]), naming it.
    pub fn check_texture(&self) -> Result<()> {
        crate::texture::validate(&self.texture, self.twist_deg, self.trajectory.closed)?;
        if self.texture.is_empty() {
            return Ok(());
        }
        let d = self.scaled_for_firing();
        let length = crate::trajectory_length(&d);
        let [along, up] = crate::texture::needs(&d.texture, length, d.trajectory.closed);
        if let Some((z, k)) = up.filter(|(z, _)| *z < MIN_LAYER) {
            return Err(Error::invalid(
                format!("texture[{k}]"),
                format!(
                    "needs layers of {z:.2} mm to show ({} samples a period in height), thinner than the thinnest layer ({MIN_LAYER} mm); make its period (or pitch) at least {} mm",
                    crate::texture::SAMPLES_PER_PERIOD,
                    MIN_LAYER * crate::texture::SAMPLES_PER_PERIOD
                ),
            ));
        }
        if let Some((s, k)) = along.filter(|(s, _)| *s < MIN_SPACING) {
            return Err(Error::invalid(
                format!("texture[{k}]"),
                format!(
                    "needs samples {s:.3} mm apart along the trajectory to show, closer than {MIN_SPACING} mm; use fewer ribs"
                ),
            ));
        }
        Ok(())
    }

    /// The design enlarged for the firing shrinkage, textures included.
    pub(super) fn scaled_for_firing(&self) -> Design {
        let [kxy, kz] = self.params.print_scale();
        self.scaled_by(kxy, kz)
    }

    /// The design as it would be drawn `scale` times as large (every
    /// length: the path, the profiles, the rim, the textures, a relief)
    /// and turned `turn_deg` degrees counter-clockwise about o seen from
    /// above: a mesh-backed design moved to the size and the side a
    /// potter wants (docs/MESHES.md). Scale 0.01 to 100, turn −360 to
    /// 360, each refused naming its key.
    pub fn transformed(&self, scale: f64, turn_deg: f64) -> crate::Result<Design> {
        if !(scale.is_finite() && (0.01..=100.0).contains(&scale)) {
            return Err(Error::invalid(
                "scale",
                format!("must be a factor from 0.01 to 100 (got {scale})"),
            ));
        }
        if !(turn_deg.is_finite() && (-360.0..=360.0).contains(&turn_deg)) {
            return Err(Error::invalid(
                "turn",
                format!("must be an angle from -360 to 360 degrees (got {turn_deg})"),
            ));
        }
        let mut d = self.scaled_by(scale, scale);
        let (s, c) = turn_deg.to_radians().sin_cos();
        let t = &mut d.trajectory;
        for pts in [t.control_points.as_mut(), t.points.as_mut()]
            .into_iter()
            .flatten()
        {
            for p in pts.iter_mut() {
                *p = [c * p[0] - s * p[1], s * p[0] + c * p[1]];
            }
        }
        if let Some(r) = d.rim.as_mut() {
            r.toward_deg = (r.toward_deg + turn_deg + 180.0).rem_euclid(360.0) - 180.0;
        }
        Ok(d)
    }

    /// The design scaled by `kxy` across and `kz` in height.
    fn scaled_by(&self, kxy: f64, kz: f64) -> Design {
        let mut d = self.clone();
        if kxy == 1.0 && kz == 1.0 {
            return d;
        }
        for c in std::iter::once(&mut d.profile_start).chain(d.profile_end.as_mut()) {
            // A scaled curve passes through its scaled rows (affine
            // invariance).
            for p in c
                .control_points
                .iter_mut()
                .chain(c.points.iter_mut().flatten())
            {
                *p = [p[0] * kxy, p[1] * kz];
            }
        }
        d.texture = self.texture.iter().map(|t| t.scaled(kxy, kz)).collect();
        if let Some(r) = d.rim.as_mut() {
            r.rise *= kz;
        }
        d.relief = self.relief.as_ref().map(|r| r.scaled(kxy, kz));
        let t = &mut d.trajectory;
        for pts in [t.control_points.as_mut(), t.points.as_mut()]
            .into_iter()
            .flatten()
        {
            for p in pts.iter_mut() {
                *p = [p[0] * kxy, p[1] * kxy];
            }
        }
        d
    }

    /// Refuses, before anything is sampled, a control point that puts the
    /// surface far outside the printer: a curve lies within its control
    /// points' hull, so Ψ's points and the profiles' widest offset bound
    /// the surface. Past the build volume by more than the volume's own
    /// size, no design fits, and sampling one (a profile point 100 km
    /// out) would take gigabytes before the exact check after sampling
    /// could say so. The point is named.
    fn reach_within(&self, this: &Design, pr: &crate::Printer) -> crate::Result<()> {
        let profiles = [
            ("profile_start", &this.profile_start),
            ("profile_end", &this.end_profile()),
        ];
        let widest = profiles
            .iter()
            .flat_map(|(k, c)| {
                c.control_points
                    .iter()
                    .enumerate()
                    .map(move |(i, p)| (*k, i, p[0].abs()))
            })
            .fold(
                ("profile_start", 0, 0.0f64),
                |m, x| if x.2 > m.2 { x } else { m },
            );
        let t = &this.trajectory;
        let key = if t.control_points.is_some() {
            "control_points"
        } else {
            "points"
        };
        for (i, p) in t.given_points().iter().enumerate() {
            for a in 0..2 {
                let (min, size) = (pr.bed_min[a], pr.build_volume[a]);
                let at = pr.origin[a] + p[a];
                let (lo, hi) = (at - widest.2, at + widest.2);
                if lo > min + 2.0 * size || hi < min - size {
                    return Err(Error::invalid(
                        format!("trajectory.{key}[{i}]"),
                        format!(
                            "the design does not fit printer `{1}`: this point puts the piece at {0} = {at:.0} mm, and the build volume spans {min:.0}..{2:.0} mm",
                            ['x', 'y'][a],
                            pr.name,
                            min + size
                        ),
                    ));
                }
            }
        }
        let room = pr.build_volume[0].max(pr.build_volume[1]);
        if widest.2 > room {
            let (k, i, x) = widest;
            return Err(Error::invalid(
                format!("{k}.control_points[{i}]"),
                format!(
                    "the design does not fit printer `{}`: this point sets the wall {x:.0} mm out from its path, more than the whole build volume ({room:.0} mm)",
                    pr.name
                ),
            ));
        }
        Ok(())
    }

    /// Refuses, before anything is sampled, a design that cannot fit its
    /// printer: the surface starts and ends at Ψ's first and last points
    /// on the bed and is as tall there as the profiles, so if those leave
    /// the build volume the whole does ([`Error::DoesNotFit`], as slicing
    /// would say). A closed B-spline Ψ does not pass through its control
    /// points, so for a closed Ψ the height and the reach of its control points are
    /// checked here (slicing checks the rest). [`crate::check_size`] adds the cap on work.
    pub fn check_fit(&self) -> crate::Result<()> {
        let printed = self.printed();
        let this = &printed;
        let pr = self.printer.resolve()?;
        let t = &this.trajectory;
        let pts = t.given_points();
        let top = |c: &CurveSpec| c.control_points.last().map_or(0.0, |p| p[1]);
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let ends = pts
            .first()
            .into_iter()
            .chain(pts.last())
            .filter(|_| !t.closed);
        for p in ends {
            for a in 0..2 {
                lo[a] = lo[a].min(pr.origin[a] + p[a]);
                hi[a] = hi[a].max(pr.origin[a] + p[a]);
            }
        }
        lo[2] = 0.0;
        hi[2] = top(&this.profile_start).max(top(&this.end_profile()));
        self.reach_within(this, &pr)?;
        for a in 0..3 {
            let (min, max) = (pr.bed_min[a], pr.bed_min[a] + pr.build_volume[a]);
            if lo[a] < min - 1e-9 || hi[a] > max + 1e-9 {
                return Err(Error::DoesNotFit {
                    printer: pr.name.clone(),
                    axis: ['x', 'y', 'z'][a],
                    min: lo[a],
                    max: hi[a],
                    low: min,
                    limit: max,
                });
            }
        }
        Ok(())
    }
}
