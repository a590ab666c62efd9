//! The `walker robustness --json` report: how much disturbance a gait survives (the gait
//! sensitivity norm, the largest step down and up, the largest change of each rate, the mean
//! first-passage time on rough floors; docs/robustness.md), with the options that choose the
//! measures, checked once here for the command and the Python package.

use super::GaitReport;
use crate::analysis::gait_sensitivity::{gait_sensitivity_norm, GaitSensitivity};
use crate::analysis::homotopy::GaitSource;
use crate::analysis::limit_cycle::{Gait, NewtonError};
use crate::analysis::robustness::{
    mean_first_passage, step_thresholds, velocity_thresholds, FirstPassage, FirstPassageOptions,
    Recovery, ReturnRule, StepThresholds, ThresholdOptions, VelocityThreshold,
};
use crate::scene::{short_number, Scene, Setup};
use serde::Serialize;
use std::collections::BTreeMap;

/// Most Monte Carlo walks per roughness.
pub const MAX_MFPT_RUNS: usize = 100_000;
/// Most strides of one Monte Carlo walk.
pub const MAX_MFPT_STRIDES: usize = 1_000_000;
/// Most Monte Carlo strides per roughness (walks × strides per walk).
pub const MAX_MFPT_TOTAL_STRIDES: usize = 100_000_000;
/// Most roughness values.
pub const MAX_SIGMAS: usize = 64;
/// Most strides a disturbed walker may take to come back to the gait.
pub const MAX_RETURN_STRIDES: usize = 100_000;
/// Finest grid step of the rate thresholds' scan [natural rates].
pub const MIN_RATE_SCAN_STEP: f64 = 1e-6;

/// The measures to take; the others are reported as `null`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Measures {
    /// The gait sensitivity norm.
    pub gsn: bool,
    /// The largest step down and up.
    pub steps: bool,
    /// The largest change of each rate.
    pub rates: bool,
    /// The mean first-passage time on rough floors.
    pub mfpt: bool,
}

impl Default for Measures {
    /// Every measure.
    fn default() -> Self {
        Self {
            gsn: true,
            steps: true,
            rates: true,
            mfpt: true,
        }
    }
}

impl Measures {
    /// The measures' names, as a list names them.
    pub const NAMES: [&'static str; 4] = ["gsn", "steps", "rates", "mfpt"];

    /// No measure.
    const fn none() -> Self {
        Self {
            gsn: false,
            steps: false,
            rates: false,
            mfpt: false,
        }
    }

    /// The measures `names` lists (`gsn`, `steps`, `rates`, `mfpt`; whitespace around each
    /// ignored).
    ///
    /// # Errors
    /// A name that is not a measure, or no name.
    pub fn from_names<'a>(
        names: impl IntoIterator<Item = &'a str>,
    ) -> Result<Self, RobustnessOptionError> {
        let mut m = Self::none();
        for name in names.into_iter().map(str::trim) {
            let slot = match name {
                "gsn" => &mut m.gsn,
                "steps" => &mut m.steps,
                "rates" => &mut m.rates,
                "mfpt" => &mut m.mfpt,
                other => return Err(RobustnessOptionError::UnknownMeasure(other.to_owned())),
            };
            *slot = true;
        }
        if m == Self::none() {
            return Err(RobustnessOptionError::NoMeasure);
        }
        Ok(m)
    }
}

/// What `walker robustness` measures and how.
#[derive(Clone, Debug)]
pub struct RobustnessOptions {
    /// The measures to take.
    pub measures: Measures,
    /// The rough floors' standard deviations for the mean first-passage time \[m\]; empty: 0.001,
    /// 0.003 and 0.01 leg lengths.
    pub sigma_m: Vec<f64>,
    /// The Monte Carlo walks per roughness, their strides and seeds.
    pub first_passage: FirstPassageOptions,
    /// The scan's grid step of the rate thresholds \[natural rates sqrt(g/L)\].
    pub rate_scan_step: f64,
    /// Strides a disturbed walker may take to come back within the return rule's tolerance.
    pub return_strides: usize,
    /// The perturbation of the gait sensitivity norm's finite differences.
    pub perturbation: f64,
}

impl Default for RobustnessOptions {
    /// `walker robustness`'s defaults.
    fn default() -> Self {
        Self {
            measures: Measures::default(),
            sigma_m: Vec::new(),
            first_passage: FirstPassageOptions::default(),
            rate_scan_step: 1e-2,
            return_strides: ReturnRule::default().max_strides,
            perturbation: 1e-6,
        }
    }
}

/// An option of [`RobustnessOptions`] out of its range: the option by its field name
/// (`mfpt_runs`, `sigma_m`, ...), which the command spells as a flag (`--mfpt-runs`) and the
/// Python package as a keyword.
#[derive(Clone, Debug, PartialEq)]
pub enum RobustnessOptionError {
    /// A measure name that is not one of [`Measures::NAMES`].
    UnknownMeasure(String),
    /// No measure named.
    NoMeasure,
    /// A count outside `min..=max`.
    Count {
        /// The option.
        option: &'static str,
        /// Its value.
        value: usize,
        /// Smallest allowed.
        min: usize,
        /// Largest allowed.
        max: usize,
    },
    /// Runs × strides over [`MAX_MFPT_TOTAL_STRIDES`].
    TooManyMonteCarloStrides {
        /// Walks.
        runs: usize,
        /// Strides per walk.
        strides: usize,
    },
    /// The rate scan step outside `MIN_RATE_SCAN_STEP..=` the scan's limit.
    RateScanStep(f64),
    /// Roughness given without the mean first-passage time among the measures.
    SigmaWithoutMfpt,
    /// More than [`MAX_SIGMAS`] roughness values.
    TooManySigmas(usize),
    /// A roughness that is not a finite number ≥ 0.
    Sigma(f64),
    /// A perturbation that is not a finite number > 0.
    Perturbation(f64),
}

impl RobustnessOptionError {
    /// The message, each option spelled by `spell` (its field name to the front end's
    /// spelling: `--mfpt-runs` for the command, `mfpt_runs` for Python).
    pub fn message(&self, spell: &dyn Fn(&str) -> String) -> String {
        match self {
            Self::UnknownMeasure(name) => format!(
                "{}: unknown measure `{name}` (expected {})",
                spell("measures"),
                Measures::NAMES.join(", ")
            ),
            Self::NoMeasure => format!(
                "{}: name at least one measure of {}",
                spell("measures"),
                Measures::NAMES.join(", ")
            ),
            Self::Count {
                option,
                value,
                min,
                max,
            } => format!(
                "{} must be between {min} and {max}, got {value}",
                spell(option)
            ),
            Self::TooManyMonteCarloStrides { runs, strides } => format!(
                "{} × {} must be at most {MAX_MFPT_TOTAL_STRIDES} strides, got {runs} × {strides}",
                spell("mfpt_runs"),
                spell("mfpt_strides")
            ),
            Self::RateScanStep(v) => format!(
                "{} must be from {MIN_RATE_SCAN_STEP:e} to {} natural rates (the scan's limit), got {}",
                spell("rate_scan_step"),
                short_number(ThresholdOptions::rates().limit),
                short_number(*v)
            ),
            Self::SigmaWithoutMfpt => format!(
                "{} is the rough floor of the mean first-passage time: add mfpt to {}",
                spell("sigma_m"),
                spell("measures")
            ),
            Self::TooManySigmas(n) => {
                format!("{} given {n} times; at most {MAX_SIGMAS}", spell("sigma_m"))
            }
            Self::Sigma(v) => format!(
                "{} {}: a standard deviation must be a finite number ≥ 0",
                spell("sigma_m"),
                short_number(*v)
            ),
            Self::Perturbation(v) => format!(
                "{} must be a finite number > 0, got {}",
                spell("perturbation"),
                short_number(*v)
            ),
        }
    }
}

impl std::fmt::Display for RobustnessOptionError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message(&|name| name.to_owned()))
    }
}

impl std::error::Error for RobustnessOptionError {}

impl RobustnessOptions {
    /// Checks every option against its range, before anything is computed.
    ///
    /// # Errors
    /// The first option out of its range.
    pub fn check(&self) -> Result<(), RobustnessOptionError> {
        let count = |option: &'static str, value: usize, max: usize| {
            if (1..=max).contains(&value) {
                Ok(())
            } else {
                Err(RobustnessOptionError::Count {
                    option,
                    value,
                    min: 1,
                    max,
                })
            }
        };
        count("return_strides", self.return_strides, MAX_RETURN_STRIDES)?;
        let step = self.rate_scan_step;
        if !(step.is_finite()
            && (MIN_RATE_SCAN_STEP..=ThresholdOptions::rates().limit).contains(&step))
        {
            return Err(RobustnessOptionError::RateScanStep(step));
        }
        let (runs, strides) = (self.first_passage.runs, self.first_passage.strides_per_run);
        count("mfpt_runs", runs, MAX_MFPT_RUNS)?;
        count("mfpt_strides", strides, MAX_MFPT_STRIDES)?;
        if runs.saturating_mul(strides) > MAX_MFPT_TOTAL_STRIDES {
            return Err(RobustnessOptionError::TooManyMonteCarloStrides { runs, strides });
        }
        if !self.measures.mfpt && !self.sigma_m.is_empty() {
            return Err(RobustnessOptionError::SigmaWithoutMfpt);
        }
        if self.sigma_m.len() > MAX_SIGMAS {
            return Err(RobustnessOptionError::TooManySigmas(self.sigma_m.len()));
        }
        if let Some(bad) = self.sigma_m.iter().find(|s| !(s.is_finite() && **s >= 0.0)) {
            return Err(RobustnessOptionError::Sigma(*bad));
        }
        if !(self.perturbation.is_finite() && self.perturbation > 0.0) {
            return Err(RobustnessOptionError::Perturbation(self.perturbation));
        }
        Ok(())
    }

    /// The roughness values measured: `sigma_m`, or 0.001, 0.003 and 0.01 of `leg_m`, each
    /// rounded to 12 significant digits (a leg length of 0.9999999999999999 m gives 0.001).
    pub fn sigmas(&self, leg_m: f64) -> Vec<f64> {
        if self.sigma_m.is_empty() {
            let round = |x: f64| format!("{x:.12e}").parse::<f64>().unwrap_or(x);
            vec![
                round(1e-3 * leg_m),
                round(3e-3 * leg_m),
                round(1e-2 * leg_m),
            ]
        } else {
            self.sigma_m.clone()
        }
    }
}

/// A threshold pair: the largest disturbance survived each way.
#[derive(Clone, Debug, Serialize)]
pub struct Signs {
    /// Largest positive change survived.
    pub positive: f64,
    /// Largest negative change survived (its size).
    pub negative: f64,
}

/// Where survival starts again past each step threshold (`null`: not up to the limit).
#[derive(Clone, Debug, Serialize)]
pub struct Again {
    /// Past the step-down threshold \[m\].
    pub down: Option<f64>,
    /// Past the step-up threshold \[m\].
    pub up: Option<f64>,
}

/// The `walker robustness --json` object (the contract's fields first; `step_thresholds` and
/// `velocity_thresholds` with every detail).
#[derive(Serialize)]
pub struct RobustnessReport {
    /// Scene name.
    pub scene: String,
    /// The gait measured, as `walker gait` reports it.
    pub gait: GaitReport,
    /// The gait sensitivity norm (`null`: not measured or failed).
    pub gait_sensitivity_norm: Option<GaitSensitivity>,
    /// Largest step down survived \[m\].
    pub step_down_max_m: Option<f64>,
    /// Largest step up survived \[m\].
    pub step_up_max_m: Option<f64>,
    /// Where survival starts again past the step thresholds.
    pub survived_again_from_m: Option<Again>,
    /// Largest change of each rate survived, by coordinate \[rad/s or m/s\].
    pub velocity_perturbation_max: Option<BTreeMap<String, Signs>>,
    /// The mean first-passage time at each roughness.
    pub mfpt: Vec<FirstPassage>,
    /// The step thresholds in full.
    pub step_thresholds: Option<StepThresholds>,
    /// The rate thresholds in full.
    pub velocity_thresholds: Option<Vec<VelocityThreshold>>,
    /// The rule a disturbed walker's return to the gait is judged by.
    pub return_rule: ReturnRule,
    /// A measure that could not be computed, and why (`gait`: no measure is defined).
    pub errors: BTreeMap<String, String>,
}

impl RobustnessReport {
    /// The measures `options` asks for of the gait search `sourced` (the one gait rule's
    /// result at `scene`'s values, `setup` built from them), `progress` called after each of
    /// the 3 + (number of roughness values) stages. No gait, or an unstable one, gives a report
    /// with no measure (an unstable gait says why in `errors`).
    pub fn measure(
        setup: &Setup,
        scene: &Scene,
        sourced: Result<(Gait, GaitSource), NewtonError>,
        options: &RobustnessOptions,
        progress: &dyn Fn(),
    ) -> Self {
        let source = sourced.as_ref().ok().map(|(_, s)| *s);
        let result = sourced.map(|(g, _)| g);
        let (mut gait_report, _) = GaitReport::of_setup(setup, scene, &result, false);
        gait_report.gait_source = source;
        let mut report = Self {
            scene: scene.name().to_owned(),
            gait: gait_report,
            gait_sensitivity_norm: None,
            step_down_max_m: None,
            step_up_max_m: None,
            survived_again_from_m: None,
            velocity_perturbation_max: None,
            mfpt: Vec::new(),
            step_thresholds: None,
            velocity_thresholds: None,
            return_rule: ReturnRule::default(),
            errors: BTreeMap::new(),
        };
        let Ok(gait) = &result else {
            return report;
        };
        if !gait.stable() {
            // every measure here asks how a disturbance dies out: at an unstable gait it grows
            report.errors.insert(
                "gait".into(),
                format!(
                    "the gait is unstable (max |λ| = {}): no robustness measure is defined there",
                    gait.max_abs_eigenvalue()
                ),
            );
            return report;
        }
        let rule = ReturnRule {
            max_strides: options.return_strides,
            ..Default::default()
        };
        report.return_rule = rule;
        let walker = &setup.walker;
        let recovery = Recovery::new(walker, &setup.settings, gait).with_rule(rule);
        let measures = options.measures;
        if measures.gsn {
            match gait_sensitivity_norm(walker, &setup.settings, gait, options.perturbation) {
                Ok(g) => report.gait_sensitivity_norm = Some(g),
                Err(e) => {
                    report
                        .errors
                        .insert("gait_sensitivity_norm".into(), e.to_string());
                }
            }
        }
        progress();
        if measures.steps {
            report.steps_from(&recovery);
        }
        progress();
        if measures.rates {
            let threshold_options = ThresholdOptions {
                scan_step: options.rate_scan_step,
                ..ThresholdOptions::rates()
            };
            report.rates_from(&recovery, &threshold_options);
        }
        progress();
        let sigmas = options.sigmas(recovery.leg_length_m());
        for sigma in sigmas.into_iter().filter(|_| measures.mfpt) {
            match mean_first_passage(&recovery, sigma, &options.first_passage) {
                Ok(m) => report.mfpt.push(m),
                Err(e) => {
                    report
                        .errors
                        .insert(format!("mfpt sigma_m={sigma}"), e.to_string());
                }
            }
            progress();
        }
        report
    }

    /// The stages [`Self::measure`] reports progress for with `options`: three, and one per
    /// roughness value.
    pub fn stages(options: &RobustnessOptions) -> usize {
        let sigmas = match (options.measures.mfpt, options.sigma_m.len()) {
            (false, _) => 0,
            (true, 0) => 3,
            (true, n) => n,
        };
        3 + sigmas
    }

    /// Whether there was a gait and every measure asked for was computed.
    pub fn complete(&self) -> bool {
        matches!(self.gait.outcome, super::GaitOutcome::Found(_)) && self.errors.is_empty()
    }

    fn steps_from(&mut self, recovery: &Recovery<'_>) {
        let steps = step_thresholds(recovery, &ThresholdOptions::steps());
        self.step_down_max_m = Some(steps.down.max);
        self.step_up_max_m = Some(steps.up.max);
        self.survived_again_from_m = Some(Again {
            down: steps.down.survived_again_from,
            up: steps.up.survived_again_from,
        });
        self.step_thresholds = Some(steps);
    }

    fn rates_from(&mut self, recovery: &Recovery<'_>, options: &ThresholdOptions) {
        let rates = velocity_thresholds(recovery, options);
        self.velocity_perturbation_max = Some(
            rates
                .iter()
                .map(|v| {
                    (
                        v.coordinate.clone(),
                        Signs {
                            positive: v.positive.max,
                            negative: v.negative.max,
                        },
                    )
                })
                .collect(),
        );
        self.velocity_thresholds = Some(rates);
    }
}
