//! Sensor samples as the node sees them, and their plausibility checks (range, rate, stuck).

use crate::convert::saturating_i16;
use crate::params::{ReflexParams, ANKLE_ANGLE_LIMIT_RAD};
use crate::time::Instant;

/// Counts per revolution of the 14-bit magnetic encoder.
pub const ENCODER_COUNTS_PER_REV: u16 = 1 << 14;

/// One good encoder reading.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AngleSample {
    /// Raw encoder counts (0..16383).
    pub counts: u16,
    /// Ankle angle after calibration \[rad\], negative when the hip is ahead of the ankle.
    pub angle_rad: f32,
}

/// Why the encoder gave no reading.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum EncoderError {
    /// The SPI transfer failed.
    Bus(embedded_hal::spi::ErrorKind),
    /// The answer's even-parity bit is wrong.
    Parity {
        /// The 16-bit word received.
        word: u16,
    },
    /// The sensor set its error flag (e.g. magnet too weak, framing error of the command).
    ErrorFlag {
        /// The 16-bit word received.
        word: u16,
    },
    /// No fresh reading arrived in time (a PWM-output encoder whose line went quiet, or a
    /// frame whose period is not the sensor's).
    NoSignal,
}

impl EncoderError {
    /// A small code for the fault event's `detail` field: 1 bus, 2 parity, 3 error flag,
    /// 4 no signal.
    pub fn detail(&self) -> i16 {
        match self {
            EncoderError::Bus(_) => 1,
            EncoderError::Parity { .. } => 2,
            EncoderError::ErrorFlag { .. } => 3,
            EncoderError::NoSignal => 4,
        }
    }
}

/// Encoder zero and direction: maps counts to the ankle angle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AngleCalibration {
    /// Counts read when the ankle angle is zero.
    pub zero_counts: u16,
    /// True when the ankle angle grows as the counts fall.
    pub reversed: bool,
}

impl AngleCalibration {
    /// Ankle angle for a reading \[rad\], wrapped to (−π, π]. Any `counts` and zero, even
    /// past the 14 bits, give an angle: only their difference modulo one revolution counts.
    pub fn angle_rad(&self, counts: u16) -> f32 {
        // Modulo 2¹⁶, then modulo 2¹⁴ (which divides 2¹⁶): the difference modulo one
        // revolution. Wrapping is the meaning here — the counts are a position on a circle.
        let d = i32::from(counts.wrapping_sub(self.zero_counts) % ENCODER_COUNTS_PER_REV);
        // 0..16384: past half a revolution is the negative side; |d| ≤ 8192 after this, so
        // neither the subtraction nor the negation can saturate.
        let half = i32::from(ENCODER_COUNTS_PER_REV / 2);
        let mut d = if d > half {
            d.saturating_sub(i32::from(ENCODER_COUNTS_PER_REV))
        } else {
            d
        };
        if self.reversed {
            d = d.saturating_neg();
        }
        d as f32 * (core::f32::consts::TAU / ENCODER_COUNTS_PER_REV as f32)
    }

    /// The reading that gives `angle_rad` (inverse of [`Self::angle_rad`], rounded to a count);
    /// used by simulated encoders to quantise like the real sensor. Any angle gives a reading:
    /// the rounded counts are reduced to one revolution before any integer arithmetic (`fmod`
    /// of an integer-valued float is exact), so a huge angle (a glitch of 1e6 rad, ±∞) can
    /// neither saturate nor wrap an integer; a NaN reads as the zero.
    pub fn counts(&self, angle_rad: f32) -> u16 {
        let n = ENCODER_COUNTS_PER_REV as f32;
        let per_rad = n / core::f32::consts::TAU;
        let within_rev = libm::fmodf(libm::roundf(angle_rad * per_rad), n);
        // |within_rev| < n = 16384 and integer-valued (NaN and ±∞ take the 0): exact as an
        // i32, and its negation cannot saturate.
        #[allow(clippy::cast_possible_truncation)]
        let mut d = if within_rev.is_finite() {
            within_rev as i32
        } else {
            0
        };
        if self.reversed {
            d = d.saturating_neg();
        }
        offset_counts(self.zero_counts, d)
    }

    /// Bit of [`Self::to_stored_word`] that holds `reversed`.
    const REVERSED_BIT: u32 = 1 << 16;

    /// The calibration as the parameter store's word: `zero_counts` in bits 0..=15,
    /// `reversed` in bit 16, the rest zero.
    pub fn to_stored_word(&self) -> u32 {
        let reversed = if self.reversed { Self::REVERSED_BIT } else { 0 };
        u32::from(self.zero_counts) | reversed
    }

    /// The calibration a stored word holds, the zero reduced to one revolution (the same
    /// angle: only the counts modulo 2¹⁴ matter); `None` when a bit above 16 is set — no
    /// version wrote one, so the word is not a calibration, refused rather than cut.
    pub fn from_stored_word(word: u32) -> Option<Self> {
        if word & !(Self::REVERSED_BIT | 0xFFFF) != 0 {
            return None;
        }
        let zero = u16::try_from(word & 0xFFFF).ok()?;
        Some(AngleCalibration {
            zero_counts: zero % ENCODER_COUNTS_PER_REV,
            reversed: word & Self::REVERSED_BIT != 0,
        })
    }
}

/// The encoder calibration of every simulated ankle: the scripted scenarios
/// ([`crate::scenarios`], on the host and on the emulated Cortex-M4), the host tests and the
/// simulator's software-in-the-loop runner. Zero at 4000 counts, not reversed: a zero away
/// from the counts' wrap, so that a conversion that ignored the offset would show. A board's
/// zero is measured after its magnet is mounted (`firmware/board-g431` sets its own), so this
/// is no board default.
pub const SIMULATED_CALIBRATION: AngleCalibration = AngleCalibration {
    zero_counts: 4000,
    reversed: false,
};

/// Output noise of a simulated magnetic encoder at sample `n` \[counts\]: −1, 0 or +1 from a
/// fixed integer hash, so that host, QEMU and simulator runs stay bit-identical. A real
/// AS5047P-class sensor's reading moves by a few counts of noise at 14 bits; a reading that
/// does not move at all for the stuck timeout is a failed sensor ([`Plausibility`]). Every
/// simulated encoder (scenarios, host tests, the simulator) adds this to its counts.
pub fn simulated_noise_counts(n: u32) -> i32 {
    // Knuth's multiplicative hash: the product modulo 2³² is the hash (wrapping on purpose);
    // its top two bits (0..=3) give (h mod 3) − 1.
    match n.wrapping_mul(2_654_435_761) >> 30 {
        1 => 0,
        2 => 1,
        _ => -1,
    }
}

/// `counts` plus [`simulated_noise_counts`], wrapped to the encoder's range.
pub fn with_simulated_noise(counts: u16, n: u32) -> u16 {
    offset_counts(counts, simulated_noise_counts(n))
}

/// `counts` moved by `delta` around the circle, reduced to one revolution (0..16384).
/// Wrapping is the meaning (an absolute encoder's position modulo a revolution); it is exact
/// for any `counts` and any `delta`, `i32::MIN` and `i32::MAX` included — no intermediate
/// value overflows or saturates.
pub fn offset_counts(counts: u16, delta: i32) -> u16 {
    let rev = i32::from(ENCODER_COUNTS_PER_REV);
    // Both terms below 2¹⁶ after the reduction of `delta`: the sum cannot saturate.
    let r = i32::from(counts)
        .saturating_add(delta.rem_euclid(rev))
        .rem_euclid(rev);
    // `rem_euclid` by a positive modulus: 0..16384, a u16 without loss.
    u16::try_from(r).unwrap_or(0)
}

/// What the plausibility checks found in one sample; `Some(detail)` when a check fails,
/// with the offending raw value for the fault event.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct SensorFindings {
    /// The read failed (detail: [`EncoderError::detail`]).
    pub comms: Option<i16>,
    /// Angle outside ±[`ANKLE_ANGLE_LIMIT_RAD`] (detail: angle in 0.1 mrad, saturated).
    pub range: Option<i16>,
    /// Rate above the limit (detail: rate in 10 mrad/s, saturated).
    pub rate: Option<i16>,
    /// No change while the actuator drives (detail: the stuck counts, saturated at 32767).
    pub stuck: Option<i16>,
}

/// Range, rate and stuck-value checks across samples.
#[derive(Clone, Copy, Debug, Default)]
pub struct Plausibility {
    last_good: Option<(Instant, AngleSample)>,
    /// The previous reading, its time and whether the actuator drove in that tick.
    last_read: Option<(Instant, u16, bool)>,
    /// Time [µs] the reading has stayed the same across consecutive driven ticks.
    still_driven_us: u64,
    stuck_at: Option<u16>,
}

impl Plausibility {
    /// Check one read. `driving` is true in a tick where the actuator is moving the ankle —
    /// the push (the setpoint profile moves it), or a hold while the spool turns (the node
    /// cross-checks the ankle angle against the spool's motion) — when a frozen reading means
    /// a stuck sensor. The stuck time accumulates over intervals between two consecutive
    /// driven ticks with the same reading; undriven ticks pause it (a still ankle with a
    /// still spool is no evidence either way), a change of the reading resets it.
    pub fn check(
        &mut self,
        now: Instant,
        read: &Result<AngleSample, EncoderError>,
        driving: bool,
        params: &ReflexParams,
    ) -> SensorFindings {
        let mut f = SensorFindings::default();
        let s = match read {
            Err(e) => {
                f.comms = Some(e.detail());
                return f;
            }
            Ok(s) => *s,
        };
        if s.angle_rad.is_nan() || s.angle_rad.abs() > ANKLE_ANGLE_LIMIT_RAD {
            f.range = Some(saturating_i16(s.angle_rad * 1.0e4));
        }
        if let Some((t, prev)) = self.last_good {
            let dt = now.secs_since(t);
            if dt > 0.0 {
                let rate = (s.angle_rad - prev.angle_rad) / dt;
                if rate.abs() > params.max_angular_rate_rad_per_s() {
                    f.rate = Some(saturating_i16(rate * 100.0));
                }
            }
        }
        match self.last_read {
            Some((_, c, _)) if c != s.counts => self.still_driven_us = 0,
            Some((t, _, was_driving)) if was_driving && driving => {
                self.still_driven_us = self.still_driven_us.saturating_add(now.micros_since(t));
            }
            _ => {}
        }
        self.last_read = Some((now, s.counts, driving));
        if self.still_driven_us as f32 >= params.stuck_timeout_s() * 1.0e6 {
            self.stuck_at = Some(s.counts);
        }
        // A stuck reading stays a fault, driving or not, until the reading changes.
        match self.stuck_at {
            // Counts are 14 bits from a healthy sensor; anything past i16 reads as its limit.
            Some(c) if c == s.counts => f.stuck = Some(i16::try_from(c).unwrap_or(i16::MAX)),
            _ => self.stuck_at = None,
        }
        self.last_good = Some((now, s));
        f
    }
}

/// Integrating debouncer for a contact switch: the state flips after `threshold` consecutive
/// samples that disagree with it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Debouncer {
    state: bool,
    count: u8,
    threshold: u8,
}

impl Debouncer {
    /// Start in `initial`, flip after `threshold` (at least 1) disagreeing samples.
    pub fn new(initial: bool, threshold: u8) -> Self {
        Debouncer {
            state: initial,
            count: 0,
            threshold: threshold.max(1),
        }
    }
    /// Feed one raw sample, get the debounced state.
    pub fn update(&mut self, raw: bool) -> bool {
        if raw == self.state {
            self.count = 0;
        } else {
            self.count = self.count.saturating_add(1);
            if self.count >= self.threshold {
                self.state = raw;
                self.count = 0;
            }
        }
        self.state
    }
    /// The debounced state.
    pub fn state(&self) -> bool {
        self.state
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(counts: u16) -> Result<AngleSample, EncoderError> {
        let cal = AngleCalibration {
            zero_counts: 8000,
            reversed: false,
        };
        Ok(AngleSample {
            counts,
            angle_rad: cal.angle_rad(counts),
        })
    }

    #[test]
    fn any_angle_gives_a_reading_without_integer_overflow() {
        // Extremes a glitch or a broken model can hand the simulated encoder: no overflow (a
        // debug build panics on one), a reading in range, and angles a whole number of
        // revolutions apart (exact in f32 counts) read the same.
        for reversed in [false, true] {
            for zero_counts in [0u16, 1, 4000, 16383, u16::MAX] {
                let cal = AngleCalibration {
                    zero_counts,
                    reversed,
                };
                for a in [
                    0.0f32,
                    -0.0,
                    1e6,
                    -1e6,
                    1e30,
                    -1e30,
                    f32::MAX,
                    f32::MIN,
                    f32::INFINITY,
                    f32::NEG_INFINITY,
                    f32::NAN,
                    f32::MIN_POSITIVE,
                ] {
                    assert!(cal.counts(a) < ENCODER_COUNTS_PER_REV, "{a}");
                }
                assert_eq!(cal.counts(f32::NAN), cal.counts(0.0));
                let per_count = core::f32::consts::TAU / ENCODER_COUNTS_PER_REV as f32;
                // 2²³ counts from zero: 512 revolutions, every count exact in f32.
                for c in [0.0f32, 1.0, 123.0, 8191.0] {
                    let far = (c + 512.0 * ENCODER_COUNTS_PER_REV as f32) * per_count;
                    let near = c * per_count;
                    let diff = (i32::from(cal.counts(far)) - i32::from(cal.counts(near)))
                        .rem_euclid(ENCODER_COUNTS_PER_REV as i32);
                    // The angles round to counts one ulp apart at most.
                    assert!(
                        diff <= 1 || diff >= ENCODER_COUNTS_PER_REV as i32 - 1,
                        "{c}: {diff}"
                    );
                }
                // A glitch of 1e6 rad moves the reading (1e6 rad is not a whole number of
                // revolutions; the old saturating cast read every huge angle as one count).
                let c0 = cal.counts(0.1);
                assert_ne!(cal.counts(0.1 + 1e6), c0);
            }
        }
    }

    #[test]
    fn calibration_wraps_and_inverts() {
        let cal = AngleCalibration {
            zero_counts: 100,
            reversed: true,
        };
        assert_eq!(cal.angle_rad(100), 0.0);
        let a = cal.angle_rad(50);
        assert!((a - 50.0 * core::f32::consts::TAU / 16384.0).abs() < 1e-7);
        for x in [-0.9f32, -0.08, 0.0, 0.2, 0.9] {
            let c = cal.counts(x);
            assert!((cal.angle_rad(c) - x).abs() <= 0.5 * core::f32::consts::TAU / 16384.0 + 1e-7);
        }
        assert_eq!(cal.counts(cal.angle_rad(16383)), 16383);
    }

    #[test]
    fn comms_range_rate_and_stuck() {
        let p = ReflexParams::default();
        let mut pl = Plausibility::default();
        let t = |ms| Instant::from_millis(ms);
        assert_eq!(
            pl.check(t(0), &sample(8000), false, &p),
            SensorFindings::default()
        );
        let f = pl.check(t(1), &Err(EncoderError::Parity { word: 1 }), false, &p);
        assert_eq!(f.comms, Some(2));
        // 1.2 rad: out of range and, 2 ms after the last good sample, too fast.
        let far = 8000 + (1.2 * 16384.0 / core::f32::consts::TAU) as u16;
        let f = pl.check(t(2), &sample(far), false, &p);
        assert!(f.range.is_some() && f.rate.is_some());
        // Stuck only counts while driving.
        let mut pl = Plausibility::default();
        for ms in 0..100 {
            assert_eq!(pl.check(t(ms), &sample(8000), false, &p).stuck, None);
        }
        let mut stuck_at = None;
        for ms in 100..200 {
            if pl.check(t(ms), &sample(8000), true, &p).stuck.is_some() {
                stuck_at = Some(ms);
                break;
            }
        }
        assert_eq!(stuck_at, Some(150), "50 ms stuck timeout");
    }

    #[test]
    fn undriven_ticks_pause_the_stuck_time_and_a_change_resets_it() {
        let p = ReflexParams::default();
        let t = |ms| Instant::from_millis(ms);
        // A hold: the spool turns every other 10 ms, the reading never changes. Only the
        // driven intervals count, so the timeout is reached after 50 ms of them.
        let mut pl = Plausibility::default();
        let mut stuck_at = None;
        for ms in 0..400 {
            let driving = (ms / 10) % 2 == 0;
            if pl.check(t(ms), &sample(8000), driving, &p).stuck.is_some() {
                stuck_at = Some(ms);
                break;
            }
        }
        // Blocks of 10 driven ticks give 9 ms each: 6 blocks (54 ms) in 0..110.
        assert!(
            stuck_at.is_some_and(|ms| (100..110).contains(&ms)),
            "{stuck_at:?}"
        );
        // A still ankle with a still spool: no evidence, never stuck.
        let mut pl = Plausibility::default();
        for ms in 0..1000 {
            assert_eq!(pl.check(t(ms), &sample(8000), false, &p).stuck, None);
        }
        // A change restarts the time.
        let mut pl = Plausibility::default();
        for ms in 0..45 {
            assert_eq!(pl.check(t(ms), &sample(8000), true, &p).stuck, None);
        }
        for ms in 45..90 {
            assert_eq!(pl.check(t(ms), &sample(8001), true, &p).stuck, None, "{ms}");
        }
    }

    #[test]
    fn simulated_noise_moves_within_a_count_and_never_sits_still_long() {
        let mut run = 0;
        let mut longest = 0;
        let mut seen = [false; 3];
        for n in 0..10_000u32 {
            let d = simulated_noise_counts(n);
            seen[(d + 1) as usize] = true;
            run = if n > 0 && d == simulated_noise_counts(n - 1) {
                run + 1
            } else {
                0
            };
            longest = longest.max(run);
        }
        assert_eq!(seen, [true; 3]);
        assert!(longest < 20, "longest still run {longest}");
        // Wrapped into the encoder's range at both ends: below 0 to the top, above it to 0.
        for n in 0..100u32 {
            let low = with_simulated_noise(0, n);
            let high = with_simulated_noise(16_383, n);
            match simulated_noise_counts(n) {
                -1 => assert_eq!((low, high), (16_383, 16_382)),
                0 => assert_eq!((low, high), (0, 16_383)),
                _ => assert_eq!((low, high), (1, 0)),
            }
        }
    }

    #[test]
    fn debouncer_needs_consecutive_samples() {
        let mut d = Debouncer::new(false, 3);
        assert!(!d.update(true));
        assert!(!d.update(true));
        assert!(!d.update(false), "bounce resets the count");
        assert!(!d.update(true));
        assert!(!d.update(true));
        assert!(d.update(true));
        assert!(d.state());
        assert_eq!(Debouncer::new(true, 0).threshold, 1);
    }
}
