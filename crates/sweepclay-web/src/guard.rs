//! What keeps the server safe to leave running (docs/MODELER.md, "Limits
//! and safety"): a bounded pool for the CPU-bound work, and a middleware
//! that answers only the page's own origin.
//!
//! Any web page the user visits can send requests to a server on
//! loopback. A cross-origin page can send a "simple" request (a `text/plain`
//! POST) without asking, and with DNS rebinding it can even read the
//! answers. So: a `Host` that is not this server's is refused (421), a
//! cross-origin `Origin` is refused (403), and work is only done for a
//! `Content-Type` a browser cannot send cross-origin without a preflight,
//! which this server never grants (no CORS headers).

use crate::api::{ApiError, Limits};
use axum::extract::Request;
use axum::http::{header, HeaderValue, Method};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use tokio::sync::Semaphore;

/// The body types the work routes take: both need a CORS preflight.
pub const BODY_TYPES: [&str; 2] = ["application/json", "application/octet-stream"];

/// A bounded pool for CPU-bound work: `workers` at once, `queue` waiting,
/// and no more.
#[derive(Debug)]
pub struct Pool {
    permits: Arc<Semaphore>,
    waiting: AtomicUsize,
    queue: usize,
    timeout: std::time::Duration,
}

impl Pool {
    /// The pool the limits describe.
    pub fn new(limits: &Limits) -> Pool {
        Pool {
            permits: Arc::new(Semaphore::new(limits.workers.max(1))),
            waiting: AtomicUsize::new(0),
            queue: limits.queue,
            timeout: limits.request_timeout,
        }
    }

    /// Runs `f` on a blocking thread once a worker is free. Too many
    /// waiting, or no worker within the time limit: 503 with `Retry-After`.
    /// The worker stays taken until `f` ends, even if the client has gone,
    /// so the pool bounds the work really running.
    pub async fn run<T: Send + 'static>(
        &self,
        f: impl FnOnce() -> Result<T, ApiError> + Send + 'static,
    ) -> Result<T, ApiError> {
        let busy = || {
            ApiError::new(503, "the server is busy: try again in a moment".to_string())
                .retry_after(2)
        };
        if self.waiting.fetch_add(1, Ordering::SeqCst) >= self.queue + self.permits_total() {
            self.waiting.fetch_sub(1, Ordering::SeqCst);
            return Err(busy());
        }
        let start = tokio::time::Instant::now();
        let permit = tokio::time::timeout(self.timeout, self.permits.clone().acquire_owned()).await;
        self.waiting.fetch_sub(1, Ordering::SeqCst);
        let Ok(Ok(permit)) = permit else {
            return Err(busy());
        };
        let left = self.timeout.saturating_sub(start.elapsed());
        let task = tokio::task::spawn_blocking(move || {
            let out = f();
            drop(permit);
            out
        });
        match tokio::time::timeout(left, task).await {
            Ok(Ok(out)) => out,
            Ok(Err(e)) => Err(ApiError::new(500, format!("internal error: {e}"))),
            Err(_) => Err(ApiError::new(
                503,
                format!(
                    "the work took longer than this server's limit of {} s",
                    self.timeout.as_secs()
                ),
            )),
        }
    }

    fn permits_total(&self) -> usize {
        // Available plus taken is constant: the workers.
        self.permits.available_permits().max(1)
    }
}

/// The host part of a `Host` header value (`[::1]:8080` → `[::1]`).
fn host_name(v: &str) -> &str {
    if let Some(end) = v.find(']') {
        &v[..=end]
    } else {
        v.split(':').next().unwrap_or(v)
    }
}

/// Refuses requests that are not from the page's own origin (above), and
/// a body larger than the route's limit before it is read; every answer
/// carries `nosniff` and a policy that no other page may frame this one.
pub async fn same_origin(
    hosts: Arc<Vec<String>>,
    body_limit: usize,
    req: Request,
    next: Next,
) -> Response {
    let mut res = match refusal(&hosts, body_limit, &req) {
        Some(e) => e.into_response(),
        None => next.run(req).await,
    };
    let headers = res.headers_mut();
    headers.insert(
        header::X_CONTENT_TYPE_OPTIONS,
        HeaderValue::from_static("nosniff"),
    );
    headers.insert(
        header::CONTENT_SECURITY_POLICY,
        HeaderValue::from_static("frame-ancestors 'none'"),
    );
    headers.insert(header::X_FRAME_OPTIONS, HeaderValue::from_static("DENY"));
    res
}

/// Why `req` is refused, if it is.
fn refusal(hosts: &[String], body_limit: usize, req: &Request) -> Option<ApiError> {
    let h = req.headers();
    let text = |name| h.get(name).and_then(|v: &HeaderValue| v.to_str().ok());
    let host = text(header::HOST).unwrap_or("");
    if !hosts.is_empty()
        && !hosts
            .iter()
            .any(|a| a.eq_ignore_ascii_case(host_name(host)))
    {
        return Some(ApiError::new(
            421,
            format!(
                "this server answers for {} only, not for Host `{host}`",
                hosts.join(", ")
            ),
        ));
    }
    if let Some(origin) = text(header::ORIGIN) {
        let own = ["http://", "https://"].iter().any(|s| {
            origin
                .strip_prefix(s)
                .is_some_and(|o| o.eq_ignore_ascii_case(host))
        });
        if !own {
            return Some(ApiError::new(
                403,
                format!(
                    "requests from `{origin}` are refused: only this server's own page may use it"
                ),
            ));
        }
    }
    if req.method() != Method::POST {
        return None;
    }
    let ty = text(header::CONTENT_TYPE).unwrap_or("");
    let base = ty.split(';').next().unwrap_or("").trim();
    if !BODY_TYPES.iter().any(|t| t.eq_ignore_ascii_case(base)) {
        return Some(ApiError::new(
            415,
            format!("send the body as {} (got `{ty}`)", BODY_TYPES.join(" or ")),
        ));
    }
    let length = text(header::CONTENT_LENGTH).and_then(|v| v.parse::<u64>().ok());
    length.filter(|&n| n > body_limit as u64).map(|_| {
        ApiError::new(
            413,
            format!("request body too large (over {} MiB)", body_limit >> 20),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn host_names_without_ports() {
        assert_eq!(host_name("127.0.0.1:8080"), "127.0.0.1");
        assert_eq!(host_name("localhost"), "localhost");
        assert_eq!(host_name("[::1]:80"), "[::1]");
        assert_eq!(host_name("evil.example:8080"), "evil.example");
    }
}
