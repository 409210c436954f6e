//! Designs the property test once found failing (minimised by proptest),
//! kept as regression tests: each must slice and pass the independent check.
//! r1: returning turn over a just-laid pass end; r2: tilted pass beside a
//! wider bead; r3: first layer thicker than 3 mm; r4: steep climbing turn;
//! r5: lean-out step at the trajectory's start; r6: steep tilted pass;
//! r7: the checker's support shortcut at a pass that curls round a corner
//! of tiny beads (the shortcut answered a bead that was not the nearest).
//! Polylines with sharp corners (SVG-like imports): p1, p2: a corner's
//! pile-up of fresh clay read as double deposition; p3: the same tilted
//! pass within the extruder body's reach round a corner (fixed in the
//! layering: reach measured in plan); p4: a returning turn turning back at
//! a corner. p5 (smooth): the first top-edge bead after an outward step,
//! running back over the pass below. p6: a returning turn running into a
//! polyline corner.

mod common;

use sweepclay_core::{slice, Design};

fn run(name: &str, text: &str) {
    let d = Design::from_json(text).unwrap_or_else(|e| panic!("{name}: {e}"));
    let s = slice(&d).unwrap_or_else(|e| panic!("{name}: {e}"));
    let r = common::check_sliced(&s);
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

regression!(r1, r2, r3, r4, r5, r6, r7, p1, p2, p3, p4, p5, p6);
