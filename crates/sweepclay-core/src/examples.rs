//! The bundled example designs, modelled on the paper's Table 1 models t1–t6
//! (Fig. 11). `sweepclay examples DIR` writes them out.

/// `(file name, design JSON)` for each bundled example.
pub const EXAMPLES: &[(&str, &str)] = &[
    ("t1.json", include_str!("../../../examples/t1.json")),
    ("t2.json", include_str!("../../../examples/t2.json")),
    ("t3.json", include_str!("../../../examples/t3.json")),
    ("t4.json", include_str!("../../../examples/t4.json")),
    ("t5.json", include_str!("../../../examples/t5.json")),
    ("t6.json", include_str!("../../../examples/t6.json")),
];

/// A bundled example by name (`t1` or `t1.json`).
pub fn example(name: &str) -> Option<&'static str> {
    let want = name.strip_suffix(".json").unwrap_or(name);
    EXAMPLES
        .iter()
        .find(|(n, _)| n.strip_suffix(".json") == Some(want))
        .map(|(_, t)| *t)
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
