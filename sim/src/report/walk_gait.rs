//! Gait figures of a walk: the means over its last steps.

use super::CostOfTransport;
use crate::engine::walker::Walker;
use crate::stride::walk::{StepSummary, Walk};
use serde::Serialize;

/// Gait figures averaged over the last completed steps of a walk (e.g. the firmware's gait in
/// `walker sil`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WalkGaitRecord {
    /// Number of steps averaged.
    pub steps_averaged: usize,
    /// Mean step period \[s\].
    pub step_period_s: f64,
    /// Mean distance between the contacts of a step \[m\].
    pub step_length_m: f64,
    /// Distance walked per step \[m\]: the hip's displacement over an even number of steps (so
    /// that the sideways zigzag cancels) divided by that number (the mean step length with a
    /// single step).
    pub progress_m_per_step: f64,
    /// `progress_m_per_step / step_period_s` [m/s].
    pub speed_m_s: f64,
    /// Mean work of the ankle actuator per step \[J\] (0 for a passive walker).
    pub actuator_work_j_per_step: f64,
    /// Actuator work per unit mass and forward distance, under the keys
    /// `cost_of_transport_J_per_kg_m` (original spelling, kept for compatibility) and
    /// `cost_of_transport_j_per_kg_m`.
    #[serde(flatten)]
    pub cost_of_transport: CostOfTransport,
    /// Mean magnitude of the per-step yaw in each step's mirrored stance frame (the zigzag,
    /// not a turn) \[rad\].
    pub heading_change_rad_per_step: f64,
    /// Direction of travel of the hip over the steps averaged in the floor frame,
    /// `atan2(Δz, Δx)` \[rad\]: 0 straight ahead along the first stance frame's x, positive
    /// toward +z; `null` with fewer than two steps.
    pub heading_rad: Option<f64>,
    /// Signed mean of the per-step yaw \[rad\].
    pub heading_change_rad_per_step_signed: f64,
}

impl WalkGaitRecord {
    /// The figures over the last `last` completed steps of `walk` by `walker`; `None` if no
    /// step completed.
    pub fn of(walker: &Walker, walk: &Walk, last: usize) -> Option<Self> {
        Self::of_steps(walker, &walk.steps, last)
    }

    /// The figures over the last `last` of `steps` (consecutive completed steps of one walk
    /// by `walker`, e.g. those before some walk time); `None` if there are none.
    pub fn of_steps(walker: &Walker, steps: &[StepSummary], last: usize) -> Option<Self> {
        let n = steps.len().min(last);
        if n == 0 {
            return None;
        }
        let steps = &steps[steps.len() - n..];
        let mean = |f: &dyn Fn(&StepSummary) -> f64| steps.iter().map(f).sum::<f64>() / n as f64;
        let period = mean(&|s| s.duration_s);
        let length = mean(&|s| s.step_length_m);
        let work = mean(&|s| s.actuator_work_j);
        let k = if n >= 3 { (n - 1) / 2 * 2 } else { n - 1 };
        let (progress, heading) = if k == 0 {
            (length, None)
        } else {
            let a = &steps[n - 1 - k].hip_floor_m;
            let b = &steps[n - 1].hip_floor_m;
            let (dx, dz) = (b[0] - a[0], b[2] - a[2]);
            ((dx * dx + dz * dz).sqrt() / k as f64, Some(dz.atan2(dx)))
        };
        let cost = work / (walker.model().total_mass_kg() * progress);
        Some(Self {
            steps_averaged: n,
            step_period_s: period,
            step_length_m: length,
            progress_m_per_step: progress,
            speed_m_s: progress / period,
            actuator_work_j_per_step: work,
            cost_of_transport: CostOfTransport { j_per_kg_m: cost },
            heading_change_rad_per_step: mean(&|s| s.heading_change_rad.abs()),
            heading_rad: heading,
            heading_change_rad_per_step_signed: mean(&|s| s.heading_change_rad),
        })
    }
}
