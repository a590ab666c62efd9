//! Rate limits for the bench log ([`crate::bench_log`]): one token bucket per kind of event, so that a flapping
//! input (a chattering contact switch, a bus going error-passive and back every tick) cannot
//! fill the RTT buffer and push out the lines that matter. A kind's bucket holds up to its
//! burst of lines and refills at its rate; a line without a token is counted, and the next
//! line of that kind that goes out says how many were left out before it.

use crate::time::Instant;

/// What a log line is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LogKind {
    /// A reflex phase change (about four per stride and leg).
    ReflexPhase,
    /// A heel strike (own or peer).
    HeelStrike,
    /// The CAN controller's error state changed.
    CanState,
    /// A parameter written or stored.
    Param,
    /// A fault raised or cleared.
    Fault,
    /// The node state changed.
    State,
}

/// Number of kinds.
pub const KINDS: usize = 6;

impl LogKind {
    fn index(self) -> usize {
        match self {
            LogKind::ReflexPhase => 0,
            LogKind::HeelStrike => 1,
            LogKind::CanState => 2,
            LogKind::Param => 3,
            LogKind::Fault => 4,
            LogKind::State => 5,
        }
    }

    /// Lines allowed at once, and the refill rate \[lines/s\]. Walking at 1.25 strides/s
    /// per leg gives about 5 phase changes and 2.5 heel strikes (own and peer) per
    /// second: each rate is twice that, each burst a stride's worth or more. Faults and
    /// states come in bursts (a failing sensor raises several at once).
    pub const fn budget(self) -> (u32, u32) {
        match self {
            LogKind::ReflexPhase => (8, 10),
            LogKind::HeelStrike => (4, 5),
            LogKind::CanState => (4, 1),
            LogKind::Param => (16, 10),
            LogKind::Fault => (8, 10),
            LogKind::State => (8, 5),
        }
    }
}

/// Whether a line may go out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Allowance {
    /// Log it; `suppressed` lines of this kind were left out since the last one logged.
    Log {
        /// Lines left out before this one.
        suppressed: u32,
    },
    /// Leave it out (counted).
    Suppressed,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Bucket {
    /// Tokens \[1/1_000_000 line\] (a line costs 1_000_000); `None` before the first line:
    /// a full bucket.
    micro_tokens: Option<u64>,
    last: Instant,
    suppressed: u32,
}

/// One token bucket per [`LogKind`]. Constant work per call.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LogLimiter {
    buckets: [Bucket; KINDS],
}

const LINE: u64 = 1_000_000;

impl LogLimiter {
    /// May a line of `kind` go out at `now`?
    pub fn allow(&mut self, kind: LogKind, now: Instant) -> Allowance {
        let (burst, per_s) = kind.budget();
        let cap = u64::from(burst).saturating_mul(LINE);
        let Some(b) = self.buckets.get_mut(kind.index()) else {
            return Allowance::Suppressed;
        };
        // Refill: per_s lines per 1e6 µs = per_s micro-tokens per µs.
        let tokens = match b.micro_tokens {
            None => cap,
            Some(t) => t
                .saturating_add(now.micros_since(b.last).saturating_mul(u64::from(per_s)))
                .min(cap),
        };
        b.last = now;
        match tokens.checked_sub(LINE) {
            Some(left) => {
                b.micro_tokens = Some(left);
                Allowance::Log {
                    suppressed: core::mem::take(&mut b.suppressed),
                }
            }
            None => {
                b.micro_tokens = Some(tokens);
                b.suppressed = b.suppressed.saturating_add(1);
                Allowance::Suppressed
            }
        }
    }

    /// Lines of `kind` left out and not yet reported.
    pub fn suppressed(&self, kind: LogKind) -> u32 {
        self.buckets.get(kind.index()).map_or(0, |b| b.suppressed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn logged(a: Allowance) -> bool {
        matches!(a, Allowance::Log { .. })
    }

    #[test]
    fn a_burst_goes_out_then_the_rate_holds() {
        let mut l = LogLimiter::default();
        let t0 = Instant::from_millis(1_000);
        // A contact chattering every millisecond for one second: 1000 phase changes.
        let out = (0..1_000u64)
            .filter(|k| logged(l.allow(LogKind::ReflexPhase, Instant(t0.0 + k * 1_000))))
            .count();
        // Burst 8, then 10 per second: 8 + 9 refills within the 0.999 s.
        assert_eq!(out, 8 + 9);
        // The refills carried the burst's remainder: lines at 100, 200, …, 900 ms; the 99
        // after the last one wait to be reported.
        assert_eq!(l.suppressed(LogKind::ReflexPhase), 99);
    }

    #[test]
    fn the_next_line_says_how_many_were_left_out() {
        let mut l = LogLimiter::default();
        let t = Instant::from_millis(5);
        for _ in 0..4 {
            assert!(logged(l.allow(LogKind::CanState, t)));
        }
        assert_eq!(l.allow(LogKind::CanState, t), Allowance::Suppressed);
        assert_eq!(l.allow(LogKind::CanState, t), Allowance::Suppressed);
        // One line per second refills.
        let later = Instant(t.0 + 1_000_000);
        assert_eq!(
            l.allow(LogKind::CanState, later),
            Allowance::Log { suppressed: 2 }
        );
        assert_eq!(l.suppressed(LogKind::CanState), 0);
    }

    #[test]
    fn kinds_do_not_share_a_bucket() {
        let mut l = LogLimiter::default();
        let t = Instant::from_millis(1);
        for _ in 0..100 {
            let _ = l.allow(LogKind::ReflexPhase, t);
        }
        assert_eq!(l.allow(LogKind::ReflexPhase, t), Allowance::Suppressed);
        assert!(logged(l.allow(LogKind::Param, t)), "a flood of one kind");
    }

    #[test]
    fn a_normal_gait_is_never_limited() {
        // Four phase changes per 0.8 s stride, spread evenly, for a minute.
        let mut l = LogLimiter::default();
        let all = (0..300u64).all(|k| logged(l.allow(LogKind::ReflexPhase, Instant(k * 200_000))));
        assert!(all);
    }
}
