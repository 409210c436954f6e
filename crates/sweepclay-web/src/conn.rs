//! Connection limits, below HTTP (docs/MODELER.md, "Limits and safety"): at
//! most [`Connections::max`] connections open at once (the next waits in
//! the kernel's backlog until one closes), and a connection on which
//! nothing is read or written for [`Connections::idle`] is closed — a
//! client that stalls while sending its headers or body, or an idle
//! keep-alive connection, no longer holds a place for ever. A request
//! must also be answered (its answer begun) within twice that of its
//! first byte, so a client trickling a byte now and then cannot hold a
//! place either.

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

/// How many connections may be open and how long one may stay silent.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Connections {
    /// Most connections open at once.
    pub max: usize,
    /// Longest a connection may go without a byte read or written; a
    /// request must be answered within twice this of its first byte.
    pub idle: Duration,
}

/// A listener that holds to [`Connections`].
pub struct Capped {
    inner: TcpListener,
    permits: Arc<Semaphore>,
    idle: Duration,
}

impl Capped {
    /// Wraps `inner`.
    pub fn new(inner: TcpListener, c: Connections) -> Capped {
        Capped {
            inner,
            permits: Arc::new(Semaphore::new(c.max.max(1))),
            idle: c.idle,
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
            idle: self.idle,
            timer: Box::pin(sleep(self.idle)),
            request: None,
        };
        (guarded, addr)
    }

    fn local_addr(&self) -> io::Result<std::net::SocketAddr> {
        self.inner.local_addr()
    }
}

/// A connection with its place and its idle timer.
pub struct Guarded {
    io: TcpStream,
    _permit: OwnedSemaphorePermit,
    idle: Duration,
    timer: Pin<Box<Sleep>>,
    /// When the request being read must be answered by: set by its first
    /// byte, cleared when the answer is written.
    request: Option<Instant>,
}

impl Guarded {
    fn touch(&mut self) {
        let mut at = Instant::now() + self.idle;
        if let Some(d) = self.request {
            at = at.min(d);
        }
        self.timer.as_mut().reset(at);
    }

    /// Whether the connection has been silent too long.
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
                    if self.request.is_none() {
                        self.request = Some(Instant::now() + 2 * self.idle);
                    }
                    self.touch();
                }
                Poll::Ready(r)
            }
            // Silent too long: the end of the stream, so HTTP closes it.
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
            // The answer has begun: the next request starts its own clock.
            self.request = None;
            self.touch();
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
