//! One number of a gait that a study maps, optimises or constrains: its stability, one of the
//! robustness measures ([`crate::analysis::robustness`]), its cost of transport, speed, period
//! or step. Written once here: `walker stability-map --quantity`, `walker optimize
//! --objective` and `--constraint` name the same ones.

use crate::analysis::gait_sensitivity::gait_sensitivity_norm;
use crate::analysis::limit_cycle::Gait;
use crate::analysis::robustness::{
    mean_first_passage, step_threshold, FirstPassageOptions, Recovery, StepDirection,
    ThresholdOptions,
};
use crate::report::gait_numbers;
use crate::scene::Setup;
use serde::{Serialize, Serializer};

/// The default step of the gait sensitivity norm's central differences.
pub const GSN_PERTURBATION: f64 = 1e-6;

/// A quantity of a gait.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// The gait sensitivity norm (both indicators, floor-step disturbance).
    Gsn,
    /// The largest step down survived \[m\].
    StepDown,
    /// The largest step up survived \[m\].
    StepUp,
    /// The largest |eigenvalue| of the stride Jacobian.
    MaxAbsEigenvalue,
    /// The mean first-passage time on a rough floor \[steps\] (the floor and the Monte Carlo
    /// in [`QuantityOptions`]; when no walk fell, the strides simulated: more than any design
    /// that fell in the same Monte Carlo scores).
    Mfpt,
    /// Actuator work per unit mass and forward distance \[J/(kg m)\] (actuated walkers).
    CostOfTransport,
    /// Forward speed \[m/s\].
    SpeedMS,
    /// Step period \[s\].
    StepPeriodS,
    /// Distance between the contacts of one step \[m\].
    StepLengthM,
}

/// What a quantity needs besides the gait: the rough floor and the Monte Carlo of `mfpt`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct QuantityOptions {
    /// The rough floor's standard deviation of `mfpt` \[m\].
    pub sigma_m: Option<f64>,
    /// Its Monte Carlo.
    pub first_passage: FirstPassageOptions,
}

impl Quantity {
    /// Every quantity, in the order the help lists them.
    pub const ALL: [Self; 9] = [
        Self::Gsn,
        Self::StepDown,
        Self::StepUp,
        Self::MaxAbsEigenvalue,
        Self::Mfpt,
        Self::CostOfTransport,
        Self::SpeedMS,
        Self::StepPeriodS,
        Self::StepLengthM,
    ];

    /// Its name, as the command line and the reports write it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Gsn => "gsn",
            Self::StepDown => "step_down",
            Self::StepUp => "step_up",
            Self::MaxAbsEigenvalue => "max_abs_eigenvalue",
            Self::Mfpt => "mfpt",
            Self::CostOfTransport => "cost_of_transport",
            Self::SpeedMS => "speed_m_s",
            Self::StepPeriodS => "step_period_s",
            Self::StepLengthM => "step_length_m",
        }
    }

    /// Its unit.
    pub fn unit(self) -> &'static str {
        match self {
            Self::Gsn => "s/m and m/m",
            Self::StepDown | Self::StepUp | Self::StepLengthM => "m",
            Self::MaxAbsEigenvalue => "1",
            Self::Mfpt => "steps",
            Self::CostOfTransport => "J/(kg m)",
            Self::SpeedMS => "m/s",
            Self::StepPeriodS => "s",
        }
    }

    /// The quantity named `name`.
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|q| q.name() == name)
    }

    /// Whether it measures how a disturbance dies out (the robustness measures): undefined at
    /// an unstable gait.
    pub fn needs_stable_gait(self) -> bool {
        matches!(self, Self::Gsn | Self::StepDown | Self::StepUp | Self::Mfpt)
    }

    /// The names, comma-separated (for messages).
    pub fn names() -> String {
        Self::ALL.map(Self::name).join(", ")
    }

    /// Checks that `options` give what this quantity needs (`mfpt`: a finite σ ≥ 0).
    ///
    /// # Errors
    /// `mfpt` without its floor, or with a σ that is not a finite number ≥ 0.
    pub fn check(self, options: &QuantityOptions) -> Result<(), QuantityError> {
        match (self, options.sigma_m) {
            (Self::Mfpt, None) => Err(QuantityError::NoSigma),
            (Self::Mfpt, Some(s)) if !(s.is_finite() && s >= 0.0) => {
                Err(QuantityError::BadSigma(s))
            }
            _ => Ok(()),
        }
    }

    /// Its value at `gait` of the walker `setup` builds (strides with `setup`'s settings).
    ///
    /// # Errors
    /// Undefined for this walker, a stride that failed, `mfpt` without its floor.
    pub fn evaluate(
        self,
        setup: &Setup,
        gait: &Gait,
        options: &QuantityOptions,
    ) -> Result<f64, QuantityError> {
        let walker = &setup.walker;
        if self.needs_stable_gait() && !gait.stable() {
            return Err(QuantityError::Undefined {
                quantity: self,
                why: format!(
                    "the gait is unstable (max |λ| = {}): a disturbance grows instead of dying \
                     out",
                    gait.max_abs_eigenvalue()
                ),
            });
        }
        let recovery = || Recovery::new(walker, &setup.settings, gait);
        let step =
            |direction| step_threshold(&recovery(), &ThresholdOptions::steps(), direction).max;
        match self {
            Self::Gsn => gait_sensitivity_norm(walker, &setup.settings, gait, GSN_PERTURBATION)
                .map(|s| s.both)
                .map_err(|e| QuantityError::StrideFailed(e.to_string())),
            Self::StepDown => Ok(step(StepDirection::Down)),
            Self::StepUp => Ok(step(StepDirection::Up)),
            Self::Mfpt => {
                self.check(options)?;
                let sigma_m = options.sigma_m.ok_or(QuantityError::NoSigma)?;
                let m = mean_first_passage(&recovery(), sigma_m, &options.first_passage).map_err(
                    |e| QuantityError::Undefined {
                        quantity: self,
                        why: e.to_string(),
                    },
                )?;
                // No walk fell: the strides simulated, which no design that fell in the same
                // Monte Carlo exceeds (T/d ≤ T), so maximising never prefers falling.
                Ok(m.steps.unwrap_or(m.strides_simulated as f64))
            }
            Self::MaxAbsEigenvalue => Ok(gait.max_abs_eigenvalue()),
            Self::CostOfTransport => {
                if walker.ankle().is_none() {
                    return Err(QuantityError::Undefined {
                        quantity: self,
                        why: "the walker has no actuated ankle (its energy comes from the \
                              slope); `walker gait` reports a cost of transport for actuated \
                              walkers only"
                            .to_owned(),
                    });
                }
                let mass = walker.model().total_mass_kg();
                let progress = gait_numbers(walker, gait).progress_m;
                Ok(gait.stride.actuator_work_j / (mass * progress))
            }
            Self::SpeedMS => Ok(gait_numbers(walker, gait).speed_m_s),
            Self::StepPeriodS => Ok(gait_numbers(walker, gait).step_period_s),
            Self::StepLengthM => Ok(gait_numbers(walker, gait).step_length_m),
        }
    }
}

impl Serialize for Quantity {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.name())
    }
}

impl std::fmt::Display for Quantity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Why a quantity has no value.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum QuantityError {
    /// No quantity of that name.
    #[error("unknown quantity `{0}` (expected one of {names})", names = Quantity::names())]
    Unknown(String),
    /// `mfpt` without its rough floor.
    #[error("mfpt needs the rough floor's standard deviation (--sigma-m)")]
    NoSigma,
    /// `mfpt` with a σ that is not a finite number ≥ 0.
    #[error("--sigma-m {0}: a standard deviation must be a finite number ≥ 0")]
    BadSigma(f64),
    /// It has no meaning for this walker.
    #[error("{quantity} is undefined here: {why}")]
    Undefined {
        /// The quantity.
        quantity: Quantity,
        /// Why, in words.
        why: String,
    },
    /// A stride it needed failed.
    #[error("a stride failed: {0}")]
    StrideFailed(String),
}

/// `quantity` of the period-1 gait through `fixed_point` (a stride-map vector) of `scene`
/// built by `setup_for`: the gait re-found by Newton from it (it is already a fixed point: the
/// search costs its Jacobian), then [`Quantity::evaluate`]. For a point of a continuation
/// (`walker sweep --quantity`), whose points carry their fixed points but not a [`Gait`].
///
/// # Errors
/// A scene that cannot be built, a gait Newton does not find again, the quantity's own.
pub fn at_fixed_point(
    quantity: Quantity,
    options: &QuantityOptions,
    scene: &crate::scene::Scene,
    setup_for: &crate::analysis::homotopy::SetupFor<'_>,
    newton: &crate::analysis::limit_cycle::NewtonSettings,
    fixed_point: &nalgebra::DVector<f64>,
) -> Result<f64, QuantityError> {
    let undefined = |why: String| QuantityError::Undefined { quantity, why };
    let setup = setup_for(scene).map_err(|e| undefined(e.to_string()))?;
    let gait =
        crate::analysis::limit_cycle::GaitSearch::new(&setup.walker, &setup.settings, newton)
            .find(fixed_point)
            .map_err(|e| {
                undefined(format!(
                    "the gait was not found again from its fixed point: {e}"
                ))
            })?;
    quantity.evaluate(&setup, &gait, options)
}
