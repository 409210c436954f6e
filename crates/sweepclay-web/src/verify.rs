//! Sliced design → G-code → independent check (docs/CHECKER.md): what `slice`
//! and the modeler's download both run before they hand out a file, and the
//! way back from a failing G-code line to the place in the design.

use crate::guard::{Cancel, CancelWriter};
use std::io::{self, Write};
use sweepclay_check::{CheckConfig, CheckWriter, Finding, Report};
use sweepclay_core::correct::{correct_with, Tightening};
use sweepclay_core::toolpath::PointKind;
use sweepclay_core::{gcode, surface, Design, Params, Printer, Sliced};

/// The checker's defaults with the printer's build volume, calibration and
/// extruder body.
pub fn printer_check(p: &Printer) -> CheckConfig {
    CheckConfig {
        build_volume: p.build_volume,
        bed_min: p.bed_min,
        bed_diameter: p.bed_diameter,
        printer: p.name.clone(),
        e_per_mm3: p.e_per_mm3,
        nozzle_radius: p.nozzle_radius,
        ..CheckConfig::default()
    }
}

/// The check a sliced design must pass: the printer's, with the design's
/// parameters.
pub fn check_config(p: &Printer, params: &Params) -> CheckConfig {
    let base = printer_check(p);
    CheckConfig {
        nozzle_height: params.nozzle_height,
        width_min: params.width_min,
        width_max: params.width_max,
        overlap_target: params.overlap,
        max_overhang_deg: params.max_overhang_deg,
        first_layer_max_mm: base.first_layer_max_mm.max(params.max_layer_height + 0.05),
        ..base
    }
}

/// G-code of a sliced design with the check's verdict on it.
#[derive(Debug)]
pub struct Verified {
    /// The G-code text.
    pub gcode: String,
    /// The checker's report.
    pub report: Report,
    /// Where in the design the first failure of each kind is (see [`locate`]).
    pub locations: Vec<String>,
    /// What to change in the design, failure by failure (see
    /// [`Checked::advice`]; empty when printable or not asked for).
    pub advice: Vec<String>,
    /// How far the corrections moved the shape, when beyond
    /// `params.max_correction_mm` (`CorrectionReport::reshaped`).
    pub reshaped: Option<String>,
}

/// Writes to two writers.
struct Tee<A, B>(A, B);

impl<A: Write, B: Write> Write for Tee<A, B> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.0.write_all(buf)?;
        self.1.write_all(buf)?;
        Ok(buf.len())
    }
    fn flush(&mut self) -> io::Result<()> {
        self.0.flush()?;
        self.1.flush()
    }
}

/// Writes the G-code of `s` to `out` and checks it in the same pass,
/// refusing beads that overlap the bead below by less than `min_overlap`
/// of their width. Nothing of the text is kept: `out` may be a file of any
/// size. Returns the report and where in the design its failures are.
pub fn verify_into<W: Write>(
    s: &Sliced,
    min_overlap: f64,
    out: W,
) -> io::Result<(Report, Vec<String>)> {
    verify_lines(s, min_overlap, out).map(|(r, l, _)| (r, l))
}

/// [`verify_into`], with the G-code line of each path point.
fn verify_lines<W: Write>(
    s: &Sliced,
    min_overlap: f64,
    out: W,
) -> io::Result<(Report, Vec<String>, Vec<usize>)> {
    let surface = &s.corrected.surface;
    let cfg = CheckConfig {
        overlap_min: min_overlap,
        ..check_config(&surface.printer, &surface.params)
    };
    let mut tee = Tee(
        out,
        CheckWriter::with_capacity(&cfg, s.toolpath.points.len()),
    );
    let point_lines = gcode::emit(s, &mut tee)?;
    tee.flush()?;
    let Tee(_, checker) = tee;
    let report = checker.finish();
    let locations = failure_lines(&report)
        .into_iter()
        .take(5)
        .filter_map(|l| locate(s, &point_lines, l))
        .collect();
    Ok((report, locations, point_lines))
}

/// Most rounds of the correction loop after the first slicing.
pub const MAX_ROUNDS: u32 = 8;

/// What the correction loop ends with: the last slicing, its G-code's
/// writer, and the check of it.
pub struct Checked<W> {
    /// The design as sliced in the last round.
    pub sliced: Sliced,
    /// Where its G-code went.
    pub out: W,
    /// The check of that G-code.
    pub report: Report,
    /// Where in the design its failures are.
    pub locations: Vec<String>,
    /// The G-code line of each path point.
    pub point_lines: Vec<usize>,
}

impl<W> Checked<W> {
    /// For each kind of failure the loop could not correct: the cause,
    /// the place (G-code line, pass, curve, u, z) and the change to the
    /// design that would fix it. Empty when printable.
    pub fn advice(&self) -> Vec<String> {
        let s = &self.sliced;
        let p = &s.corrected.surface.params;
        let r = s.corrected.surface.printer.nozzle_radius;
        let rounds = s.corrected.report.rounds;
        let uneven = s
            .corrected
            .surface
            .vessel
            .as_ref()
            .and_then(|v| v.uneven.as_ref());
        let tried = if rounds > 0 {
            format!(" (after {rounds} round(s) of tightened corrections)")
        } else {
            String::new()
        };
        Finding::ALL
            .iter()
            .filter_map(|&k| {
                let c = &self.report.findings[k];
                let line = c.first_line?;
                let worst = c.worst.map_or(0.0, |w| w.0);
                let place = locate(s, &self.point_lines, line)
                    .unwrap_or_else(|| format!("line {line}"));
                let change = match k {
                    Finding::Overhang => format!(
                        "an overhang of {worst:.0}° beyond the {}° limit{tried}: lean the profiles less there, or raise params.max_overhang_deg if your clay stands steeper",
                        p.max_overhang_deg
                    ),
                    Finding::UnderMinOverlap => format!(
                        "a bead overlapping the one below by too little{tried}: lean the profiles less there, or raise params.width_max ({} mm) so a wider bead reaches",
                        p.width_max
                    ),
                    Finding::NozzleCollision if uneven.is_some_and(|u| u.peaks.is_some()) => {
                        let why = uneven.and_then(|u| u.peaks.as_ref()).expect("matched");
                        format!("the extruder body ({r} mm radius) meets clay {worst:.1} mm above the nozzle{tried}: {why}")
                    }
                    Finding::NozzleCollision if uneven.is_some() => {
                        let u = uneven.expect("matched");
                        format!(
                            "the extruder body ({r} mm radius) meets clay {worst:.1} mm above the nozzle{tried}: the rim rises or falls too steeply round the loop for one spiral (first near ({:.0}, {:.0}) mm); bring the rim's heights within {:.1} mm of each other (now {:.1} mm apart)",
                            u.at[0], u.at[1], u.most_mm, u.spread_mm
                        )
                    }
                    Finding::NozzleCollision => format!(
                        "the extruder body ({r} mm radius) meets clay {worst:.1} mm above the nozzle{tried}: keep that part of the wall more than {:.0} mm in plan from the rest of it, or bring the two profiles' heights closer so the passes tilt less",
                        r + p.width_max / 2.0
                    ),
                    Finding::DoubleDeposition => "clay laid on clay of its own layer: move those parts of the trajectory apart, or lower params.width_max".to_string(),
                    Finding::TurnPile => "clay piling up where the path turns: lower params.max_layer_height, or set params.even_turn_flow".to_string(),
                    Finding::Unsupported => "a bead with no clay under it: lean the profiles less there".to_string(),
                    Finding::OutOfBounds => "outside the printer's build volume: make the design smaller or choose a larger printer".to_string(),
                    other => other.failure().to_string(),
                };
                Some(format!("{change} — at {place}"))
            })
            .collect()
    }
}

/// Why a slicing whose check fails cannot be corrected: the error
/// [`slice_checked`] ends with.
#[derive(Debug)]
pub enum Unchecked {
    /// The design does not slice (validation, sampling, corrections).
    Design(sweepclay_core::Error),
    /// Writing the G-code failed, or the work was cancelled.
    Io(io::Error),
}

impl From<sweepclay_core::Error> for Unchecked {
    fn from(e: sweepclay_core::Error) -> Self {
        Unchecked::Design(e)
    }
}

impl From<io::Error> for Unchecked {
    fn from(e: io::Error) -> Self {
        Unchecked::Io(e)
    }
}

impl std::fmt::Display for Unchecked {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Unchecked::Design(e) => e.fmt(f),
            Unchecked::Io(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for Unchecked {}

/// Ends the work once `cancel` is set.
fn go_on(cancel: &Cancel) -> Result<(), Unchecked> {
    match cancel.check() {
        Ok(()) => Ok(()),
        Err(e) => Err(Unchecked::Io(io::Error::other(e.error))),
    }
}

/// Slices `design`, writes its G-code to a writer `out` makes and checks
/// it in the same pass; while the check fails for a reason a correction
/// can fix, tightens the corrections where it failed and does it again,
/// at most [`MAX_ROUNDS`] more times (docs/ALGORITHMS.md §4, "The loop
/// closes"). An overhang or a bead short of the overlap tightens the
/// support-free correction on the transition curves within a bead of
/// each failure; the extruder body meeting clay compresses all offsets,
/// by steps and then by bisection, to the least compression that
/// clears. A design that passes at once costs one slicing and one check.
/// Returns the printable slicing the loop found, or else its last.
pub fn slice_checked<W: Write>(
    design: &Design,
    min_overlap: f64,
    cancel: &Cancel,
    out: impl FnMut() -> io::Result<W>,
) -> Result<Checked<W>, Unchecked> {
    slice_checked_drawn(design, min_overlap, cancel, out).map(|(c, _)| c)
}

/// [`slice_checked`], with the surface as sampled for the last round
/// (the drawing the corrections started from, its corners rounded if
/// the loop rounded them): what the preview compares the print with.
pub fn slice_checked_drawn<W: Write>(
    design: &Design,
    min_overlap: f64,
    cancel: &Cancel,
    mut out: impl FnMut() -> io::Result<W>,
) -> Result<(Checked<W>, surface::Surface), Unchecked> {
    let mut sampled = surface::sample_surface(design)?;
    go_on(cancel)?;
    let w_max = sampled.params.width_max;
    // Compressing offsets cannot help a vessel whose rim's heights are
    // what meets the body.
    let has_offsets = (sampled.samples.iter().any(|s| s.xi.abs() > 1e-9)
        || sampled.texture.iter().any(|d| d.abs() > 1e-9))
        && sampled.vessel.as_ref().is_none_or(|v| v.uneven.is_none());
    let mut tight = Tightening::default();
    // Body compression factors: the smallest known to collide, the
    // largest known to clear (with the tightening that cleared).
    let mut collides = 1.0f64;
    let mut clears: Option<(f64, Tightening)> = None;
    // Corners of a polyline Ψ where failures stay: how often each was
    // hit, and the radius it is rounded by.
    let vertices = design.trajectory.points.clone().unwrap_or_default();
    let mut hits = vec![0u32; vertices.len()];
    let mut radius: Vec<Option<f64>> = vec![None; vertices.len()];
    let mut round = |sampled: &surface::Surface,
                     tight: &Tightening|
     -> Result<(Checked<W>, Vec<usize>, bool), Unchecked> {
        let corrected = correct_with(sampled, tight)?;
        go_on(cancel)?;
        let sliced = sweepclay_core::finish(corrected)?;
        let mut w = out()?;
        let (report, locations, lines) =
            verify_lines(&sliced, min_overlap, CancelWriter(&mut w, cancel.clone()))?;
        let mut support: Vec<usize> = [Finding::Overhang, Finding::UnderMinOverlap]
            .iter()
            .flat_map(|&k| report.findings[k].lines.iter())
            .filter_map(|&l| {
                let i = lines.partition_point(|&x| x < l);
                (lines.get(i) == Some(&l)).then(|| sliced.toolpath.points[i].column as usize)
            })
            .collect();
        support.sort_unstable();
        support.dedup();
        let body = report.findings[Finding::NozzleCollision].count > 0;
        let checked = Checked {
            sliced,
            out: w,
            report,
            locations,
            point_lines: lines,
        };
        Ok((checked, support, body))
    };
    loop {
        let (checked, support, body) = round(&sampled, &tight)?;
        let printable = checked.report.printable;
        if printable {
            let Some(f) = tight.body else {
                return Ok((checked, sampled));
            };
            clears = Some((f, tight.clone()));
            if collides - f <= 0.02 || tight.rounds >= MAX_ROUNDS {
                return Ok((checked, sampled));
            }
        } else if let Some(f) = tight.body.filter(|_| body) {
            collides = collides.min(f);
        }
        let fixable = !support.is_empty() || (body && has_offsets);
        if tight.rounds >= MAX_ROUNDS || (!printable && !fixable) {
            // The last printable round, if the bisection went past it.
            return match clears {
                Some((_, t)) if !printable => {
                    let c = round(&sampled, &t)?.0;
                    Ok((c, sampled))
                }
                _ => Ok((checked, sampled)),
            };
        }
        tight.rounds += 1;
        // A failure that stays by a corner of a polyline Ψ (the second
        // round it is within two beads of it) rounds that corner, by w_max
        // and then by at most 2 w_max (reported with the corners).
        let mut rounded = false;
        for &c in &support {
            let p = checked.sliced.corrected.surface.columns[c].p;
            let near = (0..vertices.len())
                .filter(|&i| design.trajectory.closed || (i > 0 && i + 1 < vertices.len()))
                .map(|i| (i, (vertices[i][0] - p[0]).hypot(vertices[i][1] - p[1])))
                .filter(|&(_, d)| d < 2.0 * w_max)
                .min_by(|a, b| a.1.total_cmp(&b.1));
            if let Some((i, _)) = near {
                hits[i] += 1;
                let next = match radius[i] {
                    None => Some(w_max),
                    Some(r) if r < 2.0 * w_max => Some(2.0 * w_max),
                    keep => keep,
                };
                if hits[i] >= 2 && next != radius[i] {
                    radius[i] = next;
                    rounded = true;
                }
            }
        }
        if rounded {
            let mut d = design.clone();
            let (pts, fixes) = sweepclay_core::curves::round_corners_by(
                &vertices,
                design.trajectory.closed,
                0.25 * sampled.params.spacing,
                |i, _| radius[i],
            );
            d.trajectory.points = Some(pts);
            sampled = surface::sample_surface(&d)?;
            sampled.corners.extend(fixes);
            // Columns are new: the tightening starts again from here.
            tight.support.clear();
            clears = None;
            collides = 1.0;
            continue;
        }
        if !support.is_empty() {
            let surface = &checked.sliced.corrected.surface;
            let g = tightening(
                &support,
                surface.columns.len(),
                surface.spacing,
                surface.vessel.is_some(),
            );
            tight.support.resize(g.len(), 1.0);
            for (t, g) in tight.support.iter_mut().zip(g) {
                *t = (*t * (1.0 - g)).max(0.05);
            }
        }
        if printable || (body && has_offsets) {
            tight.body = Some(match &clears {
                Some((f, _)) => 0.5 * (f + collides),
                None => 0.8 * tight.body.unwrap_or(1.0),
            });
        }
    }
}

/// How much the correction loop tightens each of `n` columns (`spacing`
/// mm apart along Ψ, round a loop if `closed`) where the check failed at
/// columns `failed`: 30 % at a failure, less farther off, to nothing
/// [`TIGHTEN_SPREAD_MM`] away, the most any failure asks (not their
/// product: fifty failing neighbours are one place). Spread so, the
/// tightening changes by at most 0.1 % a millimetre along Ψ and leaves
/// no fin: a box one bead wide, compounded per failure, once held a
/// sector of a pot at its foot's radius (docs/ALGORITHMS.md §4).
fn tightening(failed: &[usize], n: usize, spacing: f64, closed: bool) -> Vec<f64> {
    let reach = TIGHTEN_SPREAD_MM / spacing.max(1e-6);
    let mut g = vec![0.0f64; n];
    // Distance to the nearest failure, by two sweeps (twice round a loop).
    let mut near = vec![f64::INFINITY; n];
    for &c in failed {
        if c < n {
            near[c] = 0.0;
        }
    }
    let passes = if closed { 2 } else { 1 };
    for _ in 0..passes {
        for k in 1..=n.saturating_sub(1) + usize::from(closed) {
            let (a, b) = ((k - 1) % n, k % n);
            near[b] = near[b].min(near[a] + 1.0);
        }
        for k in (0..n.saturating_sub(1) + usize::from(closed)).rev() {
            let (a, b) = ((k + 1) % n, k);
            near[b] = near[b].min(near[a] + 1.0);
        }
    }
    for (g, d) in g.iter_mut().zip(near) {
        *g = 0.3 * (1.0 - d / reach).max(0.0);
    }
    g
}

/// How far along Ψ a failure's tightening reaches (mm): a 30 % change of
/// the limit over it is 0.1 % a millimetre.
const TIGHTEN_SPREAD_MM: f64 = 300.0;

/// [`verify_into`] a string.
pub fn verify(s: &Sliced, min_overlap: f64) -> Verified {
    verify_until(s, min_overlap, &Cancel::new()).expect("writing to memory cannot fail")
}

/// [`verify`], stopping (with an error) at the next 64 KiB of G-code once
/// `cancel` is set.
pub fn verify_until(s: &Sliced, min_overlap: f64, cancel: &Cancel) -> io::Result<Verified> {
    let mut text = Vec::with_capacity(gcode::size_hint(s));
    let (report, locations) = verify_into(s, min_overlap, CancelWriter(&mut text, cancel.clone()))?;
    Ok(Verified {
        gcode: String::from_utf8(text).expect("G-code is UTF-8"),
        report,
        locations,
        advice: Vec::new(),
        reshaped: s.corrected.reshaped(),
    })
}

/// The first line of each kind of failure in a report.
pub fn failure_lines(r: &Report) -> Vec<usize> {
    let mut v: Vec<usize> = r
        .findings
        .occurred()
        .filter_map(|(_, c)| c.first_line)
        .collect();
    v.sort_unstable();
    v.dedup();
    v
}

/// Where in the design a G-code line of our own output is, given the line
/// of each path point (`gcode::to_string_with_lines`).
pub fn locate(s: &Sliced, lines: &[usize], line: usize) -> Option<String> {
    let i = lines.partition_point(|&l| l < line);
    if lines.get(i) != Some(&line) {
        return None;
    }
    let p = &s.toolpath.points[i];
    let col = &s.corrected.surface.columns[p.column as usize];
    let top = if p.kind == PointKind::Top {
        ", top-edge bead"
    } else {
        ""
    };
    Some(format!(
        "line {line}: pass {}, transition curve {} (u = {:.3}), z = {:.2} mm{top}",
        p.pass, p.column, col.u, p.pos[2]
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use sweepclay_core::{examples, Design};

    #[test]
    fn tightening_spreads_gently_and_does_not_compound() {
        // 1 mm columns: 30 % at a failure, 15 % 150 mm off, none past
        // 300 mm; fifty failing neighbours ask no more than one.
        let g = tightening(&[100], 1000, 1.0, false);
        assert!((g[100] - 0.3).abs() < 1e-12 && (g[250] - 0.15).abs() < 1e-12);
        assert_eq!((g[400], g[999]), (0.0, 0.0));
        assert!((g[0] - 0.2).abs() < 1e-12);
        assert!(g.windows(2).all(|w| (w[1] - w[0]).abs() <= 0.001 + 1e-12));
        let many: Vec<usize> = (100..150).collect();
        assert!(tightening(&many, 1000, 1.0, false)
            .iter()
            .all(|&x| x <= 0.3));
        // Round a loop of 400 columns, the failure at 390 reaches 0 too.
        let g = tightening(&[390], 400, 1.0, true);
        assert!(
            (g[0] - 0.3 * (1.0 - 10.0 / 300.0)).abs() < 1e-12,
            "{}",
            g[0]
        );
        assert!(
            (g[190] - 0.3 * (1.0 - 200.0 / 300.0)).abs() < 1e-12,
            "{}",
            g[190]
        );
    }

    #[test]
    fn examples_verify_and_a_strict_floor_fails_with_locations() {
        let d = Design::from_json(examples::example("t4").unwrap()).unwrap();
        let s = sweepclay_core::slice(&d).unwrap();
        let ok = verify(&s, 0.5);
        assert!(ok.report.printable, "{:?}", ok.report.failures);
        assert!(ok.locations.is_empty());
        // Beads overlap the bead below by 2/3 or a bit more, never 99 %.
        let strict = verify(&s, 0.99);
        assert!(!strict.report.printable);
        assert!(
            strict.locations[0].contains("pass") && strict.locations[0].starts_with("line "),
            "{:?}",
            strict.locations
        );
    }

    fn checked(d: &Design, min_overlap: f64) -> Checked<Vec<u8>> {
        match slice_checked(d, min_overlap, &Cancel::new(), || Ok(Vec::new())) {
            Ok(c) => c,
            Err(e) => panic!("{e}"),
        }
    }

    #[test]
    fn a_design_that_passes_at_once_is_sliced_once() {
        let d = Design::from_json(examples::example("t4").unwrap()).unwrap();
        let c = checked(&d, 0.5);
        assert!(c.report.printable);
        assert_eq!(c.sliced.corrected.report.rounds, 0);
        assert!(c.advice().is_empty());
        // The G-code handed back is the one checked.
        assert_eq!(c.out, verify(&c.sliced, 0.5).gcode.into_bytes());
    }

    #[test]
    fn the_loop_tightens_where_the_check_failed_until_it_passes() {
        // t5's beads overlap the bead below by 85 % at least: asked for
        // 95 %, the loop narrows the support-free limit on the curves
        // where beads fell short, and reports how far that moved them.
        let d = Design::from_json(examples::example("t5").unwrap()).unwrap();
        let c = checked(&d, 0.95);
        assert!(c.report.printable, "{:?}", c.report.failures);
        let r = &c.sliced.corrected.report;
        assert!(r.rounds >= 1 && r.rounds <= MAX_ROUNDS, "{}", r.rounds);
        assert!(r
            .deviation
            .as_ref()
            .is_some_and(|d| d.mm > 0.0 && d.by == "support-free"));
        assert!(r
            .summary()
            .iter()
            .any(|l| l.starts_with("correction loop:")));
        // 99 % no tightening reaches: the loop stops, with what to change
        // and where.
        let c = checked(&d, 0.99);
        assert!(!c.report.printable);
        assert_eq!(c.sliced.corrected.report.rounds, MAX_ROUNDS);
        let advice = c.advice();
        assert!(
            advice[0].contains("lean the profiles less") && advice[0].contains("transition curve"),
            "{advice:?}"
        );
    }

    #[test]
    fn the_extruder_body_is_kept_off_a_far_part_of_the_wall() {
        // An S whose end flares out over its middle: the nozzle's body
        // (not the beads: no self-intersection) meets the clay there. The
        // loop compresses the offsets to the least factor that clears.
        let d = Design::from_json(
            r#"{"sweepclay": 1, "name": "S flaring over itself",
            "profile_start": {"control_points": [[0, 0], [0.518, 9.06], [0.518, 18.12], [0, 27.18]]},
            "profile_end": {"control_points": [[0, 0], [0, 18.65], [22.66, 37.31]]},
            "trajectory": {"control_points": [[-47.46, 0], [-23.73, 23.73], [0, 0], [23.73, -23.73], [47.46, 0]], "offset": "normal"},
            "params": {"layer_height": 1.4, "max_layer_height": 2.8, "width_min": 7.03, "width_max": 14.06},
            "printer": "wasp-2040-clay"}"#,
        )
        .unwrap();
        let first = verify(&sweepclay_core::slice(&d).unwrap(), 0.5);
        assert!(first.report.findings[Finding::NozzleCollision].count > 0);
        let c = checked(&d, 0.5);
        assert!(c.report.printable, "{:?}", c.report.failures);
        let r = &c.sliced.corrected.report;
        let f = r.body_compression.expect("compressed for the body");
        assert!(f > 0.5 && f < 1.0, "{f}");
        assert_eq!(r.intersection, None);
        // The least compression that clears, to within the bisection's
        // step: a little less compression collides again.
        let t = Tightening {
            body: Some((f + 0.05).min(1.0)),
            ..Tightening::default()
        };
        let looser = sweepclay_core::finish(
            correct_with(&surface::sample_surface(&d).unwrap(), &t).unwrap(),
        )
        .unwrap();
        assert!(!verify(&looser, 0.5).report.printable);
    }
}
