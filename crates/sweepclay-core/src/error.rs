//! The one error type of the pipeline library.
//!
//! Caller mistakes (an invalid design) are kept apart from the cases where a
//! valid design cannot be printed with the given parameters; both name the
//! offending key or value so the message can be shown to a user as is.

use thiserror::Error;

/// Everything that can go wrong between a design file and G-code.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum Error {
    /// The design file is not valid JSON or does not match the format
    /// (unknown key, wrong type). `line` and `column` are 1-based.
    #[error("design file, line {line} column {column}: {message}")]
    Parse {
        /// serde_json's description, which names the key.
        message: String,
        /// 1-based line of the problem.
        line: usize,
        /// 1-based column of the problem.
        column: usize,
    },
    /// A key has a value the design format does not allow.
    #[error("{key}: {reason}")]
    Invalid {
        /// Dotted path of the key, e.g. `params.layer_height` or
        /// `profile_start.control_points[2]`.
        key: String,
        /// What is wrong, with the bad value.
        reason: String,
    },
    /// The surface meets itself and compressing the profiles cannot fix it.
    #[error("self-intersection: {0}")]
    SelfIntersection(String),
    /// No layering satisfies the layer-height bounds for this design.
    #[error("layering: {0}")]
    Layering(String),
    /// The printed object would leave the printer's build volume.
    #[error("the design does not fit printer `{printer}`: {axis} spans {min:.1}..{max:.1} mm but the build volume is {low:.1}..{limit:.1} mm")]
    DoesNotFit {
        /// Printer name.
        printer: String,
        /// `x`, `y` or `z`.
        axis: char,
        /// Lowest coordinate on the bed, bead edge included.
        min: f64,
        /// Highest coordinate on the bed, bead edge included.
        max: f64,
        /// The build volume's lowest coordinate along the axis (`bed_min`).
        low: f64,
        /// The build volume's highest coordinate along the axis.
        limit: f64,
    },
    /// The printed object would leave a round bed (a delta's).
    #[error("the design does not fit printer `{printer}`: it reaches {reach:.1} mm from the bed's centre but the round bed is {diameter:.0} mm across")]
    OffRoundBed {
        /// Printer name.
        printer: String,
        /// Farthest plan distance from the bed's centre, bead edge included.
        reach: f64,
        /// The bed's diameter.
        diameter: f64,
    },
    /// The design has more surface samples than the caller allows
    /// (estimated from its control polygons before anything is sampled).
    #[error("params.spacing / params.layer_height: the design would have about {:.1} million samples, over the limit of {:.1} million; raise the spacing or the layer height", .estimate / 1e6, .limit / 1e6)]
    TooLarge {
        /// The estimate ([`crate::estimated_samples`]).
        estimate: f64,
        /// The limit.
        limit: f64,
    },
}

impl Error {
    /// Shorthand for [`Error::Invalid`].
    pub fn invalid(key: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::Invalid {
            key: key.into(),
            reason: reason.into(),
        }
    }
}

/// Result with the library's [`enum@Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
