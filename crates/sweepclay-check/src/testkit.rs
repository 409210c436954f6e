//! What the checker's tests share, its unit tests and its integration
//! tests alike (`tests/` includes this file): a G-code writer for
//! fixtures, and the verdict they assert. Each test crate uses a part.

#![allow(dead_code, unused_imports)]

pub(crate) use sweepclay_check::{check, CheckConfig, Finding, Report};

pub(crate) const E: f64 = 0.13; // E per mm³
pub(crate) const LAYER: f64 = 1.2;
pub(crate) const W: f64 = 3.2;

/// A G-code writer that keeps absolute E and the current position.
pub(crate) struct G {
    pub(crate) out: String,
    pub(crate) e: f64,
    pub(crate) at: [f64; 3],
}

impl G {
    pub(crate) fn new(start: [f64; 3]) -> G {
        let mut g = G {
            out: String::from("; fixture\nG21\nG90\nM82\nG28\nG92 E0\n"),
            e: 0.0,
            at: start,
        };
        g.out += &format!(
            "G0 F2400 X{:.3} Y{:.3} Z{:.3}\n",
            start[0], start[1], start[2]
        );
        g
    }
    /// The beads it wrote: everything after its header and its rapid
    /// move to the start.
    pub(crate) fn moves(&self) -> &str {
        let (_, rest) = self.out.split_once("G0 F2400").expect("a rapid move");
        rest.split_once('\n').map_or("", |(_, beads)| beads)
    }
    /// Extruding move with a bead `w` wide on a layer `h` high.
    pub(crate) fn bead(&mut self, to: [f64; 3], w: f64, h: f64) {
        let l = ((to[0] - self.at[0]).powi(2)
            + (to[1] - self.at[1]).powi(2)
            + (to[2] - self.at[2]).powi(2))
        .sqrt();
        self.e += l * w * h * E;
        self.out += &format!(
            "G1 F1800 X{:.3} Y{:.3} Z{:.3} E{:.5}\n",
            to[0], to[1], to[2], self.e
        );
        self.at = to;
    }
    pub(crate) fn line(&mut self, s: &str) {
        self.out += s;
        self.out += "\n";
    }
    /// A straight run from the current point to `to` in 1 mm beads.
    pub(crate) fn run(&mut self, to: [f64; 3], w: f64, h: f64) {
        let from = self.at;
        let l = (to[0] - from[0]).hypot(to[1] - from[1]);
        let n = (l.ceil() as usize).max(1);
        for k in 1..=n {
            let t = k as f64 / n as f64;
            self.bead(
                [
                    from[0] + t * (to[0] - from[0]),
                    from[1] + t * (to[1] - from[1]),
                    from[2] + t * (to[2] - from[2]),
                ],
                w,
                h,
            );
        }
    }
}

/// A zig-zag wall along y = 50 from x = 50 to 90, `layers` high.
pub(crate) fn wall(layers: usize) -> G {
    wall_from(50.0, 90.0, layers)
}

/// A zig-zag wall along y = 50 from x = `a` to `b`, `layers` high.
pub(crate) fn wall_from(a: f64, b: f64, layers: usize) -> G {
    let mut g = G::new([a, 50.0, LAYER]);
    for k in 1..=layers {
        let z = LAYER * k as f64;
        let (x0, x1) = if k % 2 == 1 { (a, b) } else { (b, a) };
        if k > 1 {
            g.bead([x0, 50.0, z], W, LAYER);
        }
        g.run([x1, 50.0, z], W, LAYER);
    }
    g
}

/// A vase spiral of radius `r` about `c`, `turns` turns of about 1 mm
/// beads rising `layer` a turn from one layer up.
pub(crate) fn spiral(g: &mut G, c: (f64, f64), r: f64, turns: usize, layer: f64) {
    let per = (std::f64::consts::TAU * r).round() as usize;
    for k in 1..=turns * per {
        let a = std::f64::consts::TAU * k as f64 / per as f64;
        let z = layer * (1.0 + k as f64 / per as f64);
        g.bead([c.0 + r * a.cos(), c.1 + r * a.sin(), z], W, layer);
    }
}

pub(crate) fn verdict(text: &str) -> Report {
    check(text, &CheckConfig::default())
}

pub(crate) fn only(r: &Report, what: &str) {
    fails_for(r, what, &[]);
}

/// The report fails for `what` and for nothing outside `allowed`.
pub(crate) fn fails_for(r: &Report, what: &str, allowed: &[&str]) {
    assert!(
        !r.printable,
        "expected a failure for {what}:\n{}",
        r.render()
    );
    assert!(
        r.failures.iter().any(|f| f.contains(what)),
        "expected `{what}`:\n{}",
        r.render()
    );
    for f in &r.failures {
        assert!(
            f.contains(what) || allowed.iter().any(|a| f.contains(a)),
            "unexpected failure `{f}` for a `{what}` fixture:\n{}",
            r.render()
        );
    }
}
