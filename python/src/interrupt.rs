//! Long work that Ctrl-C interrupts. The work runs on a thread of its own while the calling
//! thread, without the GIL, waits for it and runs Python's signal handlers every
//! [`SIGNAL_POLL`]; a `KeyboardInterrupt` raised by them raises the work's [`Cancel`] flag.
//!
//! Two ways to end, by what the work can do:
//! - [`until_stopped`]: the work polls the flag (an ensemble between blocks, the Allan analysis
//!   between stretches) and borrows the caller's data (numpy arrays read in place): the call
//!   waits for it to stop, a fraction of a second, then raises `KeyboardInterrupt`.
//! - [`leaving_behind`]: the work owns its data and may not poll the flag everywhere (the
//!   one-axis likelihood search of `estimate_noise`, the three-axis filter): the call raises
//!   `KeyboardInterrupt` at once and the work ends in the background, its result dropped. Until
//!   then it keeps its threads busy; the interpreter is usable meanwhile.

use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::time::Duration;

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

use accelcal::progress::Cancel;

/// How often a waiting call runs the signal handlers.
pub(crate) const SIGNAL_POLL: Duration = Duration::from_millis(100);

/// Waits for the result on `rx`, running the signal handlers every [`SIGNAL_POLL`]. `Ok(Ok)`:
/// the result; `Ok(Err)`: a handler raised (the flag is raised too); `Err`: the work's thread
/// ended without sending (it panicked).
fn wait<T: Send>(py: Python<'_>, rx: Receiver<T>, cancel: &Cancel) -> PyResult<Result<T, PyErr>> {
    let mut rx = rx;
    loop {
        // The receiver is moved in and out: it is Send, not Sync.
        let (received, back) = py.detach(move || (rx.recv_timeout(SIGNAL_POLL), rx));
        rx = back;
        match received {
            Ok(result) => return Ok(Ok(result)),
            Err(RecvTimeoutError::Timeout) => {
                if let Err(raised) = py.check_signals() {
                    cancel.cancel();
                    return Ok(Err(raised));
                }
            }
            Err(RecvTimeoutError::Disconnected) => {
                return Err(PyRuntimeError::new_err(
                    "the work's thread ended without a result (a defect: please report it)",
                ));
            }
        }
    }
}

/// Runs `work` (which polls the flag it is given) on a scoped thread; on Ctrl-C raises the flag,
/// waits for the work to stop, and raises `KeyboardInterrupt` (or whatever the signal handler
/// raised).
pub(crate) fn until_stopped<T: Send>(
    py: Python<'_>,
    work: impl FnOnce(&Cancel) -> T + Send,
) -> PyResult<T> {
    let cancel = Cancel::new();
    std::thread::scope(|scope| {
        let (tx, rx) = mpsc::channel();
        let flag = cancel.clone();
        let worker = scope.spawn(move || {
            let _ = tx.send(work(&flag));
        });
        let outcome = wait(py, rx, &cancel);
        // The scope joins the worker: a raised flag stops it within one piece of work.
        py.detach(|| {
            let _ = worker.join();
        });
        match outcome {
            Ok(Ok(result)) => Ok(result),
            Ok(Err(raised)) => Err(raised),
            Err(defect) => Err(defect),
        }
    })
}

/// Runs `work` on a thread of its own; on Ctrl-C raises the flag and raises `KeyboardInterrupt`
/// at once, leaving the work to end in the background (its result is dropped).
pub(crate) fn leaving_behind<T: Send + 'static>(
    py: Python<'_>,
    work: impl FnOnce(&Cancel) -> T + Send + 'static,
) -> PyResult<T> {
    let cancel = Cancel::new();
    let (tx, rx) = mpsc::channel();
    let flag = cancel.clone();
    std::thread::spawn(move || {
        // The receiver is gone when the call was interrupted: nothing waits for the result.
        let _ = tx.send(work(&flag));
    });
    wait(py, rx, &cancel)?
}
