//! The settings of a continuation in one validated value (after BifurcationKit's
//! `ContinuationPar`): the Newton settings of every fixed point, the step bounds, the
//! corrector's budget, which bifurcations are located, the branch budgets and how the first
//! gait is found. Built by [`ContinuationSettings::builder`] and checked once, by
//! [`ContinuationSettingsBuilder::build`]; every [`super::Continuation`] carries the settings
//! that produced it.

use crate::analysis::homotopy::HomotopySettings;
use crate::analysis::limit_cycle::NewtonSettings;
use crate::stride::{SharedBudget, StrideSettings};

/// Which bifurcations a continuation locates (all by default;
/// [`super::BifurcationKind::detected_by`]). A kind not detected is neither
/// located nor reported; the branch is followed through it all the same. Without period
/// doublings no period-doubled branch is started; without folds a branch that turns back ends
/// at the point past the range, and a closed branch (which needs two folds) is not
/// recognised.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Detection {
    /// Folds and branch points (a real multiplier through +1).
    pub folds: bool,
    /// Period doublings (a real multiplier through −1).
    pub period_doublings: bool,
    /// Neimark-Sacker bifurcations (a complex pair through the unit circle).
    pub neimark_sacker: bool,
}

impl Default for Detection {
    fn default() -> Self {
        Self {
            folds: true,
            period_doublings: true,
            neimark_sacker: true,
        }
    }
}

/// A continuation setting out of its range, with the value given.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SettingsError {
    /// A count that must be at least `min`.
    #[error("{name} must be at least {min}, got {value}")]
    CountTooSmall {
        /// The setting.
        name: &'static str,
        /// Its value.
        value: usize,
        /// The least value allowed.
        min: usize,
    },
    /// A real setting outside its range (or not finite).
    #[error("{name} must be {range}, got {value}")]
    OutOfRange {
        /// The setting.
        name: &'static str,
        /// Its value.
        value: f64,
        /// The range allowed, in words.
        range: &'static str,
    },
}

/// The settings of a pseudo-arclength continuation ([`super::continuation`]). Read-only once
/// built: [`ContinuationSettings::builder`] starts from the defaults (listed field by field),
/// [`ContinuationSettingsBuilder::build`] refuses a value out of range.
#[derive(Clone, Debug, PartialEq)]
pub struct ContinuationSettings {
    newton: NewtonSettings,
    max_period: usize,
    steps_per_branch: usize,
    max_branches: usize,
    max_arclength_steps: f64,
    min_step_fraction: f64,
    corrector_iterations: usize,
    max_turn_deg: f64,
    detect: Detection,
    stride_settings: Option<StrideSettings>,
    search_budget: SharedBudget,
    start_attempts: usize,
    homotopy: HomotopySettings,
}

impl Default for ContinuationSettings {
    fn default() -> Self {
        Self {
            newton: NewtonSettings::default(),
            max_period: 8,
            steps_per_branch: 400,
            max_branches: 8,
            max_arclength_steps: 10.0,
            min_step_fraction: 1e-4,
            corrector_iterations: 12,
            max_turn_deg: 60.0,
            detect: Detection::default(),
            stride_settings: None,
            search_budget: SharedBudget::default(),
            start_attempts: 64,
            homotopy: HomotopySettings::default(),
        }
    }
}

impl ContinuationSettings {
    /// A builder starting from the defaults.
    pub fn builder() -> ContinuationSettingsBuilder {
        ContinuationSettingsBuilder(Self::default())
    }

    /// The Newton settings: the tolerance and budget of every gait search (the first gait),
    /// the Jacobians' method and perturbation (also the step of `∂S/∂p`), and the corrector's
    /// convergence tolerance. Default: [`NewtonSettings::default`].
    pub fn newton(&self) -> &NewtonSettings {
        &self.newton
    }

    /// Largest period followed (1, 2, 4, …): branches of period up to this are followed, and
    /// the period doublings on them located. Default 8.
    pub fn max_period(&self) -> usize {
        self.max_period
    }

    /// Steps allowed per branch. Default 400.
    pub fn steps_per_branch(&self) -> usize {
        self.steps_per_branch
    }

    /// Branches allowed in all. Default 8.
    pub fn max_branches(&self) -> usize {
        self.max_branches
    }

    /// Largest arclength step in grid spacings (the parameter moves at most one spacing per
    /// step in any case; the state may move more). Default 10.
    pub fn max_arclength_steps(&self) -> f64 {
        self.max_arclength_steps
    }

    /// Smallest step as a fraction of the grid spacing (at most the first step, half a
    /// spacing). Default 1e-4.
    pub fn min_step_fraction(&self) -> f64 {
        self.min_step_fraction
    }

    /// Corrector iteration budget. Default 12.
    pub fn corrector_iterations(&self) -> usize {
        self.corrector_iterations
    }

    /// Largest turn of the tangent in one accepted step \[degrees\]; a step that turns more is
    /// halved, and at the smallest step the branch ends (`not_converged`) rather than jump.
    /// Default 60.
    pub fn max_turn_deg(&self) -> f64 {
        self.max_turn_deg
    }

    /// Which bifurcations are located. Default: all.
    pub fn detect(&self) -> Detection {
        self.detect
    }

    /// Stride settings for every parameter value instead of the scene's (`None`, the
    /// default: the scene's own at each value).
    pub fn stride_settings(&self) -> Option<&StrideSettings> {
        self.stride_settings.as_ref()
    }

    /// The budget every stride of the continuation's branches takes from (none by default): a
    /// caller cancels it to stop the sweep at its next stride (Ctrl-C in the Python package).
    pub fn search_budget(&self) -> &SharedBudget {
        &self.search_budget
    }

    /// Grid values tried for a first gait ([`crate::analysis::homotopy::long_period_gait`]):
    /// the first four from `from` on, then spread over the range by halving. Default 64.
    pub fn start_attempts(&self) -> usize {
        self.start_attempts
    }

    /// How the first gait is followed from the scene's defaults. Default:
    /// [`HomotopySettings::default`].
    pub fn homotopy(&self) -> &HomotopySettings {
        &self.homotopy
    }

    /// Every setting in its range.
    fn validate(&self) -> Result<(), SettingsError> {
        let count = |name: &'static str, value: usize, min: usize| {
            if value < min {
                Err(SettingsError::CountTooSmall { name, value, min })
            } else {
                Ok(())
            }
        };
        let real = |name: &'static str, value: f64, ok: bool, range: &'static str| {
            if ok && value.is_finite() {
                Ok(())
            } else {
                Err(SettingsError::OutOfRange { name, value, range })
            }
        };
        let n = &self.newton;
        real("newton.tolerance", n.tolerance, n.tolerance > 0.0, "> 0")?;
        count("newton.max_iterations", n.max_iterations, 1)?;
        real(
            "newton.perturbation",
            n.perturbation,
            n.perturbation > 0.0,
            "> 0",
        )?;
        count("max_period", self.max_period, 1)?;
        count("steps_per_branch", self.steps_per_branch, 1)?;
        count("max_branches", self.max_branches, 1)?;
        count("corrector_iterations", self.corrector_iterations, 1)?;
        count("start_attempts", self.start_attempts, 1)?;
        let (min, max) = (self.min_step_fraction, self.max_arclength_steps);
        real(
            "min_step_fraction",
            min,
            min > 0.0 && min <= 0.5,
            "in (0, 0.5] (at most the first step, half a grid spacing)",
        )?;
        real(
            "max_arclength_steps",
            max,
            max >= 0.5,
            "at least 0.5 (the first step, half a grid spacing)",
        )?;
        let turn = self.max_turn_deg;
        real(
            "max_turn_deg",
            turn,
            turn > 0.0 && turn <= 180.0,
            "in (0, 180]",
        )?;
        let h = &self.homotopy;
        real(
            "homotopy.min_step",
            h.min_step,
            h.min_step > 0.0 && h.min_step <= 1.0,
            "in (0, 1]",
        )?;
        real(
            "homotopy.first_step",
            h.first_step,
            h.first_step >= h.min_step && h.first_step <= 1.0,
            "in [homotopy.min_step, 1]",
        )?;
        real(
            "homotopy.max_correction",
            h.max_correction,
            h.max_correction > 0.0,
            "> 0",
        )?;
        real(
            "homotopy.max_period_change",
            h.max_period_change,
            h.max_period_change > 0.0,
            "> 0",
        )?;
        count("homotopy.max_solves", h.max_solves, 1)?;
        real(
            "homotopy.path_tolerance",
            h.path_tolerance,
            h.path_tolerance > 0.0,
            "> 0",
        )?;
        count(
            "homotopy.max_corrector_iterations",
            h.max_corrector_iterations,
            1,
        )?;
        count("homotopy.max_corrector_stalls", h.max_corrector_stalls, 1)
    }
}

/// Builds [`ContinuationSettings`] from the defaults; [`Self::build`] checks them.
#[derive(Clone, Debug)]
pub struct ContinuationSettingsBuilder(ContinuationSettings);

impl ContinuationSettingsBuilder {
    /// See [`ContinuationSettings::newton`].
    pub fn newton(mut self, newton: NewtonSettings) -> Self {
        self.0.newton = newton;
        self
    }

    /// See [`ContinuationSettings::max_period`].
    pub fn max_period(mut self, strides: usize) -> Self {
        self.0.max_period = strides;
        self
    }

    /// See [`ContinuationSettings::steps_per_branch`].
    pub fn steps_per_branch(mut self, steps: usize) -> Self {
        self.0.steps_per_branch = steps;
        self
    }

    /// See [`ContinuationSettings::max_branches`].
    pub fn max_branches(mut self, branches: usize) -> Self {
        self.0.max_branches = branches;
        self
    }

    /// See [`ContinuationSettings::max_arclength_steps`].
    pub fn max_arclength_steps(mut self, spacings: f64) -> Self {
        self.0.max_arclength_steps = spacings;
        self
    }

    /// See [`ContinuationSettings::min_step_fraction`].
    pub fn min_step_fraction(mut self, fraction: f64) -> Self {
        self.0.min_step_fraction = fraction;
        self
    }

    /// See [`ContinuationSettings::corrector_iterations`].
    pub fn corrector_iterations(mut self, iterations: usize) -> Self {
        self.0.corrector_iterations = iterations;
        self
    }

    /// See [`ContinuationSettings::max_turn_deg`].
    pub fn max_turn_deg(mut self, deg: f64) -> Self {
        self.0.max_turn_deg = deg;
        self
    }

    /// See [`ContinuationSettings::detect`].
    pub fn detect(mut self, detect: Detection) -> Self {
        self.0.detect = detect;
        self
    }

    /// See [`ContinuationSettings::stride_settings`].
    pub fn stride_settings(mut self, settings: Option<StrideSettings>) -> Self {
        self.0.stride_settings = settings;
        self
    }

    /// See [`ContinuationSettings::search_budget`].
    pub fn search_budget(mut self, budget: SharedBudget) -> Self {
        self.0.search_budget = budget;
        self
    }

    /// See [`ContinuationSettings::start_attempts`].
    pub fn start_attempts(mut self, attempts: usize) -> Self {
        self.0.start_attempts = attempts;
        self
    }

    /// See [`ContinuationSettings::homotopy`].
    pub fn homotopy(mut self, homotopy: HomotopySettings) -> Self {
        self.0.homotopy = homotopy;
        self
    }

    /// The settings, each checked.
    ///
    /// # Errors
    /// [`SettingsError`]: the first setting out of its range, with its value.
    pub fn build(self) -> Result<ContinuationSettings, SettingsError> {
        self.0.validate()?;
        Ok(self.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_defaults_are_valid_and_each_bad_value_is_named() {
        let settings = ContinuationSettings::builder().build().unwrap();
        assert_eq!(settings, ContinuationSettings::default());
        assert_eq!(settings.newton(), &NewtonSettings::default());
        let refused = |b: ContinuationSettingsBuilder| b.build().unwrap_err().to_string();
        let b = ContinuationSettings::builder;
        assert_eq!(
            refused(b().max_period(0)),
            "max_period must be at least 1, got 0"
        );
        assert!(refused(b().min_step_fraction(0.0)).starts_with("min_step_fraction must be"));
        assert!(refused(b().min_step_fraction(0.6)).starts_with("min_step_fraction must be"));
        assert!(refused(b().max_turn_deg(f64::NAN)).starts_with("max_turn_deg must be"));
        assert!(refused(b().max_arclength_steps(0.1)).starts_with("max_arclength_steps"));
        let newton = NewtonSettings {
            tolerance: -1.0,
            ..NewtonSettings::default()
        };
        assert!(refused(b().newton(newton)).starts_with("newton.tolerance must be > 0"));
        let homotopy = HomotopySettings {
            first_step: 2.0,
            ..HomotopySettings::default()
        };
        assert!(refused(b().homotopy(homotopy)).starts_with("homotopy.first_step"));
        let homotopy = HomotopySettings {
            max_corrector_stalls: 0,
            ..HomotopySettings::default()
        };
        assert!(refused(b().homotopy(homotopy)).starts_with("homotopy.max_corrector_stalls"));
        let built = b().max_period(2).max_branches(1).build().unwrap();
        assert_eq!((built.max_period(), built.max_branches()), (2, 1));
    }
}
