//! Gait figures of a fixed point, comparable with [`WalkGaitRecord`](super::WalkGaitRecord).

use super::gait_numbers;
use super::CostOfTransport;
use crate::analysis::limit_cycle::Gait;
use crate::engine::walker::Walker;
use serde::Serialize;

/// The figures of [`WalkGaitRecord`](super::WalkGaitRecord) for a gait's fixed point (e.g.
/// the ideal-actuator gait in `walker sil`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct IdealGaitRecord {
    /// Step period \[s\].
    pub step_period_s: f64,
    /// Distance between the contacts of a step \[m\].
    pub step_length_m: f64,
    /// Forward speed [m/s].
    pub speed_m_s: f64,
    /// Work of the ankle actuator per step \[J\].
    pub actuator_work_j_per_step: f64,
    /// Actuator work per unit mass and forward distance, under the keys
    /// `cost_of_transport_J_per_kg_m` (original spelling, kept for compatibility) and
    /// `cost_of_transport_j_per_kg_m`.
    #[serde(flatten)]
    pub cost_of_transport: CostOfTransport,
    /// Distance walked forward per step \[m\].
    pub progress_m_per_step: f64,
    /// Magnitude of the heading change per step \[rad\].
    pub heading_change_rad_per_step: f64,
    /// Largest eigenvalue modulus of the stride Jacobian.
    pub max_abs_eigenvalue: f64,
}

impl IdealGaitRecord {
    /// The figures of `gait`, found by `walker`.
    pub fn of(walker: &Walker, gait: &Gait) -> Self {
        let n = gait_numbers(walker, gait);
        let cost = gait.stride.actuator_work_j / (walker.model().total_mass_kg() * n.progress_m);
        Self {
            step_period_s: n.step_period_s,
            step_length_m: n.step_length_m,
            speed_m_s: n.speed_m_s,
            actuator_work_j_per_step: gait.stride.actuator_work_j,
            cost_of_transport: CostOfTransport { j_per_kg_m: cost },
            progress_m_per_step: n.progress_m,
            heading_change_rad_per_step: gait.stride.heading_change_rad.abs(),
            max_abs_eigenvalue: gait.max_abs_eigenvalue(),
        }
    }
}
