//! The string actuator behind the firmware's own hardware-edge trait
//! (`firmware::drivers::actuator::Actuator`).
//!
//! On the board, `PwmDirActuator` closes a proportional loop from the measured ankle angle to
//! a PWM duty and a direction pin of a DC motor. The simulator replaces that motor and its
//! loop by [`ActuatorModel`], a position servo with a rate limit and a first-order lag that
//! leaves the string slack when released: the simulated string is rigid and unilateral and
//! has no motor model, so a DC motor at zero duty would not release it, while the reflex
//! relies on the string going slack at release. [`SimActuator::apply`] gets what any
//! `Actuator` gets — the command (setpoint or release) and the measured angle — records both,
//! and integrates the servo over the tick; the orchestrator takes the tick's
//! [`ActuatorSegment`] afterwards. It never fails (`actuator_error` stays false).
//! The board's own driver over a motor plant is the alternative
//! ([`AnkleActuator::SpoolMotor`]); [`AnkleActuator`] is either.

use std::cell::RefCell;
use std::rc::Rc;

use firmware::drivers::actuator::{Actuator, ActuatorError};
use firmware::ActuatorCommand;

use crate::actuator::ActuatorModel;
use sim::engine::control::ActuatorSegment;

/// Smallest motion of the servo's string limit in one tick that its spool sensor sees, as an
/// ankle angle \[rad\]: a tenth of the ankle encoder's count (2π/16384 ≈ 0.38 mrad), since the
/// spool's quadrature encoder sits before the gearbox and resolves far finer than the ankle.
pub const SPOOL_RESOLUTION_RAD: f64 = 3.8e-5;

/// State shared by a [`SimActuator`] and the orchestrator.
#[derive(Clone, Debug)]
pub struct ActuatorLink {
    model: ActuatorModel,
    t0_s: f64,
    t1_s: f64,
    take_up_rad: f64,
    load_n_m: f64,
    segment: Option<ActuatorSegment>,
    last_command: Option<ActuatorCommand>,
    last_measured_rad: Option<f32>,
    commands: u64,
    moving: bool,
    /// The spool sensor reports no motion from now on (an injected `SpoolStuck`).
    spool_sensor_frozen: bool,
}

impl ActuatorLink {
    /// A link over a (released) servo model.
    pub fn new(model: ActuatorModel) -> Self {
        ActuatorLink {
            model,
            t0_s: 0.0,
            t1_s: 0.0,
            take_up_rad: 0.0,
            load_n_m: 0.0,
            segment: None,
            last_command: None,
            last_measured_rad: None,
            commands: 0,
            moving: false,
            spool_sensor_frozen: false,
        }
    }

    /// The coming tick `[t0_s, t1_s]`, the true ankle angle \[rad\] (where a slack string
    /// becomes taut) and the string's torque on the ankle at the tick's start [N·m] (0 while
    /// slack; over the servo's limit it stalls, see [`ActuatorModel::tick`]).
    pub fn set_tick(&mut self, t0_s: f64, t1_s: f64, take_up_rad: f64, load_n_m: f64) {
        self.t0_s = t0_s;
        self.t1_s = t1_s;
        self.take_up_rad = take_up_rad;
        self.load_n_m = load_n_m;
    }

    /// The segment of the last command applied (taken: `None` until the next command).
    pub fn take_segment(&mut self) -> Option<ActuatorSegment> {
        self.segment.take()
    }

    /// The servo model (statistics).
    pub fn model(&self) -> &ActuatorModel {
        &self.model
    }

    /// The last command applied and the measured angle it came with \[rad\].
    pub fn last_command(&self) -> Option<(ActuatorCommand, Option<f32>)> {
        self.last_command.map(|c| (c, self.last_measured_rad))
    }

    /// Commands applied.
    pub fn commands(&self) -> u64 {
        self.commands
    }

    /// The servo's spool sensor reports no motion from now on (an injected fault).
    pub fn freeze_spool_sensor(&mut self) {
        self.spool_sensor_frozen = true;
    }
}

/// The actuator; it shares its [`ActuatorLink`] with the orchestrator.
#[derive(Clone, Debug)]
pub struct SimActuator(Rc<RefCell<ActuatorLink>>);

impl SimActuator {
    /// An actuator on `link`.
    pub fn new(link: Rc<RefCell<ActuatorLink>>) -> Self {
        SimActuator(link)
    }
}

impl Actuator for SimActuator {
    fn apply(
        &mut self,
        command: ActuatorCommand,
        measured_angle_rad: Option<f32>,
    ) -> Result<(), ActuatorError> {
        let mut l = self.0.borrow_mut();
        let setpoint = match command {
            ActuatorCommand::Released => None,
            ActuatorCommand::Position { ankle_angle_rad } => Some(f64::from(ankle_angle_rad)),
        };
        let (t0, t1, take_up, load) = (l.t0_s, l.t1_s, l.take_up_rad, l.load_n_m);
        let seg = l.model.tick(t0, t1, setpoint, take_up, load);
        l.moving = !seg.released
            && !l.spool_sensor_frozen
            && (seg.p1_rad - seg.p0_rad).abs() >= SPOOL_RESOLUTION_RAD;
        l.segment = Some(seg);
        l.last_command = Some(command);
        l.last_measured_rad = measured_angle_rad;
        l.commands += 1;
        Ok(())
    }

    fn string_moving(&self) -> bool {
        self.0.borrow().moving
    }

    fn has_spool_sensor(&self) -> bool {
        true
    }
}

/// The actuator of a simulated ankle: the firmware's spool-motor driver over the motor
/// plant, or the servo model.
pub enum AnkleActuator {
    /// The board's driver ([`firmware::drivers::spool_motor::SpoolMotor`]) over
    /// [`crate::spool_plant::SpoolPlant`].
    SpoolMotor(Box<crate::hal::spool::SimSpoolMotor>),
    /// The position servo ([`SimActuator`]).
    Servo(SimActuator),
}

impl Actuator for AnkleActuator {
    fn apply(
        &mut self,
        command: ActuatorCommand,
        measured_angle_rad: Option<f32>,
    ) -> Result<(), ActuatorError> {
        match self {
            AnkleActuator::SpoolMotor(m) => m.apply(command, measured_angle_rad),
            AnkleActuator::Servo(s) => s.apply(command, measured_angle_rad),
        }
    }

    fn string_moving(&self) -> bool {
        match self {
            AnkleActuator::SpoolMotor(m) => m.string_moving(),
            AnkleActuator::Servo(s) => s.string_moving(),
        }
    }

    fn has_spool_sensor(&self) -> bool {
        match self {
            AnkleActuator::SpoolMotor(m) => m.has_spool_sensor(),
            AnkleActuator::Servo(s) => s.has_spool_sensor(),
        }
    }

    fn stop(&mut self) -> Result<(), ActuatorError> {
        match self {
            AnkleActuator::SpoolMotor(m) => m.stop(),
            AnkleActuator::Servo(s) => s.stop(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::actuator::ActuatorParams;

    #[test]
    fn commands_move_the_servo_and_are_recorded() {
        let link = Rc::new(RefCell::new(ActuatorLink::new(ActuatorModel::new(
            ActuatorParams::default(),
        ))));
        let mut a = SimActuator::new(Rc::clone(&link));
        link.borrow_mut().set_tick(0.0, 0.001, -0.05, 0.0);
        a.apply(ActuatorCommand::Released, Some(-0.05)).unwrap();
        assert!(link.borrow_mut().take_segment().unwrap().released);
        link.borrow_mut().set_tick(0.001, 0.002, -0.06, 0.0);
        let pos = ActuatorCommand::Position {
            ankle_angle_rad: -0.055,
        };
        a.apply(pos, Some(-0.0598)).unwrap();
        let seg = link.borrow_mut().take_segment().unwrap();
        assert!(!seg.released);
        assert_eq!(
            seg.p0_rad,
            -0.06 - ActuatorParams::default().take_up_slack_rad
        );
        assert!(seg.p1_rad > seg.p0_rad && seg.p1_rad < -0.055);
        let l = link.borrow();
        assert_eq!(l.last_command(), Some((pos, Some(-0.0598))));
        assert_eq!(l.commands(), 2);
        assert_eq!(l.model().stats().position_ticks, 1);
        drop(l);
        assert_eq!(link.borrow_mut().take_segment(), None, "taken once");
    }
}
