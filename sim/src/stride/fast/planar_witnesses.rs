//! The witness evaluator of the fixed-size engine, on the planar kinematics: the same
//! [`WitnessValues`] as the general loop's `Witnesses::eval` (swing-foot height, its rate and
//! how far ahead, the hip's height margin, how far ahead and its forward velocity), from the
//! walker's [`PlanarPoints`] (compiled once per walker) and the joints' angles alone.

use super::dop853::State;
use crate::engine::planar::PlanarPoints;
use crate::stride::witnesses::{WitnessEvaluator, WitnessValues};

/// The witnesses on the planar points, with the walker's fall rule.
#[derive(Clone, Copy, Debug)]
pub(super) struct PlanarWitnesses<'w> {
    pub(super) points: &'w PlanarPoints,
    /// Fallen when the hip is lower than this above the floor \[m\].
    pub(super) min_hip_height_m: f64,
    /// The landing floor above the stance foot's \[m\]: the swing foot's height is measured
    /// from it.
    pub(super) floor_step_m: f64,
}

impl PlanarWitnesses<'_> {
    /// Every witness at `s`.
    #[inline]
    pub(super) fn eval<const N: usize>(&self, s: &State<N>) -> WitnessValues {
        let p = self.points;
        let jf = p.joint_frames(&s.q, &s.qd);
        let (p_foot, v_foot) = p.foot.point(&jf);
        let (p_hip, v_hip) = p.hip.point(&jf);
        let (p_contact, v_contact) = p.contact.point(&jf);
        // The walking direction: the stance contact link's x axis, level with the floor (as
        // the general `Witnesses::heading`): along ±x, or x when the link stands vertical.
        let c = p.contact.link_joint.map_or(1.0, |j| jf[j].0);
        let heading_x = if c.abs() > 1e-9 { c / c.abs() } else { 1.0 };
        WitnessValues {
            t_s: s.t_s,
            foot_height_m: p_foot[1] - self.floor_step_m,
            foot_height_rate_m_s: v_foot[1],
            foot_ahead_m: (p_foot[0] - p_contact[0]) * heading_x,
            foot_ahead_rate_m_s: (v_foot[0] - v_contact[0]) * heading_x,
            hip_height_margin_m: p_hip[1] - self.min_hip_height_m,
            hip_ahead_m: (p_hip[0] - p_contact[0]) * heading_x,
            hip_forward_velocity_m_s: v_hip[0] * heading_x,
        }
    }
}

impl<const N: usize> WitnessEvaluator<State<N>> for PlanarWitnesses<'_> {
    #[inline]
    fn eval(&mut self, s: &State<N>) -> WitnessValues {
        PlanarWitnesses::eval(self, s)
    }
}
