//! The control clock: the period and the time of each tick, which must not run backwards.

use crate::error::{SilError, TickError};

/// The time of one control tick, in the walker's seconds and the bus's nanoseconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct TickTime {
    /// Walk time [s].
    pub t_s: f64,
    /// The same, rounded to the bus's nanoseconds [ns].
    pub t_ns: u64,
    /// The end of the tick's control period [s].
    pub t_end_s: f64,
}

/// The control period and the ticks run so far.
#[derive(Clone, Debug)]
pub(crate) struct TickClock {
    period_us: u64,
    last_t_ns: Option<u64>,
    last_t_s: f64,
    ticks: u64,
}

impl TickClock {
    /// A clock ticking every `period_s`.
    ///
    /// # Errors
    /// [`SilError::Period`] unless the period is a positive whole number of microseconds.
    pub fn new(period_s: f64) -> Result<Self, SilError> {
        let period_us = period_s * 1e6;
        if !(period_us.is_finite() && period_us >= 1.0 && period_us.fract() == 0.0) {
            return Err(SilError::Period { period_s });
        }
        Ok(TickClock {
            period_us: period_us as u64,
            last_t_ns: None,
            last_t_s: 0.0,
            ticks: 0,
        })
    }

    /// The control period [s].
    pub fn period_s(&self) -> f64 {
        self.period_us as f64 * 1e-6
    }

    /// Start the tick at `t_s`.
    ///
    /// # Errors
    /// A time that is not finite and non-negative, or before the previous tick's.
    pub fn start(&mut self, t_s: f64) -> Result<TickTime, TickError> {
        if !(t_s.is_finite() && t_s >= 0.0) {
            return Err(TickError::InvalidTime { t_s });
        }
        let t_ns = (t_s * 1e9).round() as u64;
        if let Some(prev) = self.last_t_ns {
            if t_ns < prev {
                return Err(TickError::BeforePrevious {
                    t_s,
                    previous_s: prev as f64 * 1e-9,
                });
            }
        }
        self.last_t_ns = Some(t_ns);
        self.last_t_s = t_s;
        Ok(TickTime {
            t_s,
            t_ns,
            t_end_s: t_s + self.period_s(),
        })
    }

    /// Count the tick started last as done.
    pub fn finish(&mut self) {
        self.ticks += 1;
    }

    /// Ticks done.
    pub fn ticks(&self) -> u64 {
        self.ticks
    }

    /// The time of the last tick started [s] (0 before the first).
    pub fn last_t_s(&self) -> f64 {
        self.last_t_s
    }
}
