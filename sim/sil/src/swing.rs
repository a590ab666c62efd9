//! The swing ankle's reading: the swing foot is massless and not in the model, so its ankle
//! angle is not simulated; a [`SwingAnkleModel`] says what its encoder reads instead.

use serde::Serialize;

/// What the swing ankle's encoder reads. The swing foot is massless and not in the model, so
/// its ankle angle is not simulated.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum SwingAnkleModel {
    /// A fixed angle \[rad\]. A step between this and the stance angle at every heel strike
    /// and lift-off: with 0 rad and the stance ankle at 0.2 rad that is 200 rad/s at 1 kHz,
    /// which trips the firmware's 40 rad/s plausibility check (`EncoderRate`) every stride.
    Fixed {
        /// The angle \[rad\].
        angle_rad: f64,
    },
    /// From its angle at lift-off, the ankle moves at `rate_rad_per_s` towards the angle this
    /// foot last landed at (the other foot's until it has landed once), so that on a periodic
    /// gait (period one or two strides) the reading is continuous when it lands again.
    ToLandingAngle {
        /// Rate of the move [rad/s].
        rate_rad_per_s: f64,
    },
}

impl Default for SwingAnkleModel {
    /// `ToLandingAngle` at 2 rad/s: 0.3 rad in 0.15 s, a twentieth of the plausibility
    /// limit.
    fn default() -> Self {
        SwingAnkleModel::ToLandingAngle {
            rate_rad_per_s: 2.0,
        }
    }
}

/// The swing ankle's angle: the swing foot is massless and not in the model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SwingAnkle {
    model: SwingAnkleModel,
    angle_rad: f64,
    last_t_s: f64,
}

impl SwingAnkle {
    /// A swing ankle at `angle_rad` at `t_s`.
    pub fn new(model: SwingAnkleModel, t_s: f64, angle_rad: f64) -> Self {
        SwingAnkle {
            model,
            angle_rad,
            last_t_s: t_s,
        }
    }

    /// The angle at `t_s` given the landing angle of the last heel strike \[rad\].
    pub fn angle_at(&mut self, t_s: f64, landing_rad: f64) -> f64 {
        let dt = (t_s - self.last_t_s).max(0.0);
        self.last_t_s = t_s;
        self.angle_rad = match self.model {
            SwingAnkleModel::Fixed { angle_rad } => angle_rad,
            SwingAnkleModel::ToLandingAngle { rate_rad_per_s } => {
                let step = rate_rad_per_s.abs() * dt;
                self.angle_rad + (landing_rad - self.angle_rad).clamp(-step, step)
            }
        };
        self.angle_rad
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn swing_ankle_moves_at_a_bounded_rate() {
        let m = SwingAnkleModel::ToLandingAngle {
            rate_rad_per_s: 2.0,
        };
        let mut s = SwingAnkle::new(m, 0.0, 0.2);
        assert!((s.angle_at(0.001, -0.1) - 0.198).abs() < 1e-12);
        assert!((s.angle_at(1.0, -0.1) + 0.1).abs() < 1e-12);
        let mut f = SwingAnkle::new(SwingAnkleModel::Fixed { angle_rad: 0.0 }, 0.0, 0.2);
        assert_eq!(f.angle_at(0.001, 0.3), 0.0);
    }
}
