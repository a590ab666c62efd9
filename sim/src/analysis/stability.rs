//! Which freedoms an eigenvalue of the stride Jacobian belongs to: its eigenvector by inverse
//! iteration, grouped by coordinate (position and rate together).

use nalgebra::{Complex, DMatrix, DVector};
use serde::Serialize;

/// One eigenvalue and the freedoms that dominate its eigenvector.
#[derive(Clone, Debug, Serialize)]
pub struct EigenMode {
    /// `[re, im]`.
    pub eigenvalue: [f64; 2],
    /// Modulus.
    pub abs: f64,
    /// `(coordinate, share)` with share ≥ 0.1 of the eigenvector's squared norm, largest first.
    pub dominant: Vec<(String, f64)>,
    /// Whether the dominant freedom is one the 2D version lacks.
    pub three_d: bool,
}

/// The eigenvector of `j` for eigenvalue `lambda`, by shifted inverse iteration.
pub fn eigenvector(j: &DMatrix<f64>, lambda: Complex<f64>) -> Option<DVector<Complex<f64>>> {
    let n = j.nrows();
    let shift = lambda + Complex::new(1e-10 * (1.0 + lambda.norm()), 1e-10);
    let a = DMatrix::from_fn(n, n, |r, c| {
        Complex::new(j[(r, c)], 0.0)
            - if r == c {
                shift
            } else {
                Complex::new(0.0, 0.0)
            }
    });
    let lu = a.lu();
    let mut v = DVector::from_fn(n, |i, _| Complex::new(1.0 + 0.1 * i as f64, 0.3));
    for _ in 0..3 {
        v = lu.solve(&v)?;
        let norm = v.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt();
        if !(norm.is_finite() && norm > 0.0) {
            return None;
        }
        v /= Complex::new(norm, 0.0);
    }
    Some(v)
}

/// Modes for all eigenvalues. `names` are the stride-map entries (`coord`, then `coord_dot`);
/// `three_d` the coordinates that only the 3D model has.
pub fn modes(
    j: &DMatrix<f64>,
    eigenvalues: &[Complex<f64>],
    names: &[String],
    three_d: &[String],
) -> Vec<EigenMode> {
    let half = names.len() / 2;
    eigenvalues
        .iter()
        .map(|&lambda| {
            let mut dominant = Vec::new();
            if let Some(v) = eigenvector(j, lambda) {
                let mut shares: Vec<(String, f64)> = (0..half)
                    .map(|i| (names[i].clone(), v[i].norm_sqr() + v[i + half].norm_sqr()))
                    .collect();
                shares.sort_by(|a, b| b.1.total_cmp(&a.1));
                dominant = shares
                    .into_iter()
                    .filter(|(_, s)| *s >= 0.1)
                    .take(3)
                    .collect();
            }
            let three_d = dominant.first().is_some_and(|(n, _)| three_d.contains(n));
            EigenMode {
                eigenvalue: [lambda.re, lambda.im],
                abs: lambda.norm(),
                dominant,
                three_d,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eigenvector_of_a_block_matrix_lives_in_its_block() {
        let j = DMatrix::from_row_slice(
            4,
            4,
            &[
                0.5, 0.0, 0.0, 0.0, //
                0.0, 0.1, 0.0, 0.2, //
                0.0, 0.0, -0.3, 0.0, //
                0.0, 0.0, 0.0, 0.1,
            ],
        );
        let names: Vec<String> = ["a", "b", "a_dot", "b_dot"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let m = modes(
            &j,
            &[Complex::new(0.5, 0.0), Complex::new(-0.3, 0.0)],
            &names,
            &["b".into()],
        );
        assert_eq!(m[0].dominant[0].0, "a");
        assert!(m[0].dominant[0].1 > 0.999);
        assert_eq!(m[1].dominant[0].0, "a");
        assert!(!m[1].three_d);
    }
}
