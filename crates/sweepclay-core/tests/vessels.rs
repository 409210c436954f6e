//! Property tests of vessels (closed Ψ, docs/ALGORITHMS.md §8): random
//! loops — ellipses, lobed loops, cornered polylines, loops off the centre,
//! radial and normal offsets, 0–4 floor layers, one or two profiles —
//! through the whole pipeline, with the independent checker as the oracle
//! and the vessel's own invariants checked directly.

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
mod common;

use sweepclay_core::toolpath::PointKind;
use sweepclay_core::{slice, Design, Error};

/// 300 cases by default, a fifth of them here (or `PROPTEST_CASES`).
fn cases() -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(300)
        / 5
}

fn seed() -> RngSeed {
    RngSeed::Fixed(
        std::env::var("VESSEL_SEED")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(20261201),
    )
}

#[derive(Debug, Clone)]
struct Loop {
    shape: u8,
    rx: f64,
    ry: f64,
    lobes: u32,
    depth: f64,
    centre: (f64, f64),
    normal: bool,
}

fn a_loop() -> impl Strategy<Value = Loop> {
    (
        0u8..3,
        (18.0..55.0f64, 18.0..55.0f64),
        (3u32..8, 0.0..0.18f64),
        (-20.0..20.0f64, -20.0..20.0f64),
        any::<bool>(),
    )
        .prop_map(|(shape, (rx, ry), (lobes, depth), centre, normal)| Loop {
            shape,
            rx,
            ry,
            lobes,
            depth,
            centre,
            normal,
        })
}

/// The trajectory: an ellipse (B-spline), a lobed loop (polyline) or a
/// cornered polygon (polyline), centred off o.
fn trajectory(l: &Loop) -> serde_json::Value {
    let (cx, cy) = l.centre;
    let offset = if l.normal { "normal" } else { "radial" };
    let at = |t: f64, r: f64| [cx + r * l.rx * t.cos(), cy + r * l.ry * t.sin()];
    match l.shape {
        0 => {
            let cp: Vec<[f64; 2]> = (0..8)
                .map(|i| at(std::f64::consts::TAU * i as f64 / 8.0, 1.0))
                .collect();
            serde_json::json!({ "control_points": cp, "closed": true, "offset": offset })
        }
        1 => {
            let pts: Vec<[f64; 2]> = (0..240)
                .map(|i| {
                    let t = std::f64::consts::TAU * i as f64 / 240.0;
                    at(t, 1.0 + l.depth * (l.lobes as f64 * t).cos())
                })
                .collect();
            serde_json::json!({ "points": pts, "closed": true, "offset": offset })
        }
        _ => {
            let pts: Vec<[f64; 2]> = (0..l.lobes)
                .map(|i| at(std::f64::consts::TAU * i as f64 / l.lobes as f64, 1.0))
                .collect();
            serde_json::json!({ "points": pts, "closed": true, "offset": offset })
        }
    }
}

fn profile(h: f64, lean: f64) -> serde_json::Value {
    serde_json::json!({ "control_points": [[0.0, 0.0], [lean, h / 2.0], [0.0, h]] })
}

proptest! {
    // A fixed seed (`VESSEL_SEED` picks another; which seeds pass at
    // many cases: docs/ALGORITHMS.md, "Known limitations").
    #![proptest_config(ProptestConfig { cases: cases().max(4), failure_persistence: None, rng_seed: seed(), .. ProptestConfig::default() })]

    #[test]
    fn random_vessels_print_in_clay(
        l in a_loop(),
        (hs, ht) in (12.0..60.0f64, 0.0..12.0f64),
        (ls, lt) in (-6.0..6.0f64, -6.0..6.0f64),
        two in any::<bool>(),
        floor in 0u32..5,
    ) {
        let end = if two { profile(hs + ht, lt) } else { profile(hs, ls) };
        let v = serde_json::json!({
            "sweepclay": 1, "name": "random vessel",
            "profile_start": profile(hs, ls),
            "profile_end": end,
            "trajectory": trajectory(&l),
            "params": { "floor_layers": floor },
            "printer": { "name": "wide", "build_volume": [300.0, 300.0, 200.0], "origin": [150.0, 150.0] },
        });
        let d = Design::from_json(&v.to_string()).unwrap();
        let s = match slice(&d) {
            Ok(s) => s,
            // Refusals that name their reason are correct: a radial loop
            // round o's wrong side, a rim too steep or too uneven for a
            // spiral, a floor split into islands 8 times over or whose innermost
            // line is out of a short step's reach (docs/ALGORITHMS.md §8,
            // "Known limitations"). Sharp corners are rounded, so a
            // polygon no longer meets itself.
            Err(e @ Error::Invalid { .. }) => {
                let m = e.to_string();
                prop_assert!(
                    m.contains("too steeply") || m.contains("varies") || m.contains("centre o")
                        || m.contains("crosses itself") || m.contains("spiral fills the floor")
                        || m.contains("too narrow for a spiral") || m.contains("spiral covers only"),
                    "{m}"
                );
                return Ok(());
            }
            Err(e) => return Err(TestCaseError::fail(format!("{e}"))),
        };
        let p = &s.corrected.surface.params;
        let t = &s.toolpath;
        let vs = t.vessel.as_ref().unwrap();
        // The floor first, then only wall: no floor bead after the spiral
        // begins.
        let first_wall = t.points.iter().position(|q| q.kind != PointKind::Floor).unwrap();
        prop_assert!(t.points[first_wall..].iter().all(|q| q.kind != PointKind::Floor));
        prop_assert_eq!(vs.floor_layers, floor);
        prop_assert_eq!(vs.floor_turns == 0, floor == 0);
        // Spiral layers within the bounds, the first turn and the rim turn
        // excepted (they rise from the floor and taper to the rim).
        let lo = s.stats.layers.lower_mm;
        prop_assert!(lo[0] >= p.layer_height - 1e-9 && lo[1] <= p.max_layer_height + 1e-9, "{:?}", lo);
        // z never falls by more than a graze from one point to the next
        // of the spiral, and the top is within one layer of the rim.
        let top = t.points.iter().map(|q| q.pos[2]).fold(0.0, f64::max);
        let rim = tallest(&s);
        prop_assert!((rim - top).abs() <= p.max_layer_height + 1e-9);
        // The floor covers the inside: at least 97 % of it lies under a
        // bead of the first layer, as the floor module measures it and
        // as its path's first layer shows.
        if floor > 0 {
            prop_assert!(vs.floor_cover >= 0.97, "floor cover {}", vs.floor_cover);
            let cov = floor_coverage(&s);
            prop_assert!(cov >= 0.97, "floor coverage {cov:.3}\ndesign:\n{}", d.to_json());
        }
        // The independent checker, as `slice` runs it and by its full
        // search, says printable with the same findings (the two may name
        // a different support for a few beads: docs/CHECKER.md, "Known
        // gaps").
        let r = common::check_full(&s);
        // A rim the sampling found too uneven for one spiral is laid, and
        // refused where the replay finds the body meeting clay (the
        // check's advice names it: docs/ALGORITHMS.md §8).
        let uneven = s.corrected.surface.vessel.as_ref().is_some_and(|v| v.uneven.is_some());
        if uneven && !r.printable {
            prop_assert!(r.failures.len() == 1 && r.findings[sweepclay_check::Finding::NozzleCollision].count > 0, "{}", r.render());
            return Ok(());
        }
        prop_assert!(r.printable, "{}\ndesign:\n{}", r.render(), d.to_json());
        let fast = common::check_fast(&s);
        prop_assert!(fast.printable, "{}\ndesign:\n{}", fast.render(), d.to_json());
        prop_assert_eq!(&fast.findings, &r.findings);
        prop_assert_eq!(r.extrusion_runs, 1);
        prop_assert_eq!(r.findings[sweepclay_check::Finding::UnderMinOverlap].count, 0);
        // Our own output lays no bead on clay at its own height: no seam,
        // no join across a floor (docs/ALGORITHMS.md §8).
        prop_assert_eq!(r.support.on_clay, 0, "{}", r.render());
    }
}

/// The control points of a round loop about o whose B-spline is about
/// `r` across its radius (an 8-point loop lies inside its polygon).
fn round_loop(r: f64) -> Vec<[f64; 2]> {
    (0..8)
        .map(|i| {
            let a = std::f64::consts::TAU * f64::from(i) / 8.0;
            [r * 1.08 * a.cos(), r * 1.08 * a.sin()]
        })
        .collect()
}

/// The highest point of a slicing's path (mm).
fn path_top(s: &sweepclay_core::Sliced) -> f64 {
    s.toolpath
        .points
        .iter()
        .map(|p| p.pos[2])
        .fold(0.0, f64::max)
}

/// The share of the points of a 0.5 mm grid inside the wall's first turn
/// that lie within half a bead of a bead of the first floor layer (each
/// bead as wide as the path says).
fn floor_coverage(s: &sweepclay_core::Sliced) -> f64 {
    let t = &s.toolpath;
    let p = &s.corrected.surface.params;
    let z1 = p.layer_height + 1e-6;
    let mut segs = Vec::new();
    for i in 1..t.points.len() {
        let (a, b) = (t.points[i - 1].pos, t.points[i].pos);
        let floor =
            t.points[i].kind == PointKind::Floor && t.points[i - 1].kind == PointKind::Floor;
        if floor && a[2] <= z1 && b[2] <= z1 {
            let w = 0.5 * (s.extrusion.width[i - 1] + s.extrusion.width[i]);
            segs.push(([a[0], a[1]], [b[0], b[1]], w));
        }
    }
    let ring: Vec<[f64; 2]> = s
        .corrected
        .surface
        .columns
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let q = s.corrected.surface.position(i, c.first as usize);
            [q[0], q[1]]
        })
        .collect();
    let cell = p.width_max;
    let mut grid: std::collections::HashMap<(i64, i64), Vec<usize>> = Default::default();
    let key = |p: [f64; 2]| ((p[0] / cell).floor() as i64, (p[1] / cell).floor() as i64);
    for (k, (a, b, _)) in segs.iter().enumerate() {
        let (ka, kb) = (key(*a), key(*b));
        for x in ka.0.min(kb.0) - 1..=ka.0.max(kb.0) + 1 {
            for y in ka.1.min(kb.1) - 1..=ka.1.max(kb.1) + 1 {
                grid.entry((x, y)).or_default().push(k);
            }
        }
    }
    let dist = |p: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let l2 = (dx * dx + dy * dy).max(1e-12);
        let u = (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2).clamp(0.0, 1.0);
        (p[0] - a[0] - u * dx).hypot(p[1] - a[1] - u * dy)
    };
    let inside = |q: [f64; 2]| {
        let mut odd = false;
        for i in 0..ring.len() {
            let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
            if (a[1] > q[1]) != (b[1] > q[1])
                && q[0] < a[0] + (q[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0])
            {
                odd = !odd;
            }
        }
        odd
    };
    let (lo, hi) = ring
        .iter()
        .fold(([f64::MAX; 2], [f64::MIN; 2]), |(l, h), q| {
            (
                [l[0].min(q[0]), l[1].min(q[1])],
                [h[0].max(q[0]), h[1].max(q[1])],
            )
        });
    let (mut n, mut covered) = (0usize, 0usize);
    let mut y = lo[1];
    while y <= hi[1] {
        let mut x = lo[0];
        while x <= hi[0] {
            let q = [x, y];
            if inside(q) {
                n += 1;
                let near = grid.get(&key(q)).is_some_and(|ks| {
                    ks.iter()
                        .any(|&k| dist(q, segs[k].0, segs[k].1) <= 0.5 * segs[k].2)
                });
                covered += usize::from(near);
            }
            x += 0.5;
        }
        y += 0.5;
    }
    covered as f64 / n.max(1) as f64
}

#[test]
fn a_pot_whose_rim_dips_on_one_side_prints() {
    // A 70 mm round pot whose walls lean in 16°, its two profiles 58.3 and
    // 54.3 mm tall. It was refused ("the rim rises or falls too steeply"):
    // the sampling counted the bead just laid as old clay because it
    // measured the path along Ψ at the foot, where it is 1.8 times as
    // long as at the rim. The replay finds nothing in the body's way.
    let lean = |h: f64| {
        let x = -h * (16f64).to_radians().tan();
        serde_json::json!({ "control_points": [[0.0, 0.0], [x / 2.0, h / 2.0], [x, h]] })
    };
    let cp: Vec<[f64; 2]> = (0..8)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / 8.0;
            [37.8 * a.cos(), 37.8 * a.sin()]
        })
        .collect();
    let d = Design::from_json(
        &serde_json::json!({
            "sweepclay": 1,
            "profile_start": lean(58.3),
            "profile_end": lean(54.3),
            "trajectory": { "control_points": cp, "closed": true },
            "printer": "cerambot-plus",
        })
        .to_string(),
    )
    .unwrap();
    let s = slice(&d).unwrap();
    let v = s.corrected.surface.vessel.as_ref().unwrap();
    assert_eq!(v.uneven, None);
    let r = common::check_full(&s);
    assert!(r.printable, "{}", r.render());
    // Four times as steep a dip (18.3 mm) is more than one spiral
    // carries: the spiral carries the rim up to a level, and the part
    // above is laid as passes back and forth along its arc, each turning
    // where a climb along the rim lays the tops (docs/ALGORITHMS.md §8).
    let mut steep = d.clone();
    steep.profile_end = Some(serde_json::from_value(lean(40.0)).unwrap());
    let s = slice(&steep).unwrap();
    let v = s.corrected.surface.vessel.as_ref().unwrap();
    let a = v.arc.as_ref().expect("a raised arc");
    assert!(
        a.level_mm > 40.0 && a.level_mm < 58.3 && a.most_passes() > 2,
        "{a:?}"
    );
    let r = common::check_full(&s);
    assert!(r.printable, "{}", r.render());
    // The rim as drawn: the path's highest point is the pot's.
    let top = path_top(&s);
    assert!((top - 58.3).abs() < 0.01, "{top}");
}

#[test]
fn rims_slanted_raised_and_waved_print_as_drawn() {
    // A cylinder 93 mm across whose rim runs 60 → 100 mm round the loop
    // (slanted), or 60 mm with a back raised 40 mm (a pitcher): partial
    // layers above the spiral. A 130 mm one whose rim waves in two peaks
    // 12.5 mm above the valleys: one spiral carries it. Each passes the
    // check, its top the drawn rim's height (half a layer above at most).
    let pot = |r: f64, hi: f64, interp: Option<serde_json::Value>| {
        let mut v = serde_json::json!({
            "sweepclay": 1,
            "profile_start": { "control_points": [[0.0, 0.0], [0.0, 60.0]] },
            "profile_end": { "control_points": [[0.0, 0.0], [0.0, hi]] },
            "trajectory": { "control_points": round_loop(r), "closed": true },
            "printer": { "name": "wide", "build_volume": [300.0, 300.0, 250.0], "origin": [150.0, 150.0] },
        });
        if let Some(i) = interp {
            v["interpolation"] = i;
        }
        Design::from_json(&v.to_string()).unwrap()
    };
    let back = serde_json::json!({ "control_points": [[0, 0], [0.3, 0], [0.42, 1], [0.5, 1], [0.58, 1], [0.7, 0], [1, 0]] });
    let wave = serde_json::json!({ "control_points": [[0, 0], [0.125, 1], [0.25, 1], [0.375, 0], [0.5, 0], [0.625, 1], [0.75, 1], [0.875, 0], [1, 0]] });
    for (what, d, raised) in [
        ("slanted", pot(40.0, 100.0, None), true),
        ("pitcher", pot(40.0, 100.0, Some(back)), true),
        ("wave", pot(60.0, 73.0, Some(wave)), false),
    ] {
        let s = slice(&d).unwrap_or_else(|e| panic!("{what}: {e}"));
        let v = s.corrected.surface.vessel.as_ref().unwrap();
        assert_eq!(v.arc.is_some(), raised, "{what}");
        let r = common::check_full(&s);
        assert!(r.printable, "{what}: {}", r.render());
        // The returning turns' climbs lay no bead narrower than w_min, as
        // the checker reads each against the clay under it, nor taller
        // than it is wide (issue 57, point 5: 1.3–1.5 mm beads 2 mm tall
        // climbed the slanted rim's edge).
        assert_eq!(r.support.thin.count, 0, "{what}: {}", r.render());
        let (w, h) = (&s.extrusion.width, &s.extrusion.layer_height);
        let w_min = s.corrected.surface.params.width_min;
        for i in 0..w.len() {
            assert!(
                w[i] >= w_min - 1e-9 && h[i] <= w[i] + 1e-9,
                "{what}: point {i}: {} wide, {} tall",
                w[i],
                h[i]
            );
        }
        let top = path_top(&s);
        let rim = tallest(&s);
        // A raised arc's tops reach the rim; a spiral's rim turn ends
        // where its beads would be under half a layer (within a layer).
        let below = if raised { 1e-6 } else { 1.25 };
        assert!(
            top >= rim - below && top <= rim + 0.625 + 1e-6,
            "{what}: top {top}, rim {rim}"
        );
    }
}

#[test]
fn a_rim_shaped_by_its_rise_and_angle_prints_as_drawn() {
    // One profile and a rim: slanted 30 mm toward +y, a raised back, and
    // three waves of 6 mm on a 130 mm pot. The rim stands where the key
    // says (the columns' heights by their angle) and the print passes.
    for (rim, r) in [
        (
            serde_json::json!({ "shape": "slant", "rise": 30, "toward_deg": 90 }),
            40.0,
        ),
        (
            serde_json::json!({ "shape": "raised", "rise": 25, "toward_deg": 180, "width_deg": 100 }),
            40.0,
        ),
        (
            serde_json::json!({ "shape": "wave", "rise": 6, "peaks": 3 }),
            60.0,
        ),
    ] {
        let d = Design::from_json(
            &serde_json::json!({
                "sweepclay": 1,
                "profile_start": { "control_points": [[0.0, 0.0], [6.0, 30.0], [0.0, 60.0]] },
                "trajectory": { "control_points": round_loop(r), "closed": true },
                "rim": rim,
                "printer": { "name": "wide", "build_volume": [300.0, 300.0, 250.0], "origin": [150.0, 150.0] },
            })
            .to_string(),
        )
        .unwrap();
        let s = slice(&d).unwrap_or_else(|e| panic!("{rim}: {e}"));
        let spec = d.rim.as_ref().unwrap();
        for c in &s.corrected.surface.columns {
            let want = 60.0 + spec.rise * spec.lambda(c.p);
            assert!(
                (c.height - want).abs() < 1e-9,
                "{rim}: {} against {want}",
                c.height
            );
        }
        let r = common::check_full(&s);
        assert!(r.printable, "{rim}: {}", r.render());
        let hi = tallest(&s);
        assert!(hi > 60.0 + 0.95 * spec.rise, "{rim}: {hi}");
    }
    // Old files read as before; a rim on a wall, or beside a second
    // profile, is refused by name.
    let wall = r#"{"sweepclay":1,"profile_start":{"control_points":[[0,0],[0,30]]},"trajectory":{"control_points":[[-30,10],[30,10]]},"rim":{"shape":"slant","rise":10}}"#;
    let e = Design::from_json(wall).unwrap_err().to_string();
    assert!(e.starts_with("rim: shapes a vessel's rim"), "{e}");
}

#[test]
fn a_round_vase_twisted_up_to_two_turns_prints_as_the_vase() {
    // Refused at any twist of 90° or more: the fold test compared the
    // curves' order at the top with Ψ's unturned direction. Then at 360°
    // every bead was laid w_max wide (a column's turn along the wall was
    // taken for an offset across it: twice the clay, a failed check), and
    // at 720° the neck was called self-intersecting (samples a part of a
    // layer apart in height, turned 9° apart, compared as one layer).
    let plain = Design::from_json(include_str!("../../../examples/vase.json")).unwrap();
    let clay = slice(&plain).unwrap().extrusion.total_volume;
    for twist in [-90.0, 90.0, 180.0, 360.0, 540.0, -720.0, 720.0] {
        let mut d = plain.clone();
        d.twist_deg = twist;
        let s = slice(&d).unwrap_or_else(|e| panic!("twist {twist}: {e}"));
        let r = common::check_full(&s);
        assert!(r.printable, "twist {twist}: {}", r.render());
        let v = s.extrusion.total_volume;
        assert!(
            (v / clay - 1.0).abs() < 0.05,
            "twist {twist}: {v:.0} mm³ of clay, {clay:.0} untwisted"
        );
        // A round vase turned is the same vase: no correction moves it.
        let moved = s
            .corrected
            .report
            .support
            .iter()
            .map(|f| f.max_shift_mm)
            .fold(0.0, f64::max);
        assert!(moved < 1.0, "twist {twist}: moved {moved} mm");
    }
}

#[test]
fn a_diamond_pot_has_its_sharp_corners_rounded_and_prints() {
    // Two 53° corners: the wall's beads on their arms would lie on each
    // other (it was refused: "the trajectory comes within one bead width
    // of itself"). Rounded, reported, and printable; its rim rises by
    // 8 mm round the loop.
    let d = Design::from_json(
        &serde_json::json!({
            "sweepclay": 1,
            "profile_start": { "control_points": [[0.0, 0.0], [0.0, 40.0]] },
            "profile_end": { "control_points": [[0.0, 0.0], [0.0, 48.0]] },
            "trajectory": { "points": [[50.0, 0.0], [0.0, 25.0], [-50.0, 0.0], [0.0, -25.0]],
                            "closed": true, "offset": "normal" },
        })
        .to_string(),
    )
    .unwrap();
    let s = slice(&d).unwrap();
    let corners = &s.corrected.report.corners;
    assert_eq!(corners.len(), 2, "{corners:?}");
    assert!(corners.iter().all(|c| (c.angle_deg - 53.13).abs() < 0.01));
    assert!(s
        .corrected
        .report
        .summary()
        .iter()
        .any(|l| l.starts_with("corners: 2 sharp corner(s)")));
    let r = common::check_full(&s);
    assert!(r.printable, "{}", r.render());
}

#[test]
fn a_peanut_pot_gets_one_spiral_floor_and_prints() {
    // Two lobes joined by a waist: its offsets split into two islands,
    // the rays to a spine along its length do not. One spiral a layer,
    // and the whole pot is one path the checker passes.
    let peanut = |waist: f64| {
        let pts: Vec<[f64; 2]> = (0..48)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / 48.0;
                [
                    55.0 * a.cos(),
                    32.0 * a.sin() * (waist + (1.0 - waist) * a.cos().abs()),
                ]
            })
            .collect();
        Design::from_json(
            &serde_json::json!({
                "sweepclay": 1,
                "profile_start": { "control_points": [[0.0, 0.0], [0.0, 40.0]] },
                "trajectory": { "control_points": pts, "closed": true, "offset": "normal" },
                "params": { "floor_layers": 3 },
                "printer": "cerambot-plus",
            })
            .to_string(),
        )
        .unwrap()
    };
    let s = slice(&peanut(0.6)).unwrap();
    let v = s.toolpath.vessel.as_ref().expect("a vessel");
    assert!(v.floor_cover >= 0.97, "{}", v.floor_cover);
    let r = common::check_full(&s);
    assert!(r.printable, "{}", r.render());
    assert_eq!(r.support.on_clay, 0, "{}", r.render());
    // A waist a third of the lobes: one spiral still, or refused naming
    // the floor and the way out.
    match slice(&peanut(0.35)) {
        Ok(s) => assert!(common::check_full(&s).printable),
        Err(e) => {
            let e = e.to_string();
            assert!(e.contains("spiral fills the floor"), "{e}");
            assert!(e.contains("floor_layers = 0"), "{e}");
        }
    }
}

/// The tallest column's height (mm): the rim's highest point.
fn tallest(s: &sweepclay_core::Sliced) -> f64 {
    s.corrected
        .surface
        .columns
        .iter()
        .map(|c| c.height)
        .fold(0.0, f64::max)
}

#[test]
fn a_first_turn_that_cannot_start_names_the_most_the_rim_may_rise() {
    // A rounded square with no floor whose two-crest rim (21 to 38 mm)
    // leaves the wall's first turn more than a thickest layer above the
    // bed wherever it starts (random vessel 29 of `RIMS=1` seed 11). The
    // refusal names the highest the rim may be; lowered to it, that
    // refusal is gone.
    let text = include_str!("first-turn.json");
    let e = slice(&Design::from_json(text).unwrap())
        .unwrap_err()
        .to_string();
    let most: f64 = e
        .split("bring the rim's highest point to ")
        .nth(1)
        .and_then(|r| r.split(" mm or less").next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("{e}"));
    assert!(
        e.contains("wherever it starts") && most < 38.0 && most > 21.2,
        "{e}"
    );
    // The rim drawn toward its lowest (the start profile's top, 21.17 mm)
    // until its highest is `most`: the end profile's heights scaled.
    let mut d = Design::from_json(text).unwrap();
    let lo = d.profile_start.control_points.last().unwrap()[1];
    let end = d.profile_end.as_mut().unwrap();
    let zt = end.control_points.last().unwrap()[1];
    let f = (most - 0.05 - lo) / (38.0 - lo);
    let k = (lo + f * (zt - lo)) / zt;
    for p in &mut end.control_points {
        p[1] *= k;
    }
    let again = slice(&d)
        .map(|_| String::new())
        .unwrap_or_else(|e| e.to_string());
    assert!(!again.contains("wherever it starts"), "{again}");
}

/// Issue 57, point 2: raising the rim adds height at the rim, a
/// continuation of the body's top; it does not stretch the body. The belly
/// vase (rows 70 / 115 / 60 / 72 mm outside at 0 / 45 / 105 / 140 mm)
/// raised 30 mm at the back: below its top the wall is as wide at the back
/// as at the front, within half a millimetre, at every height; stretched,
/// the back stood several millimetres off the front at the neck.
#[test]
fn a_raised_rim_keeps_the_body_it_rises_from() {
    let mut v: serde_json::Value =
        serde_json::from_str(include_str!("../../../examples/belly-vase.json")).unwrap();
    v["rim"] = serde_json::json!({"shape": "raised", "rise": 30, "toward_deg": 90});
    let d = Design::from_json(&v.to_string()).unwrap();
    let s = slice(&d).unwrap_or_else(|e| panic!("{e}"));
    let r = common::check_full(&s);
    assert!(r.printable, "{}", r.render());
    // The wall's distance from o at the back (+y) and the front (−y),
    // over the path's points within half a millimetre of each height.
    let pts: Vec<[f64; 3]> = s
        .toolpath
        .points
        .iter()
        .filter(|p| p.kind != sweepclay_core::toolpath::PointKind::Floor)
        .map(|p| p.pos)
        .collect();
    // The toolpath is in the design's frame: o at the origin.
    let centre = |_z: f64| [0.0, 0.0];
    let at = |z: f64, back: bool| {
        let o = centre(z);
        let sel: Vec<f64> = pts
            .iter()
            .filter(|p| (p[2] - z).abs() < 0.7)
            .filter(|p| {
                let a = (p[1] - o[1]).atan2(p[0] - o[0]).to_degrees();
                if back {
                    (a - 90.0).abs() < 4.0
                } else {
                    (a + 90.0).abs() < 4.0
                }
            })
            .map(|p| (p[0] - o[0]).hypot(p[1] - o[1]))
            .collect();
        assert!(!sel.is_empty(), "no wall at z {z}");
        sel.iter().sum::<f64>() / sel.len() as f64
    };
    for z in [20.0, 45.0, 80.0, 105.0, 130.0] {
        let (b, f) = (at(z, true), at(z, false));
        assert!(
            (b - f).abs() < 0.5,
            "at z {z}: back {b:.2} mm, front {f:.2} mm from o"
        );
    }
}

/// Per 5° about the floor's middle, the outermost edge of the floor's top
/// layer minus that of the wall's first turn (mm; + a ledge, − a notch),
/// each bead's edge its middle plus half the width the extrusion gives it
/// (as `scripts/foot-flush` reads a G-code file).
fn foot_steps(s: &sweepclay_core::Sliced) -> Vec<f64> {
    let t = &s.toolpath;
    let w = &s.extrusion.width;
    let floor_top = t
        .points
        .iter()
        .filter(|p| p.kind == PointKind::Floor)
        .map(|p| p.pass)
        .max()
        .expect("a floor");
    let top: Vec<usize> = (0..t.points.len())
        .filter(|&i| t.points[i].kind == PointKind::Floor && t.points[i].pass == floor_top)
        .collect();
    let k = top.len() as f64;
    let c = top.iter().fold([0.0, 0.0], |c, &i| {
        [c[0] + t.points[i].pos[0] / k, c[1] + t.points[i].pos[1] / k]
    });
    let mut edges = [[f64::NEG_INFINITY; 2]; 72];
    for (i, p) in t.points.iter().enumerate() {
        let layer = match p.kind {
            PointKind::Floor if p.pass == floor_top => 0,
            PointKind::Pass if p.pass == floor_top + 1 => 1,
            _ => continue,
        };
        let (dx, dy) = (p.pos[0] - c[0], p.pos[1] - c[1]);
        let bin = ((dy.atan2(dx).to_degrees().rem_euclid(360.0)) / 5.0) as usize % 72;
        let e = &mut edges[bin][layer];
        *e = e.max(dx.hypot(dy) + 0.5 * w[i]);
    }
    edges
        .iter()
        .filter(|e| e.iter().all(|v| v.is_finite()))
        .map(|e| e[0] - e[1])
        .collect()
}

/// [`foot_steps`] of a sliced design, read all round (70 bins or more).
fn foot_steps_all_round(s: &sweepclay_core::Sliced) -> Vec<f64> {
    let steps = foot_steps(s);
    assert!(steps.len() >= 70, "{} bins", steps.len());
    steps
}

/// Asserts the foot steps by at most 0.3 mm in every bin.
fn assert_flush(steps: &[f64]) {
    let worst = steps.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
    assert!(
        worst <= 0.3,
        "the foot steps by up to {worst:.2} mm: {steps:?}"
    );
}

#[test]
fn a_foot_under_a_wall_leaning_out_is_flush_with_its_wider_first_turn() {
    // The bundled bowl leans out from its foot. Its first turn was laid
    // 3.8 mm wide while a wide bead higher up widened every bead under it
    // to its own width, and its edge stood 0.41 mm outside the 3 mm floor
    // beads all round until the floor's outer ring moved out to it. Each
    // bead is now widened only as far as the one above needs: the first
    // turn is 3 mm, and the foot is flush either way.
    let (_, text) = sweepclay_core::examples::EXAMPLES
        .iter()
        .find(|(n, _)| *n == "bowl.json")
        .expect("the bowl");
    let s = slice(&Design::from_json(text).expect("valid")).expect("slices");
    let first = s
        .toolpath
        .points
        .iter()
        .position(|p| p.kind == PointKind::Pass)
        .expect("a wall");
    assert!(
        s.extrusion.width[first] < 3.2,
        "{}",
        s.extrusion.width[first]
    );
    assert_flush(&foot_steps_all_round(&s));
}

#[test]
fn a_cone_leaning_out_from_its_foot_stands_flush_on_its_floor() {
    // A cone 46° from upright from its very first turn lays that turn
    // 3.9 mm wide, and the floor's outer ring moves out 0.45 mm to meet
    // it. With the inner rings stepping over 3 bead widths that spiral
    // was cut at 555 of 1,364 mm (two turns' steps 2.17 mm apart, the
    // least gap), so the floor was laid on the ring as drawn and the foot
    // read −0.45 mm all round. A longer inner step is tried next.
    let text = r#"{"sweepclay": 1, "name": "cone",
      "profile_start": {"control_points": [[0, 0], [41.4, 40]]},
      "trajectory": {"control_points": [[42.666, 0], [30.169, 30.169],
        [0, 42.666], [-30.169, 30.169], [-42.666, 0], [-30.169, -30.169],
        [0, -42.666], [30.169, -30.169]], "closed": true},
      "params": {"floor_layers": 3}, "printer": "cerambot-plus"}"#;
    let s = slice(&Design::from_json(text).expect("valid")).expect("slices");
    assert_flush(&foot_steps_all_round(&s));
}

#[test]
fn an_elongated_oval_stands_flush_on_a_floor_along_rays() {
    // A random oval, 106 × 45 mm (seed 61, vessel 142): its offsets a
    // pitch apart end in thin lenses whose sides come within the least
    // gap, so no stepped ring walk kept its turns apart, and the floor was
    // the rays' blended spiral, from half a pitch outside the outline to
    // half a pitch inside: 57 of 72 bins beyond ±0.3 mm, −2.0 to +1.8.
    // The rays stepped as the rings are keep the outermost turn on it.
    let text = r#"{"sweepclay": 1, "name": "long oval",
      "profile_start": {"control_points": [[0, 0], [7.35, 14.14], [0, 28.29]]},
      "profile_end": {"control_points": [[0, 0], [-0.6, 15.35], [0, 30.7]]},
      "trajectory": {"control_points": [[54.375, 5.868], [38.838, 21.655],
        [1.327, 28.194], [-36.184, 21.655], [-51.721, 5.868],
        [-36.184, -9.919], [1.327, -16.458], [38.838, -9.919]],
        "closed": true, "offset": "normal"},
      "params": {"floor_layers": 1},
      "printer": {"name": "wide", "build_volume": [300, 300, 250], "origin": [150, 150]}}"#;
    let s = slice(&Design::from_json(text).expect("valid")).expect("slices");
    let steps = foot_steps_all_round(&s);
    let beyond = steps.iter().filter(|d| d.abs() > 0.3).count();
    assert!(beyond <= 2, "{beyond} bins beyond ±0.3 mm: {steps:?}");
}

#[test]
fn a_floor_is_not_stepped_along_rays_slanting_at_the_walls_start() {
    // Seed 3's case 1,235 of `random_vessels_print_in_clay`: a 106 × 46 mm
    // oval with six shallow lobes, three floor layers. The ray from the
    // wall's start ran nearly along the outline round the spine's end;
    // stepped along it, the floor's last step ended a bead along the wall
    // from where it began, and the wall's first two beads rested on less
    // than half their width. Such rays are not walked stepped.
    let l = Loop {
        shape: 1,
        rx: 53.164225783954485,
        ry: 23.042513385847904,
        lobes: 6,
        depth: 0.05806219365454452,
        centre: (0.0, 0.0),
        normal: true,
    };
    let v = serde_json::json!({
        "sweepclay": 1, "name": "lobed oval",
        "profile_start": profile(24.68028131554854, -5.557182687701134),
        "profile_end": profile(24.68028131554854, -5.557182687701134),
        "trajectory": trajectory(&l),
        "params": { "floor_layers": 3 },
        "printer": { "name": "wide", "build_volume": [300.0, 300.0, 200.0], "origin": [150.0, 150.0] },
    });
    let s = slice(&Design::from_json(&v.to_string()).unwrap()).expect("slices");
    let r = common::check_full(&s);
    assert!(r.printable, "{}", r.render());
}
