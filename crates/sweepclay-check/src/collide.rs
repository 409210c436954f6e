//! Collisions with the extruder (docs/CHECKER.md, "Checks"): along a move,
//! every r/2 mm of path, the carriage against the highest clay and the
//! nozzle cylinder (radius r, up to H above the tip) against the settled
//! clay near it. Clay laid in the last r + w_max of path is the bead just
//! laid, not an obstacle.

use crate::bead::Beads;
use crate::grid::BeadGrid;
use crate::replay::Move;
use crate::report::Finding;
use crate::CheckConfig;

/// Probes move `m` (`len` long, from path distance `s_start` to `s_end`)
/// at points every r/2 mm of path (at most 200 a move), settling the
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
    let recent_nozzle = cfg.nozzle_radius + cfg.width_max;
    let reach = cfg.nozzle_radius + cfg.width_max / 2.0;
    let every = (cfg.nozzle_radius / 2.0).max(0.5);
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
            if z > zlo && d < cfg.nozzle_radius + b.width() / 2.0 {
                worst = worst.max(z - p[2]);
            }
        });
        if worst > 0.0 {
            hit(Finding::NozzleCollision, worst);
        }
    }
}
