//! The planar fast path: the equations of motion `M̄ q̈ = f̄` of a small planar tree — every
//! joint a revolute about the floor's z axis or a weld, gravity in the x-y plane — with
//! fixed-size matrices (`nalgebra::SMatrix`, the number of coordinates a const generic), one
//! `sin_cos` per joint instead of 3 × 3 rotations, and no allocation but the returned `q̈`.
//!
//! The general engine ([`crate::engine::dynamics`]) stays the reference: a phase selects this path
//! automatically when its model qualifies ([`PlanarTree::of`]), and `sim/tests/fast_path.rs`
//! checks both against each other on the equations of motion and on whole gaits.
//!
//! Planar kinematics: a link's angle is its parent's plus `±q` (the sign of its axis along z),
//! its origin its parent's plus the joint offset turned by the parent's angle. With every
//! angular velocity along z the angular bias acceleration is zero and the bias acceleration of a
//! point `p` fixed in a link is the link origin's minus `ω² (p − o)`; the gyroscopic torque
//! `ω × I ω` has no z component, so only each body's `I_zz` enters.

use crate::engine::dynamics::{Dynamics, DynamicsError};
use crate::engine::hybrid::phase::DriveValues;
use crate::engine::model::Model;
use crate::engine::singular_limit::{
    cholesky_solve, solve_limit_fixed, LimitSolveError, NULL_EIGENVALUE_REL_TOL,
};
use links::Assembled;
use nalgebra::{DVector, SMatrix, SVector};

mod chain;
mod links;
mod points;
mod three_link;
mod trig;
mod two_link;

use crate::engine::EvaluationPath;
pub use links::{LinkFrame, PlanarLinks, MAX_LINKS, MAX_PLANAR_COORDINATES};
pub(crate) use points::PlanarPoints;
pub use trig::sin_cos;

/// A small planar tree, ready for fast evaluations: built once from a [`Model`] that qualifies.
#[derive(Clone, Debug)]
pub struct PlanarTree {
    /// The links and bodies, evaluated by the link pass.
    links: PlanarLinks,
    /// The closed form of a two-link chain (the compass, the simplest walker), when the tree
    /// is one.
    two_link: Option<two_link::TwoLink>,
    /// The closed form of a three-link serial chain of finite bodies (kneed2d), when the tree
    /// is one.
    three_link: Option<three_link::ThreeLink>,
}

impl PlanarTree {
    /// The planar tree of `model`, or `None` when it does not qualify: more than
    /// `MAX_PLANAR_COORDINATES` coordinates or `MAX_LINKS` links, a prismatic joint, a revolute
    /// axis not along the floor's z axis, or gravity out of the x-y plane.
    pub fn of(model: &Model) -> Option<Self> {
        let links = PlanarLinks::of(model)?;
        Some(Self {
            two_link: two_link::TwoLink::of(&links),
            three_link: three_link::ThreeLink::of(&links),
            links,
        })
    }

    /// The planar tree `path` asks for: `None` for [`EvaluationPath::General`] (or when the
    /// model does not qualify), the link pass alone for [`EvaluationPath::LinkPass`], else
    /// [`Self::of`] (with the closed form when the tree has one).
    pub fn for_path(model: &Model, path: EvaluationPath) -> Option<Self> {
        match path {
            EvaluationPath::General => None,
            EvaluationPath::LinkPass => Self::of(model).map(Self::link_pass_only),
            EvaluationPath::Auto | EvaluationPath::GeneralLoop => Self::of(model),
        }
    }

    /// The same tree without its closed form: every evaluation by the link pass.
    pub fn link_pass_only(mut self) -> Self {
        self.two_link = None;
        self.three_link = None;
        self
    }

    /// Whether the tree evaluates by a closed form (a two-link chain: the compass, and the
    /// simplest walker with its vanishing-mass limit in closed form; a three-link serial chain
    /// of finite bodies: kneed2d) rather than by its link pass.
    pub fn has_closed_form(&self) -> bool {
        self.two_link.is_some() || self.three_link.is_some()
    }

    /// The links and bodies: their frames, Jacobians, springs and dampers.
    pub fn links(&self) -> &PlanarLinks {
        &self.links
    }

    /// Number of coordinates.
    pub fn dof(&self) -> usize {
        self.links.dof
    }

    /// Whether the tree has infinitesimal bodies (the vanishing-mass limit).
    pub fn has_infinitesimal(&self) -> bool {
        self.links.has_infinitesimal
    }

    /// `q̈` at `q`, `q̇` exactly as `crate::engine::hybrid::phase::accelerations` defines it (free,
    /// locked and driven coordinates). Models with infinitesimal bodies assemble here and solve
    /// their vanishing-mass limit in `limit` (the general workspace, its matrices overwritten).
    ///
    /// # Errors
    /// [`DynamicsError`]: a non-finite state or result, a singular reduced mass matrix.
    pub fn accelerations(
        &self,
        limit: &mut Dynamics,
        active: &[bool],
        drive: Option<&DriveValues<f64>>,
        q: &DVector<f64>,
        qd: &DVector<f64>,
    ) -> Result<DVector<f64>, DynamicsError> {
        let mut out = DVector::zeros(q.len());
        self.accelerations_into(limit, active, drive, q, qd, &mut out)?;
        Ok(out)
    }

    /// [`Self::accelerations`] written into `out` (no allocation for finite bodies).
    ///
    /// # Errors
    /// As [`Self::accelerations`]; also a state or `out` whose length is not the model's.
    pub fn accelerations_into(
        &self,
        limit: &mut Dynamics,
        active: &[bool],
        drive: Option<&DriveValues<f64>>,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        out: &mut DVector<f64>,
    ) -> Result<(), DynamicsError> {
        match self.links.dof {
            1 => self.accelerations_n::<1>(limit, active, drive, q, qd, out),
            2 => self.accelerations_n::<2>(limit, active, drive, q, qd, out),
            3 => self.accelerations_n::<3>(limit, active, drive, q, qd, out),
            4 => self.accelerations_n::<4>(limit, active, drive, q, qd, out),
            5 => self.accelerations_n::<5>(limit, active, drive, q, qd, out),
            _ => self.accelerations_n::<6>(limit, active, drive, q, qd, out),
        }
    }

    fn accelerations_n<const N: usize>(
        &self,
        limit: &mut Dynamics,
        active: &[bool],
        drive: Option<&DriveValues<f64>>,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        out: &mut DVector<f64>,
    ) -> Result<(), DynamicsError> {
        if q.len() != N || qd.len() != N || out.len() != N {
            return Err(DynamicsError::NonFinite);
        }
        let qs = SVector::<f64, N>::from_iterator(q.iter().copied());
        let qds = SVector::<f64, N>::from_iterator(qd.iter().copied());
        let qdd = self.accelerations_fixed(move || limit, active, drive, &qs, &qds)?;
        out.copy_from_slice(qdd.as_slice());
        Ok(())
    }

    /// [`Self::accelerations`] on fixed-size states (`N` must be [`Self::dof`]): the fixed-size
    /// stride's entry point. `limit` hands out the general workspace, asked for only when a
    /// model with infinitesimal bodies has a coordinate locked or driven.
    ///
    /// # Errors
    /// As [`Self::accelerations`]; also `N` or `active`'s length not the model's.
    pub fn accelerations_fixed<'d, const N: usize>(
        &self,
        limit: impl FnOnce() -> &'d mut Dynamics,
        active: &[bool],
        drive: Option<&DriveValues<f64>>,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
    ) -> Result<SVector<f64, N>, DynamicsError> {
        if drive.is_none() && active.iter().all(|&a| a) {
            if let Some(qdd) = self.free_closed_form(q, qd) {
                return Ok(qdd);
            }
        }
        if N != self.links.dof || active.len() != N {
            return Err(DynamicsError::NonFinite);
        }
        if q.iter().chain(qd.iter()).any(|v| !v.is_finite()) {
            return Err(DynamicsError::NonFinite);
        }
        let (mut qs, mut qds) = (*q, *qd);
        let mut qdd = SVector::<f64, N>::zeros();
        if let Some(d) = drive {
            qs[d.coordinate] = d.angle_rad;
            qds[d.coordinate] = d.rate_rad_s;
            qdd[d.coordinate] = d.acceleration_rad_s2;
        }
        let a = self.assemble::<N>(&qs, &qds);
        if self.links.has_infinitesimal && drive.is_none() && active.iter().all(|&a| a) {
            // Every coordinate free: the vanishing-mass limit on the fixed-size matrices.
            qdd = solve_limit_fixed(&a.m, &a.m_eps, &a.f, &a.f_eps, NULL_EIGENVALUE_REL_TOL)
                .map_err(DynamicsError::Singular)?;
        } else if self.links.has_infinitesimal {
            let limit = limit();
            limit.mass_matrix.copy_from(&a.m);
            limit.mass_matrix_infinitesimal.copy_from(&a.m_eps);
            limit.force.copy_from(&a.f);
            limit.force_infinitesimal.copy_from(&a.f_eps);
            let prescribed = drive.map(|_| DVector::from_iterator(N, qdd.iter().copied()));
            let solved = limit.solve_assembled_limit(active, prescribed.as_ref())?;
            if solved.len() != N {
                return Err(DynamicsError::NonFinite);
            }
            qdd = SVector::from_iterator(solved.iter().copied());
        } else {
            solve_active(&a.m, &a.f, active, &mut qdd)?;
        }
        if qdd.iter().any(|v| !v.is_finite()) {
            return Err(DynamicsError::NonFinite);
        }
        Ok(qdd)
    }

    /// `q̈` by the tree's closed form with every coordinate free and no drive (the two-link
    /// chain's, [`Self::has_closed_form`]), or `None` when it has none, `N` is not its size,
    /// or the result is not finite (a state that is not finite gives one that is not; then
    /// [`Self::accelerations_fixed`] reports the error): the fixed-size stride's shortcut,
    /// equal to [`Self::accelerations_fixed`] wherever it answers.
    #[inline]
    pub fn free_closed_form<const N: usize>(
        &self,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
    ) -> Option<SVector<f64, N>> {
        let qdd = match (&self.two_link, &self.three_link) {
            (Some(t), _) if N == 2 => t.free_accelerations(q, qd)?,
            (_, Some(t)) if N == 3 => {
                let a = t.assemble(q, qd);
                let (mut m, mut f) = (a.m, a.f);
                if !cholesky_solve(&mut m, &mut f) {
                    return None;
                }
                f
            }
            _ => return None,
        };
        qdd.iter().all(|v| v.is_finite()).then_some(qdd)
    }

    /// The mass matrix `M̄` at `q`, finite and infinitesimal parts (for the impacts of a
    /// fixed-size stride).
    pub fn mass_matrices<const N: usize>(
        &self,
        q: &SVector<f64, N>,
    ) -> (SMatrix<f64, N, N>, SMatrix<f64, N, N>) {
        let a = self.assemble::<N>(q, &SVector::zeros());
        (a.m, a.m_eps)
    }

    /// `M̄` and `f̄` at `q`, `q̇`, finite and infinitesimal parts: by the closed form when the
    /// tree has one, else by the link pass ([`PlanarLinks::assemble`]).
    fn assemble<const N: usize>(&self, q: &SVector<f64, N>, qd: &SVector<f64, N>) -> Assembled<N> {
        match (&self.two_link, &self.three_link) {
            (Some(t), _) if N == 2 => t.assemble(q, qd),
            (_, Some(t)) if N == 3 => t.assemble(q, qd),
            _ => self.links.assemble(q, qd),
        }
    }
}

/// Solves `M̄_aa q̈_a = f̄_a − M̄_ap q̈_p` for the active coordinates, writing them into `qdd`
/// (which holds the prescribed accelerations, zero when locked): a fixed-size Cholesky
/// factorisation of `M̄` with the rows and columns of the coordinates that are not free
/// replaced by the identity's, whose solution there is `q̈_p` itself.
fn solve_active<const N: usize>(
    m: &SMatrix<f64, N, N>,
    f: &SVector<f64, N>,
    active: &[bool],
    qdd: &mut SVector<f64, N>,
) -> Result<(), DynamicsError> {
    let mut reduced = *m;
    let mut b = *f;
    for j in (0..N).filter(|&j| !active[j]) {
        if qdd[j] != 0.0 {
            for i in 0..N {
                b[i] -= m[(i, j)] * qdd[j];
            }
        }
    }
    for j in (0..N).filter(|&j| !active[j]) {
        reduced.fill_row(j, 0.0);
        reduced.fill_column(j, 0.0);
        reduced[(j, j)] = 1.0;
        b[j] = qdd[j];
    }
    if !cholesky_solve(&mut reduced, &mut b) {
        return Err(DynamicsError::Singular(LimitSolveError::Degenerate {
            nullity: 1,
        }));
    }
    *qdd = b;
    Ok(())
}
