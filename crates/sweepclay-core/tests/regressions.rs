//! Designs the property test once found failing (minimised by proptest),
//! kept as regression tests: each must slice and pass the independent check.
//! r1: returning turn over a just-laid pass end; r2: tilted pass beside a
//! wider bead; r3: first layer thicker than 3 mm; r4: steep climbing turn;
//! r5: lean-out step at the trajectory's start; r6: steep tilted pass.

use sweepclay_check::{check, CheckConfig};
use sweepclay_core::{gcode, slice, Design};

fn run(name: &str, text: &str) {
    let d = Design::from_json(text).unwrap_or_else(|e| panic!("{name}: {e}"));
    let s = slice(&d).unwrap_or_else(|e| panic!("{name}: {e}"));
    let p = &s.corrected.surface.params;
    let pr = &s.corrected.surface.printer;
    let cfg = CheckConfig {
        build_volume: pr.build_volume,
        e_per_mm3: pr.e_per_mm3,
        nozzle_radius: pr.nozzle_radius,
        nozzle_height: p.nozzle_height,
        width_min: p.width_min,
        width_max: p.width_max,
        overlap_target: p.overlap,
        max_overhang_deg: p.max_overhang_deg,
        first_layer_max_mm: p.max_layer_height + 0.05,
        ..CheckConfig::default()
    };
    let r = check(&gcode::to_string(&s), &cfg);
    assert!(r.printable, "{name}:\n{}", r.render());
}

macro_rules! regression {
    ($($n:ident),*) => {$(
        #[test]
        fn $n() {
            run(stringify!($n), include_str!(concat!("regressions/", stringify!($n), ".json")));
        }
    )*};
}

regression!(r1, r2, r3, r4, r5, r6);
