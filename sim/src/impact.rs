//! Impacts by eq. (19)-(21): `[M̄ Gᵀ; G 0] [q̇⁺; ρ] = [M̄ q̇⁻; −e G q̇⁻]`, for any set of
//! constraint Jacobian rows `G`, including the vanishing-mass limit.

use crate::dynamics::Dynamics;
use crate::model::Model;
use crate::singular_limit::{solve_limit, LimitSolveError};
use nalgebra::{DMatrix, DVector};

/// Why an impact could not be resolved.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ImpactError {
    /// The impact equations are singular (redundant constraints, or a degenerate limit).
    #[error("impact equations are singular: {0}")]
    Singular(#[from] LimitSolveError),
}

/// Result of an impact.
#[derive(Clone, Debug, PartialEq)]
pub struct ImpactResult {
    /// Velocities after the impact (inactive coordinates keep their value).
    pub qd_plus: DVector<f64>,
    /// The contact impulse `ρ`, one per constraint row [N·s or N·m·s].
    pub impulse: DVector<f64>,
}

/// Solves eq. (21) at `q` with pre-impact velocities `qd_minus`, over the coordinates where
/// `active` is true (the others keep their rates: locked or actuator-driven joints), for constraint rows `g_rows` (k × n) and restitution `e`.
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
    dynamics.assemble(model, q, qd_minus, None);
    let idx: Vec<usize> = (0..q.len()).filter(|&i| active[i]).collect();
    let n = idx.len();
    let k = g_rows.nrows();
    let m0 = dynamics.mass_matrix.select_rows(&idx).select_columns(&idx);
    let m1 = dynamics
        .mass_matrix_infinitesimal
        .select_rows(&idx)
        .select_columns(&idx);
    let g = g_rows.select_columns(&idx);
    let v = qd_minus.select_rows(&idx);
    let mut a0 = DMatrix::zeros(n + k, n + k);
    a0.view_mut((0, 0), (n, n)).copy_from(&m0);
    a0.view_mut((0, n), (n, k)).copy_from(&g.transpose());
    a0.view_mut((n, 0), (k, n)).copy_from(&g);
    let mut a1 = DMatrix::zeros(n + k, n + k);
    a1.view_mut((0, 0), (n, n)).copy_from(&m1);
    let mut b0 = DVector::zeros(n + k);
    b0.rows_mut(0, n).copy_from(&(&m0 * &v));
    // The constraint on the whole velocity, G q̇⁺ = target, with the coordinates that are not
    // free (locked, or driven by an actuator) keeping their rates through the impact.
    let mut v_fixed = qd_minus.clone();
    for &i in &idx {
        v_fixed[i] = 0.0;
    }
    let rhs = target - g_rows * &v_fixed;
    b0.rows_mut(n, k).copy_from(&rhs);
    let mut b1 = DVector::zeros(n + k);
    b1.rows_mut(0, n).copy_from(&(&m1 * &v));
    let x = solve_limit(&a0, &a1, &b0, &b1, 1e-12)?;
    let mut qd_plus = qd_minus.clone();
    for (j, &i) in idx.iter().enumerate() {
        qd_plus[i] = x[j];
    }
    Ok(ImpactResult {
        qd_plus,
        impulse: x.rows(n, k).into_owned(),
    })
}
