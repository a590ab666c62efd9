//! Reflex parameters: a read-only set of checked values, changed only through [`ReflexParams::set`].

use protocol::{ParamId, ParamStatus, ParamValue};

/// Stretch-reflex parameters. Each field's range and default are those of its
/// [`ParamId`] (see `docs/protocol.md`); the fields are private so that a value out of range
/// or inconsistent with another can never be in force.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ReflexParams {
    taut_angle_rad: f32,
    extended_angle_rad: f32,
    push_duration_s: f32,
    max_push_rate_rad_per_s: f32,
    peer_heartbeat_timeout_s: f32,
    max_angular_rate_rad_per_s: f32,
    stuck_timeout_s: f32,
}

impl Default for ReflexParams {
    fn default() -> Self {
        ReflexParams {
            taut_angle_rad: ParamId::TautAngle.default_si(),
            extended_angle_rad: ParamId::ExtendedAngle.default_si(),
            push_duration_s: ParamId::PushDuration.default_si(),
            max_push_rate_rad_per_s: ParamId::MaxPushRate.default_si(),
            peer_heartbeat_timeout_s: ParamId::PeerHeartbeatTimeout.default_si(),
            max_angular_rate_rad_per_s: ParamId::MaxAngularRate.default_si(),
            stuck_timeout_s: ParamId::StuckTimeout.default_si(),
        }
    }
}

/// Smallest allowed gap between the taut and the extended angle \[rad\].
pub const MIN_EXTENSION_RAD: f32 = 0.05;

/// Mechanical range of the ankle: an angle beyond ±this is an encoder fault \[rad\].
pub const ANKLE_ANGLE_LIMIT_RAD: f32 = 1.0;

impl ReflexParams {
    /// Ankle angle at which the string becomes taut \[rad\] (paper: −0.08).
    pub fn taut_angle_rad(&self) -> f32 {
        self.taut_angle_rad
    }
    /// Ankle angle the actuator extends to \[rad\] (paper: 0.2).
    pub fn extended_angle_rad(&self) -> f32 {
        self.extended_angle_rad
    }
    /// Nominal duration of the extension profile \[s\].
    pub fn push_duration_s(&self) -> f32 {
        self.push_duration_s
    }
    /// Bound on the profile's angular rate [rad/s].
    pub fn max_push_rate_rad_per_s(&self) -> f32 {
        self.max_push_rate_rad_per_s
    }
    /// Peer declared lost after this long without a heartbeat \[s\].
    pub fn peer_heartbeat_timeout_s(&self) -> f32 {
        self.peer_heartbeat_timeout_s
    }
    /// Plausibility limit on the measured angular rate [rad/s].
    pub fn max_angular_rate_rad_per_s(&self) -> f32 {
        self.max_angular_rate_rad_per_s
    }
    /// Encoder declared stuck after this long without change while pushing \[s\].
    pub fn stuck_timeout_s(&self) -> f32 {
        self.stuck_timeout_s
    }

    /// Value of one parameter [its SI unit].
    pub fn get(&self, id: ParamId) -> f32 {
        match id {
            ParamId::TautAngle => self.taut_angle_rad,
            ParamId::ExtendedAngle => self.extended_angle_rad,
            ParamId::PushDuration => self.push_duration_s,
            ParamId::MaxPushRate => self.max_push_rate_rad_per_s,
            ParamId::PeerHeartbeatTimeout => self.peer_heartbeat_timeout_s,
            ParamId::MaxAngularRate => self.max_angular_rate_rad_per_s,
            ParamId::StuckTimeout => self.stuck_timeout_s,
        }
    }

    /// The wire value of one parameter.
    pub fn wire_value(&self, id: ParamId) -> ParamValue {
        ParamValue::saturating_from_si(self.get(id))
    }

    /// Set one parameter from its wire value; on any error the old value stays.
    ///
    /// # Errors
    /// [`ParamStatus::OutOfRange`] outside the parameter's range,
    /// [`ParamStatus::Inconsistent`] when the extended angle would not exceed the taut angle
    /// by [`MIN_EXTENSION_RAD`].
    pub fn set(&mut self, id: ParamId, value: ParamValue) -> Result<(), ParamStatus> {
        let v = id
            .check(value.to_si())
            .map_err(|_| ParamStatus::OutOfRange)?;
        let mut next = *self;
        match id {
            ParamId::TautAngle => next.taut_angle_rad = v,
            ParamId::ExtendedAngle => next.extended_angle_rad = v,
            ParamId::PushDuration => next.push_duration_s = v,
            ParamId::MaxPushRate => next.max_push_rate_rad_per_s = v,
            ParamId::PeerHeartbeatTimeout => next.peer_heartbeat_timeout_s = v,
            ParamId::MaxAngularRate => next.max_angular_rate_rad_per_s = v,
            ParamId::StuckTimeout => next.stuck_timeout_s = v,
        }
        if next.extended_angle_rad - next.taut_angle_rad < MIN_EXTENSION_RAD {
            return Err(ParamStatus::Inconsistent);
        }
        *self = next;
        Ok(())
    }

    /// Duration of the extension profile actually used \[s\]: the nominal duration, stretched
    /// so that the minimum-jerk profile's peak rate (1.875 × extension / duration) stays
    /// within [`Self::max_push_rate_rad_per_s`] ([`ankle_profile::duration_within_rate`]).
    pub fn effective_push_duration_s(&self) -> f32 {
        ankle_profile::duration_within_rate(
            self.extended_angle_rad - self.taut_angle_rad,
            self.push_duration_s,
            self.max_push_rate_rad_per_s,
            |c| c,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wire(id: ParamId, v: f32) -> ParamValue {
        ParamValue::from_si(v).unwrap_or_else(|_| panic!("{id:?}"))
    }

    #[test]
    fn defaults_match_the_paper() {
        let p = ReflexParams::default();
        assert_eq!(p.taut_angle_rad(), -0.08);
        assert_eq!(p.extended_angle_rad(), 0.2);
        for id in ParamId::ALL {
            assert_eq!(p.get(*id), id.default_si());
        }
    }

    #[test]
    fn set_checks_range_and_consistency() {
        let mut p = ReflexParams::default();
        assert_eq!(
            p.set(ParamId::PushDuration, wire(ParamId::PushDuration, 0.2)),
            Ok(())
        );
        assert!((p.push_duration_s() - 0.2).abs() < 1e-6);
        assert_eq!(
            p.set(ParamId::PushDuration, wire(ParamId::PushDuration, 5.0)),
            Err(ParamStatus::OutOfRange)
        );
        assert!((p.push_duration_s() - 0.2).abs() < 1e-6, "old value stays");
        // Extended 0.0 with taut -0.08 leaves 0.08 > 0.05: fine; taut 0.0 then is not.
        assert_eq!(
            p.set(ParamId::ExtendedAngle, wire(ParamId::ExtendedAngle, 0.0)),
            Ok(())
        );
        assert_eq!(
            p.set(ParamId::TautAngle, wire(ParamId::TautAngle, -0.01)),
            Err(ParamStatus::Inconsistent)
        );
        assert_eq!(p.taut_angle_rad(), -0.08);
    }

    #[test]
    fn profile_duration_respects_rate_bound() {
        let mut p = ReflexParams::default();
        // 1.875 * 0.28 / 4.0 = 0.13125 < 0.27: the default rate bound does not stretch the
        // default duration.
        assert_eq!(p.effective_push_duration_s(), 0.27);
        assert_eq!(p.effective_push_duration_s(), p.push_duration_s());
        p.set(ParamId::MaxPushRate, wire(ParamId::MaxPushRate, 1.0))
            .unwrap();
        assert!((p.effective_push_duration_s() - 0.525).abs() < 1e-6);
    }
}
