//! What a stride hands back when it completes: a [`StrideResult`] (a failed stride is a
//! [`super::StrideFailure`]); the events on the way as [`StrideEvent`]s. Every time here is
//! stride time (from the start of the stride), as are the `t_s` of the [`Sample`]s.

use super::contact_figures::ContactSummary;
use crate::engine::integrators::Sample;
use nalgebra::{DVector, Vector3};
use serde::Serialize;

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
