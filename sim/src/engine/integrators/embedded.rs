//! The adaptive embedded Runge-Kutta integrator written once for any pair of the
//! Dormand-Prince family: the stages from a (sparse) tableau, the kept first or last stage, the
//! shared step controller ([`adaptive_step`]); a pair ([`EmbeddedPair`]) gives only its
//! coefficients, its controller constants and its error estimate.

use super::dense::{DenseCoefficients, DenseOutput};
use super::{
    adaptive_step, IntegrationError, Integrator, Sample, SecondOrderSystem, StepLimits,
    SystemChange,
};
use nalgebra::DVector;
use std::fmt::Debug;
use std::marker::PhantomData;

/// A kept derivative: at time `t_s` [s] and state `q`, `v`, the accelerations `a` (buffers
/// reused from step to step; `valid` says whether they hold one).
#[derive(Clone, Debug, Default)]
struct Kept {
    valid: bool,
    /// Only the driven coordinate's prescribed acceleration changed since `a` was evaluated
    /// ([`SystemChange::DriveAcceleration`]): `a` is solved again, not copied.
    stale: bool,
    t_s: f64,
    q: DVector<f64>,
    v: DVector<f64>,
    a: DVector<f64>,
}

impl Kept {
    fn matches(&self, s: &Sample) -> bool {
        self.valid && self.t_s == s.t_s && self.q == s.q && self.v == s.qd
    }

    fn set(&mut self, t_s: f64, q: &DVector<f64>, v: &DVector<f64>, a: &DVector<f64>) {
        self.valid = true;
        self.stale = false;
        self.t_s = t_s;
        copy_into(&mut self.q, q);
        copy_into(&mut self.v, v);
        copy_into(&mut self.a, a);
    }
}

/// `dst = src`, reusing `dst`'s storage when the lengths agree.
fn copy_into(dst: &mut DVector<f64>, src: &DVector<f64>) {
    if dst.len() == src.len() {
        dst.copy_from(src);
    } else {
        *dst = src.clone();
    }
}

/// The last trial step's start and size, its start and end states (buffers), for its dense
/// output: its stages are still in the integrator's stage buffers.
#[derive(Clone, Debug, Default)]
struct LastStep {
    valid: bool,
    t0_s: f64,
    h_s: f64,
    q0: DVector<f64>,
    v0: DVector<f64>,
    q1: DVector<f64>,
    v1: DVector<f64>,
}

/// The stage buffers of one step, allocated once per state size: `kq[i]`, `kv[i]` the
/// derivatives of positions and velocities at stage `i` (the step's stages, then the end
/// derivative and the extra stages of the continuous extension), and the stage state.
#[derive(Clone, Debug, Default)]
struct Stages {
    kq: Vec<DVector<f64>>,
    kv: Vec<DVector<f64>>,
    q: DVector<f64>,
    v: DVector<f64>,
}

impl Stages {
    fn fit(&mut self, count: usize, n: usize) {
        if self.kq.len() != count || self.q.len() != n {
            self.kq = vec![DVector::zeros(n); count];
            self.kv = vec![DVector::zeros(n); count];
            self.q = DVector::zeros(n);
            self.v = DVector::zeros(n);
        }
    }

    /// Stage state `q = q0 + h Σ a_j kq_j`, `v = v0 + h Σ a_j kv_j`.
    fn combine(&mut self, q0: &DVector<f64>, v0: &DVector<f64>, h: f64, row: &[(usize, f64)]) {
        let (q, v) = (self.q.as_mut_slice(), self.v.as_mut_slice());
        q.copy_from_slice(q0.as_slice());
        v.copy_from_slice(v0.as_slice());
        let n = q.len().min(v.len());
        for &(j, a) in row {
            let ha = h * a;
            let (kq, kv) = (&self.kq[j].as_slice()[..n], &self.kv[j].as_slice()[..n]);
            // One pass over both halves (small n: the loop's overhead counts).
            for k in 0..n {
                q[k] += ha * kq[k];
                v[k] += ha * kv[k];
            }
        }
    }

    /// Evaluates stage `i` at time `t_s` from the stage state.
    fn evaluate(
        &mut self,
        sys: &mut dyn SecondOrderSystem,
        i: usize,
        t_s: f64,
    ) -> Result<(), IntegrationError> {
        sys.accelerations_into(t_s, &self.q, &self.v, &mut self.kv[i])?;
        self.kq[i].copy_from(&self.v);
        Ok(())
    }
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
    /// The pair's continuous extension, if it has one (the event locator's dense output).
    const DENSE: Option<DenseCoefficients> = None;
    /// The continuous extension [`Integrator::interpolant`] samples with: [`Self::DENSE`]
    /// unless the pair gives one for sampling only (DOPRI5, whose events keep their exact-step
    /// refinement).
    const INTERPOLANT: Option<DenseCoefficients> = Self::DENSE;

    /// The scaled error norm of a step of size `h` \[s\] from `s` to `(q_new, v_new)` with
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
    /// Smallest step before giving up \[s\].
    pub h_min_s: f64,
    /// A kept derivative reused as the first stage of a step from exactly that sample (same
    /// time, same state): the end of the last accepted step (FSAL pairs) or the last evaluated
    /// first stage (so a retried step after a rejection does not evaluate it again).
    kept: Kept,
    /// The last trial step's final stage is valid for `kept` (FSAL pairs).
    last_stage: bool,
    /// The system's epoch of the last trial step's final stage (FSAL pairs).
    last_stage_epoch: u64,
    /// The system's epoch of the accepted step's final stage, kept in `kept` (FSAL pairs):
    /// [`Integrator::end_stage_epoch`].
    end_stage_epoch: Option<u64>,
    /// The last trial step, kept for its dense output (pairs with a continuous extension).
    last_step: LastStep,
    /// Stage buffers, reused from step to step.
    stages: Stages,
    pair: PhantomData<P>,
}

impl<P: EmbeddedPair> EmbeddedRk<P> {
    /// Tolerances on the local error, and the largest step \[s\].
    pub fn new(rtol: f64, atol: f64, h_max_s: f64) -> Self {
        Self {
            tol: Tolerances { rtol, atol },
            h_max_s,
            h_next_s: 0.0,
            evaluations: 0,
            h_min_s: 1e-14,
            kept: Kept::default(),
            last_stage: false,
            last_stage_epoch: 0,
            end_stage_epoch: None,
            last_step: LastStep::default(),
            stages: Stages::default(),
            pair: PhantomData,
        }
    }

    /// Number of stage buffers: the step's stages, and with a continuous extension the end
    /// derivative and its extra stages.
    fn stage_count() -> usize {
        let extension = |d: Option<DenseCoefficients>| d.map_or(0, |d| 1 + d.extra_c.len());
        P::C.len() + extension(P::DENSE).max(extension(P::INTERPOLANT))
    }

    /// The derivative at the step's start into stage 0, from the kept one when it is at `s`.
    fn first_stage(
        &mut self,
        sys: &mut dyn SecondOrderSystem,
        s: &Sample,
    ) -> Result<(), IntegrationError> {
        self.stages.kq[0].copy_from(&s.qd);
        if self.kept.matches(s) {
            if !self.kept.stale {
                self.stages.kv[0].copy_from(&self.kept.a);
                return Ok(());
            }
            // A tick changed only the drive's acceleration at the end of the last step: the
            // derivative there solved again on the system's assembly of that step's last stage.
            self.kept.valid = false;
            if let Some(epoch) = self.end_stage_epoch.take() {
                self.evaluations += 1;
                if sys.accelerations_again_into(epoch, s.t_s, &mut self.stages.kv[0])? {
                    return Ok(());
                }
                self.evaluations -= 1;
            }
        }
        self.end_stage_epoch = None;
        self.evaluations += 1;
        sys.accelerations_into(s.t_s, &s.q, &s.qd, &mut self.stages.kv[0])?;
        if !P::FSAL {
            self.kept.set(s.t_s, &s.q, &s.qd, &self.stages.kv[0]);
        }
        Ok(())
    }

    /// The dense output of the last step (its stages still in the buffers): the derivative at
    /// its end, the extra stages, and Hairer's coefficients
    /// `F0 = Δy, F1 = h f0 − Δy, F2 = 2Δy − h (f0 + f1), F3… = h D K`.
    fn build_dense(
        &mut self,
        sys: &mut dyn SecondOrderSystem,
        coefficients: &DenseCoefficients,
    ) -> Result<DenseOutput, IntegrationError> {
        let last = &self.last_step;
        let (t0, h) = (last.t0_s, last.h_s);
        let s = P::C.len();
        let st = &mut self.stages;
        if P::FSAL {
            // The last stage was evaluated at the step's end: it is the end derivative.
            let (steps, extension) = st.kq.split_at_mut(s);
            extension[0].copy_from(&steps[s - 1]);
            let (steps, extension) = st.kv.split_at_mut(s);
            extension[0].copy_from(&steps[s - 1]);
        } else {
            st.q.copy_from(&last.q1);
            st.v.copy_from(&last.v1);
            self.evaluations += 1;
            st.evaluate(sys, s, t0 + h)?;
        }
        for (k, (c, row)) in coefficients
            .extra_c
            .iter()
            .zip(coefficients.extra_a)
            .enumerate()
        {
            st.combine(&last.q0, &last.v0, h, row);
            self.evaluations += 1;
            st.evaluate(sys, s + 1 + k, t0 + c * h)?;
        }
        let (kq, kv) = (&st.kq, &st.kv);
        let dq = &last.q1 - &last.q0;
        let dv = &last.v1 - &last.v0;
        let mut f = Vec::with_capacity(3 + coefficients.d.len());
        f.push((&kq[0] * h - &dq, &kv[0] * h - &dv));
        f.push((
            &dq * 2.0 - (&kq[0] + &kq[s]) * h,
            &dv * 2.0 - (&kv[0] + &kv[s]) * h,
        ));
        f.insert(0, (dq, dv));
        for row in coefficients.d {
            let n = last.q0.len();
            let mut fq = DVector::zeros(n);
            let mut fv = DVector::zeros(n);
            for &(j, d) in row.iter() {
                fq.axpy(h * d, &kq[j], 1.0);
                fv.axpy(h * d, &kv[j], 1.0);
            }
            f.push((fq, fv));
        }
        Ok(DenseOutput::new(t0, h, last.q0.clone(), last.v0.clone(), f))
    }

    /// The last trial step went from `from` to `to` (its stages are still in the buffers).
    fn last_step_is(&self, from: &Sample, to: &Sample) -> bool {
        let last = &self.last_step;
        last.valid
            && last.t0_s == from.t_s
            && last.t0_s + last.h_s == to.t_s
            && last.q0 == from.q
            && last.v0 == from.qd
    }

    /// Keeps an accepted step's end derivative for the next step (FSAL pairs).
    fn accept(&mut self, next: &Sample) {
        if P::FSAL {
            if self.last_stage {
                let last = P::C.len() - 1;
                self.kept
                    .set(next.t_s, &next.q, &next.qd, &self.stages.kv[last]);
                self.end_stage_epoch = Some(self.last_stage_epoch);
            } else {
                self.kept.valid = false;
                self.end_stage_epoch = None;
            }
            self.last_stage = false;
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
        self.stages.fit(Self::stage_count(), s.q.len());
        self.last_step.valid = false;
        self.last_stage = false;
        self.first_stage(sys, s)?;
        for (i, row) in P::A.iter().enumerate().skip(1) {
            self.stages.combine(&s.q, &s.qd, h, row);
            self.evaluations += 1;
            self.stages.evaluate(sys, i, s.t_s + P::C[i] * h)?;
        }
        self.last_stage_epoch = sys.evaluation_epoch();
        let mut q_new = s.q.clone();
        let mut v_new = s.qd.clone();
        let (kq, kv) = (&self.stages.kq, &self.stages.kv);
        for &(j, b) in P::B {
            q_new.axpy(h * b, &kq[j], 1.0);
            v_new.axpy(h * b, &kv[j], 1.0);
        }
        let err = P::error_norm(self.tol, h, s, &q_new, &v_new, &kq[..stages], &kv[..stages]);
        // FSAL: the last stage was evaluated at the propagated solution at t + h, kept for
        // the next step if this one is accepted.
        self.last_stage = P::FSAL;
        if P::DENSE.is_some() || P::INTERPOLANT.is_some() {
            let l = &mut self.last_step;
            l.valid = true;
            l.t0_s = s.t_s;
            l.h_s = h;
            copy_into(&mut l.q0, &s.q);
            copy_into(&mut l.v0, &s.qd);
            copy_into(&mut l.q1, &q_new);
            copy_into(&mut l.v1, &v_new);
        }
        Ok((
            Sample {
                t_s: s.t_s + h,
                q: q_new,
                qd: v_new,
            },
            err,
        ))
    }
}

impl<P: EmbeddedPair> Integrator for EmbeddedRk<P> {
    fn name(&self) -> &'static str {
        P::NAME
    }
    fn reset(&mut self) {
        self.evaluations = 0;
        self.h_next_s = 0.0;
        self.kept.valid = false;
        self.end_stage_epoch = None;
        self.last_step.valid = false;
    }
    fn system_changed(&mut self, change: SystemChange) {
        match change {
            SystemChange::DriveAcceleration if self.end_stage_epoch.is_some() => {
                self.kept.stale = true;
            }
            _ => {
                self.kept.valid = false;
                self.end_stage_epoch = None;
            }
        }
        self.last_step.valid = false;
    }
    fn end_stage_epoch(&self) -> Option<u64> {
        self.end_stage_epoch
    }
    fn dense_output(
        &mut self,
        sys: &mut dyn SecondOrderSystem,
        from: &Sample,
        to: &Sample,
    ) -> Option<Result<DenseOutput, IntegrationError>> {
        let coefficients = P::DENSE?;
        self.last_step_is(from, to)
            .then(|| self.build_dense(sys, &coefficients))
    }
    fn interpolates(&self) -> bool {
        P::INTERPOLANT.is_some()
    }
    fn interpolant(
        &mut self,
        sys: &mut dyn SecondOrderSystem,
        from: &Sample,
        to: &Sample,
    ) -> Option<Result<DenseOutput, IntegrationError>> {
        let coefficients = P::INTERPOLANT?;
        self.last_step_is(from, to)
            .then(|| self.build_dense(sys, &coefficients))
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
