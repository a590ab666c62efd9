//! The points a walker's stride events follow (the swing foot, the hip, the stance contact) on
//! a planar tree, compiled once per walker: each written from the tree's frames at `q = 0`
//! (every rotation the identity there) as a fixed base plus one constant arm per joint of its
//! chain, each turned by its joint's link: `p = o₁ + R(θ₁) (o₂ − o₁) + … + R(θₖ) (p₀ − oₖ)`,
//! `oⱼ` the joints' origins and `p₀` the point at `q = 0`, welds between joints lumped into
//! the arms; its velocity `Σ ωⱼ ẑ × R(θⱼ) armⱼ`. An evaluation then takes one `sin_cos` per
//! joint and a few products per arm, instead of every link's frame. The fixed-size stride's
//! witnesses (`stride/fast/planar_witnesses.rs`) evaluate them.

use super::chain::Joints;
use super::links::MAX_PLANAR_COORDINATES;
use super::trig::sin_cos;
use super::PlanarTree;
use crate::engine::hybrid::heel_strike::HeelStrikeRule;
use crate::engine::model::{Model, PointIndex};
use nalgebra::SVector;

/// A point fixed in a link: a base fixed in the floor frame and an arm per joint of its chain,
/// turned by that joint's link (x, y) [m]; and the joint whose link carries the point (its
/// link's angle; `None`: a link welded to the ground).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Arms {
    base_m: [f64; 2],
    arms: [(usize, [f64; 2]); MAX_PLANAR_COORDINATES],
    len: usize,
    pub(crate) link_joint: Option<usize>,
}

/// The angle's cos and sin and the angular rate of each joint's link.
pub(crate) type JointFrames = [(f64, f64, f64); MAX_PLANAR_COORDINATES];

impl Arms {
    /// Position and velocity (floor frame, x and y) at the joints' frames.
    #[inline]
    pub(crate) fn point(&self, jf: &JointFrames) -> ([f64; 2], [f64; 2]) {
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

/// The points a stride's witnesses follow, on a planar tree.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PlanarPoints {
    joints: Joints,
    /// The swing foot.
    pub(crate) foot: Arms,
    /// The hip point of the fall rule.
    pub(crate) hip: Arms,
    /// The stance contact.
    pub(crate) contact: Arms,
}

impl PlanarPoints {
    /// The swing foot and stance contact of `heel_strike` and the point `hip` of `model` on
    /// `tree` (`N` its coordinates); `None` when a point's link is not in the tree or the tree
    /// has more joints than coordinates.
    pub(crate) fn new<const N: usize>(
        model: &Model,
        heel_strike: &HeelStrikeRule,
        hip: PointIndex,
        tree: &PlanarTree,
    ) -> Option<Self> {
        let fr = tree
            .links()
            .frames(&SVector::<f64, N>::zeros(), &SVector::zeros());
        let joints = Joints::of(tree.links())?;
        let mut origin = [[0.0; 2]; MAX_PLANAR_COORDINATES];
        for (o, j) in origin.iter_mut().zip(joints.all()) {
            *o = fr.get(j.link + 1)?.origin_m;
        }
        let m = model;
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
            foot: point(heel_strike.swing_foot.0)?,
            hip: point(hip.0)?,
            contact: point(heel_strike.stance_contact.0)?,
        })
    }

    /// Every joint's link angle (cos, sin) and rate at `q`, `q̇`, parents first.
    #[inline]
    pub(crate) fn joint_frames<const N: usize>(
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
}
