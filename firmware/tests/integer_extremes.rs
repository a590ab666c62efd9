//! Every integer conversion of a sensor or wire value in the firmware at its extremes: the
//! encoder counts and calibration, the PWM encoder's capture, the spool counter, the PWM
//! duty, fault details, the clocks near the u32 and u64 limits, parameter values. Results
//! are refused or saturated where a value does not fit, wrapped only where the wrap is the
//! meaning (a position on the encoder's circle, the bus's free-running clocks).
//!
//! The oracles compute in a wider type (i64, u128, f64), so a silent wrap shows as a
//! mismatch even in a release build, where overflow does not panic.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use core::f32::consts::{PI, TAU};

use firmware::convert::{duty_from_fraction, saturating_i16, saturating_i32};
use firmware::drivers::encoder::AngleSensor;
use firmware::drivers::pwm_encoder::{
    decode, PwmAngleEncoder, PwmCapture, PwmFrame, FRAME_UNITS, HEADER_UNITS, MAX_ANGLE_12,
};
use firmware::drivers::spool_motor::CounterUnwrap;
use firmware::node::{AnkleNode, DriverHealth, NodeConfig, TickInputs, TickOutputs};
use firmware::params::ReflexParams;
use firmware::sensors::{
    offset_counts, simulated_noise_counts, with_simulated_noise, AngleCalibration, AngleSample,
    EncoderError, Plausibility, ENCODER_COUNTS_PER_REV,
};
use firmware::Instant;
use proptest::prelude::*;
use protocol::*;

const REV: i64 = ENCODER_COUNTS_PER_REV as i64;

const U16_EXTREMES: [u16; 9] = [0, 1, 4000, 8191, 8192, 16383, 16384, 32768, u16::MAX];
const I32_EXTREMES: [i32; 12] = [
    i32::MIN,
    i32::MIN + 1,
    -16385,
    -16384,
    -8192,
    -1,
    0,
    1,
    16383,
    16384,
    i32::MAX - 1,
    i32::MAX,
];
const F32_EXTREMES: [f32; 15] = [
    0.0,
    -0.0,
    f32::MIN_POSITIVE,
    0.5,
    -0.5,
    32767.9,
    -32768.9,
    1.0e10,
    -1.0e10,
    f32::MAX,
    f32::MIN,
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::NAN,
    -f32::NAN,
];

fn cal(zero_counts: u16, reversed: bool) -> AngleCalibration {
    AngleCalibration {
        zero_counts,
        reversed,
    }
}

/// The angle of a reading, computed in i64.
fn angle_oracle(c: &AngleCalibration, counts: u16) -> f32 {
    let mut d = (counts as i64 - c.zero_counts as i64).rem_euclid(REV);
    if d > REV / 2 {
        d -= REV;
    }
    if c.reversed {
        d = -d;
    }
    d as f32 * (TAU / ENCODER_COUNTS_PER_REV as f32)
}

#[test]
fn every_reading_with_any_zero_gives_the_angle_modulo_a_revolution() {
    for zero in U16_EXTREMES {
        for reversed in [false, true] {
            let c = cal(zero, reversed);
            for counts in 0..=u16::MAX {
                let a = c.angle_rad(counts);
                assert_eq!(
                    a.to_bits(),
                    angle_oracle(&c, counts).to_bits(),
                    "zero {zero} reversed {reversed} counts {counts}"
                );
                assert!((-PI..=PI).contains(&a), "{a}");
                // The reading of that angle is the counts modulo a revolution.
                assert_eq!(
                    c.counts(a) as i64,
                    (counts as i64).rem_euclid(REV),
                    "zero {zero} reversed {reversed} counts {counts}"
                );
            }
        }
    }
}

#[test]
fn offset_counts_is_exact_modulo_a_revolution_for_any_delta() {
    for counts in U16_EXTREMES {
        for delta in I32_EXTREMES {
            assert_eq!(
                offset_counts(counts, delta) as i64,
                (counts as i64 + delta as i64).rem_euclid(REV),
                "{counts} {delta}"
            );
        }
        for n in [0u32, 1, 2, 3, u32::MAX / 2, u32::MAX - 1, u32::MAX] {
            let noisy = with_simulated_noise(counts, n);
            assert!(noisy < ENCODER_COUNTS_PER_REV);
            assert_eq!(
                noisy as i64,
                (counts as i64 + simulated_noise_counts(n) as i64).rem_euclid(REV)
            );
        }
    }
}

#[test]
fn simulated_noise_is_the_hash_modulo_three_at_any_sample_index() {
    let oracle = |n: u32| ((n as u64 * 2_654_435_761 % (1 << 32)) >> 30) as i32 % 3 - 1;
    for n in (0..100_000u32).chain(u32::MAX - 100_000..=u32::MAX) {
        assert_eq!(simulated_noise_counts(n), oracle(n), "{n}");
    }
}

#[test]
fn stored_calibration_words_are_refused_past_their_bits() {
    for zero in 0..ENCODER_COUNTS_PER_REV {
        for reversed in [false, true] {
            let c = cal(zero, reversed);
            assert_eq!(
                AngleCalibration::from_stored_word(c.to_stored_word()),
                Some(c)
            );
        }
    }
    // A zero past the 14 bits (set by hand) comes back as the same angle.
    for zero in [16384u16, 32768, u16::MAX] {
        let c = cal(zero, true);
        let back = AngleCalibration::from_stored_word(c.to_stored_word()).unwrap();
        assert_eq!(back.zero_counts as i64, (zero as i64).rem_euclid(REV));
        for counts in U16_EXTREMES {
            assert_eq!(back.angle_rad(counts), c.angle_rad(counts));
        }
    }
    for bad in [
        1u32 << 17,
        1 << 31,
        0xFFFF_FFFF,
        0x0002_0000 | 4000,
        0x8001_3FFF,
    ] {
        assert_eq!(AngleCalibration::from_stored_word(bad), None, "{bad:#x}");
    }
}

/// The PWM decode computed in u128.
fn pwm_oracle(high: u32, period: u32, range: (u32, u32)) -> Result<u16, EncoderError> {
    if period < range.0 || period > range.1 || period == 0 {
        return Err(EncoderError::NoSignal);
    }
    let units = (high as u128 * FRAME_UNITS as u128 + period as u128 / 2) / period as u128;
    if units < HEADER_UNITS as u128 {
        return Err(EncoderError::ErrorFlag { word: units as u16 });
    }
    Ok(((units - HEADER_UNITS as u128).min(MAX_ANGLE_12 as u128) * 4) as u16)
}

#[test]
fn pwm_frames_at_the_extremes_decode_as_the_wide_oracle() {
    let ticks = [
        0u32,
        1,
        2,
        15,
        16,
        4118,
        4119,
        4120,
        1 << 20,
        u32::MAX - 1,
        u32::MAX,
    ];
    let ranges = [
        (0, u32::MAX),
        (1, u32::MAX),
        (3295, 4943),
        (u32::MAX, u32::MAX),
    ];
    for high in ticks {
        for period in ticks {
            for range in ranges {
                let frame = PwmFrame {
                    high_ticks: high,
                    period_ticks: period,
                };
                let r = decode(frame, range);
                assert_eq!(
                    r,
                    pwm_oracle(high, period, range),
                    "{high} {period} {range:?}"
                );
                if let Ok(c) = r {
                    assert!(c < ENCODER_COUNTS_PER_REV);
                }
            }
        }
    }
    // A high time far past the period (a glitch) is full scale, not a wrapped angle.
    let glitch = PwmFrame {
        high_ticks: u32::MAX,
        period_ticks: 1,
    };
    assert_eq!(decode(glitch, (0, u32::MAX)), Ok(4095 * 4));
}

struct OneFrame(Option<PwmFrame>);
impl PwmCapture for OneFrame {
    fn take_frame(&mut self) -> Option<PwmFrame> {
        self.0.take()
    }
}

#[test]
fn the_pwm_period_window_saturates_for_a_huge_nominal_period() {
    // ±20 % of u32::MAX: the top of the window saturates at u32::MAX (it used to wrap below
    // the bottom, refusing every frame).
    let period = u32::MAX - 1;
    let frame = PwmFrame {
        high_ticks: period / 2,
        period_ticks: period,
    };
    let mut enc = PwmAngleEncoder::new(OneFrame(Some(frame)), cal(0, false), u32::MAX, 2);
    let s = enc.read_angle().unwrap();
    assert_eq!(
        Ok(s.counts),
        pwm_oracle(frame.high_ticks, period, (0, u32::MAX))
    );
    for nominal in [0u32, 1, 4, 5, 4119, u32::MAX / 6 * 5, u32::MAX] {
        let mut enc = PwmAngleEncoder::new(OneFrame(Some(frame)), cal(0, false), nominal, 2);
        let lo = nominal as u64 / 5 * 4;
        let hi = (nominal as u64 / 5 * 6).min(u32::MAX as u64);
        let inside = (lo..=hi).contains(&(period as u64));
        assert_eq!(enc.read_angle().is_ok(), inside, "{nominal}");
    }
}

#[test]
fn the_spool_counter_unwraps_across_the_16_bit_wrap_and_saturates_at_i32() {
    let mut u = CounterUnwrap::default();
    assert_eq!(u.update(u16::MAX), 65_535);
    assert_eq!(u.update(0), 65_536, "one count forward across the wrap");
    assert_eq!(u.update(u16::MAX), 65_535, "and back");
    // Forward by 32,767 per read until far past i32::MAX: saturates, never turns negative.
    let mut u = CounterUnwrap::default();
    let mut raw = 0u16;
    let mut total = u.update(raw) as i64;
    let mut wide = 0i64;
    for _ in 0..70_000 {
        raw = raw.wrapping_add(32_767);
        wide += 32_767;
        let t = u.update(raw) as i64;
        assert!(t >= total, "monotone");
        assert_eq!(t, wide.min(i32::MAX as i64));
        total = t;
    }
    assert_eq!(total, i32::MAX as i64);
    // And backwards to i32::MIN.
    let mut u = CounterUnwrap::default();
    let mut raw = 0u16;
    u.update(raw);
    let mut wide = 0i64;
    for _ in 0..70_000 {
        raw = raw.wrapping_sub(32_768);
        wide -= 32_768;
        assert_eq!(u.update(raw) as i64, wide.max(i32::MIN as i64));
    }
}

#[test]
fn duty_is_clamped_to_the_timer_range_and_nan_is_off() {
    for max in [0u16, 1, 999, 1000, u16::MAX] {
        for f in F32_EXTREMES
            .into_iter()
            .chain([1.0, 1.000_000_1, 2.0, -1.0])
        {
            let d = duty_from_fraction(f, max);
            assert!(d <= max, "{f} {max}");
            let expected = if f.is_nan() || f <= 0.0 {
                0
            } else if f >= 1.0 {
                max
            } else {
                (f * max as f32) as u16
            };
            assert_eq!(d, expected, "{f} {max}");
        }
        // In range: exactly the old truncating product.
        for k in 0..=1000 {
            let f = k as f32 / 1000.0;
            assert_eq!(duty_from_fraction(f, max), (f * max as f32) as u16);
        }
    }
}

#[test]
fn float_details_saturate_and_nan_reads_as_zero() {
    for x in F32_EXTREMES {
        let expected16 = if x.is_nan() {
            0
        } else {
            (x as f64).trunc().clamp(i16::MIN as f64, i16::MAX as f64) as i64
        };
        assert_eq!(saturating_i16(x) as i64, expected16, "{x}");
        let expected32 = if x.is_nan() {
            0
        } else {
            (x as f64).trunc().clamp(i32::MIN as f64, i32::MAX as f64) as i64
        };
        assert_eq!(saturating_i32(x) as i64, expected32, "{x}");
    }
}

#[test]
fn plausibility_details_of_extreme_samples_saturate() {
    let p = ReflexParams::default();
    let mut pl = Plausibility::default();
    let sample = |counts, angle_rad| Ok(AngleSample { counts, angle_rad });
    let f = pl.check(
        Instant::from_millis(0),
        &sample(0, f32::INFINITY),
        false,
        &p,
    );
    assert_eq!(f.range, Some(i16::MAX));
    let f = pl.check(
        Instant::from_millis(1),
        &sample(0, f32::NEG_INFINITY),
        false,
        &p,
    );
    assert_eq!(f.range, Some(i16::MIN));
    let f = pl.check(Instant::from_millis(2), &sample(0, f32::NAN), false, &p);
    assert_eq!(f.range, Some(0), "a NaN angle is out of range, detail 0");
    // A reading past i16 that sticks while driving: the detail saturates.
    let mut pl = Plausibility::default();
    let mut stuck = None;
    for ms in 0..200 {
        let f = pl.check(Instant::from_millis(ms), &sample(u16::MAX, 0.0), true, &p);
        stuck = stuck.or(f.stuck);
    }
    assert_eq!(stuck, Some(i16::MAX));
    let f = pl.check(
        Instant::from_millis(300),
        &Err(EncoderError::ErrorFlag { word: u16::MAX }),
        true,
        &p,
    );
    assert_eq!(f.comms, Some(3));
}

#[test]
fn clocks_near_the_u32_and_u64_limits() {
    let two32 = 1u64 << 32;
    for us in [0, 1, two32 - 1, two32, two32 + 1, u64::MAX - 1, u64::MAX] {
        let t = Instant::from_micros(us);
        assert_eq!(t.uptime_us() as u64, us % two32, "{us}");
        assert_eq!(t.uptime_ms() as u64, us / 1000 % two32, "{us}");
        assert_eq!(t.micros_since(Instant(u64::MAX)), 0);
        assert_eq!(Instant(u64::MAX).micros_since(t), u64::MAX - us);
    }
    for ms in [
        two32 * 1000 - 1,
        two32 * 1000,
        u64::MAX / 1000,
        u64::MAX / 1000 + 1,
        u64::MAX,
    ] {
        let t = Instant::from_millis(ms);
        assert_eq!(
            t.0 as u128,
            (ms as u128 * 1000).min(u64::MAX as u128),
            "{ms}"
        );
    }
}

#[test]
fn parameter_values_at_the_extremes_are_refused_and_the_old_value_stays() {
    for id in ParamId::ALL {
        for raw in [i32::MIN, i32::MIN + 1, -1, 0, 1, i32::MAX - 1, i32::MAX] {
            let mut p = ReflexParams::default();
            let before = p.wire_value(*id);
            let r = p.set(*id, ParamValue(raw));
            let v = ParamValue(raw).to_si();
            let (lo, hi) = id.range_si();
            if (lo..=hi).contains(&v) {
                // In range; the consistency check may still refuse.
                assert!(
                    matches!(r, Ok(()) | Err(ParamStatus::Inconsistent)),
                    "{id:?} {raw}"
                );
            } else {
                assert_eq!(r, Err(ParamStatus::OutOfRange), "{id:?} {raw}");
                assert_eq!(p.wire_value(*id), before, "the old value stays");
            }
        }
    }
}

/// The node driven at chosen instants.
struct Bench {
    node: AnkleNode,
}

impl Bench {
    fn tick(
        &mut self,
        now: Instant,
        angle: Result<AngleSample, EncoderError>,
        rx: &[Message],
        drivers: DriverHealth,
    ) -> TickOutputs {
        let out = self.node.tick(
            now,
            &TickInputs {
                angle,
                contact_closed: false,
                received: rx,
                drivers,
            },
        );
        for m in &out.transmit {
            assert!(
                m.encode().is_ok(),
                "every message the node sends encodes: {m:?}"
            );
        }
        out
    }
}

fn good(counts: u16) -> Result<AngleSample, EncoderError> {
    let c = firmware::scenarios::CALIBRATION;
    Ok(AngleSample {
        counts,
        angle_rad: c.angle_rad(counts),
    })
}

#[test]
fn the_node_past_the_wire_clocks_wrap_sends_wrapped_uptimes_that_encode() {
    // Past 2³² ms and another 2²⁴ ms: the heartbeat's and fault's 32-bit uptime and the fault
    // history's 24-bit one have all wrapped.
    let ms = (1u64 << 32) + (1 << 24) + 12_345;
    let mut b = Bench {
        node: AnkleNode::new(NodeConfig::nominal(NodeId::LeftAnkle)).unwrap(),
    };
    let zero = firmware::scenarios::CALIBRATION.zero_counts;
    let mut seen_heartbeat = false;
    for k in 0..200 {
        let now = Instant::from_millis(ms + k);
        let o = b.tick(now, good(zero), &[], DriverHealth::default());
        for m in &o.transmit {
            if let Message::Heartbeat(h) = m {
                assert_eq!(h.uptime_ms as u64, (ms + k) % (1 << 32));
                seen_heartbeat = true;
            }
        }
    }
    assert!(seen_heartbeat);
    let now = Instant::from_millis(ms + 200);
    let o = b.tick(
        now,
        Err(EncoderError::Parity { word: 1 }),
        &[],
        DriverHealth::default(),
    );
    let raised = o
        .transmit
        .iter()
        .find_map(|m| match m {
            Message::Fault(f) if f.code == FaultCode::EncoderComms => Some(*f),
            _ => None,
        })
        .unwrap();
    assert_eq!(raised.uptime_ms as u64, (ms + 200) % (1 << 32));
    let history_request = Message::Command(Command {
        target: Target::Node(NodeId::LeftAnkle),
        kind: CommandKind::GetFaultHistory,
    });
    let o = b.tick(
        Instant::from_millis(ms + 201),
        good(zero),
        &[history_request],
        DriverHealth::default(),
    );
    let entry = o
        .transmit
        .iter()
        .find_map(|m| match m {
            Message::FaultHistory(e) if e.code == FaultCode::EncoderComms => Some(*e),
            _ => None,
        })
        .unwrap();
    assert_eq!(entry.uptime_ms as u64, (ms + 200) % (1 << 24));

    // The last microseconds of u64: still ticking, every message encodes.
    for us in [u64::MAX - 2_000, u64::MAX - 1_000, u64::MAX] {
        b.tick(Instant(us), good(zero), &[], DriverHealth::default());
    }
}

#[test]
fn lost_frames_are_totalled_saturating_not_wrapping() {
    let mut b = Bench {
        node: AnkleNode::new(NodeConfig::nominal(NodeId::LeftAnkle)).unwrap(),
    };
    let zero = firmware::scenarios::CALIBRATION.zero_counts;
    let lost = |n| DriverHealth {
        rx_lost: n,
        ..DriverHealth::default()
    };
    let newest_overflow_detail = |node: &AnkleNode| {
        node.fault_history()
            .find(|(code, ..)| *code == FaultCode::CanRxOverflow)
            .map(|(_, detail, ..)| detail)
    };
    b.tick(Instant::from_millis(0), good(zero), &[], lost(u32::MAX));
    assert_eq!(newest_overflow_detail(&b.node), Some(i16::MAX));
    b.tick(Instant::from_millis(1), good(zero), &[], lost(0));
    // One more lost frame: the total stays at u32::MAX (a wrap would give 0).
    b.tick(Instant::from_millis(200), good(zero), &[], lost(1));
    assert_eq!(b.node.fault_history().count(), 2);
    assert_eq!(newest_overflow_detail(&b.node), Some(i16::MAX));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4096))]

    /// Any angle — huge, infinite, NaN — gives a reading in range, and (for finite angles)
    /// the reading of the angle rounded to counts, reduced modulo a revolution.
    #[test]
    fn any_angle_gives_a_reading_in_range(
        a in any::<f32>(),
        zero in any::<u16>(),
        reversed in any::<bool>(),
    ) {
        let c = cal(zero, reversed);
        let counts = c.counts(a);
        prop_assert!(counts < ENCODER_COUNTS_PER_REV);
        let per_rad = ENCODER_COUNTS_PER_REV as f32 / TAU;
        let r = (a * per_rad).round();
        let expected = if r.is_finite() {
            let d = (r as f64).rem_euclid(REV as f64) as i64;
            let d = if reversed { -d } else { d };
            (zero as i64 + d).rem_euclid(REV)
        } else {
            (zero as i64).rem_euclid(REV)
        };
        prop_assert_eq!(counts as i64, expected);
    }

    #[test]
    fn any_offset_is_exact(counts in any::<u16>(), delta in any::<i32>()) {
        prop_assert_eq!(
            offset_counts(counts, delta) as i64,
            (counts as i64 + delta as i64).rem_euclid(REV)
        );
    }

    #[test]
    fn any_pwm_frame_decodes_as_the_wide_oracle(
        high in any::<u32>(),
        period in any::<u32>(),
        lo in any::<u32>(),
        hi in any::<u32>(),
    ) {
        let frame = PwmFrame { high_ticks: high, period_ticks: period };
        prop_assert_eq!(decode(frame, (lo, hi)), pwm_oracle(high, period, (lo, hi)));
        prop_assert_eq!(
            decode(frame, (0, u32::MAX)),
            pwm_oracle(high, period, (0, u32::MAX))
        );
    }
}
