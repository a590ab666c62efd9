//! Reduced equations of motion `M̄ q̈ = f̄` by the TMT (virtual power) method, eq. (1)-(9).
//!
//! `M̄ = F,qᵀ M F,q` and `f̄ = F,qᵀ (f − M F,qq q̇ q̇)` are summed body by body: for each body,
//! `F,q` is its c.m. linear Jacobian and angular Jacobian, and `F,qq q̇ q̇` its bias acceleration.

use crate::engine::kinematics::KinematicsOf;
use crate::engine::model::{JointKind, LinkIndex, Model};
use crate::engine::singular_limit::{solve_limit, LimitSolveError, NULL_EIGENVALUE_REL_TOL};
use nalgebra::{DMatrix, DVector, Matrix3, RealField, Scalar, Vector3};

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

/// The equations of motion workspace in `f64`.
pub type Dynamics = DynamicsOf<f64>;

/// The equations of motion workspace: kinematics plus the assembled `M̄`, `f̄`, over any real
/// scalar (`f64`, or dual numbers that carry derivatives).
#[derive(Clone, Debug)]
pub struct DynamicsOf<T: Scalar> {
    /// Kinematics at the last assembly.
    pub kin: KinematicsOf<T>,
    /// `M̄` from bodies of finite mass [kg·m² for angles].
    pub mass_matrix: DMatrix<T>,
    /// `M̄` per unit of infinitesimal mass (the `ε` part).
    pub mass_matrix_infinitesimal: DMatrix<T>,
    /// `f̄` from finite bodies and joint springs/dampers [N·m for angles].
    pub force: DVector<T>,
    /// `f̄` per unit of infinitesimal mass.
    pub force_infinitesimal: DVector<T>,
    /// For each link, `(coordinate, link owning it, whether its joint is revolute)` along its
    /// ancestry: the only nonzero columns of the link's Jacobians.
    chains: Vec<Vec<(usize, usize, bool)>>,
    /// Scratch: one body's nonzero Jacobian columns `(coordinate, linear, angular)`.
    cols: Vec<(usize, Vector3<T>, Vector3<T>)>,
    /// Scratch for the active-set solve (row-major k × k, then k).
    work_m: Vec<T>,
    work_b: Vec<T>,
    /// Scratch: the active coordinates of the solve.
    work_idx: Vec<usize>,
    has_infinitesimal: bool,
    /// For each link, whether its body has a nonzero inertia tensor.
    rotational: Vec<bool>,
    /// Scratch: the coordinates whose rows and columns a partial assembly computes.
    needed: Vec<bool>,
    /// The coordinates whose rows and columns the last assembly computed (all after a full
    /// one).
    assembled: Vec<bool>,
}

impl<T: RealField + Copy> DynamicsOf<T> {
    /// A workspace sized for `model`.
    pub fn new(model: &Model) -> Self {
        let n = model.dof();
        Self {
            kin: KinematicsOf::new(model),
            mass_matrix: DMatrix::zeros(n, n),
            mass_matrix_infinitesimal: DMatrix::zeros(n, n),
            force: DVector::zeros(n),
            force_infinitesimal: DVector::zeros(n),
            chains: (0..model.links.len())
                .map(|i| {
                    model
                        .ancestry(LinkIndex(i))
                        .into_iter()
                        .filter_map(|l| {
                            let link = &model.links[l.0];
                            let revolute = matches!(link.joint, JointKind::Revolute { .. });
                            link.coordinate.map(|c| (c.0, l.0, revolute))
                        })
                        .collect()
                })
                .collect(),
            cols: Vec::with_capacity(n),
            work_m: vec![T::zero(); n * n],
            work_b: vec![T::zero(); n],
            work_idx: Vec::with_capacity(n),
            has_infinitesimal: model.has_infinitesimal_bodies(),
            rotational: model
                .links
                .iter()
                .map(|l| l.body.inertia_com_kg_m2.iter().any(|v| *v != 0.0))
                .collect(),
            needed: vec![true; n],
            assembled: vec![true; n],
        }
    }

    /// Assembles `M̄` and `f̄` at `q`, `q̇`, adding the generalised force `tau_extra`, if any.
    pub fn assemble(
        &mut self,
        model: &Model,
        q: &DVector<T>,
        qd: &DVector<T>,
        tau_extra: Option<&DVector<T>>,
    ) {
        self.assemble_entries(model, q, qd, tau_extra, false);
    }

    /// [`Self::assemble`], with only the rows and columns of the coordinates where
    /// `self.needed` is true when `partial` (the others' Jacobian columns skipped: their
    /// entries stay zero, the spring and damper forces excepted). Each computed entry is the
    /// same sum as in the full assembly.
    fn assemble_entries(
        &mut self,
        model: &Model,
        q: &DVector<T>,
        qd: &DVector<T>,
        tau_extra: Option<&DVector<T>>,
        partial: bool,
    ) {
        self.kin.update(model, q, qd);
        for (j, assembled) in self.assembled.iter_mut().enumerate() {
            *assembled = !partial || self.needed[j];
        }
        // On the contiguous storage: nalgebra's `fill` walks a strided iterator per entry.
        self.mass_matrix.as_mut_slice().fill(T::zero());
        self.mass_matrix_infinitesimal
            .as_mut_slice()
            .fill(T::zero());
        self.force.as_mut_slice().fill(T::zero());
        self.force_infinitesimal.as_mut_slice().fill(T::zero());
        let c = |x: f64| -> T { nalgebra::convert(x) };
        let g: Vector3<T> = model.gravity_floor_m_s2.map(c);
        let n = self.force.len();
        for (i, link) in model.links.iter().enumerate() {
            let b = &link.body;
            let has_rot = self.rotational[i];
            if b.mass_kg == 0.0 && !has_rot {
                continue;
            }
            let li = LinkIndex(i);
            let p_com = self.kin.position_of(li, &b.p_link_com_m);
            let a_bias = self.kin.bias_acceleration_of(li, &p_com);
            // The body's Jacobian columns, only for the coordinates of its ancestry (the other
            // columns are zero): linear at the c.m. and angular.
            self.cols.clear();
            for &(c, l, revolute) in &self.chains[i] {
                if partial && !self.needed[c] {
                    continue;
                }
                let a = self.kin.axis_floor[l];
                let (jv, jw) = if revolute {
                    (a.cross(&(p_com - self.kin.p_floor_link_m[l])), a)
                } else {
                    (a, Vector3::zeros())
                };
                self.cols.push((c, jv, jw));
            }
            let (mm, ff) = if b.infinitesimal {
                (
                    self.mass_matrix_infinitesimal.as_mut_slice(),
                    self.force_infinitesimal.as_mut_slice(),
                )
            } else {
                (self.mass_matrix.as_mut_slice(), self.force.as_mut_slice())
            };
            // m Jvᵀ Jv + Jwᵀ I Jw and Jvᵀ m (g − a_bias) + Jwᵀ (−I α_bias − ω × I ω).
            let mass = c(b.mass_kg);
            let f_lin = (g - a_bias) * mass;
            let (i_w, torque) = if has_rot {
                let r = self.kin.r_floor_link[i];
                let i_w = r * b.inertia_com_kg_m2.map(c) * r.transpose();
                let w = self.kin.omega_floor_rad_s[i];
                (
                    i_w,
                    -(i_w * self.kin.alpha_bias_rad_s2[i]) - w.cross(&(i_w * w)),
                )
            } else {
                (Matrix3::zeros(), Vector3::zeros())
            };
            // Only the lower triangle (row ≥ column, column-major storage), mirrored once
            // below: each pair's sum is the same in both halves.
            for (x, &(ci, jvi, jwi)) in self.cols.iter().enumerate() {
                ff[ci] += dot3(&jvi, &f_lin) + dot3(&jwi, &torque);
                let iw_jwi = i_w * jwi;
                for &(cj, jvj, jwj) in &self.cols[..=x] {
                    let v = mass * dot3(&jvi, &jvj) + dot3(&jwj, &iw_jwi);
                    mm[ci.min(cj) * n + ci.max(cj)] += v;
                }
            }
        }
        mirror_lower(self.mass_matrix.as_mut_slice(), n);
        if self.has_infinitesimal {
            mirror_lower(self.mass_matrix_infinitesimal.as_mut_slice(), n);
        }
        for link in &model.links {
            if let Some(c) = link.coordinate {
                let jf = &link.joint_force;
                self.force[c.0] -= (q[c.0] - self::lift(jf.rest_position))
                    * self::lift(jf.stiffness)
                    + qd[c.0] * self::lift(jf.damping);
            }
        }
        if let Some(t) = tau_extra {
            self.force += t;
        }
    }

    /// Accelerations of a model without infinitesimal bodies (see [`Dynamics::accelerations`]),
    /// in any scalar. Assembles first.
    ///
    /// # Errors
    /// [`DynamicsError::Singular`] when the active block of `M̄` is not positive definite, or
    /// the model has infinitesimal bodies (their limit is solved in `f64` only).
    pub fn accelerations_finite(
        &mut self,
        model: &Model,
        q: &DVector<T>,
        qd: &DVector<T>,
        active: &[bool],
        qdd_prescribed: Option<&DVector<T>>,
    ) -> Result<DVector<T>, DynamicsError> {
        let mut qdd = DVector::zeros(q.len());
        self.accelerations_finite_into(model, q, qd, active, qdd_prescribed, &mut qdd)?;
        Ok(qdd)
    }

    /// As [`Self::accelerations_finite`], writing `q̈` into `qdd` (of `q`'s length) without
    /// allocating.
    ///
    /// # Errors
    /// As [`Self::accelerations_finite`].
    pub fn accelerations_finite_into(
        &mut self,
        model: &Model,
        q: &DVector<T>,
        qd: &DVector<T>,
        active: &[bool],
        qdd_prescribed: Option<&DVector<T>>,
        qdd: &mut DVector<T>,
    ) -> Result<(), DynamicsError> {
        self.solve_finite_into(model, q, qd, active, qdd_prescribed, qdd, false)
    }

    /// As [`Self::accelerations_finite_into`]; when `partial`, assembling only what the
    /// solve reads: the rows and columns of the free coordinates and of the prescribed ones
    /// with a nonzero acceleration (a zero one contributes `M̄_ij · 0 = 0` to the right-hand
    /// side either way), so that the free coordinates' `q̈` is the same, to the bit, as with
    /// the full assembly.
    #[allow(clippy::too_many_arguments)]
    fn solve_finite_into(
        &mut self,
        model: &Model,
        q: &DVector<T>,
        qd: &DVector<T>,
        active: &[bool],
        qdd_prescribed: Option<&DVector<T>>,
        qdd: &mut DVector<T>,
        partial: bool,
    ) -> Result<(), DynamicsError> {
        if self.has_infinitesimal {
            return Err(LimitSolveError::Degenerate { nullity: 0 }.into());
        }
        if partial {
            self.mark_needed(active, qdd_prescribed);
        }
        self.assemble_entries(model, q, qd, None, partial);
        self.solve_assembled_finite_into(active, qdd_prescribed, qdd, partial)
    }

    /// Marks in `self.needed` the coordinates whose rows and columns the solve reads: the free
    /// ones and the prescribed ones with a nonzero acceleration.
    fn mark_needed(&mut self, active: &[bool], qdd_prescribed: Option<&DVector<T>>) {
        for (j, needed) in self.needed.iter_mut().enumerate() {
            *needed = active[j] || qdd_prescribed.is_some_and(|p| p[j] != T::zero());
        }
    }

    /// The solve of [`Self::solve_finite_into`] on the matrices already assembled here:
    /// `M̄_aa q̈_a = f̄_a − M̄_ap q̈_p`, reading, when `partial`, only the prescribed
    /// coordinates marked in `self.needed`.
    fn solve_assembled_finite_into(
        &mut self,
        active: &[bool],
        qdd_prescribed: Option<&DVector<T>>,
        qdd: &mut DVector<T>,
        partial: bool,
    ) -> Result<(), DynamicsError> {
        let n = qdd.len();
        match qdd_prescribed {
            Some(p) => qdd.copy_from(p),
            None => qdd.as_mut_slice().fill(T::zero()),
        }
        // Allocation-free Cholesky solve of M̄_aa q̈_a = f̄_a − M̄_ap q̈_p on scratch buffers;
        // the active coordinates listed once, `M̄` read from its column-major storage.
        self.work_idx.clear();
        self.work_idx.extend((0..n).filter(|&j| active[j]));
        let k = self.work_idx.len();
        let (m, rows) = (self.mass_matrix.as_slice(), self.mass_matrix.nrows());
        for (r, &i) in self.work_idx.iter().enumerate() {
            let mut b = self.force[i];
            if qdd_prescribed.is_some() {
                for j in (0..n).filter(|&j| !active[j] && (!partial || self.needed[j])) {
                    b -= m[j * rows + i] * qdd[j];
                }
            }
            self.work_b[r] = b;
            let row = &mut self.work_m[r * n..r * n + k];
            for (x, &j) in row.iter_mut().zip(&self.work_idx) {
                *x = m[j * rows + i];
            }
        }
        if !cholesky_solve_in_place(&mut self.work_m, n, k, &mut self.work_b) {
            return Err(LimitSolveError::Degenerate { nullity: 1 }.into());
        }
        for (r, &i) in self.work_idx.iter().enumerate() {
            qdd[i] = self.work_b[r];
        }
        Ok(())
    }
}

/// Copies the lower triangle of the column-major `n × n` matrix `m` onto its upper triangle.
fn mirror_lower<T: Copy>(m: &mut [T], n: usize) {
    for col in 0..n {
        for row in col + 1..n {
            m[row * n + col] = m[col * n + row];
        }
    }
}

/// `a · b` written out: nalgebra's generic `dot` does not reduce to three products on every
/// scalar, and the assembly's inner loop runs it for every pair of joints of every body.
#[inline(always)]
fn dot3<T: RealField + Copy>(a: &Vector3<T>, b: &Vector3<T>) -> T {
    a.x * b.x + a.y * b.y + a.z * b.z
}

/// A model constant in the scalar `T`.
fn lift<T: RealField + Copy>(x: f64) -> T {
    nalgebra::convert(x)
}

impl Dynamics {
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
        let mut qdd = DVector::zeros(q.len());
        self.accelerations_into(model, q, qd, active, qdd_prescribed, &mut qdd)?;
        Ok(qdd)
    }

    /// As [`Self::accelerations`], writing `q̈` into `qdd` (of `q`'s length); without
    /// allocating when the model has no infinitesimal bodies.
    ///
    /// # Errors
    /// As [`Self::accelerations`].
    pub fn accelerations_into(
        &mut self,
        model: &Model,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        active: &[bool],
        qdd_prescribed: Option<&DVector<f64>>,
        qdd: &mut DVector<f64>,
    ) -> Result<(), DynamicsError> {
        self.solve_into(model, q, qd, active, qdd_prescribed, qdd, false)
    }

    /// As [`Self::accelerations_into`], assembling only the entries of `M̄` and `f̄` the solve
    /// reads (the rows and columns of the free coordinates and of prescribed ones with a
    /// nonzero acceleration; see `solve_finite_into`): the same `q̈`, to the bit, for less
    /// work where coordinates are locked. The workspace's `M̄` and `f̄` are then partial: not
    /// for energies, momenta or actuator torques. Models with infinitesimal bodies assemble
    /// fully.
    ///
    /// # Errors
    /// As [`Self::accelerations`].
    pub fn accelerations_of_free_into(
        &mut self,
        model: &Model,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        active: &[bool],
        qdd_prescribed: Option<&DVector<f64>>,
        qdd: &mut DVector<f64>,
    ) -> Result<(), DynamicsError> {
        self.solve_into(model, q, qd, active, qdd_prescribed, qdd, true)
    }

    /// As [`Self::accelerations_of_free_into`] at the `q`, `q̇` of the workspace's last
    /// assembly, on that assembly: only the solve, for another set of prescribed accelerations
    /// (the assembly depends on `q`, `q̇` only). `Ok(false)`, and nothing written, when the last
    /// assembly did not compute every row and column this solve reads (the free coordinates and
    /// the prescribed ones with a nonzero acceleration) or the model has infinitesimal bodies.
    /// The caller vouches that the workspace was last assembled (by this type's methods, its
    /// `M̄` and `f̄` untouched since) at the `q`, `q̇` it means: the result is then, to the bit,
    /// that of [`Self::accelerations_of_free_into`] there.
    ///
    /// # Errors
    /// As [`Self::accelerations`].
    pub fn accelerations_on_assembly_into(
        &mut self,
        active: &[bool],
        qdd_prescribed: Option<&DVector<f64>>,
        qdd: &mut DVector<f64>,
    ) -> Result<bool, DynamicsError> {
        let n = self.assembled.len();
        if self.has_infinitesimal || active.len() != n || qdd.len() != n {
            return Ok(false);
        }
        self.mark_needed(active, qdd_prescribed);
        if self
            .needed
            .iter()
            .zip(&self.assembled)
            .any(|(&n, &a)| n && !a)
        {
            return Ok(false);
        }
        self.solve_assembled_finite_into(active, qdd_prescribed, qdd, true)?;
        if !qdd.as_slice().iter().all(|v| v.is_finite()) {
            return Err(DynamicsError::NonFinite);
        }
        Ok(true)
    }

    /// Whether the last assembly computed coordinate `c`'s row and column of `M̄` and its
    /// entry of `f̄` (always after a full assembly).
    pub fn assembled_row(&self, c: usize) -> bool {
        self.assembled.get(c).copied().unwrap_or(false)
    }

    /// [`Self::accelerations_into`], with a partial assembly when `partial`.
    #[allow(clippy::too_many_arguments)]
    fn solve_into(
        &mut self,
        model: &Model,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        active: &[bool],
        qdd_prescribed: Option<&DVector<f64>>,
        qdd: &mut DVector<f64>,
        partial: bool,
    ) -> Result<(), DynamicsError> {
        // On the contiguous storage: nalgebra's matrix iterator is strided.
        let finite = |x: &DVector<f64>| x.as_slice().iter().all(|v| v.is_finite());
        if !finite(q) || !finite(qd) {
            return Err(DynamicsError::NonFinite);
        }
        if !self.has_infinitesimal {
            self.solve_finite_into(model, q, qd, active, qdd_prescribed, qdd, partial)?;
            if !finite(qdd) {
                return Err(DynamicsError::NonFinite);
            }
            return Ok(());
        }
        self.assemble(model, q, qd, None);
        *qdd = self.solve_assembled_limit(active, qdd_prescribed)?;
        Ok(())
    }

    /// The vanishing-mass limit of `M̄_aa q̈_a = f̄_a − M̄_ap q̈_p` on the matrices already
    /// assembled here (finite and infinitesimal parts; see [`Dynamics::accelerations`]).
    ///
    /// # Errors
    /// [`DynamicsError`]: no limit exists, or a non-finite result.
    pub fn solve_assembled_limit(
        &self,
        active: &[bool],
        qdd_prescribed: Option<&DVector<f64>>,
    ) -> Result<DVector<f64>, DynamicsError> {
        let n = active.len();
        let mut qdd = match qdd_prescribed {
            Some(p) => p.clone(),
            None => DVector::zeros(n),
        };
        {
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
            let x = solve_limit(&m0, &m1, &f0, &f1, NULL_EIGENVALUE_REL_TOL)?;
            for (k, &i) in idx.iter().enumerate() {
                qdd[i] = x[k];
            }
        }
        if qdd.iter().any(|v| !v.is_finite()) {
            return Err(DynamicsError::NonFinite);
        }
        Ok(qdd)
    }

    /// Mechanical energy of the finite bodies and joint springs \[J\], with the potential taken
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
fn cholesky_solve_in_place<T: RealField + Copy>(
    a: &mut [T],
    stride: usize,
    k: usize,
    b: &mut [T],
) -> bool {
    for j in 0..k {
        let mut d = a[j * stride + j];
        for p in 0..j {
            d -= a[j * stride + p] * a[j * stride + p];
        }
        // Also rejects NaN (which is not greater than zero).
        if d.partial_cmp(&T::zero()) != Some(std::cmp::Ordering::Greater) {
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
