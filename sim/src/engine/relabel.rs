//! After heel strike the swing foot becomes the stance contact: the state is re-expressed in the
//! same model with legs swapped (and, for 3D scenes, mirrored about the sagittal plane, eq. 22).
//!
//! This is done geometrically, not by a hand-written coordinate map: the old links' floor poses
//! and velocities are moved to the new contact point, optionally reflected (z → −z), and each
//! new link named in the correspondence is made to match its old twin by Gauss-Newton on the
//! joint coordinates (positions) and a least-squares solve (velocities). The residuals are
//! checked, so an inconsistent correspondence is an error, not a silent wrong state.

use crate::engine::hybrid::relabel::{pose_jacobian, pose_residual, row_count, RelabelTargets};
pub use crate::engine::hybrid::relabel::{LinkStatesOf, Relabel};
use crate::engine::kinematics::Kinematics;
use crate::engine::model::Model;
use nalgebra::{DMatrix, DVector};

/// Why the new coordinates could not be found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RelabelError {
    /// The poses could not be matched: the correspondence is inconsistent with the model.
    #[error("relabelled poses do not match the model (residual {residual:e} after {iterations} iterations)")]
    PoseMismatch {
        /// Final residual norm.
        residual: f64,
        /// Iterations used.
        iterations: usize,
    },
    /// The velocities could not be matched.
    #[error("relabelled velocities do not match the model (residual {residual:e})")]
    VelocityMismatch {
        /// Residual norm.
        residual: f64,
    },
}

/// Poses and velocities of every link of a model, in the floor frame (`f64`).
pub type LinkStates = LinkStatesOf<f64>;

/// The relabelled state.
#[derive(Clone, Debug, PartialEq)]
pub struct Relabelled {
    /// Coordinates in the new labelling (cyclic ones zeroed).
    pub q: DVector<f64>,
    /// Velocities in the new labelling.
    pub qd: DVector<f64>,
    /// Values the cyclic coordinates had before zeroing \[rad\].
    pub cyclic_values: Vec<f64>,
    /// Gauss-Newton iterations used.
    pub iterations: usize,
}

impl Relabel {
    /// Finds `q`, `q̇` of `model` whose paired links and points match `old` (translated to the
    /// new contact, not yet mirrored: the mirroring is done here), starting at `q_guess`.
    pub fn solve(
        &self,
        model: &Model,
        old: &LinkStates,
        q_guess: &DVector<f64>,
    ) -> Result<Relabelled, RelabelError> {
        let n = model.dof();
        let rows = row_count(self);
        let mut kin = Kinematics::new(model);
        let zero = DVector::zeros(n);
        let mut q = q_guess.clone();
        for c in &self.fixed {
            q[c.0] = 0.0;
        }
        let mut jac = DMatrix::zeros(rows, n);
        let mut res = DVector::zeros(rows);
        let mut iterations = 0;
        let targets = RelabelTargets::new(self, model, old);
        loop {
            kin.update(model, &q, &zero);
            pose_residual(self, model, &kin, &targets, &mut res);
            pose_jacobian(self, model, &kin, &mut jac);
            let r = res.norm();
            if r <= self.tolerance {
                break;
            }
            if iterations >= self.max_iterations || !r.is_finite() {
                if std::env::var_os("WALKER_DEBUG_RELABEL").is_some() {
                    eprintln!(
                        "relabel residual {:?}\nq {:?}",
                        res.as_slice(),
                        q.as_slice()
                    );
                }
                return Err(RelabelError::PoseMismatch {
                    residual: r,
                    iterations,
                });
            }
            let dq = least_squares(&jac, &res);
            q += dq;
            iterations += 1;
        }
        // Velocities: J q̇ = [ω of old twins; v of old points] (jac is at the solution).
        let target = targets.velocity_target();
        let qd = least_squares(&jac, &target);
        let vres = (&jac * &qd - &target).norm();
        if vres > 1e-8 * (1.0 + target.norm()) {
            if std::env::var_os("WALKER_DEBUG_RELABEL").is_some() {
                eprintln!(
                    "relabel velocity residual {:?}",
                    (&jac * &qd - &target).as_slice()
                );
            }
            return Err(RelabelError::VelocityMismatch { residual: vres });
        }
        let mut cyclic_values = Vec::with_capacity(self.cyclic.len());
        for c in &self.cyclic {
            cyclic_values.push(q[c.0]);
            q[c.0] = 0.0;
        }
        Ok(Relabelled {
            q,
            qd,
            cyclic_values,
            iterations,
        })
    }
}

fn least_squares(a: &DMatrix<f64>, b: &DVector<f64>) -> DVector<f64> {
    let svd = a.clone().svd(true, true);
    let tol = 1e-12 * svd.singular_values.max().max(1e-300);
    svd.solve(b, tol)
        .unwrap_or_else(|_| DVector::zeros(a.ncols()))
}
