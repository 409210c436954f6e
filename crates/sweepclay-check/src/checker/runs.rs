//! Runs and start and end code: which run of extruding moves is the
//! print, and the findings held back until that is known (a purge line,
//! a skirt, a prime are start code, not the print; docs/CHECKER.md,
//! "Start and end code").

use super::*;

/// Runs before the print kept, at most.
pub(super) const MAX_LEAD_RUNS: usize = 64;

/// Findings held back while it is not yet known whether they are in the
/// print, at most.
pub(super) const MAX_HELD: usize = 100_000;

/// A finding held back while the checker does not yet know whether it is
/// in the print or in the start code: `run` is the run it belongs to, or,
/// with `gap`, the run it comes before.
pub(super) struct Held {
    pub(super) run: usize,
    pub(super) gap: bool,
    pub(super) kind: Finding,
    pub(super) line: usize,
    pub(super) v: f64,
}

/// An extrusion run before the print is known to have begun.
pub(super) struct LeadRun {
    pub(super) first_bead: u32,
    pub(super) line: usize,
    pub(super) last_line: usize,
    /// Moves replayed before it.
    pub(super) moves_before: usize,
    /// Height of its first bead.
    pub(super) z: f64,
    pub(super) clay_mm3: f64,
    pub(super) beads: usize,
    /// Beads with nothing under them and far from the bed: a purge in the
    /// air.
    pub(super) air: usize,
    /// Beads resting on the bed.
    pub(super) on_bed: usize,
    /// The box of its beads' centrelines (low and high corners).
    pub(super) bounds: Bounds,
}

/// A box of centrelines, low and high corners; empty as `EMPTY`.
pub(super) type Bounds = ([f64; 3], [f64; 3]);

/// The box of no bead.
pub(super) const EMPTY: Bounds = ([f64::MAX; 3], [f64::MIN; 3]);

/// Where the print begins (docs/CHECKER.md, "Start and end code"): the
/// first run that clay is laid on. Runs before it that nothing rests on
/// (a skirt or purge line on the bed, a purge in the air, a stationary
/// prime) are start code. Until a bead rests on an earlier run, what the
/// runs so far did is held here.
#[derive(Default)]
pub(super) struct Lead {
    /// The print's first run, once known.
    pub(super) print_run: Option<usize>,
    pub(super) runs: Vec<LeadRun>,
    pub(super) held: Vec<Held>,
    /// Beads of the air purges (their clay falls off; it is no obstacle).
    pub(super) air: Vec<u32>,
    /// What the start code holds, once decided.
    pub(super) start: Segment,
    /// The box of the beads laid once the print's first run is known
    /// (`EMPTY` at the start: `Checker::new` sets it).
    pub(super) after: Bounds,
}

/// What a bead was found to rest on.
#[derive(Clone, Copy, PartialEq)]
pub(super) enum Rest {
    /// An earlier bead (its index).
    Bead(u32),
    /// Clay at its own height (it is pressed onto it).
    Clay,
    /// The bed.
    Bed,
    /// Nothing, far from the bed: a purge in the air, or a fault.
    Air,
}

impl Checker<'_> {
    pub(super) fn defer_or_add(&mut self, extruding: bool, kind: Finding, line: usize, v: f64) {
        if extruding {
            self.record(kind, line, v, false);
        } else {
            self.pending.push((kind, line, v));
        }
    }

    /// The print begins at run `k`: what was held for runs before it (and
    /// in the gap before it) is start code, the rest counts.
    pub(super) fn decide(&mut self, k: usize) {
        let lead = &mut self.lead;
        if lead.print_run.is_some() {
            return;
        }
        lead.print_run = Some(k);
        let cfg = self.cfg;
        let first = lead.runs.get(k);
        let first_z = first.map(|r| r.z);
        let high = first_z.filter(|&z| z > cfg.first_layer_max_mm);
        let start = &mut lead.start;
        for h in std::mem::take(&mut lead.held) {
            if h.run > k || (h.run == k && !h.gap) {
                // A first layer too high is one finding, not a bead with no
                // clay below for every bead of it.
                if h.kind == Finding::Unsupported
                    && high.is_some_and(|z| h.v <= z + cfg.min_layer_mm)
                {
                    continue;
                }
                self.r.findings[h.kind].add(h.line, h.v);
            } else {
                start.cover(h.line);
                if h.kind == Finding::ExtrusionWithoutMotion {
                    start.clay_ml += h.v / cfg.e_per_mm3 / 1000.0;
                }
                start.note(match h.kind {
                    Finding::ExtrusionWithoutMotion => {
                        format!("prime without motion (line {})", h.line)
                    }
                    Finding::Retraction => format!("retraction (line {})", h.line),
                    Finding::TravelMove => "travel moves".to_string(),
                    Finding::Pause => format!("pause (line {})", h.line),
                    Finding::Unsupported => "purge in the air (its clay is no obstacle)".into(),
                    other => format!("{} (line {})", other.label(), h.line),
                });
            }
        }
        for run in &lead.runs[..k.min(lead.runs.len())] {
            start.cover(run.line);
            start.cover(run.last_line);
            start.clay_ml += run.clay_mm3 / 1000.0;
            let what = if run.air * 2 > run.beads {
                "purge in the air"
            } else if run.on_bed * 2 > run.beads {
                "clay on the bed beside the part (skirt or purge line)"
            } else {
                "clay that nothing rests on"
            };
            start.note(format!(
                "{what}: {} bead(s), lines {}-{}",
                run.beads, run.line, run.last_line
            ));
        }
        // The start code runs from its first item to the print's first
        // bead (the report leaves it out if it holds nothing).
        if let Some(run) = first {
            start.moves = run.moves_before;
            if run.moves_before > 0 {
                start.note("homing and moves to the start".into());
            }
            start.lines = [start.lines[0].max(1), run.line.saturating_sub(1)];
        }
        // Clay purged into the air falls off: it is no obstacle to the
        // print (a height no question reaches).
        let first_bead = first.map_or(u32::MAX, |r| r.first_bead);
        for &id in &lead.air {
            if id < first_bead {
                if let Some(b) = self.beads.get_mut(id as usize) {
                    b.from32[2] = f32::NEG_INFINITY;
                    b.to32[2] = f32::NEG_INFINITY;
                }
            }
        }
        lead.air = Vec::new();
        if let Some(z) = first_z {
            self.r.first_layer_z = Some(z);
        }
        if let (Some(z), Some(run)) = (high, first) {
            self.r.findings[Finding::FirstLayerHigh].add(run.line, z);
        }
        self.r.run_starts = lead.runs[k.min(lead.runs.len())..]
            .iter()
            .map(|r| r.line)
            .take(20)
            .collect();
    }

    /// A bead begins a new extrusion run.
    pub(super) fn new_run(&mut self, m: &Move) {
        self.runs += 1;
        if self.lead.runs.len() >= MAX_LEAD_RUNS {
            // Run after run and nothing laid on any: all of it counts.
            self.decide(0);
        }
        if self.lead.print_run.is_some() {
            if self.r.run_starts.len() < 20 {
                self.r.run_starts.push(m.line);
            }
            return;
        }
        self.lead.runs.push(LeadRun {
            first_bead: self.beads.len() as u32,
            line: m.line,
            last_line: m.line,
            moves_before: self.r.moves - 1,
            z: m.from[2].max(m.to[2]),
            clay_mm3: 0.0,
            beads: 0,
            air: 0,
            on_bed: 0,
            bounds: EMPTY,
        });
    }
}

#[cfg(test)]
mod tests {
    use crate::testkit::*;

    #[test]
    fn retraction_fails() {
        let mut g = wall(4);
        g.e -= 2.0;
        g.line(&format!("G1 E{:.5}", g.e));
        g.e += 2.0;
        g.line(&format!("G1 E{:.5}", g.e));
        g.run([50.0, 50.0, 4.8], W, 0.0001);
        let mut g2 = wall(8);
        // Retract and un-retract in place, then go on with the wall.
        let e = g2.e;
        g2.line(&format!("G1 E{:.5}", e - 1.0));
        g2.line(&format!("G1 E{:.5}", e));
        let z = LAYER * 9.0;
        g2.bead([50.0, 50.0, z], W, LAYER);
        g2.run([90.0, 50.0, z], W, LAYER);
        let r = verdict(&g2.out);
        assert!(
            r.failures.iter().any(|f| f.contains("retraction")),
            "{}",
            r.render()
        );
        assert_eq!(r.findings[Finding::Retraction].count, 1);
        assert_eq!(
            r.findings[Finding::Retraction].first_line,
            Some(g2.out.lines().position(|l| l.starts_with("G1 E")).unwrap() + 1)
        );
    }

    #[test]
    fn pause_fails() {
        let mut g = wall(4);
        g.line("M0 ; wait for the user");
        let z = LAYER * 5.0;
        g.bead([50.0, 50.0, z], W, LAYER);
        g.run([90.0, 50.0, z], W, LAYER);
        fails_for(&verdict(&g.out), "pause", &["extrusion runs"]);
    }

    #[test]
    fn first_layer_in_the_air_fails() {
        let mut g = G::new([50.0, 50.0, 8.0]);
        g.run([90.0, 50.0, 8.0], W, LAYER);
        g.bead([90.0, 50.0, 8.0 + LAYER], W, LAYER);
        g.run([50.0, 50.0, 8.0 + LAYER], W, LAYER);
        let r = verdict(&g.out);
        // One finding, not a bead with no clay below for every bead of it.
        only(&r, "first layer is at 8.00 mm");
        assert_eq!(r.failures.len(), 1, "{}", r.render());
    }
}
