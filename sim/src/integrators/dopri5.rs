//! Dormand-Prince 5(4): an adaptive embedded Runge-Kutta pair, the accuracy reference.

use super::{adaptive_step, IntegrationError, Integrator, Sample, SecondOrderSystem, StepLimits};
use nalgebra::DVector;

const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
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

/// A kept end derivative: time, positions, velocities, accelerations.
type Fsal = (f64, DVector<f64>, DVector<f64>, DVector<f64>);

/// Adaptive Dormand-Prince 5(4) with a standard step-size controller.
#[derive(Clone, Debug)]
pub struct Dopri5 {
    rtol: f64,
    atol: f64,
    h_max_s: f64,
    h_next_s: f64,
    evaluations: usize,
    /// Smallest step before giving up [s].
    pub h_min_s: f64,
    /// First same as last: the last stage of a step is the derivative at its end, reused as
    /// the first stage of a step from exactly that sample (same time, same state).
    fsal: Option<Fsal>,
    /// The last trial step's seventh stage.
    last_k7: Option<DVector<f64>>,
}

impl Dopri5 {
    /// Keeps the accepted step's end derivative for the next step.
    fn accept(&mut self, next: &Sample) {
        self.fsal = self
            .last_k7
            .take()
            .map(|k| (next.t_s, next.q.clone(), next.qd.clone(), k));
    }
}

impl Dopri5 {
    /// Tolerances on the local error, and the largest step [s].
    pub fn new(rtol: f64, atol: f64, h_max_s: f64) -> Self {
        Self {
            rtol,
            atol,
            h_max_s,
            h_next_s: 0.0,
            evaluations: 0,
            h_min_s: 1e-14,
            fsal: None,
            last_k7: None,
        }
    }

    /// One Dormand-Prince step of size `h`; returns the new sample and the scaled error norm.
    fn try_step(
        &mut self,
        sys: &mut dyn SecondOrderSystem,
        s: &Sample,
        h: f64,
    ) -> Result<(Sample, f64), IntegrationError> {
        let n = s.q.len();
        let mut kq: Vec<DVector<f64>> = Vec::with_capacity(7);
        let mut kv: Vec<DVector<f64>> = Vec::with_capacity(7);
        for i in 0..7 {
            let (q, v) = if i == 0 {
                (s.q.clone(), s.qd.clone())
            } else {
                let mut q = s.q.clone();
                let mut v = s.qd.clone();
                for j in 0..i {
                    let a = A[i][j];
                    if a != 0.0 {
                        q.axpy(h * a, &kq[j], 1.0);
                        v.axpy(h * a, &kv[j], 1.0);
                    }
                }
                (q, v)
            };
            let cached = match (&self.fsal, i) {
                (Some((t, cq, cv, a)), 0) if *t == s.t_s && *cq == s.q && *cv == s.qd => {
                    Some(a.clone())
                }
                _ => None,
            };
            let acc = match cached {
                Some(a) => a,
                None => {
                    self.evaluations += 1;
                    sys.accelerations(s.t_s + C[i] * h, &q, &v)?
                }
            };
            kq.push(v);
            kv.push(acc);
        }
        // The 7th stage is evaluated at the fifth-order solution (FSAL row).
        let mut q_new = s.q.clone();
        let mut v_new = s.qd.clone();
        for j in 0..6 {
            q_new.axpy(h * A[6][j], &kq[j], 1.0);
            v_new.axpy(h * A[6][j], &kv[j], 1.0);
        }
        let mut err2 = 0.0;
        for i in 0..n {
            let (mut eq, mut ev) = (0.0, 0.0);
            for j in 0..7 {
                eq += E[j] * kq[j][i];
                ev += E[j] * kv[j][i];
            }
            let sq = self.atol + self.rtol * s.q[i].abs().max(q_new[i].abs());
            let sv = self.atol + self.rtol * s.qd[i].abs().max(v_new[i].abs());
            err2 += (h * eq / sq).powi(2) + (h * ev / sv).powi(2);
        }
        let err = (err2 / (2 * n).max(1) as f64).sqrt();
        // The seventh stage was evaluated at the fifth-order solution at t + h: kept for the
        // next step if this one is accepted.
        self.last_k7 = kv.pop();
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

impl Integrator for Dopri5 {
    fn name(&self) -> &'static str {
        "dopri5"
    }
    fn reset(&mut self) {
        self.evaluations = 0;
        self.h_next_s = 0.0;
        self.fsal = None;
    }
    fn system_changed(&mut self) {
        self.fsal = None;
    }
    fn proposed_step_s(&self) -> f64 {
        if self.h_next_s > 0.0 {
            self.h_next_s
        } else {
            // A cautious first step, scaled by the tolerance.
            (self.h_max_s * self.rtol.powf(0.2)).min(self.h_max_s)
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
            exponent: 0.2,
            min_factor: 0.2,
            max_factor: 5.0,
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
