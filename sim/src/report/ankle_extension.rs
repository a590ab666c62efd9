//! The ankle extension as it actually happens in a stride: when the string engaged, when it was
//! released, how far the ankle got and how much of the profile ran.
//!
//! The actuator extends the stance ankle along its profile from the string's engagement
//! (docs/model.md, "The extension profile"), and releases the string at the other foot's heel
//! strike. When the heel strike comes before the profile's end, the push is cut short: the
//! ankle never reaches the profile's final angle. This record says by how much, from the
//! stride's own events and the state at the release (it never simulates).

use crate::engine::actuator::AnkleReflex;
use crate::stride::StrideResult;
use serde::Serialize;

/// Name of the string's engagement event in a stride's event list.
const ENGAGED: &str = "string_engaged";
/// Name of a release before heel strike (a controller's drive going slack).
const RELEASED: &str = "string_released";
/// Name of the heel strike, which releases the string when nothing did before.
const HEEL_STRIKE: &str = "heel_strike";

/// The stance ankle's extension in one stride (`ankle_extension` in `walker gait --json`).
/// Times are stride time: from the start of the stride, just after the previous heel strike.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AnkleExtension {
    /// When the string engaged and the profile started \[s\]; `null` if it never engaged (the
    /// ankle stayed free all stride, and the fractions below are 0).
    pub engaged_at_s: Option<f64>,
    /// When the string was released \[s\]: the other foot's heel strike (the end of the stride),
    /// or an earlier `string_released` event.
    pub released_at_s: f64,
    /// The stance ankle angle just before the release \[rad\] (the stride's state there).
    pub angle_at_release_rad: f64,
    /// The fraction of the profile's duration that had run at the release, in [0, 1]:
    /// `min(1, (released_at_s − engaged_at_s) / profile_duration_s)`.
    pub profile_fraction_completed: f64,
    /// The fraction of the profile's angle travelled at the release:
    /// `(angle_at_release_rad − engage) / (final − engage)` with the reflex's engagement and
    /// final angles (1 once the profile has ended).
    pub angle_fraction_completed: f64,
    /// The profile's duration \[s\] (`ankle_extension_duration_s`).
    pub profile_duration_s: f64,
    /// The profile's final angle \[rad\] (`ankle_final_rad`).
    pub final_angle_rad: f64,
}

/// Why a stride's record could not be read.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum AnkleExtensionError {
    /// The stride's event list has no release (no heel strike): not a completed stride.
    #[error("the stride has no heel strike or string release")]
    NoRelease,
    /// The stride's event states do not match its events (one pair per event).
    #[error("the stride has {events} events but {states} event states")]
    EventStatesMismatch {
        /// Number of events.
        events: usize,
        /// Number of (before, after) state pairs.
        states: usize,
    },
    /// The reflex's ankle coordinate is not in the stride's state.
    #[error("ankle coordinate {0} is outside the stride's state")]
    AnkleOutOfRange(usize),
}

impl AnkleExtension {
    /// The extension in `stride` of the stance ankle driven by `reflex`.
    pub fn of(reflex: &AnkleReflex, stride: &StrideResult) -> Result<Self, AnkleExtensionError> {
        let events = &stride.events;
        if events.len() != stride.event_states.len() {
            return Err(AnkleExtensionError::EventStatesMismatch {
                events: events.len(),
                states: stride.event_states.len(),
            });
        }
        let release = events
            .iter()
            .position(|e| e.name == RELEASED || e.name == HEEL_STRIKE)
            .ok_or(AnkleExtensionError::NoRelease)?;
        // The engagement that the release ends: the last one before it.
        let engaged_at_s = events[..release]
            .iter()
            .rev()
            .find(|e| e.name == ENGAGED)
            .map(|e| e.t_stride_s);
        let released_at_s = events[release].t_stride_s;
        let before = &stride.event_states[release].0;
        let a = reflex.ankle.0;
        let angle_at_release_rad = *before
            .q
            .get(a)
            .ok_or(AnkleExtensionError::AnkleOutOfRange(a))?;
        let (profile_fraction_completed, angle_fraction_completed) = match engaged_at_s {
            Some(t0) => (
                ((released_at_s - t0) / reflex.duration_s).clamp(0.0, 1.0),
                (angle_at_release_rad - reflex.engage_rad) / (reflex.final_rad - reflex.engage_rad),
            ),
            None => (0.0, 0.0),
        };
        Ok(Self {
            engaged_at_s,
            released_at_s,
            angle_at_release_rad,
            profile_fraction_completed,
            angle_fraction_completed,
            profile_duration_s: reflex.duration_s,
            final_angle_rad: reflex.final_rad,
        })
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
mod tests {
    use super::*;
    use crate::analysis::limit_cycle::NewtonSettings;
    use crate::scene::Scene;

    /// The minimum-jerk smooth step written out here, independently of the engine's profile:
    /// `s(x) = 10x³ − 15x⁴ + 6x⁵`.
    fn quintic(x: f64) -> f64 {
        let x = x.clamp(0.0, 1.0);
        x.powi(3) * (10.0 - 15.0 * x + 6.0 * x * x)
    }

    fn table_one_gait() -> (
        Scene,
        crate::scene::Setup,
        crate::analysis::limit_cycle::Gait,
    ) {
        let scene = Scene::load("wisse3d").unwrap();
        let setup = scene.setup().unwrap();
        let gait = setup.find_gait(&NewtonSettings::default()).unwrap();
        (scene, setup, gait)
    }

    #[test]
    fn table_one_push_is_cut_by_heel_strike() {
        let (scene, setup, gait) = table_one_gait();
        let reflex = setup.walker.ankle().unwrap();
        let x = AnkleExtension::of(reflex, &gait.stride).unwrap();
        // The profile from the scene's parameters (Table I: -0.08 to 0.2 rad).
        let (from, to, d) = (
            scene.values["ankle_engage_rad"],
            scene.values["ankle_final_rad"],
            scene.values["ankle_extension_duration_s"],
        );
        assert_eq!((from, to), (-0.08, 0.2));
        // Independently: the event times from the event list by name, the angle from the state
        // just before heel strike (`pre_impact`), the profile evaluated by hand.
        let time = |name: &str| {
            gait.stride
                .events
                .iter()
                .find(|e| e.name == name)
                .map(|e| e.t_stride_s)
                .unwrap()
        };
        let (t0, t1) = (time("string_engaged"), time("heel_strike"));
        assert_eq!(x.engaged_at_s, Some(t0));
        assert_eq!(x.released_at_s, t1);
        assert_eq!(t1, gait.stride.duration_s);
        let pre = gait.stride.pre_impact.q[reflex.ankle.0];
        assert_eq!(x.angle_at_release_rad, pre);
        // The drive holds the ankle on the profile: the state's angle is the quintic's.
        let elapsed = t1 - t0;
        let by_hand = from + (to - from) * quintic(elapsed / d);
        assert!(
            (pre - by_hand).abs() < 1e-9,
            "ankle {pre} vs quintic {by_hand}"
        );
        assert!((x.profile_fraction_completed - elapsed / d).abs() < 1e-15);
        assert!((x.angle_fraction_completed - quintic(elapsed / d)).abs() < 1e-8);
        // The push is cut: released before the profile's end, short of 0.2 rad.
        assert!(x.profile_fraction_completed < 1.0, "{x:?}");
        assert!(x.angle_at_release_rad < to - 1e-3, "{x:?}");
        assert!(elapsed < d, "{elapsed} of {d}");
    }

    #[test]
    fn a_short_profile_completes_before_heel_strike() {
        let (_, setup, gait) = table_one_gait();
        let mut reflex = setup.walker.ankle().cloned().unwrap();
        // The same stride read with a profile shorter than the push: complete, at the end.
        let t0 = gait
            .stride
            .events
            .iter()
            .find(|e| e.name == "string_engaged")
            .unwrap()
            .t_stride_s;
        reflex.duration_s = (gait.stride.duration_s - t0) / 2.0;
        let x = AnkleExtension::of(&reflex, &gait.stride).unwrap();
        assert_eq!(x.profile_fraction_completed, 1.0);
    }

    #[test]
    fn a_stride_without_release_is_refused() {
        let (_, setup, mut gait) = table_one_gait();
        let reflex = setup.walker.ankle().unwrap();
        gait.stride.events.pop();
        gait.stride.event_states.pop();
        assert_eq!(
            AnkleExtension::of(reflex, &gait.stride),
            Err(AnkleExtensionError::NoRelease)
        );
        gait.stride.event_states.pop();
        assert!(matches!(
            AnkleExtension::of(reflex, &gait.stride),
            Err(AnkleExtensionError::EventStatesMismatch { .. })
        ));
    }
}
