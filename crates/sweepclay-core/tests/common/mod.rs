//! Helpers shared by the integration tests of the pipeline.

use sweepclay_check::{check, check_exhaustive, check_pruned, CheckConfig, Report};
use sweepclay_core::{gcode, Sliced};

/// The checker's configuration from the design's printer and parameters,
/// as `sweepclay slice` configures it.
pub fn config(s: &Sliced) -> CheckConfig {
    let p = &s.corrected.surface.params;
    let pr = &s.corrected.surface.printer;
    CheckConfig {
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
    }
}

/// The checker as `slice` runs it. Also holds the checker's fast support
/// path and its pruned full search to its plain full search: all three
/// must give the same report.
#[allow(dead_code)]
pub fn check_sliced(s: &Sliced) -> Report {
    let cfg = config(s);
    let text = gcode::to_string(s);
    let report = check(&text, &cfg);
    let plain = check_exhaustive(&text, &cfg);
    assert_eq!(
        report, plain,
        "the checker's fast support path and its full search disagree"
    );
    assert_eq!(
        check_pruned(&text, &cfg),
        plain,
        "the checker's pruned full search and its plain one disagree"
    );
    report
}

/// The checker alone, as `slice` runs it.
#[allow(dead_code)]
pub fn check_fast(s: &Sliced) -> Report {
    check(&gcode::to_string(s), &config(s))
}

/// The checker's plain full search, the reference its fast path must
/// agree with (for vessels it does not always: docs/CHECKER.md, "Known
/// gaps").
#[allow(dead_code)]
pub fn check_full(s: &Sliced) -> Report {
    check_exhaustive(&gcode::to_string(s), &config(s))
}
