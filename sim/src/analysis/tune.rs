//! Searching parameters near a design for a more stable gait: Nelder-Mead on the largest
//! |eigenvalue| of the stride Jacobian, within stated bounds. Every point's gait is the one
//! `walker gait` reports at its values ([`GaitRule`], the one rule: Newton from the scene's
//! guess and the defaults' gait followed there, the longer-period of the two), never one
//! warm-started from another point (which can land on another branch); each point says where
//! its gait came from.

use crate::analysis::homotopy::{GaitRule, GaitSource, HomotopySettings, SetupFor};
use crate::analysis::limit_cycle::NewtonSettings;
use crate::scene::{Scene, SceneError};
use serde::Serialize;

/// A parameter the search may change, with its bounds.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TunedParameter {
    /// Parameter name.
    pub name: String,
    /// Lower bound.
    pub min: f64,
    /// Upper bound.
    pub max: f64,
}

/// One evaluated point.
#[derive(Clone, Debug, Serialize)]
pub struct TunePoint {
    /// Parameter values, in [`TunedParameter`] order.
    pub values: Vec<f64>,
    /// Largest |eigenvalue|, or `None` where no gait was found.
    pub max_abs_eigenvalue: Option<f64>,
    /// Where the gait came from, as `walker gait`'s `gait_source` at these values (`None`: no
    /// gait).
    pub gait_source: Option<GaitSource>,
    /// The gait's step period \[s\] (`None`: no gait).
    pub step_period_s: Option<f64>,
}

/// The outcome of a search.
#[derive(Clone, Debug, Serialize)]
pub struct TuneResult {
    /// What was varied.
    pub parameters: Vec<TunedParameter>,
    /// The best point.
    pub best: TunePoint,
    /// Every evaluation, in order.
    pub history: Vec<TunePoint>,
}

/// Objective value for a failed gait search.
const NO_GAIT: f64 = 10.0;

/// How a search runs: what it varies, its budget, and the gait rule's solver settings.
pub struct TuneSettings<'a> {
    /// What the search may change, with its bounds.
    pub params: &'a [TunedParameter],
    /// Most gait evaluations.
    pub evaluations: usize,
    /// Builds the setup at each point (the caller's solver overrides).
    pub setup_for: &'a SetupFor<'a>,
    /// The fixed-point search.
    pub newton: &'a NewtonSettings,
    /// How the defaults' gait is followed to a point.
    pub homotopy: &'a HomotopySettings,
}

/// Minimises max |λ| over `settings.params` from the scene's current values, with at most
/// `settings.evaluations` gait evaluations.
///
/// # Errors
/// An unknown parameter, a bound out of the scene's range, a scene that cannot be built.
pub fn tune(scene: &Scene, settings: &TuneSettings<'_>) -> Result<TuneResult, SceneError> {
    tune_with_progress(scene, settings, &|| {})
}

/// As [`tune`], calling `on_evaluation` after each gait evaluation (at most `evaluations`; for
/// a progress bar).
///
/// # Errors
/// As [`tune`].
pub fn tune_with_progress(
    scene: &Scene,
    settings: &TuneSettings<'_>,
    on_evaluation: &dyn Fn(),
) -> Result<TuneResult, SceneError> {
    let (params, evaluations) = (settings.params, settings.evaluations);
    let rule = GaitRule::new(settings.setup_for, settings.newton, settings.homotopy);
    let mut scene = scene.clone();
    let n = params.len();
    let start: Vec<f64> = params
        .iter()
        .map(|p| scene_value(&scene, &p.name).clamp(p.min, p.max))
        .collect();
    for p in params {
        // Validates names and bounds against the scene's own ranges.
        scene.set(&p.name, p.min)?;
        scene.set(&p.name, p.max)?;
    }
    let mut history: Vec<TunePoint> = Vec::new();
    let mut eval = |x: &[f64], history: &mut Vec<TunePoint>| -> Result<f64, SceneError> {
        // The budget holds per gait search: a simplex step may want several searches, and
        // those beyond `evaluations` are not run (the loop below then stops).
        if history.len() >= evaluations {
            return Ok(f64::INFINITY);
        }
        let clamped: Vec<f64> = x
            .iter()
            .zip(params)
            .map(|(v, p)| v.clamp(p.min, p.max))
            .collect();
        for (v, p) in clamped.iter().zip(params) {
            scene.set(&p.name, *v)?;
        }
        let gait = rule.gait(&scene)?.ok();
        let value = gait.as_ref().map(|(g, _)| g.max_abs_eigenvalue());
        history.push(TunePoint {
            values: clamped,
            max_abs_eigenvalue: value,
            gait_source: gait.as_ref().map(|(_, source)| *source),
            step_period_s: gait.as_ref().map(|(g, _)| g.stride.duration_s),
        });
        on_evaluation();
        Ok(value.unwrap_or(NO_GAIT))
    };
    // Nelder-Mead on the box, initial simplex 10% of each range.
    let mut simplex: Vec<(Vec<f64>, f64)> = Vec::with_capacity(n + 1);
    let f0 = eval(&start, &mut history)?;
    simplex.push((start.clone(), f0));
    for (i, p) in params.iter().enumerate() {
        let mut x = start.clone();
        let d = 0.1 * (p.max - p.min);
        x[i] = if x[i] + d <= p.max {
            x[i] + d
        } else {
            x[i] - d
        };
        let f = eval(&x, &mut history)?;
        simplex.push((x, f));
    }
    while history.len() < evaluations {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let centroid: Vec<f64> = (0..n)
            .map(|k| simplex[..n].iter().map(|(x, _)| x[k]).sum::<f64>() / n as f64)
            .collect();
        let worst = simplex[n].clone();
        let along = |t: f64| -> Vec<f64> {
            centroid
                .iter()
                .zip(&worst.0)
                .zip(params)
                .map(|((c, w), p)| (c + t * (c - w)).clamp(p.min, p.max))
                .collect()
        };
        let xr = along(1.0);
        let fr = eval(&xr, &mut history)?;
        if fr < simplex[0].1 {
            let xe = along(2.0);
            let fe = eval(&xe, &mut history)?;
            simplex[n] = if fe < fr { (xe, fe) } else { (xr, fr) };
        } else if fr < simplex[n - 1].1 {
            simplex[n] = (xr, fr);
        } else {
            let xc = along(-0.5);
            let fc = eval(&xc, &mut history)?;
            if fc < worst.1 {
                simplex[n] = (xc, fc);
            } else {
                // Shrink towards the best.
                let best = simplex[0].0.clone();
                for s in simplex.iter_mut().skip(1) {
                    let x: Vec<f64> =
                        s.0.iter()
                            .zip(&best)
                            .map(|(v, b)| b + 0.5 * (v - b))
                            .collect();
                    let f = eval(&x, &mut history)?;
                    *s = (x, f);
                }
            }
        }
        let spread = simplex
            .iter()
            .map(|s| s.1)
            .fold(f64::NEG_INFINITY, f64::max)
            - simplex.iter().map(|s| s.1).fold(f64::INFINITY, f64::min);
        if spread < 1e-6 {
            break;
        }
    }
    let best = history
        .iter()
        .filter(|p| p.max_abs_eigenvalue.is_some())
        .min_by(|a, b| {
            a.max_abs_eigenvalue
                .unwrap_or(NO_GAIT)
                .total_cmp(&b.max_abs_eigenvalue.unwrap_or(NO_GAIT))
        })
        .cloned()
        .unwrap_or(TunePoint {
            values: start,
            max_abs_eigenvalue: None,
            gait_source: None,
            step_period_s: None,
        });
    Ok(TuneResult {
        parameters: params.to_vec(),
        best,
        history,
    })
}

fn scene_value(scene: &Scene, name: &str) -> f64 {
    scene.values.get(name).copied().unwrap_or(0.0)
}
