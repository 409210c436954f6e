//! A design's size before it is sampled: the length of Ψ, an upper bound
//! and an estimate of the surface samples, and the sample cap
//! (docs/PERFORMANCE.md, "The size cap").

use crate::{surface, texture, Design, Error, Params, Result};

/// The length of Ψ (mm) without resampling it: a spline flattened to
/// a few dozen points a span (its control polygon can be twice as
/// long as the curve), a polyline's own. NaN when a coordinate is not
/// a number.
pub fn trajectory_length(d: &Design) -> f64 {
    use crate::bspline::polyline_length as poly;
    let t = &d.trajectory;
    let pts = t.given_points();
    match (&t.control_points, pts.len()) {
        (Some(cp), m) if t.closed && m >= 3 => poly(&crate::curves::periodic_bspline(cp, 32)),
        (Some(cp), m) if m >= 2 => {
            crate::bspline::BSpline::clamped(cp.clone()).map_or(poly(pts), |c| poly(&c.flatten(32)))
        }
        (None, m) if t.closed && m > 1 => poly(pts) + crate::bspline::dist(pts[m - 1], pts[0]),
        _ => poly(pts),
    }
}

/// A bound on the number of path points, from the curves without
/// sampling anything (a server refuses a design before it allocates
/// anything for it): columns (Ψ's length / spacing + 1) times the
/// samples a column can get — a wall's mean height over the layer
/// height (flat layers, the most the layering chooses), a vessel's
/// lowest (its spiral turns), its rim turn and the partial layers of a
/// raised rim above — plus a vessel's floor spirals, a pitch apart over
/// the control polygon's area. [`estimated_samples`] narrows it.
/// Textures' finer sampling counted. NaN when a
/// coordinate is not a number (slicing then names it).
pub fn samples_bound(d: &Design) -> f64 {
    let t = &d.trajectory;
    // The sampling a texture asks for (idempotent: `d` may be refined).
    let p = &d.texture_params();
    let top =
        |c: &crate::design::CurveSpec| c.control_points.iter().map(|p| p[1]).fold(0.0, f64::max);
    let (zs, zt) = (top(&d.profile_start), top(&d.end_profile()));
    let per_column = if t.closed {
        // The spiral under the lower rim, a rim turn, and a raised arc's
        // passes of at most min(Δz_min, Δz_max/2) and its top above
        // (docs/ALGORITHMS.md §8).
        let arc_layer = p.layer_height.min(0.5 * p.max_layer_height);
        zs.min(zt) / p.layer_height + (zs - zt).abs() / arc_layer + 3.0
    } else {
        // The mean of λ(u) (0.5 for the default f(u) = u).
        let f = crate::curves::Interpolation::new(d.interpolation.as_ref());
        let mean = f.map_or(0.5, |f| {
            (0..=64).map(|k| f.eval(k as f64 / 64.0)).sum::<f64>() / 65.0
        });
        ((1.0 - mean) * zs + mean * zt) / p.layer_height + 1.0
    };
    (trajectory_length(d) / p.spacing + 1.0) * per_column + floor_bound(d, p)
}

/// At most how many path points a vessel's floor takes at the sampling
/// `p`: its layers of beads a pitch apart over the control polygon's
/// area (0 for a wall).
pub(crate) fn floor_bound(d: &Design, p: &Params) -> f64 {
    let t = &d.trajectory;
    let pts = t.given_points();
    if !t.closed || pts.len() < 2 {
        return 0.0;
    }
    let area = 0.5 * crate::plane::signed_area2(pts).abs();
    let pitch = p.width_min * (1.0 - crate::design::FLOOR_OVERLAP);
    let layers = p
        .floor_layers
        .unwrap_or(crate::design::DEFAULT_FLOOR_LAYERS);
    1.5 * area / (pitch * p.spacing) * f64::from(layers)
}

/// Most columns the estimate samples a wall at (coarser than its spacing
/// where it has more): enough to see its layering, far from its cost.
const ESTIMATE_COLUMNS: f64 = 2000.0;

/// Most samples the estimate's coarse sampling may take.
const ESTIMATE_SAMPLES: f64 = 200_000.0;

/// The number of path points a design will have, within about 20 %
/// (docs/PERFORMANCE.md, "The size cap"): for a wall, the samples a
/// column gets in a sampling of at most 2,000 columns (the layering as
/// slicing will choose it: tilted passes give every column the short
/// end's count, flat ones each its own height's) times the columns at
/// the design's spacing (a vessel's floor bounded as in
/// [`samples_bound`]); where that coarse sampling would be large or
/// fails, [`samples_bound`].
pub fn estimated_samples(design: &Design) -> f64 {
    let d = design.printed();
    let bound = samples_bound(&d);
    let length = trajectory_length(&d);
    let columns = length / d.params.spacing + 1.0;
    // `printed` has the textures' sampling already.
    let floor = floor_bound(&d, &d.params);
    let per_column = (bound - floor) / columns;
    if !bound.is_finite() || !length.is_finite() {
        return bound;
    }
    let coarse_columns = ESTIMATE_COLUMNS.min(ESTIMATE_SAMPLES / per_column.max(1.0));
    if coarse_columns < 50.0 {
        return bound;
    }
    let mut coarse = d.clone();
    coarse.params.spacing = d.params.spacing.max(length / coarse_columns);
    // A vessel's wall as the coarse sampling lays it (its spiral's turns
    // and any raised arc), and its floor's bound.
    match surface::sample_surface(&coarse) {
        Ok(s) if !s.columns.is_empty() => {
            s.samples.len() as f64 / s.columns.len() as f64 * columns + floor
        }
        _ => bound,
    }
}

/// Refuses, before the design is sampled at its spacing, one with a
/// parameter out of its range or whose [`estimated_samples`] is over
/// `max_samples` ([`Error::TooLarge`]): the cap on work, without
/// [`check_size`]'s early fit check (for a preview that shows what
/// leaves the printer).
pub fn check_samples(design: &Design, max_samples: f64) -> Result<()> {
    // A parameter out of its range is that, not a huge estimate (a layer
    // height of 0 is no "infinitely many samples").
    design.params.validate()?;
    design.check_texture()?;
    let estimate = estimated_samples(design);
    if estimate > max_samples {
        // Over the cap only for the sampling a texture asks: name it.
        let mut plain = design.clone();
        plain.texture.clear();
        if !design.texture.is_empty() && estimated_samples(&plain) <= max_samples {
            let d = design.printed();
            let [along, up] =
                texture::needs(&d.texture, trajectory_length(&d), d.trajectory.closed);
            let k = up.or(along).map_or(0, |(_, k)| k);
            return Err(Error::invalid(
                format!("texture[{k}]"),
                format!(
                    "needs samples {:.2} mm apart and layers of at most {:.2} mm to show ({} a period): about {estimate:.0} samples, over the cap of {max_samples:.0}; lengthen its period, use fewer ribs, or make the piece smaller",
                    d.params.spacing,
                    d.params.max_layer_height,
                    texture::SAMPLES_PER_PERIOD
                ),
            ));
        }
        return Err(Error::TooLarge {
            estimate,
            limit: max_samples,
        });
    }
    Ok(())
}

/// [`check_samples`], then [`Design::check_fit`].
pub fn check_size(design: &Design, max_samples: f64) -> Result<()> {
    check_samples(design, max_samples)?;
    design.check_fit()
}
