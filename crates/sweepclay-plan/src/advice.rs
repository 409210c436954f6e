//! What to change in a design whose G-code the correction loop could not
//! make pass: for each kind of failure the cause, the place and the
//! change, in a potter's words (docs/CHECKER.md, "Verdicts").

use crate::check::locate;
use crate::plan::Checked;
use sweepclay_check::Finding;
use sweepclay_core::rim::RimShape;

impl<W> Checked<W> {
    /// For each kind of failure the loop could not correct: the cause,
    /// the place (G-code line, pass, curve, u, z) and the change to the
    /// design that would fix it. Empty when printable.
    pub fn advice(&self) -> Vec<String> {
        let s = &self.sliced;
        let p = &s.corrected.surface.params;
        let r = s.corrected.surface.printer.nozzle_radius;
        let rounds = s.corrected.report.rounds;
        let uneven = s
            .corrected
            .surface
            .vessel
            .as_ref()
            .and_then(|v| v.uneven.as_ref());
        let tried = if rounds > 0 {
            format!(" (after {rounds} round(s) of tightened corrections)")
        } else {
            String::new()
        };
        // The most rise of this rim that prints, said once: with the
        // body's collisions (the usual cause), else on its own.
        let rise = self.most_rise.as_ref().map(|(most, rim)| {
            let (shape, fewer) = match (rim.shape, rim.peaks) {
                (RimShape::Wave, Some(k)) if k > 1 => {
                    (format!("{k}-crest wave"), ", or more with fewer crests")
                }
                (RimShape::Wave, _) => ("wave".to_string(), ""),
                (RimShape::Slant, _) => ("slant".to_string(), ""),
                (RimShape::Raised, _) => ("raised arc".to_string(), ""),
            };
            format!(
                "the rim's {shape} rises {:.1} mm, more than one continuous path climbs here; at most {most:.1} mm of rise prints this pot (rim.rise){fewer}",
                rim.rise
            )
        });
        let collides = self.report.findings[Finding::NozzleCollision]
            .first_line
            .is_some();
        Finding::ALL
            .iter()
            .filter_map(|&k| {
                let c = &self.report.findings[k];
                let line = c.first_line?;
                let worst = c.worst.map_or(0.0, |w| w.0);
                let place = locate(s, &self.point_lines, line)
                    .unwrap_or_else(|| format!("line {line}"));
                let change = match k {
                    Finding::NozzleCollision if rise.is_some() => format!(
                        "the extruder body ({r} mm radius) meets clay {worst:.1} mm above the nozzle{tried}: {}",
                        rise.as_deref().expect("matched")
                    ),
                    Finding::Overhang => format!(
                        "an overhang of {worst:.0}° beyond the {}° limit{tried}: lean the profiles less there, or raise params.max_overhang_deg if your clay stands steeper",
                        p.max_overhang_deg
                    ),
                    Finding::UnderMinOverlap => format!(
                        "a bead overlapping the one below by too little{tried}: lean the profiles less there, or raise params.width_max ({} mm) so a wider bead reaches",
                        p.width_max
                    ),
                    Finding::NozzleCollision if uneven.is_some_and(|u| u.peaks.is_some()) => {
                        let why = uneven.and_then(|u| u.peaks.as_ref()).expect("matched");
                        format!("the extruder body ({r} mm radius) meets clay {worst:.1} mm above the nozzle{tried}: {why}")
                    }
                    Finding::NozzleCollision if uneven.is_some() => {
                        let u = uneven.expect("matched");
                        format!(
                            "the extruder body ({r} mm radius) meets clay {worst:.1} mm above the nozzle{tried}: the rim rises or falls too steeply round the loop for one spiral (first near ({:.0}, {:.0}) mm); bring the rim's heights within {:.1} mm of each other (now {:.1} mm apart)",
                            u.at[0], u.at[1], u.most_mm, u.spread_mm
                        )
                    }
                    Finding::NozzleCollision => format!(
                        "the extruder body ({r} mm radius) meets clay {worst:.1} mm above the nozzle{tried}: keep that part of the wall more than {:.0} mm in plan from the rest of it, or bring the two profiles' heights closer so the passes tilt less",
                        r + p.width_max / 2.0
                    ),
                    Finding::DoubleDeposition => "clay laid on clay of its own layer: move those parts of the trajectory apart, or lower params.width_max".to_string(),
                    Finding::TurnPile => "clay piling up where the path turns: lower params.max_layer_height, or set params.even_turn_flow".to_string(),
                    Finding::Unsupported => "a bead with no clay under it: lean the profiles less there".to_string(),
                    Finding::OutOfBounds => "outside the printer's build volume: make the design smaller or choose a larger printer".to_string(),
                    other => other.failure().to_string(),
                };
                Some(format!("{change} — at {place}"))
            })
            .chain(rise.clone().filter(|_| !collides))
            .chain(self.most_twist.map(|most| {
                let t = s.corrected.surface.columns.first().map_or(0.0, |c| c.twist.to_degrees());
                format!(
                    "the twist ({t:.0}°) turns the wall across the clay below faster than it holds here: at most {most:.0}° of twist prints this shape (twist_deg)"
                )
            }))
            .collect()
    }
}
