//! The stance contact's load from the total momentum balance: the ground reaction force and
//! moment that the whole walker's motion requires, and the lateral centre of pressure under
//! the stance foot that carries the roll moment (`docs/model.md`: roll is judged this way, since the
//! foot has no roll freedom).

use crate::engine::kinematics::Kinematics;
use crate::engine::model::{LinkIndex, Model};
use nalgebra::{DVector, Vector3};

/// Ground reaction on the walker at the floor origin (the stance contact).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactLoad {
    /// Force \[N\], floor frame.
    pub force_n: Vector3<f64>,
    /// Moment about the floor origin [N·m], floor frame.
    pub moment_n_m: Vector3<f64>,
}

impl ContactLoad {
    /// `F = Σ m (a − g)`, `M_O = Σ [r × m (a − g) + I α + ω × I ω]` for accelerations `qdd`.
    /// `kin` must hold the kinematics at `q`, `q̇`.
    pub fn from_motion(model: &Model, kin: &Kinematics, qdd: &DVector<f64>) -> Self {
        let g = model.gravity_floor_m_s2;
        let mut force_n = Vector3::zeros();
        let mut moment_n_m = Vector3::zeros();
        for (i, link) in model.links.iter().enumerate() {
            let b = &link.body;
            if b.infinitesimal {
                continue;
            }
            let li = LinkIndex(i);
            let r = kin.position_of(li, &b.p_link_com_m);
            let a = kin.point_jacobian(model, li, &r) * qdd + kin.bias_acceleration_of(li, &r);
            let alpha = kin.angular_jacobian(model, li) * qdd + kin.alpha_bias_rad_s2[i];
            let rot = kin.r_floor_link[i];
            let inertia = rot * b.inertia_com_kg_m2 * rot.transpose();
            let w = kin.omega_floor_rad_s[i];
            let f = (a - g) * b.mass_kg;
            force_n += f;
            moment_n_m += r.cross(&f) + inertia * alpha + w.cross(&(inertia * w));
        }
        Self {
            force_n,
            moment_n_m,
        }
    }

    /// Lateral offset of the centre of pressure from the origin \[m\], to the right of the
    /// horizontal walking direction `heading` (unit, floor plane): the normal force at that
    /// offset carries the moment about the walking direction, `e = −M·d / F_y`.
    pub fn lateral_cop_m(&self, heading: &Vector3<f64>) -> f64 {
        -self.moment_n_m.dot(heading) / self.force_n.y
    }
}
