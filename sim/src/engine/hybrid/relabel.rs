//! The relabelling's geometry, in any scalar: the old links' states relative to the new
//! contact, their reflection about the sagittal plane, the poses and velocities the new
//! labelling must match ([`RelabelTargets`]), and the matched rows' residual and Jacobian.
//!
//! [`Relabel`] is the rule a scene states (which new link takes the pose of which old one).
//! The `f64` relabelling ([`crate::engine::relabel::Relabel::solve`]) iterates Gauss-Newton on these
//! rows; the variational Jacobian differentiates the converged solution through them.

use super::konst;
use crate::engine::kinematics::{Kinematics, KinematicsOf};
use crate::engine::math::{orientation_error, sagittal_reflection};
use crate::engine::model::{CoordIndex, LinkIndex, Model, PointIndex};
use nalgebra::{DMatrix, DVector, Matrix3, RealField, Scalar, Vector3};

/// Which new link takes the pose of which old link, and the symmetry used.
#[derive(Clone, Debug, PartialEq)]
pub struct Relabel {
    /// `(new, old)` link pairs whose orientations must agree.
    pub pairs: Vec<(LinkIndex, LinkIndex)>,
    /// `(new, old)` marker-point pairs whose positions must agree (link frames of swapped
    /// links have different origins, so positions are matched at points).
    pub point_pairs: Vec<(PointIndex, PointIndex)>,
    /// Reflect about the sagittal plane (3D walkers).
    pub mirror: bool,
    /// Root coordinates that are cyclic (the heading on level ground): reported and then set
    /// to zero, and left out of the stride map. A coordinate is cyclic when the dynamics and
    /// the floor are invariant to it; the scene builder decides which are
    /// ([`crate::scene::Scene::setup`]).
    pub cyclic: Vec<CoordIndex>,
    /// Coordinates the scene declares cyclic whose symmetry the floor breaks: the heading
    /// about the floor's normal on a slope (turning changes which way is downhill). They are
    /// ordinary coordinates here, states of the stride map like any other (empty on level
    /// ground).
    pub symmetry_broken: Vec<CoordIndex>,
    /// Coordinates held at zero (locked at the start of a stride), not solved for.
    pub fixed: Vec<CoordIndex>,
    /// Gauss-Newton tolerance on the pose residual [m or rad].
    pub tolerance: f64,
    /// Gauss-Newton iteration budget.
    pub max_iterations: usize,
}

/// Poses and velocities of every link of a model, in the floor frame.
#[derive(Clone, Debug)]
pub struct LinkStatesOf<T: Scalar> {
    /// Rotations link frame → floor frame.
    pub r: Vec<Matrix3<T>>,
    /// Origins \[m\].
    pub p: Vec<Vector3<T>>,
    /// Angular velocities [rad/s].
    pub w: Vec<Vector3<T>>,
    /// Origin velocities [m/s].
    pub v: Vec<Vector3<T>>,
}

/// The sagittal reflection (z → −z) in the scalar `T`.
fn reflection<T: RealField + Copy>() -> Matrix3<T> {
    sagittal_reflection().map(konst)
}

impl<T: RealField + Copy> LinkStatesOf<T> {
    /// Takes the link states from a kinematics workspace, dropping the first `skip` links
    /// (the released-root links of an impact model), and moving the origin to `origin` \[m\].
    pub fn from_kinematics(kin: &KinematicsOf<T>, skip: usize, origin: &Vector3<T>) -> Self {
        Self {
            r: kin.r_floor_link[skip..].to_vec(),
            p: kin.p_floor_link_m[skip..]
                .iter()
                .map(|p| p - origin)
                .collect(),
            w: kin.omega_floor_rad_s[skip..].to_vec(),
            v: kin.v_floor_link_m_s[skip..].to_vec(),
        }
    }

    /// Reflects about the sagittal plane: `R → S R S`, `p → S p`, `ω → −S ω`, `v → S v`.
    pub fn mirrored(&self) -> Self {
        let s = reflection::<T>();
        Self {
            r: self.r.iter().map(|r| s * r * s).collect(),
            p: self.p.iter().map(|p| s * p).collect(),
            w: self.w.iter().map(|w| -(s * w)).collect(),
            v: self.v.iter().map(|v| s * v).collect(),
        }
    }
}

/// What the new labelling must match, taken from the old link states (mirrored if the
/// relabelling mirrors): one entry per link pair, then per point pair.
#[derive(Clone, Debug)]
pub struct RelabelTargets<T: Scalar> {
    /// Orientation of each pair's old link.
    pub r: Vec<Matrix3<T>>,
    /// Angular velocity of each pair's old link [rad/s].
    pub w: Vec<Vector3<T>>,
    /// Position of each point pair's old point \[m\].
    pub points_m: Vec<Vector3<T>>,
    /// Velocity of each point pair's old point [m/s].
    pub point_velocities_m_s: Vec<Vector3<T>>,
}

impl<T: RealField + Copy> RelabelTargets<T> {
    /// The targets of `relabel` from the old link states `old` of `model` (translated to the
    /// new contact, not yet mirrored: the mirroring is done here).
    pub fn new(relabel: &Relabel, model: &Model, old: &LinkStatesOf<T>) -> Self {
        let s = reflection::<T>();
        // Old point positions and velocities, from the old link states before any mirroring
        // (a point's offset in its link frame is not mirrored by reflecting the frame).
        let (points_m, point_velocities_m_s) = relabel
            .point_pairs
            .iter()
            .map(|&(_, op)| {
                let pt = &model.points[op.0];
                let l = pt.link.0;
                let p = old.p[l] + old.r[l] * pt.p_link_m.map(konst::<T>);
                let v = old.v[l] + old.w[l].cross(&(p - old.p[l]));
                if relabel.mirror {
                    (s * p, s * v)
                } else {
                    (p, v)
                }
            })
            .unzip();
        let (r, w) = relabel
            .pairs
            .iter()
            .map(|&(_, old_l)| {
                let (r, w) = (old.r[old_l.0], old.w[old_l.0]);
                if relabel.mirror {
                    (s * r * s, -(s * w))
                } else {
                    (r, w)
                }
            })
            .unzip();
        Self {
            r,
            w,
            points_m,
            point_velocities_m_s,
        }
    }

    /// The velocity rows' right-hand side: `[ω of the old twins; v of the old points]`.
    pub fn velocity_target(&self) -> DVector<T> {
        let np = self.w.len();
        let mut target = DVector::zeros(3 * (np + self.point_velocities_m_s.len()));
        for (k, w) in self.w.iter().enumerate() {
            target.fixed_rows_mut::<3>(3 * k).copy_from(w);
        }
        for (k, v) in self.point_velocities_m_s.iter().enumerate() {
            target.fixed_rows_mut::<3>(3 * (np + k)).copy_from(v);
        }
        target
    }
}

/// Number of matched rows of `relabel`: three per link pair and per point pair.
pub fn row_count(relabel: &Relabel) -> usize {
    3 * (relabel.pairs.len() + relabel.point_pairs.len())
}

/// The pose residual (into `res`, [`row_count`] rows [rad or m]) of the new labelling at the
/// `f64` pose of `kin` against `targets`: orientation errors of the link pairs, then the
/// point pairs' position differences.
pub fn pose_residual<T: RealField + Copy>(
    relabel: &Relabel,
    model: &Model,
    kin: &Kinematics,
    targets: &RelabelTargets<T>,
    res: &mut DVector<T>,
) {
    let np = relabel.pairs.len();
    for (k, &(new, _)) in relabel.pairs.iter().enumerate() {
        let r_new: Matrix3<T> = kin.r_floor_link[new.0].map(konst);
        res.fixed_rows_mut::<3>(3 * k)
            .copy_from(&orientation_error(&targets.r[k], &r_new));
    }
    for (k, &(np_, _)) in relabel.point_pairs.iter().enumerate() {
        let pt = &model.points[np_.0];
        let p: Vector3<T> = kin.position_of(pt.link, &pt.p_link_m).map(konst);
        res.fixed_rows_mut::<3>(3 * (np + k))
            .copy_from(&(targets.points_m[k] - p));
    }
}

/// The matched rows' Jacobian (into `jac`, [`row_count`] × n) at the pose of `kin`: the link
/// pairs' angular Jacobians, then the point pairs' point Jacobians, with the fixed coordinates'
/// columns zero.
pub fn pose_jacobian<T: RealField + Copy>(
    relabel: &Relabel,
    model: &Model,
    kin: &KinematicsOf<T>,
    jac: &mut DMatrix<T>,
) {
    let n = model.dof();
    let np = relabel.pairs.len();
    for (k, &(new, _)) in relabel.pairs.iter().enumerate() {
        jac.view_mut((3 * k, 0), (3, n))
            .copy_from(&kin.angular_jacobian(model, new));
    }
    for (k, &(np_, _)) in relabel.point_pairs.iter().enumerate() {
        let pt = &model.points[np_.0];
        let p = kin.position_of(pt.link, &pt.p_link_m);
        jac.view_mut((3 * (np + k), 0), (3, n))
            .copy_from(&kin.point_jacobian(model, pt.link, &p));
    }
    for c in &relabel.fixed {
        jac.column_mut(c.0).fill(T::zero());
    }
}
