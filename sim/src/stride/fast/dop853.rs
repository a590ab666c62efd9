//! DOP853 on fixed-size states: the general integrator's steps, step-size controller, kept
//! first stage and seventh-order dense output ([`crate::engine::integrators::Dop853`]), with the state
//! `SVector<f64, N>` positions and velocities instead of `DVector`s and the system called
//! directly instead of through `dyn`. The tableau, the error estimate and the controller are
//! the general integrator's ([`Dop853Pair`]'s constants, `component_error`, `adaptive_step`):
//! written once, the same arithmetic in the same order.

use crate::engine::dynamics::DynamicsError;
use crate::engine::integrators::{
    adaptive_step, combined_error, component_error, Dop853Pair, EmbeddedPair, IntegrationError,
    StepLimits,
};
use nalgebra::SVector;

/// Stages of a DOP853 step.
const STAGES: usize = 12;
/// Stage buffers: the step's stages, the derivative at its end, the dense output's three extra
/// stages.
const BUFFERS: usize = STAGES + 4;
/// Hairer's dense-output coefficients `F0 … F6`.
const DENSE_TERMS: usize = 7;

/// Positions and velocities at a stride time (a fixed-size [`crate::engine::integrators::Sample`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct State<const N: usize> {
    /// Stride time [s].
    pub(super) t_s: f64,
    /// Generalised coordinates.
    pub(super) q: SVector<f64, N>,
    /// Generalised velocities.
    pub(super) qd: SVector<f64, N>,
}

/// A second-order system on fixed-size states.
pub(super) trait FixedSystem<const N: usize> {
    /// `q̈` at `t`, `q`, `q̇`.
    fn accelerations(
        &mut self,
        t_s: f64,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
    ) -> Result<SVector<f64, N>, DynamicsError>;
}

/// The derivative kept from a step's first stage (reused by a retried step or a refining step
/// from the same sample).
#[derive(Clone, Copy, Debug)]
struct Kept<const N: usize> {
    valid: bool,
    at: State<N>,
    a: SVector<f64, N>,
}

/// The last trial step, for its dense output (its stages are still in the buffers).
#[derive(Clone, Copy, Debug)]
struct LastStep<const N: usize> {
    valid: bool,
    from: State<N>,
    h_s: f64,
    q1: SVector<f64, N>,
    v1: SVector<f64, N>,
}

/// The dense output of one step: `y(t0 + θh) = y0 + θ(F0 + (1−θ)(F1 + θ(F2 + …)))`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Dense<const N: usize> {
    /// Start of the step [s].
    pub(super) t0_s: f64,
    /// Length of the step [s].
    pub(super) h_s: f64,
    q0: SVector<f64, N>,
    v0: SVector<f64, N>,
    fq: [SVector<f64, N>; DENSE_TERMS],
    fv: [SVector<f64, N>; DENSE_TERMS],
}

impl<const N: usize> Dense<N> {
    /// The interpolated state at `t_s` (inside the step).
    pub(super) fn eval(&self, t_s: f64) -> State<N> {
        let x = (t_s - self.t0_s) / self.h_s;
        let mut q = SVector::<f64, N>::zeros();
        let mut qd = SVector::<f64, N>::zeros();
        for i in 0..DENSE_TERMS {
            let k = DENSE_TERMS - 1 - i;
            let w = if i % 2 == 0 { x } else { 1.0 - x };
            for c in 0..N {
                q[c] = (q[c] + self.fq[k][c]) * w;
                qd[c] = (qd[c] + self.fv[k][c]) * w;
            }
        }
        State {
            t_s,
            q: q + self.q0,
            qd: qd + self.v0,
        }
    }
}

/// Adaptive DOP853 on fixed-size states.
#[derive(Clone, Debug)]
pub(super) struct FixedDop853<const N: usize> {
    rtol: f64,
    atol: f64,
    h_max_s: f64,
    h_next_s: f64,
    evaluations: usize,
    kept: Kept<N>,
    last: LastStep<N>,
    kq: [SVector<f64, N>; BUFFERS],
    kv: [SVector<f64, N>; BUFFERS],
}

/// The general integrator's smallest step before giving up [s].
const H_MIN_S: f64 = 1e-14;

impl<const N: usize> FixedDop853<N> {
    /// Tolerances on the local error, and the largest step [s].
    pub(super) fn new(rtol: f64, atol: f64, h_max_s: f64) -> Self {
        let zero = State {
            t_s: 0.0,
            q: SVector::zeros(),
            qd: SVector::zeros(),
        };
        Self {
            rtol,
            atol,
            h_max_s,
            h_next_s: 0.0,
            evaluations: 0,
            kept: Kept {
                valid: false,
                at: zero,
                a: SVector::zeros(),
            },
            last: LastStep {
                valid: false,
                from: zero,
                h_s: 0.0,
                q1: SVector::zeros(),
                v1: SVector::zeros(),
            },
            kq: [SVector::zeros(); BUFFERS],
            kv: [SVector::zeros(); BUFFERS],
        }
    }

    /// Evaluations since the last reset.
    pub(super) fn evaluations(&self) -> usize {
        self.evaluations
    }

    /// A new phase after an impact: the step size and the kept derivative restart.
    pub(super) fn reset(&mut self) {
        self.evaluations = 0;
        self.h_next_s = 0.0;
        self.kept.valid = false;
        self.last.valid = false;
    }

    fn proposed_step_s(&self) -> f64 {
        if self.h_next_s > 0.0 {
            self.h_next_s
        } else {
            (self.h_max_s * self.rtol.powf(Dop853Pair::EXPONENT)).min(self.h_max_s)
        }
    }

    /// Stage state `y0 + h Σ a_j k_j` over a tableau row.
    fn combine(
        &self,
        q0: &SVector<f64, N>,
        v0: &SVector<f64, N>,
        h: f64,
        row: &[(usize, f64)],
    ) -> (SVector<f64, N>, SVector<f64, N>) {
        let (mut q, mut v) = (*q0, *v0);
        for &(j, a) in row {
            let ha = h * a;
            for k in 0..N {
                q[k] += ha * self.kq[j][k];
                v[k] += ha * self.kv[j][k];
            }
        }
        (q, v)
    }

    /// One step of size `h` [s] from `s`: the new state and the scaled error norm.
    fn try_step(
        &mut self,
        sys: &mut impl FixedSystem<N>,
        s: &State<N>,
        h: f64,
    ) -> Result<(State<N>, f64), IntegrationError> {
        self.last.valid = false;
        self.kq[0] = s.qd;
        if self.kept.valid && self.kept.at == *s {
            self.kv[0] = self.kept.a;
        } else {
            self.evaluations += 1;
            self.kv[0] = sys.accelerations(s.t_s, &s.q, &s.qd)?;
            self.kept = Kept {
                valid: true,
                at: *s,
                a: self.kv[0],
            };
        }
        for i in 1..STAGES {
            let (q, v) = self.combine(&s.q, &s.qd, h, Dop853Pair::A[i]);
            self.evaluations += 1;
            self.kv[i] = sys.accelerations(s.t_s + Dop853Pair::C[i] * h, &q, &v)?;
            self.kq[i] = v;
        }
        let (mut q1, mut v1) = (s.q, s.qd);
        for &(j, b) in Dop853Pair::B {
            let hb = h * b;
            for k in 0..N {
                q1[k] += hb * self.kq[j][k];
                v1[k] += hb * self.kv[j][k];
            }
        }
        let (mut err5, mut err3) = (0.0, 0.0);
        for i in 0..N {
            for (k, y0, y1) in [(&self.kq, s.q[i], q1[i]), (&self.kv, s.qd[i], v1[i])] {
                let sk = self.atol + self.rtol * y0.abs().max(y1.abs());
                let (e5, e3) = component_error(|j| k[j][i], sk);
                err5 += e5;
                err3 += e3;
            }
        }
        let err = combined_error(h, err5, err3, 2 * N);
        self.last = LastStep {
            valid: true,
            from: *s,
            h_s: h,
            q1,
            v1,
        };
        let next = State {
            t_s: s.t_s + h,
            q: q1,
            qd: v1,
        };
        Ok((next, err))
    }

    /// One accepted step from `from`, at most `h_limit_s` long (the general integrator's
    /// `advance`).
    pub(super) fn advance(
        &mut self,
        sys: &mut impl FixedSystem<N>,
        from: &State<N>,
        h_limit_s: f64,
    ) -> Result<State<N>, IntegrationError> {
        let h = self.proposed_step_s().min(h_limit_s).min(self.h_max_s);
        let limits = StepLimits {
            exponent: Dop853Pair::EXPONENT,
            min_factor: Dop853Pair::MIN_FACTOR,
            max_factor: Dop853Pair::MAX_FACTOR,
            h_max_s: self.h_max_s,
            h_min_s: H_MIN_S,
        };
        let (next, h_next) = adaptive_step(h, limits, from.t_s, |h| self.try_step(sys, from, h))?;
        self.h_next_s = h_next;
        Ok(next)
    }

    /// One step of exactly `h_s` [s], without error control.
    pub(super) fn step_exact(
        &mut self,
        sys: &mut impl FixedSystem<N>,
        from: &State<N>,
        h_s: f64,
    ) -> Result<State<N>, IntegrationError> {
        Ok(self.try_step(sys, from, h_s)?.0)
    }

    /// The dense output of the step `from` → `to` if it is the last one taken (four more
    /// evaluations: the end derivative and the three extra stages).
    pub(super) fn dense_output(
        &mut self,
        sys: &mut impl FixedSystem<N>,
        from: &State<N>,
        to: &State<N>,
    ) -> Option<Result<Dense<N>, IntegrationError>> {
        let last = self.last;
        let same = last.valid && last.from == *from && last.from.t_s + last.h_s == to.t_s;
        same.then(|| self.build_dense(sys, &last))
    }

    fn build_dense(
        &mut self,
        sys: &mut impl FixedSystem<N>,
        last: &LastStep<N>,
    ) -> Result<Dense<N>, IntegrationError> {
        let Some(coefficients) = Dop853Pair::DENSE else {
            return Err(IntegrationError::Dynamics(DynamicsError::NonFinite));
        };
        let (t0, h) = (last.from.t_s, last.h_s);
        let (q0, v0) = (last.from.q, last.from.qd);
        self.evaluations += 1;
        self.kv[STAGES] = sys.accelerations(t0 + h, &last.q1, &last.v1)?;
        self.kq[STAGES] = last.v1;
        for (k, (c, row)) in coefficients
            .extra_c
            .iter()
            .zip(coefficients.extra_a)
            .enumerate()
        {
            let (q, v) = self.combine(&q0, &v0, h, row);
            self.evaluations += 1;
            self.kv[STAGES + 1 + k] = sys.accelerations(t0 + c * h, &q, &v)?;
            self.kq[STAGES + 1 + k] = v;
        }
        let (kq, kv) = (&self.kq, &self.kv);
        let dq = last.q1 - q0;
        let dv = last.v1 - v0;
        let mut fq = [SVector::zeros(); DENSE_TERMS];
        let mut fv = [SVector::zeros(); DENSE_TERMS];
        fq[0] = dq;
        fv[0] = dv;
        fq[1] = kq[0] * h - dq;
        fv[1] = kv[0] * h - dv;
        fq[2] = dq * 2.0 - (kq[0] + kq[STAGES]) * h;
        fv[2] = dv * 2.0 - (kv[0] + kv[STAGES]) * h;
        for (r, row) in coefficients.d.iter().take(DENSE_TERMS - 3).enumerate() {
            for &(j, d) in row.iter() {
                fq[3 + r].axpy(h * d, &kq[j], 1.0);
                fv[3 + r].axpy(h * d, &kv[j], 1.0);
            }
        }
        Ok(Dense {
            t0_s: t0,
            h_s: h,
            q0,
            v0,
            fq,
            fv,
        })
    }
}
