//! 11-bit CAN identifiers: message class in the high seven bits, node in the low four.
//!
//! ```text
//!  bit 10 ........ 4 | 3 .... 0
//!      message class  |  node
//! ```
//!
//! A lower identifier wins arbitration, so the class order below is the priority order:
//! emergency stop and heel strike beat faults and commands, which beat telemetry.
//!
//! The node field is the **sender** for everything an ankle or the host reports, and the
//! **destination** for commands (only the host sends commands, so every identifier still has
//! exactly one sender on the bus).

use crate::error::DecodeError;

/// A node on the walker's bus.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum NodeId {
    /// The host computer (operator console, logger, simulator bridge).
    Host,
    /// The left ankle microcontroller.
    LeftAnkle,
    /// The right ankle microcontroller.
    RightAnkle,
}

impl NodeId {
    /// Every node, in identifier order.
    pub const ALL: [NodeId; 3] = [NodeId::Host, NodeId::LeftAnkle, NodeId::RightAnkle];
    /// The two ankle nodes.
    pub const ANKLES: [NodeId; 2] = [NodeId::LeftAnkle, NodeId::RightAnkle];

    /// The 4-bit value in the identifier's low bits.
    pub const fn raw(self) -> u8 {
        match self {
            NodeId::Host => 0x1,
            NodeId::LeftAnkle => 0x2,
            NodeId::RightAnkle => 0x3,
        }
    }

    /// The node for a 4-bit field, or `None` when no node has that number.
    pub const fn from_raw(raw: u8) -> Option<Self> {
        match raw {
            0x1 => Some(NodeId::Host),
            0x2 => Some(NodeId::LeftAnkle),
            0x3 => Some(NodeId::RightAnkle),
            _ => None,
        }
    }

    /// The other ankle; `None` for the host.
    pub const fn peer(self) -> Option<Self> {
        match self {
            NodeId::LeftAnkle => Some(NodeId::RightAnkle),
            NodeId::RightAnkle => Some(NodeId::LeftAnkle),
            NodeId::Host => None,
        }
    }

    /// Name used in the DBC file (`BU_`) and in message names.
    pub const fn dbc_name(self) -> &'static str {
        match self {
            NodeId::Host => "HOST",
            NodeId::LeftAnkle => "LEFT_ANKLE",
            NodeId::RightAnkle => "RIGHT_ANKLE",
        }
    }
}

/// Where a command goes: one node, or every ankle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Target {
    /// One ankle (or, in principle, the host).
    Node(NodeId),
    /// Every node that listens (node field `0xF`).
    Broadcast,
}

impl Target {
    /// Raw 4-bit node field of a broadcast.
    pub const BROADCAST_RAW: u8 = 0xF;

    /// The 4-bit value in the identifier's low bits.
    pub const fn raw(self) -> u8 {
        match self {
            Target::Node(n) => n.raw(),
            Target::Broadcast => Self::BROADCAST_RAW,
        }
    }

    /// True when a node with id `me` must act on a command sent to this target.
    pub fn addresses(self, me: NodeId) -> bool {
        match self {
            Target::Node(n) => n == me,
            Target::Broadcast => true,
        }
    }

    /// Name suffix used in the DBC file.
    pub const fn dbc_name(self) -> &'static str {
        match self {
            Target::Node(n) => n.dbc_name(),
            Target::Broadcast => "ALL",
        }
    }
}

/// The message class: the identifier's high seven bits, and so its priority.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum MessageClass {
    /// Emergency stop (a command, host → ankles). Highest priority.
    EmergencyStop,
    /// Heel strike of the sending ankle's foot.
    HeelStrike,
    /// A fault was raised or cleared.
    Fault,
    /// Enable, disable, set a parameter (host → ankle).
    Command,
    /// Answer to a set-parameter command.
    ParamAck,
    /// Liveness and node state.
    Heartbeat,
    /// Ankle telemetry.
    AnkleState,
    /// Protocol and firmware version.
    Version,
    /// Chip unique ID, first 64 bits.
    Identity,
    /// Chip unique ID, last 32 bits; reset cause; where parameters and calibration came from.
    BootInfo,
    /// Answer to a command that has no other answer.
    CommandAck,
    /// One entry of the fault history.
    FaultHistory,
    /// The clock the node runs on, the crystal check, the CAN timing's tolerated error.
    ClockInfo,
}

impl MessageClass {
    /// Every class, highest priority first.
    pub const ALL: [MessageClass; 13] = [
        MessageClass::EmergencyStop,
        MessageClass::HeelStrike,
        MessageClass::Fault,
        MessageClass::Command,
        MessageClass::ParamAck,
        MessageClass::Heartbeat,
        MessageClass::AnkleState,
        MessageClass::Version,
        MessageClass::Identity,
        MessageClass::BootInfo,
        MessageClass::CommandAck,
        MessageClass::FaultHistory,
        MessageClass::ClockInfo,
    ];

    /// The 7-bit class value.
    pub const fn raw(self) -> u8 {
        match self {
            MessageClass::EmergencyStop => 0x01,
            MessageClass::HeelStrike => 0x02,
            MessageClass::Fault => 0x03,
            MessageClass::Command => 0x04,
            MessageClass::ParamAck => 0x05,
            MessageClass::Heartbeat => 0x06,
            MessageClass::AnkleState => 0x07,
            MessageClass::Version => 0x08,
            MessageClass::Identity => 0x09,
            MessageClass::BootInfo => 0x0A,
            MessageClass::CommandAck => 0x0B,
            MessageClass::FaultHistory => 0x0C,
            MessageClass::ClockInfo => 0x0D,
        }
    }

    /// The class for a 7-bit value, or `None`.
    pub const fn from_raw(raw: u8) -> Option<Self> {
        match raw {
            0x01 => Some(MessageClass::EmergencyStop),
            0x02 => Some(MessageClass::HeelStrike),
            0x03 => Some(MessageClass::Fault),
            0x04 => Some(MessageClass::Command),
            0x05 => Some(MessageClass::ParamAck),
            0x06 => Some(MessageClass::Heartbeat),
            0x07 => Some(MessageClass::AnkleState),
            0x08 => Some(MessageClass::Version),
            0x09 => Some(MessageClass::Identity),
            0x0A => Some(MessageClass::BootInfo),
            0x0B => Some(MessageClass::CommandAck),
            0x0C => Some(MessageClass::FaultHistory),
            0x0D => Some(MessageClass::ClockInfo),
            _ => None,
        }
    }
}

/// A validated 11-bit identifier of this protocol: a known class and a 4-bit node field.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CanId {
    /// The message class (high bits).
    pub class: MessageClass,
    /// The node field (low bits): sender, or destination for commands.
    pub node_raw: u8,
}

impl CanId {
    /// Bits the node field is shifted by.
    pub const NODE_BITS: u32 = 4;

    /// Build from a class and a node field; the node field is masked to four bits.
    pub const fn new(class: MessageClass, node_raw: u8) -> Self {
        CanId {
            class,
            node_raw: node_raw & 0x0F,
        }
    }

    /// The raw 11-bit identifier.
    pub const fn raw(self) -> u16 {
        ((self.class.raw() as u16) << Self::NODE_BITS) | (self.node_raw as u16)
    }

    /// Split a raw 11-bit identifier.
    ///
    /// # Errors
    /// [`DecodeError::UnknownId`] when the value exceeds 11 bits or the class is unknown.
    pub const fn from_raw(raw: u16) -> Result<Self, DecodeError> {
        if raw > 0x7FF {
            return Err(DecodeError::UnknownId { raw: raw as u32 });
        }
        // raw ≤ 0x7FF (checked above), so raw >> 4 ≤ 0x7F fits a u8 exactly.
        #[allow(clippy::cast_possible_truncation)]
        let class_raw = (raw >> Self::NODE_BITS) as u8;
        match MessageClass::from_raw(class_raw) {
            Some(class) => Ok(CanId {
                class,
                node_raw: (raw & 0x0F) as u8,
            }),
            None => Err(DecodeError::UnknownId { raw: raw as u32 }),
        }
    }

    /// As an embedded-can standard identifier (always valid: at most 0x0CF).
    pub fn standard(self) -> embedded_can::StandardId {
        // Both fields are masked, so the value is < 0x800 and `new` cannot fail; fall back to
        // ZERO rather than panic to keep the no-panic rule provable.
        embedded_can::StandardId::new(self.raw()).unwrap_or(embedded_can::StandardId::ZERO)
    }
}

/// Identifiers an ankle's acceptance filters let through, and nothing else: emergency stop
/// and command addressed to it or to every ankle, and the other ankle's heel strike, fault and
/// heartbeat (the node follows the peer's state). `None` for the host.
pub const fn accepted_by_ankle(me: NodeId) -> Option<[u16; ACCEPTED_BY_ANKLE]> {
    let Some(peer) = me.peer() else {
        return None;
    };
    let all = Target::Broadcast.raw();
    Some([
        CanId::new(MessageClass::EmergencyStop, me.raw()).raw(),
        CanId::new(MessageClass::EmergencyStop, all).raw(),
        CanId::new(MessageClass::HeelStrike, peer.raw()).raw(),
        CanId::new(MessageClass::Fault, peer.raw()).raw(),
        CanId::new(MessageClass::Command, me.raw()).raw(),
        CanId::new(MessageClass::Command, all).raw(),
        CanId::new(MessageClass::Heartbeat, peer.raw()).raw(),
    ])
}

/// Number of identifiers in [`accepted_by_ankle`].
pub const ACCEPTED_BY_ANKLE: usize = 7;

#[cfg(test)]
mod tests {
    #[test]
    fn ankle_filters_accept_only_what_the_node_reads() {
        let left = accepted_by_ankle(NodeId::LeftAnkle).unwrap();
        assert_eq!(left, [0x012, 0x01F, 0x023, 0x033, 0x042, 0x04F, 0x063]);
        let right = accepted_by_ankle(NodeId::RightAnkle).unwrap();
        assert_eq!(right, [0x013, 0x01F, 0x022, 0x032, 0x043, 0x04F, 0x062]);
        assert!(accepted_by_ankle(NodeId::Host).is_none());
    }

    use super::*;

    #[test]
    fn class_raw_round_trips_and_is_priority_ordered() {
        let mut last = 0;
        for c in MessageClass::ALL {
            assert_eq!(MessageClass::from_raw(c.raw()), Some(c));
            assert!(c.raw() > last, "classes listed in priority order");
            last = c.raw();
        }
    }

    #[test]
    fn estop_and_heel_strike_win_over_telemetry() {
        for n in 0..16u8 {
            for m in 0..16u8 {
                let estop = CanId::new(MessageClass::EmergencyStop, n).raw();
                let heel = CanId::new(MessageClass::HeelStrike, n).raw();
                for telem in [
                    MessageClass::AnkleState,
                    MessageClass::Heartbeat,
                    MessageClass::Version,
                    MessageClass::Fault,
                    MessageClass::Command,
                ] {
                    let t = CanId::new(telem, m).raw();
                    assert!(estop < t && heel < t);
                }
            }
        }
    }

    #[test]
    fn unknown_and_oversized_ids_are_rejected() {
        assert_eq!(
            CanId::from_raw(0x7FF),
            Err(DecodeError::UnknownId { raw: 0x7FF })
        );
        assert_eq!(
            CanId::from_raw(0x800),
            Err(DecodeError::UnknownId { raw: 0x800 })
        );
        assert_eq!(
            CanId::from_raw(0x005),
            Err(DecodeError::UnknownId { raw: 0x005 })
        );
        assert!(CanId::from_raw(0x072).is_ok());
    }

    #[test]
    fn node_ids_round_trip_and_peer() {
        for n in NodeId::ALL {
            assert_eq!(NodeId::from_raw(n.raw()), Some(n));
        }
        assert_eq!(NodeId::LeftAnkle.peer(), Some(NodeId::RightAnkle));
        assert_eq!(NodeId::Host.peer(), None);
        assert!(Target::Broadcast.addresses(NodeId::LeftAnkle));
        assert!(!Target::Node(NodeId::RightAnkle).addresses(NodeId::LeftAnkle));
    }
}
