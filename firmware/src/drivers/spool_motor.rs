//! The string actuator as the B-G431B-ESC1's power stage can drive it: a brushed DC gear
//! motor winding the string on a spool, across two of the board's three half-bridges (phase
//! U and V; W stays off), with the spool's position from a quadrature encoder on the motor
//! and the motor current from the board's low-side shunt amplifiers.
//!
//! Drive scheme (sign–magnitude, "slow decay"): for a positive duty, leg A switches at the
//! duty with complementary low-side switching and dead time, leg B keeps its low side on; for
//! a negative duty the legs swap. The leg held low carries the whole motor current through its
//! shunt in both halves of the PWM period (on: high A → motor → low B; off: freewheeling
//! through low A and low B), so one amplifier reading per tick is the motor current whatever
//! the PWM phase.
//!
//! What each command does:
//! * `Position { ankle_angle_rad }` — a PD loop from the measured ankle angle to the duty (the
//!   string is taut while held): `kp·e + kd·ė`, `e` = setpoint − measured angle, `ė` = the
//!   setpoint's rate (from the previous tick's setpoint) minus the ankle's rate *as the spool
//!   encoder sees it* (spool counts per tick over `counts_per_ankle_rad`; the ankle encoder's
//!   counts are too coarse to differentiate at 1 kHz). The rate term damps the motor and the
//!   load's inertia; on the setpoint's rate it adds no lag when tracking a ramp. Duty clamped
//!   to `max_duty`. The string is unilateral (it can pull, not push), so the
//!   duty toward release is bounded: the spool may pay out at most `hold_payout_counts`
//!   below where this hold began; beyond that the loop may only wind in or stop. The spool
//!   position and the measured angle of every such tick are remembered, and the measured
//!   angle of the first (where the push began: the string taut at the taut angle).
//! * Soft limits: the spool never drives below `spool_min_counts` nor above
//!   `spool_max_counts` (counts from the power-up position), in any command.
//! * `Released` — duty 0 on a geared motor would leave the string as it was (and the next
//!   stance foot would land on a string wound to the extended angle). So the spool re-spools
//!   to its rest geometry: from the last driven tick (spool `s`, measured angle `m`) it pays
//!   out to `s − counts_per_ankle_rad·(m − m_start) − slack_counts`, where `m_start` is the
//!   angle measured at the first tick of that drive (the push began there, at the taut
//!   angle): the string then becomes taut again `slack_counts` below the angle where the
//!   push began, whether the push was cut short or reached its hold (a fixed pay-out from the
//!   last hold would leave the string too long after a short push and too short after a full
//!   one). The default slack is 0: the walker falls onto the resting string, and every
//!   count of slack delays the catch (and so the push's real start) behind the setpoint
//!   profile, which starts when the taut angle is measured; a rest a little above the taut
//!   angle is harmless on a back-drivable gearbox (the load pays the string out to it). A bounded move at `release_max_duty`, then the power stage switches off. Without a
//!   previous drive (power-up) there is nothing to pay out: off. A PD move (error and
//!   spool rate) at up to `release_max_duty`, done when the spool is at the target and at
//!   rest — then the stage switches off (switched off while still turning, the motor would
//!   coast far past it). Supervised: if the pay-out error does not improve for
//!   `release_stall_ticks` ticks (jammed, or a reversed motor winding in), the stage goes
//!   off and `ReleaseStalled` is reported.
//! * [`SpoolMotor::stop_now`] (emergency stop): the stage off at once, any pay-out abandoned.
//! * Over-current: above `current_limit_a` the bridge is off for that tick (chopping). A leaky
//!   count adds one per reading over the limit and takes one off per reading under it *taken
//!   while the stage was driving*; readings with the stage off (the current decays at once)
//!   leave it as it is, so a stalled motor that is chopped every other tick still latches.
//!   At `overcurrent_ticks` the actuator latches off and reports `OverCurrent` until it has
//!   been commanded `Released` for `overcurrent_cooldown_ticks` ticks.
//! * A failed spool or current reading, a bridge error, or a pay-out that does not reach its
//!   target in `release_timeout_ticks`: off and an error (the node raises `Actuator` and goes
//!   `Safe`).

use crate::convert::saturating_i32;
use crate::drivers::actuator::{Actuator, ActuatorError};
use crate::reflex::ActuatorCommand;

/// A peripheral that failed (timer, ADC, encoder timer).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HardwareError;

/// Two half-bridges of a three-phase power stage.
pub trait HalfBridges {
    /// Drive with a signed duty in [−1, 1] (positive: wind the string in); enables the
    /// outputs when they were off.
    ///
    /// # Errors
    /// [`HardwareError`] when the timer refused the setting.
    fn drive(&mut self, signed_duty: f32) -> Result<(), HardwareError>;
    /// Every switch off (on the STM32: main output enable cleared, outputs at their idle level).
    fn off(&mut self);
}

/// The spool's position sensor (a quadrature encoder on the motor shaft).
pub trait SpoolEncoder {
    /// Spool position \[counts\], growing as the string winds in.
    ///
    /// # Errors
    /// [`HardwareError`] when the position cannot be read.
    fn spool_counts(&mut self) -> Result<i32, HardwareError>;
}

/// The motor-current measurement.
pub trait CurrentSense {
    /// Magnitude of the motor current \[A\].
    ///
    /// # Errors
    /// [`HardwareError`] when the converter failed.
    fn motor_current_a(&mut self) -> Result<f32, HardwareError>;
}

/// Gains and limits of the spool motor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpoolMotorConfig {
    /// Duty per radian of ankle-angle error while holding [1/rad].
    pub kp_per_rad: f32,
    /// Duty per radian per second of error rate (setpoint rate − the spool's rate as an
    /// ankle rate) [s/rad].
    pub kd_s_per_rad: f32,
    /// Control period \[s\] (the rates are differences over one tick).
    pub tick_s: f32,
    /// Spool counts per radian of ankle angle while the string is taut: the build's gearing
    /// (encoder counts per motor turn × gear ratio × lever arm / spool radius / 2π). Measured
    /// at bring-up (wind the taut string over a known ankle angle).
    pub counts_per_ankle_rad: f32,
    /// Largest duty while holding (0..1].
    pub max_duty: f32,
    /// Current limit \[A\].
    pub current_limit_a: f32,
    /// Level of the leaky over-current count (one up per reading over the limit, one down per
    /// driven reading under it) at which the actuator latches off.
    pub overcurrent_ticks: u16,
    /// Ticks of `Released` that clear the over-current latch.
    pub overcurrent_cooldown_ticks: u16,
    /// On release, the string is re-spooled this many counts below the geometry in which it
    /// was taut at the angle where the last push began. Default 0 (see the module
    /// documentation); a gearbox that cannot be back-driven would need the pay-out's
    /// tolerance here, so that a rest above the taut angle cannot hold the ankle off it.
    pub slack_counts: i32,
    /// Duty per count of pay-out error.
    pub release_kp_per_count: f32,
    /// Duty per count-per-tick of spool rate while paying out (braking ahead of the target).
    pub release_kd_per_count_per_tick: f32,
    /// Largest duty while paying out (0..1].
    pub release_max_duty: f32,
    /// Pay-out done within this many counts.
    pub release_tolerance_counts: i32,
    /// Pay-out must finish within this many ticks.
    pub release_timeout_ticks: u16,
    /// Pay-out aborted when its error has not improved for this many ticks.
    pub release_stall_ticks: u16,
    /// Largest pay-out \[counts\] below the spool position where a hold began, while holding.
    pub hold_payout_counts: i32,
    /// Soft limit: no drive below this spool position [counts from power-up].
    pub spool_min_counts: i32,
    /// Soft limit: no drive above this spool position [counts from power-up].
    pub spool_max_counts: i32,
}

impl Default for SpoolMotorConfig {
    /// PD 40 /rad and 0.5 s/rad up to 80 % duty at 1 kHz; 16 297 counts per ankle radian (the
    /// assumed build: 1024 counts per motor turn, gear 25:1, lever arm 20 mm, spool radius
    /// 5 mm, docs/firmware.md); 4 A limit (5 ticks to latch, 0.5 s to clear); release
    /// re-spools to the push's start geometry (no slack) at up to 30 % duty within
    /// 0.3 s (done within 16 counts, at rest), aborted after 50 ms without progress; a hold pays out at most 2000 counts
    /// (0.12 rad); soft limits ±60 000 counts (±3.7 rad of ankle).
    fn default() -> Self {
        SpoolMotorConfig {
            kp_per_rad: 40.0,
            kd_s_per_rad: 0.5,
            tick_s: 0.001,
            counts_per_ankle_rad: 16_297.0,
            max_duty: 0.8,
            current_limit_a: 4.0,
            overcurrent_ticks: 5,
            overcurrent_cooldown_ticks: 500,
            slack_counts: 0,
            release_kp_per_count: 0.003,
            release_kd_per_count_per_tick: 0.02,
            release_max_duty: 0.3,
            release_tolerance_counts: 16,
            release_timeout_ticks: 300,
            release_stall_ticks: 50,
            hold_payout_counts: 2000,
            spool_min_counts: -60_000,
            spool_max_counts: 60_000,
        }
    }
}

/// What the power stage did in the last tick (for logs and tests).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StageOutput {
    /// Switches off.
    Off,
    /// Driving at this signed duty.
    Duty(f32),
}

/// The DC gear motor on two half-bridges.
pub struct SpoolMotor<B, E, I> {
    bridge: B,
    encoder: E,
    current: I,
    config: SpoolMotorConfig,
    /// Spool position and measured angle of the last driven tick.
    held_at: Option<(i32, f32)>,
    /// Measured angle at the first driven tick since the last release.
    drive_start_rad: Option<f32>,
    /// Setpoint and spool position of the previous driven tick (for the rates).
    previous: Option<(f32, i32)>,
    hold_anchor: Option<i32>,
    release_target: Option<i32>,
    release_ticks: u16,
    release_best_error: i32,
    /// Spool position at the previous pay-out tick.
    release_last: Option<i32>,
    release_stall: u16,
    over_ticks: u16,
    last_spool: Option<i32>,
    moving: bool,
    latched: bool,
    cooldown: u16,
    output: StageOutput,
}

impl<B: HalfBridges, E: SpoolEncoder, I: CurrentSense> SpoolMotor<B, E, I> {
    /// Wrap the power stage and its sensors; the stage is switched off now.
    pub fn new(mut bridge: B, encoder: E, current: I, config: SpoolMotorConfig) -> Self {
        bridge.off();
        SpoolMotor {
            bridge,
            encoder,
            current,
            config,
            held_at: None,
            drive_start_rad: None,
            previous: None,
            hold_anchor: None,
            release_target: None,
            release_ticks: 0,
            release_best_error: i32::MAX,
            release_last: None,
            release_stall: 0,
            over_ticks: 0,
            last_spool: None,
            moving: false,
            latched: false,
            cooldown: 0,
            output: StageOutput::Off,
        }
    }

    /// What the stage did in the last tick.
    pub fn output(&self) -> StageOutput {
        self.output
    }

    /// True while the over-current latch holds the stage off.
    pub fn overcurrent_latched(&self) -> bool {
        self.latched
    }

    /// The power stage.
    pub fn bridge(&self) -> &B {
        &self.bridge
    }

    fn off(&mut self) {
        self.bridge.off();
        self.output = StageOutput::Off;
    }

    fn drive(&mut self, duty: f32) -> Result<(), ActuatorError> {
        match self.bridge.drive(duty) {
            Ok(()) => {
                self.output = StageOutput::Duty(duty);
                Ok(())
            }
            Err(HardwareError) => {
                self.off();
                Err(ActuatorError::Bridge)
            }
        }
    }

    /// The duty with the soft limits applied: no drive further past a limit.
    fn soft_limited(&self, spool: i32, duty: f32) -> f32 {
        if (duty < 0.0 && spool <= self.config.spool_min_counts)
            || (duty > 0.0 && spool >= self.config.spool_max_counts)
        {
            0.0
        } else {
            duty
        }
    }

    /// Emergency stop: every switch off at once (MOE cleared), the pay-out and the hold
    /// forgotten (the string's state is not known after a stop).
    pub fn stop_now(&mut self) {
        self.off();
        self.held_at = None;
        self.drive_start_rad = None;
        self.previous = None;
        self.hold_anchor = None;
        self.release_target = None;
    }

    fn fail(&mut self, e: ActuatorError) -> Result<(), ActuatorError> {
        self.off();
        Err(e)
    }

    /// Where the string is re-spooled to after a drive that ended at spool `s` with the
    /// measured angle `m`, having begun at the measured angle `m_start`.
    fn rest_target(&self, s: i32, m: f32, m_start: f32) -> i32 {
        let back = self.config.counts_per_ankle_rad * (m - m_start);
        // Saturating float-to-int conversion; a NaN or infinite angle gives 0 counts back.
        let back = if back.is_finite() {
            saturating_i32(back)
        } else {
            0
        };
        s.saturating_sub(back.max(0))
            .saturating_sub(self.config.slack_counts)
            .max(self.config.spool_min_counts)
    }

    fn release(&mut self, spool: i32) -> Result<(), ActuatorError> {
        self.hold_anchor = None;
        self.previous = None;
        let start = self.drive_start_rad.take();
        if let Some((s, m)) = self.held_at.take() {
            let target = self.rest_target(s, m, start.unwrap_or(m));
            self.release_target = Some(target);
            self.release_ticks = 0;
            self.release_best_error = i32::MAX;
            self.release_last = None;
            self.release_stall = 0;
        }
        let Some(target) = self.release_target else {
            self.off();
            return Ok(());
        };
        let error = target.saturating_sub(spool);
        // Spool rate [counts per tick]; a pay-out is done at the target *and* at rest (a
        // motor switched off while still turning would coast far past it).
        let rate = self.release_last.map_or(0, |p| spool.saturating_sub(p));
        self.release_last = Some(spool);
        if error.abs() <= self.config.release_tolerance_counts && rate.abs() <= 1 {
            self.release_target = None;
            self.off();
            return Ok(());
        }
        self.release_ticks = self.release_ticks.saturating_add(1);
        if self.release_ticks > self.config.release_timeout_ticks {
            self.release_target = None;
            return self.fail(ActuatorError::ReleaseTimeout);
        }
        let size = error.saturating_abs();
        if size < self.release_best_error {
            self.release_best_error = size;
            self.release_stall = 0;
        } else {
            self.release_stall = self.release_stall.saturating_add(1);
        }
        // No progress for the stall time: jammed, or a reversed motor winding in (the error
        // never shrinks). A motor still coasting on from the drive, or braking after an
        // overshoot, makes progress again within it.
        if self.release_stall >= self.config.release_stall_ticks {
            self.release_target = None;
            return self.fail(ActuatorError::ReleaseStalled);
        }
        let m = self.config.release_max_duty;
        let d = (self.config.release_kp_per_count * error as f32
            - self.config.release_kd_per_count_per_tick * rate as f32)
            .clamp(-m, m);
        let d = self.soft_limited(spool, d);
        self.drive(d)
    }
}

impl<B: HalfBridges, E: SpoolEncoder, I: CurrentSense> Actuator for SpoolMotor<B, E, I> {
    fn string_moving(&self) -> bool {
        self.moving
    }

    fn has_spool_sensor(&self) -> bool {
        true
    }

    fn stop(&mut self) -> Result<(), ActuatorError> {
        self.stop_now();
        Ok(())
    }

    fn apply(
        &mut self,
        command: ActuatorCommand,
        measured_angle_rad: Option<f32>,
    ) -> Result<(), ActuatorError> {
        let released = command == ActuatorCommand::Released;
        let driven_before = matches!(self.output, StageOutput::Duty(d) if d != 0.0);
        if self.latched {
            self.off();
            self.cooldown = if released {
                self.cooldown.saturating_add(1)
            } else {
                0
            };
            if self.cooldown < self.config.overcurrent_cooldown_ticks {
                return Err(ActuatorError::OverCurrent);
            }
            self.latched = false;
            self.over_ticks = 0;
            // The string's state is unknown after the latch: nothing to pay out from.
            self.held_at = None;
            self.drive_start_rad = None;
            self.previous = None;
            self.hold_anchor = None;
            self.release_target = None;
        }
        let Ok(amps) = self.current.motor_current_a() else {
            return self.fail(ActuatorError::CurrentSense);
        };
        if amps.is_nan() || amps.abs() > self.config.current_limit_a {
            // Over the limit (or NaN): off for this tick, latched after a run of them.
            self.over_ticks = self.over_ticks.saturating_add(1);
            self.off();
            if self.over_ticks >= self.config.overcurrent_ticks {
                self.latched = true;
                self.cooldown = 0;
                return Err(ActuatorError::OverCurrent);
            }
            return Ok(());
        }
        if driven_before {
            // Under the limit while driving: the count leaks. A reading with the stage off
            // says nothing about the motor under drive and leaves the count as it is.
            self.over_ticks = self.over_ticks.saturating_sub(1);
        }
        let Ok(spool) = self.encoder.spool_counts() else {
            self.moving = false;
            return self.fail(ActuatorError::SpoolSensor);
        };
        // Spool motion since the previous reading (at least one quadrature count).
        self.moving = self.last_spool.is_some_and(|s| s != spool);
        self.last_spool = Some(spool);
        match command {
            ActuatorCommand::Released => self.release(spool),
            ActuatorCommand::Position { ankle_angle_rad } => {
                self.release_target = None;
                let Some(m) = measured_angle_rad else {
                    return self.fail(ActuatorError::NoFeedback);
                };
                let limit = self.config.max_duty;
                let c = &self.config;
                let e = ankle_angle_rad - m;
                // Error rate: the setpoint's rate minus the spool's, as ankle rates.
                let rate = self.previous.map_or(0.0, |(s0, p0)| {
                    let spool_rate = (spool.saturating_sub(p0)) as f32 / c.counts_per_ankle_rad;
                    (ankle_angle_rad - s0 - spool_rate) / c.tick_s
                });
                let d = (c.kp_per_rad * e + c.kd_s_per_rad * rate).clamp(-limit, limit);
                if d.is_nan() {
                    return self.fail(ActuatorError::NoFeedback);
                }
                self.previous = Some((ankle_angle_rad, spool));
                self.drive_start_rad.get_or_insert(m);
                let anchor = *self.hold_anchor.get_or_insert(spool);
                // Unilateral string: pay out at most `hold_payout_counts` below the anchor.
                let floor = anchor.saturating_sub(self.config.hold_payout_counts);
                let d = if d < 0.0 && spool <= floor { 0.0 } else { d };
                let d = self.soft_limited(spool, d);
                self.held_at = Some((spool, m));
                self.drive(d)
            }
        }
    }
}

/// Extends a 16-bit hardware counter (a timer in encoder mode) to 32 bits, assuming less
/// than half a wrap (32,768 counts) between two reads. The extended position saturates at
/// the ends of `i32` (2³¹ counts, far past any spool's travel) rather than wrap to the other
/// end.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CounterUnwrap {
    last: Option<u16>,
    total: i32,
}

impl CounterUnwrap {
    /// Feed the counter's value, get the extended position.
    pub fn update(&mut self, raw: u16) -> i32 {
        if let Some(prev) = self.last {
            // The hardware counter wraps modulo 2¹⁶; the modular difference read as two's
            // complement is the signed step (|step| < 2¹⁵ between reads). Wrapping on purpose.
            #[allow(clippy::cast_possible_wrap)]
            let step = raw.wrapping_sub(prev) as i16;
            self.total = self.total.saturating_add(i32::from(step));
        } else {
            self.total = i32::from(raw);
        }
        self.last = Some(raw);
        self.total
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::cell::Cell;

    #[derive(Default)]
    struct Bridge {
        duty: Option<f32>,
        offs: u32,
        fail: bool,
    }
    impl HalfBridges for &mut Bridge {
        fn drive(&mut self, d: f32) -> Result<(), HardwareError> {
            if self.fail {
                return Err(HardwareError);
            }
            self.duty = Some(d);
            Ok(())
        }
        fn off(&mut self) {
            self.duty = None;
            self.offs += 1;
        }
    }
    struct Spool<'a>(&'a Cell<Option<i32>>);
    impl SpoolEncoder for Spool<'_> {
        fn spool_counts(&mut self) -> Result<i32, HardwareError> {
            self.0.get().ok_or(HardwareError)
        }
    }
    struct Amps<'a>(&'a Cell<Option<f32>>);
    impl CurrentSense for Amps<'_> {
        fn motor_current_a(&mut self) -> Result<f32, HardwareError> {
            self.0.get().ok_or(HardwareError)
        }
    }

    const HOLD: ActuatorCommand = ActuatorCommand::Position {
        ankle_angle_rad: 0.2,
    };

    /// A push that wound the taut string 1000 counts from the spool's position now, starting
    /// at the taut angle (−0.08 rad): a release then has 1000 counts to pay out.
    fn push_1000_counts(
        m: &mut SpoolMotor<&mut Bridge, Spool<'_>, Amps<'_>>,
        spool: &Cell<Option<i32>>,
    ) {
        let k = m.config.counts_per_ankle_rad;
        let s0 = spool.get().unwrap();
        m.apply(HOLD, Some(-0.08)).unwrap();
        spool.set(Some(s0 + 1000));
        m.apply(HOLD, Some(-0.08 + 1000.0 / k)).unwrap();
    }

    #[test]
    fn off_at_power_up_and_when_released_without_a_hold() {
        let mut b = Bridge::default();
        let spool = Cell::new(Some(0));
        let amps = Cell::new(Some(0.0));
        let mut m = SpoolMotor::new(&mut b, Spool(&spool), Amps(&amps), Default::default());
        assert_eq!(m.output(), StageOutput::Off);
        m.apply(ActuatorCommand::Released, Some(0.0)).unwrap();
        assert_eq!(m.output(), StageOutput::Off);
        assert!(m.bridge().offs >= 2 && m.bridge().duty.is_none());
    }

    #[test]
    fn holds_with_a_clamped_pd_loop_then_re_spools_to_the_rest_geometry_and_switches_off() {
        let mut b = Bridge::default();
        let spool = Cell::new(Some(10_000));
        let amps = Cell::new(Some(1.0));
        let mut m = SpoolMotor::new(&mut b, Spool(&spool), Amps(&amps), Default::default());
        // The push begins at the taut angle, −0.08 rad: 40 /rad × 0.28 rad, clamped.
        m.apply(HOLD, Some(-0.08)).unwrap();
        assert_eq!(m.output(), StageOutput::Duty(0.8), "clamped to max_duty");
        // The spool wound 4400 counts (0.27 rad of ankle) in one tick: the rate term brakes.
        spool.set(Some(14_400));
        m.apply(HOLD, Some(0.19)).unwrap();
        assert_eq!(m.output(), StageOutput::Duty(-0.8), "the rate term damps");
        m.apply(HOLD, Some(0.19)).unwrap();
        let StageOutput::Duty(d) = m.output() else {
            panic!("driving")
        };
        assert!(
            (d - 40.0 * 0.01).abs() < 1e-4,
            "still: proportional only: {d}"
        );
        // Release: back to where the string was taut at −0.08 rad (4400 counts below the last
        // hold, no slack): 10 000; at most 30 %.
        m.apply(ActuatorCommand::Released, None).unwrap();
        assert_eq!(m.output(), StageOutput::Duty(-0.3));
        // Past the target and still turning fast: the rate term brakes (clamped).
        spool.set(Some(9_950));
        m.apply(ActuatorCommand::Released, None).unwrap();
        assert_eq!(m.output(), StageOutput::Duty(0.3), "braking");
        // Within the tolerance (16 counts) but still moving: not done.
        spool.set(Some(9_995));
        m.apply(ActuatorCommand::Released, None).unwrap();
        assert!(
            matches!(m.output(), StageOutput::Duty(_)),
            "at the target, moving"
        );
        // At rest within the tolerance: off.
        m.apply(ActuatorCommand::Released, None).unwrap();
        assert_eq!(
            m.output(),
            StageOutput::Off,
            "within tolerance, at rest: off"
        );
        m.apply(ActuatorCommand::Released, None).unwrap();
        assert_eq!(m.output(), StageOutput::Off, "stays off");
    }

    #[test]
    fn a_short_push_and_a_full_one_re_spool_to_the_same_rest_geometry() {
        // The string is taut from the push's start: spool = 10 000 + K·(θ + 0.08).
        let cfg = SpoolMotorConfig::default();
        let k = cfg.counts_per_ankle_rad;
        for end_rad in [0.05f32, 0.2] {
            let mut b = Bridge::default();
            let spool = Cell::new(Some(10_000));
            let amps = Cell::new(Some(1.0));
            let mut m = SpoolMotor::new(&mut b, Spool(&spool), Amps(&amps), cfg);
            m.apply(HOLD, Some(-0.08)).unwrap();
            spool.set(Some(10_000 + (k * (end_rad + 0.08)) as i32));
            m.apply(HOLD, Some(end_rad)).unwrap();
            m.apply(ActuatorCommand::Released, None).unwrap();
            assert_eq!(
                m.release_target,
                Some(10_000 - cfg.slack_counts),
                "push ended at {end_rad}"
            );
        }
    }

    /// The DC gear motor of the simulator's plant (`sim/sil/src/spool_plant.rs`, docs/sil.md)
    /// reduced to the spool encoder: driven at duty `d` its rate relaxes towards 157.5·d
    /// counts per tick with the 25 ms electrical-mechanical time constant; switched off it
    /// coasts against its Coulomb friction (0.163 counts per tick², about 1000 rad/s² at
    /// the motor).
    struct MotorCounts {
        counts: f64,
        rate: f64,
    }
    impl MotorCounts {
        fn tick(&mut self, stage: StageOutput) {
            match stage {
                StageOutput::Duty(d) => {
                    let target = 157.5 * f64::from(d);
                    self.rate = target + (self.rate - target) * (-1.0f64 / 25.0).exp();
                }
                StageOutput::Off => {
                    let slowed = self.rate.abs() - 0.163;
                    self.rate = self.rate.signum() * slowed.max(0.0);
                }
            }
            self.counts += self.rate;
        }
    }

    #[test]
    fn the_re_spool_leaves_the_string_taut_at_the_push_start_within_its_tolerance() {
        // The walker falls onto the resting string at about 0.53 rad/s (8.6 counts per
        // tick, `wisse3d` at the taut angle): every count the string rests below the angle
        // where the push begins delays the catch, and a catch late by 8 ms (the former 49
        // counts of slack, landing 20–30 counts lower still) made the walk's slow pelvic
        // roll grow until it fell (docs/sil.md, "The motor plant"). A full push from the
        // taut angle (−0.08 rad at spool 10 000, taut) to 0.2 rad, released while the motor
        // still winds at the push's end rate; the pay-out runs on the motor above until the
        // stage is off: the string rests where it was taut at the push's start, within the
        // pay-out's tolerance (16 counts, 1 mrad: under 2 ms of the walker's fall).
        let cfg = SpoolMotorConfig::default();
        let k = f64::from(cfg.counts_per_ankle_rad);
        let mut b = Bridge::default();
        let spool = Cell::new(Some(10_000));
        let amps = Cell::new(Some(1.0));
        let mut m = SpoolMotor::new(&mut b, Spool(&spool), Amps(&amps), cfg);
        let start = -0.08f32;
        m.apply(HOLD, Some(start)).unwrap();
        let end = 0.2f64;
        let s_end = 10_000.0 + k * (end + 0.08);
        spool.set(Some(s_end as i32));
        m.apply(HOLD, Some(end as f32)).unwrap();
        // 1.5 rad/s of ankle at the push's end: 24 counts per tick.
        let mut motor = MotorCounts {
            counts: s_end,
            rate: 1.5 * k * 1e-3,
        };
        let mut ticks = 0;
        loop {
            spool.set(Some(motor.counts.floor() as i32));
            m.apply(ActuatorCommand::Released, None).unwrap();
            let stage = m.output();
            if stage == StageOutput::Off {
                break;
            }
            motor.tick(stage);
            ticks += 1;
            assert!(ticks < cfg.release_timeout_ticks, "pay-out unfinished");
        }
        let rest = spool.get().unwrap();
        assert!(
            (rest - 10_000).abs() <= cfg.release_tolerance_counts,
            "the string rests {} counts from where it was taut at the push's start (after {ticks} ticks)",
            rest - 10_000
        );
    }

    #[test]
    fn a_jammed_pay_out_is_aborted_off_after_the_stall_time() {
        let mut b = Bridge::default();
        let spool = Cell::new(Some(0));
        let amps = Cell::new(Some(0.5));
        let cfg = SpoolMotorConfig::default();
        let mut m = SpoolMotor::new(&mut b, Spool(&spool), Amps(&amps), cfg);
        push_1000_counts(&mut m, &spool);
        let mut ticks = 0;
        let result = loop {
            ticks += 1;
            let r = m.apply(ActuatorCommand::Released, None);
            if r.is_err() || ticks > cfg.release_timeout_ticks {
                break r;
            }
        };
        assert_eq!(result, Err(ActuatorError::ReleaseStalled));
        assert_eq!(
            ticks,
            cfg.release_stall_ticks + 1,
            "aborted at the stall time"
        );
        assert_eq!(m.output(), StageOutput::Off);
        assert_eq!(m.apply(ActuatorCommand::Released, None), Ok(()));
        assert_eq!(m.output(), StageOutput::Off);
    }

    #[test]
    fn a_pay_out_moving_the_wrong_way_is_aborted_off() {
        let mut b = Bridge::default();
        let spool = Cell::new(Some(10_000));
        let amps = Cell::new(Some(0.5));
        let cfg = SpoolMotorConfig::default();
        let mut m = SpoolMotor::new(&mut b, Spool(&spool), Amps(&amps), cfg);
        push_1000_counts(&mut m, &spool);
        // Reversed motor: the negative duty winds in; the error grows tick by tick and never
        // shrinks: aborted at the stall time.
        let mut result = Ok(());
        let mut ticks = 0;
        for k in 1..200 {
            ticks = k;
            result = m.apply(ActuatorCommand::Released, None);
            if result.is_err() {
                break;
            }
            assert!(matches!(m.output(), StageOutput::Duty(d) if d < 0.0));
            spool.set(Some(11_000 + 20 * k));
        }
        assert_eq!(result, Err(ActuatorError::ReleaseStalled));
        assert_eq!(ticks, i32::from(cfg.release_stall_ticks) + 1);
        assert_eq!(m.output(), StageOutput::Off);
    }

    #[test]
    fn a_motor_coasting_on_from_the_push_is_not_a_wrong_way_pay_out() {
        let mut b = Bridge::default();
        let spool = Cell::new(Some(10_000));
        let amps = Cell::new(Some(0.5));
        let cfg = SpoolMotorConfig::default();
        let mut m = SpoolMotor::new(&mut b, Spool(&spool), Amps(&amps), cfg);
        push_1000_counts(&mut m, &spool);
        // The motor winds on for a few ticks after the release (decelerating), then pays out.
        for (k, s) in [11_030, 11_050, 11_060, 11_062, 11_050, 11_000, 10_900]
            .into_iter()
            .enumerate()
        {
            assert_eq!(m.apply(ActuatorCommand::Released, None), Ok(()), "tick {k}");
            spool.set(Some(s));
        }
    }

    #[test]
    fn a_stop_switches_off_at_once_and_forgets_the_pay_out() {
        let mut b = Bridge::default();
        let spool = Cell::new(Some(10_000));
        let amps = Cell::new(Some(0.5));
        let mut m = SpoolMotor::new(&mut b, Spool(&spool), Amps(&amps), Default::default());
        push_1000_counts(&mut m, &spool);
        m.apply(ActuatorCommand::Released, None).unwrap();
        assert!(
            matches!(m.output(), StageOutput::Duty(d) if d < 0.0),
            "paying out"
        );
        assert_eq!(Actuator::stop(&mut m), Ok(()));
        assert_eq!(m.output(), StageOutput::Off);
        m.apply(ActuatorCommand::Released, None).unwrap();
        assert_eq!(
            m.output(),
            StageOutput::Off,
            "no pay-out resumed after a stop"
        );
    }

    #[test]
    fn hold_pays_out_at_most_the_bound_and_respects_the_soft_limits() {
        let mut b = Bridge::default();
        let spool = Cell::new(Some(1_000));
        let amps = Cell::new(Some(0.5));
        // Proportional only: the bounds, not the rate term, are under test.
        let cfg = SpoolMotorConfig {
            kd_s_per_rad: 0.0,
            ..SpoolMotorConfig::default()
        };
        let mut m = SpoolMotor::new(&mut b, Spool(&spool), Amps(&amps), cfg);
        // Setpoint below the measured angle: the loop wants to pay out.
        let want_out = ActuatorCommand::Position {
            ankle_angle_rad: -0.5,
        };
        m.apply(want_out, Some(0.0)).unwrap();
        assert_eq!(m.output(), StageOutput::Duty(-0.8));
        spool.set(Some(1_000 - cfg.hold_payout_counts + 1));
        m.apply(want_out, Some(0.0)).unwrap();
        assert_eq!(m.output(), StageOutput::Duty(-0.8), "inside the bound");
        spool.set(Some(1_000 - cfg.hold_payout_counts));
        m.apply(want_out, Some(0.0)).unwrap();
        assert_eq!(
            m.output(),
            StageOutput::Duty(0.0),
            "bound reached: no more pay-out"
        );
        m.apply(HOLD, Some(0.0)).unwrap();
        assert_eq!(
            m.output(),
            StageOutput::Duty(0.8),
            "winding in stays allowed"
        );
        // Soft limits, absolute.
        spool.set(Some(cfg.spool_max_counts));
        m.apply(HOLD, Some(0.0)).unwrap();
        assert_eq!(
            m.output(),
            StageOutput::Duty(0.0),
            "no wind-in past the upper limit"
        );
        let mut b2 = Bridge::default();
        let spool2 = Cell::new(Some(cfg.spool_min_counts));
        let mut m2 = SpoolMotor::new(&mut b2, Spool(&spool2), Amps(&amps), cfg);
        m2.apply(HOLD, Some(0.0)).unwrap();
        m2.apply(want_out, Some(0.0)).unwrap();
        assert_eq!(
            m2.output(),
            StageOutput::Duty(0.0),
            "no pay-out past the lower limit"
        );
    }

    #[test]
    fn a_stalled_motor_whose_current_collapses_while_off_still_latches() {
        let mut b = Bridge::default();
        let spool = Cell::new(Some(0));
        let amps = Cell::new(Some(0.0));
        let cfg = SpoolMotorConfig::default();
        let mut m = SpoolMotor::new(&mut b, Spool(&spool), Amps(&amps), cfg);
        let mut tripped_at = None;
        for tick in 0..100 {
            // Stalled: over the limit whenever the stage drove in the last tick, near zero
            // when it was off (the current decays within the tick).
            let driven = matches!(m.output(), StageOutput::Duty(d) if d != 0.0);
            amps.set(Some(if driven { 6.0 } else { 0.1 }));
            if m.apply(HOLD, Some(0.0)) == Err(ActuatorError::OverCurrent) {
                tripped_at = Some(tick);
                break;
            }
        }
        let tripped_at = tripped_at.expect("the latch must trip on a stalled motor");
        assert!(
            tripped_at < 2 * cfg.overcurrent_ticks as usize + 2,
            "{tripped_at}"
        );
        assert!(m.overcurrent_latched());
        for _ in 0..100 {
            assert_eq!(m.apply(HOLD, Some(0.0)), Err(ActuatorError::OverCurrent));
            assert_eq!(m.output(), StageOutput::Off, "stays tripped");
        }
    }

    #[test]
    fn over_current_chops_then_latches_until_released_long_enough() {
        let mut b = Bridge::default();
        let spool = Cell::new(Some(0));
        let amps = Cell::new(Some(4.5));
        let cfg = SpoolMotorConfig::default();
        let mut m = SpoolMotor::new(&mut b, Spool(&spool), Amps(&amps), cfg);
        for _ in 1..cfg.overcurrent_ticks {
            assert_eq!(m.apply(HOLD, Some(0.0)), Ok(()));
            assert_eq!(m.output(), StageOutput::Off, "chopped");
        }
        assert_eq!(m.apply(HOLD, Some(0.0)), Err(ActuatorError::OverCurrent));
        assert!(m.overcurrent_latched());
        amps.set(Some(0.0));
        // Holding keeps the latch; only Released for the cool-down clears it.
        for _ in 0..1000 {
            assert_eq!(m.apply(HOLD, Some(0.0)), Err(ActuatorError::OverCurrent));
        }
        for _ in 1..cfg.overcurrent_cooldown_ticks {
            assert_eq!(
                m.apply(ActuatorCommand::Released, None),
                Err(ActuatorError::OverCurrent)
            );
            assert_eq!(m.output(), StageOutput::Off);
        }
        assert_eq!(m.apply(ActuatorCommand::Released, None), Ok(()));
        assert!(!m.overcurrent_latched());
        assert_eq!(
            m.output(),
            StageOutput::Off,
            "nothing to pay out after a latch"
        );
        amps.set(Some(f32::NAN));
        for _ in 0..cfg.overcurrent_ticks {
            let _ = m.apply(HOLD, Some(0.0));
        }
        assert!(
            m.overcurrent_latched(),
            "NaN current counts as over the limit"
        );
    }

    #[test]
    fn failed_sensors_and_bridge_switch_off() {
        let mut b = Bridge::default();
        let spool = Cell::new(Some(0));
        let amps = Cell::new(None);
        {
            let mut m = SpoolMotor::new(&mut b, Spool(&spool), Amps(&amps), Default::default());
            assert_eq!(m.apply(HOLD, Some(0.0)), Err(ActuatorError::CurrentSense));
            amps.set(Some(0.0));
            spool.set(None);
            assert_eq!(m.apply(HOLD, Some(0.0)), Err(ActuatorError::SpoolSensor));
            spool.set(Some(0));
            assert_eq!(m.apply(HOLD, None), Err(ActuatorError::NoFeedback));
            assert_eq!(m.output(), StageOutput::Off);
        }
        b.fail = true;
        let mut m = SpoolMotor::new(&mut b, Spool(&spool), Amps(&amps), Default::default());
        assert_eq!(m.apply(HOLD, Some(0.0)), Err(ActuatorError::Bridge));
        assert_eq!(m.output(), StageOutput::Off);
    }

    #[test]
    fn counter_unwrap_follows_wraps_both_ways() {
        let mut u = CounterUnwrap::default();
        assert_eq!(u.update(65_000), 65_000);
        assert_eq!(u.update(100), 65_000 + 636);
        assert_eq!(u.update(65_500), 65_000 + 636 - 136);
    }
}
