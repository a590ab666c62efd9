//! The node's monotonic clock: the simulated tick time, set by the orchestrator.

use std::cell::Cell;
use std::rc::Rc;

use firmware::time::Monotonic;
use firmware::Instant;

/// The clock; clones share the time (the orchestrator keeps one to set it).
#[derive(Clone, Debug, Default)]
pub struct SimClock(Rc<Cell<Instant>>);

impl SimClock {
    /// A clock at 0.
    pub fn new() -> Self {
        Self::default()
    }

    /// Set the time (the orchestrator never sets it backwards).
    pub fn set(&self, t: Instant) {
        self.0.set(t);
    }
}

impl Monotonic for SimClock {
    fn now(&mut self) -> Instant {
        self.0.get()
    }
}
