//! Linear solves in the limit of vanishing masses.
//!
//! Garcia et al.'s "simplest walking model" lets the foot mass tend to zero. Its equations are
//! then the limit `ε → 0` of `(A0 + ε A1) x = b0 + ε b1`, with `A0` symmetric and singular.
//! Writing `x = x0 + ε x1 + …`: `A0 x0 = b0` at order one and `A0 x1 + A1 x0 = b1` at order `ε`,
//! whose solvability (project on the null space `N` of `A0`) gives `Nᵀ A1 x0 = Nᵀ b1`. The limit
//! is the unique `x0` meeting both, when `Nᵀ A1 N` is invertible. The same routine serves the
//! equations of motion and the impact equations (21).

use nalgebra::{DMatrix, DVector, SMatrix, SVector};

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

/// Eigenvalues of `A0` at most this times its largest in magnitude count as zero in the
/// equations of motion's limit solve.
pub const NULL_EIGENVALUE_REL_TOL: f64 = 1e-12;

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

/// [`solve_limit`] on fixed-size matrices of a small, positive semi-definite `A0` (a mass
/// matrix; no allocation), step for step the same: the eigenpairs of `A0` (cyclic Jacobi),
/// the range part of `x`, then the null-space part from `Nᵀ A1 N y = Nᵀ (b1 − A1 x_r)`, here
/// with `N` padded to `n` columns (zero columns outside the null space, whose rows and columns
/// of `Nᵀ A1 N` are the identity's, so their `y` is zero), solved by Cholesky: `Nᵀ A1 N` of an
/// infinitesimal mass matrix `A1` is positive definite where the limit exists.
///
/// # Errors
/// As [`solve_limit`]; also an eigen-decomposition that does not converge in its sweep budget
/// (`Degenerate`).
pub fn solve_limit_fixed<const N: usize>(
    a0: &SMatrix<f64, N, N>,
    a1: &SMatrix<f64, N, N>,
    b0: &SVector<f64, N>,
    b1: &SVector<f64, N>,
    rel_tol: f64,
) -> Result<SVector<f64, N>, LimitSolveError> {
    let (eigenvalues, eigenvectors) =
        symmetric_eigen_jacobi(a0).ok_or(LimitSolveError::Degenerate { nullity: N })?;
    let scale = eigenvalues.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut null = [false; N];
    for (is_null, v) in null.iter_mut().zip(eigenvalues.iter()) {
        *is_null = v.abs() <= rel_tol * scale;
    }
    let k = null.iter().filter(|&&z| z).count();
    if k == 0 {
        let mut a = *a0;
        let mut x = *b0;
        return match cholesky_solve(&mut a, &mut x) {
            true => Ok(x),
            false => Err(LimitSolveError::Degenerate { nullity: 1 }),
        };
    }
    let mut x_r = SVector::<f64, N>::zeros();
    let mut residual = 0.0f64;
    let mut nmat = SMatrix::<f64, N, N>::zeros();
    for i in 0..N {
        let v = eigenvectors.column(i);
        let c = v.dot(b0);
        if null[i] {
            residual = residual.max(c.abs());
            nmat.set_column(i, &v);
        } else {
            x_r += v * (c / eigenvalues[i]);
        }
    }
    if residual > 1e-9 * (1.0 + b0.norm()) {
        return Err(LimitSolveError::Inconsistent { residual });
    }
    let mut lhs = nmat.transpose() * a1 * nmat;
    for i in (0..N).filter(|&i| !null[i]) {
        lhs[(i, i)] = 1.0;
    }
    let mut y = nmat.transpose() * (b1 - a1 * x_r);
    if !cholesky_solve(&mut lhs, &mut y) {
        return Err(LimitSolveError::Degenerate { nullity: k });
    }
    Ok(x_r + nmat * y)
}

/// Eigenvalues and orthonormal eigenvectors (columns) of a small symmetric matrix by cyclic
/// Jacobi rotations; `None` if the off-diagonal part has not vanished within 50 sweeps.
fn symmetric_eigen_jacobi<const N: usize>(
    a: &SMatrix<f64, N, N>,
) -> Option<([f64; N], SMatrix<f64, N, N>)> {
    let mut a = *a;
    let mut v = SMatrix::<f64, N, N>::identity();
    let total: f64 = a.iter().map(|x| x * x).sum();
    for _ in 0..50 {
        let mut off = 0.0;
        for p in 0..N {
            for q in p + 1..N {
                off += a[(p, q)] * a[(p, q)];
            }
        }
        if off <= 1e-36 * total || off == 0.0 {
            let mut values = [0.0; N];
            for (i, x) in values.iter_mut().enumerate() {
                *x = a[(i, i)];
            }
            return Some((values, v));
        }
        for p in 0..N {
            for q in p + 1..N {
                let apq = a[(p, q)];
                if apq == 0.0 {
                    continue;
                }
                let theta = (a[(q, q)] - a[(p, p)]) / (2.0 * apq);
                let t = theta.signum() / (theta.abs() + theta.hypot(1.0));
                let c = 1.0 / t.hypot(1.0);
                let s = t * c;
                for r in 0..N {
                    let (arp, arq) = (a[(r, p)], a[(r, q)]);
                    a[(r, p)] = c * arp - s * arq;
                    a[(r, q)] = s * arp + c * arq;
                }
                for r in 0..N {
                    let (apr, aqr) = (a[(p, r)], a[(q, r)]);
                    a[(p, r)] = c * apr - s * aqr;
                    a[(q, r)] = s * apr + c * aqr;
                }
                for r in 0..N {
                    let (vrp, vrq) = (v[(r, p)], v[(r, q)]);
                    v[(r, p)] = c * vrp - s * vrq;
                    v[(r, q)] = s * vrp + c * vrq;
                }
            }
        }
    }
    None
}

/// Solves `A x = b` in place for a symmetric positive definite `A` (its lower triangle
/// overwritten with the Cholesky factor, `b` with `x`); false if `A` is not positive definite.
pub(crate) fn cholesky_solve<const N: usize>(
    a: &mut SMatrix<f64, N, N>,
    b: &mut SVector<f64, N>,
) -> bool {
    for j in 0..N {
        let mut d = a[(j, j)];
        for p in 0..j {
            d -= a[(j, p)] * a[(j, p)];
        }
        // Also rejects NaN (which is not greater than zero).
        if d.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return false;
        }
        let d = d.sqrt();
        a[(j, j)] = d;
        for i in j + 1..N {
            let mut v = a[(i, j)];
            for p in 0..j {
                v -= a[(i, p)] * a[(j, p)];
            }
            a[(i, j)] = v / d;
        }
    }
    for i in 0..N {
        let mut v = b[i];
        for p in 0..i {
            v -= a[(i, p)] * b[p];
        }
        b[i] = v / a[(i, i)];
    }
    for i in (0..N).rev() {
        let mut v = b[i];
        for p in i + 1..N {
            v -= a[(p, i)] * b[p];
        }
        b[i] = v / a[(i, i)];
    }
    true
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
    fn fixed_size_limit_equals_the_general_one() {
        let a0 = SMatrix::<f64, 3, 3>::new(2.0, 1.0, 0.0, 1.0, 0.5, 0.0, 0.0, 0.0, 0.0);
        let a1 = SMatrix::<f64, 3, 3>::new(1.0, 0.2, 0.1, 0.2, 1.0, 0.3, 0.1, 0.3, 2.0);
        let b0 = SVector::<f64, 3>::new(1.0, 0.5, 0.0);
        let b1 = SVector::<f64, 3>::new(0.3, -0.7, 0.4);
        let d = |m: &SMatrix<f64, 3, 3>| DMatrix::from_column_slice(3, 3, m.as_slice());
        let v = |b: &SVector<f64, 3>| DVector::from_column_slice(b.as_slice());
        let general = solve_limit(&d(&a0), &d(&a1), &v(&b0), &v(&b1), 1e-12).unwrap();
        let fixed = solve_limit_fixed(&a0, &a1, &b0, &b1, 1e-12).unwrap();
        assert!(
            (v(&fixed) - &general).amax() < 1e-14,
            "{fixed} vs {general}"
        );
        // Regular A0: the plain solve.
        let a0 = a0 + SMatrix::<f64, 3, 3>::identity();
        let general = solve_limit(&d(&a0), &d(&a1), &v(&b0), &v(&b1), 1e-12).unwrap();
        let fixed = solve_limit_fixed(&a0, &a1, &b0, &b1, 1e-12).unwrap();
        assert!((v(&fixed) - &general).amax() < 1e-14);
        // Inconsistent right-hand side.
        let b0 = SVector::<f64, 3>::new(1.0, 0.5, 1.0);
        assert!(matches!(
            solve_limit_fixed(
                &(a0 - SMatrix::<f64, 3, 3>::identity()),
                &a1,
                &b0,
                &b1,
                1e-12
            ),
            Err(LimitSolveError::Inconsistent { .. })
        ));
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
