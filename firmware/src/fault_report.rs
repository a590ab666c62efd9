//! Fault frames with an inhibit time, as CANopen's EMCY (object 0x1015): after a fault code's
//! event was sent, the next event of the same code waits until the inhibit time has passed;
//! then one event with the code's state at that moment is sent (none if it is back where the
//! last frame left it). A flapping fault costs one frame per inhibit time, not one per tick;
//! the heartbeat's fault flags always show the current state.

use protocol::{FaultCode, FaultTransition};

use crate::time::Instant;

/// Inhibit time between two events of the same fault code \[µs\] (50 ms).
pub const FAULT_INHIBIT_US: u64 = 50_000;

const CODES: usize = FaultCode::ALL.len();

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct CodeState {
    /// Time and state of the last event sent.
    sent: Option<(Instant, bool)>,
    /// A change is waiting for the inhibit time; its detail.
    pending: Option<i16>,
}

/// What to send for one fault code now.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FaultReport {
    /// The code.
    pub code: FaultCode,
    /// Raised or cleared.
    pub transition: FaultTransition,
    /// Detail of the (last) change.
    pub detail: i16,
}

/// Per-code inhibit bookkeeping.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FaultReporter {
    codes: [CodeState; CODES],
    suppressed: u32,
}

fn index(code: FaultCode) -> usize {
    (code.raw() as usize).saturating_sub(1)
}

fn transition(present: bool) -> FaultTransition {
    if present {
        FaultTransition::Raised
    } else {
        FaultTransition::Cleared
    }
}

impl FaultReporter {
    /// A fault code changed to `present`: `Some` when its event goes out now, `None` when it
    /// waits for the inhibit time.
    pub fn changed(
        &mut self,
        now: Instant,
        code: FaultCode,
        present: bool,
        detail: i16,
    ) -> Option<FaultReport> {
        let st = self.codes.get_mut(index(code))?;
        match st.sent {
            Some((at, _)) if now.0 < at.0.saturating_add(FAULT_INHIBIT_US) => {
                if st.pending.replace(detail).is_some() {
                    self.suppressed = self.suppressed.saturating_add(1);
                }
                None
            }
            _ => {
                st.sent = Some((now, present));
                st.pending = None;
                Some(FaultReport {
                    code,
                    transition: transition(present),
                    detail,
                })
            }
        }
    }

    /// Events whose inhibit time is over, given each code's current state (`active`).
    pub fn due(
        &mut self,
        now: Instant,
        active: impl Fn(FaultCode) -> bool,
    ) -> heapless::Vec<FaultReport, CODES> {
        let mut out = heapless::Vec::new();
        for (code, st) in FaultCode::ALL.iter().zip(self.codes.iter_mut()) {
            let (Some(detail), Some((at, last))) = (st.pending, st.sent) else {
                continue;
            };
            if now.0 < at.0.saturating_add(FAULT_INHIBIT_US) {
                continue;
            }
            st.pending = None;
            let present = active(*code);
            if present == last {
                self.suppressed = self.suppressed.saturating_add(1);
                continue;
            }
            st.sent = Some((now, present));
            let _ = out.push(FaultReport {
                code: *code,
                transition: transition(present),
                detail: if present { detail } else { 0 },
            });
        }
        out
    }

    /// Changes that were never sent because the state came back within the inhibit time.
    pub fn suppressed(&self) -> u32 {
        self.suppressed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flapping_fault_sends_one_event_per_inhibit_time() {
        let t = Instant::from_millis;
        let mut r = FaultReporter::default();
        let code = FaultCode::EncoderRate;
        let mut present = false;
        let mut sent = 0;
        for ms in 0..200u64 {
            present = !present;
            if r.changed(t(ms), code, present, 7).is_some() {
                sent += 1;
            }
            sent += r.due(t(ms), |_| present).len();
        }
        // 200 ms of a fault toggling every tick: at most one event per 50 ms.
        assert!(sent <= 4, "{sent} events");
        assert!(sent >= 2);
        assert!(r.suppressed() > 150);
    }

    #[test]
    fn a_change_held_through_the_inhibit_time_is_sent_at_its_end() {
        let t = Instant::from_millis;
        let mut r = FaultReporter::default();
        let c = FaultCode::EncoderComms;
        let first = r.changed(t(0), c, true, 1).unwrap();
        assert_eq!(first.transition, FaultTransition::Raised);
        assert_eq!(r.changed(t(10), c, false, 0), None, "inhibited");
        assert!(r.due(t(49), |_| false).is_empty());
        let due = r.due(t(50), |_| false);
        assert_eq!(due.len(), 1);
        assert_eq!(due[0].transition, FaultTransition::Cleared);
        // A raise and clear inside the window: nothing more to say.
        assert_eq!(r.changed(t(60), c, true, 3), None);
        assert_eq!(r.changed(t(61), c, false, 0), None);
        assert!(r.due(t(100), |_| false).is_empty());
        // Other codes are independent.
        assert!(r.changed(t(61), FaultCode::Actuator, true, 0).is_some());
    }
}
