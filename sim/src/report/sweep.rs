//! The `walker sweep` report: the gait at each parameter value and where stability changes.

use super::{eigenvalue_pairs, FixedPoint};
use crate::continuation::{StabilityBoundary, SweepPoint};
use crate::scene::Scene;
use crate::walker::Walker;
use serde::Serialize;

/// The `walker sweep --json` object.
#[derive(Clone, Debug, Serialize)]
pub struct SweepReport {
    /// Scene name.
    pub scene: String,
    /// The parameter varied.
    pub param: String,
    /// One record per parameter value, in sweep order.
    pub points: Vec<SweepPointRecord>,
    /// Changes of stability between successive converged points.
    pub stability_boundaries: Vec<BoundaryRecord>,
}

/// One point of a sweep.
#[derive(Clone, Debug, Serialize)]
#[serde(untagged)]
pub enum SweepPointRecord {
    /// A gait was found (`converged: true`).
    Converged(Box<ConvergedPoint>),
    /// None was (`converged: false`).
    Failed(FailedPoint),
}

/// A sweep point with a gait.
#[derive(Clone, Debug, Serialize)]
pub struct ConvergedPoint {
    /// The parameter varied.
    pub parameter: String,
    /// Its value.
    pub value: f64,
    /// Always `true`.
    pub converged: bool,
    /// Largest eigenvalue modulus.
    pub max_abs_eigenvalue: f64,
    /// All eigenvalues strictly inside the unit circle.
    pub stable: bool,
    /// Eigenvalues of the stride Jacobian, `[re, im]`.
    pub eigenvalues: Vec<[f64; 2]>,
    /// The fixed point (`null` if the walker of this value could not be rebuilt to name it).
    pub fixed_point: Option<FixedPoint>,
    /// Step period [s].
    pub step_period_s: f64,
    /// Distance between the contacts of a step [m].
    pub step_length_m: f64,
}

/// A sweep point without a gait.
#[derive(Clone, Debug, Serialize)]
pub struct FailedPoint {
    /// The parameter varied.
    pub parameter: String,
    /// Its value.
    pub value: f64,
    /// Always `false`.
    pub converged: bool,
    /// `null`.
    pub max_abs_eigenvalue: Option<f64>,
    /// Always `false`.
    pub stable: bool,
    /// `null`.
    pub fixed_point: Option<FixedPoint>,
    /// Why no gait was found.
    pub error: String,
}

/// A change of stability.
#[derive(Clone, Debug, Serialize)]
pub struct BoundaryRecord {
    /// Estimated parameter value where `max |λ| = 1`.
    pub value: f64,
    /// `lost` or `gained` (with increasing point index).
    pub change: &'static str,
}

impl SweepReport {
    /// The report of a sweep of `param` over `scene`. `walker_for(value)` gives the scene and
    /// walker at a parameter value, to name the fixed point's entries (`None`: unnamed, `null`).
    pub fn new(
        scene: &Scene,
        walker_for: &dyn Fn(f64) -> Option<(Scene, Walker)>,
        param: &str,
        points: &[SweepPoint],
        boundaries: &[StabilityBoundary],
    ) -> Self {
        let points = points
            .iter()
            .map(|p| match &p.gait {
                Ok(g) => SweepPointRecord::Converged(Box::new(ConvergedPoint {
                    parameter: param.to_string(),
                    value: p.value,
                    converged: true,
                    max_abs_eigenvalue: g.max_abs_eigenvalue(),
                    stable: g.stable(),
                    eigenvalues: eigenvalue_pairs(&g.eigenvalues),
                    fixed_point: walker_for(p.value).map(|(s, w)| FixedPoint::of(&s, &w, g)),
                    step_period_s: g.stride.duration_s,
                    step_length_m: g.stride.step_m.norm(),
                })),
                Err(e) => SweepPointRecord::Failed(FailedPoint {
                    parameter: param.to_string(),
                    value: p.value,
                    converged: false,
                    max_abs_eigenvalue: None,
                    stable: false,
                    fixed_point: None,
                    error: e.to_string(),
                }),
            })
            .collect();
        Self {
            scene: scene.name().to_string(),
            param: param.to_string(),
            points,
            stability_boundaries: boundaries
                .iter()
                .map(|b| BoundaryRecord {
                    value: b.value,
                    change: b.change,
                })
                .collect(),
        }
    }
}
