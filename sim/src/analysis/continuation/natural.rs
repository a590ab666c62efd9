//! Natural-parameter continuation: a gait followed over given values of one parameter, one
//! Newton solve per value from a secant predictor, with a guard against jumping to another
//! branch ([`crate::analysis::homotopy::Secant`], the step the census's homotopy also takes): the
//! stability map's rows ([`along`]) and the natural-parameter [`sweep`] (kept for tests and
//! callers that want the gait at given values without the pseudo-arclength machinery of
//! [`super::continuation`]).

use crate::analysis::homotopy::{long_period_gait, HomotopySettings, Secant, SetupFor};
use crate::analysis::limit_cycle::{Gait, NewtonError, NewtonSettings};
use crate::scene::{Scene, SceneError};

/// One point of a sweep.
#[derive(Clone, Debug)]
pub struct SweepPoint {
    /// Parameter value.
    pub value: f64,
    /// The gait, or why none was found.
    pub gait: Result<Gait, NewtonError>,
    /// The gait was seeded ([`long_period_gait`]) rather than followed from the previous
    /// points: it may lie on another branch, so no stability change is interpolated across it.
    pub seeded: bool,
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

/// One value of [`along`]: the gait and whether it was seeded, or why there is none.
pub type AlongPoint = Result<(Gait, bool), NewtonError>;

/// Follows a gait along `values` of `param` (from `scene`): each value's gait is the guarded
/// [`Secant::step`] from the last ones; the first value, a value after one without a gait,
/// and a value where that step fails or jumps are **seeded** by [`long_period_gait`] (the
/// gait `walker gait` returns there). Each result says whether it was seeded. `progress` is
/// called once per value.
///
/// # Errors
/// An unknown parameter, a value out of its range, a scene that cannot be built.
pub fn along(
    scene: &Scene,
    param: &str,
    values: &[f64],
    setup_for: &SetupFor<'_>,
    newton: &NewtonSettings,
    homotopy: &HomotopySettings,
    progress: &(dyn Fn() + Sync),
) -> Result<Vec<AlongPoint>, SceneError> {
    let mut scene = scene.clone();
    let mut path = Secant::default();
    let mut out = Vec::with_capacity(values.len());
    for &value in values {
        scene.set(param, value)?;
        let setup = setup_for(&scene)?;
        let cell = match path.step(value, &setup, newton, homotopy) {
            Some(Ok(g)) => Ok((g, false)),
            _ => long_period_gait(&scene, setup_for, newton, homotopy)?.map(|g| (g, true)),
        };
        match &cell {
            Ok((g, _)) => path.push(value, g),
            Err(_) => path.clear(),
        }
        out.push(cell);
        progress();
    }
    Ok(out)
}

/// Sweeps `param` over `points` values from `from` to `to` ([`along`], with the scene's own
/// stride settings and [`HomotopySettings::default`]), and the changes of stability between
/// successive converged points of one followed path (never across a seeded point, which may
/// lie on another branch; each point says whether it was seeded).
///
/// # Errors
/// A bad parameter name or value, fewer than two points.
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
    // Validate the name and both ends before any work.
    let mut check = scene.clone();
    check.set(param, from)?;
    check.set(param, to)?;
    let values: Vec<f64> = (0..points)
        .map(|i| from + (to - from) * i as f64 / (points - 1) as f64)
        .collect();
    let setup_for = |s: &Scene| s.setup();
    let gaits = along(
        scene,
        param,
        &values,
        &setup_for,
        settings,
        &HomotopySettings::default(),
        &|| {},
    )?;
    let out: Vec<SweepPoint> = values
        .iter()
        .zip(gaits)
        .map(|(&value, g)| SweepPoint {
            value,
            seeded: g.as_ref().is_ok_and(|(_, seeded)| *seeded),
            gait: g.map(|(g, _)| g),
        })
        .collect();
    let mut boundaries = Vec::new();
    // Successive points of one followed path only: a seeded point starts a new one.
    let converged: Vec<(f64, f64, bool)> = out
        .iter()
        .filter_map(|p| {
            p.gait
                .as_ref()
                .ok()
                .map(|g| (p.value, g.max_abs_eigenvalue(), p.seeded))
        })
        .collect();
    for w in converged.windows(2) {
        let ((p0, m0, _), (p1, m1, seeded)) = (w[0], w[1]);
        if !seeded && (m0 < 1.0) != (m1 < 1.0) {
            let value = p0 + (1.0 - m0) * (p1 - p0) / (m1 - m0);
            boundaries.push(StabilityBoundary {
                value,
                change: if m0 < 1.0 { "lost" } else { "gained" },
            });
        }
    }
    Ok((out, boundaries))
}
