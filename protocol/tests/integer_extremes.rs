//! Every integer conversion of a wire value at its extremes: a value that does not fit is
//! refused (or, where the function says so, saturated), never wrapped; any bytes decode
//! without a panic, and what decodes encodes back to the same bytes.
//!
//! The oracles compute in a wider type (i64, i128, f64) than the code under test, so a wrap
//! or a saturation where a refusal is due shows as a mismatch even in a release build
//! (where overflow does not panic).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use proptest::prelude::*;
use protocol::busload::{unstuffed_frame_bits, worst_case_frame_bits};
use protocol::signal::{Kind, SignalSpec};
use protocol::*;

/// Every kind of float a sensor, a model or a host can hand over.
const F32_EXTREMES: [f32; 16] = [
    0.0,
    -0.0,
    f32::MIN_POSITIVE,
    -f32::MIN_POSITIVE,
    1.0e-45, // smallest subnormal
    0.5,
    -0.5,
    1.0e6,
    -1.0e6,
    1.0e30,
    -1.0e30,
    f32::MAX,
    f32::MIN,
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::NAN,
];

/// Raw integers around every signal kind's limits.
const I64_EXTREMES: [i64; 22] = [
    i64::MIN,
    i64::MIN + 1,
    i32::MIN as i64 - 1,
    i32::MIN as i64,
    i16::MIN as i64 - 1,
    i16::MIN as i64,
    -1,
    0,
    1,
    u8::MAX as i64,
    u8::MAX as i64 + 1,
    i16::MAX as i64,
    i16::MAX as i64 + 1,
    u16::MAX as i64,
    u16::MAX as i64 + 1,
    0xFF_FFFF,
    0x100_0000,
    i32::MAX as i64,
    i32::MAX as i64 + 1,
    u32::MAX as i64,
    u32::MAX as i64 + 1,
    i64::MAX,
];

/// What a checked quantisation must give for `value`: the rounded count if it lies in
/// `min..=max` (decided in f64, exact for every f32 and every i32), else `None`.
fn oracle(value: f32, inv_scale: f32, min: i64, max: i64) -> Option<i64> {
    let r = (value * inv_scale).round() as f64;
    (r >= min as f64 && r <= max as f64).then_some(r as i64)
}

/// The same, saturating: clamped to `min..=max`, NaN to 0.
fn saturating_oracle(value: f32, inv_scale: f32, min: i64, max: i64) -> i64 {
    let r = (value * inv_scale).round() as f64;
    if r.is_nan() {
        0
    } else {
        r.clamp(min as f64, max as f64) as i64
    }
}

/// f32 values around `x`: `n` representable steps either side.
fn around(x: f32, n: u32) -> impl Iterator<Item = f32> {
    let b = x.to_bits();
    (b.saturating_sub(n)..=b.saturating_add(n)).map(f32::from_bits)
}

fn check_scaled(value: f32) {
    let (imin, imax) = (i16::MIN as i64, i16::MAX as i64);
    let angle = Angle::from_si(value).ok().map(|a| a.0 as i64);
    assert_eq!(angle, oracle(value, 1.0e4, imin, imax), "Angle {value:e}");
    let rate = AngularRate::from_si(value).ok().map(|a| a.0 as i64);
    assert_eq!(
        rate,
        oracle(value, 1.0e3, imin, imax),
        "AngularRate {value:e}"
    );
    let (pmin, pmax) = (i32::MIN as i64, i32::MAX as i64);
    let param = ParamValue::from_si(value).ok().map(|p| p.0 as i64);
    assert_eq!(
        param,
        oracle(value, 1.0e6, pmin, pmax),
        "ParamValue {value:e}"
    );

    assert_eq!(
        Angle::saturating_from_si(value).0 as i64,
        saturating_oracle(value, 1.0e4, imin, imax),
        "Angle saturating {value:e}"
    );
    assert_eq!(
        AngularRate::saturating_from_si(value).0 as i64,
        saturating_oracle(value, 1.0e3, imin, imax),
        "AngularRate saturating {value:e}"
    );
    assert_eq!(
        ParamValue::saturating_from_si(value).0 as i64,
        saturating_oracle(value, 1.0e6, pmin, pmax),
        "ParamValue saturating {value:e}"
    );
}

#[test]
fn scaled_values_are_refused_or_saturated_at_the_extremes() {
    for v in F32_EXTREMES {
        check_scaled(v);
    }
    // Around each raw type's edges, every representable f32 (with the f32 products the codec
    // computes). For ParamValue the edge 2³¹ counts is where `i32::MAX as f32` (= 2³¹)
    // used to let a value through that only fitted by saturating.
    for edge in [
        i16::MAX as f32 / 1.0e4,
        i16::MIN as f32 / 1.0e4,
        i16::MAX as f32 / 1.0e3,
        i16::MIN as f32 / 1.0e3,
        2_147_483_648.0 / 1.0e6,
        -2_147_483_648.0 / 1.0e6,
    ] {
        for v in around(edge, 4096) {
            check_scaled(v);
        }
    }
    assert!(ParamValue::from_si(2_147_483_648.0 / 1.0e6).is_err());
    assert_eq!(
        ParamValue::from_si(-2_147_483_648.0 / 1.0e6),
        Ok(ParamValue(i32::MIN))
    );
    assert_eq!(Angle::from_si(3.2767), Ok(Angle(i16::MAX)));
    assert_eq!(Angle::from_si(-3.2768), Ok(Angle(i16::MIN)));
    assert!(Angle::from_si(3.27676).is_err());
}

#[test]
fn parameter_values_at_the_extremes_are_refused_with_the_parameter_range() {
    for p in ParamId::ALL {
        for v in F32_EXTREMES {
            let r = Command::set_param(Target::Broadcast, *p, v);
            let (lo, hi) = p.range_si();
            assert_eq!(r.is_ok(), (lo..=hi).contains(&v), "{p:?} {v:e}");
        }
    }
}

fn all_signals() -> impl Iterator<Item = &'static SignalSpec> {
    MESSAGES.iter().flat_map(|m| m.signals.iter())
}

#[test]
fn put_refuses_every_raw_value_outside_its_signal_and_get_reads_it_back() {
    for s in all_signals() {
        let (min, max) = (s.kind.raw_min(), s.kind.raw_max());
        for raw in I64_EXTREMES.into_iter().chain([min, max, min - 1, max + 1]) {
            let mut buf = [0xA5u8; 8];
            let r = s.put(&mut buf, raw);
            if (min..=max).contains(&raw) {
                assert_eq!(r, Ok(()), "{} {raw}", s.name);
                assert_eq!(s.get(&buf), raw, "{} {raw}", s.name);
            } else {
                assert_eq!(
                    r,
                    Err(EncodeError::RawOutOfRange {
                        signal: s.name,
                        raw,
                        min,
                        max
                    }),
                    "{}",
                    s.name
                );
                assert_eq!(buf, [0xA5; 8], "{}: nothing written on a refusal", s.name);
            }
        }
    }
}

#[test]
fn get_of_any_bytes_stays_in_the_signal_range() {
    for s in all_signals() {
        for fill in [0x00u8, 0x01, 0x7F, 0x80, 0xFE, 0xFF] {
            let raw = s.get(&[fill; 8]);
            assert!(
                (s.kind.raw_min()..=s.kind.raw_max()).contains(&raw),
                "{} {fill:#x}: {raw}",
                s.name
            );
        }
        // All ones is −1 for signed kinds and the maximum for unsigned ones.
        let ones = s.get(&[0xFF; 8]);
        assert_eq!(
            ones,
            if s.kind.signed() {
                -1
            } else {
                s.kind.raw_max()
            }
        );
        // A sign bit alone is the minimum of a signed kind.
        let mut b = [0u8; 8];
        b[s.byte as usize + s.kind.bytes() as usize - 1] = 0x80;
        if s.kind.signed() {
            assert_eq!(s.get(&b), s.kind.raw_min(), "{}", s.name);
        }
        assert_eq!(s.get_as::<i64>(&[0xFF; 8]), Ok(ones));
    }
}

#[test]
fn get_as_refuses_a_field_type_narrower_than_the_raw_value() {
    let s = &messages::layout::heartbeat::UPTIME_MS;
    assert_eq!(s.kind, Kind::U32);
    assert_eq!(s.get_as::<u32>(&[0xFF; 8]), Ok(u32::MAX));
    assert_eq!(
        s.get_as::<u16>(&[0xFF; 8]),
        Err(DecodeError::ValueOutOfRange {
            signal: "uptime",
            raw: u32::MAX as i64
        })
    );
    assert_eq!(
        s.get_as::<i32>(&[0xFF; 8]),
        Err(DecodeError::ValueOutOfRange {
            signal: "uptime",
            raw: u32::MAX as i64
        })
    );
    let angle = &messages::layout::ankle_state::ANGLE;
    assert_eq!(
        angle.get_as::<i16>(&[0x00, 0x80, 0, 0, 0, 0, 0, 0]),
        Ok(i16::MIN)
    );
    assert!(angle
        .get_as::<u16>(&[0x00, 0x80, 0, 0, 0, 0, 0, 0])
        .is_err());
}

fn history(uptime_ms: u32) -> Message {
    Message::FaultHistory(FaultHistoryEntry {
        node: NodeId::LeftAnkle,
        entry: u8::MAX,
        code: FaultCode::CanRxOverflow,
        state_after: NodeState::EmergencyStop,
        detail: i16::MIN,
        uptime_ms,
    })
}

#[test]
fn the_fault_history_uptime_is_refused_past_24_bits_not_cut() {
    for ok in [0, 1, 0xFF_FFFE, 0xFF_FFFF] {
        let m = history(ok);
        let f = m.encode().unwrap();
        assert_eq!(Message::decode(f.id.raw(), f.payload()), Ok(m));
    }
    for too_big in [0x100_0000u32, 0x100_0001, 0x7FFF_FFFF, u32::MAX] {
        let mut buf = [0x5Au8; 8];
        let r = history(too_big).encode_into(&mut buf);
        assert_eq!(
            r,
            Err(EncodeError::RawOutOfRange {
                signal: "uptime",
                raw: too_big as i64,
                min: 0,
                max: 0xFF_FFFF
            })
        );
        assert_eq!(buf, [0x5A; 8], "the buffer untouched on a refusal");
        assert!(history(too_big).encode().is_err());
        assert!(r.unwrap_err().to_string().contains("outside [0, 16777215]"));
    }
}

#[test]
fn every_field_at_its_extremes_round_trips() {
    let mut msgs = Vec::new();
    for node in NodeId::ANKLES {
        for (u16v, u32v, i16v, i32v, u8v) in [
            (0u16, 0u32, i16::MIN, i32::MIN, 0u8),
            (u16::MAX, u32::MAX, i16::MAX, i32::MAX, u8::MAX),
            (1, 1, -1, -1, 1),
        ] {
            msgs.push(Message::HeelStrike(HeelStrike {
                node,
                step_count: u16v,
                time_us: u32v,
            }));
            msgs.push(Message::AnkleState(AnkleState {
                node,
                angle: Angle(i16v),
                rate: AngularRate(i16v),
                actuator_position: Angle(i16v),
                phase: ReflexPhase::Hold,
            }));
            msgs.push(Message::Heartbeat(Heartbeat {
                node,
                state: NodeState::Enabled,
                faults: FaultFlags::from_bits(FaultFlags::defined_bits()).unwrap(),
                uptime_ms: u32v,
            }));
            msgs.push(Message::Command(Command {
                target: Target::Broadcast,
                kind: CommandKind::SetParam {
                    param: ParamId::StuckTimeout,
                    value: ParamValue(i32v),
                },
            }));
            msgs.push(Message::ParamAck(ParamAck {
                node,
                param: ParamId::TautAngle,
                status: ParamStatus::OutOfRange,
                value: ParamValue(i32v),
            }));
            msgs.push(Message::Fault(FaultEvent {
                node,
                code: FaultCode::EncoderRange,
                transition: FaultTransition::Raised,
                detail: i16v,
                uptime_ms: u32v,
            }));
            msgs.push(Message::Version(Version {
                node,
                protocol: u8v,
                major: u8v,
                minor: u8v,
                patch: u8v,
                build: u32v,
            }));
            msgs.push(Message::Identity(Identity {
                node,
                uid_low: u32v,
                uid_mid: u32v,
            }));
            msgs.push(Message::BootInfo(BootInfo {
                node,
                uid_high: u32v,
                reset_cause: ResetCause::OptionBytes,
                params_source: ConfigSource::FlashUnreadable,
                fault_history_len: u8v,
                calibration_source: ConfigSource::Flash,
            }));
            msgs.push(Message::FaultHistory(FaultHistoryEntry {
                node,
                entry: u8v,
                code: FaultCode::EncoderRange,
                state_after: NodeState::Safe,
                detail: i16v,
                uptime_ms: u32v & 0xFF_FFFF,
            }));
        }
    }
    for m in msgs {
        let f = m.encode().unwrap();
        assert_eq!(Message::decode(f.id.raw(), f.payload()), Ok(m), "{m:?}");
    }
}

#[test]
fn identifiers_over_all_u16() {
    for raw in 0..=u16::MAX {
        match CanId::from_raw(raw) {
            Ok(id) => {
                assert!(raw <= 0x7FF);
                assert_eq!(id.raw(), raw);
            }
            Err(e) => assert!(
                raw > 0x7FF || MessageClass::from_raw((raw >> 4) as u8).is_none(),
                "{raw:#x}: {e:?}"
            ),
        }
        // Any identifier and any payload length: an answer, never a panic.
        let _ = Message::decode(raw, &[0xFF; 8]);
        let _ = Message::decode(raw, &[]);
    }
}

#[test]
fn frame_lengths_over_every_dlc_byte() {
    for dlc in 0..=u8::MAX {
        let exposed = 34 + 8 * dlc as u64;
        let worst = exposed + 13 + (exposed - 1) / 4;
        assert_eq!(worst_case_frame_bits(dlc) as u64, worst, "{dlc}");
        assert_eq!(unstuffed_frame_bits(dlc) as u64, exposed + 13, "{dlc}");
    }
    assert_eq!(worst_case_frame_bits(8), 135);
}

/// Every identifier of the protocol with the message's length.
fn known_frames() -> Vec<(u16, usize)> {
    let mut v = Vec::new();
    for m in MESSAGES {
        for node in m.node_fields() {
            v.push((CanId::new(m.class, node).raw(), m.dlc as usize));
        }
    }
    v
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4096))]

    /// Whatever bytes arrive under a known identifier, decoding answers (no panic), and a
    /// frame that decodes encodes back to the very same bytes: no field was cut or wrapped on
    /// the way in.
    #[test]
    fn what_decodes_encodes_back_to_the_same_bytes(
        k in 0usize..64,
        data in prop::array::uniform8(any::<u8>()),
    ) {
        let frames = known_frames();
        let (id, dlc) = frames[k % frames.len()];
        let payload = &data[..dlc];
        if let Ok(m) = Message::decode(id, payload) {
            let f = m.encode().unwrap();
            prop_assert_eq!(f.id.raw(), id);
            prop_assert_eq!(f.payload(), payload);
        }
    }

    /// Any f32: the checked quantisation is the oracle's (exact count or refusal), the
    /// saturating one the clamped count.
    #[test]
    fn any_float_quantises_exactly_or_is_refused(v in any::<f32>()) {
        check_scaled(v);
    }

    /// Any i64 into any signal: written exactly when it fits, refused otherwise.
    #[test]
    fn any_raw_value_is_written_exactly_or_refused(k in 0usize..64, raw in any::<i64>()) {
        let signals: Vec<_> = all_signals().collect();
        let s = signals[k % signals.len()];
        let mut buf = [0u8; 8];
        let fits = (s.kind.raw_min()..=s.kind.raw_max()).contains(&raw);
        prop_assert_eq!(s.put(&mut buf, raw).is_ok(), fits);
        if fits {
            prop_assert_eq!(s.get(&buf), raw);
        } else {
            prop_assert_eq!(buf, [0u8; 8]);
        }
    }
}
