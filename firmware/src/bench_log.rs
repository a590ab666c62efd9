//! The node's bench log: what it is doing, as defmt lines on the bench (fault raised and
//! cleared, node state, reflex phase with the string engaged or released, heel strikes,
//! parameter writes and saves, the CAN controller's error state). Two limits keep it from costing the control loop or
//! flooding the RTT buffer:
//!
//! * each kind has a token bucket ([`crate::log_limit`]): a flapping input's events are
//!   counted, not queued;
//! * events wait in a queue of [`QUEUE_LEN`] and at most one line is written per tick, by the
//!   node in a tick that transmits nothing (or when the queue is full)
//!   ([`BenchLog::flush_one`]), so a tick pays for one line at most (measured under QEMU);
//!   an event keeps the time and angle of its own tick. A full queue counts what it drops.
//!
//! Without the `defmt` feature (the simulator, the host tools) [`BenchLog::record`] and
//! [`BenchLog::flush_one`] do nothing: the log costs nothing where nobody reads it. (The unit
//! tests below build the queue without the feature.)

use heapless::Deque;
use protocol::{FaultCode, NodeState, ParamId, ParamStatus, ReflexPhase};

use crate::drivers::can::BusState;
#[cfg(any(feature = "defmt", test))]
use crate::log_limit::Allowance;
use crate::log_limit::{LogKind, LogLimiter};
use crate::time::Instant;

/// Events held for the log at most.
pub const QUEUE_LEN: usize = 8;

/// What the string did with a reflex phase change.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StringEdge {
    /// Nothing.
    Unchanged,
    /// Engaged: the actuator took the string at this setpoint \[rad\].
    Engaged(f32),
    /// Released; the last setpoint held \[rad\].
    Released(f32),
}

/// One thing worth a line on the bench.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BenchEvent {
    /// A fault raised, with its detail.
    FaultRaised(FaultCode, i16),
    /// A fault cleared.
    FaultCleared(FaultCode),
    /// The node state changed.
    State {
        /// Before.
        from: NodeState,
        /// After.
        to: NodeState,
    },
    /// The reflex phase changed.
    Phase {
        /// Before.
        from: ReflexPhase,
        /// After.
        to: ReflexPhase,
        /// The node's uptime \[ms\].
        at_ms: u32,
        /// Estimated ankle angle \[rad\] (NaN before a good reading).
        angle_rad: f32,
        /// The string engaged or released with it.
        string: StringEdge,
    },
    /// A heel strike: the own (with the step count) or the peer's.
    HeelStrike {
        /// The own foot (else the peer's message).
        own: bool,
        /// The own step count.
        step: u16,
        /// The node's uptime \[ms\].
        at_ms: u32,
    },
    /// A SetParam answered.
    ParamWrite {
        /// The parameter.
        param: ParamId,
        /// The value asked for \[1e-6 SI\].
        value: i32,
        /// The answer.
        status: ParamStatus,
    },
    /// A SaveParams finished.
    Saved(bool),
    /// The CAN controller's error state changed (from the runner).
    CanState {
        /// Before.
        from: BusState,
        /// After.
        to: BusState,
        /// Transmit error counter.
        tec: u8,
        /// Receive error counter.
        rec: u8,
    },
}

impl BenchEvent {
    /// The rate-limit bucket of the event.
    pub fn kind(&self) -> LogKind {
        match self {
            BenchEvent::FaultRaised(..) | BenchEvent::FaultCleared(_) => LogKind::Fault,
            BenchEvent::State { .. } => LogKind::State,
            BenchEvent::Phase { .. } => LogKind::ReflexPhase,
            BenchEvent::HeelStrike { .. } => LogKind::HeelStrike,
            BenchEvent::ParamWrite { .. } | BenchEvent::Saved(_) => LogKind::Param,
            BenchEvent::CanState { .. } => LogKind::CanState,
        }
    }
}

/// The queue and its limits.
#[derive(Clone, Debug, Default)]
pub struct BenchLog {
    #[cfg_attr(not(any(feature = "defmt", test)), allow(dead_code))]
    limiter: LogLimiter,
    queue: Deque<(BenchEvent, u32), QUEUE_LEN>,
    dropped: u32,
}

impl BenchLog {
    /// Record an event of `now` (queued when its kind has a token and the queue has room).
    #[cfg(not(any(feature = "defmt", test)))]
    #[inline(always)]
    pub fn record(&mut self, _now: Instant, _event: BenchEvent) {}

    /// Record an event of `now` (queued when its kind has a token and the queue has room).
    #[cfg(any(feature = "defmt", test))]
    pub fn record(&mut self, now: Instant, event: BenchEvent) {
        let Allowance::Log { suppressed } = self.limiter.allow(event.kind(), now) else {
            return;
        };
        if self.queue.push_back((event, suppressed)).is_err() {
            self.dropped = self.dropped.saturating_add(1);
        }
    }

    /// Write the oldest event as a line (with the `defmt` feature); true when one was taken.
    pub fn flush_one(&mut self) -> bool {
        let Some((event, suppressed)) = self.queue.pop_front() else {
            return false;
        };
        let dropped = core::mem::take(&mut self.dropped);
        write_line(&event, suppressed, dropped);
        true
    }

    /// Events waiting.
    pub fn pending(&self) -> usize {
        self.queue.len()
    }

    /// Events dropped on a full queue and not yet reported.
    pub fn dropped(&self) -> u32 {
        self.dropped
    }
}

#[cfg(feature = "defmt")]
fn write_line(event: &BenchEvent, suppressed: u32, dropped: u32) {
    match *event {
        BenchEvent::FaultRaised(code, detail) => defmt::warn!(
            "fault raised: code {=u8} (detail {=i16})",
            code.raw(),
            detail
        ),
        BenchEvent::FaultCleared(code) => defmt::info!("fault cleared: code {=u8}", code.raw()),
        BenchEvent::State { from, to } => defmt::info!(
            "node state {=u8} -> {=u8} (0 Disabled, 1 Enabled, 2 Safe, 3 EmergencyStop)",
            from.raw(),
            to.raw()
        ),
        // Phases as their wire numbers (0 Inactive, 1 Swing, 2 Free, 3 Push, 4 Hold: one
        // byte each instead of a Format index and a byte), one format per string edge: fewer
        // writes into the RTT buffer per line.
        BenchEvent::Phase {
            from,
            to,
            at_ms,
            angle_rad,
            string,
        } => match string {
            StringEdge::Unchanged => defmt::info!(
                "reflex {=u8} -> {=u8} at {=u32} ms, angle {=f32} rad",
                from.raw(),
                to.raw(),
                at_ms,
                angle_rad
            ),
            StringEdge::Engaged(setpoint) => defmt::info!(
                "reflex {=u8} -> {=u8} at {=u32} ms, angle {=f32} rad: string engaged, setpoint {=f32} rad",
                from.raw(),
                to.raw(),
                at_ms,
                angle_rad,
                setpoint
            ),
            StringEdge::Released(last) => defmt::info!(
                "reflex {=u8} -> {=u8} at {=u32} ms, angle {=f32} rad: string released, last setpoint {=f32} rad",
                from.raw(),
                to.raw(),
                at_ms,
                angle_rad,
                last
            ),
        },
        BenchEvent::HeelStrike { own, step, at_ms } => {
            defmt::info!("heel strike own {=bool} step {=u16} at {=u32} ms", own, step, at_ms)
        }
        BenchEvent::ParamWrite {
            param,
            value,
            status,
        } => defmt::info!(
            "SetParam {=u8} = {=i32} µ-SI: status {=u8}",
            param.raw(),
            value,
            status.raw()
        ),
        BenchEvent::Saved(ok) => defmt::info!("parameters saved: {=bool}", ok),
        BenchEvent::CanState { from, to, tec, rec } => defmt::warn!(
            "CAN {} -> {} (TEC {=u8}, REC {=u8})",
            from,
            to,
            tec,
            rec
        ),
    }
    if suppressed > 0 || dropped > 0 {
        defmt::warn!(
            "({=u32} earlier {} lines rate-limited, {=u32} dropped on a full queue)",
            suppressed,
            event.kind(),
            dropped
        );
    }
}

#[cfg(not(feature = "defmt"))]
fn write_line(_: &BenchEvent, _: u32, _: u32) {}

#[cfg(test)]
mod tests {
    use super::*;

    fn phase(at_ms: u32) -> BenchEvent {
        BenchEvent::Phase {
            from: ReflexPhase::Free,
            to: ReflexPhase::Push,
            at_ms,
            angle_rad: -0.08,
            string: StringEdge::Engaged(-0.08),
        }
    }

    #[test]
    fn one_line_per_tick_in_order() {
        let mut log = BenchLog::default();
        let t = Instant::from_millis(3);
        log.record(t, BenchEvent::FaultRaised(FaultCode::EncoderStuck, 50));
        log.record(
            t,
            BenchEvent::State {
                from: NodeState::Enabled,
                to: NodeState::Safe,
            },
        );
        log.record(t, phase(3));
        assert_eq!(log.pending(), 3);
        assert!(log.flush_one());
        assert_eq!(log.pending(), 2);
        assert!(log.flush_one());
        assert!(log.flush_one());
        assert!(!log.flush_one());
    }

    #[test]
    fn a_full_queue_counts_what_it_drops() {
        let mut log = BenchLog::default();
        // Eight faults (their bucket's burst) fill the queue; two parameter lines (another
        // bucket, tokens left) find it full.
        let t = Instant::from_millis(1);
        for k in 0..8i16 {
            log.record(t, BenchEvent::FaultRaised(FaultCode::EncoderStuck, k));
        }
        for _ in 0..2 {
            log.record(t, BenchEvent::Saved(true));
        }
        assert_eq!(log.pending(), QUEUE_LEN);
        assert_eq!(log.dropped(), 2);
        assert!(log.flush_one());
        assert_eq!(log.dropped(), 0, "reported with the next line");
    }

    #[test]
    fn a_flapping_input_is_rate_limited_before_the_queue() {
        let mut log = BenchLog::default();
        // 1000 phase changes in one second, one line written per tick.
        let mut written = 0;
        for ms in 0..1000u64 {
            log.record(Instant::from_millis(ms), phase(ms as u32));
            if log.flush_one() {
                written += 1;
            }
        }
        assert_eq!(written, 8 + 9, "burst, then 10 per second");
        assert_eq!(log.dropped(), 0);
    }
}
