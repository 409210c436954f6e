//! Collisions with the extruder (docs/CHECKER.md, "Collisions"): along a
//! move, every `w_min`/2 mm of path, the carriage against the highest clay and
//! the nozzle against the settled clay near it. The nozzle is a cone from
//! the tip (`w_min`/2 round) widening at 45° up to the body's radius r,
//! to H above the tip. Only the clay the tip is laying (the last `w_max`
//! of path) is exempt, whatever r.

use crate::bead::Beads;
use crate::grid::BeadGrid;
use crate::replay::Move;
use crate::report::Finding;
use crate::CheckConfig;

/// Probes move `m` (`len` long, from path distance `s_start` to `s_end`)
/// at points every `w_min`/2 mm of path (at most 200 a move), settling the
/// beads the nozzle has left behind as it goes; `hit` gets each
/// collision ([`Finding::CarriageCollision`] or
/// [`Finding::NozzleCollision`]) with how high the clay reaches above
/// the carriage or the tip (mm). `top_z` is the highest clay so far.
#[inline]
pub(crate) fn probe(
    grid: &mut BeadGrid,
    beads: &Beads,
    top_z: f64,
    cfg: &CheckConfig,
    (m, len, s_start, s_end): (&Move, f64, f64, f64),
    mut hit: impl FnMut(Finding, f64),
) {
    let recent_nozzle = cfg.width_max;
    // The nozzle's widest, at H above the tip.
    let widest = nozzle_radius_at(cfg, cfg.nozzle_height);
    let reach = widest + cfg.width_max / 2.0;
    // Probes as close as the tip is wide, whatever the body: the same
    // places are asked of every body, so a bigger one finds no less.
    let every = (0.5 * cfg.width_min).max(0.5);
    // Path distances are ≥ 0, where truncation is the floor (and no
    // library call).
    let floor = |v: f64| (v as i64) as f64;
    let (first, last) = (floor(s_start / every) + 1.0, floor(s_end / every));
    let probes = (last - first + 1.0).clamp(0.0, 200.0) as usize;
    for k in 0..probes {
        let t = if probes < 200 {
            ((first + k as f64) * every - s_start) / len
        } else {
            (k + 1) as f64 / probes as f64
        };
        let p = [
            m.from[0] + t * (m.to[0] - m.from[0]),
            m.from[1] + t * (m.to[1] - m.from[1]),
            m.from[2] + t * (m.to[2] - m.from[2]),
        ];
        let sp = s_start + t * len;
        // Beads the nozzle has left behind count for collisions.
        grid.settle(beads, |b| b.s_end <= sp - recent_nozzle);
        if top_z > p[2] + cfg.nozzle_height + cfg.collision_tolerance_mm {
            hit(Finding::CarriageCollision, top_z - p[2] - cfg.nozzle_height);
        }
        let mut worst: f64 = 0.0;
        let zlo = p[2] + cfg.collision_tolerance_mm;
        grid.settled_near(beads, p, reach, zlo, p[2] + cfg.nozzle_height, |id| {
            let b = &beads[id as usize];
            if b.s_end > sp - recent_nozzle {
                return;
            }
            let (d, z, _) = b.closest(p);
            if z > zlo && d < nozzle_radius_at(cfg, z - p[2]) + b.width() / 2.0 {
                worst = worst.max(z - p[2]);
            }
        });
        if worst > 0.0 {
            hit(Finding::NozzleCollision, worst);
        }
    }
}

/// The nozzle's radius `h` mm above its tip: `w_min`/2 at the tip (the
/// bore's rim), widening by a millimetre a millimetre (45°, wider than
/// any clay nozzle's taper: Luer and WASP tips widen 0.2–0.4 mm a
/// millimetre), at most the body's radius.
#[inline]
pub(crate) fn nozzle_radius_at(cfg: &CheckConfig, h: f64) -> f64 {
    (0.5 * cfg.width_min + h.max(0.0)).min(cfg.nozzle_radius)
}
