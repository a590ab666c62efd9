//! The accelerations of one smooth phase: some coordinates free, some locked, at most one
//! driven along a prescribed angle, in any scalar.

use crate::engine::dynamics::{Dynamics, DynamicsError, DynamicsOf};
use crate::engine::model::Model;
use nalgebra::{DVector, RealField};
use num_dual::DualSVec64;

/// A scalar the hybrid core runs on: `f64` (the engine) or dual numbers (the variational
/// equations). The one scalar-specific step is the acceleration solve.
pub trait EngineScalar: RealField + Copy {
    /// `q̈` at `q`, `q̇` with the coordinates where `active` is false given by
    /// `qdd_prescribed` (zero if `None`), as [`Dynamics::accelerations`]. Assembles first.
    ///
    /// # Errors
    /// [`DynamicsError`]: a singular reduced mass matrix or a non-finite state.
    fn solve_accelerations(
        dynamics: &mut DynamicsOf<Self>,
        model: &Model,
        q: &DVector<Self>,
        qd: &DVector<Self>,
        active: &[bool],
        qdd_prescribed: Option<&DVector<Self>>,
    ) -> Result<DVector<Self>, DynamicsError>;
}

impl EngineScalar for f64 {
    /// Finite masses, and the vanishing-mass limit of infinitesimal bodies.
    fn solve_accelerations(
        dynamics: &mut Dynamics,
        model: &Model,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        active: &[bool],
        qdd_prescribed: Option<&DVector<f64>>,
    ) -> Result<DVector<f64>, DynamicsError> {
        dynamics.accelerations(model, q, qd, active, qdd_prescribed)
    }
}

impl<const N: usize> EngineScalar for DualSVec64<N> {
    /// Finite masses only (models with infinitesimal bodies are an error).
    fn solve_accelerations(
        dynamics: &mut DynamicsOf<Self>,
        model: &Model,
        q: &DVector<Self>,
        qd: &DVector<Self>,
        active: &[bool],
        qdd_prescribed: Option<&DVector<Self>>,
    ) -> Result<DVector<Self>, DynamicsError> {
        dynamics.accelerations_finite(model, q, qd, active, qdd_prescribed)
    }
}

/// A driven coordinate's prescribed motion at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DriveValues<T> {
    /// The driven coordinate (an index into `q`).
    pub coordinate: usize,
    /// Its angle \[rad\].
    pub angle_rad: T,
    /// Its rate [rad/s].
    pub rate_rad_s: T,
    /// Its acceleration [rad/s²].
    pub acceleration_rad_s2: T,
}

/// `q̈` [rad/s² or m/s²] of a phase at `q`, `q̇`: the coordinates where `active` is true are
/// free, the others locked (zero acceleration) except the `drive`n one, which is put on its
/// prescribed angle and rate and moves with its prescribed acceleration.
///
/// # Errors
/// [`DynamicsError`]: a singular reduced mass matrix or a non-finite state.
pub fn accelerations<T: EngineScalar>(
    model: &Model,
    dynamics: &mut DynamicsOf<T>,
    active: &[bool],
    drive: Option<&DriveValues<T>>,
    q: &DVector<T>,
    qd: &DVector<T>,
) -> Result<DVector<T>, DynamicsError> {
    match drive {
        None => T::solve_accelerations(dynamics, model, q, qd, active, None),
        Some(d) => {
            let (mut q, mut qd) = (q.clone(), qd.clone());
            q[d.coordinate] = d.angle_rad;
            qd[d.coordinate] = d.rate_rad_s;
            let mut qdd_p = DVector::zeros(q.len());
            qdd_p[d.coordinate] = d.acceleration_rad_s2;
            T::solve_accelerations(dynamics, model, &q, &qd, active, Some(&qdd_p))
        }
    }
}
