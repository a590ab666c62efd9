//! The string actuator: a DC motor through PWM and a direction pin, or a position servo (the
//! B-G431B-ESC1's two half-bridges are in [`crate::drivers::spool_motor`]).

use embedded_hal::digital::{Error as _, ErrorKind as PinErrorKind, OutputPin};
use embedded_hal::pwm::{Error as _, ErrorKind as PwmErrorKind, SetDutyCycle};

use crate::convert::duty_from_fraction;
use crate::reflex::ActuatorCommand;

/// Why the actuator could not apply a command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ActuatorError {
    /// The PWM channel failed.
    Pwm(PwmErrorKind),
    /// The direction pin failed.
    Pin(PinErrorKind),
    /// A position command without a valid angle measurement (closed loop impossible).
    NoFeedback,
    /// The motor current stayed over the limit; the power stage is latched off.
    OverCurrent,
    /// The motor-current measurement failed.
    CurrentSense,
    /// The spool position could not be read.
    SpoolSensor,
    /// The power stage refused a setting.
    Bridge,
    /// Paying out the slack on release did not finish in time (jammed spool?).
    ReleaseTimeout,
    /// The pay-out made no progress or moved the wrong way (jammed or reversed); stage off.
    ReleaseStalled,
}

impl ActuatorError {
    /// A small code for the `Actuator` fault event's `detail`: 1 PWM, 2 pin, 3 no feedback,
    /// 4 over-current, 5 current sense, 6 spool sensor, 7 bridge, 8 release timeout,
    /// 9 release stalled (the spool made no progress paying out: jammed, reversed, or a
    /// spool encoder that stopped).
    pub fn detail(&self) -> i16 {
        match self {
            ActuatorError::Pwm(_) => 1,
            ActuatorError::Pin(_) => 2,
            ActuatorError::NoFeedback => 3,
            ActuatorError::OverCurrent => 4,
            ActuatorError::CurrentSense => 5,
            ActuatorError::SpoolSensor => 6,
            ActuatorError::Bridge => 7,
            ActuatorError::ReleaseTimeout => 8,
            ActuatorError::ReleaseStalled => 9,
        }
    }
}

/// Anything that can hold the string at an ankle angle or release it.
pub trait Actuator {
    /// Apply `command`; `measured_angle_rad` is the current ankle angle estimate, `None` when
    /// the encoder gives none.
    ///
    /// # Errors
    /// [`ActuatorError`]; the node raises an `Actuator` fault on the next tick.
    fn apply(
        &mut self,
        command: ActuatorCommand,
        measured_angle_rad: Option<f32>,
    ) -> Result<(), ActuatorError>;

    /// True when the actuator moved the string in the last [`Actuator::apply`] (a spool
    /// sensor saw it turn). The default, for actuators without such a sensor: false (the
    /// node then has no evidence that a hold moves the ankle).
    fn string_moving(&self) -> bool {
        false
    }

    /// True when the actuator has a spool sensor behind [`Actuator::string_moving`] (the node
    /// then cross-checks it against the ankle reading: `SpoolStuck`). The default: false.
    fn has_spool_sensor(&self) -> bool {
        false
    }

    /// Emergency stop: the actuator off at once, without a release sequence. The default
    /// applies `Released` (for actuators whose release is already immediate).
    ///
    /// # Errors
    /// As [`Actuator::apply`].
    fn stop(&mut self) -> Result<(), ActuatorError> {
        self.apply(ActuatorCommand::Released, None)
    }
}

impl<T: Actuator + ?Sized> Actuator for &mut T {
    fn apply(&mut self, c: ActuatorCommand, m: Option<f32>) -> Result<(), ActuatorError> {
        T::apply(self, c, m)
    }
    fn stop(&mut self) -> Result<(), ActuatorError> {
        T::stop(self)
    }
    fn string_moving(&self) -> bool {
        T::string_moving(self)
    }
    fn has_spool_sensor(&self) -> bool {
        T::has_spool_sensor(self)
    }
}

/// Gains of the motor's proportional position loop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PwmDirGains {
    /// Duty fraction per radian of error [1/rad].
    pub kp_per_rad: f32,
    /// Largest duty fraction (0..1] (limits current and speed).
    pub max_duty: f32,
}

impl Default for PwmDirGains {
    /// 10 /rad: full duty from 0.1 rad of error, limited to 80 %.
    fn default() -> Self {
        PwmDirGains {
            kp_per_rad: 10.0,
            max_duty: 0.8,
        }
    }
}

/// A DC motor winding the string, driven by PWM magnitude and a direction pin, closed around
/// the ankle angle (the string is taut whenever the actuator holds it).
pub struct PwmDirActuator<P, D> {
    pwm: P,
    dir: D,
    gains: PwmDirGains,
}

impl<P: SetDutyCycle, D: OutputPin> PwmDirActuator<P, D> {
    /// Wrap a PWM channel and a direction pin (high: shorten the string).
    pub fn new(pwm: P, dir: D, gains: PwmDirGains) -> Self {
        PwmDirActuator { pwm, dir, gains }
    }

    /// Give the channel and pin back.
    pub fn release(self) -> (P, D) {
        (self.pwm, self.dir)
    }

    /// The signed duty fraction for an error \[rad\] (positive: shorten the string).
    pub fn duty_for_error(&self, error_rad: f32) -> f32 {
        let d = self.gains.kp_per_rad * error_rad;
        d.clamp(-self.gains.max_duty, self.gains.max_duty)
    }

    fn set(&mut self, signed_duty: f32) -> Result<(), ActuatorError> {
        if signed_duty >= 0.0 {
            self.dir.set_high()
        } else {
            self.dir.set_low()
        }
        .map_err(|e| ActuatorError::Pin(e.kind()))?;
        let duty = duty_from_fraction(libm::fabsf(signed_duty), self.pwm.max_duty_cycle());
        self.pwm
            .set_duty_cycle(duty)
            .map_err(|e| ActuatorError::Pwm(e.kind()))
    }
}

impl<P: SetDutyCycle, D: OutputPin> Actuator for PwmDirActuator<P, D> {
    fn apply(
        &mut self,
        command: ActuatorCommand,
        measured_angle_rad: Option<f32>,
    ) -> Result<(), ActuatorError> {
        match command {
            ActuatorCommand::Released => self.set(0.0),
            ActuatorCommand::Position { ankle_angle_rad } => match measured_angle_rad {
                Some(m) => {
                    let d = self.duty_for_error(ankle_angle_rad - m);
                    self.set(d)
                }
                None => {
                    self.set(0.0)?;
                    Err(ActuatorError::NoFeedback)
                }
            },
        }
    }
}

/// Pulse widths of a position servo.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ServoRange {
    /// PWM period \[µs\] (20 000 for 50 Hz servos).
    pub period_us: f32,
    /// Pulse for `min_angle_rad` \[µs\].
    pub min_pulse_us: f32,
    /// Pulse for `max_angle_rad` \[µs\].
    pub max_pulse_us: f32,
    /// Ankle angle at the shortest pulse \[rad\].
    pub min_angle_rad: f32,
    /// Ankle angle at the longest pulse \[rad\].
    pub max_angle_rad: f32,
}

impl Default for ServoRange {
    /// 50 Hz, 1.0–2.0 ms for −0.3…0.4 rad of ankle angle.
    fn default() -> Self {
        ServoRange {
            period_us: 20_000.0,
            min_pulse_us: 1_000.0,
            max_pulse_us: 2_000.0,
            min_angle_rad: -0.3,
            max_angle_rad: 0.4,
        }
    }
}

/// A position servo on a PWM channel; released means no pulses (the servo goes limp).
pub struct ServoActuator<P> {
    pwm: P,
    range: ServoRange,
}

impl<P: SetDutyCycle> ServoActuator<P> {
    /// Wrap a PWM channel running at `range.period_us`.
    pub fn new(pwm: P, range: ServoRange) -> Self {
        ServoActuator { pwm, range }
    }

    /// Pulse width for a setpoint \[µs\], the setpoint clamped to the servo's range.
    pub fn pulse_us(&self, ankle_angle_rad: f32) -> f32 {
        let r = &self.range;
        let a = ankle_angle_rad.clamp(r.min_angle_rad, r.max_angle_rad);
        let f = (a - r.min_angle_rad) / (r.max_angle_rad - r.min_angle_rad);
        r.min_pulse_us + f * (r.max_pulse_us - r.min_pulse_us)
    }
}

impl<P: SetDutyCycle> Actuator for ServoActuator<P> {
    fn apply(&mut self, command: ActuatorCommand, _: Option<f32>) -> Result<(), ActuatorError> {
        let duty = match command {
            ActuatorCommand::Released => 0,
            ActuatorCommand::Position { ankle_angle_rad } => {
                let f = self.pulse_us(ankle_angle_rad) / self.range.period_us;
                duty_from_fraction(f, self.pwm.max_duty_cycle())
            }
        };
        self.pwm
            .set_duty_cycle(duty)
            .map_err(|e| ActuatorError::Pwm(e.kind()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::convert::Infallible;

    #[derive(Default)]
    struct Pwm {
        duty: u16,
        fail: bool,
    }
    #[derive(Debug)]
    struct PwmFail;
    impl embedded_hal::pwm::Error for PwmFail {
        fn kind(&self) -> PwmErrorKind {
            PwmErrorKind::Other
        }
    }
    impl embedded_hal::pwm::ErrorType for Pwm {
        type Error = PwmFail;
    }
    impl SetDutyCycle for Pwm {
        fn max_duty_cycle(&self) -> u16 {
            1000
        }
        fn set_duty_cycle(&mut self, duty: u16) -> Result<(), PwmFail> {
            if self.fail {
                return Err(PwmFail);
            }
            self.duty = duty;
            Ok(())
        }
    }
    #[derive(Default)]
    struct Dir(bool);
    impl embedded_hal::digital::ErrorType for Dir {
        type Error = Infallible;
    }
    impl OutputPin for Dir {
        fn set_low(&mut self) -> Result<(), Infallible> {
            self.0 = false;
            Ok(())
        }
        fn set_high(&mut self) -> Result<(), Infallible> {
            self.0 = true;
            Ok(())
        }
    }

    #[test]
    fn pwm_dir_closes_the_loop_and_saturates() {
        let mut a = PwmDirActuator::new(Pwm::default(), Dir::default(), PwmDirGains::default());
        let pos = |x| ActuatorCommand::Position { ankle_angle_rad: x };
        a.apply(pos(0.1), Some(0.05)).unwrap();
        let (p, d) = a.release();
        assert_eq!((p.duty, d.0), (500, true));
        let mut a = PwmDirActuator::new(p, d, PwmDirGains::default());
        a.apply(pos(-0.5), Some(0.2)).unwrap();
        a.apply(ActuatorCommand::Released, Some(0.0)).unwrap();
        let (p, d) = a.release();
        assert_eq!((p.duty, d.0), (0, true));
        let mut a = PwmDirActuator::new(p, d, PwmDirGains::default());
        assert_eq!(a.duty_for_error(-1.0), -0.8);
        assert_eq!(a.apply(pos(0.1), None), Err(ActuatorError::NoFeedback));
        let (p, _) = a.release();
        assert_eq!(p.duty, 0, "no feedback: motor off");
        let mut a = PwmDirActuator::new(
            Pwm {
                duty: 0,
                fail: true,
            },
            Dir::default(),
            PwmDirGains::default(),
        );
        assert_eq!(
            a.apply(ActuatorCommand::Released, None),
            Err(ActuatorError::Pwm(PwmErrorKind::Other))
        );
    }

    #[test]
    fn servo_maps_angle_to_pulse_and_releases() {
        let mut s = ServoActuator::new(Pwm::default(), ServoRange::default());
        assert_eq!(s.pulse_us(-0.3), 1000.0);
        assert_eq!(s.pulse_us(1.0), 2000.0);
        s.apply(
            ActuatorCommand::Position {
                ankle_angle_rad: 0.4,
            },
            None,
        )
        .unwrap();
        assert_eq!(s.pwm.duty, 100);
        s.apply(ActuatorCommand::Released, None).unwrap();
        assert_eq!(s.pwm.duty, 0);
    }
}
