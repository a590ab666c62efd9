//! Contact and clearance figures of a stride, gathered at every accepted sample when asked for
//! ([`super::StrideOptions::contact`]).

use super::phase::Phase;
use super::witnesses::Witnesses;
use crate::engine::dynamics::DynamicsError;
use crate::engine::integrators::{Sample, SecondOrderSystem};
use crate::engine::walker::Walker;
use serde::Serialize;

/// Contact and clearance figures of a stride (with [`super::StrideOptions::contact`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ContactSummary {
    /// Largest |lateral centre of pressure| under the stance foot \[m\].
    pub max_lateral_cop_m: f64,
    /// Smallest normal force on the stance foot \[N\] (negative: the foot would have to pull).
    pub min_normal_force_n: f64,
    /// Smallest swing-ankle height while it passes within 0.1 m of the stance contact \[m\].
    pub mid_swing_clearance_m: Option<f64>,
    /// Lateral centre of pressure at each accepted sample `(t_stride_s, cop_m)`
    /// (stride time \[s\], lateral position \[m\]).
    pub lateral_cop_trace: Vec<(f64, f64)>,
}

impl ContactSummary {
    /// Adds the figures of the accepted sample `s`.
    pub(super) fn add(
        &mut self,
        walker: &Walker,
        phase: &mut Phase,
        wit: &mut Witnesses,
        s: &Sample,
    ) -> Result<(), DynamicsError> {
        let qdd = phase.accelerations(s.t_s, &s.q, &s.qd)?;
        let mut s2 = s.clone();
        phase.snap(&mut s2);
        wit.update(&s2);
        let load = crate::engine::contact::ContactLoad::from_motion(walker.model(), &wit.kin, &qdd);
        let cop = load.lateral_cop_m(&wit.heading());
        if self.lateral_cop_trace.is_empty() {
            self.min_normal_force_n = f64::INFINITY;
        }
        self.lateral_cop_trace.push((s.t_s, cop));
        self.max_lateral_cop_m = self.max_lateral_cop_m.max(cop.abs());
        self.min_normal_force_n = self.min_normal_force_n.min(load.force_n.y);
        let w = wit.eval(&s2);
        if w.foot_ahead_m.abs() < 0.1 {
            let h = w.foot_height_m;
            self.mid_swing_clearance_m = Some(self.mid_swing_clearance_m.map_or(h, |m| m.min(h)));
        }
        Ok(())
    }
}
