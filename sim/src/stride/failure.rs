//! A failed stride: a [`StrideFailure`], when it failed and why, the [`FailureCause`] with the
//! values that were wrong. The cause's text is the failure's `detail`; its [`FailureKind`]
//! follows from it ([`FailureCause::kind`]).

use crate::engine::control::ControlError;
use crate::engine::dynamics::DynamicsError;
use crate::engine::events::EventError;
use crate::engine::impact::ImpactError;
use crate::engine::integrators::IntegrationError;
use crate::engine::relabel::RelabelError;
use serde::Serialize;

/// The kinds of failure a stride can end in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FailureKind {
    /// The walker fell with its hip behind the stance contact.
    FellBackward,
    /// The walker fell with its hip ahead of the stance contact.
    FellForward,
    /// The swing foot hit the floor mid-swing (scene does not ignore scuffing).
    Scuffed,
    /// Heel strike came before the swing knee locked.
    HeelStrikeBeforeKneeLock,
    /// After heel strike the old stance foot did not move upward.
    StanceFootDidNotLift,
    /// No heel strike within the stride time budget.
    NoImpactWithinTime,
    /// The state became NaN or infinite, or the mass matrix singular.
    NonFiniteState,
    /// A fixed step exceeded the stability limit of eq. (12).
    StepTooLarge,
    /// An adaptive step fell below its floor.
    StepUnderflow,
    /// At string engagement the heel would be pressed into the floor instead of lifting.
    HeelDidNotLift,
    /// During push-off the heel came back down to the floor.
    HeelReturnedToFloor,
    /// An event could not be located to its tolerance.
    EventNotLocated,
    /// The impact equations were singular.
    ImpactSingular,
    /// The relabelled state could not be matched to the model.
    RelabelFailed,
    /// The stride took its step budget ([`super::StrideSettings::max_steps`]) of integrator
    /// steps without ending.
    StepBudgetExceeded,
    /// The stride evaluated the equations of motion as often as its budget
    /// ([`super::StrideSettings::max_evaluations`]) allows without ending.
    EvaluationBudgetExceeded,
    /// The controller's period ([`crate::engine::control::AnkleController::period_s`]) is not a finite
    /// positive time, or too short for its ticks to advance over the stride.
    InvalidControlPeriod,
    /// The controller could not run a control tick (its error), or a tick could not run.
    ControlFailed,
    /// The request does not fit the walker (a controlled stride on a walker without an ankle
    /// reflex): a configuration error, found before the stride starts.
    InvalidConfiguration,
    /// The search the stride belongs to has used its budget of strides
    /// ([`super::SearchBudget`]): not run.
    SearchBudgetExhausted,
}

/// A failed stride. Serialised as `{kind, time_s, detail}` (`detail`: the cause's text).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{kind:?} at t = {t_stride_s:.6} s: {cause}")]
pub struct StrideFailure {
    /// What happened (the cause's [`FailureCause::kind`]).
    pub kind: FailureKind,
    /// When, from the start of the stride \[s\] (stride time; serialised as `time_s`).
    pub t_stride_s: f64,
    /// Why, with the values that were wrong (boxed: a failure stays as small as a result's
    /// error should be).
    pub cause: Box<FailureCause>,
}

impl StrideFailure {
    /// The stride failed at `t_stride_s` [s, stride time] because of `cause` (its kind
    /// follows from the cause).
    pub(crate) fn new(t_stride_s: f64, cause: impl Into<FailureCause>) -> Self {
        let cause = cause.into();
        Self {
            kind: cause.kind(),
            t_stride_s,
            cause: Box::new(cause),
        }
    }

    /// The cause in words (the `detail` of the JSON and of the text reports).
    pub fn detail(&self) -> String {
        self.cause.to_string()
    }

    pub(super) fn from_integration(e: IntegrationError, t: f64) -> Self {
        Self::new(t, e)
    }

    pub(super) fn from_event(e: EventError, t: f64) -> Self {
        Self::new(t, e)
    }
}

impl Serialize for StrideFailure {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct as _;
        let mut s = serializer.serialize_struct("StrideFailure", 3)?;
        s.serialize_field("kind", &self.kind)?;
        s.serialize_field("time_s", &self.t_stride_s)?;
        s.serialize_field("detail", &self.detail())?;
        s.end()
    }
}

/// The cause of a failed stride, by where it arose: the request, the state, the integration,
/// an event, an impact, the relabelling, the controller, a budget, or the walker's motion
/// (a fall, a scuff, a foot that does not lift).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FailureCause {
    /// A controlled stride on a walker without an ankle reflex (the scene has no
    /// `ankle_reflex` section): a request that does not fit the walker.
    #[error("a controlled stride needs a scene with an ankle_reflex section")]
    NoAnkleReflex,
    /// A stride-map vector of another length than the walker's map: a state of another
    /// walker (the map changes size where a symmetry breaks, e.g. the 3D walker's heading,
    /// cyclic on level ground and a state on a slope).
    #[error(
        "a stride-map vector of {got} entries for a walker whose stride map has {expected} \
         (the map changes size where a symmetry breaks: the 3D walker's heading is a state on a \
         slope and cyclic on level ground)"
    )]
    MapLength {
        /// The walker's map length.
        expected: usize,
        /// The vector's.
        got: usize,
    },
    /// The search's budget of strides is spent: the stride was not run.
    #[error("the search's budget of {limit_strides} strides is spent (--max-strides)")]
    SearchBudget {
        /// The budget \[strides\].
        limit_strides: usize,
    },
    /// The stride's start state is not finite.
    #[error("initial state")]
    NonFiniteInitialState,
    /// A step ended in a state that is not finite.
    #[error("state")]
    NonFiniteState,
    /// The state after an impact (named as in the stride's events: `heel_down`,
    /// `string_engaged`, `knee lock`) is not finite, or does not fit the engine's storage.
    #[error("state after the {impact}")]
    NonFiniteAfterImpact {
        /// The impact.
        impact: &'static str,
    },
    /// The fixed-size engine met a step that triggered several events: it hands the stride
    /// back to the reference engine, which locates each (never reported: the reference runs
    /// the stride again).
    #[error("several events in one step: handed back to the reference engine")]
    SeveralEventsHandedBack,
    /// An integrator step failed.
    #[error(transparent)]
    Integration(IntegrationError),
    /// The equations of motion failed outside a step (the contact figures of an accepted
    /// sample, the string's torque at a control tick).
    #[error(transparent)]
    Dynamics(DynamicsError),
    /// An event could not be located to its tolerance (a failed refinement step is
    /// [`Self::Integration`]).
    #[error(transparent)]
    Event(EventError),
    /// An impact could not be resolved.
    #[error(transparent)]
    Impact(ImpactError),
    /// The state after heel strike could not be relabelled.
    #[error(transparent)]
    Relabel(RelabelError),
    /// The controller failed a tick.
    #[error(transparent)]
    Control(ControlError),
    /// The controller's period is not a finite positive time.
    #[error("control period {period_s} s is not a finite positive time")]
    ControlPeriodNotPositive {
        /// The period \[s\].
        period_s: f64,
    },
    /// The controller's period is too short for the tick grid to advance from the walk time
    /// over the stride's time budget.
    #[error(
        "control period {period_s} s does not advance the tick grid from walk time \
         {t_walk_start_s} s"
    )]
    ControlPeriodTooShort {
        /// The period \[s\].
        period_s: f64,
        /// Walk time at the start of the stride \[s\].
        t_walk_start_s: f64,
    },
    /// The controller's period does not advance the next tick's time (inside a step).
    #[error("the control period {period_s} s does not advance")]
    ControlPeriodStalls {
        /// The period \[s\].
        period_s: f64,
    },
    /// A control tick lies inside a step that has no interpolant to run it on (a defect of
    /// the stride loop, not a result).
    #[error(
        "the control tick at stride time {tick_s} s lies inside a step without an interpolant"
    )]
    TickInsideStep {
        /// The tick's time [s, stride time].
        tick_s: f64,
    },
    /// A control tick was passed without running (a defect of the stride loop, not a result).
    #[error("the control tick at stride time {tick_s} s was passed without running")]
    TickPassed {
        /// The tick's time [s, stride time].
        tick_s: f64,
    },
    /// A control tick came without a controller (a defect of the stride loop).
    #[error("a control tick without a controller")]
    TickWithoutController,
    /// No heel strike within the stride's time budget.
    #[error("no heel strike within {max_stride_time_s} s")]
    TimeBudget {
        /// The budget, [`super::StrideSettings::max_stride_time_s`] \[s\].
        max_stride_time_s: f64,
    },
    /// No heel strike within the stride's step budget.
    #[error(
        "no heel strike within the step budget max_steps = {max_steps} ({evaluations} evaluations)"
    )]
    StepBudget {
        /// The budget, [`super::StrideSettings::max_steps`].
        max_steps: usize,
        /// Evaluations of the equations of motion used.
        evaluations: usize,
    },
    /// The control ticks used the stride's step budget.
    #[error(
        "no heel strike within the step budget max_steps = {max_steps} of control ticks \
         (period {period_s} s)"
    )]
    TickBudget {
        /// The budget, [`super::StrideSettings::max_steps`].
        max_steps: usize,
        /// The controller's period \[s\].
        period_s: f64,
    },
    /// No heel strike within the stride's evaluation budget.
    #[error("no heel strike within the evaluation budget max_evaluations = {max_evaluations} ({steps} steps)")]
    EvaluationBudget {
        /// The budget, [`super::StrideSettings::max_evaluations`].
        max_evaluations: usize,
        /// Integrator steps used.
        steps: usize,
    },
    /// The hip fell below its minimum height; the walker fell forward when the hip was
    /// ahead of the stance contact (or level with it), backward otherwise.
    #[error("hip below its minimum height")]
    HipTooLow {
        /// How far the hip is ahead of the stance contact \[m\].
        hip_ahead_m: f64,
    },
    /// The hip moved back behind the stance contact.
    #[error("hip moved back behind the stance contact")]
    HipBehindStance,
    /// The stance heel came back down while the drive still held the ankle.
    #[error("the stance heel came back down during push-off")]
    HeelReturnedToFloor,
    /// At string engagement the heel would be pressed into the floor.
    #[error("at string engagement the heel moves down ({toe_pitch_rate_rad_s:.3e} rad/s)")]
    HeelMovesDown {
        /// The foot's pitch rate about its toe just after the engagement (positive: the heel
        /// moves down) [rad/s].
        toe_pitch_rate_rad_s: f64,
    },
    /// The swing foot touched the floor too close to the stance contact (a scuff).
    #[error("swing foot touched the floor {foot_ahead_m:.4} m ahead of the stance contact")]
    Scuff {
        /// How far the swing foot is ahead of the stance contact \[m\].
        foot_ahead_m: f64,
    },
    /// Heel strike with a knee still free.
    #[error("knee `{knee}` still free at heel strike")]
    KneeFreeAtHeelStrike {
        /// The knee coordinate's name.
        knee: String,
    },
    /// The old stance contact does not move upward after heel strike.
    #[error("old stance contact moves {lift_m_s:.3e} m/s upward after impact")]
    StanceFootDidNotLift {
        /// Its upward velocity just after the impact [m/s].
        lift_m_s: f64,
    },
}

impl FailureCause {
    /// The kind of failure this cause is.
    pub fn kind(&self) -> FailureKind {
        match self {
            Self::NoAnkleReflex | Self::MapLength { .. } => FailureKind::InvalidConfiguration,
            Self::SearchBudget { .. } => FailureKind::SearchBudgetExhausted,
            Self::NonFiniteInitialState
            | Self::NonFiniteState
            | Self::NonFiniteAfterImpact { .. }
            | Self::Dynamics(_) => FailureKind::NonFiniteState,
            Self::Integration(e) => match e {
                IntegrationError::Dynamics(_) => FailureKind::NonFiniteState,
                IntegrationError::StepTooLarge { .. } => FailureKind::StepTooLarge,
                IntegrationError::StepUnderflow { .. } => FailureKind::StepUnderflow,
            },
            Self::Event(EventError::Integration(i)) => Self::Integration(i.clone()).kind(),
            Self::Event(EventError::NotLocated { .. } | EventError::NoDenseOutput { .. })
            | Self::SeveralEventsHandedBack => FailureKind::EventNotLocated,
            Self::Impact(_) => FailureKind::ImpactSingular,
            Self::Relabel(_) => FailureKind::RelabelFailed,
            Self::Control(_)
            | Self::TickInsideStep { .. }
            | Self::TickPassed { .. }
            | Self::TickWithoutController => FailureKind::ControlFailed,
            Self::ControlPeriodNotPositive { .. }
            | Self::ControlPeriodTooShort { .. }
            | Self::ControlPeriodStalls { .. } => FailureKind::InvalidControlPeriod,
            Self::TimeBudget { .. } => FailureKind::NoImpactWithinTime,
            Self::StepBudget { .. } | Self::TickBudget { .. } => FailureKind::StepBudgetExceeded,
            Self::EvaluationBudget { .. } => FailureKind::EvaluationBudgetExceeded,
            Self::HipTooLow { hip_ahead_m } if *hip_ahead_m >= 0.0 => FailureKind::FellForward,
            Self::HipTooLow { .. } | Self::HipBehindStance => FailureKind::FellBackward,
            Self::HeelReturnedToFloor => FailureKind::HeelReturnedToFloor,
            Self::HeelMovesDown { .. } => FailureKind::HeelDidNotLift,
            Self::Scuff { .. } => FailureKind::Scuffed,
            Self::KneeFreeAtHeelStrike { .. } => FailureKind::HeelStrikeBeforeKneeLock,
            Self::StanceFootDidNotLift { .. } => FailureKind::StanceFootDidNotLift,
        }
    }
}

impl From<IntegrationError> for FailureCause {
    fn from(e: IntegrationError) -> Self {
        Self::Integration(e)
    }
}

/// A failed refinement step is an integration failure; the rest an event's.
impl From<EventError> for FailureCause {
    fn from(e: EventError) -> Self {
        match e {
            EventError::Integration(i) => Self::Integration(i),
            other => Self::Event(other),
        }
    }
}

impl From<DynamicsError> for FailureCause {
    fn from(e: DynamicsError) -> Self {
        Self::Dynamics(e)
    }
}

impl From<ImpactError> for FailureCause {
    fn from(e: ImpactError) -> Self {
        Self::Impact(e)
    }
}

impl From<RelabelError> for FailureCause {
    fn from(e: RelabelError) -> Self {
        Self::Relabel(e)
    }
}

impl From<ControlError> for FailureCause {
    fn from(e: ControlError) -> Self {
        Self::Control(e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fall_from_a_low_hip_is_forward_with_the_hip_ahead_and_backward_behind() {
        let low = |hip_ahead_m| FailureCause::HipTooLow { hip_ahead_m }.kind();
        assert_eq!(low(0.0), FailureKind::FellForward);
        assert_eq!(low(0.1), FailureKind::FellForward);
        assert_eq!(low(-0.1), FailureKind::FellBackward);
    }

    #[test]
    fn a_failure_serialises_as_its_kind_time_and_the_cause_s_text() {
        let f = StrideFailure::new(0.5, FailureCause::HipTooLow { hip_ahead_m: 0.1 });
        assert_eq!(f.kind, FailureKind::FellForward);
        assert_eq!(
            serde_json::to_string(&f).ok().as_deref(),
            Some(r#"{"kind":"fell_forward","time_s":0.5,"detail":"hip below its minimum height"}"#)
        );
        assert_eq!(
            f.to_string(),
            "FellForward at t = 0.500000 s: hip below its minimum height"
        );
    }

    #[test]
    fn a_request_that_does_not_fit_the_walker_is_not_a_non_finite_state() {
        let cause = FailureCause::NoAnkleReflex;
        assert_eq!(cause.kind(), FailureKind::InvalidConfiguration);
        assert_eq!(
            cause.to_string(),
            "a controlled stride needs a scene with an ankle_reflex section"
        );
    }

    #[test]
    fn a_refinement_step_that_fails_is_the_integration_s_failure() {
        let e = IntegrationError::StepUnderflow {
            h_s: 1e-20,
            t_s: 0.5,
        };
        let cause = FailureCause::from(EventError::Integration(e.clone()));
        assert_eq!(cause, FailureCause::Integration(e.clone()));
        assert_eq!(cause.kind(), FailureKind::StepUnderflow);
        assert_eq!(cause.to_string(), e.to_string());
    }

    #[test]
    fn budgets_say_their_budget_and_what_was_used() {
        let steps = FailureCause::StepBudget {
            max_steps: 10,
            evaluations: 61,
        };
        assert_eq!(steps.kind(), FailureKind::StepBudgetExceeded);
        assert_eq!(
            steps.to_string(),
            "no heel strike within the step budget max_steps = 10 (61 evaluations)"
        );
        let evaluations = FailureCause::EvaluationBudget {
            max_evaluations: 100,
            steps: 16,
        };
        assert_eq!(evaluations.kind(), FailureKind::EvaluationBudgetExceeded);
        assert_eq!(
            evaluations.to_string(),
            "no heel strike within the evaluation budget max_evaluations = 100 (16 steps)"
        );
    }
}
