//! Vessels keep the potter's form through the correction loop
//! (docs/ALGORITHMS.md §4, "The loop closes"): where the check fails and
//! the loop tightens the support-free correction, it tightens a long,
//! gentle stretch of the loop, never a sector, so a round pot stays round.

use sweepclay_core::Design;
use sweepclay_web::guard::Cancel;
use sweepclay_web::verify::slice_checked;

/// Each layer's (1.25 mm of height's) radii about o of the extruding
/// moves' ends, from the G-code: (z, min, mean, max).
fn layer_radii(gcode: &str, origin: [f64; 2]) -> Vec<(f64, f64, f64, f64)> {
    let mut by: std::collections::BTreeMap<i64, Vec<f64>> = Default::default();
    let mut z = 0.0;
    for line in gcode.lines().filter(|l| l.starts_with("G1 ")) {
        let word = |c: char| {
            line.split_whitespace()
                .find(|w| w.starts_with(c))
                .and_then(|w| w[1..].parse::<f64>().ok())
        };
        if let Some(v) = word('Z') {
            z = v;
        }
        if let (Some(x), Some(y), Some(_)) = (word('X'), word('Y'), word('E')) {
            let r = (x - origin[0]).hypot(y - origin[1]);
            by.entry((z / 1.25).round() as i64).or_default().push(r);
        }
    }
    by.into_iter()
        .map(|(k, r)| {
            let lo = r.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = r.iter().copied().fold(0.0, f64::max);
            (
                k as f64 * 1.25,
                lo,
                r.iter().sum::<f64>() / r.len() as f64,
                hi,
            )
        })
        .collect()
}

#[test]
fn a_pot_on_a_wide_foot_is_corrected_round() {
    // "New pot" on the cerambot-plus with its base typed 150 mm wide under
    // rows 60 mm wide: the wall leans in past the overhang limit and the
    // support-free correction holds it out. The first G-code fails its
    // check at a few columns; the tightening there was a box a bead wide,
    // compounded per failing column, and left a fin standing out to the
    // foot's radius (91 × 109 mm at z 30, "31.2 mm wider than drawn").
    let cp: Vec<[f64; 2]> = (0..8)
        .map(|i| {
            let a = std::f64::consts::TAU * f64::from(i) / 8.0;
            [81.0 * a.cos(), 81.0 * a.sin()]
        })
        .collect();
    let d = Design::from_json(
        &serde_json::json!({
            "sweepclay": 1, "name": "new pot",
            "profile_start": { "control_points": [[0, 0], [-45, 20], [-45, 40], [-45, 60]] },
            "trajectory": { "control_points": cp, "closed": true },
            "printer": "cerambot-plus",
        })
        .to_string(),
    )
    .unwrap();
    let c = slice_checked(&d, 0.5, &Cancel::new(), || Ok(Vec::new())).unwrap();
    assert!(c.report.printable, "{:?}", c.report.failures);
    let origin = c.sliced.corrected.surface.printer.origin;
    let text = String::from_utf8(c.out).unwrap();
    let floor = c.sliced.toolpath.vessel.as_ref().unwrap().floor_top_mm;
    let mut layers = 0;
    for (z, lo, mean, hi) in layer_radii(&text, origin) {
        if z <= floor + 1e-6 {
            continue;
        }
        layers += 1;
        assert!(
            hi - mean <= 3.0 && mean - lo <= 3.0,
            "z {z}: radius {lo:.1}..{hi:.1} about {mean:.1}"
        );
    }
    assert!(layers > 40, "{layers}");
}
