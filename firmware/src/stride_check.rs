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
//!   ankle (the trailing foot must lift) while the ankle does not turn as a loaded one, or
//!   closed again less than [`MIN_SWING_S`] after the own lift-off (no swing is that short),
//!   or a walking stance whose reading changes but turns less than
//!   [`STANCE_MIN_ROTATION_RAD`] over a stuck timeout, at least [`STANCE_ROTATION_WINDOW_S`]
//!   (a foot in the air);
//! * open: in a swing, the reading moving *away* from the foot's rest angle by more than
//!   [`SWING_TURN_AWAY_RAD`] beyond the closest it came in that swing (the spring returns a
//!   swinging foot; only the floor turns the ankle away), or down through the taut angle, or
//!   the other foot's heel strike arriving again while this ankle is still in the swing its
//!   previous one began.
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

/// Net turn of the ankle over one stuck timeout of a walking stance below which the foot is
/// taken as not loaded \[rad\]: 8 counts (3.1 mrad). The nominal walks turn it by at least 30
/// counts per 50 ms in `Free` (docs/firmware.md).
pub const STANCE_MIN_ROTATION_RAD: f32 = 8.0 * COUNT_RAD;

/// Shortest window over which a walking stance's rotation is judged \[s\]: the nominal walks
/// turn the ankle by at least 30 counts per 50 ms in `Free` (docs/firmware.md), so
/// [`STANCE_MIN_ROTATION_RAD`] over 50 ms is far below a loaded foot's; over a stuck timeout
/// shorter than this (`stuck_timeout_s` may be 10 ms) a healthy stance turns only a few counts
/// and was taken for a foot in the air.
pub const STANCE_ROTATION_WINDOW_S: f32 = 0.05;

/// A swing ankle that turned away from its rest angle by no more than this \[rad\] is not
/// loaded: 4 counts (1.5 mrad), twice a healthy encoder's ±1-count noise.
pub const SWING_STILL_RAD: f32 = 4.0 * COUNT_RAD;

/// A swing ankle turned away from its rest angle by more than this, beyond the closest it
/// came in that swing, is turned by the floor \[rad\]: 0.015 rad (39 counts; the nominal
/// walks' swings only approach the rest angle).
pub const SWING_TURN_AWAY_RAD: f32 = 0.015;

/// How long a swing must stay turned away from rest before the switch is taken as stuck
/// open \[s\]: 10 ms, over the debouncer's 3 samples that a real landing takes to close it.
pub const SWING_AWAY_HELD_S: f32 = 0.01;

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

/// `ContactStuck` detail: closed `StuckTimeout` after the other foot's heel strike released
/// this ankle, the ankle not turning as a loaded one (the foot must have lifted).
pub const CONTACT_STUCK_CLOSED: i16 = 1;
/// `ContactStuck` detail: open while the swing turns the ankle away from its rest angle or
/// down through the taut angle (only the floor does).
pub const CONTACT_STUCK_OPEN: i16 = 2;
/// `ContactStuck` detail: closed again less than [`MIN_SWING_S`] after the lift-off.
pub const CONTACT_CLOSED_TOO_SOON: i16 = 3;
/// `ContactStuck` detail: closed in a walking stance whose ankle does not turn (a foot in
/// the air).
pub const CONTACT_CLOSED_NO_STANCE: i16 = 4;
/// `ContactStuck` detail: open when the other foot's heel strike came again during this
/// foot's swing (it must have landed in between).
pub const CONTACT_OPEN_PEER_AGAIN: i16 = 5;

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
///
/// `ContactStuck`'s details: [`CONTACT_STUCK_CLOSED`] 1, [`CONTACT_STUCK_OPEN`] 2,
/// [`CONTACT_CLOSED_TOO_SOON`] 3, [`CONTACT_CLOSED_NO_STANCE`] 4, [`CONTACT_OPEN_PEER_AGAIN`] 5.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StrideFindings {
    /// `ContactStuck` (its evidence: 1–5, see above).
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
    /// The reading was above the taut angle in this swing (switch open).
    swing_above_taut: bool,
    /// Since when the swing has turned away from rest (or is below the taut angle after
    /// being above it).
    swing_away_since: Option<Instant>,
    /// The switch at the previous check.
    last_contact_closed: Option<bool>,
    /// The ankle angle when the spool last turned (push and hold) \[rad\].
    spool_ref_rad: Option<f32>,
    /// The stance rotation's window (`Free`, walking, switch closed).
    stance_window: Option<StanceWindow>,
    contact: Option<(i16, bool)>,
    spool: Option<i16>,
}

/// One stuck timeout of a walking stance: where the reading started and whether it changed.
#[derive(Clone, Copy, Debug)]
struct StanceWindow {
    since: Instant,
    from_rad: f32,
    last_counts: u16,
    changed: bool,
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
    pub fn check(
        &mut self,
        i: &StrideInputs,
        stuck_timeout_s: f32,
        taut_angle_rad: f32,
    ) -> StrideFindings {
        self.check_contact(i, stuck_timeout_s, taut_angle_rad);
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

    fn check_contact(&mut self, i: &StrideInputs, stuck_timeout_s: f32, taut_angle_rad: f32) {
        // A finding stays until the switch changes.
        if let Some((_, closed)) = self.contact {
            if closed != i.contact_closed {
                self.contact = None;
            }
        }
        self.check_stance_rotation(i, stuck_timeout_s);
        // The switch opening starts the swing proper (the foot in the air from here): the
        // swing's closest approach to rest is counted from it.
        if self.last_contact_closed.replace(i.contact_closed) == Some(true) && !i.contact_closed {
            self.swing_closest_rad = None;
            self.swing_above_taut = false;
            self.swing_away_since = None;
        }
        if i.phase != ReflexPhase::Swing {
            return;
        }
        // How far the swing turned the ankle away from its rest angle, beyond the closest it
        // came in this swing [rad] (0 before the first landing).
        let turned_away_rad = match (self.landing_rad, i.sample) {
            (Some(rest), Some(s)) => {
                let d = (s.angle_rad - rest).abs();
                let closest = self.swing_closest_rad.map_or(d, |c| c.min(d));
                self.swing_closest_rad = Some(closest);
                d - closest
            }
            _ => 0.0,
        };
        if i.contact_closed {
            // Released by the other foot's heel strike, this foot must lift: a switch still
            // closed over the stuck timeout while the ankle does not turn as a loaded foot's
            // (a stance rotation here says the other foot's heel strike was the wrong one).
            let due = self
                .released_by_peer_at
                .is_some_and(|t| i.now.secs_since(t) >= stuck_timeout_s);
            if due && turned_away_rad <= SWING_STILL_RAD {
                self.raise_contact(CONTACT_STUCK_CLOSED, true);
            }
        } else {
            if i.peer_heel_strike && self.swing_after_release {
                self.raise_contact(CONTACT_OPEN_PEER_AGAIN, false);
            }
            // Only the floor turns a swinging ankle away from its rest angle, or down through
            // the taut angle (a swing foot hangs near its landing angle, far above it).
            let above_taut = i.sample.map(|s| s.angle_rad > taut_angle_rad);
            let crossed_down = self.swing_above_taut && above_taut == Some(false);
            self.swing_above_taut |= above_taut == Some(true);
            // Held for a while: a foot that just landed turns away too, for the few ticks
            // the switch's debouncer takes to close.
            if turned_away_rad > SWING_TURN_AWAY_RAD || crossed_down {
                let since = *self.swing_away_since.get_or_insert(i.now);
                if i.now.secs_since(since) >= SWING_AWAY_HELD_S {
                    self.raise_contact(CONTACT_STUCK_OPEN, false);
                }
            } else {
                self.swing_away_since = None;
            }
        }
    }

    /// A walking stance (`Free` after an own heel strike, switch closed) turns the ankle: a
    /// reading that changes (so the encoder works) but moves less than
    /// [`STANCE_MIN_ROTATION_RAD`] over a stuck timeout (at least
    /// [`STANCE_ROTATION_WINDOW_S`]) is a foot in the air on a switch
    /// that reads closed. A reading that does not change at all is the encoder's fault
    /// (`EncoderStuck`), not this one.
    fn check_stance_rotation(&mut self, i: &StrideInputs, stuck_timeout_s: f32) {
        let window_s = stuck_timeout_s.max(STANCE_ROTATION_WINDOW_S);
        let stance = i.phase == ReflexPhase::Free && self.walking && i.contact_closed;
        let (Some(s), true) = (i.sample, stance) else {
            self.stance_window = None;
            return;
        };
        let Some(mut w) = self.stance_window else {
            self.stance_window = Some(StanceWindow {
                since: i.now,
                from_rad: s.angle_rad,
                last_counts: s.counts,
                changed: false,
            });
            return;
        };
        // A change in the window's second half: a reading frozen early in the window is the
        // encoder's (`EncoderStuck`), not a foot in the air.
        let late = i.now.secs_since(w.since) >= 0.5 * window_s;
        w.changed |= late && s.counts != w.last_counts;
        w.last_counts = s.counts;
        if i.now.secs_since(w.since) >= window_s {
            if w.changed && (s.angle_rad - w.from_rad).abs() < STANCE_MIN_ROTATION_RAD {
                self.raise_contact(CONTACT_CLOSED_NO_STANCE, true);
            }
            w = StanceWindow {
                since: i.now,
                from_rad: s.angle_rad,
                last_counts: s.counts,
                changed: false,
            };
        }
        self.stance_window = Some(w);
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
                    self.raise_contact(CONTACT_CLOSED_TOO_SOON, true);
                }
                self.walking = true;
                self.swing_after_release = false;
                self.swing_closest_rad = None;
                self.swing_above_taut = false;
                self.swing_away_since = None;
                if let Some(s) = sample {
                    self.landing_rad = Some(s.angle_rad);
                }
            }
            Some(ReflexEvent::Released(cause)) => {
                self.swing_after_release = true;
                self.swing_closest_rad = None;
                self.swing_above_taut = false;
                self.swing_away_since = None;
                if cause == ReleaseCause::PeerHeelStrike && !lift_off {
                    self.released_by_peer_at = Some(now);
                }
            }
            _ => {}
        }
    }

    /// The reflex stopped (node not enabled): the stride starts over, the last landing angle
    /// forgotten too (a node enabled again with its foot in the air has no rest angle until
    /// its next heel strike); the findings stay until their sensor changes (so that the node
    /// cannot be enabled again on them).
    pub fn stop(&mut self) {
        *self = StrideCheck {
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
            let f = c.check(&inputs(ms, ReflexPhase::Swing, 0.15, true), 0.05, -0.08);
            assert_eq!(f.contact, None, "{ms}");
        }
        let f = c.check(&inputs(850, ReflexPhase::Swing, 0.15, true), 0.05, -0.08);
        assert_eq!(f.contact, Some(CONTACT_STUCK_CLOSED));
        // It stays while the switch stays, and goes when the switch changes.
        assert_eq!(
            c.check(&inputs(900, ReflexPhase::Swing, 0.15, true), 0.05, -0.08)
                .contact,
            Some(CONTACT_STUCK_CLOSED)
        );
        assert_eq!(
            c.check(&inputs(901, ReflexPhase::Swing, 0.15, false), 0.05, -0.08)
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
            let f = c.check(&inputs(ms, ReflexPhase::Swing, 0.16, false), 0.05, -0.08);
            assert_eq!(f.contact, None);
        }
        // A heel strike 100 ms after the lift-off: no swing is that short.
        c.observe(
            Instant::from_millis(910),
            sample(0.16),
            false,
            Some(ReflexEvent::HeelStrike),
        );
        let f = c.check(&inputs(911, ReflexPhase::Free, 0.16, true), 0.05, -0.08);
        assert_eq!(f.contact, Some(CONTACT_CLOSED_TOO_SOON));
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
                c.check(&inputs(ms, ReflexPhase::Swing, a, false), 0.05, -0.08)
                    .contact,
                None
            );
        }
        // Then it turns away as a loaded foot does: found once 0.03 rad past the closest.
        let mut found = None;
        for ms in 1000..1200 {
            a -= 0.0005;
            let f = c.check(&inputs(ms, ReflexPhase::Swing, a, false), 0.05, -0.08);
            if f.contact.is_some() {
                found = Some((ms, f.contact));
                break;
            }
        }
        assert!(
            matches!(found, Some((ms, Some(CONTACT_STUCK_OPEN))) if (1040..1044).contains(&ms)),
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
        assert_eq!(c.check(&i, 0.05, -0.08).contact, None);
        i.peer_heel_strike = true;
        assert_eq!(
            c.check(&i, 0.05, -0.08).contact,
            Some(CONTACT_OPEN_PEER_AGAIN)
        );
    }

    #[test]
    fn an_ankle_moving_under_a_silent_spool_in_push_is_a_stuck_spool() {
        let mut c = StrideCheck::default();
        let mut i = inputs(0, ReflexPhase::Push, -0.08, true);
        i.string_moving = true;
        assert_eq!(c.check(&i, 0.05, -0.08).spool, None);
        let per_count = core::f32::consts::TAU / 16384.0;
        let mut found = None;
        for k in 1..40u16 {
            let mut i = inputs(
                u64::from(k),
                ReflexPhase::Push,
                -0.08 + f32::from(k) * per_count,
                true,
            );
            i.string_moving = false;
            if let Some(d) = c.check(&i, 0.05, -0.08).spool {
                found = Some((k, d));
                break;
            }
        }
        assert_eq!(found, Some((17, 17)));
        // The spool turning again clears it; outside push and hold nothing is checked.
        let mut i = inputs(40, ReflexPhase::Push, 0.0, true);
        i.string_moving = true;
        assert_eq!(c.check(&i, 0.05, -0.08).spool, None);
        assert_eq!(
            c.check(&inputs(41, ReflexPhase::Free, -0.5, true), 0.05, -0.08)
                .spool,
            None
        );
    }
}
