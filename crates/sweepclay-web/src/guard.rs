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

use crate::error::ApiError;
use axum::extract::Request;
use axum::http::{header, HeaderName, HeaderValue, Method};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use tokio::sync::Semaphore;

/// Limits that keep one request, or many, from exhausting the machine
/// (docs/MODELER.md, "Limits and safety").
#[derive(Clone, Debug, PartialEq)]
pub struct Limits {
    /// Most surface samples a design may have (estimated before slicing).
    pub max_samples: f64,
    /// Slices, checks and meshes run at once (default: the cores).
    pub workers: usize,
    /// Requests that may wait for a worker; beyond them, 503 with
    /// `Retry-After` (default: 4 a worker).
    pub queue: usize,
    /// How long a request may wait for a worker and run (default 60 s);
    /// past it, 503.
    pub request_timeout: std::time::Duration,
    /// The names the server answers to in `Host` (with any port):
    /// `127.0.0.1`, `localhost`, `[::1]` and the address it was started
    /// on; in LAN mode also the machine's names and `--allow-host`.
    /// Never empty in practice: a DNS-rebinding page's requests carry its
    /// own name, which no list holds (docs/MODELER.md, "LAN mode").
    pub hosts: Vec<String>,
    /// LAN mode (bound to every interface): any IP address is also a
    /// name the server answers to (a rebinding page cannot send one as
    /// its Host: it would be that page's own origin).
    pub lan: bool,
    /// A secret the page must carry to use the API (its cookie, set when
    /// the page is opened with `?token=…`, or the header
    /// `x-sweepclay-token`); `None`: no token.
    pub token: Option<String>,
    /// Most bytes of request bodies held at once, received or being
    /// worked on (default [`BODY_BUDGET`]): each POST reserves its
    /// `Content-Length` (its route's limit when it gives none) before any
    /// of it is read, and frees it with its answer; past the budget, 503.
    pub body_budget: usize,
    /// Connections open at once and how long a client may take (default
    /// 256; 10 s to start a request, send its headers or fall silent in
    /// its body; an answer may take the request timeout plus a minute, so
    /// a slice in flight is never cut).
    pub connections: crate::conn::Connections,
}

impl Default for Limits {
    fn default() -> Self {
        let workers = std::thread::available_parallelism().map_or(2, |n| n.get());
        Limits {
            max_samples: sweepclay_plan::job::DEFAULT_MAX_SAMPLES as f64,
            workers,
            queue: 4 * workers,
            request_timeout: std::time::Duration::from_secs(60),
            connections: crate::conn::Connections {
                max: 256,
                read: std::time::Duration::from_secs(10),
                answer: std::time::Duration::from_secs(120),
            },
            hosts: ["127.0.0.1", "localhost", "[::1]"]
                .map(String::from)
                .to_vec(),
            lan: false,
            token: None,
            body_budget: BODY_BUDGET,
        }
    }
}

/// The work's stop flag (`sweepclay_plan::Cancel`), set when the request
/// that asked for the work is gone (its client disconnected, or its time
/// ran out): the work stops at its next check, between the pipeline's
/// stages and every 64 KiB of G-code written or read (docs/MODELER.md,
/// "Limits and safety").
pub use sweepclay_plan::{Cancel, CancelReader, CancelWriter};

/// A stopped piece of work as the API answers it.
pub trait Stopped {
    /// An error to end the work with once the flag is set (503).
    fn check(&self) -> Result<(), ApiError>;
    /// The error of an I/O step that failed: the stop, if the flag is set
    /// (a [`CancelWriter`] or [`CancelReader`] failing on purpose), else
    /// `what` failing (500).
    fn io_error(&self, what: &str, e: std::io::Error) -> ApiError;
}

impl Stopped for Cancel {
    fn check(&self) -> Result<(), ApiError> {
        if self.is_set() {
            Err(ApiError::new(
                503,
                "the work was stopped: its request went away or ran out of time".to_string(),
            ))
        } else {
            Ok(())
        }
    }

    fn io_error(&self, what: &str, e: std::io::Error) -> ApiError {
        self.check()
            .err()
            .unwrap_or_else(|| ApiError::new(500, format!("{what}: {e}")))
    }
}

/// Sets its flag when dropped: when the request's future is dropped (the
/// client disconnected) or returns (its time ran out, or it is done).
struct SetOnDrop(Cancel);

impl Drop for SetOnDrop {
    fn drop(&mut self) {
        self.0.set();
    }
}

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
    /// When the request goes away (this future is dropped, or the time
    /// limit passes) `f`'s [`Cancel`] is set and it stops at its next
    /// check; the worker stays taken until it has, so the pool bounds the
    /// work really running.
    pub async fn run<T: Send + 'static>(
        &self,
        f: impl FnOnce(&Cancel) -> Result<T, ApiError> + Send + 'static,
    ) -> Result<T, ApiError> {
        let cancel = Cancel::new();
        let _stop = SetOnDrop(cancel.clone());
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
            let out = f(&cancel);
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

/// The host part of a `Host` header value (`[::1]:8080` → `[::1]`), if
/// it is one: a name of letters, digits, dots and hyphens or a bracketed
/// IPv6 address, then at most a `:` and a port of digits. Anything else
/// (`[::1]evil.example`, `localhost:80@evil`) is no host.
fn host_name(v: &str) -> Option<&str> {
    let (name, port) = if v.starts_with('[') {
        let end = v.find(']')?;
        (&v[..=end], &v[end + 1..])
    } else {
        match v.find(':') {
            Some(i) => (&v[..i], &v[i..]),
            None => (v, ""),
        }
    };
    let port_ok = port.is_empty()
        || (port.len() > 1
            && port.starts_with(':')
            && port[1..].bytes().all(|b| b.is_ascii_digit()));
    let name_ok = match name.strip_prefix('[') {
        Some(inner) => inner.strip_suffix(']').is_some_and(|a| {
            !a.is_empty()
                && a.bytes()
                    .all(|b| b.is_ascii_hexdigit() || b == b':' || b == b'.')
        }),
        None => {
            !name.is_empty()
                && name
                    .bytes()
                    .all(|b| b.is_ascii_alphanumeric() || b == b'.' || b == b'-')
        }
    };
    (port_ok && name_ok).then_some(name)
}

/// Refuses requests that are not from the page's own origin (above), and
/// a body larger than the route's limit before it is read; every answer
/// carries `nosniff` and a policy that no other page may frame this one.
pub async fn same_origin(
    who: Arc<Admission>,
    body_limit: usize,
    req: Request,
    next: Next,
) -> Response {
    // The page opened with the right `?token=…` gets it as a cookie, which
    // its every request then carries (the slice worker's too).
    let set_cookie = who.token.as_ref().filter(|t| link_carries(&req, t));
    let cookie =
        set_cookie.map(|t| format!("{TOKEN_COOKIE}={t}; Path=/; HttpOnly; SameSite=Strict"));
    let mut res = match refusal(&who, body_limit, &req) {
        Some(e) => e.into_response(),
        None => match reserve_body(&who, body_limit, &req) {
            // Held until the answer is made: the body and the work on it.
            Ok(_held) => next.run(req).await,
            Err(e) => e.into_response(),
        },
    };
    let headers = res.headers_mut();
    if let Some(c) = cookie.and_then(|c| HeaderValue::from_str(&c).ok()) {
        headers.insert(header::SET_COOKIE, c);
    }
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

/// The memory request bodies may hold at once by default: 512 MiB
/// (docs/MODELER.md, "Memory budget").
pub const BODY_BUDGET: usize = 512 << 20;

/// Who may use the server: the names it answers to, LAN mode, a token,
/// and the bodies' memory budget (in KiB permits).
#[derive(Clone, Debug, Default)]
pub struct Admission {
    /// The budget of body memory, one permit a KiB.
    pub bodies: Option<Arc<Semaphore>>,
    /// That budget, in MiB (for the refusal's words).
    pub budget_mib: usize,
    /// See [`Limits::hosts`].
    pub hosts: Vec<String>,
    /// See [`Limits::lan`].
    pub lan: bool,
    /// See [`Limits::token`].
    pub token: Option<String>,
}

impl Admission {
    /// The admission rules of `limits`.
    pub fn of(limits: &Limits) -> Admission {
        Admission {
            bodies: Some(Arc::new(Semaphore::new(limits.body_budget >> 10))),
            budget_mib: limits.body_budget >> 20,
            hosts: limits.hosts.clone(),
            lan: limits.lan,
            token: limits.token.clone(),
        }
    }
}

/// The cookie that carries the token.
pub const TOKEN_COOKIE: &str = "sweepclay_token";

/// Whether `name` (a Host without its port) is an IP address literal.
fn is_ip(name: &str) -> bool {
    name.parse::<std::net::Ipv4Addr>().is_ok()
        || name
            .strip_prefix('[')
            .and_then(|n| n.strip_suffix(']'))
            .is_some_and(|n| n.parse::<std::net::Ipv6Addr>().is_ok())
}

/// Reserves a POST's body in the memory budget before it is read (its
/// `Content-Length`, or its route's limit when it gives none), or refuses
/// it with 503 and `Retry-After` when the bodies in flight hold the
/// budget already.
fn reserve_body(
    who: &Admission,
    body_limit: usize,
    req: &Request,
) -> Result<Option<tokio::sync::OwnedSemaphorePermit>, ApiError> {
    let Some(bodies) = who.bodies.as_ref().filter(|_| req.method() == Method::POST) else {
        return Ok(None);
    };
    let length = req
        .headers()
        .get(header::CONTENT_LENGTH)
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.parse::<usize>().ok())
        .unwrap_or(body_limit)
        .min(body_limit);
    let kib = u32::try_from(length.div_ceil(1024).max(1)).unwrap_or(u32::MAX);
    bodies.clone().try_acquire_many_owned(kib).map(Some).map_err(|_| {
        ApiError::new(
            503,
            format!(
                "the server is holding as much request data as its memory budget allows ({} MiB); try again in a moment",
                who.budget_mib
            ),
        )
        .retry_after(2)
    })
}

/// Whether `req` opens the page by the printed link: `/?token=` `t`.
fn link_carries(req: &Request, t: &str) -> bool {
    req.uri().path() == "/"
        && req
            .uri()
            .query()
            .is_some_and(|q| q.split('&').any(|kv| kv.strip_prefix("token=") == Some(t)))
}

/// Why `req` is refused, if it is.
fn refusal(who: &Admission, body_limit: usize, req: &Request) -> Option<ApiError> {
    let hosts = &who.hosts;
    let h = req.headers();
    let text = |name| h.get(name).and_then(|v: &HeaderValue| v.to_str().ok());
    // Two Host or Origin headers: which one a proxy or the server reads
    // is anyone's guess, so neither is trusted.
    for (name, what) in [(header::HOST, "Host"), (header::ORIGIN, "Origin")] {
        if h.get_all(name).iter().count() > 1 {
            return Some(ApiError::new(
                400,
                format!("the request carries more than one {what} header; refused"),
            ));
        }
    }
    let host = text(header::HOST).unwrap_or("");
    let Some(name) = host_name(host).or(hosts.is_empty().then_some(host)) else {
        return Some(ApiError::new(
            400,
            format!("Host `{host}` is no host name (letters, digits, dots, hyphens or [an IPv6 address], then a port)"),
        ));
    };
    let known = hosts.iter().any(|a| a.eq_ignore_ascii_case(name)) || (who.lan && is_ip(name));
    if !hosts.is_empty() && !known {
        return Some(ApiError::new(
            421,
            format!(
                "this server answers for {}{} only, not for Host `{host}` (start it with --allow-host {name} to add that name)",
                hosts.join(", "),
                if who.lan { " and its IP addresses" } else { "" }
            ),
        ));
    }
    if let Some(t) = &who.token {
        let path = req.uri().path();
        let carried = h
            .get_all(header::COOKIE)
            .iter()
            .filter_map(|v| v.to_str().ok())
            .flat_map(|v| v.split(';'))
            .any(|kv| {
                kv.trim()
                    .strip_prefix(TOKEN_COOKIE)
                    .and_then(|r| r.strip_prefix('='))
                    == Some(t.as_str())
            })
            || text(HeaderName::from_static("x-sweepclay-token")) == Some(t.as_str())
            || link_carries(req, t);
        if !carried && !path.starts_with("/assets/") {
            return Some(ApiError::new(
                401,
                "this server needs its token: open the link it printed when it started (…/?token=…)",
            ));
        }
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
        assert_eq!(host_name("127.0.0.1:8080"), Some("127.0.0.1"));
        assert_eq!(host_name("localhost"), Some("localhost"));
        assert_eq!(host_name("[::1]:80"), Some("[::1]"));
        assert_eq!(host_name("evil.example:8080"), Some("evil.example"));
        // Not host names: each was read as an allowed one.
        for bad in [
            "[::1]evil.example",
            "localhost:80@evil",
            "localhost:",
            "local host",
            "[::1",
            "",
        ] {
            assert_eq!(host_name(bad), None, "{bad}");
        }
    }
}
