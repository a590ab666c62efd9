//! The ideal ankle drive's extension profile (paper Fig. 8): a quintic smooth step with zero
//! rate and acceleration at both ends, in any scalar.

use super::konst;
use crate::actuator::AnkleProfile;
use nalgebra::RealField;

/// Angle [rad], rate [rad/s] and acceleration [rad/s²] of `profile` at time `t_s` [s] for an
/// extension started at `start_s` [s] (which may differ from `profile.start_s`: the variational
/// code gives the start its own sensitivity). Before the start the angle is `from_rad`, after
/// the end `to_rad`, both at rest.
pub fn extension<T: RealField + Copy>(profile: &AnkleProfile, t_s: T, start_s: T) -> (T, T, T) {
    let d: T = konst(profile.duration_s);
    let x = (t_s - start_s) / d;
    if x <= T::zero() {
        return (konst(profile.from_rad), T::zero(), T::zero());
    }
    if x >= T::one() {
        return (konst(profile.to_rad), T::zero(), T::zero());
    }
    let span: T = konst(profile.to_rad - profile.from_rad);
    let one = T::one();
    let (x2, x3) = (x * x, x * x * x);
    let s = x3 * (konst::<T>(10.0) - konst::<T>(15.0) * x + konst::<T>(6.0) * x2);
    let ds = konst::<T>(30.0) * x2 * (one - x) * (one - x);
    let dds = konst::<T>(60.0) * x * (one - x) * (one - konst::<T>(2.0) * x);
    (
        konst::<T>(profile.from_rad) + span * s,
        span * ds / d,
        span * dds / (d * d),
    )
}
