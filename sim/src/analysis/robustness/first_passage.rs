//! The mean first-passage time of a gait on a rough floor (Byl & Tedrake 2009, IJRR 28(8)):
//! how many steps a walker takes, on average, before it falls, when at every heel strike the
//! floor's level changes by a draw from `N(0, σ²)` ([`crate::stride::Floor::Rough`]).
//!
//! Monte Carlo: `runs` walks from the gait's fixed point, walk `r` over the rough floor of
//! seed `seed + r`, each up to `strides_per_run` strides. A metastable walker fails at each
//! stride with (nearly) a constant probability `p` (Byl & Tedrake), so the strides to failure
//! are geometric and the mean first-passage time, in steps, is `1/p`. With `d` failures in
//! `T` strides simulated (a walk that did not fail — a censored walk — counts its strides in
//! `T` and no failure; a failed walk counts its strides up to and including the failing one),
//! the maximum-likelihood estimate is `T/d`, and the exact (Garwood) 95 % interval of the
//! rate `d/T`, `[χ²(0.025; 2d)/(2T), χ²(0.975; 2d+2)/(2T)]`, inverted gives the interval of
//! the mean. With no failure there is no estimate: the interval is `[2T/χ²(0.975; 2), ∞)`
//! (a lower bound only, reported with `steps` and `ci_high` as `None`).

use super::recovery::{Outcome, Recovery, Until};
use crate::stride::{Floor, StrideWorkspace};
use rayon::prelude::*;
use serde::Serialize;
use statrs::distribution::{ChiSquared, ContinuousCDF};
use std::collections::BTreeMap;

/// The Monte Carlo's size and seed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FirstPassageOptions {
    /// Walks.
    pub runs: usize,
    /// Most strides of one walk (a walk that reaches it is censored).
    pub strides_per_run: usize,
    /// The first walk's floor seed (walk `r` has `seed + r`).
    pub seed: u64,
}

impl Default for FirstPassageOptions {
    fn default() -> Self {
        Self {
            runs: 100,
            strides_per_run: 200,
            seed: 0,
        }
    }
}

/// The mean first-passage time at one roughness.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FirstPassage {
    /// The floor's standard deviation \[m\].
    pub sigma_m: f64,
    /// The mean first-passage time in steps (`T/d`); `None` when no walk failed.
    pub steps: Option<f64>,
    /// The 95 % interval's low end (steps).
    pub ci_low: f64,
    /// Its high end; `None` (unbounded) when no walk failed.
    pub ci_high: Option<f64>,
    /// `T`: strides simulated, the failing ones included.
    pub strides_simulated: usize,
    /// Walks that reached `strides_per_run` without failing.
    pub censored: usize,
    /// `d`: walks that failed.
    pub failed: usize,
    /// Walks.
    pub runs: usize,
    /// Most strides of one walk.
    pub strides_per_run: usize,
    /// The first walk's floor seed.
    pub seed: u64,
    /// The failures by kind (`fell_forward`, ...).
    pub failures: BTreeMap<String, usize>,
}

/// Why a first-passage estimate was refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FirstPassageError {
    /// σ negative or not finite.
    #[error("sigma_m = {0} must be a finite number ≥ 0")]
    Sigma(f64),
    /// No walks or no strides.
    #[error("the Monte Carlo needs at least one walk of at least one stride")]
    Empty,
}

/// The mean first-passage time of `recovery`'s gait on a floor of roughness `sigma_m`.
///
/// # Errors
/// A σ that is not a finite number ≥ 0; an empty Monte Carlo.
pub fn mean_first_passage(
    recovery: &Recovery<'_>,
    sigma_m: f64,
    options: &FirstPassageOptions,
) -> Result<FirstPassage, FirstPassageError> {
    if !(sigma_m.is_finite() && sigma_m >= 0.0) {
        return Err(FirstPassageError::Sigma(sigma_m));
    }
    if options.runs == 0 || options.strides_per_run == 0 {
        return Err(FirstPassageError::Empty);
    }
    let walk = Recovery {
        rule: super::ReturnRule {
            max_strides: options.strides_per_run,
            ..recovery.rule
        },
        ..*recovery
    };
    let outcomes: Vec<Outcome> = (0..options.runs)
        .into_par_iter()
        .map_init(
            || StrideWorkspace::new(recovery.walker),
            |ws, r| {
                let floor = Floor::Rough {
                    sigma_m,
                    seed: options.seed.wrapping_add(r as u64),
                };
                let mut heights = floor.heights();
                walk.follow(
                    ws,
                    recovery.fixed_point,
                    &mut |_| heights.next_step_m(),
                    Until::Failure,
                )
            },
        )
        .collect();
    let mut failures = BTreeMap::new();
    let (mut strides, mut failed, mut censored) = (0usize, 0usize, 0usize);
    for o in &outcomes {
        strides += o.strides();
        match o {
            Outcome::Failed { .. } => {
                failed += 1;
                *failures.entry(o.name()).or_insert(0) += 1;
            }
            _ => censored += 1,
        }
    }
    let (steps, ci_low, ci_high) = estimate(strides, failed);
    Ok(FirstPassage {
        sigma_m,
        steps,
        ci_low,
        ci_high,
        strides_simulated: strides,
        censored,
        failed,
        runs: options.runs,
        strides_per_run: options.strides_per_run,
        seed: options.seed,
        failures,
    })
}

/// `(T/d, ci_low, ci_high)` for `d` failures in `T` strides (module documentation).
pub fn estimate(strides: usize, failed: usize) -> (Option<f64>, f64, Option<f64>) {
    let t = strides as f64;
    let d = failed as f64;
    let quantile = |dof: f64, p: f64| {
        ChiSquared::new(dof)
            .map(|c| c.inverse_cdf(p))
            .unwrap_or(f64::NAN)
    };
    // mean = 1/rate: the rate's upper end gives the mean's lower end
    let ci_low = 2.0 * t / quantile(2.0 * d + 2.0, 0.975);
    if failed == 0 {
        return (None, ci_low, None);
    }
    let ci_high = 2.0 * t / quantile(2.0 * d, 0.025);
    (Some(t / d), ci_low, Some(ci_high))
}
