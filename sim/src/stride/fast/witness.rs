//! The stride's witnesses on the planar kinematics: the same [`WitnessValues`] as the general
//! loop's `Witnesses::eval` (swing-foot height, its rate and how far ahead, the hip's height
//! margin, how far ahead and its forward velocity), from one pass over the planar tree's link
//! frames instead of the general 3D kinematics.

use super::dop853::State;
use crate::planar::PlanarTree;
use crate::stride::witnesses::WitnessValues;
use crate::walker::Walker;

/// A point fixed in a link: the link's frame slot and the point in the link frame (x, y) [m].
#[derive(Clone, Copy, Debug)]
struct LinkPoint {
    slot: usize,
    p_link_m: [f64; 2],
}

/// The points the witnesses follow, with the walker's fall rule.
#[derive(Clone, Copy, Debug)]
pub(super) struct PlanarWitnesses {
    foot: LinkPoint,
    hip: LinkPoint,
    contact: LinkPoint,
    min_hip_height_m: f64,
}

impl PlanarWitnesses {
    /// The swing foot, hip and stance contact of `walker`.
    pub(super) fn new(walker: &Walker) -> Self {
        let m = &walker.model;
        let point = |i: usize| {
            let p = &m.points[i];
            LinkPoint {
                slot: p.link.0 + 1,
                p_link_m: [p.p_link_m.x, p.p_link_m.y],
            }
        };
        Self {
            foot: point(walker.heel_strike.swing_foot.0),
            hip: point(walker.fall.hip.0),
            contact: point(walker.heel_strike.stance_contact.0),
            min_hip_height_m: walker.fall.min_hip_height_m,
        }
    }

    /// Every witness at `s`.
    pub(super) fn eval<const N: usize>(&self, tree: &PlanarTree, s: &State<N>) -> WitnessValues {
        let fr = tree.frames(&s.q, &s.qd);
        let at = |p: &LinkPoint| fr.get(p.slot).map(|f| f.point(p.p_link_m));
        let nan = ([f64::NAN; 2], [f64::NAN; 2]);
        let (p_foot, v_foot) = at(&self.foot).unwrap_or(nan);
        let (p_hip, v_hip) = at(&self.hip).unwrap_or(nan);
        let (p_contact, _) = at(&self.contact).unwrap_or(nan);
        // The walking direction: the stance contact link's x axis, level with the floor (as
        // the general `Witnesses::heading`): along ±x, or x when the link stands vertical.
        let c = fr.get(self.contact.slot).map_or(1.0, |f| f.cos);
        let heading_x = if c.abs() > 1e-9 { c / c.abs() } else { 1.0 };
        WitnessValues {
            t_s: s.t_s,
            foot_height_m: p_foot[1],
            foot_height_rate_m_s: v_foot[1],
            foot_ahead_m: (p_foot[0] - p_contact[0]) * heading_x,
            hip_height_margin_m: p_hip[1] - self.min_hip_height_m,
            hip_ahead_m: (p_hip[0] - p_contact[0]) * heading_x,
            hip_forward_velocity_m_s: v_hip[0] * heading_x,
        }
    }
}
