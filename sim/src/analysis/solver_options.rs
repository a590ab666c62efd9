//! The numerical options every scene study shares: the integrator, its fixed step or its
//! tolerance, and the gait search's Newton settings and stride budget. Checked and applied
//! once here, for the `walker` command's shared options and the Python package's
//! `Scene.with_solver`.

use super::homotopy::{HomotopySettings, DEFAULT_GAIT_STRIDE_BUDGET};
use super::limit_cycle::{JacobianMethod, NewtonSettings};
use crate::engine::integrators::IntegratorChoice;
use crate::scene::short_number;
use crate::stride::StrideSettings;

/// The options; [`Default`] is every command's default (the scene's own integrator).
#[derive(Clone, Debug, PartialEq)]
pub struct SolverOptions {
    /// The integrator: `meijaard`, `rk4`, `dopri5` or `dop853` (`None`: the scene's).
    pub integrator: Option<String>,
    /// The fixed step of `meijaard` and `rk4` \[s\] (`None`: the scene's or the default).
    pub step_s: Option<f64>,
    /// The relative and absolute tolerance of `dopri5` and `dop853` (`None`: the scene's).
    pub rtol: Option<f64>,
    /// Newton's tolerance on |Δv|.
    pub newton_tol: f64,
    /// Newton's iteration budget.
    pub newton_max_iter: usize,
    /// Strides one gait search may take (its Newton searches and the path from the defaults).
    pub max_strides: usize,
    /// The perturbation step of the stride Jacobian's differences.
    pub perturbation: f64,
    /// The perturbed strides replay the nominal stride's steps.
    pub frozen_steps: bool,
    /// How the stride Jacobian is computed.
    pub jacobian: JacobianMethod,
}

impl Default for SolverOptions {
    fn default() -> Self {
        let newton = NewtonSettings::default();
        Self {
            integrator: None,
            step_s: None,
            rtol: None,
            newton_tol: newton.tolerance,
            newton_max_iter: newton.max_iterations,
            max_strides: DEFAULT_GAIT_STRIDE_BUDGET,
            perturbation: newton.perturbation,
            frozen_steps: newton.frozen_steps,
            jacobian: newton.jacobian,
        }
    }
}

/// An option refused, by its field name (`step_s`, `newton_max_iter`, ...), which the command
/// spells as a flag (`--step-s`) and the Python package as a keyword.
#[derive(Clone, Debug, PartialEq)]
pub enum SolverOptionError {
    /// A number that must be finite and positive.
    NotPositive {
        /// The option.
        option: &'static str,
        /// Its value.
        value: f64,
    },
    /// A count that must be at least 1.
    Zero {
        /// The option.
        option: &'static str,
        /// What it counts.
        counts: &'static str,
    },
    /// A Jacobian method that is not `central` or `variational`.
    UnknownJacobian(String),
    /// An integrator that is not one of the four.
    UnknownIntegrator(String),
    /// A fixed step for an integrator that chooses its own.
    StepForAdaptive(&'static str),
    /// A tolerance for a fixed-step integrator.
    TolForFixedStep(&'static str),
    /// Settings the stride cannot run with (a step too small for its budgets).
    Settings(String),
}

impl SolverOptionError {
    /// The message, each option spelled by `spell` (its field name to the front end's
    /// spelling).
    pub fn message(&self, spell: &dyn Fn(&str) -> String) -> String {
        match self {
            Self::NotPositive { option, value } => format!(
                "{} must be a positive number, got {}",
                spell(option),
                short_number(*value)
            ),
            Self::Zero { option, counts } => {
                format!("{} must be at least 1 ({counts})", spell(option))
            }
            Self::UnknownJacobian(name) => format!(
                "{} `{name}`: expected central or variational",
                spell("jacobian")
            ),
            Self::UnknownIntegrator(name) => format!(
                "{} `{name}`: expected meijaard, rk4, dopri5 or dop853",
                spell("integrator")
            ),
            Self::StepForAdaptive(kind) => format!(
                "{} sets the fixed step of meijaard and rk4; the integrator here is {kind}, \
                 which chooses its own steps (use {}, or {} rk4)",
                spell("step_s"),
                spell("rtol"),
                spell("integrator")
            ),
            Self::TolForFixedStep(kind) => format!(
                "{} sets the tolerance of dopri5 and dop853; the integrator here is {kind}, \
                 with a fixed step (use {}, or {} dop853)",
                spell("rtol"),
                spell("step_s"),
                spell("integrator")
            ),
            Self::Settings(why) => why.clone(),
        }
    }
}

impl std::fmt::Display for SolverOptionError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message(&|name| name.to_owned()))
    }
}

impl std::error::Error for SolverOptionError {}

/// The Jacobian method named `name` (`central`, `variational`).
///
/// # Errors
/// Any other name.
pub fn jacobian_method(name: &str) -> Result<JacobianMethod, SolverOptionError> {
    match name {
        "central" => Ok(JacobianMethod::CentralDifferences),
        "variational" => Ok(JacobianMethod::Variational),
        other => Err(SolverOptionError::UnknownJacobian(other.to_owned())),
    }
}

/// The name of a Jacobian method, as [`jacobian_method`] reads it.
pub fn jacobian_name(method: JacobianMethod) -> &'static str {
    match method {
        JacobianMethod::CentralDifferences => "central",
        JacobianMethod::Variational => "variational",
    }
}

impl SolverOptions {
    /// Applies the integrator options to a scene's stride settings, after checking every
    /// numeric option.
    ///
    /// # Errors
    /// A number that is not positive, a zero count, an unknown integrator, a step for an
    /// adaptive integrator or a tolerance for a fixed-step one (refused, not ignored), settings
    /// the stride cannot run with.
    pub fn configure(&self, settings: &mut StrideSettings) -> Result<(), SolverOptionError> {
        let positive = |option: &'static str, v: Option<f64>| match v {
            Some(value) if !(value.is_finite() && value > 0.0) => {
                Err(SolverOptionError::NotPositive { option, value })
            }
            _ => Ok(()),
        };
        positive("step_s", self.step_s)?;
        positive("rtol", self.rtol)?;
        positive("newton_tol", Some(self.newton_tol))?;
        if self.max_strides == 0 {
            return Err(SolverOptionError::Zero {
                option: "max_strides",
                counts: "strides one gait search may take",
            });
        }
        if self.newton_max_iter == 0 {
            return Err(SolverOptionError::Zero {
                option: "newton_max_iter",
                counts: "Newton iterations allowed",
            });
        }
        positive("perturbation", Some(self.perturbation))?;
        if let Some(kind) = &self.integrator {
            settings.integrator =
                IntegratorChoice::from_kind(kind, self.step_s, self.rtol, None, None)
                    .ok_or_else(|| SolverOptionError::UnknownIntegrator(kind.clone()))?;
        } else {
            settings.integrator = settings
                .integrator
                .with_tolerance_or_step(self.rtol, self.step_s);
        }
        // An option the chosen integrator would ignore is refused, not dropped in silence.
        let adaptive = matches!(
            settings.integrator,
            IntegratorChoice::Dopri5 { .. } | IntegratorChoice::Dop853 { .. }
        );
        let kind = settings.integrator.kind();
        if adaptive && self.step_s.is_some() {
            return Err(SolverOptionError::StepForAdaptive(kind));
        }
        if !adaptive && self.rtol.is_some() {
            return Err(SolverOptionError::TolForFixedStep(kind));
        }
        // A step too small for the stride's budgets would only run out of them, slowly.
        settings
            .validate()
            .map_err(|e| SolverOptionError::Settings(e.to_string()))
    }

    /// The gait search's Newton settings.
    pub fn newton(&self) -> NewtonSettings {
        NewtonSettings {
            tolerance: self.newton_tol,
            max_iterations: self.newton_max_iter,
            perturbation: self.perturbation,
            frozen_steps: self.frozen_steps,
            jacobian: self.jacobian,
            ..NewtonSettings::default()
        }
    }

    /// How a gait is followed from the scene's defaults, with the gait's budget of strides.
    pub fn homotopy(&self) -> HomotopySettings {
        HomotopySettings {
            gait_stride_budget: self.max_strides,
            ..HomotopySettings::default()
        }
    }

    /// Whether these are the defaults (a front end need not mention them).
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }
}
