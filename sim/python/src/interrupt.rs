//! Long computations with the GIL released, stopped by Ctrl-C.
//!
//! The work runs on a thread of its own while the calling (Python main) thread, without the
//! GIL, polls for signals every [`POLL`]: on Ctrl-C it cancels the work's
//! [`SearchBudget`] (every later stride fails at once, so a gait search or a walk ends at its
//! next stride), waits for the work to return and raises `KeyboardInterrupt`.
//!
//! [`run_counted`] also reports a study's progress: the work ticks a [`Counter`] (an atomic
//! count, no GIL), and the waiting thread hands the count to a Python callable
//! `progress(done, total)` at each poll (the package passes a tqdm bar's update).

use pyo3::prelude::*;
use sim::stride::SearchBudget;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::Arc;
use std::time::Duration;

/// How often the waiting thread checks for Ctrl-C.
const POLL: Duration = Duration::from_millis(50);

/// A study's units done, of how many, and the Python callable told about them.
pub struct Counter {
    done: AtomicUsize,
    total: usize,
    callback: Option<Py<PyAny>>,
}

impl Counter {
    /// A count of `total` units, reported to `callback(done, total)` (none: not reported).
    pub fn new(total: usize, callback: Option<Py<PyAny>>) -> Self {
        Self {
            done: AtomicUsize::new(0),
            total,
            callback,
        }
    }

    /// One unit done (from any thread, without the GIL).
    pub fn tick(&self) {
        self.done.fetch_add(1, Ordering::Relaxed);
    }

    /// `done` units done (a study that reports a fraction, scaled to `total`).
    pub fn set(&self, done: usize) {
        self.done.store(done.min(self.total), Ordering::Relaxed);
    }

    /// Tells the callable the count (with the GIL).
    fn report(&self, py: Python<'_>) -> PyResult<()> {
        match &self.callback {
            Some(f) => f
                .call1(py, (self.done.load(Ordering::Relaxed), self.total))
                .map(drop),
            None => Ok(()),
        }
    }
}

/// `work()` with the GIL released; `KeyboardInterrupt` (or the signal handler's exception) if
/// a signal arrived meanwhile, after `budgets` were cancelled and the work returned.
pub fn run<T, F>(py: Python<'_>, budgets: &[&Arc<SearchBudget>], work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce() -> T + Send,
{
    run_counted(py, budgets, &Counter::new(0, None), work)
}

/// [`run`], telling `counter`'s callable its count at every poll and once at the end; an
/// exception the callable raises stops the work as Ctrl-C does and is raised.
pub fn run_counted<T, F>(
    py: Python<'_>,
    budgets: &[&Arc<SearchBudget>],
    counter: &Counter,
    work: F,
) -> PyResult<T>
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
                            let polled = Python::attach(|py| {
                                py.check_signals().and_then(|()| counter.report(py))
                            });
                            if let Err(e) = polled {
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
    counter.report(py)?;
    out.map_err(|_| {
        pyo3::exceptions::PyRuntimeError::new_err(
            "the computation panicked (a bug: please report it with the call that caused it)",
        )
    })
}
