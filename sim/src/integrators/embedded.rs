//! The adaptive embedded Runge-Kutta integrator written once for any pair of the
//! Dormand-Prince family: the stages from a (sparse) tableau, the kept first or last stage, the
//! shared step controller ([`adaptive_step`]); a pair ([`EmbeddedPair`]) gives only its
//! coefficients, its controller constants and its error estimate.

use super::dense::{DenseCoefficients, DenseOutput};
use super::{adaptive_step, IntegrationError, Integrator, Sample, SecondOrderSystem, StepLimits};
use nalgebra::DVector;
use std::fmt::Debug;
use std::marker::PhantomData;

/// A kept derivative: time [s], positions, velocities, accelerations.
type Kept = (f64, DVector<f64>, DVector<f64>, DVector<f64>);

/// One trial step's start, size, stages and end, from which its dense output is built.
#[derive(Clone, Debug)]
struct LastStep {
    t0_s: f64,
    h_s: f64,
    q0: DVector<f64>,
    kq: Vec<DVector<f64>>,
    kv: Vec<DVector<f64>>,
    q1: DVector<f64>,
    v1: DVector<f64>,
}

/// Local-error tolerances of an embedded pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerances {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
}

/// One embedded Runge-Kutta pair: its tableau, step-size controller constants and error
/// estimate.
pub trait EmbeddedPair: Clone + Debug {
    /// Name for reports.
    const NAME: &'static str;
    /// Stage nodes `c_i` (stage 0 first, `c_0 = 0`).
    const C: &'static [f64];
    /// The nonzero stage coefficients `(j, a_ij)` of each stage `i` (row 0 empty).
    const A: &'static [&'static [(usize, f64)]];
    /// The nonzero weights `(j, b_j)` of the propagated solution.
    const B: &'static [(usize, f64)];
    /// Error exponent of the controller: 1/(order + 1) of the lower-order estimate.
    const EXPONENT: f64;
    /// Smallest step-size factor.
    const MIN_FACTOR: f64;
    /// Largest step-size factor.
    const MAX_FACTOR: f64;
    /// First same as last: the last stage is the derivative at the step's end (kept from an
    /// accepted step for the next one). Otherwise the first stage is kept once evaluated.
    const FSAL: bool;
    /// The pair's continuous extension, if it has one.
    const DENSE: Option<DenseCoefficients> = None;

    /// The scaled error norm of a step of size `h` [s] from `s` to `(q_new, v_new)` with
    /// stage derivatives `kq` (of the positions) and `kv` (of the velocities).
    #[allow(clippy::too_many_arguments)]
    fn error_norm(
        tol: Tolerances,
        h: f64,
        s: &Sample,
        q_new: &DVector<f64>,
        v_new: &DVector<f64>,
        kq: &[DVector<f64>],
        kv: &[DVector<f64>],
    ) -> f64;
}

/// An adaptive embedded Runge-Kutta integrator over the pair `P`.
#[derive(Clone, Debug)]
pub struct EmbeddedRk<P: EmbeddedPair> {
    tol: Tolerances,
    h_max_s: f64,
    h_next_s: f64,
    evaluations: usize,
    /// Smallest step before giving up [s].
    pub h_min_s: f64,
    /// A kept derivative reused as the first stage of a step from exactly that sample (same
    /// time, same state): the end of the last accepted step (FSAL pairs) or the last evaluated
    /// first stage (so a retried step after a rejection does not evaluate it again).
    kept: Option<Kept>,
    /// The last trial step's final stage (FSAL pairs).
    last_stage: Option<DVector<f64>>,
    /// The last trial step, kept for its dense output (pairs with a continuous extension).
    last_step: Option<LastStep>,
    pair: PhantomData<P>,
}

impl<P: EmbeddedPair> EmbeddedRk<P> {
    /// Tolerances on the local error, and the largest step [s].
    pub fn new(rtol: f64, atol: f64, h_max_s: f64) -> Self {
        Self {
            tol: Tolerances { rtol, atol },
            h_max_s,
            h_next_s: 0.0,
            evaluations: 0,
            h_min_s: 1e-14,
            kept: None,
            last_stage: None,
            last_step: None,
            pair: PhantomData,
        }
    }

    /// The derivative at the step's start, from the kept one when it is at `s`.
    fn first_stage(
        &mut self,
        sys: &mut dyn SecondOrderSystem,
        s: &Sample,
    ) -> Result<DVector<f64>, IntegrationError> {
        if let Some((t, q, v, a)) = &self.kept {
            if *t == s.t_s && *q == s.q && *v == s.qd {
                return Ok(a.clone());
            }
        }
        self.evaluations += 1;
        let a = sys.accelerations(s.t_s, &s.q, &s.qd)?;
        if !P::FSAL {
            self.kept = Some((s.t_s, s.q.clone(), s.qd.clone(), a.clone()));
        }
        Ok(a)
    }

    /// The dense output of the kept last step: the derivative at its end (kept for a next
    /// step from there), the extra stages, and Hairer's coefficients
    /// `F0 = Δy, F1 = h f0 − Δy, F2 = 2Δy − h (f0 + f1), F3… = h D K`.
    fn build_dense(
        &mut self,
        sys: &mut dyn SecondOrderSystem,
        last: &LastStep,
        coefficients: &DenseCoefficients,
    ) -> Result<DenseOutput, IntegrationError> {
        let (t0, h) = (last.t0_s, last.h_s);
        let t1 = t0 + h;
        let end = Sample {
            t_s: t1,
            q: last.q1.clone(),
            qd: last.v1.clone(),
        };
        self.evaluations += 1;
        let a_end = sys.accelerations(end.t_s, &end.q, &end.qd)?;
        let (mut kq, mut kv) = (last.kq.clone(), last.kv.clone());
        kq.truncate(P::C.len());
        kv.truncate(P::C.len());
        kq.push(end.qd.clone());
        kv.push(a_end);
        for (c, row) in coefficients.extra_c.iter().zip(coefficients.extra_a) {
            let mut q = last.q0.clone();
            let mut v = last.kq[0].clone();
            for &(j, a) in row.iter() {
                q.axpy(h * a, &kq[j], 1.0);
                v.axpy(h * a, &kv[j], 1.0);
            }
            self.evaluations += 1;
            let acc = sys.accelerations(t0 + c * h, &q, &v)?;
            kq.push(v);
            kv.push(acc);
        }
        let s = P::C.len();
        let dq = &last.q1 - &last.q0;
        let dv = &last.v1 - &last.kq[0];
        let mut f = Vec::with_capacity(3 + coefficients.d.len());
        f.push((dq.clone(), dv.clone()));
        f.push((&kq[0] * h - &dq, &kv[0] * h - &dv));
        f.push((
            &dq * 2.0 - (&kq[0] + &kq[s]) * h,
            &dv * 2.0 - (&kv[0] + &kv[s]) * h,
        ));
        for row in coefficients.d {
            let mut fq = DVector::zeros(dq.len());
            let mut fv = DVector::zeros(dq.len());
            for &(j, d) in row.iter() {
                fq.axpy(h * d, &kq[j], 1.0);
                fv.axpy(h * d, &kv[j], 1.0);
            }
            f.push((fq, fv));
        }
        Ok(DenseOutput::new(
            t0,
            h,
            last.q0.clone(),
            last.kq[0].clone(),
            f,
        ))
    }

    /// Keeps an accepted step's end derivative for the next step (FSAL pairs).
    fn accept(&mut self, next: &Sample) {
        if P::FSAL {
            self.kept = self
                .last_stage
                .take()
                .map(|k| (next.t_s, next.q.clone(), next.qd.clone(), k));
        }
    }

    /// One step of size `h` [s]; returns the new sample and the scaled error norm.
    fn try_step(
        &mut self,
        sys: &mut dyn SecondOrderSystem,
        s: &Sample,
        h: f64,
    ) -> Result<(Sample, f64), IntegrationError> {
        let stages = P::C.len();
        let mut kq: Vec<DVector<f64>> = Vec::with_capacity(stages);
        let mut kv: Vec<DVector<f64>> = Vec::with_capacity(stages);
        kq.push(s.qd.clone());
        kv.push(self.first_stage(sys, s)?);
        for (i, row) in P::A.iter().enumerate().skip(1) {
            let mut q = s.q.clone();
            let mut v = s.qd.clone();
            for &(j, a) in row.iter() {
                q.axpy(h * a, &kq[j], 1.0);
                v.axpy(h * a, &kv[j], 1.0);
            }
            self.evaluations += 1;
            let acc = sys.accelerations(s.t_s + P::C[i] * h, &q, &v)?;
            kq.push(v);
            kv.push(acc);
        }
        let mut q_new = s.q.clone();
        let mut v_new = s.qd.clone();
        for &(j, b) in P::B {
            q_new.axpy(h * b, &kq[j], 1.0);
            v_new.axpy(h * b, &kv[j], 1.0);
        }
        let err = P::error_norm(self.tol, h, s, &q_new, &v_new, &kq, &kv);
        if P::FSAL {
            // The last stage was evaluated at the propagated solution at t + h: kept for the
            // next step if this one is accepted.
            self.last_stage = kv.pop();
        }
        let next = Sample {
            t_s: s.t_s + h,
            q: q_new,
            qd: v_new,
        };
        if P::DENSE.is_some() {
            self.last_step = Some(LastStep {
                t0_s: s.t_s,
                h_s: h,
                q0: s.q.clone(),
                kq,
                kv,
                q1: next.q.clone(),
                v1: next.qd.clone(),
            });
        }
        Ok((next, err))
    }
}

impl<P: EmbeddedPair> Integrator for EmbeddedRk<P> {
    fn name(&self) -> &'static str {
        P::NAME
    }
    fn reset(&mut self) {
        self.evaluations = 0;
        self.h_next_s = 0.0;
        self.kept = None;
        self.last_step = None;
    }
    fn system_changed(&mut self) {
        self.kept = None;
        self.last_step = None;
    }
    fn dense_output(
        &mut self,
        sys: &mut dyn SecondOrderSystem,
        from: &Sample,
        to: &Sample,
    ) -> Option<Result<DenseOutput, IntegrationError>> {
        let coefficients = P::DENSE?;
        let last = self.last_step.take()?;
        let same = last.t0_s == from.t_s
            && last.t0_s + last.h_s == to.t_s
            && last.q0 == from.q
            && last.kq[0] == from.qd;
        let dense = same.then(|| self.build_dense(sys, &last, &coefficients));
        self.last_step = Some(last);
        dense
    }
    fn proposed_step_s(&self) -> f64 {
        if self.h_next_s > 0.0 {
            self.h_next_s
        } else {
            // A cautious first step, scaled by the tolerance.
            (self.h_max_s * self.tol.rtol.powf(P::EXPONENT)).min(self.h_max_s)
        }
    }
    fn advance(
        &mut self,
        sys: &mut dyn SecondOrderSystem,
        from: &Sample,
        h_limit_s: f64,
    ) -> Result<Sample, IntegrationError> {
        let h = self.proposed_step_s().min(h_limit_s).min(self.h_max_s);
        let limits = StepLimits {
            exponent: P::EXPONENT,
            min_factor: P::MIN_FACTOR,
            max_factor: P::MAX_FACTOR,
            h_max_s: self.h_max_s,
            h_min_s: self.h_min_s,
        };
        let (next, h_next) = adaptive_step(h, limits, from.t_s, |h| self.try_step(sys, from, h))?;
        self.h_next_s = h_next;
        self.accept(&next);
        Ok(next)
    }
    fn step_exact(
        &mut self,
        sys: &mut dyn SecondOrderSystem,
        from: &Sample,
        h_s: f64,
    ) -> Result<Sample, IntegrationError> {
        let next = self.try_step(sys, from, h_s)?.0;
        self.accept(&next);
        Ok(next)
    }
    fn evaluations(&self) -> usize {
        self.evaluations
    }
}
