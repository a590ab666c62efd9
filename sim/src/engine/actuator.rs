//! The ankle stretch reflex with an ideal actuator (paper Fig. 8, `docs/model.md`).
//!
//! While the string is slack the ankle is free and the foot flat. When the ankle angle falls to
//! the engagement angle the string is taut: an inelastic impact stops the ankle, the foot starts
//! to pivot about its toe, and the actuator drives the ankle angle along a smooth profile to its
//! final angle, then holds it. The actuator releases at the other foot's heel strike, when this
//! leg becomes the swing leg (whose massless foot is not modelled).

pub use crate::engine::hybrid::profile::AnkleProfile;
use crate::engine::model::{CoordIndex, PointIndex};
use serde::Serialize;

/// The reflex of the stance ankle, as a scene describes it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AnkleReflex {
    /// The ankle coordinate (leg pitch relative to the foot; negative with the hip ahead).
    #[serde(skip)]
    pub ankle: CoordIndex,
    /// The foot's pitch about its toe (0 while flat, negative with the heel up).
    #[serde(skip)]
    pub toe_pitch: CoordIndex,
    /// The toe point (the contact during push-off).
    #[serde(skip)]
    pub toe: PointIndex,
    /// Ankle angle at which the string becomes taut \[rad\].
    pub engage_rad: f64,
    /// Ankle angle the actuator extends to \[rad\].
    pub final_rad: f64,
    /// Duration of the extension \[s\].
    pub duration_s: f64,
}

impl AnkleReflex {
    /// The ideal actuator's extension started at `start_s` (stride time \[s\], the string's
    /// engagement): from the engagement angle to the final angle over the reflex's duration.
    pub fn extension_from(&self, start_s: f64) -> AnkleProfile {
        AnkleProfile {
            start_s,
            duration_s: self.duration_s,
            from_rad: self.engage_rad,
            to_rad: self.final_rad,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profile_is_smooth_and_reaches_its_end() {
        let p = AnkleProfile {
            start_s: 1.0,
            duration_s: 0.2,
            from_rad: -0.08,
            to_rad: 0.2,
        };
        assert_eq!(p.eval(0.5), (-0.08, 0.0, 0.0));
        assert_eq!(p.eval(1.3), (0.2, 0.0, 0.0));
        // Rate is the derivative of the angle, acceleration of the rate.
        let h = 1e-6;
        for t in [1.03, 1.1, 1.17] {
            let (a0, v0, acc0) = p.eval(t);
            let (ap, vp, _) = p.eval(t + h);
            let (am, vm, _) = p.eval(t - h);
            assert!(((ap - am) / (2.0 * h) - v0).abs() < 1e-6);
            assert!(((vp - vm) / (2.0 * h) - acc0).abs() < 1e-4);
            assert!(a0 > -0.08 && a0 < 0.2);
        }
    }
}
