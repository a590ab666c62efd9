//! Dormand-Prince 5(4): an adaptive embedded Runge-Kutta pair, the accuracy reference.

use super::dense::DenseCoefficients;
use super::embedded::{EmbeddedPair, EmbeddedRk, Tolerances};
use super::Sample;
use nalgebra::DVector;

const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
/// The nonzero stage coefficients `a_ij` as `(j, a_ij)`, stages 1 to 7 (the seventh row is
/// the fifth-order weights: first same as last).
const A: [&[(usize, f64)]; 7] = [
    &[],
    &[(0, 1.0 / 5.0)],
    &[(0, 3.0 / 40.0), (1, 9.0 / 40.0)],
    &[(0, 44.0 / 45.0), (1, -56.0 / 15.0), (2, 32.0 / 9.0)],
    &[
        (0, 19372.0 / 6561.0),
        (1, -25360.0 / 2187.0),
        (2, 64448.0 / 6561.0),
        (3, -212.0 / 729.0),
    ],
    &[
        (0, 9017.0 / 3168.0),
        (1, -355.0 / 33.0),
        (2, 46732.0 / 5247.0),
        (3, 49.0 / 176.0),
        (4, -5103.0 / 18656.0),
    ],
    B5,
];
/// Fifth-order weights (the seventh stage's row).
const B5: &[(usize, f64)] = &[
    (0, 35.0 / 384.0),
    (2, 500.0 / 1113.0),
    (3, 125.0 / 192.0),
    (4, -2187.0 / 6784.0),
    (5, 11.0 / 84.0),
];

/// Fifth-order weights minus fourth-order weights.
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// Dormand and Prince's continuous extension of order 4 (Hairer, Nørsett & Wanner, *Solving
/// Ordinary Differential Equations I*, II.6; `CONTD5` of Hairer's `dopri5.f`): no extra stage,
/// the fifth coefficient `h Σ d_j k_j` over the step's stages, the seventh the derivative at
/// the step's end (first same as last).
const INTERPOLANT: DenseCoefficients = DenseCoefficients {
    extra_c: &[],
    extra_a: &[],
    d: &[&[
        (0, -12715105075.0 / 11282082432.0),
        (2, 87487479700.0 / 32700410799.0),
        (3, -10690763975.0 / 1880347072.0),
        (4, 701980252875.0 / 199316789632.0),
        (5, -1453857185.0 / 822651844.0),
        (6, 69997945.0 / 29380423.0),
    ]],
};

/// The Dormand-Prince 5(4) pair with a standard step-size controller (exponent 1/5).
#[derive(Clone, Copy, Debug)]
pub struct Dopri5Pair;

impl EmbeddedPair for Dopri5Pair {
    const NAME: &'static str = "dopri5";
    const C: &'static [f64] = &C;
    const A: &'static [&'static [(usize, f64)]] = &A;
    const B: &'static [(usize, f64)] = B5;
    const EXPONENT: f64 = 0.2;
    const MIN_FACTOR: f64 = 0.2;
    const MAX_FACTOR: f64 = 5.0;
    const FSAL: bool = true;
    /// For sampling only: events keep their exact-step refinement (no `DENSE`).
    const INTERPOLANT: Option<DenseCoefficients> = Some(INTERPOLANT);

    fn error_norm(
        tol: Tolerances,
        h: f64,
        s: &Sample,
        q_new: &DVector<f64>,
        v_new: &DVector<f64>,
        kq: &[DVector<f64>],
        kv: &[DVector<f64>],
    ) -> f64 {
        let n = s.q.len();
        let mut err2 = 0.0;
        for i in 0..n {
            let (mut eq, mut ev) = (0.0, 0.0);
            for j in 0..7 {
                eq += E[j] * kq[j][i];
                ev += E[j] * kv[j][i];
            }
            let sq = tol.atol + tol.rtol * s.q[i].abs().max(q_new[i].abs());
            let sv = tol.atol + tol.rtol * s.qd[i].abs().max(v_new[i].abs());
            err2 += (h * eq / sq).powi(2) + (h * ev / sv).powi(2);
        }
        (err2 / (2 * n).max(1) as f64).sqrt()
    }
}

/// Adaptive Dormand-Prince 5(4) with a standard step-size controller.
pub type Dopri5 = EmbeddedRk<Dopri5Pair>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_sum_to_the_nodes_and_the_error_weights_to_zero() {
        for (i, row) in A.iter().enumerate() {
            let sum: f64 = row.iter().map(|(_, a)| a).sum();
            assert!((sum - C[i]).abs() < 1e-14, "row {i}: {sum} vs {}", C[i]);
        }
        assert!(E.iter().sum::<f64>().abs() < 1e-15);
    }

    /// `q̈ = −sin q`.
    struct Pendulum;

    impl crate::engine::integrators::SecondOrderSystem for Pendulum {
        fn accelerations(
            &mut self,
            _t: f64,
            q: &DVector<f64>,
            _qd: &DVector<f64>,
        ) -> Result<DVector<f64>, crate::engine::dynamics::DynamicsError> {
            Ok(q.map(|x| -x.sin()))
        }
    }

    /// Largest difference between the interpolant of one step of size `h` and exact steps to
    /// interior points, the difference at the step's end, and the evaluations it cost.
    fn interpolant_error(h: f64) -> (f64, f64, usize) {
        use crate::engine::integrators::Integrator;
        let mut i = Dopri5::new(1.0, 1.0, 1.0);
        let s = Sample {
            t_s: 0.3,
            q: DVector::from_element(1, 1.2),
            qd: DVector::from_element(1, -0.4),
        };
        let end = i.step_exact(&mut Pendulum, &s, h).unwrap();
        let before = i.evaluations();
        assert!(i.dense_output(&mut Pendulum, &s, &end).is_none());
        let dense = i.interpolant(&mut Pendulum, &s, &end).unwrap().unwrap();
        let cost = i.evaluations() - before;
        let at_end = dense.eval(end.t_s);
        let end_error = (at_end.q[0] - end.q[0])
            .abs()
            .max((at_end.qd[0] - end.qd[0]).abs());
        let mut worst = 0.0f64;
        for k in 1..10 {
            let t = s.t_s + h * f64::from(k) / 10.0;
            let d = dense.eval(t);
            let e = Dopri5::new(1.0, 1.0, 1.0)
                .step_exact(&mut Pendulum, &s, t - s.t_s)
                .unwrap();
            worst = worst.max((d.q[0] - e.q[0]).abs().max((d.qd[0] - e.qd[0]).abs()));
        }
        (worst, end_error, cost)
    }

    #[test]
    fn the_interpolant_is_fifth_order_locally_free_and_ends_on_the_step() {
        let (e1, end1, cost1) = interpolant_error(0.4);
        let (e2, end2, cost2) = interpolant_error(0.2);
        assert!(end1 < 1e-15 && end2 < 1e-15, "{end1:e} {end2:e}");
        assert_eq!((cost1, cost2), (0, 0));
        // A fourth-order continuous extension: local error O(h⁵).
        let order = (e1 / e2).log2();
        assert!(order > 4.5, "order {order} ({e1:e}, {e2:e})");
        assert!(e2 < 1e-6, "{e2:e}");
    }
}
