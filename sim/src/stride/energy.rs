//! Energy accounting over a stride: the ankle actuator's work and the joint dampers'
//! dissipation.

use super::state::StrideState;
use crate::engine::dynamics::Dynamics;
use crate::engine::integrators::Sample;
use crate::engine::model::Model;

/// Running actuator work and damper dissipation over accepted steps.
///
/// The damper's dissipation `∫ c q̇² dt` is a trapezoidal quadrature (smooth integrand). The
/// actuator's work is taken from the energy balance of each interval over which the string
/// stays engaged without an impact, `W = E(end) − E(start) + D(start, end)`: exact up to the
/// state's own integration error, whatever the step sizes. (A quadrature of the actuator power
/// `τ q̇` is not: with a controller the drive's acceleration jumps at every control tick, and a
/// trapezoid over one or two steps per tick lost 1.6 % of the work at DOPRI5 1e-9.)
pub(super) struct Power {
    /// Work of the ankle actuator so far [J].
    pub(super) work_j: f64,
    /// Damper dissipation so far [J].
    pub(super) dissipation_j: f64,
    /// Energy and dissipation so far at the start of the open engaged interval.
    open: Option<(f64, f64)>,
    /// The workspace of the energy's evaluations (made at the first engaged interval).
    dynamics: Option<Dynamics>,
    /// `(coordinate, damping coefficient)` of every damped joint.
    damping: Vec<(usize, f64)>,
}

impl Power {
    pub(super) fn new(model: &Model) -> Self {
        let damping = model
            .links
            .iter()
            .filter_map(|l| l.coordinate.map(|c| (c.0, l.joint_force.damping)))
            .filter(|(_, d)| *d != 0.0)
            .collect();
        Self {
            work_j: 0.0,
            dissipation_j: 0.0,
            open: None,
            dynamics: None,
            damping,
        }
    }

    /// Whether no joint has a damper (the dissipation stays zero).
    pub(super) fn undamped(&self) -> bool {
        self.damping.is_empty()
    }

    /// An engaged interval starts at `s` (after the engagement or a knee-lock impact).
    pub(super) fn open(&mut self, model: &Model, s: &impl StrideState) {
        let dynamics = self.dynamics.get_or_insert_with(|| Dynamics::new(model));
        self.open = Some((energy(dynamics, model, &s.to_sample()), self.dissipation_j));
    }

    /// The open interval, if any, ends at `s` (before an impact or at heel strike).
    pub(super) fn close(&mut self, model: &Model, s: &impl StrideState) {
        if let Some((e0, d0)) = self.open.take() {
            let dynamics = self.dynamics.get_or_insert_with(|| Dynamics::new(model));
            let e1 = energy(dynamics, model, &s.to_sample());
            self.work_j += e1 - e0 + (self.dissipation_j - d0);
        }
    }

    /// The dampers' dissipation over the step `from` → `to`: `∫ c q̇² dt` of each damped
    /// joint with `q̇` the derivative of the cubic Hermite through both ends' values and rates
    /// (exact for that quadratic; the trapezoid on the rates alone, second order, made the
    /// energy balance depend on the step size: issue 31).
    #[inline]
    pub(super) fn accumulate<S: StrideState>(&mut self, from: &S, to: &S) {
        let h = to.t_s() - from.t_s();
        if h <= 0.0 {
            return;
        }
        let step: f64 = self
            .damping
            .iter()
            .map(|&(i, c)| {
                let (v0, v1) = (from.qd(i), to.qd(i));
                let mean = (to.q(i) - from.q(i)) / h;
                c * hermite_rate_square_mean(mean, v0, v1)
            })
            .sum();
        self.dissipation_j += h * step;
    }
}

/// The mean over a step of `q̇²`, `q̇` the derivative of the cubic Hermite of `q` with mean rate
/// `mean` (`Δq / h`) and end rates `v0`, `v1`: `q̇(x) = 6x(1−x)·mean + (1−4x+3x²)·v0 +
/// (3x²−2x)·v1` on `x ∈ [0, 1]`, squared and integrated in closed form.
fn hermite_rate_square_mean(mean: f64, v0: f64, v1: f64) -> f64 {
    1.2 * mean * mean + (2.0 / 15.0) * (v0 * v0 + v1 * v1)
        - 0.2 * mean * (v0 + v1)
        - (1.0 / 15.0) * v0 * v1
}

/// The mechanical energy of `s` [J].
pub(super) fn energy(dynamics: &mut Dynamics, model: &Model, s: &Sample) -> f64 {
    dynamics.assemble(model, &s.q, &s.qd, None);
    dynamics.energy_j(model, &s.q, &s.qd)
}

#[cfg(test)]
mod tests {
    use super::hermite_rate_square_mean;

    /// The closed form against a fine midpoint sum of the Hermite derivative squared, and a
    /// constant rate (mean = v0 = v1 = v gives v²).
    #[test]
    fn the_hermite_rate_square_mean_is_its_integral() {
        for (mean, v0, v1) in [(0.3, -1.2, 2.5), (1.0, 1.0, 1.0), (-0.7, 0.4, -2.0)] {
            let n = 200_000;
            let sum: f64 = (0..n)
                .map(|k| {
                    let x = (k as f64 + 0.5) / n as f64;
                    let v = 6.0 * x * (1.0 - x) * mean
                        + (1.0 - 4.0 * x + 3.0 * x * x) * v0
                        + (3.0 * x * x - 2.0 * x) * v1;
                    v * v
                })
                .sum::<f64>()
                / n as f64;
            let closed = hermite_rate_square_mean(mean, v0, v1);
            assert!(
                (sum - closed).abs() < 1e-9 * (1.0 + sum.abs()),
                "{sum} vs {closed}"
            );
        }
        assert!((hermite_rate_square_mean(2.0, 2.0, 2.0) - 4.0).abs() < 1e-15);
    }
}
