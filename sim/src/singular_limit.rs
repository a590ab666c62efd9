//! Linear solves in the limit of vanishing masses.
//!
//! Garcia et al.'s "simplest walking model" lets the foot mass tend to zero. Its equations are
//! then the limit `ε → 0` of `(A0 + ε A1) x = b0 + ε b1`, with `A0` symmetric and singular.
//! Writing `x = x0 + ε x1 + …`: `A0 x0 = b0` at order one and `A0 x1 + A1 x0 = b1` at order `ε`,
//! whose solvability (project on the null space `N` of `A0`) gives `Nᵀ A1 x0 = Nᵀ b1`. The limit
//! is the unique `x0` meeting both, when `Nᵀ A1 N` is invertible. The same routine serves the
//! equations of motion and the impact equations (21).

use nalgebra::{DMatrix, DVector};

/// Why a limit solve failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LimitSolveError {
    /// `A0` is singular and the infinitesimal terms do not fix the null-space part.
    #[error("matrix is singular (null space of dimension {nullity}) and the vanishing-mass terms do not determine it")]
    Degenerate {
        /// Dimension of the null space of `A0`.
        nullity: usize,
    },
    /// `b0` has a component outside the range of `A0`: no limit exists.
    #[error("right-hand side not in the range of the matrix (residual {residual:e})")]
    Inconsistent {
        /// Size of the inconsistent part.
        residual: f64,
    },
}

/// Solves `A x = b` for a symmetric `A` (LU with partial pivoting, any definiteness).
pub fn solve_regular(a: &DMatrix<f64>, b: &DVector<f64>) -> Result<DVector<f64>, LimitSolveError> {
    a.clone()
        .lu()
        .solve(b)
        .ok_or(LimitSolveError::Degenerate { nullity: 1 })
}

/// Solves the limit `ε → 0` of `(A0 + ε A1) x = b0 + ε b1` for symmetric `A0`.
/// `rel_tol` decides which eigenvalues of `A0` count as zero, relative to the largest.
pub fn solve_limit(
    a0: &DMatrix<f64>,
    a1: &DMatrix<f64>,
    b0: &DVector<f64>,
    b1: &DVector<f64>,
    rel_tol: f64,
) -> Result<DVector<f64>, LimitSolveError> {
    let n = a0.nrows();
    let eig = a0.clone().symmetric_eigen();
    let scale = eig.eigenvalues.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let null: Vec<usize> = (0..n)
        .filter(|&i| eig.eigenvalues[i].abs() <= rel_tol * scale)
        .collect();
    if null.is_empty() {
        return solve_regular(a0, b0);
    }
    // Range part: x_r = Σ (v_iᵀ b0 / λ_i) v_i over the non-null eigenpairs.
    let mut x_r = DVector::zeros(n);
    let mut residual = 0.0f64;
    for i in 0..n {
        let v = eig.eigenvectors.column(i);
        let c = v.dot(b0);
        if null.contains(&i) {
            residual = residual.max(c.abs());
        } else {
            x_r += v * (c / eig.eigenvalues[i]);
        }
    }
    if residual > 1e-9 * (1.0 + b0.norm()) {
        return Err(LimitSolveError::Inconsistent { residual });
    }
    let k = null.len();
    let mut nmat = DMatrix::zeros(n, k);
    for (j, &i) in null.iter().enumerate() {
        nmat.set_column(j, &eig.eigenvectors.column(i));
    }
    let lhs = nmat.transpose() * a1 * &nmat;
    let rhs = nmat.transpose() * (b1 - a1 * &x_r);
    let y = lhs
        .lu()
        .solve(&rhs)
        .ok_or(LimitSolveError::Degenerate { nullity: k })?;
    Ok(x_r + nmat * y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limit_matches_small_epsilon_solution() {
        let a0 = DMatrix::from_row_slice(2, 2, &[2.0, 0.0, 0.0, 0.0]);
        let a1 = DMatrix::from_row_slice(2, 2, &[1.0, 0.5, 0.5, 1.0]);
        let b0 = DVector::from_vec(vec![1.0, 0.0]);
        let b1 = DVector::from_vec(vec![0.3, 0.7]);
        let x = solve_limit(&a0, &a1, &b0, &b1, 1e-12).unwrap();
        let eps = 1e-7;
        let xe = (&a0 + &a1 * eps).lu().solve(&(&b0 + &b1 * eps)).unwrap();
        assert!((x - xe).norm() < 1e-6);
    }

    #[test]
    fn degenerate_limit_is_reported() {
        let a0 = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 0.0]);
        let a1 = DMatrix::zeros(2, 2);
        let b = DVector::from_vec(vec![1.0, 0.0]);
        assert!(matches!(
            solve_limit(&a0, &a1, &b, &b, 1e-12),
            Err(LimitSolveError::Degenerate { nullity: 1 })
        ));
    }
}
