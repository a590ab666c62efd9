//! Forward kinematics: world poses, velocities and velocity-product ("bias") accelerations of
//! every link, and the Jacobians `F,q` of the TMT method (eq. 4-7 of the paper).

use crate::engine::math::rotation_about;
use crate::engine::model::{JointKind, LinkIndex, Model, PointIndex};
use nalgebra::{DMatrix, DVector, Matrix3, RealField, Scalar, Vector3};

/// The kinematic workspace for one model in `f64`, refilled by [`KinematicsOf::update`].
pub type Kinematics = KinematicsOf<f64>;

/// The kinematic workspace for one model, over any real scalar (`f64`, or dual numbers that
/// carry derivatives), refilled by [`KinematicsOf::update`].
#[derive(Clone, Debug)]
pub struct KinematicsOf<T: Scalar> {
    /// Rotation link frame → floor frame.
    pub r_floor_link: Vec<Matrix3<T>>,
    /// Link origin in the floor frame \[m\].
    pub p_floor_link_m: Vec<Vector3<T>>,
    /// Joint axis in the floor frame (zero for welds).
    pub axis_floor: Vec<Vector3<T>>,
    /// Angular velocity of each link, floor frame [rad/s].
    pub omega_floor_rad_s: Vec<Vector3<T>>,
    /// Velocity of each link origin, floor frame [m/s].
    pub v_floor_link_m_s: Vec<Vector3<T>>,
    /// Angular acceleration with `q̈ = 0` [rad/s²].
    pub alpha_bias_rad_s2: Vec<Vector3<T>>,
    /// Acceleration of each link origin with `q̈ = 0` [m/s²].
    pub a_bias_link_m_s2: Vec<Vector3<T>>,
}

/// A revolute axis along one of the parent frame's own axes (`+x`, `+y`, `+z`): the joint's
/// rotation mixes two columns of the parent's rotation, with one `sin_cos`, instead of a full
/// rotation matrix and a 3 × 3 product (the same rotation, `R·e_k` exact where the general
/// formula rounds `c + (1 − c)`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum CoordinateAxis {
    X,
    Y,
    Z,
}

impl CoordinateAxis {
    /// The axis `axis` is, exactly, if any.
    fn of(axis: &Vector3<f64>) -> Option<Self> {
        match (axis.x, axis.y, axis.z) {
            (1.0, 0.0, 0.0) => Some(Self::X),
            (0.0, 1.0, 0.0) => Some(Self::Y),
            (0.0, 0.0, 1.0) => Some(Self::Z),
            _ => None,
        }
    }

    /// The joint axis in the floor frame and `r_p · R_k(angle)`, for a parent rotation `r_p`.
    fn rotate<T: RealField + Copy>(self, r_p: &Matrix3<T>, angle: T) -> (Vector3<T>, Matrix3<T>) {
        let (s, c) = angle.sin_cos();
        // Columns i, j of `r_p` rotate into c·i + s·j and c·j − s·i, about the third.
        let (i, j, k) = match self {
            Self::X => (1, 2, 0),
            Self::Y => (2, 0, 1),
            Self::Z => (0, 1, 2),
        };
        let (ci, cj) = (r_p.column(i).into_owned(), r_p.column(j).into_owned());
        let mut r = *r_p;
        r.set_column(i, &(ci * c + cj * s));
        r.set_column(j, &(cj * c - ci * s));
        (r_p.column(k).into_owned(), r)
    }
}

/// A model vector in the scalar `T`.
fn lift<T: RealField + Copy>(v: &Vector3<f64>) -> Vector3<T> {
    v.map(nalgebra::convert)
}

impl<T: RealField + Copy> KinematicsOf<T> {
    /// A workspace sized for `model`.
    pub fn new(model: &Model) -> Self {
        let n = model.links.len();
        Self {
            r_floor_link: vec![Matrix3::identity(); n],
            p_floor_link_m: vec![Vector3::zeros(); n],
            axis_floor: vec![Vector3::zeros(); n],
            omega_floor_rad_s: vec![Vector3::zeros(); n],
            v_floor_link_m_s: vec![Vector3::zeros(); n],
            alpha_bias_rad_s2: vec![Vector3::zeros(); n],
            a_bias_link_m_s2: vec![Vector3::zeros(); n],
        }
    }

    /// Recomputes poses, velocities and bias accelerations for `q`, `q̇`.
    pub fn update(&mut self, model: &Model, q: &DVector<T>, qd: &DVector<T>) {
        for (i, link) in model.links.iter().enumerate() {
            let (r_p, p_p, w_p, v_p, al_p, a_p) = match link.parent {
                Some(p) => (
                    self.r_floor_link[p.0],
                    self.p_floor_link_m[p.0],
                    self.omega_floor_rad_s[p.0],
                    self.v_floor_link_m_s[p.0],
                    self.alpha_bias_rad_s2[p.0],
                    self.a_bias_link_m_s2[p.0],
                ),
                None => (
                    Matrix3::identity(),
                    Vector3::zeros(),
                    Vector3::zeros(),
                    Vector3::zeros(),
                    Vector3::zeros(),
                    Vector3::zeros(),
                ),
            };
            let d = r_p * lift::<T>(&link.p_parent_joint_m);
            let o = p_p + d;
            let v_o = v_p + w_p.cross(&d);
            let a_o = a_p + al_p.cross(&d) + w_p.cross(&w_p.cross(&d));
            let (qi, qdi) = match link.coordinate {
                Some(c) => (q[c.0], qd[c.0]),
                None => (T::zero(), T::zero()),
            };
            match &link.joint {
                JointKind::Revolute { axis_parent } => {
                    let (a, r) = match CoordinateAxis::of(axis_parent) {
                        Some(k) => k.rotate(&r_p, qi),
                        None => (
                            r_p * lift::<T>(axis_parent),
                            r_p * rotation_about(axis_parent, qi),
                        ),
                    };
                    self.axis_floor[i] = a;
                    self.r_floor_link[i] = r;
                    self.p_floor_link_m[i] = o;
                    self.omega_floor_rad_s[i] = w_p + a * qdi;
                    self.v_floor_link_m_s[i] = v_o;
                    self.alpha_bias_rad_s2[i] = al_p + w_p.cross(&a) * qdi;
                    self.a_bias_link_m_s2[i] = a_o;
                }
                JointKind::Prismatic { axis_parent } => {
                    let a = r_p * lift::<T>(axis_parent);
                    self.axis_floor[i] = a;
                    self.r_floor_link[i] = r_p;
                    let s = a * qi;
                    self.p_floor_link_m[i] = o + s;
                    self.omega_floor_rad_s[i] = w_p;
                    self.v_floor_link_m_s[i] = v_o + w_p.cross(&s) + a * qdi;
                    self.alpha_bias_rad_s2[i] = al_p;
                    self.a_bias_link_m_s2[i] = a_o
                        + al_p.cross(&s)
                        + w_p.cross(&w_p.cross(&s))
                        + w_p.cross(&a) * (qdi + qdi);
                }
                JointKind::Weld => {
                    self.axis_floor[i] = Vector3::zeros();
                    self.r_floor_link[i] = r_p;
                    self.p_floor_link_m[i] = o;
                    self.omega_floor_rad_s[i] = w_p;
                    self.v_floor_link_m_s[i] = v_o;
                    self.alpha_bias_rad_s2[i] = al_p;
                    self.a_bias_link_m_s2[i] = a_o;
                }
            }
        }
    }

    /// Position in the floor frame of a point given in a link frame \[m\].
    pub fn position_of(&self, link: LinkIndex, p_link_m: &Vector3<f64>) -> Vector3<T> {
        self.p_floor_link_m[link.0] + self.r_floor_link[link.0] * lift::<T>(p_link_m)
    }

    /// Position of a marker point \[m\].
    pub fn point_position(&self, model: &Model, point: PointIndex) -> Vector3<T> {
        let p = &model.points[point.0];
        self.position_of(p.link, &p.p_link_m)
    }

    /// Velocity in the floor frame of a floor-frame point moving with `link` [m/s].
    pub fn velocity_of(&self, link: LinkIndex, p_floor_m: &Vector3<T>) -> Vector3<T> {
        self.v_floor_link_m_s[link.0]
            + self.omega_floor_rad_s[link.0].cross(&(p_floor_m - self.p_floor_link_m[link.0]))
    }

    /// Bias acceleration (`q̈ = 0`) of a floor-frame point moving with `link` [m/s²].
    pub fn bias_acceleration_of(&self, link: LinkIndex, p_floor_m: &Vector3<T>) -> Vector3<T> {
        let r = p_floor_m - self.p_floor_link_m[link.0];
        let w = self.omega_floor_rad_s[link.0];
        self.a_bias_link_m_s2[link.0]
            + self.alpha_bias_rad_s2[link.0].cross(&r)
            + w.cross(&w.cross(&r))
    }

    /// Linear Jacobian `∂v/∂q̇` (3 × n) of a floor-frame point moving with `link`.
    pub fn point_jacobian(
        &self,
        model: &Model,
        link: LinkIndex,
        p_floor_m: &Vector3<T>,
    ) -> DMatrix<T> {
        let mut j = DMatrix::zeros(3, model.dof());
        self.point_jacobian_into(model, link, p_floor_m, &mut j);
        j
    }

    /// As [`Self::point_jacobian`], writing into `j` (3 × n, overwritten).
    pub fn point_jacobian_into(
        &self,
        model: &Model,
        link: LinkIndex,
        p_floor_m: &Vector3<T>,
        j: &mut DMatrix<T>,
    ) {
        j.fill(T::zero());
        let mut cur = Some(link);
        while let Some(l) = cur {
            let lk = &model.links[l.0];
            if let Some(c) = lk.coordinate {
                let a = self.axis_floor[l.0];
                let col = match lk.joint {
                    JointKind::Revolute { .. } => a.cross(&(p_floor_m - self.p_floor_link_m[l.0])),
                    _ => a,
                };
                j.fixed_view_mut::<3, 1>(0, c.0).copy_from(&col);
            }
            cur = lk.parent;
        }
    }

    /// Angular Jacobian `∂ω/∂q̇` (3 × n) of `link`.
    pub fn angular_jacobian(&self, model: &Model, link: LinkIndex) -> DMatrix<T> {
        let mut j = DMatrix::zeros(3, model.dof());
        self.angular_jacobian_into(model, link, &mut j);
        j
    }

    /// As [`Self::angular_jacobian`], writing into `j` (3 × n, overwritten).
    pub fn angular_jacobian_into(&self, model: &Model, link: LinkIndex, j: &mut DMatrix<T>) {
        j.fill(T::zero());
        let mut cur = Some(link);
        while let Some(l) = cur {
            let lk = &model.links[l.0];
            if let (Some(c), JointKind::Revolute { .. }) = (lk.coordinate, &lk.joint) {
                j.fixed_view_mut::<3, 1>(0, c.0)
                    .copy_from(&self.axis_floor[l.0]);
            }
            cur = lk.parent;
        }
    }

    /// Centre of mass of the whole model (infinitesimal bodies excluded) \[m\].
    pub fn centre_of_mass(&self, model: &Model) -> Vector3<T> {
        let mut sum = Vector3::zeros();
        let mut m = 0.0;
        for (i, l) in model.links.iter().enumerate() {
            if l.body.infinitesimal || l.body.mass_kg == 0.0 {
                continue;
            }
            sum += self.position_of(LinkIndex(i), &l.body.p_link_com_m)
                * nalgebra::convert::<f64, T>(l.body.mass_kg);
            m += l.body.mass_kg;
        }
        if m > 0.0 {
            sum / nalgebra::convert::<f64, T>(m)
        } else {
            Vector3::zeros()
        }
    }
}
