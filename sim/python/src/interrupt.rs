//! Long computations with the GIL released, stopped by Ctrl-C.
//!
//! The work runs on a thread of its own while the calling (Python main) thread, without the
//! GIL, polls for signals every [`POLL`]: on Ctrl-C it cancels the work's
//! [`SearchBudget`] (every later stride fails at once, so a gait search or a walk ends at its
//! next stride), waits for the work to return and raises `KeyboardInterrupt`.

use pyo3::prelude::*;
use sim::stride::SearchBudget;
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::Arc;
use std::time::Duration;

/// How often the waiting thread checks for Ctrl-C.
const POLL: Duration = Duration::from_millis(50);

/// `work()` with the GIL released; `KeyboardInterrupt` (or the signal handler's exception) if
/// a signal arrived meanwhile, after `budgets` were cancelled and the work returned.
pub fn run<T, F>(py: Python<'_>, budgets: &[&Arc<SearchBudget>], work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce() -> T + Send,
{
    let (out, signal) = py.detach(|| {
        std::thread::scope(|s| {
            // The work's end wakes the waiting thread at once (a poll alone would add up to
            // POLL to every call).
            let (done_tx, done_rx) = mpsc::channel::<()>();
            let handle = s.spawn(move || {
                let out = work();
                let _ = done_tx.send(());
                out
            });
            let mut signal: Option<PyErr> = None;
            loop {
                match done_rx.recv_timeout(POLL) {
                    // Done, or the work's thread ended without sending (it panicked).
                    Ok(()) | Err(RecvTimeoutError::Disconnected) => break,
                    Err(RecvTimeoutError::Timeout) => {
                        if signal.is_none() {
                            if let Err(e) = Python::attach(|py| py.check_signals()) {
                                budgets.iter().for_each(|b| b.cancel());
                                signal = Some(e);
                            }
                        }
                    }
                }
            }
            (handle.join(), signal)
        })
    });
    if let Some(e) = signal {
        return Err(e);
    }
    out.map_err(|_| {
        pyo3::exceptions::PyRuntimeError::new_err(
            "the computation panicked (a bug: please report it with the call that caused it)",
        )
    })
}
