//! Connection limits, below HTTP (docs/MODELER.md, "Limits and safety"): at
//! most [`Connections::max`] connections open at once (the next waits in
//! the kernel's backlog until one closes), and a client must send at the
//! pace of a client, not of an attacker:
//!
//! - a request's headers must all arrive within [`Connections::read`] of
//!   its first byte, and a new or kept-alive connection must start a
//!   request within that time too, so an idle or silent connection gives
//!   its place back in seconds;
//! - its body may fall silent for at most that long, and must arrive at
//!   [`MIN_BODY_RATE`] or faster on the whole, so a client trickling a
//!   byte now and then cannot hold a place either;
//! - once the request is read, its answer must begin within
//!   [`Connections::answer`] (the handlers' own timeout bounds the work;
//!   this is the backstop).
//!
//! The headers are read here only to find where they end and how long the
//! body is (`Content-Length`); HTTP itself is hyper's.

use std::future::Future;
use std::io;
use std::pin::Pin;
use std::sync::Arc;
use std::task::{Context, Poll};
use std::time::Duration;
use tokio::io::{AsyncRead, AsyncWrite, ReadBuf};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::{OwnedSemaphorePermit, Semaphore};
use tokio::time::{sleep, Instant, Sleep};

/// How many connections may be open and how long a client may take.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Connections {
    /// Most connections open at once.
    pub max: usize,
    /// Longest a client may take to start a request, to send its headers,
    /// or to fall silent in its body.
    pub read: Duration,
    /// Longest a request, once read, may wait for its answer to begin.
    pub answer: Duration,
}

/// The slowest a request body may arrive on the whole (bytes a second),
/// after a first [`Connections::read`] of grace: 64 KiB/s, a 100 MB mesh in
/// 26 minutes, far below any studio's network.
pub const MIN_BODY_RATE: u64 = 64 * 1024;

/// How many [`Connections::read`] a kept-alive connection may wait for
/// its next request, or a client stall while an answer is sent to it.
pub const KEEP_ALIVE: u32 = 3;

/// The most header bytes read for the body's length: beyond it, hyper
/// refuses the request anyway.
const MAX_HEAD: usize = 64 * 1024;

/// A listener that holds to [`Connections`].
pub struct Capped {
    inner: TcpListener,
    permits: Arc<Semaphore>,
    limits: Connections,
}

impl Capped {
    /// Wraps `inner`.
    pub fn new(inner: TcpListener, c: Connections) -> Capped {
        Capped {
            inner,
            permits: Arc::new(Semaphore::new(c.max.max(1))),
            limits: c,
        }
    }
}

impl axum::serve::Listener for Capped {
    type Io = Guarded;
    type Addr = std::net::SocketAddr;

    async fn accept(&mut self) -> (Guarded, std::net::SocketAddr) {
        // Wait for a place before taking the next connection off the
        // backlog; the permit goes with the connection.
        let permit = self
            .permits
            .clone()
            .acquire_owned()
            .await
            .expect("the semaphore is never closed");
        let (io, addr) = axum::serve::Listener::accept(&mut self.inner).await;
        let guarded = Guarded {
            io,
            _permit: permit,
            limits: self.limits,
            timer: Box::pin(sleep(self.limits.read)),
            phase: Phase::Waiting { fresh: true },
            head: Vec::new(),
        };
        (guarded, addr)
    }

    fn local_addr(&self) -> io::Result<std::net::SocketAddr> {
        self.inner.local_addr()
    }
}

/// Where a connection is in its request.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Phase {
    /// No request begun: a new connection (`fresh`), which must start one
    /// within [`Connections::read`], or one whose answer has begun, kept
    /// alive for [`KEEP_ALIVE`] reads of it (an answer still being sent
    /// resets it at each write).
    Waiting { fresh: bool },
    /// Reading headers, which must be complete by the deadline.
    Head { deadline: Instant },
    /// Reading a body of `left` more bytes, all in by the deadline.
    Body { left: u64, deadline: Instant },
    /// Read; the answer must begin by the deadline.
    Answering { deadline: Instant },
}

/// A connection with its place and its timer.
pub struct Guarded {
    io: TcpStream,
    _permit: OwnedSemaphorePermit,
    limits: Connections,
    timer: Pin<Box<Sleep>>,
    phase: Phase,
    /// The headers read so far (up to [`MAX_HEAD`] bytes).
    head: Vec<u8>,
}

/// The end of a request's headers in `head`, if it holds it.
fn head_end(head: &[u8]) -> Option<usize> {
    head.windows(4)
        .position(|w| w == b"\r\n\r\n")
        .map(|i| i + 4)
}

/// The body's length the headers announce: `Content-Length`, 0 without
/// one; `None` for a chunked body, whose length is not said.
fn body_length(head: &[u8]) -> Option<u64> {
    let text = String::from_utf8_lossy(head);
    let mut length = 0;
    for line in text.split("\r\n").skip(1) {
        let Some((name, value)) = line.split_once(':') else {
            continue;
        };
        let (name, value) = (name.trim(), value.trim());
        if name.eq_ignore_ascii_case("transfer-encoding") {
            return None;
        }
        if name.eq_ignore_ascii_case("content-length") {
            length = value.parse().unwrap_or(0);
        }
    }
    Some(length)
}

impl Guarded {
    /// When the connection is closed unless a byte comes first.
    fn due(&self) -> Instant {
        let now = Instant::now();
        match self.phase {
            Phase::Waiting { fresh: true } => now + self.limits.read,
            Phase::Waiting { fresh: false } => now + KEEP_ALIVE * self.limits.read,
            Phase::Head { deadline } => deadline,
            Phase::Body { deadline, .. } => deadline.min(now + self.limits.read),
            Phase::Answering { deadline } => deadline,
        }
    }

    /// The phase after reading `bytes`.
    fn read_bytes(&mut self, bytes: &[u8]) {
        let now = Instant::now();
        let mut rest = bytes;
        while !rest.is_empty() {
            match self.phase {
                Phase::Waiting { .. } => {
                    self.head.clear();
                    self.phase = Phase::Head {
                        deadline: now + self.limits.read,
                    };
                }
                Phase::Head { .. } => {
                    // Keep a few bytes of overlap to find a `\r\n\r\n` cut
                    // between two reads.
                    let start = self.head.len();
                    let room = MAX_HEAD.saturating_sub(start);
                    self.head.extend_from_slice(&rest[..rest.len().min(room)]);
                    let Some(end) = head_end(&self.head) else {
                        return;
                    };
                    // Bytes of this read after the headers belong to the body.
                    let used = end.saturating_sub(start);
                    rest = &rest[used.min(rest.len())..];
                    self.phase = match body_length(&self.head[..end]) {
                        Some(0) => Phase::Answering {
                            deadline: now + self.limits.answer,
                        },
                        Some(n) => Phase::Body {
                            left: n,
                            deadline: now
                                + self.limits.read
                                + Duration::from_secs_f64(n as f64 / MIN_BODY_RATE as f64),
                        },
                        // A chunked body: silence is its only limit, up
                        // to the largest body's time.
                        None => Phase::Body {
                            left: u64::MAX,
                            deadline: now + self.limits.read + self.limits.answer,
                        },
                    };
                }
                Phase::Body { left, deadline } => {
                    let n = (rest.len() as u64).min(left);
                    rest = &rest[n as usize..];
                    self.phase = if left - n == 0 {
                        Phase::Answering {
                            deadline: now + self.limits.answer,
                        }
                    } else {
                        Phase::Body {
                            left: left - n,
                            deadline,
                        }
                    };
                }
                // A pipelined next request: judged once this answer begins.
                Phase::Answering { .. } => return,
            }
        }
    }

    fn arm(&mut self) {
        let at = self.due();
        self.timer.as_mut().reset(at);
    }

    /// Whether the connection has taken too long.
    fn expired(&mut self, cx: &mut Context<'_>) -> bool {
        self.timer.as_mut().poll(cx).is_ready()
    }
}

impl AsyncRead for Guarded {
    fn poll_read(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        buf: &mut ReadBuf<'_>,
    ) -> Poll<io::Result<()>> {
        let before = buf.filled().len();
        match Pin::new(&mut self.io).poll_read(cx, buf) {
            Poll::Ready(r) => {
                if buf.filled().len() > before {
                    self.read_bytes(&buf.filled()[before..]);
                    self.arm();
                }
                Poll::Ready(r)
            }
            // Too long: the end of the stream, so HTTP closes it.
            Poll::Pending if self.expired(cx) => Poll::Ready(Ok(())),
            Poll::Pending => Poll::Pending,
        }
    }
}

impl AsyncWrite for Guarded {
    fn poll_write(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        data: &[u8],
    ) -> Poll<io::Result<usize>> {
        let r = Pin::new(&mut self.io).poll_write(cx, data);
        if matches!(r, Poll::Ready(Ok(n)) if n > 0) {
            // The answer has begun (or goes on): the next request starts
            // its own clock, and a long answer is no silence.
            if matches!(self.phase, Phase::Answering { .. }) {
                self.phase = Phase::Waiting { fresh: false };
            }
            self.arm();
        }
        r
    }

    fn poll_flush(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.io).poll_flush(cx)
    }

    fn poll_shutdown(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.io).poll_shutdown(cx)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headers_end_and_say_the_bodys_length() {
        let h = b"POST /api/slice HTTP/1.1\r\nHost: x\r\ncontent-length: 42\r\n\r\nbody";
        let end = head_end(h).unwrap();
        assert_eq!(&h[end..], b"body");
        assert_eq!(body_length(&h[..end]), Some(42));
        assert_eq!(body_length(b"GET / HTTP/1.1\r\nHost: x\r\n\r\n"), Some(0));
        assert_eq!(
            body_length(b"POST / HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\n"),
            None
        );
        assert_eq!(head_end(b"GET / HTTP/1.1\r\nHost: x\r\n"), None);
    }
}
