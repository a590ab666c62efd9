//! Every kind of malformed frame gives its typed error.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use embedded_can::{ExtendedId, Frame, Id, StandardId};
use protocol::*;

/// A minimal embedded-can frame for the tests.
#[derive(Debug)]
struct TestFrame {
    id: Id,
    remote: bool,
    dlc: usize,
    data: [u8; 8],
}

impl Frame for TestFrame {
    fn new(id: impl Into<Id>, data: &[u8]) -> Option<Self> {
        if data.len() > 8 {
            return None;
        }
        let mut d = [0; 8];
        d[..data.len()].copy_from_slice(data);
        Some(TestFrame {
            id: id.into(),
            remote: false,
            dlc: data.len(),
            data: d,
        })
    }
    fn new_remote(id: impl Into<Id>, dlc: usize) -> Option<Self> {
        Some(TestFrame {
            id: id.into(),
            remote: true,
            dlc,
            data: [0; 8],
        })
    }
    fn is_extended(&self) -> bool {
        matches!(self.id, Id::Extended(_))
    }
    fn is_remote_frame(&self) -> bool {
        self.remote
    }
    fn id(&self) -> Id {
        self.id
    }
    fn dlc(&self) -> usize {
        self.dlc
    }
    fn data(&self) -> &[u8] {
        if self.remote {
            &[]
        } else {
            &self.data[..self.dlc]
        }
    }
}

fn state_left() -> Message {
    Message::AnkleState(AnkleState {
        node: NodeId::LeftAnkle,
        angle: Angle(-800),
        rate: AngularRate(0),
        actuator_position: Angle(0),
        phase: ReflexPhase::Free,
    })
}

#[test]
fn wrong_length_short_and_long() {
    let f = state_left().encode().unwrap();
    let id = f.id.raw();
    assert_eq!(
        Message::decode(id, &f.data[..6]),
        Err(DecodeError::WrongLength {
            id,
            expected: 7,
            actual: 6
        })
    );
    assert_eq!(
        Message::decode(id, &f.data[..8]),
        Err(DecodeError::WrongLength {
            id,
            expected: 7,
            actual: 8
        })
    );
    assert_eq!(
        Message::decode(id, &[]),
        Err(DecodeError::WrongLength {
            id,
            expected: 7,
            actual: 0
        })
    );
}

#[test]
fn wrong_length_for_every_message() {
    for m in MESSAGES {
        let node = m.node_fields().next().unwrap();
        let id = CanId::new(m.class, node).raw();
        for len in 0..=8usize {
            if len == m.dlc as usize {
                continue;
            }
            let data = [0u8; 8];
            assert_eq!(
                Message::decode(id, &data[..len]),
                Err(DecodeError::WrongLength {
                    id,
                    expected: m.dlc,
                    actual: len
                }),
                "{} len {len}",
                m.name
            );
        }
    }
}

#[test]
fn unknown_identifiers() {
    // Unknown class.
    assert_eq!(
        Message::decode(0x000, &[]),
        Err(DecodeError::UnknownId { raw: 0 })
    );
    assert_eq!(
        Message::decode(0x0E2, &[0; 8]),
        Err(DecodeError::UnknownId { raw: 0x0E2 })
    );
    // Identity from the host: ankles only.
    assert_eq!(
        Message::decode(0x091, &[0; 8]),
        Err(DecodeError::UnknownId { raw: 0x091 })
    );
    // Known class, node field without that message: ankle telemetry "from" the host,
    // a node number that does not exist, a command to the host.
    assert_eq!(
        Message::decode(0x071, &[0; 7]),
        Err(DecodeError::UnknownId { raw: 0x071 })
    );
    assert_eq!(
        Message::decode(0x075, &[0; 7]),
        Err(DecodeError::UnknownId { raw: 0x075 })
    );
    assert_eq!(
        Message::decode(0x041, &[1, 0, 0, 0, 0, 0]),
        Err(DecodeError::UnknownId { raw: 0x041 })
    );
    // More than 11 bits.
    assert_eq!(
        Message::decode(0x872, &[0; 7]),
        Err(DecodeError::UnknownId { raw: 0x872 })
    );
}

#[test]
fn every_undefined_identifier_is_rejected() {
    let mut defined = 0;
    for raw in 0u16..0x800 {
        let known = MESSAGES.iter().any(|m| {
            m.class.raw() as u16 == raw >> 4 && m.node_fields().any(|n| n as u16 == raw & 0xF)
        });
        let r = Message::decode(raw, &[0u8; 8][..]);
        if known {
            defined += 1;
            assert!(
                !matches!(r, Err(DecodeError::UnknownId { .. })),
                "0x{raw:03X}"
            );
        } else {
            assert_eq!(r, Err(DecodeError::UnknownId { raw: raw as u32 }));
        }
    }
    // emergency stop 3, heel strike 2, fault 2, command 3, ack 2, heartbeat 3, state 2, version 3,
    // identity 2, boot info 2, command ack 2, fault history 2, clock info 2
    assert_eq!(defined, 30);
}

#[test]
fn extended_and_remote_frames() {
    let ext = TestFrame::new(ExtendedId::new(0x72).unwrap(), &[0; 7]).unwrap();
    assert_eq!(
        Message::from_frame(&ext),
        Err(DecodeError::UnknownId { raw: 0x72 })
    );
    let rtr = TestFrame::new_remote(StandardId::new(0x072).unwrap(), 7).unwrap();
    assert_eq!(
        Message::from_frame(&rtr),
        Err(DecodeError::RemoteFrame { raw: 0x072 })
    );
    let ok: TestFrame = state_left().to_frame().unwrap();
    assert_eq!(Message::from_frame(&ok), Ok(state_left()));
}

#[test]
fn out_of_range_enumerations() {
    // Reflex phase 5 is undefined.
    let mut f = state_left().encode().unwrap();
    f.data[6] = 5;
    assert_eq!(
        Message::decode(0x072, f.payload()),
        Err(DecodeError::ValueOutOfRange {
            signal: "reflex_phase",
            raw: 5
        })
    );
    // Heartbeat state 9, undefined fault bit.
    assert_eq!(
        Message::decode(0x062, &[9, 0, 0, 0, 0, 0, 0]),
        Err(DecodeError::ValueOutOfRange {
            signal: "state",
            raw: 9
        })
    );
    assert_eq!(
        Message::decode(0x062, &[0, 0, 0x80, 0, 0, 0, 0]),
        Err(DecodeError::ValueOutOfRange {
            signal: "fault_flags",
            raw: 0x8000
        })
    );
    // Fault code 0 and 200, transition 2.
    assert_eq!(
        Message::decode(0x032, &[0, 1, 0, 0, 0, 0, 0, 0]),
        Err(DecodeError::ValueOutOfRange {
            signal: "code",
            raw: 0
        })
    );
    assert_eq!(
        Message::decode(0x032, &[200, 1, 0, 0, 0, 0, 0, 0]),
        Err(DecodeError::ValueOutOfRange {
            signal: "code",
            raw: 200
        })
    );
    assert_eq!(
        Message::decode(0x032, &[1, 2, 0, 0, 0, 0, 0, 0]),
        Err(DecodeError::ValueOutOfRange {
            signal: "transition",
            raw: 2
        })
    );
    // Param ack: unknown parameter, unknown status.
    assert_eq!(
        Message::decode(0x052, &[99, 0, 0, 0, 0, 0]),
        Err(DecodeError::ValueOutOfRange {
            signal: "param_id",
            raw: 99
        })
    );
    assert_eq!(
        Message::decode(0x052, &[1, 7, 0, 0, 0, 0]),
        Err(DecodeError::ValueOutOfRange {
            signal: "status",
            raw: 7
        })
    );
}

#[test]
fn malformed_commands() {
    // Unknown opcode.
    assert_eq!(
        Message::decode(0x042, &[0, 0, 0, 0, 0, 0]),
        Err(DecodeError::ValueOutOfRange {
            signal: "opcode",
            raw: 0
        })
    );
    // Emergency stop on the command identifier (it has its own).
    assert_eq!(
        Message::decode(0x042, &[3, 0, 0, 0, 0, 0]),
        Err(DecodeError::ValueOutOfRange {
            signal: "opcode",
            raw: 3
        })
    );
    // Emergency-stop identifier with another opcode.
    assert_eq!(
        Message::decode(0x012, &[1]),
        Err(DecodeError::ValueOutOfRange {
            signal: "opcode",
            raw: 1
        })
    );
    // Enable with non-zero reserved fields.
    assert_eq!(
        Message::decode(0x042, &[1, 2, 0, 0, 0, 0]),
        Err(DecodeError::ValueOutOfRange {
            signal: "param_id",
            raw: 2
        })
    );
    assert_eq!(
        Message::decode(0x04F, &[2, 0, 1, 0, 0, 0]),
        Err(DecodeError::ValueOutOfRange {
            signal: "param_value",
            raw: 1
        })
    );
    // SetParam with an unknown parameter.
    assert_eq!(
        Message::decode(0x042, &[4, 0, 0, 0, 0, 0]),
        Err(DecodeError::ValueOutOfRange {
            signal: "param_id",
            raw: 0
        })
    );
    // SetParam with an out-of-range value still decodes: the node answers OutOfRange.
    assert!(matches!(
        Message::decode(0x042, &[4, 1, 0xFF, 0xFF, 0xFF, 0x7F]),
        Ok(Message::Command(Command {
            kind: CommandKind::SetParam { .. },
            ..
        }))
    ));
}

#[test]
fn errors_display_their_values() {
    let e = Message::decode(0x072, &[0; 3]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "frame 0x072: 3 data bytes, the message has 7"
    );
}
