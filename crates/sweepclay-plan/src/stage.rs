//! The plan's stages, named, and what each reads of a job
//! (docs/ARCHITECTURE.md, "Stages"): an edit recomputes only the stages
//! from the first whose inputs it changes, as PrusaSlicer's
//! `PrintObjectStep` invalidates only the steps below a changed setting.
//!
//! Stage 1's output, the sampled surface, is kept in a [`Samples`] store
//! and reused by a job whose sampling inputs are equal: a new printer,
//! speed or flow setting does not resample (sampling a vessel, with its
//! layering search, is a third of its plan; docs/PERFORMANCE.md). The
//! stages after sampling run as one loop, since the check of one round's
//! G-code decides the next round's corrections: whatever changes from
//! stage 2 on runs that loop again.

use std::sync::{Arc, Mutex};
use sweepclay_core::printer::{Printer, PrinterRef};
use sweepclay_core::{surface, Design, Result, Surface};

/// A stage of the plan, in the order they run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Stage {
    /// Parsing and the job's checks (`Job::new`): every refusal that
    /// needs no slicing.
    Validate,
    /// 1: the design's curves sampled into columns (paper §3), the
    /// layering chosen, textures and twist applied
    /// ([`surface::sample_surface`]).
    Sample,
    /// 2: the corrections for overhang, self-intersection and the
    /// extruder body (paper §4).
    Correct,
    /// 3: the path through the samples (paper §5.1–5.2).
    Path,
    /// 4: the bead widths and flows (paper §5.3).
    Extrude,
    /// 5: the G-code written.
    Emit,
    /// The independent check of that G-code (docs/CHECKER.md).
    Check,
}

impl Stage {
    /// The first stage whose inputs differ between two designs, or
    /// `None` when they are equal (the job adds the check's overlap
    /// floor: `Job::first_changed`). Stage 1 reads the curves, the
    /// textures, the twist, rim and relief, the parameters but the
    /// feedrate, the even-turn flow and the correction report's limit,
    /// and of the printer only the extruder body's radius (its reach
    /// decides which columns are neighbours); stage 2 reports with
    /// `max_correction_mm`; stage 4 reads `even_turn_flow`; stage 5 the
    /// rest of the printer, the feedrate and the name.
    pub fn between(a: &Design, b: &Design) -> Option<Stage> {
        if sampling_view(a) != sampling_view(b) {
            Some(Stage::Sample)
        } else if a.params.max_correction_mm != b.params.max_correction_mm {
            Some(Stage::Correct)
        } else if a.params.even_turn_flow != b.params.even_turn_flow {
            Some(Stage::Extrude)
        } else if a != b {
            Some(Stage::Emit)
        } else {
            None
        }
    }
}

/// What stage 1 reads of a design: the design with what it does not
/// read set to one value (the printer's body radius kept; a printer that
/// does not resolve is kept whole, and `Job::new` refuses it).
fn sampling_view(d: &Design) -> Design {
    let mut v = d.clone();
    v.name.clear();
    let defaults = sweepclay_core::Params::default();
    v.params.feedrate = defaults.feedrate;
    v.params.even_turn_flow = defaults.even_turn_flow;
    v.params.max_correction_mm = defaults.max_correction_mm;
    if let Ok(p) = d.printer.resolve() {
        v.printer = PrinterRef::Inline(Box::new(Printer {
            nozzle_radius: p.nozzle_radius,
            ..Printer::default()
        }));
    }
    v
}

/// How many sampled surfaces a [`Samples`] store keeps: a modeler's
/// open tabs and the design before an edit.
pub const KEPT_SURFACES: usize = 4;

/// Stage 1's outputs kept for reuse, the most recently used first; a
/// cheap handle to share between threads (the server keeps one).
#[derive(Clone, Default)]
pub struct Samples(Arc<Mutex<Vec<Kept>>>);

/// A kept surface and what its sampling read ([`sampling_view`]).
type Kept = (Design, Arc<Surface>);

impl std::fmt::Debug for Samples {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let n = self.0.lock().map_or(0, |v| v.len());
        write!(f, "Samples({n} kept)")
    }
}

impl Samples {
    /// An empty store.
    pub fn new() -> Samples {
        Samples::default()
    }

    /// The sampled surface of `design`: a kept one whose sampling inputs
    /// are the design's ([`Stage::between`] after [`Stage::Sample`]), given the design's name, parameters and
    /// printer, or else sampled now and kept.
    pub fn sampled(&self, design: &Design) -> Result<Arc<Surface>> {
        let view = sampling_view(design);
        let hit = {
            let mut kept = self.0.lock().unwrap_or_else(|e| e.into_inner());
            let i = kept.iter().position(|(v, _)| *v == view);
            i.map(|i| {
                let e = kept.remove(i);
                let s = e.1.clone();
                kept.insert(0, e);
                s
            })
        };
        if let Some(s) = hit {
            return reuse(s, design);
        }
        let s = Arc::new(surface::sample_surface(design)?);
        let mut kept = self.0.lock().unwrap_or_else(|e| e.into_inner());
        kept.retain(|(v, _)| *v != view);
        kept.insert(0, (view, s.clone()));
        kept.truncate(KEPT_SURFACES);
        Ok(s)
    }

    /// How many surfaces are kept.
    pub fn len(&self) -> usize {
        self.0.lock().map_or(0, |v| v.len())
    }

    /// Whether none is.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// A kept surface for a design whose sampling inputs are its own: the
/// same samples with the design's name, parameters (as printed) and
/// printer, which later stages read.
fn reuse(kept: Arc<Surface>, design: &Design) -> Result<Arc<Surface>> {
    let printer = design.printer.resolve()?;
    let params = design.printed().params;
    if kept.name == design.name && kept.params == params && kept.printer == printer {
        return Ok(kept);
    }
    let mut s = (*kept).clone();
    s.name = design.name.clone();
    s.params = params;
    s.printer = printer;
    Ok(Arc::new(s))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use sweepclay_core::examples;

    pub(crate) fn example(name: &str) -> Design {
        Design::from_json(examples::example(name).unwrap()).unwrap()
    }

    /// An edit's name, the stage it must first recompute, the edit.
    pub(crate) type Edit = (&'static str, Stage, fn(&mut Design));

    pub(crate) fn edits() -> Vec<Edit> {
        vec![
            ("name", Stage::Emit, |d| d.name = "renamed".into()),
            ("feedrate", Stage::Emit, |d| d.params.feedrate *= 1.5),
            ("even turn flow", Stage::Extrude, |d| {
                d.params.even_turn_flow = !d.params.even_turn_flow
            }),
            ("report limit", Stage::Correct, |d| {
                d.params.max_correction_mm += 1.0
            }),
            ("printer flow", Stage::Emit, |d| {
                let mut p = d.printer.resolve().unwrap();
                p.e_per_mm3 *= 1.1;
                p.travel_feedrate *= 0.5;
                p.start_gcode.push_str("\n; hello");
                d.printer = PrinterRef::Inline(Box::new(p));
            }),
            ("body radius", Stage::Sample, |d| {
                let mut p = d.printer.resolve().unwrap();
                p.nozzle_radius += 2.0;
                d.printer = PrinterRef::Inline(Box::new(p));
            }),
            ("layer height", Stage::Sample, |d| {
                d.params.max_layer_height *= 0.9
            }),
            ("twist", Stage::Sample, |d| d.twist_deg += 10.0),
        ]
    }

    /// The store's answer after any edit is what sampling the edited
    /// design gives: a kept surface is reused only where sampling reads
    /// nothing the edit changed.
    #[test]
    fn a_kept_surface_is_what_sampling_the_edited_design_gives() {
        for name in ["vase", "t1", "ripple-vase", "pitcher"] {
            let d = example(name);
            let store = Samples::new();
            store.sampled(&d).unwrap();
            for (what, _, edit) in edits() {
                let mut e = d.clone();
                edit(&mut e);
                let fresh = surface::sample_surface(&e).unwrap();
                let kept = store.sampled(&e).unwrap();
                assert!(*kept == fresh, "{name}: {what}");
            }
        }
    }

    #[test]
    fn the_store_keeps_the_most_recent_surfaces_and_reuses_them() {
        let store = Samples::new();
        let d = example("vase");
        let a = store.sampled(&d).unwrap();
        let b = store.sampled(&d).unwrap();
        assert!(Arc::ptr_eq(&a, &b), "the same design is not sampled twice");
        for k in 0..KEPT_SURFACES + 2 {
            let mut e = d.clone();
            e.twist_deg = 5.0 * (k + 1) as f64;
            store.sampled(&e).unwrap();
        }
        assert_eq!(store.len(), KEPT_SURFACES);
        let c = store.sampled(&d).unwrap();
        assert!(!Arc::ptr_eq(&a, &c), "the oldest was let go");
    }
}
