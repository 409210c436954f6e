//! A picture of the toolpath: an SVG in an axonometric view, passes
//! coloured from blue (first) to red (last), the top-edge beads of returning
//! turns in black, the start (green) and end (red) marked as in the paper's
//! Fig. 11. Pure: returns the SVG text.

use crate::toolpath::PointKind;
use crate::Sliced;
use std::fmt::Write;

const W: f64 = 900.0;
const H: f64 = 640.0;
const MARGIN: f64 = 30.0;

fn project(p: [f64; 3]) -> (f64, f64) {
    // View from the front right, 20° above the horizon.
    let (s, c) = (35f64.to_radians().sin(), 35f64.to_radians().cos());
    let u = p[0] * c - p[1] * s;
    let v = p[0] * s + p[1] * c;
    (u, -p[2] - 0.34 * v)
}

fn colour(f: f64) -> String {
    // Blue → green → red.
    let h = 240.0 * (1.0 - f.clamp(0.0, 1.0));
    format!("hsl({h:.0},75%,45%)")
}

/// The toolpath of `s` as an SVG document.
pub fn svg(s: &Sliced) -> String {
    let pts = &s.toolpath.points;
    let proj: Vec<(f64, f64)> = pts.iter().map(|p| project(p.pos)).collect();
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in &proj {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    let top = 70.0;
    let scale =
        ((W - 2.0 * MARGIN) / (x1 - x0).max(1e-9)).min((H - top - MARGIN) / (y1 - y0).max(1e-9));
    let map = |(x, y): (f64, f64)| (MARGIN + (x - x0) * scale, top + (y - y0) * scale);
    let mut out = String::new();
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}" font-family="sans-serif">"#
    );
    let _ = writeln!(
        out,
        r##"<rect width="100%" height="100%" fill="#fbfaf7"/>"##
    );
    let st = &s.stats;
    let name = s.corrected.surface.name.replace(['<', '>', '&'], " ");
    let _ = writeln!(
        out,
        r#"<text x="{MARGIN}" y="28" font-size="18" font-weight="bold">{name}</text>"#
    );
    let layering = match &st.vessel {
        Some(v) => format!(
            "floor of {} layers · {} spiral turns",
            v.floor_layers, v.wall_turns
        ),
        None => format!(
            "{} passes · {} stage{}",
            st.passes,
            st.stages,
            if st.stages == 1 { "" } else { "s" }
        ),
    };
    let _ = writeln!(
        out,
        r#"<text x="{MARGIN}" y="50" font-size="13">{:.1} × {:.1} × {:.1} mm · {} points · {layering} · {:.1} m · {:.1} ml · {:.1} min</text>"#,
        st.size_mm[0],
        st.size_mm[1],
        st.size_mm[2],
        st.sample_points,
        st.path_length_mm / 1000.0,
        st.volume_ml,
        st.time_min
    );
    // One polyline per run of points of one pass (and kind).
    let mut i = 0;
    while i + 1 < pts.len() {
        let (pass, kind) = (pts[i + 1].pass, pts[i + 1].kind);
        let mut d = String::new();
        let (x, y) = map(proj[i]);
        let _ = write!(d, "{x:.1},{y:.1}");
        let mut j = i + 1;
        while j < pts.len() && pts[j].pass == pass && pts[j].kind == kind {
            let (x, y) = map(proj[j]);
            let _ = write!(d, " {x:.1},{y:.1}");
            j += 1;
        }
        let stroke = match kind {
            PointKind::Top => "#111".to_string(),
            PointKind::Floor => "#9a7b4f".to_string(),
            PointKind::Pass => colour((pass as f64 - 1.0) / (st.passes.max(2) - 1) as f64),
        };
        let _ = writeln!(
            out,
            r#"<polyline points="{d}" fill="none" stroke="{stroke}" stroke-width="0.8" stroke-linejoin="round"/>"#
        );
        i = j - 1;
    }
    for (p, c) in [(proj[0], "#1a9b3c"), (proj[proj.len() - 1], "#d62020")] {
        let (x, y) = map(p);
        let _ = writeln!(out, r#"<circle cx="{x:.1}" cy="{y:.1}" r="5" fill="{c}"/>"#);
    }
    let _ = writeln!(
        out,
        r##"<text x="{MARGIN}" y="{:.0}" font-size="11" fill="#555">passes coloured blue (first) to red (last); black: top-edge beads of returning turns (a vessel: its rim); brown: floor; green: start; red: end</text>"##,
        H - 10.0
    );
    out.push_str("</svg>\n");
    out
}

#[cfg(test)]
mod tests {
    use crate::Design;

    #[test]
    fn preview_draws_every_point_and_marks() {
        let d = Design::from_json(crate::examples::example("t2").unwrap()).unwrap();
        let s = crate::slice(&d).unwrap();
        let svg = super::svg(&s);
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        let coords: usize = svg
            .lines()
            .filter(|l| l.starts_with("<polyline"))
            .map(|l| {
                l.split("points=\"")
                    .nth(1)
                    .unwrap()
                    .split('"')
                    .next()
                    .unwrap()
                    .split(' ')
                    .count()
            })
            .sum();
        // Each polyline repeats the point it starts from.
        let lines = svg.lines().filter(|l| l.starts_with("<polyline")).count();
        assert_eq!(coords - lines + 1, s.toolpath.points.len());
        assert!(svg.contains("#111"), "two-stage t2 has returning turns");
        assert_eq!(svg.matches("<circle").count(), 2);
    }
}
