//! Property: every message decodes back to itself, bit for bit, and its frame has the
//! message's fixed length and identifier layout.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use proptest::prelude::*;
use protocol::*;

fn node() -> impl Strategy<Value = NodeId> {
    prop::sample::select(NodeId::ALL.to_vec())
}
fn ankle() -> impl Strategy<Value = NodeId> {
    prop::sample::select(NodeId::ANKLES.to_vec())
}
fn target() -> impl Strategy<Value = Target> {
    prop_oneof![ankle().prop_map(Target::Node), Just(Target::Broadcast)]
}
fn pick<T: Copy + core::fmt::Debug + 'static>(all: &'static [T]) -> impl Strategy<Value = T> {
    prop::sample::select(all.to_vec())
}

fn message() -> impl Strategy<Value = Message> {
    prop_oneof![
        (ankle(), any::<u16>(), any::<u32>()).prop_map(|(node, step_count, time_us)| {
            Message::HeelStrike(HeelStrike {
                node,
                step_count,
                time_us,
            })
        }),
        (
            ankle(),
            any::<i16>(),
            any::<i16>(),
            any::<i16>(),
            pick(ReflexPhase::ALL)
        )
            .prop_map(|(node, a, r, p, phase)| Message::AnkleState(AnkleState {
                node,
                angle: Angle(a),
                rate: AngularRate(r),
                actuator_position: Angle(p),
                phase,
            })),
        (
            node(),
            pick(NodeState::ALL),
            0..=FaultFlags::defined_bits(),
            any::<u32>()
        )
            .prop_map(
                |(node, state, bits, uptime_ms)| Message::Heartbeat(Heartbeat {
                    node,
                    state,
                    faults: FaultFlags::from_bits(bits & FaultFlags::defined_bits())
                        .unwrap_or_default(),
                    uptime_ms,
                })
            ),
        (
            target(),
            prop_oneof![
                Just(CommandKind::Enable),
                Just(CommandKind::Disable),
                Just(CommandKind::EmergencyStop),
                Just(CommandKind::SaveParams),
                Just(CommandKind::ClearErrors),
                Just(CommandKind::GetIdentity),
                Just(CommandKind::GetFaultHistory),
                Just(CommandKind::CalibrateEncoderZero),
                pick(ParamId::ALL).prop_map(|param| CommandKind::GetParam { param }),
                (pick(ParamId::ALL), any::<i32>()).prop_map(|(param, v)| {
                    CommandKind::SetParam {
                        param,
                        value: ParamValue(v),
                    }
                })
            ]
        )
            .prop_map(|(target, kind)| Message::Command(Command { target, kind })),
        (
            ankle(),
            pick(ParamId::ALL),
            pick(ParamStatus::ALL),
            any::<i32>()
        )
            .prop_map(|(node, param, status, v)| Message::ParamAck(ParamAck {
                node,
                param,
                status,
                value: ParamValue(v),
            })),
        (
            ankle(),
            pick(FaultCode::ALL),
            pick(FaultTransition::ALL),
            any::<i16>(),
            any::<u32>()
        )
            .prop_map(|(node, code, transition, detail, uptime_ms)| {
                Message::Fault(FaultEvent {
                    node,
                    code,
                    transition,
                    detail,
                    uptime_ms,
                })
            }),
        (node(), any::<[u8; 4]>(), any::<u32>()).prop_map(|(node, v, build)| {
            Message::Version(Version {
                node,
                protocol: v[0],
                major: v[1],
                minor: v[2],
                patch: v[3],
                build,
            })
        }),
        (ankle(), any::<u32>(), any::<u32>()).prop_map(|(node, uid_low, uid_mid)| {
            Message::Identity(Identity {
                node,
                uid_low,
                uid_mid,
            })
        }),
        (
            ankle(),
            any::<u32>(),
            pick(ResetCause::ALL),
            pick(ConfigSource::ALL),
            any::<u8>(),
            pick(ConfigSource::ALL)
        )
            .prop_map(|(node, uid_high, reset_cause, params_source, n, cal)| {
                Message::BootInfo(BootInfo {
                    node,
                    uid_high,
                    reset_cause,
                    params_source,
                    fault_history_len: n,
                    calibration_source: cal,
                })
            }),
        (ankle(), pick(Opcode::ALL), pick(CommandResult::ALL)).prop_map(
            |(node, opcode, result)| Message::CommandAck(CommandAck {
                node,
                opcode,
                result,
            })
        ),
        (
            ankle(),
            any::<u8>(),
            pick(FaultCode::ALL),
            pick(NodeState::ALL),
            any::<i16>(),
            0u32..=0xFF_FFFF
        )
            .prop_map(|(node, entry, code, state_after, detail, uptime_ms)| {
                Message::FaultHistory(FaultHistoryEntry {
                    node,
                    entry,
                    code,
                    state_after,
                    detail,
                    uptime_ms,
                })
            }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4096))]

    #[test]
    fn every_message_round_trips(m in message()) {
        let frame = m.encode().unwrap();
        let spec = spec(frame.id.class).unwrap();
        prop_assert_eq!(frame.len, spec.dlc);
        prop_assert_eq!(frame.id, m.id());
        prop_assert!(frame.id.raw() <= 0x7FF);
        prop_assert_eq!(Message::decode(frame.id.raw(), frame.payload()), Ok(m));
    }

    #[test]
    fn angles_quantise_to_half_a_count(x in -3.2f32..3.2f32) {
        let a = Angle::from_si(x).unwrap();
        prop_assert!((a.to_si() - x).abs() <= 0.5e-4 + 1e-6);
    }

    #[test]
    fn in_range_params_are_accepted_and_out_of_range_refused(k in 0usize..7, f in -0.5f32..1.5f32) {
        let p = ParamId::ALL[k];
        let (lo, hi) = p.range_si();
        let v = lo + f * (hi - lo);
        let r = Command::set_param(Target::Broadcast, p, v);
        prop_assert_eq!(r.is_ok(), (lo..=hi).contains(&v));
    }

    #[test]
    fn decoding_arbitrary_bytes_never_panics(id in 0u16..0x900, data in prop::collection::vec(any::<u8>(), 0..12)) {
        let _ = Message::decode(id, &data);
    }
}
