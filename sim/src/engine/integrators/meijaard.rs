//! Meijaard's explicit one-evaluation scheme for second-order systems, eq. (11), with the
//! stability limit of eq. (12).

use super::{IntegrationError, Integrator, Sample, SecondOrderSystem};

/// Meijaard's scheme: `k = f(q̇ₙ, qₙ + h/2 q̇ₙ, tₙ + h/2)`, `qₙ₊₁ = qₙ + h q̇ₙ + h²/2 k`,
/// `q̇ₙ₊₁ = q̇ₙ + h k`. One evaluation of the equations of motion per step.
#[derive(Clone, Debug)]
pub struct Meijaard {
    h_s: f64,
    check_every: usize,
    steps: usize,
    evaluations: usize,
}

impl Meijaard {
    /// Fixed step `h_s` \[s\]; eq. (12) is checked every `check_every` steps (0: never).
    pub fn new(h_s: f64, check_every: usize) -> Self {
        Self {
            h_s,
            check_every,
            steps: 0,
            evaluations: 0,
        }
    }
}

impl Integrator for Meijaard {
    fn name(&self) -> &'static str {
        "meijaard"
    }
    fn reset(&mut self) {
        self.steps = 0;
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
        if self.check_every > 0 && self.steps.is_multiple_of(self.check_every) {
            if let Some(lim) = sys.stability_limit(from.t_s, &from.q, &from.qd) {
                if self.h_s > lim.h_max_s() {
                    return Err(IntegrationError::StepTooLarge {
                        h_s: self.h_s,
                        h_max_s: lim.h_max_s(),
                        lambda_max_rad_s: lim.lambda_max_rad_s,
                        beta: lim.beta,
                    });
                }
            }
        }
        self.steps += 1;
        self.step_exact(sys, from, self.h_s.min(h_limit_s))
    }
    fn step_exact(
        &mut self,
        sys: &mut dyn SecondOrderSystem,
        from: &Sample,
        h: f64,
    ) -> Result<Sample, IntegrationError> {
        let q_mid = &from.q + &from.qd * (0.5 * h);
        let k = sys.accelerations(from.t_s + 0.5 * h, &q_mid, &from.qd)?;
        self.evaluations += 1;
        Ok(Sample {
            t_s: from.t_s + h,
            q: &from.q + &from.qd * h + &k * (0.5 * h * h),
            qd: &from.qd + &k * h,
        })
    }
    fn evaluations(&self) -> usize {
        self.evaluations
    }
}
