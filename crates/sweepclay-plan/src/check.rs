//! Stage 5's check of sliced G-code (docs/CHECKER.md): the G-code of a
//! sliced design is written and read by the independent checker in one
//! pass, and a failing line is traced back to its place in the design
//! (pass, transition curve, u, z).

use crate::cancel::{Cancel, CancelWriter};
use std::io::{self, Write};
use sweepclay_check::{CheckConfig, CheckWriter, Report};
use sweepclay_core::toolpath::PointKind;
use sweepclay_core::{gcode, Params, Printer, Sliced};

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
    /// [`crate::Checked::advice`]; empty when printable or not asked for).
    pub advice: Vec<String>,
    /// How far the corrections moved the shape, when beyond
    /// `params.max_correction_mm` (`CorrectionReport::reshaped`).
    pub reshaped: Option<String>,
    /// For a rim that does not print: the most rise of it that does (see
    /// [`crate::Checked::most_rise`]; `None` when not looked for).
    pub most_rise: Option<f64>,
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
pub(crate) fn verify_lines<W: Write>(
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
        most_rise: None,
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
}
