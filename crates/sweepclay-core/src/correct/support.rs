//! The support-free correction (paper §4, "Support-free correction";
//! docs/ALGORITHMS.md §4): each transition curve walked upward, a step
//! whose horizontal offset exceeds s_max(Δz) shortened to it, the points
//! above moving with it.

use super::report::{CurveId, SupportFix};
use crate::surface::Surface;

/// Walks every column upward and shortens steps that overhang too far
/// (s_max times the column's factor in `scale`, if it has one).
pub(super) fn support_free(s: &mut Surface, scale: &[f64]) -> Vec<SupportFix> {
    let n = s.columns.len();
    let mut fixes = Vec::new();
    for (c, col) in s.columns.iter().enumerate() {
        let range = col.samples();
        let mut carry = 0.0;
        let mut fix: Option<SupportFix> = None;
        let mut prev = s.samples[range.start];
        for i in range.start + 1..range.end {
            let design = s.samples[i];
            let mut xi = design.xi + carry;
            let (limit, by_angle) = s.params.offset_limit(design.z - prev.z);
            let limit = limit * scale.get(c).copied().unwrap_or(1.0);
            // The twist's turn overhangs too, where it crosses the wall.
            let tw = col.twist_step(prev.xi, prev.z, design.z);
            let step = xi - prev.xi + tw;
            if step.abs() > limit + 1e-12 {
                let clamped = prev.xi - tw + limit.copysign(step);
                carry += clamped - xi;
                xi = clamped;
                let f = fix.get_or_insert(SupportFix {
                    curve: if c == 0 {
                        CurveId::ProfileStart
                    } else if c == n - 1 {
                        CurveId::ProfileEnd
                    } else {
                        CurveId::Transition(c as u32)
                    },
                    u: col.u,
                    z_mm: design.z,
                    max_shift_mm: 0.0,
                    steps_shortened: 0,
                    by_overlap: 0,
                });
                f.steps_shortened += 1;
                f.by_overlap += u32::from(!by_angle);
            }
            if let Some(f) = fix.as_mut() {
                f.max_shift_mm = f.max_shift_mm.max(carry.abs());
            }
            s.samples[i].xi = xi;
            prev = s.samples[i];
        }
        fixes.extend(fix);
    }
    fixes
}
