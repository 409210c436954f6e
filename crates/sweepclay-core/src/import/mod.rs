//! Trajectories from other tools: the first curve of an SVG file, or a CSV
//! of points, as the polyline `trajectory.points` of a design, open or
//! closed (a vessel; docs/FORMATS.md). Pure: text in, points out.
//!
//! SVG: the first `path`, `polyline`, `polygon`, `line`, `circle`,
//! `ellipse` or `rect` outside `<defs>` (the last four and a path that
//! closes are loops),
//! with the `transform`s of the element and its ancestors applied. Curves
//! (cubic, quadratic, arcs, smooth variants) are flattened to segments of at
//! most [`FLATTEN_MM`]. Units: user units are CSS pixels (25.4/96 mm)
//! unless the root `<svg>` gives its `width` in mm, cm or in with a
//! `viewBox`, which fixes the scale. The y axis is flipped (SVG's points
//! down) and the curve is centred on `o`.
//!
//! CSV: one `x, y` pair per line (comma, semicolon, tab or spaces; a
//! decimal comma with `;` or tabs between fields), in mm;
//! blank lines and `#` comments are skipped, and so are header lines
//! before the data; the points are centred on `o`, as an SVG's are.

use crate::error::{Error, Result};
use std::str::FromStr;

/// Longest segment of a flattened curve (mm).
pub const FLATTEN_MM: f64 = 0.5;
/// Most points an imported trajectory keeps (resampled by arc length).
pub const MAX_POINTS: usize = 2000;

mod csv;
mod svg;

pub use csv::*;
pub use svg::*;

/// An imported trajectory: its points and whether it is a loop (a vessel:
/// `trajectory.closed`; the first point is then not repeated at the end).
#[derive(Clone, Debug, PartialEq)]
pub struct ImportedPath {
    /// The points (mm).
    pub points: Vec<[f64; 2]>,
    /// A closed shape: `<circle>`, `<ellipse>`, `<rect>`, `<polygon>`, a
    /// `<path>` that closes, or a CSV whose last point meets its first.
    pub closed: bool,
}

/// [`finish`] for a path that may be closed: a loop drops a repeated first
/// point, is resampled round its closing side too, and needs three points.
pub(super) fn finish_path(mut pts: Vec<[f64; 2]>, closed: bool, key: &str) -> Result<ImportedPath> {
    if !closed {
        return Ok(ImportedPath {
            points: finish(pts, key)?,
            closed,
        });
    }
    if let Some(&first) = pts.first() {
        pts.push(first);
    }
    let mut points = finish(pts, key)?;
    // The loop's repeated first point.
    if points.len() > 1 {
        points.pop();
    }
    if points.len() < 3 {
        return Err(Error::invalid(
            key,
            "a closed shape needs at least three distinct points",
        ));
    }
    Ok(ImportedPath { points, closed })
}

pub(super) fn finish(pts: Vec<[f64; 2]>, key: &str) -> Result<Vec<[f64; 2]>> {
    let mut out: Vec<[f64; 2]> = Vec::with_capacity(pts.len());
    for p in pts {
        if !(p[0].is_finite() && p[1].is_finite()) {
            return Err(Error::invalid(key, "has a coordinate that is not a number"));
        }
        if out
            .last()
            .is_none_or(|q| (p[0] - q[0]).hypot(p[1] - q[1]) > 1e-6)
        {
            out.push(p);
        }
    }
    if out.len() < 2 {
        return Err(Error::invalid(key, "needs at least two distinct points"));
    }
    Ok(resample(&out, MAX_POINTS))
}

/// The offset frame an imported open path needs: `Normal` with a note
/// saying so when it passes within `near` mm of the centre `o` (where a
/// radial offset is undefined or flips: a wall drawn through the middle
/// of a sheet, a centred S-curve), else the default `Radial`.
pub fn offset_for(pts: &[[f64; 2]], near: f64) -> (crate::Offset, Option<String>) {
    let from_o = pts
        .windows(2)
        .map(|w| {
            let (a, b) = (w[0], w[1]);
            let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
            let l2 = dx * dx + dy * dy;
            let t = if l2 > 0.0 {
                (-(a[0] * dx + a[1] * dy) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (a[0] + t * dx).hypot(a[1] + t * dy)
        })
        .fold(f64::INFINITY, f64::min);
    if from_o < near {
        let note = format!(
            "the path passes {from_o:.1} mm from the centre o, so its profiles are offset perpendicular to it (\"offset\": \"normal\")"
        );
        (crate::Offset::Normal, Some(note))
    } else {
        (crate::Offset::Radial, None)
    }
}

/// Moves the points so that the centre of their bounding box is at `o`.
pub fn centre(pts: &mut [[f64; 2]]) {
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for p in pts.iter() {
        for a in 0..2 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let c = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0];
    for p in pts.iter_mut() {
        p[0] -= c[0];
        p[1] -= c[1];
    }
}

/// At most `max` points, equally spaced by arc length, ends kept.
pub(super) fn resample(pts: &[[f64; 2]], max: usize) -> Vec<[f64; 2]> {
    if pts.len() <= max {
        return pts.to_vec();
    }
    crate::curves::resample_polyline(pts, &crate::curves::arc_lengths(pts), max)
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::bspline::polyline_length as length;

    #[test]
    fn one_bad_shape_leaves_the_good_ones() {
        // A drawing with a broken path among good shapes: the good ones
        // are kept and the bad one named (the whole file was refused).
        let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">
            <path id="broken" d="M 10 10 L 20"/>
            <circle id="good" cx="50" cy="50" r="20"/></svg>"#;
        let (shapes, skipped) = svg_shapes_skipping(svg, MAX_SHAPES).unwrap();
        assert_eq!(shapes.len(), 1);
        assert_eq!(shapes[0].0, "<circle> good");
        assert_eq!(skipped.len(), 1);
        assert!(
            skipped[0].starts_with("<path> broken left out"),
            "{skipped:?}"
        );
        // Only bad shapes: the first one's reason.
        let bad = r#"<svg xmlns="http://www.w3.org/2000/svg"><path d="M 10 10 L 20"/></svg>"#;
        assert!(svg_shapes(bad, MAX_SHAPES).is_err());
    }

    #[test]
    fn a_european_csv_reads_its_decimal_commas() {
        // A spreadsheet in a European locale writes `;` between fields and
        // decimal commas: read as commas between fields it was a zig-zag.
        let eu = "x;y\n0,000;0,000\n45,500;0,000\n45,500;20,250\n";
        let p = csv_path(eu).unwrap();
        let us = csv_path("x,y\n0,0\n45.5,0\n45.5,20.25\n").unwrap();
        assert_eq!(p.points, us.points);
        // Tabs between fields too.
        let tab = csv_path("0,0\t0,0\n45,5\t0\n45,5\t20,25\n").unwrap();
        assert_eq!(tab.points, us.points);
        // A decimal comma with spaces between fields is refused by name.
        let e = csv_path("0 0\n45,5 0,2\n").unwrap_err().to_string();
        assert!(
            e.contains("csv line 2") && e.contains("decimal comma"),
            "{e}"
        );
        // Plain commas and spaces still read as before (three columns:
        // the first two).
        assert!(csv_path("1, 2, 3\n10, 2, 3\n10, 12, 3\n").is_ok());
    }

    #[test]
    fn an_illustrator_export_with_its_doctype_is_read() {
        // Adobe Illustrator's standard SVG export: an XML declaration,
        // its generator comment and the SVG 1.1 DOCTYPE (refused once:
        // "XML with DTD detected").
        let svg = r#"<?xml version="1.0" encoding="utf-8"?>
<!-- Generator: Adobe Illustrator 27.0.0, SVG Export Plug-In . SVG Version: 6.00 Build 0)  -->
<!DOCTYPE svg PUBLIC "-//W3C//DTD SVG 1.1//EN" "http://www.w3.org/Graphics/SVG/1.1/DTD/svg11.dtd">
<svg version="1.1" id="Layer_1" xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" x="0px" y="0px"
	 width="283.5px" height="283.5px" viewBox="0 0 283.5 283.5" style="enable-background:new 0 0 283.5 283.5;" xml:space="preserve">
<style type="text/css">
	.st0{fill:none;stroke:#000000;stroke-miterlimit:10;}
</style>
<circle class="st0" cx="141.7" cy="141.7" r="113.4"/>
</svg>
"#;
        let shapes = svg_shapes(svg, MAX_SHAPES).unwrap();
        assert_eq!(shapes.len(), 1);
        // r = 113.4 px = 30 mm: a circle 2π·30 mm round.
        let p = &shapes[0].1;
        assert!(p.closed);
        let mut ring = p.points.clone();
        ring.push(ring[0]);
        assert!((length(&ring) - std::f64::consts::TAU * 30.0).abs() < 0.5);
        // Entities in the DOCTYPE are refused by name.
        let with_entities = svg.replace(
            "svg11.dtd\">",
            "svg11.dtd\" [<!ENTITY ns_svg \"http://www.w3.org/2000/svg\">]>",
        );
        let e = svg_shapes(&with_entities, MAX_SHAPES)
            .unwrap_err()
            .to_string();
        assert!(e.contains("entities"), "{e}");
    }

    #[test]
    fn svg_arc_in_mm_is_flattened_and_flipped() {
        // A half circle of radius 40 mm, drawn with an arc command, in a
        // 200 mm wide document with a matching viewBox.
        let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="200mm" height="100mm" viewBox="0 0 200 100">
            <defs><path d="M 0 0 L 1 1"/></defs>
            <path d="M 60 60 A 40 40 0 0 1 140 60"/></svg>"#;
        let p = svg_trajectory(svg).unwrap();
        assert!(
            (length(&p) - std::f64::consts::PI * 40.0).abs() < 0.2,
            "{}",
            length(&p)
        );
        // Sweep flag 1 turns clockwise on screen: over the top (y = 20 in
        // SVG). Flipped and centred on the bounding box (100, −40): the
        // ends at (±40, −20), the middle at (0, 20).
        assert!(
            (p[0][0] + 40.0).abs() < 1e-9 && (p[0][1] + 20.0).abs() < 1e-9,
            "{:?}",
            p[0]
        );
        let mid = p[p.len() / 2];
        assert!(
            mid[0].abs() < 0.5 && (mid[1] - 20.0).abs() < 1e-3,
            "{mid:?}"
        );
        for w in p.windows(2) {
            assert!((w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]) <= FLATTEN_MM + 1e-9);
        }
    }

    #[test]
    fn svg_transforms_and_pixel_units_apply() {
        let svg = r#"<svg xmlns="http://www.w3.org/2000/svg"><g transform="translate(10,0) scale(2)">
            <polyline points="0,0 96,0 96,96"/></g></svg>"#;
        let p = svg_trajectory(svg).unwrap();
        // 96 user units × 2 = 192 px = 50.8 mm.
        assert_eq!(p.len(), 3);
        assert!((p[1][0] - p[0][0] - 50.8).abs() < 1e-9);
        assert!((p[2][1] - p[1][1] + 50.8).abs() < 1e-9);
    }

    #[test]
    fn svg_cubic_and_quadratic_curves() {
        let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="100mm" viewBox="0 0 100 100">
            <path d="M0,0 C 0,50 100,50 100,0 q 10 -20 20 0"/></svg>"#;
        let p = svg_trajectory(svg).unwrap();
        let (first, last) = (p[0], p[p.len() - 1]);
        assert!(
            (last[0] - first[0] - 120.0).abs() < 1e-9,
            "{first:?} {last:?}"
        );
        assert!((last[1] - first[1]).abs() < 1e-9);
        assert!(length(&p) > 150.0);
    }

    #[test]
    fn svg_errors_name_the_problem() {
        for (svg, want) in [
            ("not xml", "not an SVG document"),
            ("<html/>", "not <svg>"),
            (
                r#"<svg xmlns="http://www.w3.org/2000/svg"><g/></svg>"#,
                "no <path>",
            ),
            (
                r#"<svg xmlns="http://www.w3.org/2000/svg"><rect/></svg>"#,
                "has no `width`",
            ),
            (
                r#"<svg xmlns="http://www.w3.org/2000/svg"><circle r="-3"/></svg>"#,
                "positive",
            ),
            (
                r#"<svg xmlns="http://www.w3.org/2000/svg"><path/></svg>"#,
                "has no `d`",
            ),
            (
                r#"<svg xmlns="http://www.w3.org/2000/svg"><path d="M 0 0"/></svg>"#,
                "two distinct points",
            ),
            (
                r#"<svg xmlns="http://www.w3.org/2000/svg"><line x1="a" x2="1" y1="0" y2="0"/></svg>"#,
                "`a` is not a number",
            ),
        ] {
            let e = svg_trajectory(svg).unwrap_err().to_string();
            assert!(e.contains(want), "{svg}: {e}");
        }
    }

    #[test]
    fn every_shape_and_sub_path_is_offered() {
        // A drawing program's export: a ring (outside and hole in one
        // path), then a circle with an id.
        let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">
            <path d="M 10 10 L 90 10 L 90 90 L 10 90 Z M 30 30 L 70 30 L 70 70 L 30 70 Z"/>
            <circle id="foot" cx="50" cy="50" r="20"/></svg>"#;
        let shapes = svg_shapes(svg, MAX_SHAPES).unwrap();
        let labels: Vec<&str> = shapes.iter().map(|s| s.0.as_str()).collect();
        assert_eq!(
            labels,
            ["<path>, sub-path 1", "<path>, sub-path 2", "<circle> foot"]
        );
        assert!(shapes.iter().all(|s| s.1.closed));
        // Each centred on o: the hole is a 40 mm square round it.
        let hole = &shapes[1].1.points;
        assert!(hole
            .iter()
            .all(|p| (p[0].abs() - 20.0).abs() < 1e-9 || (p[1].abs() - 20.0).abs() < 1e-9));
        // The first shape is what a plain import takes; the cap holds.
        assert_eq!(svg_path(svg).unwrap(), shapes[0].1);
        assert_eq!(svg_shapes(svg, 2).unwrap().len(), 2);
    }

    #[test]
    fn closed_shapes_import_as_loops() {
        let mm = |body: &str| {
            format!(
                r#"<svg xmlns="http://www.w3.org/2000/svg" width="200mm" height="200mm" viewBox="0 0 200 200">{body}</svg>"#
            )
        };
        // A circle of radius 30 mm: a loop round o, 2π·30 long.
        let c = svg_path(&mm(r#"<circle cx="100" cy="80" r="30"/>"#)).unwrap();
        assert!(c.closed);
        for p in &c.points {
            assert!((p[0].hypot(p[1]) - 30.0).abs() < 1e-3, "{p:?}");
        }
        let e = svg_path(&mm(r#"<ellipse cx="50" cy="50" rx="40" ry="20"/>"#)).unwrap();
        assert!(e.closed);
        let xs = e.points.iter().map(|p| p[0].abs()).fold(0.0, f64::max);
        assert!((xs - 40.0).abs() < 1e-3);
        let r = svg_path(&mm(r#"<rect x="10" y="10" width="60" height="40"/>"#)).unwrap();
        assert!(r.closed);
        assert_eq!(r.points.len(), 4);
        assert!(r.points.contains(&[-30.0, 20.0]) && r.points.contains(&[30.0, -20.0]));
        // Closed paths (with Z, or ending on their start) and polygons.
        for body in [
            r#"<path d="M 0 0 L 50 0 L 50 50 Z"/>"#,
            r#"<path d="M 0 0 L 50 0 L 50 50 L 0 0"/>"#,
            r#"<polygon points="0,0 50,0 50,50"/>"#,
        ] {
            let p = svg_path(&mm(body)).unwrap();
            assert!(p.closed, "{body}");
            assert_eq!(p.points.len(), 3, "{body}: {:?}", p.points);
        }
        assert!(
            !svg_path(&mm(r#"<path d="M 0 0 L 50 0 L 50 50"/>"#))
                .unwrap()
                .closed
        );
        // A CSV whose last point meets its first.
        let c = csv_path("0,0\n40,0\n40,40\n0,40\n0,0\n").unwrap();
        assert!(c.closed);
        assert_eq!(c.points.len(), 4);
        assert!(!csv_path("0,0\n40,0\n40,40\n").unwrap().closed);
    }

    #[test]
    fn csv_with_header_comments_and_separators() {
        // Comments and a header before the data; centred on o (the box
        // 0..20 × 0..20 moves by −10, −10).
        let p = csv_trajectory(
            "# exported from a drawing\nx,y\n0,0\n\n# a comment\n10;0\n10\t10  # end\n20 20\n",
        )
        .unwrap();
        assert_eq!(
            p,
            vec![[-10.0, -10.0], [0.0, -10.0], [0.0, 0.0], [10.0, 10.0]]
        );
        let e = csv_trajectory("0,0\n1,zz\n").unwrap_err().to_string();
        assert_eq!(e, "csv line 2: `zz` is not a number");
        let e = csv_trajectory("0,0\n5\n").unwrap_err().to_string();
        assert!(e.starts_with("csv line 2: expected `x, y`"), "{e}");
        assert!(csv_trajectory("").is_err());
    }

    #[test]
    fn a_path_through_the_centre_gets_normal_offsets() {
        let (o, note) = offset_for(&[[-40.0, -1.0], [40.0, 1.0]], 10.0);
        assert_eq!(o, crate::Offset::Normal);
        assert!(note.unwrap().contains("0.0 mm from the centre"));
        let (o, note) = offset_for(&[[-40.0, 30.0], [0.0, 50.0], [40.0, 30.0]], 10.0);
        assert_eq!((o, note), (crate::Offset::Radial, None));
    }

    #[test]
    fn long_imports_are_resampled_and_centred() {
        let text: String = (0..5000).map(|i| format!("{i},{}\n", i % 2)).collect();
        let p = csv_trajectory(&text).unwrap();
        assert_eq!(p.len(), MAX_POINTS);
        // The box 0..4999 × 0..1, centred: its ends at ±2499.5.
        assert_eq!(p[0], [-2499.5, -0.5]);
        assert_eq!(p[MAX_POINTS - 1], [2499.5, 0.5]);
    }
}
