//! A validated job: a design with its printer and parameters resolved,
//! checked once before anything is sampled (docs/ARCHITECTURE.md). Every
//! refusal that needs no slicing happens here — a parameter out of its
//! range, a texture, the sample cap, the build volume — the way a
//! command line's raw flags become one validated job before work starts.

use crate::stage::{Samples, Stage};
use std::sync::Arc;
use sweepclay_core::{surface, Design, Error, Result, Surface};

/// What a job is held to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    /// The checker's hard floor: a bead overlapping the bead below by
    /// less than this fraction of its width fails (0 to 1).
    pub min_overlap: f64,
    /// The most surface samples a design may have, estimated before it is
    /// sampled ([`sweepclay_core::estimated_samples`]).
    pub max_samples: f64,
    /// Refuse a design that leaves the build volume before slicing it
    /// (the CLI); the modeler lets it through to show the part outside.
    pub must_fit: bool,
}

impl Default for Limits {
    /// The checker's half-bead floor, the default sample cap, and a
    /// design that must fit.
    fn default() -> Limits {
        Limits {
            min_overlap: 0.5,
            max_samples: DEFAULT_MAX_SAMPLES as f64,
            must_fit: true,
        }
    }
}

/// The sample cap `slice` and `serve` use unless told otherwise
/// (docs/PERFORMANCE.md, "The size cap").
pub const DEFAULT_MAX_SAMPLES: u64 = 1_500_000;

/// A design ready to plan: validated against its [`Limits`].
#[derive(Clone, Debug)]
pub struct Job {
    design: Design,
    min_overlap: f64,
    samples: Option<Samples>,
}

impl Job {
    /// Validates `design` once: `min_overlap` in 0..=1, the parameters'
    /// ranges, the textures, the estimated samples under the cap, and
    /// (with `must_fit`) the build volume. Each refusal names its key.
    pub fn new(design: Design, limits: &Limits) -> Result<Job> {
        if !(0.0..=1.0).contains(&limits.min_overlap) {
            return Err(Error::invalid(
                "min_overlap",
                format!(
                    "must be a fraction from 0 to 1 (got {})",
                    limits.min_overlap
                ),
            ));
        }
        if limits.max_samples.is_finite() {
            sweepclay_core::check_samples(&design, limits.max_samples)?;
        } else {
            // No cap: no estimate (a coarse sampling) to compare with it.
            design.params.validate()?;
            design.check_texture()?;
        }
        // A printer is resolved here, once, not left to the sampling a
        // kept surface may spare (docs/ARCHITECTURE.md, "Stages").
        design.printer.resolve()?;
        if limits.must_fit {
            design.check_fit()?;
        }
        Ok(Job {
            design,
            min_overlap: limits.min_overlap,
            samples: None,
        })
    }

    /// The job drawing its sampled surface from `store` (and keeping it
    /// there): a job whose sampling inputs equal a kept one's is not
    /// sampled again ([`Job::first_changed`]).
    pub fn with_samples(mut self, store: &Samples) -> Job {
        self.samples = Some(store.clone());
        self
    }

    /// The first stage whose inputs differ from this job's in `new`
    /// ([`Stage::between`] their designs, then the check's overlap
    /// floor), or `None` when they plan alike.
    pub fn first_changed(&self, new: &Job) -> Option<Stage> {
        Stage::between(&self.design, &new.design)
            .or((self.min_overlap != new.min_overlap).then_some(Stage::Check))
    }

    /// Stage 1's output for the job: from its store if it has one, else
    /// sampled now.
    pub fn sampled(&self) -> Result<Arc<Surface>> {
        match &self.samples {
            Some(store) => store.sampled(&self.design),
            None => surface::sample_surface(&self.design).map(Arc::new),
        }
    }

    /// The design as validated.
    pub fn design(&self) -> &Design {
        &self.design
    }

    /// The overlap floor the job's G-code is checked with.
    pub fn min_overlap(&self) -> f64 {
        self.min_overlap
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sweepclay_core::examples;

    #[test]
    fn an_edit_names_the_first_stage_it_changes() {
        use crate::stage::tests::{edits, example};
        let job = |d: Design| Job::new(d, &Limits::default()).unwrap();
        let d = example("vase");
        assert_eq!(job(d.clone()).first_changed(&job(d.clone())), None);
        for (what, stage, edit) in edits() {
            let mut e = d.clone();
            edit(&mut e);
            assert_eq!(job(d.clone()).first_changed(&job(e)), Some(stage), "{what}");
        }
        let strict = Job::new(
            d.clone(),
            &Limits {
                min_overlap: 0.7,
                ..Limits::default()
            },
        )
        .unwrap();
        assert_eq!(job(d).first_changed(&strict), Some(Stage::Check));
    }

    fn vase() -> Design {
        Design::from_json(examples::example("vase").unwrap()).unwrap()
    }

    #[test]
    fn a_job_refuses_by_name_before_anything_is_sampled() {
        assert!(Job::new(vase(), &Limits::default()).is_ok());
        let e = Job::new(
            vase(),
            &Limits {
                min_overlap: 1.5,
                ..Limits::default()
            },
        )
        .unwrap_err();
        assert!(e.to_string().starts_with("min_overlap:"), "{e}");
        let mut d = vase();
        d.params.layer_height = 0.0;
        let e = Job::new(d, &Limits::default()).unwrap_err().to_string();
        assert!(e.contains("layer_height"), "{e}");
        let small = Limits {
            max_samples: 1000.0,
            ..Limits::default()
        };
        assert!(matches!(
            Job::new(vase(), &small),
            Err(Error::TooLarge { .. })
        ));
    }

    #[test]
    fn a_design_outside_the_printer_is_refused_only_when_it_must_fit() {
        let mut d = vase();
        // The vase 300 mm tall on a printer 200 mm high.
        for c in [&mut d.profile_start, d.profile_end.as_mut().unwrap()] {
            for p in &mut c.control_points {
                p[1] *= 3.0;
            }
        }
        assert!(Job::new(d.clone(), &Limits::default()).is_err());
        let shown = Limits {
            must_fit: false,
            ..Limits::default()
        };
        assert!(Job::new(d, &shown).is_ok());
    }
}
