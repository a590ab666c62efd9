//! Dense output: a polynomial through one accepted step of an embedded pair that has a
//! continuous extension (Hairer's for DOP853, order 7), evaluated anywhere inside the step
//! without evaluating the equations of motion. The event locator finds crossings on it.

use super::Sample;
use nalgebra::DVector;

/// A pair's continuous extension: extra stages and the rows of the interpolation matrix `D`.
/// Stage indices run over the step's stages (`0 … s−1`), the derivative at the step's end
/// (`s`), then the extra stages (`s+1 …`).
#[derive(Clone, Copy, Debug)]
pub struct DenseCoefficients {
    /// Nodes of the extra stages.
    pub extra_c: &'static [f64],
    /// Nonzero coefficients `(j, a_ij)` of each extra stage.
    pub extra_a: &'static [&'static [(usize, f64)]],
    /// Nonzero entries `(j, d_rj)` of the rows of `D` (the coefficients from the fourth on).
    pub d: &'static [&'static [(usize, f64)]],
}

/// The interpolant of one step from `t0_s` over `h_s`: `y(t0 + θh)` for `θ ∈ [0, 1]`, in
/// Hairer's form `y0 + θ(F0 + (1−θ)(F1 + θ(F2 + (1−θ)(F3 + …))))`.
#[derive(Clone, Debug)]
pub struct DenseOutput {
    /// Start of the step \[s\].
    pub t0_s: f64,
    /// Length of the step \[s\].
    pub h_s: f64,
    /// Positions and velocities at the start.
    q0: DVector<f64>,
    qd0: DVector<f64>,
    /// The coefficients `F_k` for positions and velocities.
    f: Vec<(DVector<f64>, DVector<f64>)>,
}

impl DenseOutput {
    /// An interpolant from its start and coefficients.
    pub fn new(
        t0_s: f64,
        h_s: f64,
        q0: DVector<f64>,
        qd0: DVector<f64>,
        f: Vec<(DVector<f64>, DVector<f64>)>,
    ) -> Self {
        Self {
            t0_s,
            h_s,
            q0,
            qd0,
            f,
        }
    }

    /// The interpolated sample at `t_s` \[s\] (inside the step).
    pub fn eval(&self, t_s: f64) -> Sample {
        let x = (t_s - self.t0_s) / self.h_s;
        let n = self.q0.len();
        let mut q = DVector::zeros(n);
        let mut qd = DVector::zeros(n);
        let last = self.f.len().saturating_sub(1);
        for (i, (fq, fv)) in self.f.iter().rev().enumerate() {
            // `F_k` is multiplied by θ for even k, by 1 − θ for odd k.
            let w = if (last - i).is_multiple_of(2) {
                x
            } else {
                1.0 - x
            };
            for k in 0..n {
                q[k] = (q[k] + fq[k]) * w;
                qd[k] = (qd[k] + fv[k]) * w;
            }
        }
        q += &self.q0;
        qd += &self.qd0;
        Sample { t_s, q, qd }
    }
}
