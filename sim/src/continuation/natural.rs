//! Natural-parameter continuation: follow a gait while one scene parameter changes, and report
//! where the largest |eigenvalue| crosses 1.

use crate::limit_cycle::{Gait, GaitSearch, NewtonError, NewtonSettings};
use crate::scene::{Scene, SceneError};
use nalgebra::DVector;

/// One point of a sweep.
#[derive(Clone, Debug)]
pub struct SweepPoint {
    /// Parameter value.
    pub value: f64,
    /// The gait, or why none was found.
    pub gait: Result<Gait, NewtonError>,
}

/// A change of stability between two successive converged points, located by linear
/// interpolation of `max |λ| − 1`.
#[derive(Clone, Debug, PartialEq)]
pub struct StabilityBoundary {
    /// Estimated parameter value where `max |λ| = 1`.
    pub value: f64,
    /// `lost` (stable → unstable with increasing index) or `gained`.
    pub change: &'static str,
}

/// Why a sweep could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SweepError {
    /// A parameter or scene problem.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// Fewer than two points.
    #[error("a sweep needs at least 2 points, got {0}")]
    TooFewPoints(usize),
}

/// Sweeps `param` over `points` values from `from` to `to`, continuing each gait from the
/// previous ones (secant predictor).
pub fn sweep(
    scene: &Scene,
    param: &str,
    from: f64,
    to: f64,
    points: usize,
    settings: &NewtonSettings,
) -> Result<(Vec<SweepPoint>, Vec<StabilityBoundary>), SweepError> {
    if points < 2 {
        return Err(SweepError::TooFewPoints(points));
    }
    let mut scene = scene.clone();
    // Validate the name and both ends before any work.
    scene.set(param, from)?;
    scene.set(param, to)?;
    let mut out: Vec<SweepPoint> = Vec::with_capacity(points);
    let mut history: Vec<(f64, DVector<f64>)> = Vec::new();
    for i in 0..points {
        let value = from + (to - from) * i as f64 / (points - 1) as f64;
        scene.set(param, value)?;
        let setup = scene.setup()?;
        let search = GaitSearch::new(&setup.walker, &setup.settings, settings);
        let from_guess = || setup.walker.pack(&setup.guess.q, &setup.guess.qd);
        let guess = match history.as_slice() {
            [] => from_guess(),
            [.., (_, v)] if history.len() == 1 => v.clone(),
            [.., (p0, v0), (p1, v1)] => v1 + (v1 - v0) * ((value - p1) / (p1 - p0)),
            _ => from_guess(),
        };
        let mut gait = search.find(&guess);
        if gait.is_err() && !history.is_empty() {
            if let Some((_, last)) = history.last() {
                gait = search.find(last);
            }
        }
        if let Ok(g) = &gait {
            history.push((value, g.fixed_point.clone()));
        }
        out.push(SweepPoint { value, gait });
    }
    let mut boundaries = Vec::new();
    let converged: Vec<(f64, f64)> = out
        .iter()
        .filter_map(|p| {
            p.gait
                .as_ref()
                .ok()
                .map(|g| (p.value, g.max_abs_eigenvalue()))
        })
        .collect();
    for w in converged.windows(2) {
        let ((p0, m0), (p1, m1)) = (w[0], w[1]);
        if (m0 < 1.0) != (m1 < 1.0) {
            let value = p0 + (1.0 - m0) * (p1 - p0) / (m1 - m0);
            boundaries.push(StabilityBoundary {
                value,
                change: if m0 < 1.0 { "lost" } else { "gained" },
            });
        }
    }
    Ok((out, boundaries))
}
