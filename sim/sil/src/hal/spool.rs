//! The board's power stage, spool encoder and current sense over the simulator's
//! [`SpoolPlant`], for the firmware's own [`SpoolMotor`] driver: the code the board runs
//! computes the duty (its PD loop on the *measured* ankle angle, its current limit, its
//! re-spool on release) and the plant turns the duty into motor current, spool motion and
//! the string's limit on the walker's ankle.

use std::cell::RefCell;
use std::rc::Rc;

use firmware::drivers::spool_motor::{
    CurrentSense, HalfBridges, HardwareError, SpoolEncoder, SpoolMotor, StageOutput,
};

use crate::spool_plant::SpoolPlant;

/// The plant, shared by the three pieces of hardware and the orchestrator.
pub type PlantLink = Rc<RefCell<SpoolPlant>>;

/// The two half-bridges: the duty the firmware sets is the plant's for the tick.
#[derive(Clone, Debug)]
pub struct SimBridges(pub PlantLink);

impl HalfBridges for SimBridges {
    fn drive(&mut self, signed_duty: f32) -> Result<(), HardwareError> {
        if !signed_duty.is_finite() {
            return Err(HardwareError);
        }
        self.0
            .borrow_mut()
            .set_stage(StageOutput::Duty(signed_duty.clamp(-1.0, 1.0)));
        Ok(())
    }

    fn off(&mut self) {
        self.0.borrow_mut().set_stage(StageOutput::Off);
    }
}

/// The spool's quadrature encoder (TIM4 on the board).
#[derive(Clone, Debug)]
pub struct SimSpoolEncoder(pub PlantLink);

impl SpoolEncoder for SimSpoolEncoder {
    fn spool_counts(&mut self) -> Result<i32, HardwareError> {
        Ok(self.0.borrow().encoder_counts())
    }
}

/// The shunt amplifiers and ADC: |motor current|, quantised.
#[derive(Clone, Debug)]
pub struct SimCurrentSense(pub PlantLink);

impl CurrentSense for SimCurrentSense {
    fn motor_current_a(&mut self) -> Result<f32, HardwareError> {
        Ok(self.0.borrow().current_reading_a() as f32)
    }
}

/// The firmware's spool-motor driver on the simulated hardware.
pub type SimSpoolMotor = SpoolMotor<SimBridges, SimSpoolEncoder, SimCurrentSense>;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spool_plant::{PlantTick, SpoolPlantParams};
    use firmware::drivers::actuator::Actuator;
    use firmware::drivers::spool_motor::SpoolMotorConfig;
    use firmware::ActuatorCommand;

    #[test]
    fn the_firmware_driver_winds_the_string_to_its_setpoint_through_the_plant() {
        let plant: PlantLink = Rc::new(RefCell::new(SpoolPlant::new(SpoolPlantParams::default())));
        let mut m = SpoolMotor::new(
            SimBridges(Rc::clone(&plant)),
            SimSpoolEncoder(Rc::clone(&plant)),
            SimCurrentSense(Rc::clone(&plant)),
            SpoolMotorConfig::default(),
        );
        // A free ankle at the limit's angle (−0.081) that follows the string (as if taut
        // without load): the measured angle is the limit.
        let mut angle = -0.081;
        for k in 0..300 {
            plant.borrow_mut().set_tick(PlantTick {
                t0_s: k as f64 * 1e-3,
                t1_s: (k + 1) as f64 * 1e-3,
                stance: true,
                ankle_rad: angle,
                engaged: true,
                load_n_m: 0.5,
            });
            m.apply(
                ActuatorCommand::Position {
                    ankle_angle_rad: 0.0,
                },
                Some(angle as f32),
            )
            .unwrap();
            let seg = plant.borrow_mut().finish_tick();
            angle = seg.p1_rad;
        }
        assert!(angle.abs() < 0.005, "settled near the setpoint: {angle}");
        assert!(m.string_moving() || angle.abs() < 0.005);
        // Released: re-spooled to where the drive began (−0.081, no slack), within the
        // pay-out's tolerance (16 counts, 1 mrad), then off.
        for k in 300..700 {
            plant.borrow_mut().set_tick(PlantTick {
                t0_s: k as f64 * 1e-3,
                t1_s: (k + 1) as f64 * 1e-3,
                stance: true,
                ankle_rad: 0.5,
                engaged: false,
                load_n_m: 0.0,
            });
            m.apply(ActuatorCommand::Released, Some(0.5)).unwrap();
            plant.borrow_mut().finish_tick();
        }
        assert_eq!(plant.borrow().stage(), StageOutput::Off);
        let limit = plant.borrow_mut().finish_tick().p1_rad;
        assert!((limit - (-0.081)).abs() <= 0.001, "{limit}");
    }
}
