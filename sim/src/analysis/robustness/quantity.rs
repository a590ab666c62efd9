//! One number of a gait that a study maps, sweeps or optimises: its stability (the largest
//! |eigenvalue|) or one of the robustness measures. Written once here; the stability map's
//! `--quantity` and the optimiser's `--objective` name the same ones.

use super::first_passage::{mean_first_passage, FirstPassageOptions};
use super::recovery::Recovery;
use super::threshold::{step_threshold, StepDirection, ThresholdOptions};
use crate::analysis::gait_sensitivity::gait_sensitivity_norm;
use crate::analysis::limit_cycle::Gait;
use crate::engine::walker::Walker;
use crate::stride::StrideSettings;
use serde::Serialize;

/// A number of a gait.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "name", rename_all = "snake_case")]
pub enum Quantity {
    /// The largest |eigenvalue| of the stride Jacobian (smaller is more stable).
    MaxAbsEigenvalue,
    /// The gait sensitivity norm for both indicators \[s/m and m/m\] (smaller rejects floor
    /// steps better).
    Gsn,
    /// The largest step down survived \[m\].
    StepDown,
    /// The largest step up survived \[m\].
    StepUp,
    /// The mean first-passage time on a rough floor \[steps\] (the lower end of its interval
    /// when no walk fell).
    Mfpt {
        /// The floor's standard deviation \[m\].
        sigma_m: f64,
        /// The Monte Carlo.
        #[serde(skip)]
        options: FirstPassageOptions,
    },
}

/// The quantities' names, as options take them.
pub const QUANTITY_NAMES: [&str; 5] = ["max_abs_eigenvalue", "gsn", "step_down", "step_up", "mfpt"];

/// Why a quantity could not be had.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum QuantityError {
    /// No such quantity.
    #[error("unknown quantity `{0}` (expected one of max_abs_eigenvalue, gsn, step_down, step_up, mfpt)")]
    Unknown(String),
    /// `mfpt` without a roughness.
    #[error("mfpt needs the rough floor's standard deviation (--sigma-m)")]
    NoSigma,
    /// A stride of the measure failed (the gait sensitivity norm's perturbed strides).
    #[error("{0}")]
    Stride(String),
    /// The first-passage Monte Carlo was refused.
    #[error("{0}")]
    FirstPassage(String),
}

impl Quantity {
    /// The quantity named `name` (`mfpt` with `sigma_m` and `options`).
    ///
    /// # Errors
    /// An unknown name; `mfpt` without `sigma_m`.
    pub fn parse(
        name: &str,
        sigma_m: Option<f64>,
        options: FirstPassageOptions,
    ) -> Result<Self, QuantityError> {
        Ok(match name {
            "max_abs_eigenvalue" => Quantity::MaxAbsEigenvalue,
            "gsn" => Quantity::Gsn,
            "step_down" => Quantity::StepDown,
            "step_up" => Quantity::StepUp,
            "mfpt" => Quantity::Mfpt {
                sigma_m: sigma_m.ok_or(QuantityError::NoSigma)?,
                options,
            },
            other => return Err(QuantityError::Unknown(other.to_owned())),
        })
    }

    /// Its name.
    pub fn name(&self) -> &'static str {
        match self {
            Quantity::MaxAbsEigenvalue => "max_abs_eigenvalue",
            Quantity::Gsn => "gsn",
            Quantity::StepDown => "step_down",
            Quantity::StepUp => "step_up",
            Quantity::Mfpt { .. } => "mfpt",
        }
    }

    /// Its unit.
    pub fn unit(&self) -> &'static str {
        match self {
            Quantity::MaxAbsEigenvalue => "",
            Quantity::Gsn => "s/m, m/m",
            Quantity::StepDown | Quantity::StepUp => "m",
            Quantity::Mfpt { .. } => "steps",
        }
    }

    /// Whether a larger value is the better design (the thresholds and first-passage times).
    pub fn larger_is_better(&self) -> bool {
        matches!(
            self,
            Quantity::StepDown | Quantity::StepUp | Quantity::Mfpt { .. }
        )
    }

    /// Its value for `gait` of `walker` (strides with `settings`).
    ///
    /// # Errors
    /// A measure that could not be computed (a perturbed stride that failed, a refused
    /// Monte Carlo).
    pub fn of(
        &self,
        walker: &Walker,
        settings: &StrideSettings,
        gait: &Gait,
    ) -> Result<f64, QuantityError> {
        let recovery = Recovery::new(walker, settings, gait);
        match self {
            Quantity::MaxAbsEigenvalue => Ok(gait.max_abs_eigenvalue()),
            Quantity::Gsn => gait_sensitivity_norm(walker, settings, gait, 1e-6)
                .map(|g| g.both)
                .map_err(|e| QuantityError::Stride(e.to_string())),
            Quantity::StepDown => {
                Ok(step_threshold(&recovery, &ThresholdOptions::steps(), StepDirection::Down).max)
            }
            Quantity::StepUp => {
                Ok(step_threshold(&recovery, &ThresholdOptions::steps(), StepDirection::Up).max)
            }
            Quantity::Mfpt { sigma_m, options } => {
                let m = mean_first_passage(&recovery, *sigma_m, options)
                    .map_err(|e| QuantityError::FirstPassage(e.to_string()))?;
                Ok(m.steps.unwrap_or(m.ci_low))
            }
        }
    }
}
