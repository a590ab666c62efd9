//! The classical fourth-order Runge-Kutta method on the first-order form `(q, q̇)`.

use super::{IntegrationError, Integrator, Sample, SecondOrderSystem};

/// Classical RK4 with a fixed step.
#[derive(Clone, Debug)]
pub struct Rk4 {
    h_s: f64,
    evaluations: usize,
}

impl Rk4 {
    /// Fixed step `h_s` \[s\].
    pub fn new(h_s: f64) -> Self {
        Self {
            h_s,
            evaluations: 0,
        }
    }
}

impl Integrator for Rk4 {
    fn name(&self) -> &'static str {
        "rk4"
    }
    fn reset(&mut self) {
        self.evaluations = 0;
    }
    fn proposed_step_s(&self) -> f64 {
        self.h_s
    }
    fn advance(
        &mut self,
        sys: &mut dyn SecondOrderSystem,
        from: &Sample,
        h_limit_s: f64,
    ) -> Result<Sample, IntegrationError> {
        self.step_exact(sys, from, self.h_s.min(h_limit_s))
    }
    fn step_exact(
        &mut self,
        sys: &mut dyn SecondOrderSystem,
        s: &Sample,
        h: f64,
    ) -> Result<Sample, IntegrationError> {
        let (t, q, v) = (s.t_s, &s.q, &s.qd);
        let a1 = sys.accelerations(t, q, v)?;
        let q2 = q + v * (0.5 * h);
        let v2 = v + &a1 * (0.5 * h);
        let a2 = sys.accelerations(t + 0.5 * h, &q2, &v2)?;
        let q3 = q + &v2 * (0.5 * h);
        let v3 = v + &a2 * (0.5 * h);
        let a3 = sys.accelerations(t + 0.5 * h, &q3, &v3)?;
        let q4 = q + &v3 * h;
        let v4 = v + &a3 * h;
        let a4 = sys.accelerations(t + h, &q4, &v4)?;
        self.evaluations += 4;
        Ok(Sample {
            t_s: t + h,
            q: q + (v + &v2 * 2.0 + &v3 * 2.0 + &v4) * (h / 6.0),
            qd: v + (a1 + a2 * 2.0 + a3 * 2.0 + a4) * (h / 6.0),
        })
    }
    fn evaluations(&self) -> usize {
        self.evaluations
    }
}
