//! The stretch reflex of the paper's Fig. 8, as a pure state machine.
//!
//! ```text
//!            own heel strike                 angle <= taut            profile done
//!  Swing ──────────────────────▶ Free ───────────────────────▶ Push ───────────────▶ Hold
//!    ▲                            │                             │                    │
//!    └────────────────────────────┴─────────────────────────────┴────────────────────┘
//!         release: the other foot's heel strike (CAN), or the own foot lifting off
//!         (contact switch) when that message is late
//! ```
//!
//! In `Swing` and `Free` the actuator is released (the string is slack and the ankle is a free
//! joint). In `Push` the actuator holds the string at a setpoint that follows a minimum-jerk
//! profile from the taut angle to the extended angle; in `Hold` it holds the extended angle.
//! `Inactive` is every node state other than enabled: actuator released.

use protocol::ReflexPhase;

use crate::params::ReflexParams;
use crate::time::Instant;

/// What the actuator must do this tick.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ActuatorCommand {
    /// String released: the ankle is free (safe state).
    Released,
    /// Hold the string so that the ankle angle cannot fall below this \[rad\].
    Position {
        /// Setpoint as an ankle angle \[rad\].
        ankle_angle_rad: f32,
    },
}

impl ActuatorCommand {
    /// A 32-bit fingerprint for bit-exact comparisons: `0xFFFF_FFFF` for released (a NaN
    /// pattern never produced as a setpoint), else the setpoint's IEEE-754 bits.
    pub fn bits(&self) -> u32 {
        match self {
            ActuatorCommand::Released => u32::MAX,
            ActuatorCommand::Position { ankle_angle_rad } => ankle_angle_rad.to_bits(),
        }
    }
}

/// Why the string was released.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ReleaseCause {
    /// The other foot's heel-strike message arrived (normal case).
    PeerHeelStrike,
    /// The own foot lifted off before the message arrived (fallback).
    OwnLiftOff,
}

/// A phase change reported by [`Reflex::step`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ReflexEvent {
    /// Own heel strike: Swing → Free.
    HeelStrike,
    /// String taut: Free → Push.
    Engaged,
    /// Profile finished: Push → Hold.
    Extended,
    /// Free, Push or Hold → Swing.
    Released(ReleaseCause),
}

/// Inputs of one reflex step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReflexInputs {
    /// Time of the step.
    pub now: Instant,
    /// Estimated ankle angle \[rad\].
    pub angle_rad: f32,
    /// The own contact switch closed this tick (debounced rising edge).
    pub heel_strike: bool,
    /// The own contact switch opened this tick (debounced falling edge).
    pub lift_off: bool,
    /// A heel-strike message from the other ankle arrived this tick.
    pub peer_heel_strike: bool,
}

/// Minimum-jerk blend `s(τ) = 10τ³ − 15τ⁴ + 6τ⁵` for τ clamped to [0, 1]; peak slope
/// [`ankle_profile::PEAK_SLOPE`] (1.875). The one profile of the `ankle-profile` crate, which
/// the simulator's ideal ankle drive follows too.
pub fn min_jerk(tau: f32) -> f32 {
    ankle_profile::blend(tau, |c| c).s
}

/// The reflex state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reflex {
    phase: ReflexPhase,
    push_start: Instant,
    last_setpoint_rad: f32,
}

impl Default for Reflex {
    fn default() -> Self {
        Reflex {
            phase: ReflexPhase::Inactive,
            push_start: Instant(0),
            last_setpoint_rad: 0.0,
        }
    }
}

impl Reflex {
    /// Current phase.
    pub fn phase(&self) -> ReflexPhase {
        self.phase
    }

    /// Last position setpoint \[rad\] (kept after release, for telemetry).
    pub fn last_setpoint_rad(&self) -> f32 {
        self.last_setpoint_rad
    }

    /// Start running: `Free` if the foot is on the floor, else `Swing`.
    pub fn start(&mut self, contact_closed: bool) {
        self.phase = if contact_closed {
            ReflexPhase::Free
        } else {
            ReflexPhase::Swing
        };
    }

    /// Stop running (`Inactive`, actuator released).
    pub fn stop(&mut self) {
        self.phase = ReflexPhase::Inactive;
    }

    fn release(&mut self, cause: ReleaseCause) -> Option<ReflexEvent> {
        self.phase = ReflexPhase::Swing;
        Some(ReflexEvent::Released(cause))
    }

    fn setpoint(&mut self, now: Instant, p: &ReflexParams) -> f32 {
        ankle_profile::Extension {
            from: p.taut_angle_rad(),
            to: p.extended_angle_rad(),
            duration: p.effective_push_duration_s(),
        }
        .angle(now.secs_since(self.push_start), |c| c)
    }

    /// One control step: at most one phase change, constant work.
    pub fn step(
        &mut self,
        i: &ReflexInputs,
        p: &ReflexParams,
    ) -> (ActuatorCommand, Option<ReflexEvent>) {
        let mut event = None;
        match self.phase {
            ReflexPhase::Inactive => {}
            ReflexPhase::Swing => {
                if i.heel_strike {
                    self.phase = ReflexPhase::Free;
                    event = Some(ReflexEvent::HeelStrike);
                }
            }
            ReflexPhase::Free | ReflexPhase::Push | ReflexPhase::Hold => {
                if i.peer_heel_strike {
                    event = self.release(ReleaseCause::PeerHeelStrike);
                } else if i.lift_off {
                    event = self.release(ReleaseCause::OwnLiftOff);
                } else if self.phase == ReflexPhase::Free && i.angle_rad <= p.taut_angle_rad() {
                    self.phase = ReflexPhase::Push;
                    self.push_start = i.now;
                    event = Some(ReflexEvent::Engaged);
                }
            }
        }
        let cmd = match self.phase {
            ReflexPhase::Inactive | ReflexPhase::Swing | ReflexPhase::Free => {
                ActuatorCommand::Released
            }
            ReflexPhase::Push => {
                let sp = self.setpoint(i.now, p);
                if i.now.secs_since(self.push_start) >= p.effective_push_duration_s() {
                    self.phase = ReflexPhase::Hold;
                    event = Some(ReflexEvent::Extended);
                }
                ActuatorCommand::Position {
                    ankle_angle_rad: sp,
                }
            }
            ReflexPhase::Hold => ActuatorCommand::Position {
                ankle_angle_rad: p.extended_angle_rad(),
            },
        };
        if let ActuatorCommand::Position { ankle_angle_rad } = cmd {
            self.last_setpoint_rad = ankle_angle_rad;
        }
        (cmd, event)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn inputs(ms: u64, angle: f32) -> ReflexInputs {
        ReflexInputs {
            now: Instant::from_millis(ms),
            angle_rad: angle,
            heel_strike: false,
            lift_off: false,
            peer_heel_strike: false,
        }
    }

    #[test]
    fn min_jerk_is_bounded_and_monotone() {
        assert_eq!(min_jerk(-1.0), 0.0);
        assert_eq!(min_jerk(0.0), 0.0);
        assert_eq!(min_jerk(1.0), 1.0);
        assert_eq!(min_jerk(2.0), 1.0);
        let mut last = 0.0;
        for k in 1..=1000 {
            let s = min_jerk(k as f32 / 1000.0);
            assert!(s >= last - 1e-6, "monotone up to rounding");
            assert!((s - last) * 1000.0 <= 1.875 + 1e-3, "peak slope 1.875");
            last = s;
        }
    }

    #[test]
    fn full_cycle_follows_fig_8() {
        let p = ReflexParams::default();
        let mut r = Reflex::default();
        assert_eq!(
            r.step(&inputs(0, 0.0), &p),
            (ActuatorCommand::Released, None)
        );
        r.start(false);
        assert_eq!(r.phase(), ReflexPhase::Swing);
        let mut i = inputs(1, 0.1);
        i.heel_strike = true;
        assert_eq!(
            r.step(&i, &p),
            (ActuatorCommand::Released, Some(ReflexEvent::HeelStrike))
        );
        assert_eq!(r.phase(), ReflexPhase::Free);
        assert_eq!(r.step(&inputs(2, -0.079), &p).1, None);
        let (cmd, ev) = r.step(&inputs(10, -0.08), &p);
        assert_eq!(ev, Some(ReflexEvent::Engaged));
        assert_eq!(
            cmd,
            ActuatorCommand::Position {
                ankle_angle_rad: -0.08
            }
        );
        let mut last = -0.08;
        let mut extended_at = None;
        for ms in 11..400 {
            let (cmd, ev) = r.step(&inputs(ms, last), &p);
            let ActuatorCommand::Position { ankle_angle_rad } = cmd else {
                panic!("released during push");
            };
            assert!(ankle_angle_rad >= last && ankle_angle_rad <= 0.2 + 1e-6);
            assert!(
                (ankle_angle_rad - last) <= 4.0e-3 + 1e-5,
                "rate bound 4 rad/s"
            );
            last = ankle_angle_rad;
            if ev == Some(ReflexEvent::Extended) {
                extended_at = Some(ms);
            }
        }
        assert_eq!(extended_at, Some(280), "270 ms profile");
        assert_eq!(r.phase(), ReflexPhase::Hold);
        assert_eq!(last, 0.2);
        let mut i = inputs(401, 0.2);
        i.peer_heel_strike = true;
        assert_eq!(
            r.step(&i, &p),
            (
                ActuatorCommand::Released,
                Some(ReflexEvent::Released(ReleaseCause::PeerHeelStrike))
            )
        );
        assert_eq!(r.phase(), ReflexPhase::Swing);
        assert_eq!(r.last_setpoint_rad(), 0.2);
    }

    #[test]
    fn lift_off_releases_from_free_push_and_hold() {
        let p = ReflexParams::default();
        for phase_target in [ReflexPhase::Free, ReflexPhase::Push, ReflexPhase::Hold] {
            let mut r = Reflex::default();
            r.start(true);
            if phase_target != ReflexPhase::Free {
                r.step(&inputs(0, -0.1), &p);
            }
            if phase_target == ReflexPhase::Hold {
                r.step(&inputs(1000, -0.1), &p);
            }
            assert_eq!(r.phase(), phase_target);
            let mut i = inputs(2000, 0.0);
            i.lift_off = true;
            let (cmd, ev) = r.step(&i, &p);
            assert_eq!(cmd, ActuatorCommand::Released);
            assert_eq!(ev, Some(ReflexEvent::Released(ReleaseCause::OwnLiftOff)));
        }
    }

    #[test]
    fn peer_heel_strike_in_swing_is_ignored_and_stop_releases() {
        let p = ReflexParams::default();
        let mut r = Reflex::default();
        r.start(false);
        let mut i = inputs(0, 0.0);
        i.peer_heel_strike = true;
        i.lift_off = true;
        assert_eq!(r.step(&i, &p), (ActuatorCommand::Released, None));
        r.start(true);
        r.step(&inputs(1, -0.2), &p);
        assert_eq!(r.phase(), ReflexPhase::Push);
        r.stop();
        assert_eq!(
            r.step(&inputs(2, -0.2), &p),
            (ActuatorCommand::Released, None)
        );
        assert_eq!(ActuatorCommand::Released.bits(), u32::MAX);
    }
}
