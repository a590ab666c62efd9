//! The finite impact's equations on fixed-capacity arrays: the general `kkt_system`
//! (`hybrid::impact`) — `[M̄ Gᵀ; G 0] [u⁺_free; ρ] = [M̄ u⁻_free; target − G u⁻_fixed]` over
//! the free velocities — and its solve, an LU factorisation with partial pivoting, for the heel
//! strike of a fixed-size stride on a tree without infinitesimal bodies. The same equations as
//! the general impact's `DMatrix` system and LU, without an allocation; the rounding of the
//! elimination may differ from nalgebra's in the last bits (`tests/fast_stride.rs` compares
//! the strides with the general loop's, whose heel strike is the general one).

use crate::engine::planar::MAX_PLANAR_COORDINATES;

/// The impact model's largest number of velocities: the coordinates and the root's
/// translation in x and y.
pub(super) const MAX_VELOCITIES: usize = MAX_PLANAR_COORDINATES + 2;
/// The largest number of constraint rows (the contact's x and y).
pub(super) const MAX_ROWS: usize = 2;
/// The largest system: free velocities and impulses.
const MAX_UNKNOWNS: usize = MAX_VELOCITIES + MAX_ROWS;

/// An impact to solve: `n` velocities, the impact model's mass matrix `mass(i, j)`, `k`
/// constraint rows `rows(r, j)` with `G u⁺ = target`, which velocities are free, and the
/// velocities before the impact.
pub(super) struct FiniteImpact<'a, M, G> {
    pub(super) n: usize,
    pub(super) mass: M,
    pub(super) k: usize,
    pub(super) rows: G,
    pub(super) target: [f64; MAX_ROWS],
    pub(super) free: &'a [bool],
    pub(super) u_minus: &'a [f64; MAX_VELOCITIES],
}

impl<M: Fn(usize, usize) -> f64, G: Fn(usize, usize) -> f64> FiniteImpact<'_, M, G> {
    /// The velocities after the impact (the fixed ones as before it); `None` when the sizes
    /// exceed the arrays or a pivot is zero up to rounding (`≤ 1e-12` of the largest:
    /// redundant constraints, which the general impact reports).
    pub(super) fn solve(&self) -> Option<[f64; MAX_VELOCITIES]> {
        let (n, k) = (self.n, self.k);
        if n > MAX_VELOCITIES || k > MAX_ROWS || self.free.len() < n {
            return None;
        }
        let mut free = [0usize; MAX_VELOCITIES];
        let mut nf = 0;
        for (i, _) in self.free[..n].iter().enumerate().filter(|(_, &f)| f) {
            free[nf] = i;
            nf += 1;
        }
        let free = &free[..nf];
        let size = nf + k;
        let mut a = [[0.0; MAX_UNKNOWNS]; MAX_UNKNOWNS];
        let mut b = [0.0; MAX_UNKNOWNS];
        for (r, &i) in free.iter().enumerate() {
            for (c, &j) in free.iter().enumerate() {
                a[r][c] = (self.mass)(i, j);
            }
            for row in 0..k {
                a[r][nf + row] = (self.rows)(row, i);
                a[nf + row][r] = (self.rows)(row, i);
            }
            // M̄ u⁻ over the free velocities, summed over the columns in order.
            b[r] = free
                .iter()
                .enumerate()
                .fold(0.0, |acc, (c, &j)| acc + a[r][c] * self.u_minus[j]);
        }
        // The rows on the whole velocity: the velocities that are not free keep theirs.
        for row in 0..k {
            let fixed: f64 = (0..n)
                .filter(|&j| !self.free[j])
                .fold(0.0, |acc, j| acc + (self.rows)(row, j) * self.u_minus[j]);
            b[nf + row] = self.target[row] - fixed;
        }
        let x = lu_solve(&mut a, &mut b, size)?;
        let mut u_plus = *self.u_minus;
        for (c, &i) in free.iter().enumerate() {
            u_plus[i] = x[c];
        }
        Some(u_plus)
    }
}

/// Solves `a x = b` (the leading `size` rows and columns) by Gaussian elimination with
/// partial pivoting; `None` when a pivot is at most `1e-12` of the largest.
fn lu_solve(
    a: &mut [[f64; MAX_UNKNOWNS]; MAX_UNKNOWNS],
    b: &mut [f64; MAX_UNKNOWNS],
    size: usize,
) -> Option<[f64; MAX_UNKNOWNS]> {
    let mut pivots = [0.0f64; MAX_UNKNOWNS];
    for col in 0..size {
        let p = (col..size).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        a.swap(col, p);
        b.swap(col, p);
        let pivot = a[col][col];
        pivots[col] = pivot.abs();
        if pivot == 0.0 || !pivot.is_finite() {
            return None;
        }
        let (upper, lower) = a.split_at_mut(col + 1);
        let pivot_row = &upper[col];
        for (k, row) in lower[..size - col - 1].iter_mut().enumerate() {
            let f = row[col] / pivot;
            if f != 0.0 {
                for (x, p) in row[col + 1..size].iter_mut().zip(&pivot_row[col + 1..size]) {
                    *x -= f * p;
                }
                b[col + 1 + k] -= f * b[col];
            }
        }
    }
    let largest = pivots[..size].iter().fold(0.0f64, |m, &p| m.max(p));
    if pivots[..size].iter().any(|&p| p <= 1e-12 * largest) {
        return None;
    }
    let mut x = [0.0; MAX_UNKNOWNS];
    for r in (0..size).rev() {
        let s = (r + 1..size).fold(b[r], |acc, c| acc - a[r][c] * x[c]);
        x[r] = s / a[r][r];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    /// Against nalgebra's LU: a diagonally dominant mass matrix (no row swap), and one whose
    /// first mass entry is small against the constraint row's (the elimination swaps rows).
    #[test]
    fn the_solve_agrees_with_nalgebra_lu() {
        let dominant = [
            [3.0, 1.0, 0.5, 0.2],
            [1.0, 4.0, 0.3, 0.1],
            [0.5, 0.3, 2.0, 0.7],
            [0.2, 0.1, 0.7, 1.5],
        ];
        let small_first = [
            [0.01, 0.002, 0.001, 0.0],
            [0.002, 4.0, 0.3, 0.1],
            [0.001, 0.3, 2.0, 0.7],
            [0.0, 0.1, 0.7, 1.5],
        ];
        for m in [dominant, small_first] {
            agrees_with_nalgebra_lu(m);
        }
    }

    fn agrees_with_nalgebra_lu(m: [[f64; 4]; 4]) {
        let g = [[1.0, 0.0, 0.4, -0.9], [0.0, 1.0, -1.1, 0.3]];
        let mut u_minus = [0.0; MAX_VELOCITIES];
        u_minus[..4].copy_from_slice(&[0.0, 0.0, -1.2, 0.8]);
        for free in [[true, true, true, true], [true, true, true, false]] {
            let impact = FiniteImpact {
                n: 4,
                mass: |i: usize, j: usize| m[i][j],
                k: 2,
                rows: |r: usize, j: usize| g[r][j],
                target: [0.1, -0.3],
                free: &free,
                u_minus: &u_minus,
            };
            let u_plus = impact.solve().expect("solvable");
            // The general system, assembled as `kkt_system` does, solved by nalgebra.
            let idx: Vec<usize> = (0..4).filter(|&i| free[i]).collect();
            let nf = idx.len();
            let mut a = DMatrix::zeros(nf + 2, nf + 2);
            let mut b = nalgebra::DVector::zeros(nf + 2);
            for (r, &i) in idx.iter().enumerate() {
                for (c, &j) in idx.iter().enumerate() {
                    a[(r, c)] = m[i][j];
                    b[r] += m[i][j] * u_minus[j];
                }
                for row in 0..2 {
                    a[(r, nf + row)] = g[row][i];
                    a[(nf + row, r)] = g[row][i];
                }
            }
            for row in 0..2 {
                let fixed: f64 = (0..4)
                    .filter(|&j| !free[j])
                    .map(|j| g[row][j] * u_minus[j])
                    .sum();
                b[nf + row] = impact.target[row] - fixed;
            }
            let x = a.lu().solve(&b).expect("nalgebra");
            for (c, &i) in idx.iter().enumerate() {
                assert!((u_plus[i] - x[c]).abs() < 1e-14, "{free:?} {i}");
            }
            for i in (0..4).filter(|&i| !free[i]) {
                assert_eq!(u_plus[i], u_minus[i]);
            }
        }
    }

    /// Two constraint rows equal but for 1e-14: refused as the general impact's LU would be
    /// (a pivot at or below 1e-12 of the largest).
    #[test]
    fn nearly_redundant_rows_are_refused() {
        let u_minus = [1.0; MAX_VELOCITIES];
        let g = [[1.0, 2.0], [1.0, 2.0 + 1e-14]];
        let impact = FiniteImpact {
            n: 2,
            mass: |i: usize, j: usize| if i == j { 1.0 } else { 0.0 },
            k: 2,
            rows: |r: usize, j: usize| g[r][j],
            target: [0.0, 0.0],
            free: &[true, true],
            u_minus: &u_minus,
        };
        assert!(impact.solve().is_none());
    }

    #[test]
    fn redundant_rows_are_refused() {
        let u_minus = [1.0; MAX_VELOCITIES];
        let impact = FiniteImpact {
            n: 2,
            mass: |i: usize, j: usize| if i == j { 1.0 } else { 0.0 },
            k: 2,
            rows: |_: usize, j: usize| [1.0, 2.0][j],
            target: [0.0, 0.0],
            free: &[true, true],
            u_minus: &u_minus,
        };
        assert!(impact.solve().is_none());
    }
}
