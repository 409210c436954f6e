//! The error every API call answers with: an HTTP status and a message
//! that names the key (or line) at fault, in the page's JSON.

use serde::Serialize;
use sweepclay_core::Error;

/// An answer the page shows as an error: an HTTP status and a message that
/// names the key (or line) at fault.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ApiError {
    /// HTTP status: 400 unreadable input, 413 too large, 422 a valid design
    /// that cannot be printed or has values out of range.
    #[serde(skip)]
    pub status: u16,
    /// The message, e.g. `params.layer_height: must be between …`.
    pub error: String,
    /// The offending key, when there is one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub key: Option<String>,
    /// The checker's failures, for a design whose G-code is not printable.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub failures: Vec<String>,
    /// Where in the design the failures are.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub locations: Vec<String>,
    /// Seconds after which a busy server may be asked again (503).
    #[serde(skip)]
    pub retry_after: Option<u32>,
}

impl ApiError {
    /// An error with a status and message.
    pub fn new(status: u16, error: impl Into<String>) -> Self {
        ApiError {
            status,
            error: error.into(),
            key: None,
            failures: Vec::new(),
            locations: Vec::new(),
            retry_after: None,
        }
    }

    /// The same error, saying when to try again (`Retry-After`).
    pub fn retry_after(self, secs: u32) -> Self {
        ApiError {
            retry_after: Some(secs),
            ..self
        }
    }
}

impl ApiError {
    /// The same error, naming the offending key.
    pub fn with_key(self, key: impl Into<String>) -> Self {
        ApiError {
            key: Some(key.into()),
            ..self
        }
    }
}

impl From<Error> for ApiError {
    fn from(e: Error) -> Self {
        let (status, key) = match &e {
            Error::Parse { .. } => (400, None),
            Error::Invalid { key, .. } => (422, Some(key.clone())),
            Error::TooLarge { .. } => (413, Some("params.spacing".into())),
            _ => (422, None),
        };
        ApiError {
            key,
            ..ApiError::new(status, e.to_string())
        }
    }
}
