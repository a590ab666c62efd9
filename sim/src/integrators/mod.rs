//! Time integrators for `q̈ = f(q, q̇, t)` behind one interface.
//!
//! Every integrator advances a [`SecondOrderSystem`] by one accepted step and can take an
//! exact step of any smaller size, which the event locator uses to refine event times.

mod dense;
mod dop853;
mod dopri5;
mod embedded;
mod meijaard;
mod rk4;

pub use dense::{DenseCoefficients, DenseOutput};
pub(crate) use dop853::{combined_error, component_error};
pub use dop853::{Dop853, Dop853Pair};
pub use dopri5::{Dopri5, Dopri5Pair};
pub use embedded::{EmbeddedPair, EmbeddedRk, Tolerances};
pub use meijaard::{Meijaard, StabilityLimit};
pub use rk4::Rk4;

use crate::dynamics::DynamicsError;
use nalgebra::DVector;
use serde::{Deserialize, Serialize};

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

/// Why an integrator's settings cannot run a stride (from a scene file or the command line),
/// naming the setting and its value.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IntegratorError {
    /// A step, largest step or tolerance that is zero, negative, NaN or infinite.
    #[error("integrator {kind}: `{setting}` = {value:e} must be a positive, finite number")]
    NotPositive {
        /// The integrator's kind.
        kind: &'static str,
        /// The setting (`h_s`, `h_max_s`, `rtol`, `atol`).
        setting: &'static str,
        /// Its value.
        value: f64,
    },
    /// A (largest) step so small that the stride time budget takes more steps than the
    /// stride's step budget allows.
    #[error("integrator {kind}: `{setting}` = {value:e} s is too small: {steps:.3e} steps to cover the stride time budget of {max_stride_time_s} s, more than the step budget of {max_steps}")]
    TooManySteps {
        /// The integrator's kind.
        kind: &'static str,
        /// The setting (`h_s` or `h_max_s`).
        setting: &'static str,
        /// Its value \[s\].
        value: f64,
        /// Steps the time budget needs at this step.
        steps: f64,
        /// The stride time budget \[s\].
        max_stride_time_s: f64,
        /// The stride step budget.
        max_steps: usize,
    },
    /// A stride time budget that is zero, negative, NaN or infinite.
    #[error("stride time budget max_stride_time_s = {value} s must be a positive, finite number")]
    BadTimeBudget {
        /// Its value \[s\].
        value: f64,
    },
}

/// The step-size controller of the embedded pairs (DOPRI5, DOP853): from `h`, try a step;
/// accept it when its scaled error is at most 1 and propose the next step
/// `h · clamp(0.9 · err^(−exponent), min, max)` (at most `h_max_s`); otherwise shrink and retry,
/// down to `h_min_s`. Returns the accepted sample and the proposal.
pub(crate) fn adaptive_step<S>(
    mut h: f64,
    limits: StepLimits,
    t_s: f64,
    mut try_step: impl FnMut(f64) -> Result<(S, f64), IntegrationError>,
) -> Result<(S, f64), IntegrationError> {
    loop {
        let (next, err) = try_step(h)?;
        let factor = if err == 0.0 {
            limits.max_factor
        } else {
            (0.9 * err.powf(-limits.exponent)).clamp(limits.min_factor, limits.max_factor)
        };
        if err <= 1.0 && err.is_finite() {
            return Ok((next, (h * factor).min(limits.h_max_s)));
        }
        h *= if err.is_finite() {
            factor.min(0.9)
        } else {
            0.2
        };
        if h < limits.h_min_s {
            return Err(IntegrationError::StepUnderflow { h_s: h, t_s });
        }
    }
}

/// Bounds of [`adaptive_step`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct StepLimits {
    /// Error exponent: 1/(order + 1) of the lower-order estimate.
    pub exponent: f64,
    /// Smallest step-size factor.
    pub min_factor: f64,
    /// Largest step-size factor.
    pub max_factor: f64,
    /// Largest step [s].
    pub h_max_s: f64,
    /// Smallest step before giving up [s].
    pub h_min_s: f64,
}

/// Which integrator to use, with its settings. Serialised in reports.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum IntegratorChoice {
    /// Meijaard's one-evaluation scheme, eq. (11).
    Meijaard {
        /// Step \[s\].
        h_s: f64,
        /// Check eq. (12) every this many steps (0: never).
        check_every: usize,
    },
    /// Classical fourth-order Runge-Kutta.
    Rk4 {
        /// Step \[s\].
        h_s: f64,
    },
    /// Dormand-Prince 8(5,3), adaptive (Hairer's DOP853).
    Dop853 {
        /// Relative tolerance.
        rtol: f64,
        /// Absolute tolerance.
        atol: f64,
        /// Largest step \[s\].
        h_max_s: f64,
    },
    /// Dormand-Prince 5(4), adaptive.
    Dopri5 {
        /// Relative tolerance.
        rtol: f64,
        /// Absolute tolerance.
        atol: f64,
        /// Largest step \[s\].
        h_max_s: f64,
    },
}

impl IntegratorChoice {
    /// Builds the integrator.
    pub fn build(&self) -> Box<dyn Integrator> {
        match *self {
            IntegratorChoice::Meijaard { h_s, check_every } => {
                Box::new(Meijaard::new(h_s, check_every))
            }
            IntegratorChoice::Rk4 { h_s } => Box::new(Rk4::new(h_s)),
            IntegratorChoice::Dopri5 {
                rtol,
                atol,
                h_max_s,
            } => Box::new(Dopri5::new(rtol, atol, h_max_s)),
            IntegratorChoice::Dop853 {
                rtol,
                atol,
                h_max_s,
            } => Box::new(Dop853::new(rtol, atol, h_max_s)),
        }
    }

    /// An integrator by kind name (`meijaard`, `rk4`, `dopri5`, `dop853`) with optional settings; the
    /// defaults are a 1 ms step, tolerances 1e-12 and a 0.05 s largest step. `None` for an
    /// unknown kind.
    pub fn from_kind(
        kind: &str,
        h_s: Option<f64>,
        rtol: Option<f64>,
        atol: Option<f64>,
        h_max_s: Option<f64>,
    ) -> Option<Self> {
        let h_s = h_s.unwrap_or(1e-3);
        match kind {
            "meijaard" => Some(IntegratorChoice::Meijaard {
                h_s,
                check_every: 0,
            }),
            "rk4" => Some(IntegratorChoice::Rk4 { h_s }),
            "dopri5" => Some(IntegratorChoice::Dopri5 {
                rtol: rtol.unwrap_or(1e-12),
                atol: atol.or(rtol).unwrap_or(1e-12),
                h_max_s: h_max_s.unwrap_or(0.05),
            }),
            "dop853" => Some(IntegratorChoice::Dop853 {
                rtol: rtol.unwrap_or(1e-12),
                atol: atol.or(rtol).unwrap_or(1e-12),
                h_max_s: h_max_s.unwrap_or(0.05),
            }),
            _ => None,
        }
    }

    /// The same integrator with its tolerances (rtol = atol) or its fixed step replaced,
    /// where it has one.
    pub fn with_tolerance_or_step(&self, rtol: Option<f64>, h_s: Option<f64>) -> Self {
        match (self.clone(), rtol, h_s) {
            (IntegratorChoice::Dopri5 { h_max_s, .. }, Some(r), _) => IntegratorChoice::Dopri5 {
                rtol: r,
                atol: r,
                h_max_s,
            },
            (IntegratorChoice::Dop853 { h_max_s, .. }, Some(r), _) => IntegratorChoice::Dop853 {
                rtol: r,
                atol: r,
                h_max_s,
            },
            (IntegratorChoice::Meijaard { check_every, .. }, _, Some(h)) => {
                IntegratorChoice::Meijaard {
                    h_s: h,
                    check_every,
                }
            }
            (IntegratorChoice::Rk4 { .. }, _, Some(h)) => IntegratorChoice::Rk4 { h_s: h },
            (other, _, _) => other,
        }
    }

    /// The kind's name (`meijaard`, `rk4`, `dopri5`, `dop853`), as [`Self::from_kind`] takes it.
    pub fn kind(&self) -> &'static str {
        match self {
            IntegratorChoice::Meijaard { .. } => "meijaard",
            IntegratorChoice::Rk4 { .. } => "rk4",
            IntegratorChoice::Dopri5 { .. } => "dopri5",
            IntegratorChoice::Dop853 { .. } => "dop853",
        }
    }

    /// Checks that these settings can run a stride: every step, largest step and tolerance
    /// positive and finite, and the (largest) step long enough to cover `max_stride_time_s`
    /// \[s\] within `max_steps` steps (a smaller one could only end in a budget failure, after
    /// a long time).
    ///
    /// # Errors
    /// [`IntegratorError`] naming the setting and its value.
    pub fn validate_with_budget(
        &self,
        max_stride_time_s: f64,
        max_steps: usize,
    ) -> Result<(), IntegratorError> {
        let kind = self.kind();
        if !(max_stride_time_s.is_finite() && max_stride_time_s > 0.0) {
            return Err(IntegratorError::BadTimeBudget {
                value: max_stride_time_s,
            });
        }
        let positive = |setting: &'static str, value: f64| {
            if value.is_finite() && value > 0.0 {
                Ok(())
            } else {
                Err(IntegratorError::NotPositive {
                    kind,
                    setting,
                    value,
                })
            }
        };
        let (setting, step_s) = match *self {
            IntegratorChoice::Meijaard { h_s, .. } | IntegratorChoice::Rk4 { h_s } => ("h_s", h_s),
            IntegratorChoice::Dopri5 {
                rtol,
                atol,
                h_max_s,
            }
            | IntegratorChoice::Dop853 {
                rtol,
                atol,
                h_max_s,
            } => {
                positive("rtol", rtol)?;
                positive("atol", atol)?;
                ("h_max_s", h_max_s)
            }
        };
        positive(setting, step_s)?;
        let steps = max_stride_time_s / step_s;
        if steps > max_steps as f64 {
            return Err(IntegratorError::TooManySteps {
                kind,
                setting,
                value: step_s,
                steps,
                max_stride_time_s,
                max_steps,
            });
        }
        Ok(())
    }

    /// A short label for tables.
    pub fn label(&self) -> String {
        match self {
            IntegratorChoice::Meijaard { h_s, .. } => format!("meijaard h={h_s:e}"),
            IntegratorChoice::Rk4 { h_s } => format!("rk4 h={h_s:e}"),
            IntegratorChoice::Dopri5 { rtol, .. } => format!("dopri5 rtol={rtol:e}"),
            IntegratorChoice::Dop853 { rtol, .. } => format!("dop853 rtol={rtol:e}"),
        }
    }
}

/// One integrator: a step chosen by itself, and an exact step of a given size.
pub trait Integrator {
    /// Name for reports.
    fn name(&self) -> &'static str;
    /// Clears any per-trajectory memory (step-size history, counters). Call at a new start.
    fn reset(&mut self);
    /// The step this integrator would take next from `t_s` \[s\].
    fn proposed_step_s(&self) -> f64;
    /// Takes one accepted step from `from` of size at most `h_limit_s`, returning the new sample.
    fn advance(
        &mut self,
        sys: &mut dyn SecondOrderSystem,
        from: &Sample,
        h_limit_s: f64,
    ) -> Result<Sample, IntegrationError>;
    /// Takes one step of exactly `h_s` (no error control; used to refine an event time
    /// inside the last accepted step).
    fn step_exact(
        &mut self,
        sys: &mut dyn SecondOrderSystem,
        from: &Sample,
        h_s: f64,
    ) -> Result<Sample, IntegrationError>;
    /// Number of right-hand-side evaluations since `reset`.
    fn evaluations(&self) -> usize;
    /// The equations changed without the state changing (e.g. a control tick moved an
    /// actuator): forget any derivative kept from the last step.
    fn system_changed(&mut self) {}
    /// The dense output of the last step taken (by `advance` or `step_exact`) when it went
    /// from `from` to `to` and the integrator has a continuous extension; `None` otherwise
    /// (then events are refined with exact steps). Its extra stages count as evaluations.
    fn dense_output(
        &mut self,
        _sys: &mut dyn SecondOrderSystem,
        _from: &Sample,
        _to: &Sample,
    ) -> Option<Result<DenseOutput, IntegrationError>> {
        None
    }
    /// Whether [`Self::interpolant`] can give the solution inside a step (a continuous
    /// extension for sampling, which events need not use).
    fn interpolates(&self) -> bool {
        false
    }
    /// An interpolant of the last step taken when it went from `from` to `to`: the solution
    /// anywhere inside it, for sampling (a controller's ticks inside a step). DOP853's dense
    /// output, DOPRI5's continuous extension (which its event location does not use); `None`
    /// otherwise. Its extra stages, if any, count as evaluations.
    fn interpolant(
        &mut self,
        _sys: &mut dyn SecondOrderSystem,
        _from: &Sample,
        _to: &Sample,
    ) -> Option<Result<DenseOutput, IntegrationError>> {
        None
    }
}
