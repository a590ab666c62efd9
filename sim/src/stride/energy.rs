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

    /// The dampers' dissipation over the step `from` → `to`.
    #[inline]
    pub(super) fn accumulate<S: StrideState>(&mut self, from: &S, to: &S) {
        let h = to.t_s() - from.t_s();
        let damping = &self.damping;
        let diss = |s: &S| {
            damping
                .iter()
                .map(|&(i, c)| c * s.qd(i) * s.qd(i))
                .sum::<f64>()
        };
        self.dissipation_j += 0.5 * h * (diss(from) + diss(to));
    }
}

/// The mechanical energy of `s` [J].
pub(super) fn energy(dynamics: &mut Dynamics, model: &Model, s: &Sample) -> f64 {
    dynamics.assemble(model, &s.q, &s.qd, None);
    dynamics.energy_j(model, &s.q, &s.qd)
}
