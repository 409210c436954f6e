//! The printing time as a firmware's planner spends it (not in the paper,
//! which reports measured times; docs/ALGORITHMS.md §9): each move is a
//! trapezoid of speed, accelerating at most at the printer's acceleration
//! (and each axis's own), cruising at the feedrate or the slowest limit of
//! its axes and its extruder, and slowing for the corner into the next
//! move by junction deviation, as Marlin and Klipper plan it.
//!
//! Linear in the moves: one pass forward for the limits, one backward and
//! one forward for the speeds at the corners.

use crate::printer::Printer;

/// Motion limits of a printer (mm, s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    /// Acceleration of printing moves (mm/s²).
    pub acceleration: f64,
    /// Fastest speed of each axis x, y, z (mm/s).
    pub max_speed: [f64; 3],
    /// Fastest acceleration of each axis (mm/s²).
    pub max_acceleration: [f64; 3],
    /// Junction deviation (mm): how far the path may stray from a corner,
    /// which sets the speed the corner is taken at.
    pub junction_deviation: f64,
    /// Most clay the extruder pushes a second (mm³/s); a clay screw or
    /// piston is often the slowest axis. `None`: not limited.
    pub max_flow: Option<f64>,
}

impl Limits {
    /// The printer profile's limits.
    pub fn of(p: &Printer) -> Limits {
        Limits {
            acceleration: p.acceleration_mm_s2,
            max_speed: p.max_speed_mm_s,
            max_acceleration: p.max_acceleration_mm_s2,
            junction_deviation: p.junction_deviation_mm,
            max_flow: p.max_flow_mm3_s,
        }
    }
}

/// One move of a print: where it ends, its feedrate and its clay.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Move {
    /// End point (mm); the move starts where the one before ended.
    pub to: [f64; 3],
    /// Feedrate asked for (mm/s).
    pub feed: f64,
    /// Clay it lays (mm³).
    pub volume: f64,
}

/// Seconds to print `moves` from rest at `start` to rest at the end.
pub fn print_time(start: [f64; 3], moves: impl IntoIterator<Item = Move>, lim: &Limits) -> f64 {
    // Per move: length, cruise speed, acceleration, and the fastest the
    // corner into it may be taken (from the move before).
    let moves = moves.into_iter();
    let cap = moves.size_hint().0;
    let [mut len, mut cruise, mut acc] = [(); 3].map(|_| Vec::with_capacity(cap));
    let mut entry = Vec::with_capacity(cap + 1);
    let mut from = start;
    let mut prev: Option<([f64; 3], f64, f64)> = None; // direction, cruise, acceleration
    for m in moves {
        let d = [m.to[0] - from[0], m.to[1] - from[1], m.to[2] - from[2]];
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let mut v = m.feed.max(1e-9);
        let mut a = lim.acceleration.max(1e-9);
        let u = if l > 0.0 { d.map(|c| c / l) } else { [0.0; 3] };
        if l > 0.0 {
            for ((c, vmax), amax) in u.iter().zip(lim.max_speed).zip(lim.max_acceleration) {
                let share = c.abs();
                if share > 0.0 {
                    v = v.min(vmax / share);
                    a = a.min(amax / share);
                }
            }
            if let Some(f) = lim.max_flow.filter(|_| m.volume > 0.0) {
                v = v.min(f * l / m.volume);
            }
        }
        let corner = match prev {
            None => 0.0,
            Some((w, pv, pa)) => {
                let cos = -(u[0] * w[0] + u[1] * w[1] + u[2] * w[2]);
                let c = if l == 0.0 || w == [0.0; 3] || cos > 0.999_999 {
                    // A reversal (or a move of no length): through rest.
                    0.0
                } else if cos < -0.999_999 {
                    f64::INFINITY
                } else {
                    let sin_half = (0.5 * (1.0 - cos)).sqrt();
                    (a.min(pa) * lim.junction_deviation * sin_half / (1.0 - sin_half)).sqrt()
                };
                c.min(v).min(pv)
            }
        };
        len.push(l);
        cruise.push(v);
        acc.push(a);
        entry.push(corner);
        prev = Some((u, v, a));
        from = m.to;
    }
    let n = len.len();
    entry.push(0.0);
    // Reachable speeds: no move may need to brake or speed up faster than
    // its acceleration allows over its length (in squares of speed, so
    // without roots until the end).
    for e in &mut entry {
        *e = if e.is_finite() {
            *e * *e
        } else {
            f64::INFINITY
        };
    }
    for i in (0..n).rev() {
        entry[i] = entry[i].min(entry[i + 1] + 2.0 * acc[i] * len[i]);
    }
    for i in 0..n {
        entry[i + 1] = entry[i + 1].min(entry[i] + 2.0 * acc[i] * len[i]);
    }
    let speed: Vec<f64> = entry.iter().map(|e| e.sqrt()).collect();
    (0..n)
        .map(|i| trapezoid(len[i], speed[i], speed[i + 1], cruise[i], acc[i]))
        .sum()
}

/// Seconds to cover `l` mm starting at speed `v0`, ending at `v1`, at most
/// `vc`, accelerating and braking at `a`.
pub fn trapezoid(l: f64, v0: f64, v1: f64, vc: f64, a: f64) -> f64 {
    if l <= 0.0 {
        return 0.0;
    }
    let up = (vc * vc - v0 * v0) / (2.0 * a);
    let down = (vc * vc - v1 * v1) / (2.0 * a);
    if up + down <= l {
        (vc - v0) / a + (vc - v1) / a + (l - up - down) / vc
    } else {
        // No room to cruise: the peak where the two ramps meet.
        let peak = ((2.0 * a * l + v0 * v0 + v1 * v1) / 2.0).sqrt();
        (peak - v0) / a + (peak - v1) / a
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lim() -> Limits {
        Limits {
            acceleration: 100.0,
            max_speed: [300.0, 300.0, 5.0],
            max_acceleration: [3000.0, 3000.0, 100.0],
            junction_deviation: 0.013,
            max_flow: None,
        }
    }

    fn mv(x: f64, y: f64, feed: f64) -> Move {
        Move {
            to: [x, y, 0.0],
            feed,
            volume: 0.0,
        }
    }

    #[test]
    fn each_preset_family_plans_with_its_own_limits() {
        use crate::printer::Printer;
        // 100 mm at 40 mm/s along x. Marlin's defaults (generic, CERAMBOT,
        // WASP: none published): a = 3000, 0.27 mm each way, 2.5133 s.
        // Eazao (Cura's definitions): a = 300, 2.67 mm each way, 2.6333 s.
        let line = [Move {
            to: [100.0, 0.0, 0.0],
            feed: 40.0,
            volume: 0.0,
        }];
        // Every preset is of a family with a known acceleration, so a new
        // one cannot slip in with limits nobody chose.
        for &name in crate::printer::PRESETS {
            let a = if name.starts_with("eazao-") {
                300.0
            } else {
                3000.0
            };
            let lim = Limits::of(&Printer::preset(name).unwrap());
            assert_eq!(lim.acceleration, a, "{name}");
            let t = print_time([0.0; 3], line, &lim);
            let want = trapezoid(100.0, 0.0, 0.0, 40.0, a);
            assert!((t - want).abs() < 1e-12, "{name}: {t} against {want}");
            let closed = 2.0 * 40.0 / a + (100.0 - 40.0 * 40.0 / a) / 40.0;
            assert!((t - closed).abs() < 1e-9, "{name}: {t} against {closed}");
        }
        // Eazao's z axis: 5 mm/s at most, 50 mm/s².
        let lim = Limits::of(&Printer::preset("eazao-zero").unwrap());
        assert_eq!(lim.max_speed, [100.0, 100.0, 5.0]);
        assert_eq!(lim.max_acceleration, [500.0, 500.0, 50.0]);
        assert!((lim.junction_deviation - 0.4 * 100.0 / 300.0).abs() < 1e-12);
    }

    #[test]
    fn a_straight_line_is_one_trapezoid() {
        // 100 mm at 20 mm/s, a = 100: 0.2 s up and 0.2 s down over 2 mm
        // each, 96 mm cruising at 20 mm/s (4.8 s): 5.2 s.
        let t = print_time([0.0; 3], [mv(100.0, 0.0, 20.0)], &lim());
        assert!((t - 5.2).abs() < 1e-12, "{t}");
        // Too short to cruise: 1 mm peaks at √(a · l) = 10 mm/s, 0.2 s.
        let t = print_time([0.0; 3], [mv(1.0, 0.0, 20.0)], &lim());
        assert!((t - 0.2).abs() < 1e-12, "{t}");
        // Split in two collinear halves, the same.
        let t = print_time(
            [0.0; 3],
            [mv(50.0, 0.0, 20.0), mv(100.0, 0.0, 20.0)],
            &lim(),
        );
        assert!((t - 5.2).abs() < 1e-9, "{t}");
    }

    #[test]
    fn a_square_slows_at_each_corner_by_junction_deviation() {
        // 40 mm sides at 20 mm/s: each 90° corner is taken at
        // v = √(a · δ · s / (1 − s)), s = sin 45°.
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let vj = (100.0 * 0.013 * s / (1.0 - s)).sqrt();
        let side = |v0: f64, v1: f64| trapezoid(40.0, v0, v1, 20.0, 100.0);
        let want = side(0.0, vj) + 2.0 * side(vj, vj) + side(vj, 0.0);
        let moves = [
            mv(40.0, 0.0, 20.0),
            mv(40.0, 40.0, 20.0),
            mv(0.0, 40.0, 20.0),
            mv(0.0, 0.0, 20.0),
        ];
        let t = print_time([0.0; 3], moves, &lim());
        assert!((t - want).abs() < 1e-12, "{t} {want}");
        // By hand: vj = 2.104 mm/s; a side from rest to vj: 0.2 s up,
        // (20 − 2.104)/100 = 0.179 s down, the ramps 2 + 1.978 mm, cruise
        // 36.022 mm in 1.801 s.
        assert!(
            (side(0.0, vj)
                - (0.2 + (20.0 - vj) / 100.0 + (40.0 - 2.0 - (400.0 - vj * vj) / 200.0) / 20.0))
                .abs()
                < 1e-12
        );
    }

    #[test]
    fn a_zig_zag_stops_at_each_reversal() {
        // Four 30 mm passes back and forth: each reversal is through rest,
        // so each pass is a full trapezoid from rest to rest.
        let moves = [
            mv(30.0, 0.0, 20.0),
            mv(0.0, 0.0, 20.0),
            mv(30.0, 0.0, 20.0),
            mv(0.0, 0.0, 20.0),
        ];
        let t = print_time([0.0; 3], moves, &lim());
        let pass = trapezoid(30.0, 0.0, 0.0, 20.0, 100.0);
        assert!((pass - (0.4 + 26.0 / 20.0)).abs() < 1e-12);
        assert!((t - 4.0 * pass).abs() < 1e-12, "{t}");
    }

    #[test]
    fn axes_and_the_extruder_cap_the_speed() {
        // Straight up 10 mm: z's 5 mm/s and 100 mm/s² rule.
        let up = Move {
            to: [0.0, 0.0, 10.0],
            feed: 20.0,
            volume: 0.0,
        };
        let t = print_time([0.0; 3], [up], &lim());
        assert!((t - trapezoid(10.0, 0.0, 0.0, 5.0, 100.0)).abs() < 1e-12);
        // 100 mm laying 3.75 mm³ a mm with the extruder at 37.5 mm³/s:
        // at most 10 mm/s.
        let bead = Move {
            to: [100.0, 0.0, 0.0],
            feed: 20.0,
            volume: 375.0,
        };
        let slow = Limits {
            max_flow: Some(37.5),
            ..lim()
        };
        let t = print_time([0.0; 3], [bead], &slow);
        assert!((t - trapezoid(100.0, 0.0, 0.0, 10.0, 100.0)).abs() < 1e-12);
    }
}
