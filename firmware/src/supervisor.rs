//! Decides whether the control loop ran on time, so that the board pets its independent
//! watchdog only then: a loop that stalls, runs late or hangs in a tick stops petting, and the
//! watchdog resets the chip (which starts with the power stage off).

use crate::time::Instant;

/// Watches the start and end of every control tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LoopSupervisor {
    period_us: u64,
    max_late_us: u64,
    max_tick_us: u64,
    last_start: Option<Instant>,
    late_ticks: u32,
    worst_interval_us: u64,
}

impl LoopSupervisor {
    /// A loop of `period_us`, on time while each tick starts at most `max_late_us` after its
    /// period and lasts at most `max_tick_us`.
    pub fn new(period_us: u64, max_late_us: u64, max_tick_us: u64) -> Self {
        LoopSupervisor {
            period_us,
            max_late_us,
            max_tick_us,
            last_start: None,
            late_ticks: 0,
            worst_interval_us: 0,
        }
    }

    /// Report one tick (its start and end); true when the watchdog may be petted.
    pub fn tick(&mut self, started: Instant, finished: Instant) -> bool {
        let interval_ok = match self.last_start {
            Some(prev) => {
                let interval = started.0.saturating_sub(prev.0);
                self.worst_interval_us = self.worst_interval_us.max(interval);
                interval <= self.period_us.saturating_add(self.max_late_us)
            }
            None => true,
        };
        self.last_start = Some(started);
        let duration_ok = finished.0.saturating_sub(started.0) <= self.max_tick_us;
        let on_time = interval_ok && duration_ok && finished.0 >= started.0;
        if !on_time {
            self.late_ticks = self.late_ticks.saturating_add(1);
        }
        on_time
    }

    /// Ticks that were late or too long since start-up.
    pub fn late_ticks(&self) -> u32 {
        self.late_ticks
    }

    /// Longest interval between two tick starts seen \[µs\].
    pub fn worst_interval_us(&self) -> u64 {
        self.worst_interval_us
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pets_only_on_time() {
        let us = Instant::from_micros;
        let mut s = LoopSupervisor::new(1_000, 500, 200);
        assert!(s.tick(us(0), us(50)));
        assert!(s.tick(us(1_000), us(1_100)));
        assert!(s.tick(us(2_400), us(2_500)), "400 µs late is tolerated");
        assert!(!s.tick(us(4_000), us(4_050)), "600 µs late");
        assert!(!s.tick(us(5_000), us(5_300)), "a 300 µs tick is too long");
        assert!(s.tick(us(6_000), us(6_100)), "back on time");
        assert!(
            !s.tick(us(7_000), us(6_900)),
            "a clock going backwards is not on time"
        );
        assert_eq!(s.late_ticks(), 3);
        assert_eq!(s.worst_interval_us(), 1_600);
    }
}
