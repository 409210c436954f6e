//! What the modeler's JSON API computes, without the HTTP: design text in,
//! plain serialisable answers out. Design text becomes a validated
//! [`Job`] once; every answer that slices comes from the one plan
//! (`sweepclay_plan::plan`), so the preview, the verdict, the G-code and
//! the STL are of the same path.

pub use crate::error::ApiError;
pub use crate::guard::Limits;
use crate::guard::{Cancel, Stopped};
use serde::Serialize;
use sweepclay_core::mesh;
use sweepclay_core::toolpath::PointKind;
use sweepclay_core::{correct, surface, Design, Sliced};
use sweepclay_plan::{plan, Job, Planned, Unchecked, Verified};

mod view;

pub use view::*;

/// Parses a design into a job, refusing one whose parameters are out of
/// range or whose sample count is over the limit. One that leaves the
/// build volume is let through: slicing refuses it all the same, and the
/// preview shows it with the part outside marked.
pub fn parse_design(text: &str, limits: &Limits) -> Result<Job, ApiError> {
    let d = Design::from_json(text)?;
    let limits = sweepclay_plan::Limits {
        min_overlap: MIN_OVERLAP,
        max_samples: limits.max_samples,
        must_fit: false,
    };
    Ok(Job::new(d, &limits)?)
}

/// The overlap floor the modeler checks with: the checker's default.
const MIN_OVERLAP: f64 = 0.5;

/// The plan of a job, its G-code written to what `out` makes.
fn planned<W: std::io::Write>(
    job: &Job,
    cancel: &Cancel,
    out: impl FnMut() -> std::io::Result<W>,
) -> Result<Planned<W>, ApiError> {
    plan(job, cancel, out).map_err(|e| match e {
        Unchecked::Design(e) => e.into(),
        Unchecked::Io(e) => cancel.io_error("writing G-code", e),
    })
}

/// Slices a design through the correction loop and keeps what the
/// preview shows: the path of the last round, the one the G-code prints
/// and the download writes (docs/MODELER.md), which samples the
/// corrections moved from the drawing, and the check's verdict, so one
/// edit costs one slice. A print that leaves the build volume is shown
/// as the stages lay it, with why it cannot print and no verdict.
pub fn slice_view(job: &Job, cancel: &Cancel) -> Result<SliceView, ApiError> {
    let t0 = std::time::Instant::now();
    let Planned { checked, drawn } = match plan(job, cancel, || Ok(std::io::sink())) {
        Ok(c) => c,
        Err(Unchecked::Io(e)) => return Err(cancel.io_error("checking the G-code", e)),
        Err(Unchecked::Design(e)) => return unfit_view(job, cancel, t0, e),
    };
    let verdict = Verdict {
        printable: checked.report.printable,
        failures: checked.report.failures.clone(),
        locations: checked.locations.clone(),
        advice: checked.advice(),
        reshaped: checked.sliced.corrected.reshaped(),
        min_overlap: checked.report.support.min_overlap.map(|(f, _)| f),
        lines: checked.report.lines,
        most_rise: checked.most_rise.as_ref().map(|(most, _)| *most),
    };
    let (moved, printed) = moved_from(&drawn, &checked.sliced.corrected);
    drop(drawn);
    let slice_ms = t0.elapsed().as_secs_f64() * 1e3;
    Ok(SliceView {
        printed,
        verdict: Some(verdict),
        ..view(&checked.sliced, moved, slice_ms, None)
    })
}

/// The samples the corrections moved from the drawing (the texture,
/// which is not a correction, taken out), and the curves as printed.
fn moved_from(
    drawn: &surface::Surface,
    corrected: &correct::Corrected,
) -> (Vec<u32>, PrintedCurves) {
    let mut plain = corrected.surface.clone();
    for (i, smp) in plain.samples.iter_mut().enumerate() {
        if let (Some(k), Some(d)) = (corrected.kept.get(i), drawn.texture.get(i)) {
            smp.xi -= k * d;
        }
    }
    let moved: Vec<u32> = drawn
        .samples
        .iter()
        .zip(&plain.samples)
        .enumerate()
        .filter(|(_, (a, b))| (a.xi - b.xi).abs() > 0.05)
        .map(|(i, _)| i as u32)
        .collect();
    (moved, printed_curves(drawn, &plain))
}

/// The preview of a design the loop refused with `why`: where the stages
/// lay a print that leaves the build volume (or a floor one spiral cannot
/// fill), it is shown with what lies outside marked and why it cannot be
/// printed; any other refusal is the answer.
fn unfit_view(
    job: &Job,
    cancel: &Cancel,
    t0: std::time::Instant,
    why: sweepclay_core::Error,
) -> Result<SliceView, ApiError> {
    let unfit = match sweepclay_plan::unfit(job, cancel) {
        Ok(Some(u)) => u,
        Ok(None) => return Err(why.into()),
        Err(Unchecked::Io(e)) => return Err(cancel.io_error("slicing", e)),
        Err(Unchecked::Design(_)) => return Err(why.into()),
    };
    let (moved, printed) = moved_from(&unfit.drawn, &unfit.sliced.corrected);
    let e = ApiError::from(unfit.why);
    let fit_error = Some(FitError {
        error: e.error,
        key: e.key,
    });
    let slice_ms = t0.elapsed().as_secs_f64() * 1e3;
    Ok(SliceView {
        printed,
        ..view(&unfit.sliced, moved, slice_ms, fit_error)
    })
}

/// The checker's verdict on a design's G-code.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Verdict {
    /// Whether the G-code passes the check.
    pub printable: bool,
    /// Why not.
    pub failures: Vec<String>,
    /// Where in the design.
    pub locations: Vec<String>,
    /// What to change in the design, failure by failure.
    pub advice: Vec<String>,
    /// "up to 29.9 mm narrower than drawn at z 230 mm …" when the
    /// corrections moved the shape beyond `params.max_correction_mm`.
    pub reshaped: Option<String>,
    /// Smallest overlap with the bead below (fraction of the width).
    pub min_overlap: Option<f64>,
    /// Lines of G-code.
    pub lines: usize,
    /// For a rim that does not print: the most rise of it that does (mm;
    /// the modeler offers it beside the rim's field).
    pub most_rise: Option<f64>,
}

/// Plans, emits and checks a job, through the correction loop
/// (stopping once `cancel` is set).
pub fn verified(job: &Job, cancel: &Cancel) -> Result<Verified, ApiError> {
    let c = planned(job, cancel, || Ok(Vec::new()))?.checked;
    let advice = c.advice();
    let reshaped = c.sliced.corrected.reshaped();
    Ok(Verified {
        gcode: String::from_utf8(c.out).expect("G-code is UTF-8"),
        report: c.report,
        locations: c.locations,
        advice,
        reshaped,
        most_rise: c.most_rise.map(|(most, _)| most),
    })
}

/// The verdict of [`verified`].
pub fn verdict(v: &Verified) -> Verdict {
    Verdict {
        printable: v.report.printable,
        failures: v.report.failures.clone(),
        locations: v.locations.clone(),
        advice: v.advice.clone(),
        reshaped: v.reshaped.clone(),
        min_overlap: v.report.support.min_overlap.map(|(f, _)| f),
        lines: v.report.lines,
        most_rise: v.most_rise,
    }
}

/// The G-code of a design, only if it passes the check; otherwise a 422
/// that says why and where.
pub fn gcode(job: &Job, cancel: &Cancel) -> Result<String, ApiError> {
    let Verified {
        gcode,
        report,
        locations,
        advice,
        ..
    } = verified(job, cancel)?;
    if report.printable {
        Ok(gcode)
    } else {
        let error = format!(
            "not printable: {}; change the design: {}",
            report.failures.join("; "),
            advice.join("; ")
        );
        Err(ApiError {
            failures: report.failures,
            locations,
            ..ApiError::new(422, error)
        })
    }
}

/// A vessel mesh fitted by a design (docs/MESHES.md): the design, how
/// close it is and what was assumed.
#[derive(Clone, Debug, Serialize)]
pub struct MeshImport {
    /// The design the page opens.
    pub design: serde_json::Value,
    /// The largest difference from the mesh's sections (mm).
    pub deviation_mm: f64,
    /// Where it lies (mm, the design's frame).
    pub at: [f64; 3],
    /// `solid` or `shell` (a wall with its thickness); either way the
    /// printed bead's outer edge is the mesh's outside.
    pub kind: &'static str,
    /// Triangles read.
    pub triangles: usize,
    /// What was assumed about its units, if anything.
    pub note: Option<String>,
    /// Where the mesh is no sweep within 0.3 mm: the closest sweep's
    /// difference from it (mm) and where it lies; the design then
    /// carries the rest as its relief and prints as the mesh is.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sweep: Option<SweepMiss>,
}

/// How far a mesh is from the closest sweep (docs/MESHES.md, "Printed as
/// the mesh is").
#[derive(Clone, Debug, Serialize)]
pub struct SweepMiss {
    /// The largest difference (mm).
    pub deviation_mm: f64,
    /// Where it lies (mm, the design's frame).
    pub at: [f64; 3],
}

/// Reads a mesh (`name` gives its format by the extension), stands it
/// up (`up`: 0 x, 1 y, 2 z), takes its units, and fits it by a design.
pub fn import_mesh(name: &str, bytes: &[u8], up: usize) -> Result<MeshImport, ApiError> {
    use sweepclay_core::meshfit;
    let m = meshfit::import(name, bytes, up, None, &meshfit::FitOptions::default())?;
    let f = m.fitted;
    let design = serde_json::from_str(&f.design.to_json())
        .map_err(|e| ApiError::new(500, format!("the fitted design: {e}")))?;
    Ok(MeshImport {
        design,
        deviation_mm: f.deviation_mm,
        at: f.at,
        kind: f.kind,
        triangles: m.triangles,
        // The units assumed and the details taken in, one sentence each.
        note: {
            let notes: Vec<String> = [m.units_note, f.absorbed, f.inside]
                .into_iter()
                .flatten()
                .collect();
            (!notes.is_empty()).then(|| notes.join("; "))
        },
        sweep: f
            .sweep
            .map(|(deviation_mm, at)| SweepMiss { deviation_mm, at }),
    })
}

/// A binary STL of the planned surface (the one the G-code prints)
/// thickened to the bead width.
pub fn stl(job: &Job, cancel: &Cancel) -> Result<Vec<u8>, ApiError> {
    let s = planned(job, cancel, || Ok(std::io::sink()))?.checked.sliced;
    let mut out = Vec::new();
    mesh::write_stl(&s, &mut out).map_err(|e| ApiError::new(500, e.to_string()))?;
    Ok(out)
}

/// Trajectory points imported from an SVG or CSV file.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Imported {
    /// The file's first shape, the one a plain import takes (its fields
    /// at the top level of the answer).
    #[serde(flatten)]
    pub first: ImportedPoints,
    /// Every shape of the file to pick from (an SVG's elements and
    /// sub-paths, the first being the one above), each with its own label.
    pub shapes: Vec<ImportedShape>,
    /// The shapes left out, each with its reason (`"<path> p3 left out:
    /// …"`): one bad shape no longer refuses the whole file.
    pub skipped: Vec<String>,
}

/// One shape of an imported file.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ImportedShape {
    /// What it is in the file: `<path> id, sub-path 2`, `<circle>`, `CSV`.
    pub label: String,
    /// Its points, its length, its offset frame and note, closed or not.
    #[serde(flatten)]
    pub path: ImportedPoints,
}

/// The points of one imported shape and what follows from them: its
/// length and the offset frame it needs.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ImportedPoints {
    /// The points (mm, relative to `o`).
    pub points: Vec<[f64; 2]>,
    /// Arc length (mm).
    pub length_mm: f64,
    /// The offset frame it needs.
    pub offset: sweepclay_core::Offset,
    /// What the page should tell the user about that choice.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
    /// A closed shape.
    pub closed: bool,
}

fn imported_points(path: sweepclay_core::import::ImportedPath) -> ImportedPoints {
    let (mut points, closed) = (path.points, path.closed);
    for p in &mut points {
        *p = p.map(|x| (x * 1000.0).round() / 1000.0);
    }
    let mut length_mm = sweepclay_core::bspline::polyline_length(&points);
    if closed {
        length_mm += sweepclay_core::bspline::dist(points[points.len() - 1], points[0]);
    }
    // Near o a radial offset flips from side to side: 10 mm, about two of
    // the widest beads.
    let (offset, note) = sweepclay_core::import::offset_for(&points, 10.0);
    ImportedPoints {
        points,
        length_mm,
        offset,
        note,
        closed,
    }
}

/// Imports a trajectory; `format` is `svg` or `csv`.
pub fn import(format: &str, text: &str) -> Result<Imported, ApiError> {
    let (shapes, skipped): (Vec<ImportedShape>, Vec<String>) = match format {
        "svg" => {
            let (shapes, skipped) = sweepclay_core::import::svg_shapes_skipping(
                text,
                sweepclay_core::import::MAX_SHAPES,
            )?;
            let shapes = shapes
                .into_iter()
                .map(|(label, path)| ImportedShape {
                    label,
                    path: imported_points(path),
                })
                .collect();
            (shapes, skipped)
        }
        "csv" => (
            vec![ImportedShape {
                label: "CSV points".into(),
                path: imported_points(sweepclay_core::import::csv_path(text)?),
            }],
            Vec::new(),
        ),
        other => {
            return Err(ApiError::new(
                400,
                format!("format: `{other}` is not an import format (svg, csv)"),
            )
            .with_key("format"))
        }
    };
    Ok(Imported {
        first: shapes[0].path.clone(),
        shapes,
        skipped,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use sweepclay_core::examples;

    fn design(name: &str) -> Design {
        Design::from_json(examples::example(name).unwrap()).unwrap()
    }

    /// A design as the server takes it, with no sample cap.
    fn job(d: Design) -> Job {
        let limits = sweepclay_plan::Limits {
            max_samples: f64::INFINITY,
            must_fit: false,
            ..sweepclay_plan::Limits::default()
        };
        Job::new(d, &limits).unwrap()
    }

    #[test]
    fn slice_view_indexes_every_sample_once() {
        let v = slice_view(&job(design("t2")), &Cancel::new()).unwrap();
        let n = v.surface.positions.len() / 3;
        assert_eq!(v.stats.sample_points, n);
        let mut seen = vec![false; n];
        for &s in &v.path.order {
            assert!(!seen[s as usize]);
            seen[s as usize] = true;
        }
        assert!(seen.iter().all(|&s| s));
        assert_eq!(v.path.width.len(), n);
        let cols = &v.surface.columns;
        assert_eq!(cols.len(), 2 * v.surface.curves);
        assert_eq!(cols[cols.len() - 2] + cols[cols.len() - 1], n as u32);
        assert_eq!(v.plan.stages, 2);
        assert!(!v.path.top.is_empty());
        assert!(v.warnings[0].starts_with("two stages"));
    }

    #[test]
    fn binary_form_carries_the_same_arrays() {
        let v = slice_view(&job(design("t2")), &Cancel::new()).unwrap();
        let b = v.to_binary();
        assert_eq!(&b[..4], b"SWCL");
        let u32_at = |o: usize| u32::from_le_bytes(b[o..o + 4].try_into().unwrap()) as usize;
        let json_len = u32_at(4);
        assert_eq!(json_len % 4, 0);
        let head: serde_json::Value = serde_json::from_slice(&b[8..8 + json_len]).unwrap();
        assert_eq!(head["stats"]["sample_points"], v.stats.sample_points);
        let mut o = 8 + json_len;
        let mut arrays = Vec::new();
        while o < b.len() {
            let n = u32_at(o);
            arrays.push((o + 4, n));
            o += 4 + 4 * n;
        }
        assert_eq!(o, b.len());
        let lens: Vec<usize> = arrays.iter().map(|a| a.1).collect();
        let n = v.stats.sample_points;
        assert_eq!(
            lens,
            vec![
                3 * n,
                v.surface.columns.len(),
                v.surface.moved.len(),
                n,
                n,
                n,
                v.path.top.len(),
                n,
                n,
                n,
                n,
                0
            ]
        );
        // Spot-check values: the last position and the last pass.
        let (start, _) = arrays[0];
        let last = f32::from_le_bytes(
            b[start + 4 * (3 * n - 1)..start + 4 * 3 * n]
                .try_into()
                .unwrap(),
        );
        assert_eq!(last, v.surface.positions[3 * n - 1]);
        let (start, _) = arrays[5];
        assert_eq!(u32_at(start + 4 * (n - 1)) as u32, v.path.pass[n - 1]);
        // A textured design sends the texture kept, a value a path point.
        let v = slice_view(&job(design("ripple-vase")), &Cancel::new()).unwrap();
        let b = v.to_binary();
        let last_len = {
            let json_len = u32::from_le_bytes(b[4..8].try_into().unwrap()) as usize;
            let mut o = 8 + json_len;
            let mut last = 0;
            while o < b.len() {
                last = u32::from_le_bytes(b[o..o + 4].try_into().unwrap()) as usize;
                o += 4 + 4 * last;
            }
            last
        };
        assert_eq!(last_len, v.path.order.len());
        assert!(v.path.texture_kept.iter().any(|&k| k < 1.0));
        assert!(v.path.texture_kept.iter().filter(|&&k| k == 1.0).count() > last_len / 2);
    }

    #[test]
    fn corrections_mark_moved_samples() {
        let plain = slice_view(&job(design("t4")), &Cancel::new()).unwrap();
        assert!(plain.corrections.is_empty() && plain.surface.moved.is_empty());
        // An end profile leaning 45 mm over 20 mm of height overhangs far
        // beyond 57°: the support correction moves its upper samples.
        let mut d = design("t4");
        d.profile_end = Some(sweepclay_core::design::CurveSpec {
            control_points: vec![[0.0, 0.0], [45.0, 20.0], [45.0, 40.0]],
            points: None,
        });
        let v = slice_view(&job(d.clone()), &Cancel::new()).unwrap();
        assert!(!v.corrections.is_empty());
        assert!(!v.surface.moved.is_empty());
        let n = (v.surface.positions.len() / 3) as u32;
        assert!(v.surface.moved.iter().all(|&i| i < n));
    }

    #[test]
    fn sample_cap_refuses_before_slicing() {
        let mut d = design("t1");
        d.params.spacing = 0.02;
        d.params.layer_height = 0.5;
        let text = d.to_json();
        let e = parse_design(&text, &Limits::default()).unwrap_err();
        assert_eq!(e.status, 413);
        assert!(e.error.contains("params.spacing"), "{}", e.error);
    }

    #[test]
    fn a_print_too_big_is_previewed_with_why_it_cannot_print() {
        let mut d = design("t1");
        d.printer = sweepclay_core::PrinterRef::Preset("cerambot-mini".into());
        // Let through to the preview, which says why...
        let d = parse_design(&d.to_json(), &Limits::default()).unwrap();
        let v = slice_view(&d, &Cancel::new()).unwrap();
        let fit = v.fit_error.as_ref().unwrap();
        assert!(
            fit.error.contains("does not fit printer `cerambot-mini`"),
            "{}",
            fit.error
        );
        assert_eq!(v.printer.build_volume, [120.0, 135.0, 100.0]);
        assert!(serde_json::to_string(&v).unwrap().contains("\"fit_error\""));
        // ... but its G-code is refused.
        assert_eq!(gcode(&d, &Cancel::new()).unwrap_err().status, 422);
        assert!(slice_view(&job(design("t1")), &Cancel::new())
            .unwrap()
            .fit_error
            .is_none());
    }

    #[test]
    fn the_bead_map_has_a_figure_for_every_path_point() {
        let v = slice_view(&job(design("t2")), &Cancel::new()).unwrap();
        let n = v.path.order.len();
        let b = &v.path.beads;
        for a in [&b.overlap, &b.overhang_deg, &b.layer_height, &b.clearance] {
            assert_eq!(a.len(), n);
        }
        // t2 verifies: every bead overlaps the one below by at least half.
        assert!(b.overlap.iter().all(|&o| o >= 0.5 - 1e-6));
        assert!(b.clearance.iter().all(|&c| c > 0.0));
    }

    #[test]
    fn an_svg_import_lists_its_shapes() {
        let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100"><path d="M 10 50 L 90 50 M 50 10 L 50 90"/><circle cx="50" cy="50" r="30"/></svg>"#;
        let im = import("svg", svg).unwrap();
        let labels: Vec<&str> = im.shapes.iter().map(|s| s.label.as_str()).collect();
        assert_eq!(
            labels,
            ["<path>, sub-path 1", "<path>, sub-path 2", "<circle>"]
        );
        assert_eq!(im.first.points, im.shapes[0].path.points);
        assert!(im.shapes[2].path.closed && !im.shapes[1].path.closed);
        let j = serde_json::to_value(&im).unwrap();
        assert_eq!(j["shapes"][2]["closed"], true);
        assert!(j["shapes"][0]["points"].is_array());
    }

    #[test]
    fn errors_carry_status_and_key() {
        let e = parse_design("{", &Limits::default()).unwrap_err();
        assert_eq!(e.status, 400);
        // Refused once, when the text becomes a job, before any slicing.
        let mut d = design("t1");
        d.params.layer_height = 0.1;
        let e = parse_design(&d.to_json(), &Limits::default()).unwrap_err();
        assert_eq!(
            (e.status, e.key.as_deref()),
            (422, Some("params.layer_height"))
        );
        assert_eq!(import("dxf", "").unwrap_err().status, 400);
    }

    #[test]
    fn gcode_is_verified() {
        let text = gcode(&job(design("t5")), &Cancel::new()).unwrap();
        assert!(text.contains("G1"));
    }

    #[test]
    fn the_preview_is_the_path_the_download_prints() {
        // A pot on a foot 150 mm wide: its first G-code fails the check
        // and the loop tightens the corrections, so the first round's path
        // (what the preview showed) is not what prints. The preview is now
        // the last round's, point for point the G-code's moves, and it
        // carries that G-code's verdict.
        // "New pot" on the cerambot-plus, its base typed 150 mm wide under
        // rows 60 mm wide.
        let d =
            Design::from_json(include_str!("../../../sweepclay-plan/tests/foot-pot.json")).unwrap();
        let v = slice_view(&job(d.clone()), &Cancel::new()).unwrap();
        let verdict = v.verdict.as_ref().expect("a verdict");
        assert!(verdict.printable, "{:?}", verdict.failures);
        assert!(
            v.corrections.iter().any(|c| c.contains("correction loop")),
            "{:?}",
            v.corrections
        );
        let text = gcode(&job(d.clone()), &Cancel::new()).unwrap();
        assert_eq!(text.lines().count(), verdict.lines);
        // One point of the path a move of the file (the browser test
        // `the_page_previews_the_path_it_downloads_point_for_point`
        // compares them point for point, as the page shows them).
        let moves = text
            .lines()
            .filter(|l| l.starts_with("G1 ") || l.starts_with("G0 "))
            .count();
        assert!(v.path.order.len() <= moves && moves <= v.path.order.len() + 20);
    }
}
