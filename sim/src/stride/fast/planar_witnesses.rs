//! The witness evaluator of the fixed-size engine, on the planar kinematics: the same [`WitnessValues`] as the general
//! loop's `Witnesses::eval` (swing-foot height, its rate and how far ahead, the hip's height
//! margin, how far ahead and its forward velocity), from the planar tree's joints alone.
//!
//! Each followed point is written once, from the tree's frames at `q = 0` (every rotation the
//! identity there), as a fixed base plus one constant arm per joint of its chain, each turned
//! by its joint's link: `p = o₁ + R(θ₁) (o₂ − o₁) + … + R(θₖ) (p₀ − oₖ)`, `oⱼ` the joints'
//! origins and `p₀` the point at `q = 0`, welds between joints lumped into the arms; its
//! velocity `Σ ωⱼ ẑ × R(θⱼ) armⱼ`. An evaluation then takes one `sin_cos` per joint and a few
//! products per arm, instead of every link's frame.

use super::dop853::State;
use crate::engine::planar::{sin_cos, Joints, PlanarTree, MAX_PLANAR_COORDINATES};
use crate::engine::walker::Walker;
use crate::stride::witnesses::{WitnessEvaluator, WitnessValues};
use nalgebra::SVector;

/// A point fixed in a link: a base fixed in the floor frame and an arm per joint of its chain,
/// turned by that joint's link (x, y) [m]; and the joint whose link carries the point (its
/// link's angle; `None`: a link welded to the ground).
#[derive(Clone, Copy, Debug)]
struct Arms {
    base_m: [f64; 2],
    arms: [(usize, [f64; 2]); MAX_PLANAR_COORDINATES],
    len: usize,
    link_joint: Option<usize>,
}

/// The angle's cos and sin and the angular rate of each joint's link.
type JointFrames = [(f64, f64, f64); MAX_PLANAR_COORDINATES];

impl Arms {
    /// Position and velocity (floor frame, x and y) at the joints' frames.
    #[inline]
    fn point(&self, jf: &JointFrames) -> ([f64; 2], [f64; 2]) {
        let (mut p, mut v) = (self.base_m, [0.0; 2]);
        for &(j, [x, y]) in &self.arms[..self.len] {
            let (c, s, w) = jf[j];
            let (rx, ry) = (c * x - s * y, s * x + c * y);
            p[0] += rx;
            p[1] += ry;
            v[0] -= w * ry;
            v[1] += w * rx;
        }
        (p, v)
    }
}

/// The points the witnesses follow, with the walker's fall rule.
#[derive(Clone, Copy, Debug)]
pub(super) struct PlanarWitnesses {
    joints: Joints,
    foot: Arms,
    hip: Arms,
    contact: Arms,
    min_hip_height_m: f64,
}

impl PlanarWitnesses {
    /// The swing foot, hip and stance contact of `walker` on `tree` (`N` its coordinates);
    /// `None` when a point's link is not in the tree or the tree has more joints than
    /// coordinates.
    pub(super) fn new<const N: usize>(walker: &Walker, tree: &PlanarTree) -> Option<Self> {
        let fr = tree
            .links()
            .frames(&SVector::<f64, N>::zeros(), &SVector::zeros());
        let joints = Joints::of(tree.links())?;
        let mut origin = [[0.0; 2]; MAX_PLANAR_COORDINATES];
        for (o, j) in origin.iter_mut().zip(joints.all()) {
            *o = fr.get(j.link + 1)?.origin_m;
        }
        let m = &walker.model;
        let point = |i: usize| -> Option<Arms> {
            let p = m.points.get(i)?;
            let link = p.link.0;
            let o = fr.get(link + 1)?.origin_m;
            let mut at = [o[0] + p.p_link_m.x, o[1] + p.p_link_m.y];
            let link_joint = joints.owner(link);
            let mut arms = Arms {
                base_m: at,
                arms: [(0, [0.0; 2]); MAX_PLANAR_COORDINATES],
                len: 0,
                link_joint,
            };
            // From the point up its chain of joints: arms nearest first, then reversed.
            let mut cur = link_joint;
            while let Some(j) = cur {
                let oj = origin[j];
                *arms.arms.get_mut(arms.len)? = (j, [at[0] - oj[0], at[1] - oj[1]]);
                arms.len += 1;
                at = oj;
                cur = joints.all().get(j)?.parent;
            }
            arms.base_m = at;
            arms.arms[..arms.len].reverse();
            Some(arms)
        };
        Some(Self {
            joints,
            foot: point(walker.heel_strike.swing_foot.0)?,
            hip: point(walker.fall.hip.0)?,
            contact: point(walker.heel_strike.stance_contact.0)?,
            min_hip_height_m: walker.fall.min_hip_height_m,
        })
    }

    /// Every joint's link angle (cos, sin) and rate at `q`, `q̇`, parents first.
    #[inline]
    fn joint_frames<const N: usize>(
        &self,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
    ) -> JointFrames {
        let mut jf = [(1.0, 0.0, 0.0); MAX_PLANAR_COORDINATES];
        for (j, joint) in self.joints.all().iter().enumerate() {
            let (s, co) = sin_cos(joint.sign * q[joint.coordinate]);
            let rate = joint.sign * qd[joint.coordinate];
            jf[j] = match joint.parent {
                Some(p) => {
                    let (pc, ps, pw) = jf[p];
                    (pc * co - ps * s, ps * co + pc * s, pw + rate)
                }
                None => (co, s, rate),
            };
        }
        jf
    }

    /// Every witness at `s`.
    #[inline]
    pub(super) fn eval<const N: usize>(&self, s: &State<N>) -> WitnessValues {
        let jf = self.joint_frames(&s.q, &s.qd);
        let (p_foot, v_foot) = self.foot.point(&jf);
        let (p_hip, v_hip) = self.hip.point(&jf);
        let (p_contact, v_contact) = self.contact.point(&jf);
        // The walking direction: the stance contact link's x axis, level with the floor (as
        // the general `Witnesses::heading`): along ±x, or x when the link stands vertical.
        let c = self.contact.link_joint.map_or(1.0, |j| jf[j].0);
        let heading_x = if c.abs() > 1e-9 { c / c.abs() } else { 1.0 };
        WitnessValues {
            t_s: s.t_s,
            foot_height_m: p_foot[1],
            foot_height_rate_m_s: v_foot[1],
            foot_ahead_m: (p_foot[0] - p_contact[0]) * heading_x,
            foot_ahead_rate_m_s: (v_foot[0] - v_contact[0]) * heading_x,
            hip_height_margin_m: p_hip[1] - self.min_hip_height_m,
            hip_ahead_m: (p_hip[0] - p_contact[0]) * heading_x,
            hip_forward_velocity_m_s: v_hip[0] * heading_x,
        }
    }
}

impl<const N: usize> WitnessEvaluator<State<N>> for PlanarWitnesses {
    #[inline]
    fn eval(&mut self, s: &State<N>) -> WitnessValues {
        PlanarWitnesses::eval(self, s)
    }
}
