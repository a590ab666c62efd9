//! Sensor plausibility across the whole stride: what the contact switch, the spool encoder,
//! the other foot's heel strikes and the swing under the ankle spring imply about the ankle
//! reading, and what the ankle reading implies about the contact switch and the spool.
//!
//! [`crate::sensors::Plausibility`] decides *that* a reading did not change over the stuck
//! timeout; this module decides *when the ankle must have moved*
//! ([`StrideCheck::ankle_expected_to_move`]) and checks the other two sensors:
//!
//! | phase | the ankle must move because |
//! | --- | --- |
//! | `Swing` | the ankle spring returns the swing foot to its rest angle (the angle it last landed at): while the reading is more than [`SWING_REST_BAND_RAD`] from it |
//! | `Free` | after an own heel strike, with the contact closed, the stance leg rotates over the foot (the nominal walk turns the ankle by a count every millisecond) |
//! | `Push` | the setpoint profile moves it |
//! | `Hold` | in ticks where the spool turned (the taut string moved it) |
//!
//! The contact switch (`ContactStuck`, detail 1 closed, 2 open):
//! * closed: still closed `StuckTimeout` after the other foot's heel strike released this
//!   ankle (the trailing foot must lift), or closed again less than [`MIN_SWING_S`] after the
//!   own lift-off (no swing is that short);
//! * open: in a swing, the reading moving *away* from the foot's rest angle by more than
//!   [`SWING_REST_BAND_RAD`] beyond the closest it came in that swing (the spring returns a
//!   swinging foot; only the floor turns the ankle away), or the other foot's heel strike
//!   arriving again while this ankle is still in the swing its previous one began.
//!
//! The spool encoder (`SpoolStuck`): in `Push` and `Hold` only the string winding in extends
//! the ankle, so an ankle reading that rises more than [`SPOOL_SILENT_ANKLE_COUNTS`] while the
//! spool reports no motion means the spool encoder stopped.
//!
//! Each finding stays until its sensor shows the contradiction is gone (the switch changes,
//! the spool turns), also after the node left `Enabled`. Constant work per tick.

use protocol::ReflexPhase;

use crate::reflex::{ReflexEvent, ReleaseCause};
use crate::sensors::AngleSample;
use crate::time::Instant;

/// Half-width of the swing foot's rest band about the angle it last landed at \[rad\]: the
/// spring holds a swinging foot within it once returned. 0.03 rad (79 counts): the nominal
/// walk's swing readings stay within 0.02 rad of the landing angle once returned
/// (docs/firmware.md).
pub const SWING_REST_BAND_RAD: f32 = 0.03;

/// Shortest swing the walker can make \[s\]: an own heel strike sooner than this after the
/// own lift-off is a contact switch that closed by itself. 0.2 s, a quarter of the nominal
/// 0.8 s stride.
pub const MIN_SWING_S: f32 = 0.2;

/// Ankle extension \[counts\] while the spool reports no motion, in push or hold, above
/// which the spool encoder is taken as stopped. 16 counts (6.1 mrad); the nominal walks'
/// largest is 0.4 counts (docs/firmware.md).
pub const SPOOL_SILENT_ANKLE_COUNTS: u16 = 16;

/// One count of the ankle encoder \[rad\].
const COUNT_RAD: f32 = core::f32::consts::TAU / crate::sensors::ENCODER_COUNTS_PER_REV as f32;

/// `ContactStuck` detail: the switch reads closed where the foot must be in the air.
pub const CONTACT_STUCK_CLOSED: i16 = 1;
/// `ContactStuck` detail: the switch reads open where the foot must be on the floor.
pub const CONTACT_STUCK_OPEN: i16 = 2;

/// What one tick of the node tells the stride check (the phase is the one the tick started
/// in: the reflex has not stepped yet).
#[derive(Clone, Copy, Debug)]
pub struct StrideInputs {
    /// Time of the tick.
    pub now: Instant,
    /// The reflex phase the tick started in.
    pub phase: ReflexPhase,
    /// This tick's good reading, if any.
    pub sample: Option<AngleSample>,
    /// Debounced contact switch: true when it reads the foot on the floor.
    pub contact_closed: bool,
    /// The spool turned in the last tick (`DriverHealth::string_moving`).
    pub string_moving: bool,
    /// The actuator has a spool sensor (`DriverHealth::spool_sensor`); without one the spool
    /// is not checked.
    pub spool_sensor: bool,
    /// The other ankle's `HeelStrike` arrived this tick.
    pub peer_heel_strike: bool,
}

/// What the stride check found in one tick: `Some(detail)` per fault.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StrideFindings {
    /// `ContactStuck` ([`CONTACT_STUCK_CLOSED`] or [`CONTACT_STUCK_OPEN`]).
    pub contact: Option<i16>,
    /// `SpoolStuck` (ankle counts moved while the spool stood still).
    pub spool: Option<i16>,
}

/// The stride's expectations, from one reflex event to the next.
#[derive(Clone, Copy, Debug, Default)]
pub struct StrideCheck {
    /// The reading at the last own heel strike \[rad\]: the foot's rest angle in the swing.
    landing_rad: Option<f32>,
    /// An own heel strike since the reflex started: the walker walks.
    walking: bool,
    /// When the other foot's heel strike released this ankle (cleared at the own lift-off).
    released_by_peer_at: Option<Instant>,
    /// The last own lift-off.
    lift_off_at: Option<Instant>,
    /// In `Swing` since a release (not since the start).
    swing_after_release: bool,
    /// Closest the reading came to the rest angle in this swing \[rad\].
    swing_closest_rad: Option<f32>,
    /// The ankle angle when the spool last turned (push and hold) \[rad\].
    spool_ref_rad: Option<f32>,
    contact: Option<(i16, bool)>,
    spool: Option<i16>,
}

impl StrideCheck {
    /// Whether this tick's reading must differ from a frozen one: see the module's table.
    pub fn ankle_expected_to_move(&self, i: &StrideInputs) -> bool {
        match i.phase {
            ReflexPhase::Push => true,
            ReflexPhase::Hold => i.string_moving,
            ReflexPhase::Free => self.walking && i.contact_closed,
            ReflexPhase::Swing => match (self.landing_rad, i.sample) {
                (Some(rest), Some(s)) => (s.angle_rad - rest).abs() > SWING_REST_BAND_RAD,
                _ => false,
            },
            ReflexPhase::Inactive => false,
        }
    }

    /// The contact and spool checks of one tick, before the reflex steps.
    pub fn check(&mut self, i: &StrideInputs, stuck_timeout_s: f32) -> StrideFindings {
        self.check_contact(i, stuck_timeout_s);
        self.check_spool(i);
        StrideFindings {
            contact: self.contact.map(|(d, _)| d),
            spool: self.spool,
        }
    }

    fn raise_contact(&mut self, detail: i16, closed: bool) {
        if self.contact.is_none() {
            self.contact = Some((detail, closed));
        }
    }

    fn check_contact(&mut self, i: &StrideInputs, stuck_timeout_s: f32) {
        // A finding stays until the switch changes.
        if let Some((_, closed)) = self.contact {
            if closed != i.contact_closed {
                self.contact = None;
            }
        }
        if i.phase == ReflexPhase::Swing && i.contact_closed {
            if let Some(t) = self.released_by_peer_at {
                if i.now.secs_since(t) >= stuck_timeout_s {
                    self.raise_contact(CONTACT_STUCK_CLOSED, true);
                }
            }
        }
        if i.phase == ReflexPhase::Swing && !i.contact_closed {
            if i.peer_heel_strike && self.swing_after_release {
                self.raise_contact(CONTACT_STUCK_OPEN, false);
            }
            if let (Some(rest), Some(s)) = (self.landing_rad, i.sample) {
                let d = (s.angle_rad - rest).abs();
                let closest = self.swing_closest_rad.map_or(d, |c| c.min(d));
                self.swing_closest_rad = Some(closest);
                if d - closest > SWING_REST_BAND_RAD {
                    self.raise_contact(CONTACT_STUCK_OPEN, false);
                }
            }
        }
    }

    fn check_spool(&mut self, i: &StrideInputs) {
        let taut = matches!(i.phase, ReflexPhase::Push | ReflexPhase::Hold) && i.spool_sensor;
        if i.string_moving {
            self.spool = None;
        }
        let Some(s) = i.sample else {
            return;
        };
        if !taut || i.string_moving {
            self.spool_ref_rad = taut.then_some(s.angle_rad);
            return;
        }
        let reference = *self.spool_ref_rad.get_or_insert(s.angle_rad);
        // Only the extension: the ankle sinking onto a string that took up its slack (at the
        // push's start: up to 15 counts in the nominal walks) or a servo that stalls is no
        // evidence; the ankle rising is the string winding it up (or a slack string lifted by
        // the walker: 0.4 counts at most in the nominal walks).
        let rise_counts = libm::roundf((s.angle_rad - reference) / COUNT_RAD);
        if rise_counts > f32::from(SPOOL_SILENT_ANKLE_COUNTS) {
            self.spool = Some(crate::convert::saturating_i16(rise_counts));
        }
    }

    /// The own contact's edges and the reflex's event of this tick, after the reflex stepped:
    /// they set what the coming ticks expect.
    pub fn observe(
        &mut self,
        now: Instant,
        sample: Option<AngleSample>,
        lift_off: bool,
        event: Option<ReflexEvent>,
    ) {
        if lift_off {
            self.lift_off_at = Some(now);
            self.released_by_peer_at = None;
        }
        match event {
            Some(ReflexEvent::HeelStrike) => {
                if self
                    .lift_off_at
                    .is_some_and(|t| now.secs_since(t) < MIN_SWING_S)
                {
                    self.raise_contact(CONTACT_STUCK_CLOSED, true);
                }
                self.walking = true;
                self.swing_after_release = false;
                self.swing_closest_rad = None;
                if let Some(s) = sample {
                    self.landing_rad = Some(s.angle_rad);
                }
            }
            Some(ReflexEvent::Released(cause)) => {
                self.swing_after_release = true;
                self.swing_closest_rad = None;
                if cause == ReleaseCause::PeerHeelStrike && !lift_off {
                    self.released_by_peer_at = Some(now);
                }
            }
            _ => {}
        }
    }

    /// The reflex stopped (node not enabled): the stride starts over; the findings stay
    /// until their sensor changes (so that the node cannot be enabled again on them).
    pub fn stop(&mut self) {
        *self = StrideCheck {
            landing_rad: self.landing_rad,
            contact: self.contact,
            spool: self.spool,
            ..StrideCheck::default()
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sensors::SIMULATED_CALIBRATION as CAL;

    fn sample(angle: f32) -> Option<AngleSample> {
        let counts = CAL.counts(angle);
        Some(AngleSample {
            counts,
            angle_rad: CAL.angle_rad(counts),
        })
    }

    fn inputs(ms: u64, phase: ReflexPhase, angle: f32, contact: bool) -> StrideInputs {
        StrideInputs {
            now: Instant::from_millis(ms),
            phase,
            sample: sample(angle),
            contact_closed: contact,
            string_moving: false,
            spool_sensor: true,
            peer_heel_strike: false,
        }
    }

    #[test]
    fn the_ankle_must_move_in_every_phase_of_a_walking_stride() {
        let mut c = StrideCheck::default();
        // Before the first own heel strike nothing says the stance rotates.
        assert!(!c.ankle_expected_to_move(&inputs(0, ReflexPhase::Free, 0.1, true)));
        c.observe(
            Instant::from_millis(1),
            sample(0.16),
            false,
            Some(ReflexEvent::HeelStrike),
        );
        assert!(c.ankle_expected_to_move(&inputs(2, ReflexPhase::Free, 0.1, true)));
        assert!(c.ankle_expected_to_move(&inputs(2, ReflexPhase::Push, 0.1, true)));
        let mut hold = inputs(2, ReflexPhase::Hold, 0.2, true);
        assert!(!c.ankle_expected_to_move(&hold));
        hold.string_moving = true;
        assert!(c.ankle_expected_to_move(&hold));
        // Swing: away from the rest angle the spring moves it, at rest nothing does.
        assert!(c.ankle_expected_to_move(&inputs(3, ReflexPhase::Swing, 0.2, false)));
        assert!(!c.ankle_expected_to_move(&inputs(3, ReflexPhase::Swing, 0.17, false)));
        assert!(!c.ankle_expected_to_move(&inputs(3, ReflexPhase::Inactive, 0.0, false)));
    }

    #[test]
    fn a_switch_closed_after_the_release_or_too_soon_after_the_lift_off_is_stuck_closed() {
        let mut c = StrideCheck::default();
        c.observe(
            Instant::from_millis(0),
            sample(0.16),
            false,
            Some(ReflexEvent::HeelStrike),
        );
        c.observe(
            Instant::from_millis(800),
            sample(0.15),
            false,
            Some(ReflexEvent::Released(ReleaseCause::PeerHeelStrike)),
        );
        for ms in 801..850 {
            let f = c.check(&inputs(ms, ReflexPhase::Swing, 0.15, true), 0.05);
            assert_eq!(f.contact, None, "{ms}");
        }
        let f = c.check(&inputs(850, ReflexPhase::Swing, 0.15, true), 0.05);
        assert_eq!(f.contact, Some(CONTACT_STUCK_CLOSED));
        // It stays while the switch stays, and goes when the switch changes.
        assert_eq!(
            c.check(&inputs(900, ReflexPhase::Swing, 0.15, true), 0.05)
                .contact,
            Some(CONTACT_STUCK_CLOSED)
        );
        assert_eq!(
            c.check(&inputs(901, ReflexPhase::Swing, 0.15, false), 0.05)
                .contact,
            None
        );
        // A normal lift-off 10 ms after the release: nothing.
        let mut c = StrideCheck::default();
        c.observe(
            Instant::from_millis(800),
            sample(0.15),
            false,
            Some(ReflexEvent::Released(ReleaseCause::PeerHeelStrike)),
        );
        c.observe(Instant::from_millis(810), sample(0.15), true, None);
        for ms in 811..1500 {
            let f = c.check(&inputs(ms, ReflexPhase::Swing, 0.16, false), 0.05);
            assert_eq!(f.contact, None);
        }
        // A heel strike 100 ms after the lift-off: no swing is that short.
        c.observe(
            Instant::from_millis(910),
            sample(0.16),
            false,
            Some(ReflexEvent::HeelStrike),
        );
        let f = c.check(&inputs(911, ReflexPhase::Free, 0.16, true), 0.05);
        assert_eq!(f.contact, Some(CONTACT_STUCK_CLOSED));
    }

    #[test]
    fn a_swing_that_turns_away_from_rest_or_outlasts_the_other_foots_stance_is_stuck_open() {
        let mut c = StrideCheck::default();
        c.observe(
            Instant::from_millis(0),
            sample(0.16),
            false,
            Some(ReflexEvent::HeelStrike),
        );
        c.observe(
            Instant::from_millis(800),
            sample(0.2),
            true,
            Some(ReflexEvent::Released(ReleaseCause::PeerHeelStrike)),
        );
        // The spring returns the foot from 0.2 to 0.16 rad: nothing.
        let mut a = 0.2;
        for ms in 801..1000 {
            a = f32::max(a - 0.002, 0.16);
            assert_eq!(
                c.check(&inputs(ms, ReflexPhase::Swing, a, false), 0.05)
                    .contact,
                None
            );
        }
        // Then it turns away as a loaded foot does: found once 0.03 rad past the closest.
        let mut found = None;
        for ms in 1000..1200 {
            a -= 0.0005;
            let f = c.check(&inputs(ms, ReflexPhase::Swing, a, false), 0.05);
            if f.contact.is_some() {
                found = Some((ms, f.contact));
                break;
            }
        }
        assert!(
            matches!(found, Some((ms, Some(CONTACT_STUCK_OPEN))) if (1060..1064).contains(&ms)),
            "{found:?}"
        );
        // The other foot's heel strike again while this one still swings.
        let mut c = StrideCheck::default();
        c.observe(
            Instant::from_millis(800),
            sample(0.2),
            true,
            Some(ReflexEvent::Released(ReleaseCause::PeerHeelStrike)),
        );
        let mut i = inputs(1600, ReflexPhase::Swing, 0.16, false);
        assert_eq!(c.check(&i, 0.05).contact, None);
        i.peer_heel_strike = true;
        assert_eq!(c.check(&i, 0.05).contact, Some(CONTACT_STUCK_OPEN));
    }

    #[test]
    fn an_ankle_moving_under_a_silent_spool_in_push_is_a_stuck_spool() {
        let mut c = StrideCheck::default();
        let mut i = inputs(0, ReflexPhase::Push, -0.08, true);
        i.string_moving = true;
        assert_eq!(c.check(&i, 0.05).spool, None);
        let per_count = core::f32::consts::TAU / 16384.0;
        let mut found = None;
        for k in 1..40u16 {
            let mut i = inputs(u64::from(k), ReflexPhase::Push, -0.08 + f32::from(k) * per_count, true);
            i.string_moving = false;
            if let Some(d) = c.check(&i, 0.05).spool {
                found = Some((k, d));
                break;
            }
        }
        assert_eq!(found, Some((17, 17)));
        // The spool turning again clears it; outside push and hold nothing is checked.
        let mut i = inputs(40, ReflexPhase::Push, 0.0, true);
        i.string_moving = true;
        assert_eq!(c.check(&i, 0.05).spool, None);
        assert_eq!(
            c.check(&inputs(41, ReflexPhase::Free, -0.5, true), 0.05).spool,
            None
        );
    }
}
