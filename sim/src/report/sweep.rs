//! The `walker sweep` report of a pseudo-arclength continuation
//! ([`SweepReport::from_continuation`]): the gait at each parameter value with its branch and
//! period, the bifurcations by kind, where and why branches end, the bifurcations not
//! located and the period doublings with no doubled branch.

use super::{eigenvalue_pairs, FixedPoint};
use crate::analysis::continuation::{Bifurcation, BranchPoint, Continuation, Family};
use crate::analysis::homotopy::SetupFor;
use crate::analysis::limit_cycle::NewtonSettings;
use crate::analysis::quantity::{at_fixed_point, Quantity, QuantityError, QuantityOptions};
use serde::Serialize;

/// The `walker sweep --json` object.
#[derive(Clone, Debug, Serialize)]
pub struct SweepReport {
    /// Scene name.
    pub scene: String,
    /// The parameter varied, as given on the command line (an alias such as `slope` stays).
    pub param: String,
    /// Its canonical name (e.g. `slope_rad`).
    pub param_canonical: String,
    /// One record per parameter value, in sweep order.
    pub points: Vec<SweepPointRecord>,
    /// Every located bifurcation (with its `kind`).
    pub stability_boundaries: Vec<BoundaryRecord>,
    /// Where and why branches end.
    pub branch_ends: Vec<BranchEndRecord>,
    /// The branches followed.
    pub branches: Vec<BranchRecord>,
    /// Bifurcations detected (a test function changed sign between two points) but not
    /// located, with their bracket and why.
    pub unlocated: Vec<UnlocatedRecord>,
    /// Period doublings with no doubled branch, with why (a failed switch, the branch
    /// budget).
    pub switch_failures: Vec<SwitchFailureRecord>,
}

/// A bifurcation detected but not located.
#[derive(Clone, Debug, Serialize)]
pub struct UnlocatedRecord {
    /// The branch.
    pub branch: usize,
    /// Strides per cycle on it.
    pub period_strides: usize,
    /// `fold`, `branch_point`, `period_doubling`, `neimark_sacker`.
    pub kind: &'static str,
    /// The parameter values of the two branch points between which its test function
    /// changed sign, in arclength order.
    pub bracket: [f64; 2],
    /// Why it was not located.
    pub reason: String,
}

/// A period doubling whose doubled branch was not followed.
#[derive(Clone, Debug, Serialize)]
pub struct SwitchFailureRecord {
    /// The branch the period doubling is on.
    pub branch: usize,
    /// Strides per cycle on it.
    pub period_strides: usize,
    /// The parameter value of the period doubling.
    pub value: f64,
    /// Why there is no doubled branch.
    pub reason: String,
}

/// Where a branch ends.
#[derive(Clone, Debug, Serialize)]
pub struct BranchEndRecord {
    /// The branch.
    pub branch: usize,
    /// Strides per cycle on it.
    pub period_strides: usize,
    /// The parameter value of the branch's last point.
    pub value: f64,
    /// `event_change`, `fold`, `not_converged` or `budget`.
    pub kind: &'static str,
    /// The event that appears, disappears or fails (e.g. `scuffed`), when there is one.
    pub event: Option<String>,
    /// What happens there, in words.
    pub detail: String,
    /// Width of the arclength bracket of the bisection that located it (it bounds the
    /// parameter's bracket; for a `not_converged` end, the last step tried; 0 for a fold). Not
    /// the accuracy of a grazing
    /// end: see `accuracy`.
    pub bracket: f64,
    /// The bad side is a failing stride (a grazing swing foot, an event not found): the
    /// location depends on the integrator's step grid and event detection, beyond `bracket`.
    pub grazing: bool,
    /// A bound on the error of `value`: `bracket` for an end between two converged event
    /// sequences; `null` when not known (a grazing end, an end not located by bisection).
    pub accuracy: Option<f64>,
    /// The location ran out of its trial budget before reaching its tolerance.
    pub budget_exhausted: bool,
}

/// A branch of the continuation.
#[derive(Clone, Debug, Serialize)]
pub struct BranchRecord {
    /// Its id, as the points' `branch`.
    pub branch: usize,
    /// Strides per cycle.
    pub period_strides: usize,
    /// The branch it was switched from, at its period doubling (`null` for branch 0).
    pub parent: Option<usize>,
    /// The parameter value of that period doubling.
    pub born_at: Option<f64>,
    /// Continuation steps taken.
    pub steps: usize,
    /// The stride event sequence along it (`|` between strides of a cycle).
    pub events: Vec<String>,
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
    /// Step period \[s\] (of the first stride of the cycle).
    pub step_period_s: f64,
    /// Distance between the contacts of a step \[m\] (of the first stride of the cycle).
    pub step_length_m: f64,
    /// Strides per cycle (1, 2, 4, …).
    pub period_strides: usize,
    /// The branch (`branches[..].branch`); 0 for the natural-parameter sweep.
    pub branch: usize,
    /// For period > 1: the cycle's states, each like `fixed_point` (the first is it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orbit: Option<Vec<Option<FixedPoint>>>,
    /// How the stride Jacobians were taken (`central_differences`, `variational`).
    pub jacobian_method: crate::analysis::limit_cycle::JacobianMethod,
    /// The sweep's `--quantity` at this gait, or why it has none (absent without one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub quantity: Option<QuantityValue>,
}

/// A quantity's value at a sweep point, or why it has none.
#[derive(Clone, Debug, Serialize)]
pub struct QuantityValue {
    /// The quantity (`gsn`, `step_down`, `mfpt`, ...).
    pub name: crate::analysis::quantity::Quantity,
    /// The rough floor of `mfpt` \[m\] (`null` for the others).
    pub sigma_m: Option<f64>,
    /// Its value (`null`: see `error`).
    pub value: Option<f64>,
    /// Why it has none (`null` when it has one).
    pub error: Option<String>,
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
    /// Why no gait was found (as `error`): the Newton failure, or where and why the branch
    /// ended before this value.
    pub reason: String,
    /// The branch that did not reach this value (0).
    pub branch: usize,
    /// Strides per cycle of that branch (1).
    pub period_strides: usize,
}

/// A change of stability.
#[derive(Clone, Debug, Serialize)]
pub struct BoundaryRecord {
    /// Estimated parameter value where `max |λ| = 1`.
    pub value: f64,
    /// `lost` or `gained` (along the branch), `none` when the crossing keeps the point
    /// unstable.
    pub change: &'static str,
    /// `fold`, `branch_point`, `period_doubling`, `neimark_sacker`.
    pub kind: &'static str,
    /// The branch.
    pub branch: usize,
    /// Strides per cycle on the branch.
    pub period_strides: usize,
    /// The multipliers at the located point, `[re, im]`.
    pub multipliers: Vec<[f64; 2]>,
    /// Width of the final arclength bracket of the location (it bounds the parameter's).
    pub bracket: f64,
    /// The location ran out of its trial budget before reaching its tolerance.
    pub budget_exhausted: bool,
}

impl FailedPoint {
    /// The record of grid value `value` of `param` that branch 0 (period 1) did not reach,
    /// and why.
    pub fn new(param: &str, value: f64, reason: String) -> Self {
        Self {
            parameter: param.to_string(),
            value,
            converged: false,
            max_abs_eigenvalue: None,
            stable: false,
            fixed_point: None,
            error: reason.clone(),
            reason,
            branch: 0,
            period_strides: 1,
        }
    }
}

impl SweepReport {
    /// `quantity` at every period-1 point of the sweep `result` (this report's continuation),
    /// in parallel, into the report's points (which list the branches' grid points in the same
    /// order): each gait re-found by Newton (`newton`) from its fixed point at its value, with
    /// setups from `setup_for`; `progress` called once per point (`walker sweep --quantity`).
    pub fn measure(
        &mut self,
        result: &Continuation,
        (quantity, options): (Quantity, &QuantityOptions),
        setup_for: &SetupFor<'_>,
        newton: &NewtonSettings,
        progress: &(dyn Fn() + Sync),
    ) {
        use rayon::prelude::*;
        let family = &result.family;
        let points: Vec<&BranchPoint> = result
            .branches
            .iter()
            .flat_map(|b| b.grid.iter().map(|g| &g.point))
            .collect();
        let values: Vec<Result<f64, QuantityError>> = points
            .par_iter()
            .map(|p| {
                let value = if p.period_strides() > 1 {
                    Err(QuantityError::Undefined {
                        quantity,
                        why: format!(
                            "defined for period-1 gaits; this one repeats every {} strides",
                            p.period_strides()
                        ),
                    })
                } else {
                    family
                        .scene_at(p.value)
                        .map_err(|e| QuantityError::Undefined {
                            quantity,
                            why: e.to_string(),
                        })
                        .and_then(|scene| {
                            at_fixed_point(
                                quantity,
                                options,
                                &scene,
                                setup_for,
                                newton,
                                &p.orbit[0],
                            )
                        })
                };
                progress();
                value
            })
            .collect();
        let converged = self.points.iter_mut().filter_map(|r| match r {
            SweepPointRecord::Converged(c) => Some(c),
            SweepPointRecord::Failed(_) => None,
        });
        for (c, v) in converged.zip(values) {
            c.quantity = Some(QuantityValue {
                name: quantity,
                sigma_m: options.sigma_m.filter(|_| quantity == Quantity::Mfpt),
                value: v.as_ref().ok().copied(),
                error: v.err().map(|e| e.to_string()),
            });
        }
    }

    /// The points [`Self::measure`] visits: every grid point of every branch (a period-doubled
    /// one gets its reason for no value), its progress's total.
    pub fn measured_points(result: &Continuation) -> usize {
        result.branches.iter().map(|b| b.grid.len()).sum()
    }

    /// The report of a pseudo-arclength continuation (of its family's parameter): each branch's
    /// points at the grid values in arclength order (branch 0 first, then the grid values it
    /// did not reach, with the reason; then the period-doubled branches), every located
    /// bifurcation, and the branches' ends.
    pub fn from_continuation(c: &Continuation) -> Self {
        let family = &c.family;
        let param = family.param.clone();
        let mut points = Vec::new();
        for b in &c.branches {
            for g in &b.grid {
                points.push(SweepPointRecord::Converged(Box::new(converged(
                    family, &param, b.id, &g.point,
                ))));
            }
            if b.id == 0 {
                for (value, reason) in c.unreached(&param) {
                    points.push(SweepPointRecord::Failed(FailedPoint::new(
                        &param, value, reason,
                    )));
                }
            }
        }
        if c.branches.is_empty() {
            for (value, reason) in c.unreached(&param) {
                points.push(SweepPointRecord::Failed(FailedPoint::new(
                    &param, value, reason,
                )));
            }
        }
        let boundary = |id: usize, k: usize, b: &Bifurcation| BoundaryRecord {
            value: b.value,
            change: match (b.stable_before, b.stable_after) {
                (true, false) => "lost",
                (false, true) => "gained",
                _ => "none",
            },
            kind: b.kind.name(),
            branch: id,
            period_strides: k,
            multipliers: eigenvalue_pairs(&b.multipliers),
            bracket: b.bracket,
            budget_exhausted: b.budget_exhausted,
        };
        Self {
            scene: family.scene.name().to_string(),
            param_canonical: family
                .scene
                .parameter_name(&param)
                .unwrap_or_else(|_| param.clone()),
            param: param.clone(),
            points,
            stability_boundaries: c
                .branches
                .iter()
                .flat_map(|br| {
                    br.bifurcations
                        .iter()
                        .map(move |b| boundary(br.id, br.period_strides, b))
                })
                .collect(),
            branch_ends: c
                .branches
                .iter()
                .flat_map(|br| {
                    [&br.end_before, &br.end]
                        .into_iter()
                        .flatten()
                        .map(|e| BranchEndRecord {
                            branch: br.id,
                            period_strides: br.period_strides,
                            value: e.value,
                            kind: e.kind.name(),
                            event: e.event.clone(),
                            detail: e.detail.clone(),
                            bracket: e.bracket,
                            grazing: e.grazing,
                            accuracy: e.accuracy(),
                            budget_exhausted: e.budget_exhausted,
                        })
                })
                .collect(),
            branches: c
                .branches
                .iter()
                .map(|br| BranchRecord {
                    branch: br.id,
                    period_strides: br.period_strides,
                    parent: br.parent.map(|p| p.0),
                    born_at: br.parent.map(|p| p.1),
                    steps: br.steps,
                    events: br
                        .grid
                        .first()
                        .map(|g| g.point.signature.0.clone())
                        .unwrap_or_default(),
                })
                .collect(),
            unlocated: c
                .branches
                .iter()
                .flat_map(|br| {
                    br.unlocated.iter().map(move |u| UnlocatedRecord {
                        branch: br.id,
                        period_strides: br.period_strides,
                        kind: u.kind.name(),
                        bracket: [u.bracket.0, u.bracket.1],
                        reason: u.reason.clone(),
                    })
                })
                .collect(),
            switch_failures: c
                .switch_failures
                .iter()
                .map(|f| SwitchFailureRecord {
                    branch: f.parent,
                    period_strides: f.period_strides,
                    value: f.value,
                    reason: f.reason.clone(),
                })
                .collect(),
        }
    }
}

/// The record of a continuation point on branch `id`.
fn converged(family: &Family, param: &str, id: usize, p: &BranchPoint) -> ConvergedPoint {
    let named = family
        .scene_at(p.value)
        .ok()
        .and_then(|s| s.setup().ok().map(|setup| (s, setup.walker)));
    let name = |v| named.as_ref().map(|(s, w)| FixedPoint::of_state(s, w, v));
    let first = &p.strides[0];
    ConvergedPoint {
        parameter: param.to_string(),
        value: p.value,
        converged: true,
        max_abs_eigenvalue: p.max_abs_multiplier(),
        stable: p.stable(),
        eigenvalues: eigenvalue_pairs(&p.multipliers),
        fixed_point: name(&p.orbit[0]),
        step_period_s: first.duration_s,
        step_length_m: first.step_m.norm(),
        period_strides: p.period_strides(),
        branch: id,
        orbit: (p.period_strides() > 1).then(|| p.orbit.iter().map(name).collect()),
        jacobian_method: p.jacobian_method,
        quantity: None,
    }
}
