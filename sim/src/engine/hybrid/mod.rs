//! The rules a scene states and the hybrid core written once over the scalar: the pieces of
//! the stride that both the `f64` engine ([`crate::stride`], [`crate::engine::impact`],
//! [`crate::engine::relabel`]) and the variational Jacobian ([`crate::analysis::variational`], on dual numbers)
//! evaluate. A leaf: it depends on the model and the engine's numerics (kinematics, dynamics,
//! the vanishing-mass limit, `math`) only; the walker, the actuator and the relabelling solve
//! depend on it, never the other way.
//!
//! - [`heel_strike`]: the heel-strike rule and the contact constraints it imposes;
//! - [`profile`]: the ideal ankle drive's [`profile::AnkleProfile`] and its smooth extension
//!   (angle, rate, acceleration);
//! - [`phase`]: the accelerations of a smooth phase with an optional driven coordinate;
//! - [`impact`]: the impact equations (19)-(21) for finite masses;
//! - [`contact_rows`]: the heel-strike constraint rows on the released impact model;
//! - [`relabel`]: the relabelling rule ([`relabel::Relabel`]) and its geometry (old link states at the new contact, the
//!   sagittal mirroring, the matched rows and their Jacobian).
//!
//! Everything here is generic over `T: RealField + Copy` (`f64`, or `num_dual` dual numbers
//! that carry derivatives); the only scalar-specific step, the acceleration solve (the `f64`
//! engine also solves the vanishing-mass limit), is the [`EngineScalar`] trait.

pub mod contact_rows;
pub mod heel_strike;
pub mod impact;
pub mod phase;
pub mod profile;
pub mod relabel;

pub use phase::EngineScalar;

/// A model constant (an `f64`) in the scalar `T`.
pub(crate) fn konst<T: nalgebra::RealField + Copy>(x: f64) -> T {
    nalgebra::convert(x)
}
