//! The verdict: the failures a report holds, in words.

use crate::report::{Count, Report};
use crate::CheckConfig;

pub(crate) fn verdict(r: &mut Report, cfg: &CheckConfig) {
    let mut f = Vec::new();
    let line = |c: &Count| {
        c.first_line
            .map(|l| format!(" (first at line {l})"))
            .unwrap_or_default()
    };
    if r.extruding_moves == 0 {
        f.push("no extrusion at all".to_string());
    }
    if r.extrusion_runs > 1 {
        f.push(format!(
            "{} separate extrusion runs, must be 1 (the second starts at line {})",
            r.extrusion_runs, r.run_starts[1]
        ));
    }
    for (name, c) in [
        ("travel move(s) after the first bead", &r.travel_moves),
        ("retraction(s)", &r.retractions),
        ("pause(s)", &r.pauses),
        ("extrusion(s) without motion", &r.extrusion_without_motion),
        ("move(s) outside the build volume", &r.out_of_bounds),
        (
            "nozzle collision(s) with printed clay",
            &r.nozzle_collisions,
        ),
        (
            "carriage collision(s) with printed clay",
            &r.carriage_collisions,
        ),
        ("bead(s) with no clay below", &r.support.unsupported),
        (
            "bead(s) laid on clay at their own height",
            &r.support.double_deposition,
        ),
        (
            "bead(s) overlapping the bead below by less than half",
            &r.support.under_min,
        ),
        ("overhang(s) beyond the limit", &r.support.overhang),
    ] {
        if c.count > 0 {
            f.push(format!("{} {name}{}", c.count, line(c)));
        }
    }
    if let Some(z) = r.first_layer_z {
        if z > cfg.first_layer_max_mm {
            f.push(format!(
                "the first bead is {z:.2} mm above the bed (at most {} mm)",
                cfg.first_layer_max_mm
            ));
        }
    }
    r.printable = f.is_empty();
    r.failures = f;
}
