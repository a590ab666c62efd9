//! A walk of the simulated walker with the firmware actuating its ankles, as `walker sil`
//! runs and reports it: its options checked ([`check_options`], [`require_ankle`],
//! [`config_from_specs`]), the walk ([`walk_with_firmware`]) and its report ([`SilRun`],
//! [`SilWalkReport`], the `walker sil --json` object). The command and the Python package's
//! `walker.sil` both build the report here, so it is written once and their numbers agree.

use std::collections::BTreeMap;

use canbus::BusStats;
use serde::Serialize;
use sim::analysis::homotopy::GaitSource;
use sim::analysis::limit_cycle::Gait;
use sim::engine::actuator::AnkleReflex;
use sim::engine::control::AnkleController;
use sim::engine::integrators::IntegratorChoice;
use sim::engine::walker::Walker;
use sim::report::{IdealGaitRecord, StartRecord, WalkGaitRecord};
use sim::stride::walk::{StepSummary, Walk, WalkFailure, WalkOptions, WalkRequest, MAX_WALK_STEPS};
use sim::stride::{Floor, StrideSettings};

use crate::config::{ActuatorChoice, SilConfig};
use crate::report::{FallCause, FaultRecord, NodeReport, SilReport};
use crate::sensors::AppliedSensorFault;
use crate::side::Side;

/// Bad input to a SIL walk: the message `walker sil` prints after `error:` (exit code 2).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct SilInputError(pub String);

/// The gait figures average this many last steps (`gait`); a walk keeps at least these step
/// summaries.
pub const GAIT_STEPS_AVERAGED: usize = 10;

/// The options checked in order: the actuator's name (`motor`, `servo`), the number of steps
/// (0 to [`MAX_WALK_STEPS`]), the emergency stop's time (finite, not negative). The actuator
/// and the steps.
///
/// # Errors
/// The first option that is wrong, named as `walker sil`'s.
pub fn check_options(
    actuator: &str,
    steps: usize,
    estop_at: Option<f64>,
) -> Result<(ActuatorChoice, usize), SilInputError> {
    let Some(actuator_choice) = ActuatorChoice::from_name(actuator) else {
        return Err(SilInputError(format!(
            "--actuator `{actuator}`: expected `motor` or `servo`"
        )));
    };
    if steps > MAX_WALK_STEPS {
        return Err(SilInputError(format!(
            "--steps must be between 0 and {MAX_WALK_STEPS}, got {steps}"
        )));
    }
    if let Some(t) = estop_at {
        if !(t.is_finite() && t >= 0.0) {
            return Err(SilInputError(format!(
                "--estop-at must be a finite walk time of 0 s or more, got {t}"
            )));
        }
    }
    Ok((actuator_choice, steps))
}

/// The ankle reflex of `walker` (scene `scene`): the firmware needs actuated ankles.
///
/// # Errors
/// The scene has none.
pub fn require_ankle(walker: &Walker, scene: &str) -> Result<AnkleReflex, SilInputError> {
    walker.ankle().cloned().ok_or_else(|| {
        SilInputError(format!(
            "scene `{scene}` has no actuated ankles (ankle_reflex)"
        ))
    })
}

/// The text forms of what a SIL walk changes in the firmware's configuration, as `walker sil`
/// takes them: `--firmware-param NAME=VALUE`, `--fault SPEC`, `--sensor-fault SPEC`.
#[derive(Clone, Copy, Debug, Default)]
pub struct Specs<'a> {
    /// Firmware parameters written to both ankles at start-up, in order.
    pub firmware_params: &'a [String],
    /// Bus faults.
    pub faults: &'a [String],
    /// Encoder faults.
    pub sensor_faults: &'a [String],
}

/// The firmware in the loop's configuration with `actuator_choice` and `specs` (the
/// firmware's own parameters unless some are written), and the parameters written, by name
/// [SI units]. No candump log, no socketcand server: the caller sets those.
///
/// # Errors
/// The first spec that cannot be read or taken, named as `walker sil`'s option.
pub fn config_from_specs(
    actuator_choice: ActuatorChoice,
    specs: Specs<'_>,
) -> Result<(SilConfig, BTreeMap<&'static str, f64>), SilInputError> {
    let mut config = SilConfig {
        actuator_choice,
        ..SilConfig::default()
    };
    for p in specs.firmware_params {
        config = config
            .with_firmware_param_str(p)
            .map_err(|e| SilInputError(format!("--firmware-param `{p}`: {e}")))?;
    }
    let firmware_params_written = config
        .firmware_param_writes()
        .iter()
        .map(|w| (crate::firmware_param::param_name(w.id), w.wire_value_f64()))
        .collect();
    for f in specs.faults {
        config = config
            .with_fault_str(f)
            .map_err(|e| SilInputError(format!("--fault `{f}`: {e}")))?;
    }
    for f in specs.sensor_faults {
        config = config
            .with_sensor_fault_str(f)
            .map_err(|e| SilInputError(format!("--sensor-fault `{f}`: {e}")))?;
    }
    Ok((config, firmware_params_written))
}

/// An error of [`crate::FirmwareInTheLoop::new`] (other than the candump log's, which the
/// caller names with its path) as bad input.
pub fn setup_error(e: &crate::SilError) -> SilInputError {
    SilInputError(format!("software in the loop: {e}"))
}

/// The stride settings of the walk with the firmware: the scene's, with
/// [`crate::SIL_INTEGRATOR`] in place of its integrator unless one was chosen
/// (`integrator_chosen`: `walker sil --integrator`, `--rtol` or `--step-s`).
pub fn walk_settings(scene_settings: &StrideSettings, integrator_chosen: bool) -> StrideSettings {
    let mut settings = scene_settings.clone();
    if !integrator_chosen {
        settings.integrator = crate::SIL_INTEGRATOR;
    }
    settings
}

/// How the walk with the firmware runs: its steps, the step summaries kept, whether it
/// records the path (and at which interval), the floor.
#[derive(Clone, Copy, Debug)]
pub struct WalkPlan {
    /// Steps to walk at most.
    pub steps: usize,
    /// Step summaries kept (the last N; at least [`GAIT_STEPS_AVERAGED`]); `None`: all.
    pub keep_steps: Option<usize>,
    /// Record the path (for an animation).
    pub record: bool,
    /// With `record`: one path sample per this interval \[s\].
    pub path_interval_s: Option<f64>,
    /// The floor.
    pub floor: Floor,
}

/// The walk from the ideal gait's start state `(q, qd)` with `controller` (the firmware in the
/// loop, or a pacing wrapper of it) actuating the ankles; `on_step` is called with each step's
/// summary.
pub fn walk_with_firmware(
    walker: &Walker,
    (q, qd): (&nalgebra::DVector<f64>, &nalgebra::DVector<f64>),
    settings: &StrideSettings,
    controller: &mut dyn AnkleController,
    plan: &WalkPlan,
    on_step: Option<&mut dyn FnMut(&StepSummary)>,
) -> Walk {
    // The gait figures average the last 10 steps: keep at least those; keeping more than
    // the walk's steps keeps them all (and a huge N never reaches the walk's arithmetic).
    let options = WalkOptions {
        record: plan.record,
        path_interval_s: plan.path_interval_s,
        keep_steps: plan
            .keep_steps
            .map(|n| n.clamp(GAIT_STEPS_AVERAGED, MAX_WALK_STEPS)),
        max_path_samples: None,
    };
    let mut request = WalkRequest::new(settings, plan.steps)
        .options(options)
        .floor(plan.floor)
        .controlled(controller);
    if let Some(f) = on_step {
        request = request.on_step(f);
    }
    sim::stride::walk::walk(walker, q, qd, request)
}

/// The walk time the host sent its first emergency stop \[s\], from the run's report (`None`
/// if it sent none).
pub fn emergency_stop_sent_s(r: &SilReport) -> Option<f64> {
    r.host
        .commands_sent
        .iter()
        .find(|(_, command)| command.contains("EmergencyStop"))
        .map(|(t_s, _)| *t_s)
}

/// The `walker sil --json` object.
#[derive(Serialize)]
pub struct SilWalkReport<'a> {
    /// Scene name.
    pub scene: &'a str,
    /// The integrator of the walk with the firmware.
    pub integrator: &'a IntegratorChoice,
    /// Steps completed.
    pub steps_completed: usize,
    /// The first failure (`null` if none).
    pub failure: Option<&'a WalkFailure>,
    /// The fault that ended the walk: the first safety-relevant fault a node raised at or
    /// before the failure (`null` without a failure, or when no node raised one: a fall the
    /// nodes did not see coming).
    pub fall_cause: Option<FallCause>,
    /// The firmware's gait over the last 10 steps that ended by the emergency stop (all
    /// steps without one; `null` if there is no such step).
    pub gait: Option<WalkGaitRecord>,
    /// Walk time the host sent the emergency stop (`--estop-at`) \[s\]; `null` if none was sent.
    pub emergency_stop_sent_s: Option<f64>,
    /// Steps completed that ended by the emergency stop (all of them without one).
    pub steps_before_emergency_stop: usize,
    /// The ideal-actuator gait.
    pub ideal_gait: IdealGaitRecord,
    /// What the walk started from: the ideal-actuator gait, as `walker gait` finds it
    /// (`gait_source`, its step period).
    pub start: StartRecord,
    /// Faults the nodes raised or cleared.
    pub node_faults: &'a [FaultRecord],
    /// The left and the right node; `nodes.<side>.parameters`: the extension profile's
    /// parameters in force as the node reported them over the bus.
    pub nodes: &'a BTreeMap<Side, NodeReport>,
    /// Firmware parameters written at start-up (`--firmware-param`), by name [SI units].
    pub firmware_params_written: BTreeMap<&'static str, f64>,
    /// Differences between the scene's extension profile (the plant's string geometry and
    /// the ideal gait) and the one the nodes report; empty when they agree.
    pub warnings: &'a [String],
    /// Bus load [-].
    pub bus_load: f64,
    /// Bus statistics.
    pub bus: &'a BusStats,
    /// Frames delivered on the bus.
    pub frames: u64,
    /// The step summaries kept (`--keep-steps`).
    pub steps: &'a [StepSummary],
    /// Injected encoder faults that took effect: `[{side, kind, t_s}]`.
    pub sensor_faults_applied: &'a [AppliedSensorFault],
    /// The ankles' actuator (`motor`, `servo`).
    pub actuator: &'static str,
    /// The floor walked over (`{kind, ...}`, as `walker walk` reports it).
    pub floor: Floor,
}

/// What a walk with the firmware gave, for its report.
pub struct SilRun<'a> {
    /// Scene name.
    pub scene: &'a str,
    /// The walker walked (the firmware's gait is measured on it).
    pub walker: &'a Walker,
    /// The integrator of the walk.
    pub integrator: &'a IntegratorChoice,
    /// The ideal-actuator gait's walker (the scene's own setup).
    pub ideal_walker: &'a Walker,
    /// The ideal-actuator gait the walk started from, and where it came from.
    pub ideal: (&'a Gait, GaitSource),
    /// The walk.
    pub walk: &'a Walk,
    /// Step summaries the report keeps (the last N; `None`: all).
    pub keep_steps: Option<usize>,
    /// The firmware's report.
    pub firmware: &'a SilReport,
    /// Firmware parameters written at start-up, by name [SI units].
    pub firmware_params_written: BTreeMap<&'static str, f64>,
    /// Differences between the scene's extension profile and the nodes'
    /// ([`crate::scene_profile::profile_mismatches`]).
    pub warnings: &'a [String],
    /// The ankles' actuator.
    pub actuator: ActuatorChoice,
    /// The floor walked over.
    pub floor: Floor,
}

impl<'a> SilRun<'a> {
    /// The `walker sil` report. The firmware's gait: the steps that ended by the emergency
    /// stop (one under way at the stop, or begun after it, is not walked with the ankles
    /// actuating throughout).
    pub fn report(self) -> SilWalkReport<'a> {
        let walk = self.walk;
        let kept = self.keep_steps.unwrap_or(usize::MAX).min(walk.steps.len());
        let emergency_stop_sent_s = emergency_stop_sent_s(self.firmware);
        let actuated_steps = match emergency_stop_sent_s {
            Some(t_stop) => {
                let before = walk
                    .steps
                    .partition_point(|s| s.start_t_walk_s + s.duration_s <= t_stop);
                &walk.steps[..before]
            }
            None => &walk.steps[..],
        };
        let (ideal, source) = self.ideal;
        SilWalkReport {
            scene: self.scene,
            integrator: self.integrator,
            steps_completed: walk.steps_completed,
            failure: walk.failure.as_ref(),
            fall_cause: walk
                .failure
                .as_ref()
                .and_then(|f| self.firmware.fall_cause(f.t_walk_s)),
            gait: WalkGaitRecord::of_steps(self.walker, actuated_steps, GAIT_STEPS_AVERAGED),
            emergency_stop_sent_s,
            steps_before_emergency_stop: actuated_steps.len(),
            ideal_gait: IdealGaitRecord::of(self.ideal_walker, ideal),
            start: StartRecord::gait(self.scene, ideal, source),
            node_faults: &self.firmware.faults,
            nodes: &self.firmware.nodes,
            firmware_params_written: self.firmware_params_written,
            warnings: self.warnings,
            bus_load: self.firmware.bus.load,
            bus: &self.firmware.bus,
            frames: self.firmware.frames_delivered,
            steps: &walk.steps[walk.steps.len() - kept..],
            sensor_faults_applied: &self.firmware.sensor_faults_applied,
            actuator: self.actuator.name(),
            floor: self.floor,
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;

    #[test]
    fn options_are_checked_in_order_with_the_commands_messages() {
        let (choice, steps) = check_options("motor", 12, Some(0.0)).unwrap();
        assert_eq!((choice, steps), (ActuatorChoice::SpoolMotor, 12));
        let e = check_options("piston", MAX_WALK_STEPS + 1, Some(-1.0)).unwrap_err();
        assert_eq!(e.0, "--actuator `piston`: expected `motor` or `servo`");
        let e = check_options("servo", MAX_WALK_STEPS + 1, Some(-1.0)).unwrap_err();
        assert_eq!(e.0, "--steps must be between 0 and 100000, got 100001");
        for bad in [-1.0, f64::NAN, f64::INFINITY] {
            let e = check_options("servo", 1, Some(bad)).unwrap_err();
            assert!(
                e.0.starts_with("--estop-at must be a finite walk time"),
                "{e}"
            );
        }
    }

    #[test]
    fn specs_configure_the_firmware_or_name_the_one_refused() {
        let params = ["taut_angle_rad=-0.07".to_owned()];
        let faults = ["drop:id=0x022,count=5".to_owned()];
        let sensor_faults = ["stuck:side=left,from_ms=500".to_owned()];
        let (config, written) = config_from_specs(
            ActuatorChoice::Servo,
            Specs {
                firmware_params: &params,
                faults: &faults,
                sensor_faults: &sensor_faults,
            },
        )
        .unwrap();
        assert_eq!(written.get("taut_angle_rad"), Some(&-0.07));
        assert_eq!(
            (config.bus_faults.len(), config.sensor_faults.len()),
            (1, 1)
        );
        let bogus = ["bogus".to_owned()];
        let e = config_from_specs(
            ActuatorChoice::Servo,
            Specs {
                faults: &bogus,
                ..Specs::default()
            },
        )
        .unwrap_err();
        assert!(e.0.starts_with("--fault `bogus`: "), "{e}");
        let e = config_from_specs(
            ActuatorChoice::Servo,
            Specs {
                firmware_params: &bogus,
                ..Specs::default()
            },
        )
        .unwrap_err();
        assert!(e.0.starts_with("--firmware-param `bogus`: "), "{e}");
    }
}
