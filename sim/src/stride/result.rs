//! What a stride hands back: a [`StrideResult`], or a [`StrideFailure`] of some
//! [`FailureKind`]; the events on the way as [`StrideEvent`]s. Every time here is stride time
//! (from the start of the stride), as are the `t_s` of the [`Sample`]s.

use super::contact_figures::ContactSummary;
use crate::events::EventError;
use crate::integrators::{IntegrationError, Sample};
use nalgebra::{DVector, Vector3};
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
    /// The controller's period ([`crate::control::AnkleController::period_s`]) is not a finite
    /// positive time, or too short for its ticks to advance over the stride.
    InvalidControlPeriod,
}

/// A failed stride.
#[derive(Clone, Debug, PartialEq, Serialize, thiserror::Error)]
#[error("{kind:?} at t = {t_stride_s:.6} s: {detail}")]
pub struct StrideFailure {
    /// What happened.
    pub kind: FailureKind,
    /// When, from the start of the stride \[s\] (stride time; serialised as `time_s`).
    #[serde(rename = "time_s")]
    pub t_stride_s: f64,
    /// Details.
    pub detail: String,
}

impl StrideFailure {
    pub(super) fn new(kind: FailureKind, t_stride_s: f64, detail: impl Into<String>) -> Self {
        Self {
            kind,
            t_stride_s,
            detail: detail.into(),
        }
    }

    pub(super) fn from_integration(e: IntegrationError, t: f64) -> Self {
        let kind = match &e {
            IntegrationError::Dynamics(_) => FailureKind::NonFiniteState,
            IntegrationError::StepTooLarge { .. } => FailureKind::StepTooLarge,
            IntegrationError::StepUnderflow { .. } => FailureKind::StepUnderflow,
        };
        Self::new(kind, t, e.to_string())
    }

    pub(super) fn from_event(e: EventError, t: f64) -> Self {
        match e {
            EventError::Integration(i) => Self::from_integration(i, t),
            other => Self::new(FailureKind::EventNotLocated, t, other.to_string()),
        }
    }
}

/// An event inside a stride.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StrideEvent {
    /// `knee_lock:<coordinate>` or `heel_strike`.
    pub name: String,
    /// Time from the start of the stride \[s\] (stride time; serialised as `time_s`).
    #[serde(rename = "time_s")]
    pub t_stride_s: f64,
}

/// A completed stride.
#[derive(Clone, Debug)]
pub struct StrideResult {
    /// The state just before and just after each event of [`Self::events`], in the same
    /// order (for the heel strike both are the pre-impact state).
    pub event_states: Vec<(Sample, Sample)>,
    /// Coordinates at the start of the next stride (relabelled).
    pub q_next: DVector<f64>,
    /// Velocities at the start of the next stride (relabelled).
    pub qd_next: DVector<f64>,
    /// Stride duration \[s\].
    pub duration_s: f64,
    /// New contact point in the old stance frame \[m\].
    pub step_m: Vector3<f64>,
    /// Heading change of the relabelled cyclic coordinates \[rad\].
    pub heading_change_rad: f64,
    /// Events in order.
    pub events: Vec<StrideEvent>,
    /// State just before heel strike (in the stance labelling).
    pub pre_impact: Sample,
    /// Upward velocity of the old stance contact just after impact [m/s].
    pub lift_velocity_m_s: f64,
    /// Mechanical energy lost in all impacts of the stride \[J\].
    pub impact_energy_loss_j: f64,
    /// Right-hand-side evaluations.
    pub evaluations: usize,
    /// Accepted samples, when recording.
    pub trajectory: Vec<Sample>,
    /// Work done by the ankle actuator (from the energy balance of the engaged intervals) \[J\].
    pub actuator_work_j: f64,
    /// Energy dissipated by joint dampers (trapezoidal quadrature) \[J\].
    pub damping_dissipation_j: f64,
    /// Contact figures (with [`super::StrideOptions::contact`]).
    pub contact: ContactSummary,
}
