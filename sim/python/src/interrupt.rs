//! Long computations with the GIL released, stopped by Ctrl-C.
//!
//! [`run_counted`]: the work runs on a thread of its own while the calling (Python main)
//! thread, without the GIL, polls for signals every [`POLL`]: on Ctrl-C it cancels the work's
//! [`SearchBudget`] (every later stride fails at once, so a gait search or a walk ends at its
//! next stride), waits for the work to return and raises `KeyboardInterrupt`. [`run`] runs the
//! work on the calling thread instead where a watcher of Python's signal wake-up fd can stand
//! in for the poll (no Python handler but SIGINT's default), else as [`run_counted`].
//!
//! [`run_counted`] also reports a study's progress: the work ticks a [`Counter`] (an atomic
//! count, no GIL), and the waiting thread hands the count to a Python callable
//! `progress(done, total)` at each poll (the package passes a tqdm bar's update).

use pyo3::prelude::*;
#[cfg(unix)]
use pyo3::types::PyDict;
use sim::stride::SearchBudget;
#[cfg(unix)]
use std::io::Read;
#[cfg(unix)]
use std::net::Shutdown;
#[cfg(unix)]
use std::os::fd::AsRawFd;
#[cfg(unix)]
use std::os::unix::net::UnixStream;
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
///
/// Where it can, the work runs on the calling thread itself and a watcher thread learns of
/// Ctrl-C through Python's signal wake-up fd ([`CtrlCWatch`]): no hand-over between threads, which
/// on a loaded machine cost milliseconds per call (a hundred compass gaits took 4 to 6 times
/// the Rust library's time, against 1.6 to 1.8 inline). Where it cannot (not the main thread,
/// or the wake-up fd is someone else's, e.g. asyncio's in a notebook), the work runs on a
/// thread of its own while this one polls ([`run_counted`]).
pub fn run<T, F>(py: Python<'_>, budgets: &[&Arc<SearchBudget>], work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce() -> T + Send,
{
    let Some(watch) = CtrlCWatch::start(py, budgets) else {
        return run_counted(py, budgets, &Counter::new(0, None), work);
    };
    // A signal that arrived before the wake-up fd was ours wrote nothing to it.
    if let Err(e) = py.check_signals() {
        watch.stop(py)?;
        return Err(e);
    }
    let out = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| py.detach(work)));
    watch.stop(py)?;
    out.map_err(|_| panicked())
}

/// The error of a computation that panicked.
fn panicked() -> PyErr {
    pyo3::exceptions::PyRuntimeError::new_err(
        "the computation panicked (a bug: please report it with the call that caused it)",
    )
}

/// Signals whose Python handlers commonly raise (timeouts, termination, user signals): with one
/// of them handled, the poll stands in for the watcher. Others (SIGCHLD, SIGWINCH, ...) are
/// handled when the call returns. Checking every valid signal cost ~100 µs a call.
#[cfg(unix)]
const RAISING_SIGNALS: [&str; 8] = [
    "SIGALRM",
    "SIGVTALRM",
    "SIGPROF",
    "SIGTERM",
    "SIGHUP",
    "SIGQUIT",
    "SIGUSR1",
    "SIGUSR2",
];

/// Whether this is the main thread, SIGINT's handler is Python's default
/// (`signal.default_int_handler`, which raises `KeyboardInterrupt`) and none of
/// [`RAISING_SIGNALS`] has a Python handler.
#[cfg(unix)]
fn only_default_ctrl_c(py: Python<'_>, signal: &Bound<'_, PyModule>) -> PyResult<bool> {
    let threading = py.import("threading")?;
    if !threading
        .call_method0("current_thread")?
        .is(&threading.call_method0("main_thread")?)
    {
        return Ok(false);
    }
    let sigint = signal.call_method1("getsignal", (signal.getattr("SIGINT")?,))?;
    if !sigint.is(&signal.getattr("default_int_handler")?) {
        return Ok(false);
    }
    for name in RAISING_SIGNALS {
        let Ok(number) = signal.getattr(name) else {
            continue;
        };
        if signal.call_method1("getsignal", (number,))?.is_callable() {
            return Ok(false);
        }
    }
    Ok(true)
}

/// The signal number of SIGINT (Ctrl-C) on the platforms CPython's wake-up fd serves.
#[cfg(unix)]
const SIGINT: u8 = 2;

/// A watcher of Ctrl-C while the calling thread works: Python's signal handler writes each
/// signal's number to the wake-up fd (`signal.set_wakeup_fd`), here one end of a socket pair
/// whose other end a thread reads; on SIGINT it cancels the budgets. Python's own handler has
/// tripped meanwhile, so `check_signals` raises `KeyboardInterrupt` once the work returns.
#[cfg(unix)]
struct CtrlCWatch {
    /// The `signal` module.
    signal: Py<PyAny>,
    /// The end the watcher reads (shut down to end it).
    reader: UnixStream,
    /// The end Python writes to (kept open while it is the wake-up fd).
    _writer: UnixStream,
}

#[cfg(unix)]
impl CtrlCWatch {
    /// Starts watching; `None` when this thread is not the main thread, when a signal has a
    /// Python handler other than SIGINT's default (whose effect the watcher cannot know: a
    /// handler that does not raise must not stop the work, one that raises must stop it at
    /// once, as the poll does), or when the wake-up fd is already set by someone else (theirs
    /// is put back).
    fn start(py: Python<'_>, budgets: &[&Arc<SearchBudget>]) -> Option<Self> {
        let signal = py.import("signal").ok()?;
        if !only_default_ctrl_c(py, &signal).unwrap_or(false) {
            return None;
        }
        let (reader, writer) = UnixStream::pair().ok()?;
        writer.set_nonblocking(true).ok()?;
        let watched = reader.try_clone().ok()?;
        let budgets: Vec<Arc<SearchBudget>> = budgets.iter().map(|b| Arc::clone(b)).collect();
        std::thread::Builder::new()
            .name("walker-ctrl-c".into())
            .spawn(move || {
                let mut signals = [0u8; 64];
                // Ends when the reader is shut down (read gives 0) or fails.
                while let Ok(n @ 1..) = (&watched).read(&mut signals) {
                    if signals[..n].contains(&SIGINT) {
                        budgets.iter().for_each(|b| b.cancel());
                    }
                }
            })
            .ok()?;
        let stop_watcher = || {
            let _ = reader.shutdown(Shutdown::Both);
        };
        let kwargs = PyDict::new(py);
        if kwargs.set_item("warn_on_full_buffer", false).is_err() {
            stop_watcher();
            return None;
        }
        let old = signal
            .call_method("set_wakeup_fd", (writer.as_raw_fd(),), Some(&kwargs))
            .and_then(|o| o.extract::<i64>());
        match old {
            Ok(-1) => Some(Self {
                signal: signal.into_any().unbind(),
                reader,
                _writer: writer,
            }),
            Ok(theirs) => {
                let _ = signal.call_method1("set_wakeup_fd", (theirs,));
                stop_watcher();
                None
            }
            Err(_) => {
                stop_watcher();
                None
            }
        }
    }

    /// Puts the wake-up fd back, ends the watcher (without waiting for it) and raises what a
    /// signal that arrived meanwhile raises (`KeyboardInterrupt` for Ctrl-C).
    fn stop(self, py: Python<'_>) -> PyResult<()> {
        let restored = self.signal.call_method1(py, "set_wakeup_fd", (-1,));
        let _ = self.reader.shutdown(Shutdown::Both);
        restored?;
        py.check_signals()
    }
}

/// Elsewhere the work always runs on a thread of its own ([`run_counted`]).
#[cfg(not(unix))]
struct CtrlCWatch;

#[cfg(not(unix))]
impl CtrlCWatch {
    fn start(_: Python<'_>, _: &[&Arc<SearchBudget>]) -> Option<Self> {
        None
    }

    fn stop(self, _: Python<'_>) -> PyResult<()> {
        Ok(())
    }
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
    out.map_err(|_| panicked())
}
