//! A flag that asks long work to stop: checked between the pipeline's
//! stages and every 64 KiB of G-code written or read, so a client that
//! leaves (the modeler) or a signal (the CLI) ends the work within a
//! stage (docs/MODELER.md, "Limits and safety").

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// A shared stop flag: clones see the same flag.
#[derive(Clone, Debug, Default)]
pub struct Cancel(Arc<AtomicBool>);

impl Cancel {
    /// A flag not yet set.
    pub fn new() -> Cancel {
        Cancel::default()
    }

    /// Whether the work should stop.
    pub fn is_set(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }

    /// Asks the work to stop.
    pub fn set(&self) {
        self.0.store(true, Ordering::Relaxed);
    }
}

/// A writer that fails once its [`Cancel`] is set, so a long emission or
/// check stops between chunks.
pub struct CancelWriter<W>(pub W, pub Cancel);

impl<W: std::io::Write> std::io::Write for CancelWriter<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if self.1.is_set() {
            return Err(std::io::Error::other("cancelled"));
        }
        self.0.write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.0.flush()
    }
}

/// A reader that fails once its [`Cancel`] is set.
pub struct CancelReader<R>(pub R, pub Cancel);

impl<R: std::io::Read> std::io::Read for CancelReader<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if self.1.is_set() {
            return Err(std::io::Error::other("cancelled"));
        }
        self.0.read(buf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    #[test]
    fn a_writer_stops_once_its_flag_is_set() {
        let c = Cancel::new();
        let mut w = CancelWriter(Vec::new(), c.clone());
        w.write_all(b"G1 X1\n").unwrap();
        c.set();
        assert!(w.write_all(b"G1 X2\n").is_err());
        assert_eq!(w.0, b"G1 X1\n");
    }
}
