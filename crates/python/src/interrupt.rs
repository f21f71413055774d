//! Long jobs (renders, benches, convergence studies) run on a thread of their own while the
//! calling thread, holding the GIL only between short waits, polls Python's signal handlers:
//! Ctrl-C raises `KeyboardInterrupt` within a tenth of a second however long the job is.
//!
//! An interrupted job is told through [`Cancel`]: renders stop at the next pass
//! (`render_until`), benches and studies at the next render.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, RecvTimeoutError};
use std::sync::Arc;
use std::time::Duration;

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

/// How often the calling thread wakes to run Python's signal handlers.
const POLL: Duration = Duration::from_millis(50);

/// Set when the caller gave up on the job: renders stop at the next pass, jobs made of
/// several renders at the next one.
#[derive(Clone, Default)]
pub struct Cancel(Arc<AtomicBool>);

impl Cancel {
    pub fn is_set(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
    /// The flag itself, for the render loop's `cancel`.
    pub fn flag(&self) -> &AtomicBool {
        &self.0
    }
    fn set(&self) {
        self.0.store(true, Ordering::Relaxed);
    }
}

/// Runs `job` on a new thread with the GIL released and returns its result, or the
/// exception a signal handler raised (`KeyboardInterrupt` for Ctrl-C) as soon as it does.
pub fn run<T: Send + 'static>(py: Python<'_>, job: impl FnOnce(Cancel) -> T + Send + 'static) -> PyResult<T> {
    let (tx, rx) = channel();
    let cancel = Cancel::default();
    let c = cancel.clone();
    std::thread::Builder::new()
        .name("raylab-job".into())
        .spawn(move || {
            // The receiver is gone when the caller was interrupted: nothing to do then.
            let _ = tx.send(job(c));
        })
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start a worker thread: {e}")))?;
    let mut rx = rx;
    loop {
        // The receiver moves into the GIL-free closure and back out (it is Send, not Sync).
        let (got, back) = py.detach(move || (rx.recv_timeout(POLL), rx));
        rx = back;
        match got {
            Ok(v) => return Ok(v),
            Err(RecvTimeoutError::Timeout) => {
                if let Err(e) = py.check_signals() {
                    cancel.set();
                    return Err(e);
                }
            }
            Err(RecvTimeoutError::Disconnected) => return Err(PyRuntimeError::new_err("raylab's worker thread panicked (see the message above)")),
        }
    }
}
