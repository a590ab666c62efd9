//! The ideal ankle drive's extension profile (paper Fig. 8): the quintic smooth step of the
//! `ankle-profile` crate (the one the firmware's push setpoint follows), in any scalar.

use super::konst;
use crate::actuator::AnkleProfile;
use nalgebra::RealField;

/// Angle \[rad\], rate [rad/s] and acceleration [rad/s²] of `profile` at time `t_s` \[s\] for an
/// extension started at `start_s` \[s\] (which may differ from `profile.start_s`: the variational
/// code gives the start its own sensitivity). Before the start the angle is `from_rad`, after
/// the end `to_rad`, both at rest.
pub fn extension<T: RealField + Copy>(profile: &AnkleProfile, t_s: T, start_s: T) -> (T, T, T) {
    let lift = |c: f32| konst::<T>(f64::from(c));
    let sample = ankle_profile::Extension {
        from: konst::<T>(profile.from_rad),
        to: konst::<T>(profile.to_rad),
        duration: konst::<T>(profile.duration_s),
    }
    .sample(t_s - start_s, lift);
    (sample.angle, sample.rate, sample.acceleration)
}
