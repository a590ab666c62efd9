//! Reduced equations of motion `M̄ q̈ = f̄` by the TMT (virtual power) method, eq. (1)-(9).
//!
//! `M̄ = F,qᵀ M F,q` and `f̄ = F,qᵀ (f − M F,qq q̇ q̇)` are summed body by body: for each body,
//! `F,q` is its c.m. linear Jacobian and angular Jacobian, and `F,qq q̇ q̇` its bias acceleration.

use crate::kinematics::Kinematics;
use crate::model::{JointKind, LinkIndex, Model};
use crate::singular_limit::{solve_limit, LimitSolveError};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

/// Why the accelerations could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DynamicsError {
    /// The reduced mass matrix (or its vanishing-mass limit) is singular.
    #[error("reduced mass matrix is singular: {0}")]
    Singular(#[from] LimitSolveError),
    /// A coordinate or velocity is NaN or infinite.
    #[error("non-finite state")]
    NonFinite,
}

/// The equations of motion workspace: kinematics plus the assembled `M̄`, `f̄`.
#[derive(Clone, Debug)]
pub struct Dynamics {
    /// Kinematics at the last assembly.
    pub kin: Kinematics,
    /// `M̄` from bodies of finite mass [kg·m² for angles].
    pub mass_matrix: DMatrix<f64>,
    /// `M̄` per unit of infinitesimal mass (the `ε` part).
    pub mass_matrix_infinitesimal: DMatrix<f64>,
    /// `f̄` from finite bodies and joint springs/dampers [N·m for angles].
    pub force: DVector<f64>,
    /// `f̄` per unit of infinitesimal mass.
    pub force_infinitesimal: DVector<f64>,
    /// For each link, `(coordinate, link owning it)` along its ancestry.
    chains: Vec<Vec<(usize, usize)>>,
    /// Scratch: one body's nonzero Jacobian columns `(coordinate, linear, angular)`.
    cols: Vec<(usize, Vector3<f64>, Vector3<f64>)>,
    /// Scratch for the active-set solve (row-major k × k, then k).
    work_m: Vec<f64>,
    work_b: Vec<f64>,
    has_infinitesimal: bool,
}

impl Dynamics {
    /// A workspace sized for `model`.
    pub fn new(model: &Model) -> Self {
        let n = model.dof();
        Self {
            kin: Kinematics::new(model),
            mass_matrix: DMatrix::zeros(n, n),
            mass_matrix_infinitesimal: DMatrix::zeros(n, n),
            force: DVector::zeros(n),
            force_infinitesimal: DVector::zeros(n),
            chains: (0..model.links.len())
                .map(|i| {
                    model
                        .ancestry(LinkIndex(i))
                        .into_iter()
                        .filter_map(|l| model.links[l.0].coordinate.map(|c| (c.0, l.0)))
                        .collect()
                })
                .collect(),
            cols: Vec::with_capacity(n),
            work_m: vec![0.0; n * n],
            work_b: vec![0.0; n],
            has_infinitesimal: model.has_infinitesimal_bodies(),
        }
    }

    /// Assembles `M̄` and `f̄` at `q`, `q̇`, adding the generalised force `tau_extra`, if any.
    pub fn assemble(
        &mut self,
        model: &Model,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        tau_extra: Option<&DVector<f64>>,
    ) {
        self.kin.update(model, q, qd);
        self.mass_matrix.fill(0.0);
        self.mass_matrix_infinitesimal.fill(0.0);
        self.force.fill(0.0);
        self.force_infinitesimal.fill(0.0);
        let g = model.gravity_floor_m_s2;
        for (i, link) in model.links.iter().enumerate() {
            let b = &link.body;
            let has_rot = b.inertia_com_kg_m2.iter().any(|v| *v != 0.0);
            if b.mass_kg == 0.0 && !has_rot {
                continue;
            }
            let li = LinkIndex(i);
            let p_com = self.kin.position_of(li, &b.p_link_com_m);
            let a_bias = self.kin.bias_acceleration_of(li, &p_com);
            // The body's Jacobian columns, only for the coordinates of its ancestry (the other
            // columns are zero): linear at the c.m. and angular.
            self.cols.clear();
            for &(c, l) in &self.chains[i] {
                let a = self.kin.axis_floor[l];
                let (jv, jw) = match model.links[l].joint {
                    JointKind::Revolute { .. } => {
                        (a.cross(&(p_com - self.kin.p_floor_link_m[l])), a)
                    }
                    _ => (a, Vector3::zeros()),
                };
                self.cols.push((c, jv, jw));
            }
            let (mm, ff) = if b.infinitesimal {
                (
                    &mut self.mass_matrix_infinitesimal,
                    &mut self.force_infinitesimal,
                )
            } else {
                (&mut self.mass_matrix, &mut self.force)
            };
            // m Jvᵀ Jv + Jwᵀ I Jw and Jvᵀ m (g − a_bias) + Jwᵀ (−I α_bias − ω × I ω).
            let f_lin = (g - a_bias) * b.mass_kg;
            let (i_w, torque) = if has_rot {
                let r = self.kin.r_floor_link[i];
                let i_w = r * b.inertia_com_kg_m2 * r.transpose();
                let w = self.kin.omega_floor_rad_s[i];
                (
                    i_w,
                    -(i_w * self.kin.alpha_bias_rad_s2[i]) - w.cross(&(i_w * w)),
                )
            } else {
                (Matrix3::zeros(), Vector3::zeros())
            };
            for (x, &(ci, jvi, jwi)) in self.cols.iter().enumerate() {
                ff[ci] += jvi.dot(&f_lin) + jwi.dot(&torque);
                let iw_jwi = i_w * jwi;
                for &(cj, jvj, jwj) in &self.cols[..=x] {
                    let v = b.mass_kg * jvi.dot(&jvj) + jwj.dot(&iw_jwi);
                    mm[(ci, cj)] += v;
                    if ci != cj {
                        mm[(cj, ci)] += v;
                    }
                }
            }
        }
        for link in &model.links {
            if let Some(c) = link.coordinate {
                let jf = &link.joint_force;
                self.force[c.0] -=
                    jf.stiffness * (q[c.0] - jf.rest_position) + jf.damping * qd[c.0];
            }
        }
        if let Some(t) = tau_extra {
            self.force += t;
        }
    }

    /// Accelerations `q̈` at `q`, `q̇`. Coordinates where `active` is false are not free: their
    /// accelerations are given by `qdd_prescribed` (zero if `None`: locked joints), and the
    /// free ones answer `M̄_aa q̈_a = f̄_a − M̄_ap q̈_p`. Assembles first.
    pub fn accelerations(
        &mut self,
        model: &Model,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        active: &[bool],
        qdd_prescribed: Option<&DVector<f64>>,
    ) -> Result<DVector<f64>, DynamicsError> {
        if q.iter().chain(qd.iter()).any(|v| !v.is_finite()) {
            return Err(DynamicsError::NonFinite);
        }
        self.assemble(model, q, qd, None);
        let n = q.len();
        let mut qdd = match qdd_prescribed {
            Some(p) => p.clone(),
            None => DVector::zeros(n),
        };
        if self.has_infinitesimal {
            let idx: Vec<usize> = (0..n).filter(|&i| active[i]).collect();
            let m0 = self.mass_matrix.select_rows(&idx).select_columns(&idx);
            let mut f0 = self.force.select_rows(&idx);
            if let Some(qdd_p) = qdd_prescribed {
                let fixed: Vec<usize> = (0..n).filter(|&i| !active[i]).collect();
                let m_ap = self.mass_matrix.select_rows(&idx).select_columns(&fixed);
                f0 -= m_ap * qdd_p.select_rows(&fixed);
            }
            let m1 = self
                .mass_matrix_infinitesimal
                .select_rows(&idx)
                .select_columns(&idx);
            let f1 = self.force_infinitesimal.select_rows(&idx);
            let x = solve_limit(&m0, &m1, &f0, &f1, 1e-12)?;
            for (k, &i) in idx.iter().enumerate() {
                qdd[i] = x[k];
            }
        } else {
            // Allocation-free Cholesky solve of M̄_aa q̈_a = f̄_a − M̄_ap q̈_p on scratch buffers.
            let mut k = 0;
            for i in 0..n {
                if !active[i] {
                    continue;
                }
                let mut b = self.force[i];
                if qdd_prescribed.is_some() {
                    for j in (0..n).filter(|&j| !active[j]) {
                        b -= self.mass_matrix[(i, j)] * qdd[j];
                    }
                }
                self.work_b[k] = b;
                for (l, j) in (0..n).filter(|&j| active[j]).enumerate() {
                    self.work_m[k * n + l] = self.mass_matrix[(i, j)];
                }
                k += 1;
            }
            if !cholesky_solve_in_place(&mut self.work_m, n, k, &mut self.work_b) {
                return Err(LimitSolveError::Degenerate { nullity: 1 }.into());
            }
            let mut r = 0;
            for i in 0..n {
                if active[i] {
                    qdd[i] = self.work_b[r];
                    r += 1;
                }
            }
        }
        if qdd.iter().any(|v| !v.is_finite()) {
            return Err(DynamicsError::NonFinite);
        }
        Ok(qdd)
    }

    /// Mechanical energy of the finite bodies and joint springs [J], with the potential taken
    /// relative to the floor origin. Call after `assemble` at the same state.
    pub fn energy_j(&self, model: &Model, q: &DVector<f64>, qd: &DVector<f64>) -> f64 {
        let kinetic = 0.5 * qd.dot(&(&self.mass_matrix * qd));
        let mut potential = 0.0;
        for (i, link) in model.links.iter().enumerate() {
            if link.body.infinitesimal {
                continue;
            }
            let p = self.kin.position_of(LinkIndex(i), &link.body.p_link_com_m);
            potential -= link.body.mass_kg * model.gravity_floor_m_s2.dot(&p);
            if let Some(c) = link.coordinate {
                let jf = &link.joint_force;
                potential += 0.5 * jf.stiffness * (q[c.0] - jf.rest_position).powi(2);
            }
        }
        kinetic + potential
    }

    /// Angular momentum of the finite bodies about a floor-frame point [kg·m²/s]. Uses the
    /// kinematics of the last `assemble`.
    pub fn angular_momentum_about(&self, model: &Model, p_floor_m: &Vector3<f64>) -> Vector3<f64> {
        let mut h = Vector3::zeros();
        for (i, link) in model.links.iter().enumerate() {
            let b = &link.body;
            if b.infinitesimal {
                continue;
            }
            let li = LinkIndex(i);
            let p = self.kin.position_of(li, &b.p_link_com_m);
            let v = self.kin.velocity_of(li, &p);
            let r = self.kin.r_floor_link[i];
            let i_w = r * b.inertia_com_kg_m2 * r.transpose();
            h += (p - p_floor_m).cross(&(v * b.mass_kg)) + i_w * self.kin.omega_floor_rad_s[i];
        }
        h
    }
}

/// Solves `A x = b` for the leading `k × k` block of a symmetric positive definite `A` stored
/// row-major with row stride `stride`, overwriting `A` with its Cholesky factor and `b` with
/// `x`. Returns false if `A` is not positive definite.
fn cholesky_solve_in_place(a: &mut [f64], stride: usize, k: usize, b: &mut [f64]) -> bool {
    for j in 0..k {
        let mut d = a[j * stride + j];
        for p in 0..j {
            d -= a[j * stride + p] * a[j * stride + p];
        }
        // Also rejects NaN.
        if d.is_nan() || d <= 0.0 {
            return false;
        }
        let d = d.sqrt();
        a[j * stride + j] = d;
        for i in j + 1..k {
            let mut v = a[i * stride + j];
            for p in 0..j {
                v -= a[i * stride + p] * a[j * stride + p];
            }
            a[i * stride + j] = v / d;
        }
    }
    for i in 0..k {
        let mut v = b[i];
        for p in 0..i {
            v -= a[i * stride + p] * b[p];
        }
        b[i] = v / a[i * stride + i];
    }
    for i in (0..k).rev() {
        let mut v = b[i];
        for p in i + 1..k {
            v -= a[p * stride + i] * b[p];
        }
        b[i] = v / a[i * stride + i];
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn in_place_cholesky_solves_an_spd_block() {
        // 3 x 3 SPD block inside a 4-wide buffer.
        let m = [4.0, 1.0, 0.5, 9.0, 1.0, 3.0, 0.2, 9.0, 0.5, 0.2, 2.0, 9.0];
        let mut a = m.to_vec();
        let x = [1.0, -2.0, 0.5];
        let mut b: Vec<f64> = (0..3)
            .map(|i| (0..3).map(|j| m[i * 4 + j] * x[j]).sum())
            .collect();
        assert!(cholesky_solve_in_place(&mut a, 4, 3, &mut b));
        for i in 0..3 {
            assert!((b[i] - x[i]).abs() < 1e-14);
        }
        let mut not_pd = vec![1.0, 2.0, 2.0, 1.0];
        assert!(!cholesky_solve_in_place(&mut not_pd, 2, 2, &mut [1.0, 1.0]));
    }
}
