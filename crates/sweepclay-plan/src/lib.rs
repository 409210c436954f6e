//! The one plan of sweepclay (docs/ARCHITECTURE.md): a design becomes a
//! validated [`Job`], and [`plan()`] runs the pipeline's stages
//! (`sweepclay-core`) and checks their G-code with the independent checker
//! (`sweepclay-check`), correcting and running again until it passes or no
//! correction helps. It sits above both crates so that the pipeline never
//! depends on the checker that judges it. The CLI's `slice` and every
//! modeler route that slices call [`plan()`]: what the preview shows is
//! what the download prints.

pub mod advice;
pub mod cancel;
pub mod check;
pub mod job;
pub mod plan;
pub mod stage;

pub use cancel::{Cancel, CancelReader, CancelWriter};
pub use check::{check_config, locate, printer_check, verify, verify_into, verify_until, Verified};
pub use job::{Job, Limits};
pub use plan::{plan, slice_checked, unfit, Checked, Planned, Unchecked, Unfit, MAX_ROUNDS};
pub use stage::{Samples, Stage};
