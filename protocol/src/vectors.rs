//! Shared test vectors: frames encoded by the Rust codec, with the physical value of every
//! signal as the layout table defines it. The Python side decodes the same frames with
//! cantools from the generated DBC file and must get the same values.
//!
//! Host-only test data (feature `std`): the arithmetic and casts here act on small loop
//! indices and chosen constants, not on sensor or wire values, so the crate's integer lints
//! are off for this module; the vectors themselves go through the checked codec.
#![allow(
    clippy::arithmetic_side_effects,
    clippy::cast_possible_truncation,
    clippy::cast_possible_wrap,
    clippy::cast_sign_loss
)]

extern crate alloc;
extern crate std;

use alloc::string::String;
use alloc::vec::Vec;
use core::fmt::Write as _;

use crate::id::{NodeId, Target};
use crate::messages::{
    spec, AnkleState, BootInfo, ClockInfo, Command, CommandAck, CommandKind, FaultEvent,
    FaultHistoryEntry, Heartbeat, HeelStrike, Identity, Message, ParamAck, Version,
};
use crate::values::{
    Angle, AngularRate, ClockSource, CommandResult, ConfigSource, CrystalStatus, FaultCode,
    FaultFlags, FaultTransition, NodeState, Opcode, ParamId, ParamStatus, ParamValue, ReflexPhase,
    ResetCause,
};

/// Messages covering every identifier, every enumeration value at least once, and the
/// extremes of every scaled signal.
pub fn messages() -> Vec<Message> {
    let mut v = Vec::new();
    let targets = [
        Target::Node(NodeId::LeftAnkle),
        Target::Node(NodeId::RightAnkle),
        Target::Broadcast,
    ];
    for (i, node) in NodeId::ANKLES.into_iter().enumerate() {
        let i16s = [i16::MIN, -800, 0, 2000, i16::MAX];
        for (k, phase) in ReflexPhase::ALL.iter().enumerate() {
            v.push(Message::AnkleState(AnkleState {
                node,
                angle: Angle(i16s[k % 5]),
                rate: AngularRate(i16s[(k + 1) % 5]),
                actuator_position: Angle(i16s[(k + 2 + i) % 5]),
                phase: *phase,
            }));
        }
        v.push(Message::HeelStrike(HeelStrike {
            node,
            step_count: u16::MAX - i as u16,
            time_us: 4_000_000_000 + i as u32,
        }));
        for (k, code) in FaultCode::ALL.iter().enumerate() {
            v.push(Message::Fault(FaultEvent {
                node,
                code: *code,
                transition: FaultTransition::ALL[k % 2],
                detail: i16s[k % 5],
                uptime_ms: 123_456 * k as u32,
            }));
        }
        for (k, status) in ParamStatus::ALL.iter().enumerate() {
            let param = ParamId::ALL[k % ParamId::ALL.len()];
            v.push(Message::ParamAck(ParamAck {
                node,
                param,
                status: *status,
                value: param
                    .wire_value(param.default_si())
                    .unwrap_or(ParamValue(i32::MIN)),
            }));
        }
    }
    for (k, node) in NodeId::ALL.into_iter().enumerate() {
        let state = NodeState::ALL[k % NodeState::ALL.len()];
        v.push(Message::Heartbeat(Heartbeat {
            node,
            state,
            faults: FaultFlags::from_bits(FaultFlags::defined_bits() >> k).unwrap_or_default(),
            uptime_ms: u32::MAX - k as u32,
        }));
        v.push(Message::Version(Version {
            node,
            protocol: crate::PROTOCOL_VERSION,
            major: 0,
            minor: 1,
            patch: k as u8,
            build: 0xDEAD_BEEF,
        }));
    }
    for s in NodeState::ALL.iter().skip(NodeId::ALL.len()) {
        v.push(Message::Heartbeat(Heartbeat {
            node: NodeId::LeftAnkle,
            state: *s,
            faults: FaultFlags::NONE,
            uptime_ms: 0,
        }));
    }
    for target in targets {
        for kind in [
            CommandKind::Enable,
            CommandKind::Disable,
            CommandKind::EmergencyStop,
            CommandKind::SaveParams,
            CommandKind::ClearErrors,
            CommandKind::GetIdentity,
            CommandKind::GetFaultHistory,
            CommandKind::CalibrateEncoderZero,
            CommandKind::GetParam {
                param: ParamId::StuckTimeout,
            },
        ] {
            v.push(Message::Command(Command { target, kind }));
        }
    }
    for (k, param) in ParamId::ALL.iter().enumerate() {
        let (lo, hi) = param.range_si();
        let value = if k % 2 == 0 { lo } else { hi };
        if let Ok(c) = Command::set_param(targets[k % 3], *param, value) {
            v.push(Message::Command(c));
        }
    }
    v.push(Message::Command(Command {
        target: Target::Broadcast,
        kind: CommandKind::SetParam {
            param: ParamId::TautAngle,
            value: ParamValue(i32::MIN),
        },
    }));
    for (i, node) in NodeId::ANKLES.into_iter().enumerate() {
        v.push(Message::Identity(Identity {
            node,
            uid_low: 0x0034_0021 + i as u32,
            uid_mid: u32::MAX,
        }));
        for (k, cause) in ResetCause::ALL.iter().enumerate() {
            v.push(Message::BootInfo(BootInfo {
                node,
                uid_high: 0x2020_4E50,
                reset_cause: *cause,
                params_source: ConfigSource::ALL[k % ConfigSource::ALL.len()],
                // Spread over the byte (k * 37 passes 255 for the last cause: reduced on purpose).
                fault_history_len: (k * 37 % 256) as u8,
                calibration_source: ConfigSource::ALL[(k + 1) % ConfigSource::ALL.len()],
            }));
        }
        for (k, source) in ClockSource::ALL.iter().enumerate() {
            v.push(Message::ClockInfo(ClockInfo {
                node,
                source: *source,
                crystal: CrystalStatus::ALL[k % CrystalStatus::ALL.len()],
                oscillator_error_centi_pct: [1, 100, 255][k % 3],
                tolerated_error_ppm: [4_854, 0, u16::MAX][k % 3],
                crystal_freq_10hz: [800_000, 0, 0xFF_FFFF][k % 3],
            }));
        }
        for (k, op) in Opcode::ALL.iter().enumerate() {
            v.push(Message::CommandAck(CommandAck {
                node,
                opcode: *op,
                result: CommandResult::ALL[k % CommandResult::ALL.len()],
            }));
        }
        for (k, code) in FaultCode::ALL.iter().enumerate() {
            v.push(Message::FaultHistory(FaultHistoryEntry {
                node,
                entry: k as u8,
                code: *code,
                state_after: NodeState::ALL[k % NodeState::ALL.len()],
                detail: [i16::MIN, -1, 0, 1, i16::MAX][k % 5],
                uptime_ms: [0, 1, 123_456, 0xFF_FFFF][k % 4],
            }));
        }
    }
    v
}

/// The vectors as JSON: `[{"id": 114, "name": "AnkleState_LEFT_ANKLE", "data": "e0fc...",
/// "signals": {"angle": -0.08, ...}}, ...]`, one vector per line.
pub fn render_json() -> String {
    let mut out = String::from("[\n");
    let msgs = messages();
    for (n, m) in msgs.iter().enumerate() {
        let Ok(frame) = m.encode() else { continue };
        let Some(spec) = spec(frame.id.class) else {
            continue;
        };
        let mut data = [0u8; 8];
        data.copy_from_slice(&frame.data);
        let mut hex = String::new();
        for b in frame.payload() {
            let _ = write!(hex, "{b:02x}");
        }
        let _ = write!(
            out,
            "  {{\"id\": {}, \"name\": \"{}_{}\", \"data\": \"{hex}\", \"signals\": {{",
            frame.id.raw(),
            spec.name,
            spec.node_suffix(frame.id.node_raw)
        );
        for (k, s) in spec.signals.iter().enumerate() {
            let phys = s.phys(s.get(&data));
            let sep = if k == 0 { "" } else { ", " };
            let _ = write!(out, "{sep}\"{}\": {}", s.name, fmt_json(phys));
        }
        let comma = if n + 1 == msgs.len() { "" } else { "," };
        let _ = writeln!(out, "}}}}{comma}");
    }
    out.push_str("]\n");
    out
}

fn fmt_json(v: f64) -> String {
    // `{:?}` prints the shortest round-tripping form, with exponent when needed (valid JSON).
    alloc::format!("{v:?}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vectors_encode_and_decode_back() {
        let msgs = messages();
        assert!(msgs.len() > 40);
        for m in msgs {
            let f = m.encode().unwrap();
            assert_eq!(Message::decode(f.id.raw(), f.payload()), Ok(m));
        }
    }
}
