//! Closing the loop on the stance ankle: a controller (the firmware's ankle nodes, or any other)
//! is sampled at fixed control ticks, sample-and-hold, and moves the string's limit on the
//! stance ankle angle. Every tick runs, at its exact time; a tick whose output changes the
//! plant's input is a breakpoint of the integration, a tick that holds it may fall inside a
//! step and see the integrator's interpolant there ([`TickStepping`]).
//!
//! The string is a unilateral constraint: the stance ankle angle cannot fall below the limit.
//! While the angle is above it the ankle is free and the foot flat; reaching it is the string
//! engagement (an inelastic impact), after which the foot pivots on its toe and the ankle
//! follows the limit. A limit that is released (string slack) never engages; released during
//! push-off, the heel comes back down, which ends the stride as `heel_returned_to_floor`.

use crate::engine::hermite::{self, Knot};
use serde::Serialize;

/// What the stance ankle's sensors see at a tick (true physical values; a controller quantises
/// and filters them as its hardware would).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct AnkleSensing {
    /// Time since the start of the walk \[s\] (walk time; serialised as `t_s`).
    #[serde(rename = "t_s")]
    pub t_walk_s: f64,
    /// Stance ankle angle \[rad\] (negative with the hip ahead of the ankle).
    pub stance_ankle_rad: f64,
    /// Stance ankle rate [rad/s].
    pub stance_ankle_rate_rad_s: f64,
    /// The stance foot is on the floor (always, in single stance).
    pub stance_foot_on_floor: bool,
    /// The swing foot touches the floor (its height is not above it).
    pub swing_foot_on_floor: bool,
    /// The string is taut (engaged) on the stance ankle.
    pub string_engaged: bool,
    /// Torque the engaged string exerts on the stance ankle at the tick, just before the new
    /// segment [N·m] (the generalised force of the drive on the ankle coordinate; 0 while the
    /// string is slack).
    pub string_torque_n_m: f64,
}

/// The stance string's limit over one tick: a cubic Hermite from `(p0, v0)` at `t0` to
/// `(p1, v1)` at `t1` (continuous position and rate across ticks), or released.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ActuatorSegment {
    /// Start of the tick \[s\] (walk time as a controller returns it; a stride shifts its
    /// segments to stride time).
    pub t0_s: f64,
    /// End of the tick \[s\] (same clock as [`Self::t0_s`]).
    pub t1_s: f64,
    /// Limit angle at the start \[rad\].
    pub p0_rad: f64,
    /// Limit rate at the start [rad/s].
    pub v0_rad_s: f64,
    /// Limit angle at the end \[rad\].
    pub p1_rad: f64,
    /// Limit rate at the end [rad/s].
    pub v1_rad_s: f64,
    /// The string is slack: no limit.
    pub released: bool,
}

impl ActuatorSegment {
    /// A constant limit over `[t0, t1]`.
    pub fn hold(t0_s: f64, t1_s: f64, p_rad: f64) -> Self {
        Self {
            t0_s,
            t1_s,
            p0_rad: p_rad,
            v0_rad_s: 0.0,
            p1_rad: p_rad,
            v1_rad_s: 0.0,
            released: false,
        }
    }

    /// The limit does not move over the tick: released, or held at one angle.
    pub fn is_held(&self) -> bool {
        self.released
            || (self.p0_rad == self.p1_rad && self.v0_rad_s == 0.0 && self.v1_rad_s == 0.0)
    }

    /// `next` gives the plant the same input as `self` (as functions of time, whatever their
    /// ticks): both released, or both held at the same angle. A controlled stride's step may
    /// then run across the tick between them ([`TickStepping::HeldAcrossTicks`]).
    pub fn same_held_input(&self, next: &ActuatorSegment) -> bool {
        match (self.released, next.released) {
            (true, true) => true,
            (false, false) => self.is_held() && next.is_held() && self.p1_rad == next.p0_rad,
            _ => false,
        }
    }

    /// Limit angle \[rad\], rate [rad/s] and acceleration [rad/s²] at `t_s` (the clock of
    /// [`Self::t0_s`]; clamped to the tick).
    pub fn eval(&self, t_s: f64) -> (f64, f64, f64) {
        let h = self.t1_s - self.t0_s;
        if h <= 0.0 {
            return (self.p1_rad, self.v1_rad_s, 0.0);
        }
        let x = ((t_s - self.t0_s) / h).clamp(0.0, 1.0);
        let knot = |value, rate| Knot { value, rate };
        hermite::scalar(
            knot(self.p0_rad, self.v0_rad_s),
            knot(self.p1_rad, self.v1_rad_s),
            h,
            x,
        )
    }
}

/// How a controlled stride's integration steps meet the control ticks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TickStepping {
    /// The default: while the controller's output holds the plant's input (a released string,
    /// a limit held at one angle) a step runs across ticks; the controller still runs at every
    /// tick, on the state the integrator's interpolant gives there, and the step ends at the
    /// first tick whose output changes the plant's input (the state there is the
    /// interpolant's, the one the controller saw, so nothing is rolled back). A moving limit,
    /// or an integrator without an interpolant (RK4, Meijaard), ends every step at a tick.
    #[default]
    HeldAcrossTicks,
    /// Every step ends at the next tick (the reference the default is tested against).
    EndAtEveryTick,
}

/// Why a controller could not run a tick.
///
/// A controller lives outside this crate (the firmware in the loop of crate `sil`, a test's
/// controller), so its failure is its own typed error, kept whole: [`Self::source_error`]
/// downcasts to it (e.g. `sil::TickError`).
#[derive(Debug, Clone, thiserror::Error)]
pub enum ControlError {
    /// The controller `controller` failed a tick.
    #[error("controller: {controller}: {source}")]
    Controller {
        /// Which controller (`firmware in the loop`).
        controller: &'static str,
        /// Its error.
        source: std::sync::Arc<dyn std::error::Error + Send + Sync + 'static>,
    },
}

impl ControlError {
    /// The controller `controller` failed a tick with `error`.
    pub fn controller(
        controller: &'static str,
        error: impl std::error::Error + Send + Sync + 'static,
    ) -> Self {
        Self::Controller {
            controller,
            source: std::sync::Arc::new(error),
        }
    }

    /// The controller's own error (downcast it to the controller's error type).
    pub fn source_error(&self) -> &(dyn std::error::Error + Send + Sync + 'static) {
        match self {
            Self::Controller { source, .. } => source.as_ref(),
        }
    }
}

/// Two controller failures are equal when the same controller failed with the same error
/// (the same value, or errors that read the same: an error need not be comparable).
impl PartialEq for ControlError {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (
                Self::Controller {
                    controller: a,
                    source: e,
                },
                Self::Controller {
                    controller: b,
                    source: f,
                },
            ) => a == b && (std::sync::Arc::ptr_eq(e, f) || e.to_string() == f.to_string()),
        }
    }
}

/// A controller of the stance ankle's string, sampled every `period_s`.
pub trait AnkleController {
    /// Control period \[s\]: a finite positive time (a controlled stride refuses any other, as
    /// `FailureKind::InvalidControlPeriod`).
    fn period_s(&self) -> f64;
    /// One tick at `sensing.t_walk_s`: returns the string's limit until the next tick.
    fn tick(&mut self, sensing: &AnkleSensing) -> Result<ActuatorSegment, ControlError>;
    /// Heel strike at walk time `t_walk_s`: the swing leg becomes the stance leg (the legs
    /// swap roles).
    fn heel_strike(&mut self, t_walk_s: f64);
}

/// Wraps a controller so that walk time keeps pace with wall-clock time (times `factor`): each
/// tick sleeps until its walk time is due. For watching a simulation live. A factor whose
/// waits are not representable durations (0, NaN, 1e-300) does not pace (and does not panic);
/// callers validate the factor (`walker sil --realtime` takes 0.001 to 1000).
pub struct Paced<'a> {
    inner: &'a mut dyn AnkleController,
    factor: f64,
    start: std::time::Instant,
}

impl<'a> Paced<'a> {
    /// Paces `inner` at `factor` × real time from `start`.
    pub fn new(inner: &'a mut dyn AnkleController, factor: f64, start: std::time::Instant) -> Self {
        Self {
            inner,
            factor,
            start,
        }
    }
}

impl AnkleController for Paced<'_> {
    fn period_s(&self) -> f64 {
        self.inner.period_s()
    }
    fn tick(&mut self, sensing: &AnkleSensing) -> Result<ActuatorSegment, ControlError> {
        // A due time that is no duration (a factor of 0 or NaN, or one so small that the wait
        // overflows) is not waited for: pacing never panics.
        if let Ok(due) =
            std::time::Duration::try_from_secs_f64((sensing.t_walk_s / self.factor).max(0.0))
        {
            let elapsed = self.start.elapsed();
            if due > elapsed {
                std::thread::sleep(due - elapsed);
            }
        }
        self.inner.tick(sensing)
    }
    fn heel_strike(&mut self, t_walk_s: f64) {
        self.inner.heel_strike(t_walk_s);
    }
}

/// A sampled version of the ideal stretch reflex: the limit is held at the engagement angle
/// until a tick sees the string taut, then follows the ideal smooth extension from that tick,
/// and is re-armed at heel strike. The reference controller for the control-tick machinery: it
/// differs from the ideal actuator only by the sample-and-hold delay.
#[derive(Clone, Debug, PartialEq)]
pub struct SampledReflex {
    /// Control period \[s\].
    pub period_s: f64,
    /// Engagement (taut) angle \[rad\].
    pub engage_rad: f64,
    /// Final angle \[rad\].
    pub final_rad: f64,
    /// Extension duration \[s\].
    pub duration_s: f64,
    started_at_s: Option<f64>,
}

impl SampledReflex {
    /// A reflex with the given period and the ideal reflex's angles and duration.
    pub fn new(period_s: f64, reflex: &crate::engine::actuator::AnkleReflex) -> Self {
        Self {
            period_s,
            engage_rad: reflex.engage_rad,
            final_rad: reflex.final_rad,
            duration_s: reflex.duration_s,
            started_at_s: None,
        }
    }
}

impl AnkleController for SampledReflex {
    fn period_s(&self) -> f64 {
        self.period_s
    }
    fn tick(&mut self, sensing: &AnkleSensing) -> Result<ActuatorSegment, ControlError> {
        let t = sensing.t_walk_s;
        if self.started_at_s.is_none() && sensing.string_engaged {
            self.started_at_s = Some(t);
        }
        let t1 = t + self.period_s;
        Ok(match self.started_at_s {
            None => ActuatorSegment::hold(t, t1, self.engage_rad),
            Some(start_s) => {
                let profile = crate::engine::actuator::AnkleProfile {
                    start_s,
                    duration_s: self.duration_s,
                    from_rad: self.engage_rad,
                    to_rad: self.final_rad,
                };
                let (p0, v0, _) = profile.eval(t);
                let (p1, v1, _) = profile.eval(t1);
                ActuatorSegment {
                    t0_s: t,
                    t1_s: t1,
                    p0_rad: p0,
                    v0_rad_s: v0,
                    p1_rad: p1,
                    v1_rad_s: v1,
                    released: false,
                }
            }
        })
    }
    fn heel_strike(&mut self, _t_s: f64) {
        self.started_at_s = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Holds the limit at 0, counting its ticks.
    struct Counting(usize);

    impl AnkleController for Counting {
        fn period_s(&self) -> f64 {
            1e-3
        }
        fn tick(&mut self, sensing: &AnkleSensing) -> Result<ActuatorSegment, ControlError> {
            self.0 += 1;
            Ok(ActuatorSegment::hold(
                sensing.t_walk_s,
                sensing.t_walk_s + 1e-3,
                0.0,
            ))
        }
        fn heel_strike(&mut self, _t_walk_s: f64) {}
    }

    #[test]
    fn pacing_by_a_factor_whose_wait_is_no_duration_neither_panics_nor_waits() {
        // `walker sil --realtime 1e-300` panicked in `Duration::from_secs_f64`.
        for factor in [1e-300, 0.0, -1.0, f64::NAN, f64::INFINITY] {
            let mut inner = Counting(0);
            let mut paced = Paced::new(&mut inner, factor, std::time::Instant::now());
            let sensing = AnkleSensing {
                t_walk_s: 1.0,
                stance_ankle_rad: 0.0,
                stance_ankle_rate_rad_s: 0.0,
                stance_foot_on_floor: true,
                swing_foot_on_floor: false,
                string_engaged: false,
                string_torque_n_m: 0.0,
            };
            assert!(paced.tick(&sensing).is_ok(), "{factor}");
            assert_eq!(inner.0, 1, "{factor}");
        }
    }

    #[test]
    fn only_a_released_string_or_one_held_angle_holds_the_plant_s_input() {
        let hold = |t0: f64, p: f64| ActuatorSegment::hold(t0, t0 + 1e-3, p);
        let released = ActuatorSegment {
            released: true,
            ..hold(0.0, 0.3)
        };
        let moving = ActuatorSegment {
            p1_rad: -0.079,
            v1_rad_s: 1.0,
            ..hold(0.0, -0.08)
        };
        assert!(hold(0.0, -0.08).is_held() && released.is_held() && !moving.is_held());
        // Released to released (whatever the angles), the same angle at the next tick.
        let next_released = ActuatorSegment {
            released: true,
            ..hold(1e-3, -0.2)
        };
        assert!(released.same_held_input(&next_released));
        assert!(hold(0.0, -0.08).same_held_input(&hold(1e-3, -0.08)));
        // Another angle, taut after slack, slack after taut, a limit that starts moving.
        assert!(!hold(0.0, -0.08).same_held_input(&hold(1e-3, -0.0801)));
        assert!(!released.same_held_input(&hold(1e-3, 0.3)));
        assert!(!hold(0.0, 0.3).same_held_input(&next_released));
        let starts_moving = ActuatorSegment {
            t0_s: 1e-3,
            t1_s: 2e-3,
            ..moving
        };
        assert!(!hold(0.0, -0.08).same_held_input(&starts_moving));
        assert!(!moving.same_held_input(&hold(1e-3, -0.079)));
    }

    #[test]
    fn segment_is_a_c1_cubic_with_consistent_derivatives() {
        let s = ActuatorSegment {
            t0_s: 1.0,
            t1_s: 1.001,
            p0_rad: -0.08,
            v0_rad_s: 0.5,
            p1_rad: -0.079,
            v1_rad_s: 1.5,
            released: false,
        };
        assert_eq!(s.eval(1.0).0, -0.08);
        assert!((s.eval(1.001).0 + 0.079).abs() < 1e-15);
        assert!((s.eval(1.0).1 - 0.5).abs() < 1e-9 && (s.eval(1.001).1 - 1.5).abs() < 1e-9);
        let h = 1e-8;
        let t = 1.0004;
        assert!(((s.eval(t + h).0 - s.eval(t - h).0) / (2.0 * h) - s.eval(t).1).abs() < 1e-5);
        assert!(((s.eval(t + h).1 - s.eval(t - h).1) / (2.0 * h) - s.eval(t).2).abs() < 1e-2);
    }
}
