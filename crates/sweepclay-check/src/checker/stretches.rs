//! Stretches and turns: beads judged by the stretch they belong to, not
//! one by one. Too little overlap, a layer gap and an overhang fail only
//! over a length of path; clay laid on clay at its own height fails when
//! most of a stretch's clay has no room, a ramp excepted; the steps of a
//! turnaround carry the clay the end of the next bead needs
//! (docs/CHECKER.md, "Overhangs", "Overlap", "Layer gaps", "Clay on clay",
//! "Turns").

use super::*;

/// The findings judged by stretches of [`Weak`] beads.
pub(super) const WEAK_KINDS: [Finding; 3] = [
    Finding::UnderMinOverlap,
    Finding::LayerGap,
    Finding::Overhang,
];

/// How much a ramp's gap or height may dip from one bead to the next
/// (rounding in the file) and still rise (mm).
pub(super) const RAMP_SLACK_MM: f64 = 0.02;

/// Consecutive beads overlapping the bead below by less than the least
/// overlap, resting over a layer gap, or leaning past the overhang limit
/// ([`WEAK_KINDS`]). Shorter in all than [`Checker::weak_length`], they
/// are held up by the clay on either side (a slicer's seam bead a
/// millimetre long, the end of a pass over the slope the pass below
/// climbed); longer, each is a failure (docs/CHECKER.md, "Overlap",
/// "Layer gaps", "Overhangs").
#[derive(Default)]
pub(super) struct Weak {
    /// Their length in plan (mm).
    pub(super) length: f64,
    /// The beads not yet recorded: line and value.
    pub(super) pending: Vec<(usize, f64)>,
}

/// A stretch of consecutive beads laid on clay at their own height: their
/// clay and the part of it that has no room (docs/CHECKER.md, "Clay on
/// clay").
#[derive(Default)]
pub(super) struct Stretch {
    pub(super) first_line: usize,
    pub(super) length: f64,
    pub(super) volume: f64,
    pub(super) excess: f64,
    /// The gap at the start of its first bead and the end of its last
    /// (mm).
    pub(super) first_gap: f64,
    pub(super) last_gap: f64,
    /// Whether some bead of it lies lower than the one before, or on a
    /// thinner gap: then it is no ramp.
    pub(super) falls: bool,
    /// Height of its last bead's end (mm).
    pub(super) last_z: f64,
}

/// Turnaround steps since the last bead: the first one's line, their
/// clay (mm³) and rise (mm), and the width of the bead before them (mm).
pub(super) struct Turn {
    pub(super) line: usize,
    pub(super) clay: f64,
    pub(super) rise: f64,
    /// Path length of the steps (mm).
    pub(super) length: f64,
    pub(super) before: f64,
}

impl Checker<'_> {
    /// Records the beads of a stretch of [`Weak`] beads of kind `k`, if it
    /// is long enough to fail: half the narrowest bead.
    /// How long a stretch of weak beads of kind `k` must be to fail: half
    /// the narrowest bead for too little overlap and a layer gap (a bead
    /// shorter than that is a blob on its neighbours); the narrowest
    /// bead's width for an overhang, the shortest length of bead that can
    /// sag on its own: a shorter one leans no farther than the supported
    /// clay it joins at both ends holds it (docs/CHECKER.md, "Overhangs").
    pub(super) fn weak_length(&self, k: usize) -> f64 {
        match WEAK_KINDS[k] {
            Finding::Overhang => self.cfg.width_min,
            _ => 0.5 * self.cfg.width_min,
        }
    }

    pub(super) fn flush_weak(&mut self, k: usize) {
        if self.weak[k].length < self.weak_length(k) {
            return;
        }
        let mut pending = std::mem::take(&mut self.weak[k].pending);
        for &(line, v) in &pending {
            self.record(WEAK_KINDS[k], line, v, false);
        }
        pending.clear();
        self.weak[k].pending = pending;
    }

    /// The share of a stretch's clay on clay at its own height that may have
    /// no room before it fails: half. A bead under the nozzle a gap g above
    /// clay is at most 1.25 w_max wide (the widths' tolerance), so it holds
    /// 1.25 w_max g a millimetre; past twice that, more clay is pushed out
    /// than the bead keeps (docs/CHECKER.md, "Clay on clay").
    pub(super) const SQUISH_EXCESS: f64 = 0.5;

    /// Ends a stretch of beads on clay at their own height: a failure if
    /// most of its clay had no room, it is at least 3/4 `w_min` long (more
    /// than a seam's last bead) and its excess is a bead's clay (more
    /// than a `w_min`-wide bead of `min_layer_mm` a millimetre, over at
    /// least `w_min`): a pass laid again, or the step from one ring of a
    /// floor to the next laid as a full bead over both (docs/CHECKER.md,
    /// "Clay on clay"). A move carrying next to no clay across them fails
    /// as under-extruded instead (docs/CHECKER.md, "Under-extruded moves").
    ///
    /// A *ramp* is neither: a stretch whose gap only grows, by at least
    /// half the thinnest layer, and that the path leaves by a bead resting
    /// on the clay below at least a thinnest layer up, a vase's first turn
    /// rising from its flat loop, at any slope, width or lean (`climbs_out`:
    /// the gap under the bead that ended the stretch, if it rests on clay).
    pub(super) fn close_stretch(&mut self, climbs_out: Option<f64>) {
        if self.stretch.length == 0.0 {
            return;
        }
        let st = std::mem::take(&mut self.stretch);
        let cfg = self.cfg;
        let ramp = !st.falls
            && st.last_gap - st.first_gap >= 0.5 * cfg.min_layer_mm
            && climbs_out
                .is_some_and(|g| g >= cfg.min_layer_mm && g <= st.last_gap + cfg.min_layer_mm);
        if ramp {
            return;
        }
        // Either way its excess must be a bead's clay: a move with next
        // to no clay is judged as under-extruded, not here.
        let bead = cfg.width_min * cfg.min_layer_mm * st.length.max(cfg.width_min);
        if st.excess > Self::SQUISH_EXCESS * st.volume
            && st.excess > bead
            && st.length >= 0.75 * cfg.width_min
        {
            self.record(Finding::DoubleDeposition, st.first_line, st.excess, false);
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::testkit::*;

    #[test]
    fn an_overhang_fails_over_a_beads_width_and_too_little_overlap_over_half() {
        let cfg = CheckConfig {
            width_min: 3.0,
            ..CheckConfig::default()
        };
        let c = super::Checker::new(&cfg);
        let length =
            |f: Finding| c.weak_length(super::WEAK_KINDS.iter().position(|&k| k == f).unwrap());
        assert_eq!(length(Finding::Overhang), 3.0);
        assert_eq!(length(Finding::UnderMinOverlap), 1.5);
        assert_eq!(length(Finding::LayerGap), 1.5);
    }

    /// A floor of concentric rings 0.85 w apart round (100, 100), two layers
    /// (inward, then outward), each ring closed on its entry at angle 0 and the
    /// step to the next ring laid with `step_w`-wide clay.
    fn ring_floor(step_w: f64) -> G {
        let pitch = 0.85 * W;
        let radii: Vec<f64> = (0..8).map(|k| 30.0 - pitch * k as f64).collect();
        let at = |r: f64, a: f64, z: f64| [100.0 + r * a.cos(), 100.0 + r * a.sin(), z];
        let mut g = G::new(at(radii[0], 0.0, LAYER));
        for layer in 1..=2 {
            let z = LAYER * layer as f64;
            let order: Vec<f64> = if layer == 1 {
                radii.clone()
            } else {
                radii.iter().rev().copied().collect()
            };
            for (k, &r) in order.iter().enumerate() {
                if k > 0 {
                    g.bead(at(r, 0.0, z), step_w, LAYER);
                } else if layer == 2 {
                    g.bead(at(r, 0.0, z), W, LAYER);
                }
                let seg = (std::f64::consts::TAU * r / 1.1).ceil() as usize;
                for i in 1..=seg {
                    let a = std::f64::consts::TAU * i as f64 / seg as f64;
                    g.bead(at(r, a, z), W, LAYER);
                }
            }
        }
        g
    }

    /// A zig-zag wall of 12 layers of `w` wide beads, `h` high, whose passes
    /// climb to the next layer back along the new pass at 1:2 (2 h along for
    /// h up), each climb laid as a bead `climb_w` wide.
    fn climbing_wall(w: f64, h: f64, climb_w: f64) -> G {
        let mut g = G::new([50.0, 50.0, h]);
        for k in 1..=12 {
            let z = h * k as f64;
            let (x0, x1, dir) = if k % 2 == 1 {
                (50.0, 90.0, 1.0)
            } else {
                (90.0, 50.0, -1.0)
            };
            if k > 1 {
                g.bead([x0 + dir * 2.0 * h, 50.0, z], climb_w, h);
            }
            g.run([x1, 50.0, z], w, h);
        }
        g
    }

    #[test]
    fn a_floor_whose_ring_steps_lay_beads_or_joins_across_its_rings_fails() {
        // The junction fault: each step from one ring to the next runs across
        // clay both rings cover; laid as a full bead, it is clay on clay.
        let r = verdict(&ring_floor(W).out);
        only(&r, "laid on clay at their own height");
        // The same steps as joins at 5 % of a bead are no smear a clay
        // extruder can lay: under-extruded (docs/CHECKER.md, "Under-extruded
        // moves").
        let r = verdict(&ring_floor(0.05 * W).out);
        only(&r, "under-extruded");
    }

    #[test]
    fn a_steep_bead_with_a_beads_clay_is_no_pile() {
        // A wall of 4.5 mm beads on 1.8 mm layers whose passes climb to the
        // next layer along a slope of 1:2 (3.6 mm along for 1.8 up), each
        // climb carrying a bead's clay a millimetre: read as turnaround steps
        // they made "more than twice the clay" (the half-disc a turn needs
        // is less than a bead's clay along a long slope).
        let (w, h) = (4.5, 1.8);
        let r = verdict(&climbing_wall(w, h, w).out);
        assert_eq!(r.findings[Finding::TurnPile].count, 0, "{}", r.render());
        assert!(r.printable, "{}", r.render());
        // The same climbs carrying three times the clay do pile up.
        let g = climbing_wall(w, h, 3.0 * w);
        assert!(verdict(&g.out).findings[Finding::TurnPile].count > 0);
    }

    #[test]
    fn double_deposition_fails() {
        // Layer 5 printed twice at the same height.
        let mut g = wall(5);
        g.run([if 5 % 2 == 1 { 50.0 } else { 90.0 }, 50.0, 6.0], W, LAYER);
        let r = verdict(&g.out);
        only(&r, "laid on clay at their own height");
    }

    /// A turn laid 0.2 mm above the one below at full flow (a layer of
    /// 1.25 mm's clay in a 0.2 mm gap): most of its clay has no room and is
    /// pushed out sideways and up into the nozzle's path (docs/CHECKER.md,
    /// "Clay on clay"). It used to pass with a warning.
    #[test]
    fn a_turn_squashed_into_a_fifth_of_its_layer_fails() {
        let mut g = wall(6);
        let at = g.at;
        let z = at[2] + 0.2;
        g.bead([at[0], at[1], z], W, LAYER);
        let x1 = if at[0] < 70.0 { 90.0 } else { 50.0 };
        g.run([x1, 50.0, z], W, LAYER);
        let z2 = z + LAYER;
        g.bead([x1, 50.0, z2], W, LAYER);
        g.run([at[0], 50.0, z2], W, LAYER);
        let r = verdict(&g.out);
        assert!(!r.printable, "{}", r.render());
    }
}
