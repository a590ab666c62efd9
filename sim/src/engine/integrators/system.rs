//! The integrators' common vocabulary: the system they advance ([`SecondOrderSystem`]), a
//! state at a time ([`Sample`]), why a step fails ([`IntegrationError`]), the estimate behind
//! eq. (12) ([`StabilityLimit`]).

use crate::engine::dynamics::DynamicsError;
use nalgebra::DVector;

/// A system of second-order ODEs.
pub trait SecondOrderSystem {
    /// Accelerations at `t`, `q`, `q̇`.
    fn accelerations(
        &mut self,
        t_s: f64,
        q: &DVector<f64>,
        qd: &DVector<f64>,
    ) -> Result<DVector<f64>, DynamicsError>;

    /// Accelerations at `t`, `q`, `q̇` written into `out` (of the state's length): the
    /// integrators' entry point, which a system can implement without allocating.
    fn accelerations_into(
        &mut self,
        t_s: f64,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        out: &mut DVector<f64>,
    ) -> Result<(), DynamicsError> {
        let a = self.accelerations(t_s, q, qd)?;
        if out.len() == a.len() {
            out.copy_from(&a);
        } else {
            *out = a;
        }
        Ok(())
    }

    /// How many evaluations (and other uses of its workspace) the system has made: an epoch
    /// that names its last evaluation. `0` for a system that keeps no assembly.
    fn evaluation_epoch(&self) -> u64 {
        0
    }

    /// Accelerations at time `t_s` into `out` by a solve on the assembly of evaluation
    /// `epoch`, when the caller states that this is that evaluation's state with only the
    /// driven coordinate's prescribed acceleration changed since (its angle and rate the same
    /// to the bit), and the system has not been used since: `Ok(true)`, the same result to the
    /// bit as an evaluation. `Ok(false)`: not available, evaluate instead.
    fn accelerations_again_into(
        &mut self,
        _epoch: u64,
        _t_s: f64,
        _out: &mut DVector<f64>,
    ) -> Result<bool, DynamicsError> {
        Ok(false)
    }

    /// Largest undamped eigenfrequency `λ_max` [rad/s] and its relative damping `β` of the
    /// linearised system at `q`, `q̇` (for eq. 12). `None` if the system cannot tell.
    fn stability_limit(
        &mut self,
        _t_s: f64,
        _q: &DVector<f64>,
        _qd: &DVector<f64>,
    ) -> Option<StabilityLimit> {
        None
    }
}

/// Positions and velocities at a time.
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    /// Time \[s\].
    pub t_s: f64,
    /// Generalised coordinates.
    pub q: DVector<f64>,
    /// Generalised velocities.
    pub qd: DVector<f64>,
}

/// Why a step failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IntegrationError {
    /// The equations of motion could not be evaluated.
    #[error(transparent)]
    Dynamics(#[from] DynamicsError),
    /// The fixed step exceeds the stability limit of eq. (12).
    #[error("step {h_s:e} s exceeds the stability limit h_max = {h_max_s:e} s (λ_max = {lambda_max_rad_s:.3} rad/s, β = {beta:.3})")]
    StepTooLarge {
        /// The step \[s\].
        h_s: f64,
        /// The limit \[s\].
        h_max_s: f64,
        /// Largest undamped eigenfrequency [rad/s].
        lambda_max_rad_s: f64,
        /// Relative damping of that mode.
        beta: f64,
    },
    /// The adaptive step fell below its floor.
    #[error("adaptive step size fell to {h_s:e} s at t = {t_s} s")]
    StepUnderflow {
        /// The step \[s\].
        h_s: f64,
        /// Time \[s\].
        t_s: f64,
    },
}

/// The estimate behind eq. (12).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StabilityLimit {
    /// Largest undamped eigenfrequency of the linearised system [rad/s].
    pub lambda_max_rad_s: f64,
    /// Relative damping of that mode (0 = undamped).
    pub beta: f64,
}

impl StabilityLimit {
    /// `h_max = (1 − β) 2 / λ_max` \[s\].
    pub fn h_max_s(&self) -> f64 {
        if self.lambda_max_rad_s <= 0.0 {
            f64::INFINITY
        } else {
            (1.0 - self.beta).max(0.0) * 2.0 / self.lambda_max_rad_s
        }
    }
}
