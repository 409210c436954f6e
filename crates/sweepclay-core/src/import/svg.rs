//! SVG in (docs/FORMATS.md, "Importing a path"): the first shapes of a
//! drawing as Illustrator and Inkscape write it, transforms applied,
//! curves flattened, in millimetres by the root's width and viewBox.

use super::*;
use svgtypes::{PointsParser, SimplePathSegment, SimplifyingPathParser, Transform};

pub(super) const PX_MM: f64 = 25.4 / 96.0;

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
pub(super) fn parse_svg(text: &str) -> Result<roxmltree::Document<'_>> {
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
pub(super) fn skipped_notes(skipped: Vec<(String, Error)>) -> Vec<String> {
    skipped
        .into_iter()
        .map(|(label, e)| format!("{label} left out: {e}"))
        .collect()
}

/// One element's shapes in mm (y up, not yet centred): a `<path>`'s
/// sub-paths, or the one shape of the others, each with whether it closes.
pub(super) fn shape_of(
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

pub(super) fn compose(outer: &Transform, inner: &Transform) -> Transform {
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
pub(super) fn unit_scale(root: &roxmltree::Node) -> Result<f64> {
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
pub(super) fn spend(budget: &mut usize, n: usize) -> Result<()> {
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

pub(super) fn flatten_path(
    d: &str,
    step: f64,
    budget: &mut usize,
) -> Result<Vec<(Vec<[f64; 2]>, bool)>> {
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
pub(super) fn end_subpath(
    out: &mut Vec<(Vec<[f64; 2]>, bool)>,
    mut pts: Vec<[f64; 2]>,
    closed: bool,
) {
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
pub(super) fn pieces(ctrl: &[[f64; 2]], step: f64) -> usize {
    let poly = crate::bspline::polyline_length(ctrl);
    ((poly / step).ceil() as usize).clamp(1, 10_000)
}
