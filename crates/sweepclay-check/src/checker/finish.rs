//! The end of the file: the last stretches closed, the held findings and
//! the layers counted, and the verdict written (docs/CHECKER.md,
//! "Checks", "Numbers").

use super::*;

impl Checker<'_> {
    pub(super) fn finish(mut self) -> Report {
        self.close_stretch(None);
        // A taper at the rim is a few millimetres; a whole layer or more
        // of too little clay at the end is under-extruded all the same.
        let tail: f64 = self.under.iter().map(|u| u.2).sum();
        if tail > 2.0 * self.cfg.width_max {
            for (line, w, _) in std::mem::take(&mut self.under) {
                self.record(Finding::UnderExtruded, line, w, false);
            }
        }
        for k in 0..WEAK_KINDS.len() {
            self.flush_weak(k);
        }
        if self.lead.print_run.is_none() {
            // Nothing rests on anything (a single layer): the print begins
            // at the first run that is not a purge in the air.
            let runs = &self.lead.runs;
            let k = runs.iter().position(|r| r.air * 2 <= r.beads).unwrap_or(0);
            self.decide(k);
        }
        let start = std::mem::take(&mut self.lead.start);
        self.r.start_code = (!start.items.is_empty()).then_some(start);
        self.r.extrusion_runs = self.runs.saturating_sub(self.lead.print_run.unwrap_or(0));
        // What follows the last bead is the end code.
        let (moves_at, line_at) = self.last_bead;
        if self.started && (self.r.moves > moves_at || !self.pending.is_empty()) {
            let mut end = Segment {
                lines: [line_at + 1, self.r.lines],
                moves: self.r.moves - moves_at,
                ..Segment::default()
            };
            for &(kind, line, v) in &self.pending {
                end.note(match kind {
                    Finding::Retraction => format!("end retraction (line {line})"),
                    Finding::TravelMove => "lifting off and travel".into(),
                    Finding::Pause => format!("pause (line {line})"),
                    // Not printing, but into the piece just printed: a
                    // crash like any other (an end code's `G1 Z+30` read
                    // as Z30 from above the rim).
                    Finding::NozzleCollision | Finding::CarriageCollision
                        if !self.replayer.homing_lines.contains(&line) =>
                    {
                        self.r.findings[kind].add(line, v);
                        format!("drives the nozzle into the printed piece (line {line})")
                    }
                    Finding::NozzleCollision | Finding::CarriageCollision => {
                        "homing through the clay after the print (where the endstops are is the printer's), not judged".into()
                    }
                    _ => "moves after the print, not judged".into(),
                });
            }
            if end.items.is_empty() {
                end.note("moves after the last bead".into());
            }
            self.r.end_code = Some(end);
        }
        let r = &mut self.r;
        let ambiguous = &self.parser.ambiguous;
        if ambiguous.count > 0 {
            r.findings[Finding::AmbiguousNumber] = ambiguous.clone();
        }
        let unreadable = &self.parser.unreadable;
        if unreadable.count > 0 {
            r.findings[Finding::UnreadableNumber] = unreadable.clone();
        }
        // The size of the piece a person measures: the print's beads,
        // not a purge line or skirt of the start code beside it.
        let first = self
            .lead
            .print_run
            .filter(|&k| k < self.lead.runs.len())
            .unwrap_or(0);
        let (mut lo, mut hi) = self.lead.after;
        for run in self.lead.runs.get(first..).unwrap_or_default() {
            for a in 0..3 {
                lo[a] = lo[a].min(run.bounds.0[a]);
                hi[a] = hi[a].max(run.bounds.1[a]);
            }
        }
        if r.extruding_moves > 0 {
            r.size_mm = [hi[0] - lo[0], hi[1] - lo[1], hi[2].max(0.0)];
        }
        if let Some(median) = self.layer_heights.median() {
            if median > 0.0 {
                r.layers = (hi[2] / median).round() as usize;
            }
        }
        self.diags.sort_by_key(|d| d.line);
        r.diagnostics_total = self.diags.len() + self.diags_dropped;
        r.diagnostics = self.diags;
        r.printer = self.cfg.printer.clone();
        r.firmware = self.cfg.firmware.name().to_string();
        // A command the replay does not follow, between the print's first
        // bead and its last: what the clay sees after it is unknown.
        let print_line = self
            .lead
            .print_run
            .and_then(|k| self.lead.runs.get(k))
            .map_or(0, |run| run.line);
        let inside = self
            .unreplayed_inside
            .iter()
            .find(|(line, _)| *line > print_line)
            .map(|&(line, name)| {
                (
                    line,
                    format!("{name} inside the print: the checker does not replay it, and it may change where the nozzle goes or how much clay it lays (docs/CHECKER.md, \"Commands\"); move it to the start or end code"),
                )
            });
        r.cannot_judge = [self.replayer.cannot_judge.take(), inside]
            .into_iter()
            .flatten()
            .min_by_key(|(line, _)| *line)
            .map(|(line, message)| Diagnostic { line, message });
        verdict(r, self.cfg);
        self.r
    }
}

/// Layer heights counted in 1 µm bins up to 65.535 mm (higher ones in the
/// last): the median of millions of beads' heights in 256 KB.
#[derive(Default)]
pub(super) struct Heights {
    bins: Vec<u32>,
    n: u64,
}

impl Heights {
    /// Counts a layer height (mm; a NaN or negative one is not counted).
    pub(super) fn add(&mut self, dz: f64) {
        if dz.is_nan() || dz < 0.0 {
            return;
        }
        if self.bins.is_empty() {
            self.bins = vec![0; 1 << 16];
        }
        let k = ((dz * 1000.0).round() as usize).min(self.bins.len() - 1);
        self.bins[k] = self.bins[k].saturating_add(1);
        self.n += 1;
    }

    /// The element a sort would put in the middle (index n / 2), to the
    /// micrometre; `None` before any.
    pub(super) fn median(&self) -> Option<f64> {
        let mut left = self.n / 2;
        for (k, &c) in self.bins.iter().enumerate() {
            if left < u64::from(c) {
                return Some(k as f64 / 1000.0);
            }
            left -= u64::from(c);
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use crate::testkit::*;

    #[test]
    fn layers_are_the_height_over_the_median_layer_height() {
        // 6 layers of 0.8 mm, 8 of 1.2 and 6 of 1.6: 24 mm, median 1.2 mm
        // (the thinnest would say 30 layers, the thickest 15).
        let heights = [[0.8; 6].as_slice(), &[1.2; 8], &[1.6; 6]].concat();
        let mut g = G::new([50.0, 50.0, 0.8]);
        let mut z = 0.0;
        for (k, h) in heights.iter().enumerate() {
            z += h;
            let (x0, x1) = if k % 2 == 0 {
                (50.0, 90.0)
            } else {
                (90.0, 50.0)
            };
            if k > 0 {
                g.bead([x0, 50.0, z], W, *h);
            }
            g.run([x1, 50.0, z], W, *h);
        }
        let r = verdict(&g.out);
        assert!((r.size_mm[2] - 24.0).abs() < 1e-9, "{:?}", r.size_mm);
        assert_eq!(r.layers, 20, "{}", r.render());
    }

    #[test]
    fn json_report_round_trips_the_verdict() {
        let r = verdict(&wall(3).out);
        let v = serde_json::to_value(&r).unwrap();
        assert_eq!(v["printable"], true);
        assert_eq!(v["extrusion_runs"], 1);
    }
}
