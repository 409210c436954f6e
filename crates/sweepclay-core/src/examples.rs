//! The bundled example designs: six pots as potters make them (a
//! cylinder, a belly vase, a bowl, a tumbler, a planter, a bud vase, each
//! typed as widths at heights; `scripts/pot-examples` writes them, and the
//! first is the modeler's cold open), walls modelled on the paper's Table 1
//! models t1–t6 (Fig. 11), five vessels (a round vase, a flower vase
//! whose two profiles differ, a cup for the cerambot-mini, a vase whose
//! rim slants and a pitcher with a raised back, both with partial layers
//! above the spiral) and four
//! textured ones (a rippled vase, a fluted cup, twisted lobes, a vase with
//! an image texture; `scripts/texture-examples` writes them). `sweepclay
//! examples DIR` writes them out.

/// `(file name, design JSON)` for each bundled example.
pub const EXAMPLES: &[(&str, &str)] = &[
    (
        "belly-vase.json",
        include_str!("../../../examples/belly-vase.json"),
    ),
    (
        "cylinder.json",
        include_str!("../../../examples/cylinder.json"),
    ),
    ("bowl.json", include_str!("../../../examples/bowl.json")),
    (
        "tumbler.json",
        include_str!("../../../examples/tumbler.json"),
    ),
    (
        "planter.json",
        include_str!("../../../examples/planter.json"),
    ),
    (
        "bud-vase.json",
        include_str!("../../../examples/bud-vase.json"),
    ),
    ("t1.json", include_str!("../../../examples/t1.json")),
    ("t2.json", include_str!("../../../examples/t2.json")),
    ("t3.json", include_str!("../../../examples/t3.json")),
    ("t4.json", include_str!("../../../examples/t4.json")),
    ("t5.json", include_str!("../../../examples/t5.json")),
    ("t6.json", include_str!("../../../examples/t6.json")),
    ("vase.json", include_str!("../../../examples/vase.json")),
    ("flower.json", include_str!("../../../examples/flower.json")),
    ("cup.json", include_str!("../../../examples/cup.json")),
    (
        "slanted-vase.json",
        include_str!("../../../examples/slanted-vase.json"),
    ),
    (
        "pitcher.json",
        include_str!("../../../examples/pitcher.json"),
    ),
    (
        "ripple-vase.json",
        include_str!("../../../examples/ripple-vase.json"),
    ),
    (
        "fluted-cup.json",
        include_str!("../../../examples/fluted-cup.json"),
    ),
    (
        "twisted-lobes.json",
        include_str!("../../../examples/twisted-lobes.json"),
    ),
    (
        "diamond-vase.json",
        include_str!("../../../examples/diamond-vase.json"),
    ),
];

/// A bundled example by name (`t1` or `t1.json`).
pub fn example(name: &str) -> Option<&'static str> {
    let want = name.strip_suffix(".json").unwrap_or(name);
    EXAMPLES
        .iter()
        .find(|(n, _)| n.strip_suffix(".json") == Some(want))
        .map(|(_, t)| *t)
}

/// The sample counts of the benchmarks' scaling series of [`scaled`].
pub const SCALING_SIZES: [usize; 7] = [
    10_000, 30_000, 100_000, 300_000, 1_000_000, 3_000_000, 10_000_000,
];

/// The benchmark design: t1 enlarged 2.5× in plan, both profiles stretched
/// to 240 mm (a wall on a 400 mm printer), sampled at the layer height and
/// spacing that give about `samples` surface samples (layer height from
/// 1.25 mm down to 0.5 mm first, then the spacing). Every size is the same
/// shape, only finer: the scaling series of the benchmarks.
pub fn scaled(samples: usize) -> crate::Design {
    use crate::printer::{Printer, PrinterRef};
    let mut d = crate::Design::from_json(example("t1").expect("t1 is bundled")).expect("t1 parses");
    d.name = format!("t1 x2.5, 240 mm, {samples} samples");
    if let Some(p) = d.trajectory.points.as_mut() {
        p.iter_mut().for_each(|q| *q = q.map(|v| 2.5 * v));
    }
    // Both ends 240 mm tall: one stage at every resolution, so the sample
    // count follows spacing and layer height smoothly.
    for c in std::iter::once(&mut d.profile_start).chain(d.profile_end.as_mut()) {
        let top = c.control_points.last().expect("a profile has points")[1];
        c.control_points
            .iter_mut()
            .for_each(|q| q[1] *= 240.0 / top);
    }
    d.printer = PrinterRef::Inline(Box::new(Printer {
        name: "bench-400".into(),
        build_volume: [400.0, 400.0, 400.0],
        origin: [200.0, 200.0],
        ..Printer::preset("generic").expect("generic is a preset")
    }));
    // About 110,000 samples at 1.1 mm × 1.25 mm; samples ∝ 1 / (spacing ·
    // layer height).
    let base = 110_000.0 * 1.1 * 1.25;
    let lh = (1.25 * (110_000.0 / samples as f64).sqrt()).clamp(0.5, 1.25);
    d.params.layer_height = lh;
    d.params.max_layer_height = 2.0 * lh;
    d.params.spacing = (base / (lh * samples as f64)).clamp(0.01, 50.0);
    // Corrections from real counts (sampling is cheap next to the rest of
    // the pipeline); the layering itself depends a little on the spacing.
    for _ in 0..6 {
        let Ok(s) = crate::surface::sample_surface(&d) else {
            break;
        };
        let ratio = s.samples.len() as f64 / samples as f64;
        if (ratio - 1.0).abs() < 0.03 {
            break;
        }
        d.params.spacing = (d.params.spacing * ratio).clamp(0.01, 50.0);
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Design;

    #[test]
    fn every_example_parses_and_slices() {
        for (name, text) in EXAMPLES {
            let d = Design::from_json(text).unwrap_or_else(|e| panic!("{name}: {e}"));
            let s = crate::slice(&d).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(s.stats.sample_points > 1000, "{name}: {:?}", s.stats);
        }
    }

    #[test]
    fn scaled_design_has_about_the_samples_asked_for() {
        for n in [10_000, 100_000] {
            let d = scaled(n);
            let s = crate::surface::sample_surface(&d).unwrap();
            let got = s.samples.len() as f64;
            assert!((got / n as f64 - 1.0).abs() < 0.1, "{n}: {got}");
        }
    }

    #[test]
    fn two_stage_examples_are_the_papers() {
        for (name, text) in EXAMPLES {
            let s = crate::slice(&Design::from_json(text).unwrap()).unwrap();
            let want = if matches!(*name, "t2.json" | "t3.json") {
                2
            } else {
                1
            };
            assert_eq!(s.stats.stages, want, "{name}");
        }
    }
}
