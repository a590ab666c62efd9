//! Monotonic time in microseconds.

/// A point in time since the node started \[µs\]. 64 bits: no wrap in the robot's lifetime.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Instant(pub u64);

impl Instant {
    /// From microseconds.
    pub const fn from_micros(us: u64) -> Self {
        Instant(us)
    }
    /// From milliseconds.
    pub const fn from_millis(ms: u64) -> Self {
        Instant(ms.saturating_mul(1000))
    }
    /// Microseconds since start.
    pub const fn as_micros(self) -> u64 {
        self.0
    }
    /// Time since `earlier` \[µs\], 0 if `earlier` is later.
    pub const fn micros_since(self, earlier: Instant) -> u64 {
        self.0.saturating_sub(earlier.0)
    }
    /// Time since `earlier` \[s\].
    pub fn secs_since(self, earlier: Instant) -> f32 {
        self.micros_since(earlier) as f32 * 1.0e-6
    }
    /// Uptime in wrapping milliseconds, as sent on the bus: modulo 2³² ms (49.7 days), the
    /// wire's free-running clock (the heartbeat and fault `uptime` signals say it wraps).
    pub const fn uptime_ms(self) -> u32 {
        // Wrapping on purpose: the low 32 bits are the clock modulo 2³².
        ((self.0 / 1000) & 0xFFFF_FFFF) as u32
    }
    /// Uptime in wrapping microseconds, as sent on the bus: modulo 2³² µs (71.6 min), the
    /// heel strike's `time` signal (documented to wrap after 4295 s).
    pub const fn uptime_us(self) -> u32 {
        // Wrapping on purpose: the low 32 bits are the clock modulo 2³².
        (self.0 & 0xFFFF_FFFF) as u32
    }
}

/// A monotonic clock.
pub trait Monotonic {
    /// The current time; never decreases.
    fn now(&mut self) -> Instant;
}

impl<T: Monotonic + ?Sized> Monotonic for &mut T {
    fn now(&mut self) -> Instant {
        T::now(self)
    }
}
