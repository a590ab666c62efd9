//! Which integrator a stride uses, with its settings, validated and built.

use super::integrator::Integrator;
use super::{Dop853, Dopri5, Meijaard, Rk4};
use serde::{Deserialize, Serialize};

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
