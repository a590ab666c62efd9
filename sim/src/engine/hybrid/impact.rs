//! The impact equations (19)-(21) for finite masses, in any scalar:
//! `[M̄ Gᵀ; G 0] [q̇⁺; ρ] = [M̄ q̇⁻; target]` over the free coordinates.

use crate::engine::dynamics::DynamicsOf;
use crate::engine::model::Model;
use crate::engine::singular_limit::LimitSolveError;
use nalgebra::{DMatrix, DVector, RealField};

/// The solution of the impact equations.
#[derive(Clone, Debug, PartialEq)]
pub struct ImpactSolution<T: nalgebra::Scalar> {
    /// Velocities after the impact (coordinates that are not free keep their rates).
    pub qd_plus: DVector<T>,
    /// The impulse `ρ`, one per constraint row [N·s or N·m·s].
    pub impulse: DVector<T>,
}

/// The impact equations' matrix and right-hand side over the free coordinates `free`, with
/// `M̄` taken from `mass_matrix`: `[M̄ Gᵀ; G 0]` and `[M̄ q̇⁻; target − G q̇_fixed]`, where
/// `q̇_fixed` keeps only the rates of the coordinates that are not free.
pub(crate) fn kkt_system<T: RealField + Copy>(
    mass_matrix: &DMatrix<T>,
    free: &[usize],
    qd_minus: &DVector<T>,
    g_rows: &DMatrix<T>,
    target: &DVector<T>,
) -> (DMatrix<T>, DVector<T>) {
    let n = free.len();
    let k = g_rows.nrows();
    let m0 = mass_matrix.select_rows(free).select_columns(free);
    let g = g_rows.select_columns(free);
    let v = qd_minus.select_rows(free);
    let mut a = DMatrix::zeros(n + k, n + k);
    a.view_mut((0, 0), (n, n)).copy_from(&m0);
    a.view_mut((0, n), (n, k)).copy_from(&g.transpose());
    a.view_mut((n, 0), (k, n)).copy_from(&g);
    let mut b = DVector::zeros(n + k);
    b.rows_mut(0, n).copy_from(&(&m0 * &v));
    // The constraint on the whole velocity, G q̇⁺ = target, with the coordinates that are not
    // free (locked, or driven by an actuator) keeping their rates through the impact.
    let mut v_fixed = qd_minus.clone();
    for &i in free {
        v_fixed[i] = T::zero();
    }
    let rhs = target - g_rows * &v_fixed;
    b.rows_mut(n, k).copy_from(&rhs);
    (a, b)
}

/// Solves the impact equations at `q` with pre-impact velocities `qd_minus` for a model of
/// finite masses, over the coordinates where `active` is true, for constraint rows `g_rows`
/// (k × n) and the constrained velocities after the impact `G q̇⁺ = target` (assembles
/// `dynamics` at `q`, `qd_minus`).
///
/// # Errors
/// [`LimitSolveError::Degenerate`] when the impact equations are singular.
pub fn solve_finite<T: RealField + Copy>(
    dynamics: &mut DynamicsOf<T>,
    model: &Model,
    q: &DVector<T>,
    qd_minus: &DVector<T>,
    active: &[bool],
    g_rows: &DMatrix<T>,
    target: &DVector<T>,
) -> Result<ImpactSolution<T>, LimitSolveError> {
    dynamics.assemble(model, q, qd_minus, None);
    let free: Vec<usize> = (0..q.len()).filter(|&i| active[i]).collect();
    let (a, b) = kkt_system(&dynamics.mass_matrix, &free, qd_minus, g_rows, target);
    let x = a
        .lu()
        .solve(&b)
        .ok_or(LimitSolveError::Degenerate { nullity: 1 })?;
    Ok(scatter(qd_minus, &free, &x))
}

/// `q̇⁺` from the solution `x = [q̇⁺_free; ρ]`, the other rates as in `qd_minus`.
pub(crate) fn scatter<T: RealField + Copy>(
    qd_minus: &DVector<T>,
    free: &[usize],
    x: &DVector<T>,
) -> ImpactSolution<T> {
    let n = free.len();
    let mut qd_plus = qd_minus.clone();
    for (j, &i) in free.iter().enumerate() {
        qd_plus[i] = x[j];
    }
    ImpactSolution {
        qd_plus,
        impulse: x.rows(n, x.len() - n).into_owned(),
    }
}

/// A unit constraint row on coordinate `c` of `n`: the row of a joint stop, a foot landing
/// flat or a taut string.
pub fn unit_row<T: RealField + Copy>(n: usize, c: usize) -> DMatrix<T> {
    let mut g = DMatrix::zeros(1, n);
    g[(0, c)] = T::one();
    g
}

/// The state after a locking impact on coordinate `c`: the coordinate put exactly at
/// `value` [rad or m] moving at `rate` [rad/s or m/s] (zero at a stop, the drive's rate for a
/// string), the others at their positions `q` with their post-impact rates `qd_plus`.
pub fn locked_state<T: RealField + Copy>(
    q: &DVector<T>,
    mut qd_plus: DVector<T>,
    c: usize,
    value: T,
    rate: T,
) -> (DVector<T>, DVector<T>) {
    let mut q = q.clone();
    q[c] = value;
    qd_plus[c] = rate;
    (q, qd_plus)
}
