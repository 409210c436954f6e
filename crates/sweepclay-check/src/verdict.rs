//! The verdict: the failures and warnings a report holds, in words, from
//! the one list of [`Finding`]s.

use crate::report::{Count, Finding, Report};
use crate::CheckConfig;

/// How far outside `[width_min, width_max]` an inferred bead width may be
/// before it is a warning (a fraction of the limit): widths are read from
/// the volume, the length and the local layer height, all rounded.
pub const WIDTH_TOLERANCE: f64 = 0.25;

/// Fills `printable`, `failures` and `warnings` from the counts.
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
            r.extrusion_runs,
            r.run_starts.get(1).copied().unwrap_or(0)
        ));
    }
    for (kind, c) in r.findings.occurred() {
        f.push(match kind {
            Finding::FirstLayerHigh => format!(
                "the first layer is at {:.2} mm, too far above the bed (at most {} mm)",
                c.worst.map_or(0.0, |w| w.0),
                cfg.first_layer_max_mm
            ),
            _ => format!("{} {}{}", c.count, kind.failure(), line(c)),
        });
    }
    let mut w = Vec::new();
    let sp = &r.support;
    if let Some((v, l)) = sp.wide.worst {
        w.push(format!(
            "{} over-squished bead(s) wider than {:.1} mm (widest {v:.1} mm at line {l}): they print, pressed flat",
            sp.wide.count,
            cfg.width_max * (1.0 + WIDTH_TOLERANCE)
        ));
    }
    if let Some(first) = sp.thin.first_line {
        w.push(format!(
            "{} bead(s) narrower than {:.1} mm (first at line {first}): too little clay for the layer",
            sp.thin.count,
            cfg.width_min * (1.0 - WIDTH_TOLERANCE)
        ));
    }
    if let Some(d) = &r.cannot_judge {
        f.insert(0, format!("cannot judge: line {}: {}", d.line, d.message));
    }
    r.printable = f.is_empty();
    r.failures = f;
    r.warnings = w;
}
