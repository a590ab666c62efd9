//! Following error: the measured ankle angle against the setpoint the actuator was given,
//! in every driven state (push and hold). The string can only pull the ankle up to the
//! setpoint (it is unilateral: the foot may lift above it), so only a measured angle *below*
//! the setpoint counts. Staying more than [`FOLLOWING_ERROR_LIMIT_RAD`] below it for
//! [`FOLLOWING_ERROR_TIME_S`] means the string is not where it is commanded: a reversed or
//! failed motor, a broken string, or an encoder reading frozen away from the setpoint.

use crate::convert::saturating_i16;
use crate::time::Instant;

/// Largest tolerated shortfall of the measured angle below the setpoint \[rad\]: 12 × the
/// profile's one-tick step at its peak rate (4 rad/s × 1 ms), 3 × the simulated servo's lag
/// at that rate (4 rad/s × 5 ms).
pub const FOLLOWING_ERROR_LIMIT_RAD: f32 = 0.05;
/// How long the shortfall may last \[s\].
pub const FOLLOWING_ERROR_TIME_S: f32 = 0.03;

/// Watches the shortfall across ticks.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FollowingErrorMonitor {
    since: Option<Instant>,
}

impl FollowingErrorMonitor {
    /// Check one tick: `setpoint_rad` the position commanded in the previous tick (`None`
    /// while not driving), `measured_rad` this tick's good encoder angle (`None` when the read
    /// failed: that is the encoder's own fault). `Some(detail)` — the shortfall in 0.1 mrad,
    /// saturated — while the fault holds.
    pub fn check(
        &mut self,
        now: Instant,
        setpoint_rad: Option<f32>,
        measured_rad: Option<f32>,
    ) -> Option<i16> {
        let (Some(s), Some(m)) = (setpoint_rad, measured_rad) else {
            self.since = None;
            return None;
        };
        let shortfall = s - m;
        if shortfall.is_nan() || shortfall <= FOLLOWING_ERROR_LIMIT_RAD {
            self.since = None;
            return None;
        }
        let since = *self.since.get_or_insert(now);
        // Detail in 0.1 mrad, saturated (an infinite shortfall reads as 32767).
        (now.secs_since(since) >= FOLLOWING_ERROR_TIME_S)
            .then_some(saturating_i16(shortfall * 1.0e4))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_lasting_shortfall_below_the_setpoint_counts() {
        let t = Instant::from_millis;
        let mut f = FollowingErrorMonitor::default();
        assert_eq!(f.check(t(0), Some(0.2), Some(0.19)), None, "small lag");
        assert_eq!(
            f.check(t(1), Some(0.2), Some(0.5)),
            None,
            "above: string slack"
        );
        for ms in 2..32 {
            assert_eq!(f.check(t(ms), Some(0.2), Some(0.1)), None, "{ms} ms");
        }
        assert_eq!(f.check(t(32), Some(0.2), Some(0.1)), Some(1000));
        assert_eq!(f.check(t(33), None, Some(0.1)), None, "not driving");
        assert_eq!(
            f.check(t(34), Some(0.2), Some(0.1)),
            None,
            "timer restarted"
        );
        assert_eq!(f.check(t(35), Some(0.2), None), None, "no reading");
    }
}
