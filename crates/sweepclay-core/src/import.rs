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
use svgtypes::{PointsParser, SimplePathSegment, SimplifyingPathParser, Transform};

/// Longest segment of a flattened curve (mm).
pub const FLATTEN_MM: f64 = 0.5;
/// Most points an imported trajectory keeps (resampled by arc length).
pub const MAX_POINTS: usize = 2000;

const PX_MM: f64 = 25.4 / 96.0;

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

/// The first curve of an SVG document as trajectory points (mm, centred on
/// `o`, y up), open or closed.
pub fn svg_trajectory(text: &str) -> Result<Vec<[f64; 2]>> {
    svg_path(text).map(|p| p.points)
}

/// [`svg_trajectory`] with whether the shape is closed: the document's
/// first shape (see [`svg_shapes`]).
pub fn svg_path(text: &str) -> Result<ImportedPath> {
    let mut shapes = svg_shapes(text, 1)?;
    Ok(shapes.remove(0).1)
}

/// Most shapes [`svg_shapes`] lists for the user to pick from.
pub const MAX_SHAPES: usize = 20;

/// Most XML nodes an imported SVG may hold (elements, text, attributes'
/// nodes): a drawing has a few thousand; the cap bounds the parser's
/// memory on a hostile file.
pub const MAX_SVG_NODES: u32 = 200_000;

/// Deepest nesting of elements an imported SVG may have: drawings nest
/// groups a few levels; the cap keeps the work a shape's ancestors cost
/// (its transforms, whether it is in `<defs>`) bounded on a hostile file
/// (100,000 nested `<g>` took 22 s).
pub const MAX_SVG_DEPTH: usize = 100;

/// Most points the flattening of an SVG's curves may give, over all its
/// shapes: a curve is cut every 0.5 mm, so a huge `transform` scale made
/// 48 KB of curves into gigabytes of points.
pub const MAX_FLAT_POINTS: usize = 400_000;

/// An SVG document parsed as drawing programs write it: a `<!DOCTYPE>`
/// (Adobe Illustrator's standard export declares the SVG 1.1 DTD) is
/// read; entities declared in it are refused by name, since expanding
/// them is no drawing's business.
fn parse_svg(text: &str) -> Result<roxmltree::Document<'_>> {
    let root_at = text.find("<svg").unwrap_or(text.len());
    if text[..root_at].contains("<!ENTITY") {
        return Err(Error::invalid(
            "svg",
            "its DOCTYPE declares entities (<!ENTITY …>), which are not expanded: export it without them (Illustrator: SVG 1.1, with \"Preserve Illustrator Editing Capabilities\" off)",
        ));
    }
    let opt = roxmltree::ParsingOptions {
        allow_dtd: true,
        nodes_limit: MAX_SVG_NODES,
        ..roxmltree::ParsingOptions::default()
    };
    roxmltree::Document::parse_with_options(text, opt).map_err(|e| match e {
        roxmltree::Error::NodesLimitReached => Error::invalid(
            "svg",
            format!(
                "more than {MAX_SVG_NODES} XML nodes (the cap of an import): simplify the drawing"
            ),
        ),
        e => Error::invalid("svg", format!("not an SVG document: {e}")),
    })
}

/// One shape of an imported file: its label (element, `id`, sub-path)
/// and its points.
pub type Shape = (String, ImportedPath);

/// Every shape of an SVG document, in document order, each as trajectory
/// points (mm, centred on `o`, y up), at most `max`: each `<polyline>`,
/// `<polygon>`, `<line>`, `<circle>`, `<ellipse>` and `<rect>`, and each
/// sub-path of each `<path>` (a drawing program's one path often holds a
/// shape and its hole, or several strokes). Labelled by element, `id` and
/// sub-path. An error when there is none.
pub fn svg_shapes(text: &str, max: usize) -> Result<Vec<Shape>> {
    svg_shapes_skipping(text, max).map(|(shapes, _)| shapes)
}

/// [`svg_shapes`], keeping the good shapes of a file with a bad one: each
/// shape that cannot be read (a path with a broken `d`, a degenerate
/// circle) is left out and named with its reason in the second list. An
/// error only when no shape can be read: the first shape's reason.
pub fn svg_shapes_skipping(text: &str, max: usize) -> Result<(Vec<Shape>, Vec<String>)> {
    let doc = parse_svg(text)?;
    let root = doc.root_element();
    if root.tag_name().name() != "svg" {
        return Err(Error::invalid(
            "svg",
            format!(
                "the root element is <{}>, not <svg>",
                root.tag_name().name()
            ),
        ));
    }
    // Depth by one pass in document order (a node's parent comes first).
    let mut depth = vec![0usize; doc.descendants().count() + 1];
    for n in root.descendants().skip(1) {
        let d = n.parent().map_or(0, |p| depth[p.id().get_usize()]) + 1;
        if d > MAX_SVG_DEPTH {
            return Err(Error::invalid(
                "svg",
                format!("its elements nest more than {MAX_SVG_DEPTH} deep (the cap of an import): flatten the groups"),
            ));
        }
        depth[n.id().get_usize()] = d;
    }
    drop(depth);
    let mm_per_unit = unit_scale(&root)?;
    let mut budget = MAX_FLAT_POINTS;
    let mut out = Vec::new();
    let mut skipped: Vec<(String, Error)> = Vec::new();
    let nodes = root
        .descendants()
        .filter(|n| n.is_element())
        .filter(|n| !n.ancestors().any(|a| a.tag_name().name() == "defs"))
        .filter(|n| {
            matches!(
                n.tag_name().name(),
                "path" | "polyline" | "polygon" | "line" | "circle" | "ellipse" | "rect"
            )
        });
    for node in nodes {
        let tag = node.tag_name().name();
        let name = match node.attribute("id") {
            Some(id) => format!("<{tag}> {id}"),
            None => format!("<{tag}>"),
        };
        let parts = match shape_of(node, mm_per_unit, &mut budget) {
            Ok(parts) => parts,
            // Over the cap, the file is refused whole: no point going on.
            Err(e) if budget == 0 => return Err(e),
            Err(e) => {
                skipped.push((name, e));
                continue;
            }
        };
        let many = parts.len() > 1;
        for (k, (pts, closed)) in parts.into_iter().enumerate() {
            if out.len() >= max {
                return Ok((out, skipped_notes(skipped)));
            }
            let label = if many {
                format!("{name}, sub-path {}", k + 1)
            } else {
                name.clone()
            };
            match finish_path(pts, closed, &format!("svg <{tag}>")) {
                Ok(mut path) => {
                    centre(&mut path.points);
                    out.push((label, path));
                }
                Err(e) => skipped.push((label, e)),
            }
        }
    }
    if out.is_empty() {
        return Err(match skipped.into_iter().next() {
            Some((_, e)) => e,
            None => Error::invalid(
                "svg",
                "no <path>, <polyline>, <polygon>, <line>, <circle>, <ellipse> or <rect> element to import",
            ),
        });
    }
    Ok((out, skipped_notes(skipped)))
}

/// The shapes an import left out, each with its reason.
fn skipped_notes(skipped: Vec<(String, Error)>) -> Vec<String> {
    skipped
        .into_iter()
        .map(|(label, e)| format!("{label} left out: {e}"))
        .collect()
}

/// One element's shapes in mm (y up, not yet centred): a `<path>`'s
/// sub-paths, or the one shape of the others, each with whether it closes.
fn shape_of(
    node: roxmltree::Node,
    mm_per_unit: f64,
    budget: &mut usize,
) -> Result<Vec<(Vec<[f64; 2]>, bool)>> {
    let tag = node.tag_name().name();
    // Accumulated transform, outermost first.
    let mut ts = Transform::default();
    let chain: Vec<_> = node.ancestors().collect();
    for n in chain.iter().rev() {
        if let Some(t) = n.attribute("transform") {
            let t = Transform::from_str(t).map_err(|e| {
                Error::invalid(
                    format!("svg <{}> transform", n.tag_name().name()),
                    e.to_string(),
                )
            })?;
            ts = compose(&ts, &t);
        }
    }
    let scale = mm_per_unit * (ts.a * ts.d - ts.b * ts.c).abs().sqrt().max(1e-12);
    let step = FLATTEN_MM / scale;
    let attr = |name: &str| {
        node.attribute(name)
            .ok_or_else(|| Error::invalid(format!("svg <{tag}>"), format!("has no `{name}`")))
    };
    let num = |name: &str| -> Result<f64> {
        let v = attr(name)?;
        v.trim().parse().map_err(|_| {
            Error::invalid(
                format!("svg <{tag}> {name}"),
                format!("`{v}` is not a number"),
            )
        })
    };
    let opt = |name: &str| -> Result<f64> {
        if node.attribute(name).is_some() {
            num(name)
        } else {
            Ok(0.0)
        }
    };
    let mut ellipse = |cx: f64, cy: f64, rx: f64, ry: f64| -> Result<Vec<[f64; 2]>> {
        if !(rx > 0.0 && ry > 0.0 && rx.is_finite() && ry.is_finite()) {
            return Err(Error::invalid(
                format!("svg <{tag}>"),
                "its radius must be a positive number",
            ));
        }
        let around = std::f64::consts::TAU * rx.max(ry);
        let n = ((around / step).ceil() as usize).clamp(16, 4 * MAX_POINTS);
        spend(budget, n)?;
        Ok((0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                [cx + rx * a.cos(), cy + ry * a.sin()]
            })
            .collect())
    };
    let parts: Vec<(Vec<[f64; 2]>, bool)> = match tag {
        "path" => flatten_path(attr("d")?, step, budget)?,
        "line" => vec![(
            vec![[num("x1")?, num("y1")?], [num("x2")?, num("y2")?]],
            false,
        )],
        "circle" => {
            let r = num("r")?;
            vec![(ellipse(opt("cx")?, opt("cy")?, r, r)?, true)]
        }
        "ellipse" => vec![(
            ellipse(opt("cx")?, opt("cy")?, num("rx")?, num("ry")?)?,
            true,
        )],
        "rect" => {
            let (x, y, w, h) = (opt("x")?, opt("y")?, num("width")?, num("height")?);
            if !(w > 0.0 && h > 0.0) {
                return Err(Error::invalid(
                    "svg <rect>",
                    "its width and height must be positive",
                ));
            }
            vec![(vec![[x, y], [x + w, y], [x + w, y + h], [x, y + h]], true)]
        }
        _ => {
            let pts: Vec<[f64; 2]> = PointsParser::from(attr("points")?)
                .map(|(x, y)| [x, y])
                .collect();
            vec![(pts, tag == "polygon")]
        }
    };
    Ok(parts
        .into_iter()
        .map(|(local, closed)| {
            let pts = local
                .iter()
                .map(|&[x, y]| {
                    let (x, y) = (ts.a * x + ts.c * y + ts.e, ts.b * x + ts.d * y + ts.f);
                    [x * mm_per_unit, -y * mm_per_unit]
                })
                .collect();
            (pts, closed)
        })
        .collect())
}

/// Points of a CSV file as a trajectory (mm, centred on `o` as an SVG's).
pub fn csv_trajectory(text: &str) -> Result<Vec<[f64; 2]>> {
    csv_path(text).map(|p| p.points)
}

/// The fields of one CSV line. A line with `;` (a European spreadsheet's
/// export, `45,000;0,000`) or a tab between its fields may write its
/// numbers with a decimal comma; a line with neither is split at commas
/// and spaces, and one that mixes a decimal comma with spaces
/// (`45,5 0,2`: x 45.5 and y 0.2, or four numbers?) is refused by name
/// rather than read as a zig-zag.
fn csv_fields(line: &str, key: &str) -> Result<Vec<String>> {
    let decimal_comma = |f: &str| f.trim().replace(',', ".");
    if line.contains(';') || line.contains('\t') {
        return Ok(line
            .split([';', '\t'])
            .map(decimal_comma)
            .filter(|f| !f.is_empty())
            .collect());
    }
    let b = line.as_bytes();
    let mixed = (1..b.len().saturating_sub(1))
        .any(|k| b[k] == b',' && b[k - 1].is_ascii_digit() && b[k + 1].is_ascii_digit())
        && line.split(',').any(|part| part.trim().contains(' '));
    if mixed {
        return Err(Error::invalid(
            key,
            format!("`{line}` mixes a decimal comma with spaces between fields: separate x and y by `;` or a tab (`45,5; 0,2`), or write decimal points"),
        ));
    }
    Ok(line
        .split([',', ' '])
        .map(str::trim)
        .filter(|f| !f.is_empty())
        .map(str::to_string)
        .collect())
}

/// [`csv_trajectory`], closed when its last point meets its first.
pub fn csv_path(text: &str) -> Result<ImportedPath> {
    let mut pts = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let key = format!("csv line {}", i + 1);
        let fields = csv_fields(line, &key)?;
        let parsed: Vec<Option<f64>> = fields.iter().map(|f| f.parse().ok()).collect();
        if pts.is_empty() && parsed.iter().all(Option::is_none) {
            continue; // a header (or a title) before the data
        }
        if fields.len() < 2 {
            return Err(Error::invalid(
                key,
                format!("expected `x, y`, got `{line}`"),
            ));
        }
        let mut xy = [0.0; 2];
        for k in 0..2 {
            xy[k] = parsed[k]
                .filter(|v: &f64| v.is_finite())
                .ok_or_else(|| Error::invalid(&key, format!("`{}` is not a number", fields[k])))?;
        }
        pts.push(xy);
    }
    let closed = pts.len() > 3
        && pts
            .first()
            .zip(pts.last())
            .is_some_and(|(a, b)| (a[0] - b[0]).hypot(a[1] - b[1]) <= 1e-6);
    let mut path = finish_path(pts, closed, "csv")?;
    // Centred on o, as an SVG is: a CSV from a drawing starting at (0, 0)
    // would otherwise land on the centre.
    centre(&mut path.points);
    Ok(path)
}

/// [`finish`] for a path that may be closed: a loop drops a repeated first
/// point, is resampled round its closing side too, and needs three points.
fn finish_path(mut pts: Vec<[f64; 2]>, closed: bool, key: &str) -> Result<ImportedPath> {
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

fn finish(pts: Vec<[f64; 2]>, key: &str) -> Result<Vec<[f64; 2]>> {
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
fn resample(pts: &[[f64; 2]], max: usize) -> Vec<[f64; 2]> {
    if pts.len() <= max {
        return pts.to_vec();
    }
    crate::curves::resample_polyline(pts, &crate::curves::arc_lengths(pts), max)
}

fn compose(outer: &Transform, inner: &Transform) -> Transform {
    Transform::new(
        outer.a * inner.a + outer.c * inner.b,
        outer.b * inner.a + outer.d * inner.b,
        outer.a * inner.c + outer.c * inner.d,
        outer.b * inner.c + outer.d * inner.d,
        outer.a * inner.e + outer.c * inner.f + outer.e,
        outer.b * inner.e + outer.d * inner.f + outer.f,
    )
}

/// Millimetres per user unit of the root `<svg>`.
fn unit_scale(root: &roxmltree::Node) -> Result<f64> {
    let Some(width) = root.attribute("width") else {
        return Ok(PX_MM);
    };
    let w = width.trim();
    let split = w
        .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == '+' || c == 'e'))
        .unwrap_or(w.len());
    let (value, unit) = w.split_at(split);
    let Ok(value) = value.parse::<f64>() else {
        return Ok(PX_MM);
    };
    let mm = match unit.trim() {
        "mm" => value,
        "cm" => 10.0 * value,
        "in" => 25.4 * value,
        "pt" => value * 25.4 / 72.0,
        "" | "px" => value * PX_MM,
        _ => return Ok(PX_MM), // %, em: no absolute size
    };
    let vb_width = root.attribute("viewBox").and_then(|vb| {
        vb.split([' ', ','])
            .filter(|s| !s.is_empty())
            .nth(2)
            .and_then(|s| s.parse::<f64>().ok())
    });
    Ok(match vb_width {
        Some(vw) if vw > 0.0 && mm > 0.0 => mm / vw,
        // Without a viewBox a user unit is a CSS pixel.
        _ => PX_MM,
    })
}

/// Each sub-path of `d` flattened, and whether it closes (a `Z`, or an
/// end on its start). A sub-path of one point (a bare move) is skipped.
/// Takes `n` points from the import's flattening budget, or refuses the
/// file naming the cap (the budget is then 0).
fn spend(budget: &mut usize, n: usize) -> Result<()> {
    if n > *budget {
        *budget = 0;
        return Err(Error::invalid(
            "svg",
            format!("its curves flatten to more than {MAX_FLAT_POINTS} points at 0.5 mm (the cap of an import): the drawing is too large or scaled too far up"),
        ));
    }
    *budget -= n;
    Ok(())
}

fn flatten_path(d: &str, step: f64, budget: &mut usize) -> Result<Vec<(Vec<[f64; 2]>, bool)>> {
    let mut out = Vec::new();
    let mut closed = false;
    let mut pts: Vec<[f64; 2]> = Vec::new();
    let mut start = [0.0, 0.0];
    let mut cur = [0.0, 0.0];
    for seg in SimplifyingPathParser::from(d) {
        let seg = seg.map_err(|e| Error::invalid("svg <path> d", e.to_string()))?;
        match seg {
            SimplePathSegment::MoveTo { x, y } => {
                end_subpath(&mut out, std::mem::take(&mut pts), closed);
                closed = false;
                cur = [x, y];
                start = cur;
                pts.push(cur);
            }
            SimplePathSegment::LineTo { x, y } => {
                spend(budget, 1)?;
                cur = [x, y];
                pts.push(cur);
            }
            SimplePathSegment::ClosePath => {
                cur = start;
                pts.push(cur);
                end_subpath(&mut out, std::mem::take(&mut pts), true);
                // Drawing on after a `Z` starts from the sub-path's start.
                pts.push(cur);
            }
            SimplePathSegment::CurveTo {
                x1,
                y1,
                x2,
                y2,
                x,
                y,
            } => {
                let (p0, p1, p2, p3) = (cur, [x1, y1], [x2, y2], [x, y]);
                let n = pieces(&[p0, p1, p2, p3], step);
                spend(budget, n)?;
                for i in 1..=n {
                    let t = i as f64 / n as f64;
                    let s = 1.0 - t;
                    let b = [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t];
                    pts.push([
                        b[0] * p0[0] + b[1] * p1[0] + b[2] * p2[0] + b[3] * p3[0],
                        b[0] * p0[1] + b[1] * p1[1] + b[2] * p2[1] + b[3] * p3[1],
                    ]);
                }
                cur = p3;
            }
            SimplePathSegment::Quadratic { x1, y1, x, y } => {
                let (p0, p1, p2) = (cur, [x1, y1], [x, y]);
                let n = pieces(&[p0, p1, p2], step);
                spend(budget, n)?;
                for i in 1..=n {
                    let t = i as f64 / n as f64;
                    let s = 1.0 - t;
                    let b = [s * s, 2.0 * s * t, t * t];
                    pts.push([
                        b[0] * p0[0] + b[1] * p1[0] + b[2] * p2[0],
                        b[0] * p0[1] + b[1] * p1[1] + b[2] * p2[1],
                    ]);
                }
                cur = p2;
            }
        }
    }
    end_subpath(&mut out, pts, closed);
    if out.is_empty() {
        return Err(Error::invalid(
            "svg <path> d",
            "draws nothing: a path needs at least two distinct points",
        ));
    }
    Ok(out)
}

/// Adds a flattened sub-path to `out` unless it is a lone point; one drawn
/// back onto its start without a `Z` is closed too, and a closed one drops
/// its repeated start.
fn end_subpath(out: &mut Vec<(Vec<[f64; 2]>, bool)>, mut pts: Vec<[f64; 2]>, closed: bool) {
    if pts.len() < 2 {
        return;
    }
    let ends_on_start = pts.len() > 3 && {
        let (a, b) = (pts[0], pts[pts.len() - 1]);
        (a[0] - b[0]).hypot(a[1] - b[1]) <= 1e-6 * (1.0 + a[0].abs() + a[1].abs())
    };
    if closed || ends_on_start {
        pts.pop();
    }
    out.push((pts, closed || ends_on_start));
}

/// Segments for a Bézier curve so each is at most `step` long (the control
/// polygon bounds the curve's length), capped for absurd inputs.
fn pieces(ctrl: &[[f64; 2]], step: f64) -> usize {
    let poly = crate::bspline::polyline_length(ctrl);
    ((poly / step).ceil() as usize).clamp(1, 10_000)
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
