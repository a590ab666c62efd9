//! Impacts by eq. (19)-(21): `[M̄ Gᵀ; G 0] [q̇⁺; ρ] = [M̄ q̇⁻; −e G q̇⁻]`, for any set of
//! constraint Jacobian rows `G`, including the vanishing-mass limit. The finite-mass solve is
//! the generic one of `crate::engine::hybrid::impact`; this module adds the `f64`-only limit of
//! infinitesimal bodies.

use crate::engine::dynamics::Dynamics;
use crate::engine::hybrid::impact::{kkt_system, scatter, ImpactSolution};
use crate::engine::model::Model;
use crate::engine::singular_limit::{solve_limit, LimitSolveError};
use nalgebra::{DMatrix, DVector};

/// Why an impact could not be resolved.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ImpactError {
    /// The impact equations are singular (redundant constraints, or a degenerate limit).
    #[error("impact equations are singular: {0}")]
    Singular(#[from] LimitSolveError),
}

/// Result of an impact: velocities after it (inactive coordinates keep their value) and the
/// contact impulse `ρ`, one per constraint row [N·s or N·m·s].
pub type ImpactResult = ImpactSolution<f64>;

/// Solves eq. (21) at `q` with pre-impact velocities `qd_minus`, over the coordinates where
/// `active` is true (the others keep their rates: locked or actuator-driven joints), for
/// constraint rows `g_rows` (k × n) and restitution `e`.
pub fn resolve(
    dynamics: &mut Dynamics,
    model: &Model,
    q: &DVector<f64>,
    qd_minus: &DVector<f64>,
    active: &[bool],
    g_rows: &DMatrix<f64>,
    restitution: f64,
) -> Result<ImpactResult, ImpactError> {
    let target = g_rows * qd_minus * (-restitution);
    resolve_to(dynamics, model, q, qd_minus, active, g_rows, &target)
}

/// As [`resolve`], with the constrained velocities after the impact given: `G q̇⁺ = target`
/// (e.g. a string whose far end moves at a known rate).
pub fn resolve_to(
    dynamics: &mut Dynamics,
    model: &Model,
    q: &DVector<f64>,
    qd_minus: &DVector<f64>,
    active: &[bool],
    g_rows: &DMatrix<f64>,
    target: &DVector<f64>,
) -> Result<ImpactResult, ImpactError> {
    // In f64 the equations always go through the limit solve, which also checks their rank
    // (a nearly redundant set of constraints is `Singular`, not a huge impulse); the dual-number
    // engine uses [`crate::engine::hybrid::impact::solve_finite`] on the same assembled system.
    dynamics.assemble(model, q, qd_minus, None);
    let free: Vec<usize> = (0..q.len()).filter(|&i| active[i]).collect();
    let (a0, b0) = kkt_system(&dynamics.mass_matrix, &free, qd_minus, g_rows, target);
    let no_rows = DMatrix::zeros(g_rows.nrows(), g_rows.ncols());
    let no_target = DVector::zeros(target.len());
    let (a1, b1) = kkt_system(
        &dynamics.mass_matrix_infinitesimal,
        &free,
        qd_minus,
        &no_rows,
        &no_target,
    );
    let x = solve_limit(&a0, &a1, &b0, &b1, 1e-12)?;
    Ok(scatter(qd_minus, &free, &x))
}
