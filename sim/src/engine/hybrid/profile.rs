//! The ideal ankle drive's extension profile (paper Fig. 8): the quintic smooth step of the
//! `ankle-profile` crate (the one the firmware's push setpoint follows), in any scalar.

use super::konst;
use nalgebra::RealField;

/// A prescribed ankle angle: a quintic smooth step (zero rate and acceleration at both ends)
/// from `from_rad` at `start_s` to `to_rad` at `start_s + duration_s`, held after.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AnkleProfile {
    /// Start time \[s\].
    pub start_s: f64,
    /// Duration \[s\].
    pub duration_s: f64,
    /// Start angle \[rad\].
    pub from_rad: f64,
    /// Final angle \[rad\].
    pub to_rad: f64,
}

impl AnkleProfile {
    /// Angle \[rad\], rate [rad/s] and acceleration [rad/s²] at `t_s`.
    pub fn eval(&self, t_s: f64) -> (f64, f64, f64) {
        extension(self, t_s, self.start_s)
    }
}

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
