//! The stride Jacobian and its eigenvectors as the gait report lists them: rows, columns and
//! vector entries in the fixed point's order (its stride-map names sorted, as the JSON object
//! `fixed_point` lists its keys).

use crate::analysis::stability::eigenvector;
use nalgebra::{Complex, DMatrix, DVector};
use serde::Serialize;

/// The stride Jacobian `∂S/∂v` at a fixed point, by name.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StrideJacobian {
    /// The stride-map entries (coordinates and their rates, `_dot`) in the order of the rows
    /// and of the columns: sorted, as `fixed_point` lists them (`fixed_point` may hold more
    /// keys, the scene's convention outputs, which are not stride-map entries).
    pub names: Vec<String>,
    /// Row `i`, column `k`: `∂S_i/∂v_k`, entries in the units of `names` (rad, m, rad/s, m/s)
    /// per unit of the column's entry.
    pub rows: Vec<Vec<f64>>,
}

/// A complex vector as two real vectors of one length.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ComplexVector {
    /// Real parts.
    pub re: Vec<f64>,
    /// Imaginary parts.
    pub im: Vec<f64>,
}

impl StrideJacobian {
    /// `jacobian` (rows and columns in the stride map's order, named by `map_names`) reordered
    /// into the sorted order of its names.
    pub fn new(jacobian: &DMatrix<f64>, map_names: &[String]) -> Self {
        let order = sorted_order(map_names);
        Self {
            names: order.iter().map(|&i| map_names[i].clone()).collect(),
            rows: order
                .iter()
                .map(|&r| order.iter().map(|&c| jacobian[(r, c)]).collect())
                .collect(),
        }
    }
}

/// The eigenvector of `jacobian` (stride-map order, named by `map_names`) for each of
/// `eigenvalues`, in the sorted order of the names: unit 2-norm, its largest entry real and
/// positive; `None` where inverse iteration gave none.
pub fn eigenvectors(
    jacobian: &DMatrix<f64>,
    eigenvalues: &[Complex<f64>],
    map_names: &[String],
) -> Vec<Option<ComplexVector>> {
    let order = sorted_order(map_names);
    eigenvalues
        .iter()
        .map(|&lambda| {
            eigenvector(jacobian, lambda).map(|v| {
                let v = with_real_largest_entry(v);
                ComplexVector {
                    re: order.iter().map(|&i| v[i].re).collect(),
                    im: order.iter().map(|&i| v[i].im).collect(),
                }
            })
        })
        .collect()
}

/// The indices of `names` in the sorted order of the names.
fn sorted_order(names: &[String]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..names.len()).collect();
    order.sort_by(|&a, &b| names[a].cmp(&names[b]));
    order
}

/// `v` times the unit complex number that makes its largest entry real and positive (a
/// unit vector stays one): an eigenvector's phase fixed, so two runs print the same.
fn with_real_largest_entry(v: DVector<Complex<f64>>) -> DVector<Complex<f64>> {
    let largest = v
        .iter()
        .copied()
        .max_by(|a, b| a.norm_sqr().total_cmp(&b.norm_sqr()));
    match largest {
        Some(z) if z.norm() > 0.0 => {
            let phase = z.conj() / z.norm();
            v.map(|x| x * phase)
        }
        _ => v,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_columns_and_vectors_follow_the_sorted_names() {
        // Stride-map order b, a; sorted order a, b.
        let j = DMatrix::from_row_slice(2, 2, &[0.5, 0.2, 0.0, -0.3]);
        let names = vec!["b".to_string(), "a".to_string()];
        let sj = StrideJacobian::new(&j, &names);
        assert_eq!(sj.names, ["a", "b"]);
        assert_eq!(sj.rows, vec![vec![-0.3, 0.0], vec![0.2, 0.5]]);
        let lambdas = [Complex::new(0.5, 0.0), Complex::new(-0.3, 0.0)];
        let vs = eigenvectors(&j, &lambdas, &names);
        for (lambda, v) in lambdas.iter().zip(&vs) {
            let v = v.as_ref().expect("inverse iteration finds the eigenvector");
            for (i, row) in sj.rows.iter().enumerate() {
                let jv: f64 = row.iter().zip(&v.re).map(|(a, x)| a * x).sum();
                assert!((jv - lambda.re * v.re[i]).abs() < 1e-9, "{jv}");
            }
            let norm: f64 = v.re.iter().chain(&v.im).map(|x| x * x).sum();
            assert!((norm - 1.0).abs() < 1e-12);
            assert!(v.im.iter().all(|x| x.abs() < 1e-12));
            let largest = v.re.iter().copied().fold(0.0_f64, |m, x| m.max(x.abs()));
            assert!(v.re.contains(&largest), "the largest entry is positive");
        }
    }
}
