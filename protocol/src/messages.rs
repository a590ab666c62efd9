//! The messages, their layout (defined once, in [`MESSAGES`]) and the codec.

use crate::error::{DecodeError, EncodeError};
use crate::id::{CanId, MessageClass, NodeId, Target};
use crate::signal::{Direction, Kind, MessageSpec, SignalSpec};
use crate::values::{
    Angle, AngularRate, ClockSource, CommandResult, ConfigSource, CrystalStatus, FaultCode,
    FaultFlags, FaultTransition, NodeState, Opcode, ParamId, ParamStatus, ParamValue, ReflexPhase,
    ResetCause,
};

/// Version of this message set, sent in [`Version`]. Bump on any layout change.
pub const PROTOCOL_VERSION: u8 = 3;

/// Nominal bus bit rate [bit/s] (classic CAN, FDCAN in classic mode).
pub const BITRATE_BPS: u32 = 500_000;

const ANKLES: &[NodeId] = &NodeId::ANKLES;
const ALL_NODES: &[NodeId] = &NodeId::ALL;
const COMMAND_TARGETS: &[Target] = &[
    Target::Node(NodeId::LeftAnkle),
    Target::Node(NodeId::RightAnkle),
    Target::Broadcast,
];

const fn sig(
    name: &'static str,
    byte: u8,
    kind: Kind,
    scale: f64,
    unit: &'static str,
    comment: &'static str,
) -> SignalSpec {
    SignalSpec {
        name,
        byte,
        kind,
        scale,
        unit,
        choices: &[],
        comment,
    }
}

const fn enum_sig(
    name: &'static str,
    byte: u8,
    choices: &'static [(u32, &'static str)],
    comment: &'static str,
) -> SignalSpec {
    SignalSpec {
        name,
        byte,
        kind: Kind::U8,
        scale: 1.0,
        unit: "",
        choices,
        comment,
    }
}

/// Signal layouts, one module per message.
pub mod layout {
    use super::*;

    /// [`Command`] with opcode `EmergencyStop` (class `EmergencyStop`).
    pub mod emergency_stop {
        use super::*;
        /// Always `EmergencyStop`.
        pub const OPCODE: SignalSpec =
            enum_sig("opcode", 0, Opcode::CHOICES, "always EmergencyStop (3)");
        /// Signals in byte order.
        pub const SIGNALS: &[SignalSpec] = &[OPCODE];
    }

    /// [`HeelStrike`].
    pub mod heel_strike {
        use super::*;
        /// Heel strikes since power-up, wrapping.
        pub const STEP_COUNT: SignalSpec = sig(
            "step_count",
            0,
            Kind::U16,
            1.0,
            "",
            "heel strikes of this foot since power-up (wraps)",
        );
        /// Time of the strike.
        pub const TIME_US: SignalSpec = sig(
            "time",
            2,
            Kind::U32,
            1.0e-6,
            "s",
            "sender's uptime at the strike (1 us counts, wraps after 4295 s)",
        );
        /// Signals in byte order.
        pub const SIGNALS: &[SignalSpec] = &[STEP_COUNT, TIME_US];
    }

    /// [`FaultEvent`].
    pub mod fault {
        use super::*;
        /// Fault code.
        pub const CODE: SignalSpec = enum_sig("code", 0, FaultCode::CHOICES, "what the fault is");
        /// Raised or cleared.
        pub const TRANSITION: SignalSpec = enum_sig(
            "transition",
            1,
            FaultTransition::CHOICES,
            "fault appeared (1) or went away (0)",
        );
        /// Offending raw value.
        pub const DETAIL: SignalSpec = sig(
            "detail",
            2,
            Kind::I16,
            1.0,
            "",
            "offending raw value (encoder counts, rate in mrad/s, ...), 0 if none",
        );
        /// Time of the event.
        pub const UPTIME_MS: SignalSpec = sig(
            "uptime",
            4,
            Kind::U32,
            1.0e-3,
            "s",
            "sender's uptime at the event (1 ms counts)",
        );
        /// Signals in byte order.
        pub const SIGNALS: &[SignalSpec] = &[CODE, TRANSITION, DETAIL, UPTIME_MS];
    }

    /// [`Command`] other than emergency stop.
    pub mod command {
        use super::*;
        /// Opcode.
        pub const OPCODE: SignalSpec = enum_sig("opcode", 0, Opcode::CHOICES, "what to do");
        /// Parameter for `SetParam`, 0 otherwise.
        pub const PARAM_ID: SignalSpec = enum_sig(
            "param_id",
            1,
            ParamId::CHOICES,
            "parameter to set (SetParam only, else 0)",
        );
        /// Value for `SetParam`, 0 otherwise.
        pub const PARAM_VALUE: SignalSpec = sig(
            "param_value",
            2,
            Kind::I32,
            1.0e-6,
            "",
            "new value in 1e-6 of the parameter's SI unit (SetParam only, else 0)",
        );
        /// Signals in byte order.
        pub const SIGNALS: &[SignalSpec] = &[OPCODE, PARAM_ID, PARAM_VALUE];
    }

    /// [`ParamAck`].
    pub mod param_ack {
        use super::*;
        /// Parameter.
        pub const PARAM_ID: SignalSpec =
            enum_sig("param_id", 0, ParamId::CHOICES, "parameter that was set");
        /// Status.
        pub const STATUS: SignalSpec =
            enum_sig("status", 1, ParamStatus::CHOICES, "outcome of the command");
        /// Value in force.
        pub const PARAM_VALUE: SignalSpec = sig(
            "param_value",
            2,
            Kind::I32,
            1.0e-6,
            "",
            "value now in force, 1e-6 of the parameter's SI unit",
        );
        /// Signals in byte order.
        pub const SIGNALS: &[SignalSpec] = &[PARAM_ID, STATUS, PARAM_VALUE];
    }

    /// [`Heartbeat`].
    pub mod heartbeat {
        use super::*;
        /// Node state.
        pub const STATE: SignalSpec =
            enum_sig("state", 0, NodeState::CHOICES, "state of the sending node");
        /// Active faults.
        pub const FAULT_FLAGS: SignalSpec = sig(
            "fault_flags",
            1,
            Kind::U16,
            1.0,
            "",
            "active faults, bit (code - 1) per fault code",
        );
        /// Uptime.
        pub const UPTIME_MS: SignalSpec = sig(
            "uptime",
            3,
            Kind::U32,
            1.0e-3,
            "s",
            "sender's uptime (1 ms counts)",
        );
        /// Signals in byte order.
        pub const SIGNALS: &[SignalSpec] = &[STATE, FAULT_FLAGS, UPTIME_MS];
    }

    /// [`AnkleState`].
    pub mod ankle_state {
        use super::*;
        /// Estimated ankle angle.
        pub const ANGLE: SignalSpec = sig(
            "angle",
            0,
            Kind::I16,
            Angle::SCALE,
            "rad",
            "estimated ankle angle, negative when the hip is ahead of the ankle",
        );
        /// Estimated ankle rate.
        pub const RATE: SignalSpec = sig(
            "rate",
            2,
            Kind::I16,
            AngularRate::SCALE,
            "rad/s",
            "estimated ankle angular rate",
        );
        /// Actuator setpoint.
        pub const ACTUATOR_POSITION: SignalSpec = sig(
            "actuator_position",
            4,
            Kind::I16,
            Angle::SCALE,
            "rad",
            "ankle angle the string is being held at (last setpoint when released)",
        );
        /// Reflex phase.
        pub const PHASE: SignalSpec = enum_sig(
            "reflex_phase",
            6,
            ReflexPhase::CHOICES,
            "stretch-reflex phase",
        );
        /// Signals in byte order.
        pub const SIGNALS: &[SignalSpec] = &[ANGLE, RATE, ACTUATOR_POSITION, PHASE];
    }

    /// [`Version`].
    pub mod version {
        use super::*;
        /// Protocol version.
        pub const PROTOCOL: SignalSpec = sig(
            "protocol_version",
            0,
            Kind::U8,
            1.0,
            "",
            "message-set version (PROTOCOL_VERSION)",
        );
        /// Firmware major version.
        pub const MAJOR: SignalSpec = sig("fw_major", 1, Kind::U8, 1.0, "", "firmware major");
        /// Firmware minor version.
        pub const MINOR: SignalSpec = sig("fw_minor", 2, Kind::U8, 1.0, "", "firmware minor");
        /// Firmware patch version.
        pub const PATCH: SignalSpec = sig("fw_patch", 3, Kind::U8, 1.0, "", "firmware patch");
        /// Build identifier.
        pub const BUILD: SignalSpec = sig(
            "build_id",
            4,
            Kind::U32,
            1.0,
            "",
            "build identifier (e.g. first 8 hex digits of the commit)",
        );
        /// Signals in byte order.
        pub const SIGNALS: &[SignalSpec] = &[PROTOCOL, MAJOR, MINOR, PATCH, BUILD];
    }

    /// [`Identity`].
    pub mod identity {
        use super::*;
        /// UID bits 0–31.
        pub const UID_LOW: SignalSpec = sig(
            "uid_low",
            0,
            Kind::U32,
            1.0,
            "",
            "chip unique ID, bits 0-31 (STM32: UID word at 0x1FFF7590)",
        );
        /// UID bits 32–63.
        pub const UID_MID: SignalSpec = sig(
            "uid_mid",
            4,
            Kind::U32,
            1.0,
            "",
            "chip unique ID, bits 32-63",
        );
        /// Signals in byte order.
        pub const SIGNALS: &[SignalSpec] = &[UID_LOW, UID_MID];
    }

    /// [`BootInfo`].
    pub mod boot_info {
        use super::*;
        /// UID bits 64–95.
        pub const UID_HIGH: SignalSpec = sig(
            "uid_high",
            0,
            Kind::U32,
            1.0,
            "",
            "chip unique ID, bits 64-95",
        );
        /// Reset cause.
        pub const RESET_CAUSE: SignalSpec = enum_sig(
            "reset_cause",
            4,
            ResetCause::CHOICES,
            "why the microcontroller last reset",
        );
        /// Where the parameters came from.
        pub const PARAMS_SOURCE: SignalSpec = enum_sig(
            "params_source",
            5,
            ConfigSource::CHOICES,
            "where the reflex parameters in force came from at start-up",
        );
        /// Entries in the fault history.
        pub const FAULT_HISTORY_LEN: SignalSpec = sig(
            "fault_history_len",
            6,
            Kind::U8,
            1.0,
            "",
            "entries in the fault history (GetFaultHistory reads them)",
        );
        /// Where the encoder zero came from.
        pub const CALIBRATION_SOURCE: SignalSpec = enum_sig(
            "calibration_source",
            7,
            ConfigSource::CHOICES,
            "where the encoder zero in force came from",
        );
        /// Signals in byte order.
        pub const SIGNALS: &[SignalSpec] = &[
            UID_HIGH,
            RESET_CAUSE,
            PARAMS_SOURCE,
            FAULT_HISTORY_LEN,
            CALIBRATION_SOURCE,
        ];
    }

    /// [`CommandAck`].
    pub mod command_ack {
        use super::*;
        /// The command answered.
        pub const OPCODE: SignalSpec =
            enum_sig("opcode", 0, Opcode::CHOICES, "the command answered");
        /// Outcome.
        pub const RESULT: SignalSpec = enum_sig(
            "result",
            1,
            CommandResult::CHOICES,
            "outcome of the command",
        );
        /// Signals in byte order.
        pub const SIGNALS: &[SignalSpec] = &[OPCODE, RESULT];
    }

    /// [`FaultHistoryEntry`].
    pub mod fault_history {
        use super::*;
        /// Entry index, 0 = newest.
        pub const ENTRY: SignalSpec =
            sig("entry", 0, Kind::U8, 1.0, "", "entry index, 0 = the newest");
        /// Fault code.
        pub const CODE: SignalSpec =
            enum_sig("code", 1, FaultCode::CHOICES, "the fault that was raised");
        /// Node state after the tick of the raise.
        pub const STATE_AFTER: SignalSpec = enum_sig(
            "state_after",
            2,
            NodeState::CHOICES,
            "node state after that tick (Safe: this raise is why the node went safe)",
        );
        /// Offending raw value.
        pub const DETAIL: SignalSpec = sig(
            "detail",
            3,
            Kind::I16,
            1.0,
            "",
            "offending raw value, as in the Fault event",
        );
        /// Time of the raise.
        pub const UPTIME_MS: SignalSpec = sig(
            "uptime",
            5,
            Kind::U24,
            1.0e-3,
            "s",
            "sender's uptime at the raise (1 ms counts, wraps after 4.66 h)",
        );
        /// Signals in byte order.
        pub const SIGNALS: &[SignalSpec] = &[ENTRY, CODE, STATE_AFTER, DETAIL, UPTIME_MS];
    }

    /// [`ClockInfo`].
    pub mod clock_info {
        use super::*;
        /// Oscillator in use.
        pub const SOURCE: SignalSpec = enum_sig(
            "clock_source",
            0,
            ClockSource::CHOICES,
            "the oscillator the node and its CAN controller run on",
        );
        /// Crystal check.
        pub const CRYSTAL: SignalSpec = enum_sig(
            "crystal",
            1,
            CrystalStatus::CHOICES,
            "what the start-up check found of the crystal",
        );
        /// The oscillator's specified error.
        pub const OSCILLATOR_ERROR: SignalSpec = sig(
            "oscillator_error",
            2,
            Kind::U8,
            0.01,
            "%",
            "specified error bound of the oscillator in use (saturates at 2.55 %)",
        );
        /// What the CAN timing tolerates.
        pub const TOLERATED_ERROR: SignalSpec = sig(
            "tolerated_error",
            3,
            Kind::U16,
            1.0e-4,
            "%",
            "oscillator error the CAN bit timing tolerates (ISO 11898-1 conditions); power stage refused when oscillator_error exceeds it",
        );
        /// The crystal's measured frequency.
        pub const CRYSTAL_FREQ: SignalSpec = sig(
            "crystal_freq",
            5,
            Kind::U24,
            10.0,
            "Hz",
            "crystal frequency measured against the internal oscillator at start-up (10 Hz counts, its error), 0 when it did not start",
        );
        /// Signals in byte order.
        pub const SIGNALS: &[SignalSpec] = &[
            SOURCE,
            CRYSTAL,
            OSCILLATOR_ERROR,
            TOLERATED_ERROR,
            CRYSTAL_FREQ,
        ];
    }
}

/// Every message's layout, highest priority first. The DBC file, the bus-load figure and the
/// shared test vectors are generated from this table; the codec writes through the same
/// [`SignalSpec`] constants.
pub const MESSAGES: &[MessageSpec] = &[
    MessageSpec {
        class: MessageClass::EmergencyStop,
        name: "EmergencyStop",
        dlc: 1,
        signals: layout::emergency_stop::SIGNALS,
        direction: Direction::ToNode(COMMAND_TARGETS),
        nominal_rate_hz: 0.0,
        comment: "release the actuator now; latched until Disable",
    },
    MessageSpec {
        class: MessageClass::HeelStrike,
        name: "HeelStrike",
        dlc: 6,
        signals: layout::heel_strike::SIGNALS,
        direction: Direction::FromNode(ANKLES),
        nominal_rate_hz: 2.0,
        comment: "the sender's foot touched the floor; the other ankle releases its string",
    },
    MessageSpec {
        class: MessageClass::Fault,
        name: "Fault",
        dlc: 8,
        signals: layout::fault::SIGNALS,
        direction: Direction::FromNode(ANKLES),
        nominal_rate_hz: 2.0,
        comment: "a fault was raised or cleared",
    },
    MessageSpec {
        class: MessageClass::Command,
        name: "Command",
        dlc: 6,
        signals: layout::command::SIGNALS,
        direction: Direction::ToNode(COMMAND_TARGETS),
        nominal_rate_hz: 1.0,
        comment: "host command: enable, disable or set a reflex parameter",
    },
    MessageSpec {
        class: MessageClass::ParamAck,
        name: "ParamAck",
        dlc: 6,
        signals: layout::param_ack::SIGNALS,
        direction: Direction::FromNode(ANKLES),
        nominal_rate_hz: 1.0,
        comment: "answer to SetParam",
    },
    MessageSpec {
        class: MessageClass::Heartbeat,
        name: "Heartbeat",
        dlc: 7,
        signals: layout::heartbeat::SIGNALS,
        direction: Direction::FromNode(ALL_NODES),
        nominal_rate_hz: 20.0,
        comment: "liveness, node state and active faults",
    },
    MessageSpec {
        class: MessageClass::AnkleState,
        name: "AnkleState",
        dlc: 7,
        signals: layout::ankle_state::SIGNALS,
        direction: Direction::FromNode(ANKLES),
        nominal_rate_hz: 200.0,
        comment: "ankle telemetry",
    },
    MessageSpec {
        class: MessageClass::Version,
        name: "Version",
        dlc: 8,
        signals: layout::version::SIGNALS,
        direction: Direction::FromNode(ALL_NODES),
        nominal_rate_hz: 0.2,
        comment: "protocol and firmware version",
    },
    MessageSpec {
        class: MessageClass::Identity,
        name: "Identity",
        dlc: 8,
        signals: layout::identity::SIGNALS,
        direction: Direction::FromNode(ANKLES),
        nominal_rate_hz: 0.0,
        comment: "chip unique ID (first 64 bits); at start-up and on GetIdentity",
    },
    MessageSpec {
        class: MessageClass::BootInfo,
        name: "BootInfo",
        dlc: 8,
        signals: layout::boot_info::SIGNALS,
        direction: Direction::FromNode(ANKLES),
        nominal_rate_hz: 0.0,
        comment: "chip unique ID (last 32 bits), reset cause, parameter and calibration source",
    },
    MessageSpec {
        class: MessageClass::CommandAck,
        name: "CommandAck",
        dlc: 2,
        signals: layout::command_ack::SIGNALS,
        direction: Direction::FromNode(ANKLES),
        nominal_rate_hz: 0.0,
        comment: "answer to SaveParams, ClearErrors, CalibrateEncoderZero",
    },
    MessageSpec {
        class: MessageClass::FaultHistory,
        name: "FaultHistory",
        dlc: 8,
        signals: layout::fault_history::SIGNALS,
        direction: Direction::FromNode(ANKLES),
        nominal_rate_hz: 0.0,
        comment: "one fault-history entry, sent on GetFaultHistory (newest first)",
    },
    MessageSpec {
        class: MessageClass::ClockInfo,
        name: "ClockInfo",
        dlc: 8,
        signals: layout::clock_info::SIGNALS,
        direction: Direction::FromNode(ANKLES),
        nominal_rate_hz: 0.0,
        comment: "clock source, crystal check, tolerated oscillator error; at start-up and on GetIdentity",
    },
];

/// The layout of a message class.
pub fn spec(class: MessageClass) -> Option<&'static MessageSpec> {
    MESSAGES.iter().find(|m| m.class == class)
}

/// The sending ankle's foot touched the floor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HeelStrike {
    /// The ankle whose foot struck.
    pub node: NodeId,
    /// Heel strikes of this foot since power-up (wraps).
    pub step_count: u16,
    /// Sender's uptime at the strike \[µs\] (wraps).
    pub time_us: u32,
}

/// Ankle telemetry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AnkleState {
    /// The sending ankle.
    pub node: NodeId,
    /// Estimated ankle angle.
    pub angle: Angle,
    /// Estimated ankle rate.
    pub rate: AngularRate,
    /// Ankle angle the actuator holds the string at (last setpoint when released).
    pub actuator_position: Angle,
    /// Stretch-reflex phase.
    pub phase: ReflexPhase,
}

/// Liveness, node state and active faults.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Heartbeat {
    /// The sender.
    pub node: NodeId,
    /// Its state.
    pub state: NodeState,
    /// Its active faults.
    pub faults: FaultFlags,
    /// Its uptime \[ms\] (wraps).
    pub uptime_ms: u32,
}

/// What a host command asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum CommandKind {
    /// Start running the reflex.
    Enable,
    /// Stop running the reflex, release the actuator.
    Disable,
    /// Release the actuator now; latched until `Disable`. Sent with the highest-priority class.
    EmergencyStop,
    /// Set one reflex parameter (the receiver checks the range again and acknowledges).
    SetParam {
        /// Which parameter.
        param: ParamId,
        /// New value.
        value: ParamValue,
    },
    /// Read one parameter (answered by `ParamAck`, status `Read`).
    GetParam {
        /// Which parameter.
        param: ParamId,
    },
    /// Store parameters and encoder zero in flash (answered by `CommandAck`).
    SaveParams,
    /// Empty the fault history (answered by `CommandAck`).
    ClearErrors,
    /// Send `Version`, `Identity`, `BootInfo` and `ClockInfo`.
    GetIdentity,
    /// Send the fault history.
    GetFaultHistory,
    /// Take the current reading as encoder zero (answered by `CommandAck`).
    CalibrateEncoderZero,
}

impl CommandKind {
    /// The opcode on the wire.
    pub const fn opcode(&self) -> Opcode {
        match self {
            CommandKind::Enable => Opcode::Enable,
            CommandKind::Disable => Opcode::Disable,
            CommandKind::EmergencyStop => Opcode::EmergencyStop,
            CommandKind::SetParam { .. } => Opcode::SetParam,
            CommandKind::GetParam { .. } => Opcode::GetParam,
            CommandKind::SaveParams => Opcode::SaveParams,
            CommandKind::ClearErrors => Opcode::ClearErrors,
            CommandKind::GetIdentity => Opcode::GetIdentity,
            CommandKind::GetFaultHistory => Opcode::GetFaultHistory,
            CommandKind::CalibrateEncoderZero => Opcode::CalibrateEncoderZero,
        }
    }
}

/// A host command to one ankle or to all.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Command {
    /// Destination.
    pub target: Target,
    /// What to do.
    pub kind: CommandKind,
}

impl Command {
    /// A set-parameter command with the value checked against the parameter's range.
    ///
    /// # Errors
    /// [`EncodeError::ValueOutOfRange`] when `value_si` is outside [`ParamId::range_si`].
    pub fn set_param(target: Target, param: ParamId, value_si: f32) -> Result<Self, EncodeError> {
        Ok(Command {
            target,
            kind: CommandKind::SetParam {
                param,
                value: param.wire_value(value_si)?,
            },
        })
    }
}

/// Answer to a set-parameter command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ParamAck {
    /// The answering ankle.
    pub node: NodeId,
    /// The parameter.
    pub param: ParamId,
    /// Outcome.
    pub status: ParamStatus,
    /// Value now in force.
    pub value: ParamValue,
}

/// A fault was raised or cleared.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FaultEvent {
    /// The reporting ankle.
    pub node: NodeId,
    /// What.
    pub code: FaultCode,
    /// Raised or cleared.
    pub transition: FaultTransition,
    /// Offending raw value, 0 if none.
    pub detail: i16,
    /// Sender's uptime \[ms\] (wraps).
    pub uptime_ms: u32,
}

/// Protocol and firmware version.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Version {
    /// The sender.
    pub node: NodeId,
    /// Message-set version ([`PROTOCOL_VERSION`]).
    pub protocol: u8,
    /// Firmware major version.
    pub major: u8,
    /// Firmware minor version.
    pub minor: u8,
    /// Firmware patch version.
    pub patch: u8,
    /// Build identifier.
    pub build: u32,
}

/// Chip unique ID, first 64 bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Identity {
    /// The sender.
    pub node: NodeId,
    /// UID bits 0–31.
    pub uid_low: u32,
    /// UID bits 32–63.
    pub uid_mid: u32,
}

/// Chip unique ID (last 32 bits), reset cause and where the configuration came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BootInfo {
    /// The sender.
    pub node: NodeId,
    /// UID bits 64–95.
    pub uid_high: u32,
    /// Why the microcontroller last reset.
    pub reset_cause: ResetCause,
    /// Where the reflex parameters came from.
    pub params_source: ConfigSource,
    /// Entries in the fault history.
    pub fault_history_len: u8,
    /// Where the encoder zero came from.
    pub calibration_source: ConfigSource,
}

/// Answer to a command without another answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CommandAck {
    /// The answering ankle.
    pub node: NodeId,
    /// The command answered.
    pub opcode: Opcode,
    /// Outcome.
    pub result: CommandResult,
}

/// One fault-history entry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FaultHistoryEntry {
    /// The sender.
    pub node: NodeId,
    /// Index, 0 = newest.
    pub entry: u8,
    /// The fault raised.
    pub code: FaultCode,
    /// Node state after the tick of the raise.
    pub state_after: NodeState,
    /// Offending raw value.
    pub detail: i16,
    /// Uptime at the raise \[ms\], 24 bits on the wire (wraps after 4.66 h): the sender
    /// reduces its clock modulo 2²⁴; [`Message::encode`] refuses 2²⁴ or more.
    pub uptime_ms: u32,
}

/// The clock the node runs on and what its CAN timing tolerates (sent with `BootInfo`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ClockInfo {
    /// The sender.
    pub node: NodeId,
    /// The oscillator in use.
    pub source: ClockSource,
    /// What the crystal check found.
    pub crystal: CrystalStatus,
    /// The oscillator's specified error \[0.01 %\] (100 ppm counts), saturated at 255.
    pub oscillator_error_centi_pct: u8,
    /// The error the CAN timing tolerates \[ppm\].
    pub tolerated_error_ppm: u16,
    /// The crystal's measured frequency \[10 Hz\], 24 bits on the wire; 0 if it did not
    /// start.
    pub crystal_freq_10hz: u32,
}

/// Any message of the protocol.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Message {
    /// Heel strike.
    HeelStrike(HeelStrike),
    /// Ankle telemetry.
    AnkleState(AnkleState),
    /// Heartbeat.
    Heartbeat(Heartbeat),
    /// Host command (emergency stop included).
    Command(Command),
    /// Parameter acknowledgement.
    ParamAck(ParamAck),
    /// Fault raised or cleared.
    Fault(FaultEvent),
    /// Version.
    Version(Version),
    /// Chip unique ID (first part).
    Identity(Identity),
    /// Chip unique ID (last part), reset cause, configuration sources.
    BootInfo(BootInfo),
    /// Command acknowledgement.
    CommandAck(CommandAck),
    /// Fault-history entry.
    FaultHistory(FaultHistoryEntry),
    /// Clock source and tolerance.
    ClockInfo(ClockInfo),
}

/// An encoded frame: identifier, length and payload.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RawFrame {
    /// Identifier.
    pub id: CanId,
    /// Payload length \[bytes\].
    pub len: u8,
    /// Payload; bytes past `len` are zero.
    pub data: [u8; 8],
}

impl RawFrame {
    /// The payload.
    pub fn payload(&self) -> &[u8] {
        self.data.get(..self.len as usize).unwrap_or(&self.data)
    }

    /// As any embedded-can frame type.
    pub fn to_frame<F: embedded_can::Frame>(&self) -> Option<F> {
        F::new(self.id.standard(), self.payload())
    }
}

fn enum_field<T>(
    spec: &SignalSpec,
    buf: &[u8; 8],
    from_raw: fn(u8) -> Option<T>,
) -> Result<T, DecodeError> {
    let raw = spec.get(buf);
    u8::try_from(raw)
        .ok()
        .and_then(from_raw)
        .ok_or(DecodeError::ValueOutOfRange {
            signal: spec.name,
            raw,
        })
}

fn sender(class: MessageClass, node_raw: u8) -> Result<NodeId, DecodeError> {
    let known = spec(class).is_some_and(|s| s.has_node_field(node_raw));
    match NodeId::from_raw(node_raw) {
        Some(n) if known => Ok(n),
        _ => Err(DecodeError::UnknownId {
            raw: CanId::new(class, node_raw).raw() as u32,
        }),
    }
}

fn target(class: MessageClass, node_raw: u8) -> Result<Target, DecodeError> {
    let known = spec(class).is_some_and(|s| s.has_node_field(node_raw));
    let t = if node_raw == Target::BROADCAST_RAW {
        Some(Target::Broadcast)
    } else {
        NodeId::from_raw(node_raw).map(Target::Node)
    };
    match t {
        Some(t) if known => Ok(t),
        _ => Err(DecodeError::UnknownId {
            raw: CanId::new(class, node_raw).raw() as u32,
        }),
    }
}

impl Message {
    /// The message class.
    pub fn class(&self) -> MessageClass {
        match self {
            Message::HeelStrike(_) => MessageClass::HeelStrike,
            Message::AnkleState(_) => MessageClass::AnkleState,
            Message::Heartbeat(_) => MessageClass::Heartbeat,
            Message::Command(c) if c.kind == CommandKind::EmergencyStop => {
                MessageClass::EmergencyStop
            }
            Message::Command(_) => MessageClass::Command,
            Message::ParamAck(_) => MessageClass::ParamAck,
            Message::Fault(_) => MessageClass::Fault,
            Message::Version(_) => MessageClass::Version,
            Message::Identity(_) => MessageClass::Identity,
            Message::BootInfo(_) => MessageClass::BootInfo,
            Message::CommandAck(_) => MessageClass::CommandAck,
            Message::FaultHistory(_) => MessageClass::FaultHistory,
            Message::ClockInfo(_) => MessageClass::ClockInfo,
        }
    }

    /// The identifier this message is sent with.
    pub fn id(&self) -> CanId {
        let node_raw = match self {
            Message::HeelStrike(m) => m.node.raw(),
            Message::AnkleState(m) => m.node.raw(),
            Message::Heartbeat(m) => m.node.raw(),
            Message::Command(m) => m.target.raw(),
            Message::ParamAck(m) => m.node.raw(),
            Message::Fault(m) => m.node.raw(),
            Message::Version(m) => m.node.raw(),
            Message::Identity(m) => m.node.raw(),
            Message::BootInfo(m) => m.node.raw(),
            Message::CommandAck(m) => m.node.raw(),
            Message::FaultHistory(m) => m.node.raw(),
            Message::ClockInfo(m) => m.node.raw(),
        };
        CanId::new(self.class(), node_raw)
    }

    /// Encode into a frame.
    ///
    /// # Errors
    /// [`EncodeError::InvalidNode`] when the message cannot use its node (e.g. a heel strike
    /// "from" the host); [`EncodeError::RawOutOfRange`] when a field does not fit its signal
    /// (of the field types, only [`FaultHistoryEntry::uptime_ms`] can: 24 bits on the wire).
    /// A value is refused, never cut to the signal's width.
    pub fn encode(&self) -> Result<RawFrame, EncodeError> {
        let mut data = [0u8; 8];
        let len = self.encode_into(&mut data)?;
        Ok(RawFrame {
            id: self.id(),
            len,
            data,
        })
    }

    /// Encode the payload into `buf`, returning its length \[bytes\].
    ///
    /// # Errors
    /// [`EncodeError::BufferTooShort`] when `buf` is shorter than the message's DLC;
    /// [`EncodeError::InvalidNode`] and [`EncodeError::RawOutOfRange`] as for
    /// [`Message::encode`]. On an error `buf` is left as it was.
    pub fn encode_into(&self, buf: &mut [u8]) -> Result<u8, EncodeError> {
        use layout::*;
        let id = self.id();
        let spec = spec(id.class).ok_or(EncodeError::InvalidNode {
            class: id.class,
            node_raw: id.node_raw,
        })?;
        if !spec.has_node_field(id.node_raw) {
            return Err(EncodeError::InvalidNode {
                class: id.class,
                node_raw: id.node_raw,
            });
        }
        if buf.len() < spec.dlc as usize {
            return Err(EncodeError::BufferTooShort {
                needed: spec.dlc,
                available: buf.len(),
            });
        }
        let mut b = [0u8; 8];
        match self {
            Message::HeelStrike(m) => {
                heel_strike::STEP_COUNT.put(&mut b, m.step_count)?;
                heel_strike::TIME_US.put(&mut b, m.time_us)?;
            }
            Message::AnkleState(m) => {
                ankle_state::ANGLE.put(&mut b, m.angle.0)?;
                ankle_state::RATE.put(&mut b, m.rate.0)?;
                ankle_state::ACTUATOR_POSITION.put(&mut b, m.actuator_position.0)?;
                ankle_state::PHASE.put(&mut b, m.phase.raw())?;
            }
            Message::Heartbeat(m) => {
                heartbeat::STATE.put(&mut b, m.state.raw())?;
                heartbeat::FAULT_FLAGS.put(&mut b, m.faults.bits())?;
                heartbeat::UPTIME_MS.put(&mut b, m.uptime_ms)?;
            }
            Message::Command(m) => match m.kind {
                CommandKind::EmergencyStop => {
                    emergency_stop::OPCODE.put(&mut b, Opcode::EmergencyStop.raw())?;
                }
                CommandKind::Enable => command::OPCODE.put(&mut b, Opcode::Enable.raw())?,
                CommandKind::Disable => command::OPCODE.put(&mut b, Opcode::Disable.raw())?,
                CommandKind::SetParam { param, value } => {
                    command::OPCODE.put(&mut b, Opcode::SetParam.raw())?;
                    command::PARAM_ID.put(&mut b, param.raw())?;
                    command::PARAM_VALUE.put(&mut b, value.0)?;
                }
                CommandKind::GetParam { param } => {
                    command::OPCODE.put(&mut b, Opcode::GetParam.raw())?;
                    command::PARAM_ID.put(&mut b, param.raw())?;
                }
                other => {
                    let op = other.opcode();
                    command::OPCODE.put(&mut b, op.raw())?;
                }
            },
            Message::ParamAck(m) => {
                param_ack::PARAM_ID.put(&mut b, m.param.raw())?;
                param_ack::STATUS.put(&mut b, m.status.raw())?;
                param_ack::PARAM_VALUE.put(&mut b, m.value.0)?;
            }
            Message::Fault(m) => {
                fault::CODE.put(&mut b, m.code.raw())?;
                fault::TRANSITION.put(&mut b, m.transition.raw())?;
                fault::DETAIL.put(&mut b, m.detail)?;
                fault::UPTIME_MS.put(&mut b, m.uptime_ms)?;
            }
            Message::Version(m) => {
                version::PROTOCOL.put(&mut b, m.protocol)?;
                version::MAJOR.put(&mut b, m.major)?;
                version::MINOR.put(&mut b, m.minor)?;
                version::PATCH.put(&mut b, m.patch)?;
                version::BUILD.put(&mut b, m.build)?;
            }
            Message::Identity(m) => {
                identity::UID_LOW.put(&mut b, m.uid_low)?;
                identity::UID_MID.put(&mut b, m.uid_mid)?;
            }
            Message::BootInfo(m) => {
                boot_info::UID_HIGH.put(&mut b, m.uid_high)?;
                boot_info::RESET_CAUSE.put(&mut b, m.reset_cause.raw())?;
                boot_info::PARAMS_SOURCE.put(&mut b, m.params_source.raw())?;
                boot_info::FAULT_HISTORY_LEN.put(&mut b, m.fault_history_len)?;
                boot_info::CALIBRATION_SOURCE.put(&mut b, m.calibration_source.raw())?;
            }
            Message::CommandAck(m) => {
                command_ack::OPCODE.put(&mut b, m.opcode.raw())?;
                command_ack::RESULT.put(&mut b, m.result.raw())?;
            }
            Message::FaultHistory(m) => {
                fault_history::ENTRY.put(&mut b, m.entry)?;
                fault_history::CODE.put(&mut b, m.code.raw())?;
                fault_history::STATE_AFTER.put(&mut b, m.state_after.raw())?;
                fault_history::DETAIL.put(&mut b, m.detail)?;
                fault_history::UPTIME_MS.put(&mut b, m.uptime_ms)?;
            }
            Message::ClockInfo(m) => {
                clock_info::SOURCE.put(&mut b, m.source.raw())?;
                clock_info::CRYSTAL.put(&mut b, m.crystal.raw())?;
                clock_info::OSCILLATOR_ERROR.put(&mut b, m.oscillator_error_centi_pct)?;
                clock_info::TOLERATED_ERROR.put(&mut b, m.tolerated_error_ppm)?;
                clock_info::CRYSTAL_FREQ.put(&mut b, m.crystal_freq_10hz)?;
            }
        }
        let n = spec.dlc as usize;
        if let (Some(dst), Some(src)) = (buf.get_mut(..n), b.get(..n)) {
            dst.copy_from_slice(src);
        }
        Ok(spec.dlc)
    }

    /// Decode a data frame with an 11-bit identifier.
    ///
    /// # Errors
    /// [`DecodeError::UnknownId`] for an identifier this protocol does not define,
    /// [`DecodeError::WrongLength`] when `data` is not exactly the message's DLC,
    /// [`DecodeError::ValueOutOfRange`] for an undefined enumeration value, undefined fault
    /// bits or a non-zero reserved field.
    pub fn decode(raw_id: u16, data: &[u8]) -> Result<Message, DecodeError> {
        use layout::*;
        let id = CanId::from_raw(raw_id)?;
        let spec = spec(id.class).ok_or(DecodeError::UnknownId { raw: raw_id as u32 })?;
        if !spec.has_node_field(id.node_raw) {
            return Err(DecodeError::UnknownId { raw: raw_id as u32 });
        }
        if data.len() != spec.dlc as usize {
            return Err(DecodeError::WrongLength {
                id: raw_id,
                expected: spec.dlc,
                actual: data.len(),
            });
        }
        let mut b = [0u8; 8];
        if let Some(dst) = b.get_mut(..data.len()) {
            dst.copy_from_slice(data);
        }
        let zero = |s: &SignalSpec| -> Result<(), DecodeError> {
            match s.get(&b) {
                0 => Ok(()),
                raw => Err(DecodeError::ValueOutOfRange {
                    signal: s.name,
                    raw,
                }),
            }
        };
        let msg = match id.class {
            MessageClass::EmergencyStop => {
                let target = target(id.class, id.node_raw)?;
                match enum_field(&emergency_stop::OPCODE, &b, Opcode::from_raw)? {
                    Opcode::EmergencyStop => Message::Command(Command {
                        target,
                        kind: CommandKind::EmergencyStop,
                    }),
                    other => {
                        return Err(DecodeError::ValueOutOfRange {
                            signal: emergency_stop::OPCODE.name,
                            raw: other.raw() as i64,
                        })
                    }
                }
            }
            MessageClass::Command => {
                let target = target(id.class, id.node_raw)?;
                let kind = match enum_field(&command::OPCODE, &b, Opcode::from_raw)? {
                    Opcode::Enable => {
                        zero(&command::PARAM_ID)?;
                        zero(&command::PARAM_VALUE)?;
                        CommandKind::Enable
                    }
                    Opcode::Disable => {
                        zero(&command::PARAM_ID)?;
                        zero(&command::PARAM_VALUE)?;
                        CommandKind::Disable
                    }
                    Opcode::SetParam => CommandKind::SetParam {
                        param: enum_field(&command::PARAM_ID, &b, ParamId::from_raw)?,
                        value: ParamValue(command::PARAM_VALUE.get_as(&b)?),
                    },
                    Opcode::GetParam => {
                        zero(&command::PARAM_VALUE)?;
                        CommandKind::GetParam {
                            param: enum_field(&command::PARAM_ID, &b, ParamId::from_raw)?,
                        }
                    }
                    op @ (Opcode::SaveParams
                    | Opcode::ClearErrors
                    | Opcode::GetIdentity
                    | Opcode::GetFaultHistory
                    | Opcode::CalibrateEncoderZero) => {
                        zero(&command::PARAM_ID)?;
                        zero(&command::PARAM_VALUE)?;
                        match op {
                            Opcode::SaveParams => CommandKind::SaveParams,
                            Opcode::ClearErrors => CommandKind::ClearErrors,
                            Opcode::GetIdentity => CommandKind::GetIdentity,
                            Opcode::GetFaultHistory => CommandKind::GetFaultHistory,
                            _ => CommandKind::CalibrateEncoderZero,
                        }
                    }
                    Opcode::EmergencyStop => {
                        // Emergency stop has its own, higher-priority identifier.
                        return Err(DecodeError::ValueOutOfRange {
                            signal: command::OPCODE.name,
                            raw: Opcode::EmergencyStop.raw() as i64,
                        });
                    }
                };
                Message::Command(Command { target, kind })
            }
            MessageClass::HeelStrike => Message::HeelStrike(HeelStrike {
                node: sender(id.class, id.node_raw)?,
                step_count: heel_strike::STEP_COUNT.get_as(&b)?,
                time_us: heel_strike::TIME_US.get_as(&b)?,
            }),
            MessageClass::AnkleState => Message::AnkleState(AnkleState {
                node: sender(id.class, id.node_raw)?,
                angle: Angle(ankle_state::ANGLE.get_as(&b)?),
                rate: AngularRate(ankle_state::RATE.get_as(&b)?),
                actuator_position: Angle(ankle_state::ACTUATOR_POSITION.get_as(&b)?),
                phase: enum_field(&ankle_state::PHASE, &b, ReflexPhase::from_raw)?,
            }),
            MessageClass::Heartbeat => {
                let raw_flags: u16 = heartbeat::FAULT_FLAGS.get_as(&b)?;
                Message::Heartbeat(Heartbeat {
                    node: sender(id.class, id.node_raw)?,
                    state: enum_field(&heartbeat::STATE, &b, NodeState::from_raw)?,
                    faults: FaultFlags::from_bits(raw_flags).ok_or(
                        DecodeError::ValueOutOfRange {
                            signal: heartbeat::FAULT_FLAGS.name,
                            raw: i64::from(raw_flags),
                        },
                    )?,
                    uptime_ms: heartbeat::UPTIME_MS.get_as(&b)?,
                })
            }
            MessageClass::ParamAck => Message::ParamAck(ParamAck {
                node: sender(id.class, id.node_raw)?,
                param: enum_field(&param_ack::PARAM_ID, &b, ParamId::from_raw)?,
                status: enum_field(&param_ack::STATUS, &b, ParamStatus::from_raw)?,
                value: ParamValue(param_ack::PARAM_VALUE.get_as(&b)?),
            }),
            MessageClass::Fault => Message::Fault(FaultEvent {
                node: sender(id.class, id.node_raw)?,
                code: enum_field(&fault::CODE, &b, FaultCode::from_raw)?,
                transition: enum_field(&fault::TRANSITION, &b, FaultTransition::from_raw)?,
                detail: fault::DETAIL.get_as(&b)?,
                uptime_ms: fault::UPTIME_MS.get_as(&b)?,
            }),
            MessageClass::Version => Message::Version(Version {
                node: sender(id.class, id.node_raw)?,
                protocol: version::PROTOCOL.get_as(&b)?,
                major: version::MAJOR.get_as(&b)?,
                minor: version::MINOR.get_as(&b)?,
                patch: version::PATCH.get_as(&b)?,
                build: version::BUILD.get_as(&b)?,
            }),
            MessageClass::Identity => Message::Identity(Identity {
                node: sender(id.class, id.node_raw)?,
                uid_low: identity::UID_LOW.get_as(&b)?,
                uid_mid: identity::UID_MID.get_as(&b)?,
            }),
            MessageClass::BootInfo => Message::BootInfo(BootInfo {
                node: sender(id.class, id.node_raw)?,
                uid_high: boot_info::UID_HIGH.get_as(&b)?,
                reset_cause: enum_field(&boot_info::RESET_CAUSE, &b, ResetCause::from_raw)?,
                params_source: enum_field(&boot_info::PARAMS_SOURCE, &b, ConfigSource::from_raw)?,
                fault_history_len: boot_info::FAULT_HISTORY_LEN.get_as(&b)?,
                calibration_source: enum_field(
                    &boot_info::CALIBRATION_SOURCE,
                    &b,
                    ConfigSource::from_raw,
                )?,
            }),
            MessageClass::CommandAck => Message::CommandAck(CommandAck {
                node: sender(id.class, id.node_raw)?,
                opcode: enum_field(&command_ack::OPCODE, &b, Opcode::from_raw)?,
                result: enum_field(&command_ack::RESULT, &b, CommandResult::from_raw)?,
            }),
            MessageClass::FaultHistory => Message::FaultHistory(FaultHistoryEntry {
                node: sender(id.class, id.node_raw)?,
                entry: fault_history::ENTRY.get_as(&b)?,
                code: enum_field(&fault_history::CODE, &b, FaultCode::from_raw)?,
                state_after: enum_field(&fault_history::STATE_AFTER, &b, NodeState::from_raw)?,
                detail: fault_history::DETAIL.get_as(&b)?,
                uptime_ms: fault_history::UPTIME_MS.get_as(&b)?,
            }),
            MessageClass::ClockInfo => Message::ClockInfo(ClockInfo {
                node: sender(id.class, id.node_raw)?,
                source: enum_field(&clock_info::SOURCE, &b, ClockSource::from_raw)?,
                crystal: enum_field(&clock_info::CRYSTAL, &b, CrystalStatus::from_raw)?,
                oscillator_error_centi_pct: clock_info::OSCILLATOR_ERROR.get_as(&b)?,
                tolerated_error_ppm: clock_info::TOLERATED_ERROR.get_as(&b)?,
                crystal_freq_10hz: clock_info::CRYSTAL_FREQ.get_as(&b)?,
            }),
        };
        Ok(msg)
    }

    /// Decode any embedded-can frame.
    ///
    /// # Errors
    /// [`DecodeError::UnknownId`] for extended identifiers, [`DecodeError::RemoteFrame`] for
    /// remote frames, else as [`Message::decode`].
    pub fn from_frame<F: embedded_can::Frame>(frame: &F) -> Result<Message, DecodeError> {
        match frame.id() {
            embedded_can::Id::Extended(e) => Err(DecodeError::UnknownId { raw: e.as_raw() }),
            embedded_can::Id::Standard(s) => {
                if frame.is_remote_frame() {
                    return Err(DecodeError::RemoteFrame {
                        raw: s.as_raw() as u32,
                    });
                }
                Message::decode(s.as_raw(), frame.data())
            }
        }
    }

    /// Encode into any embedded-can frame type.
    ///
    /// # Errors
    /// As [`Message::encode`]; [`EncodeError::BufferTooShort`] if the frame type refuses
    /// the payload.
    pub fn to_frame<F: embedded_can::Frame>(&self) -> Result<F, EncodeError> {
        let raw = self.encode()?;
        raw.to_frame().ok_or(EncodeError::BufferTooShort {
            needed: raw.len,
            available: 0,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_layout_fits_its_dlc_without_overlap() {
        for m in MESSAGES {
            let mut used = 0u8;
            for s in m.signals {
                for i in 0..s.kind.bytes() {
                    let byte = s.byte + i;
                    assert!(byte < m.dlc, "{}.{} past DLC", m.name, s.name);
                    assert_eq!(used & (1 << byte), 0, "{}.{} overlaps", m.name, s.name);
                    used |= 1 << byte;
                }
            }
            assert_eq!(
                used.count_ones(),
                m.dlc as u32,
                "{}: payload fully used",
                m.name
            );
        }
    }

    #[test]
    fn every_class_has_one_spec() {
        for c in MessageClass::ALL {
            assert_eq!(MESSAGES.iter().filter(|m| m.class == c).count(), 1);
        }
    }

    #[test]
    fn ankle_state_wire_format_is_little_endian_scaled() {
        let m = Message::AnkleState(AnkleState {
            node: NodeId::LeftAnkle,
            angle: Angle(-800),
            rate: AngularRate(1500),
            actuator_position: Angle(2000),
            phase: ReflexPhase::Push,
        });
        let f = m.encode().unwrap();
        assert_eq!(f.id.raw(), 0x072);
        assert_eq!(f.payload(), &[0xE0, 0xFC, 0xDC, 0x05, 0xD0, 0x07, 3]);
        assert_eq!(Message::decode(0x072, f.payload()), Ok(m));
    }

    #[test]
    fn emergency_stop_uses_its_own_high_priority_id() {
        let m = Message::Command(Command {
            target: Target::Broadcast,
            kind: CommandKind::EmergencyStop,
        });
        let f = m.encode().unwrap();
        assert_eq!(f.id.raw(), 0x01F);
        assert_eq!(f.payload(), &[3]);
        assert_eq!(Message::decode(0x01F, &[3]), Ok(m));
    }

    #[test]
    fn encode_rejects_invalid_node_and_short_buffer() {
        let m = Message::HeelStrike(HeelStrike {
            node: NodeId::Host,
            step_count: 0,
            time_us: 0,
        });
        assert!(matches!(
            m.encode(),
            Err(EncodeError::InvalidNode {
                class: MessageClass::HeelStrike,
                node_raw: 1
            })
        ));
        let ok = Message::HeelStrike(HeelStrike {
            node: NodeId::LeftAnkle,
            step_count: 0,
            time_us: 0,
        });
        let mut small = [0u8; 3];
        assert_eq!(
            ok.encode_into(&mut small),
            Err(EncodeError::BufferTooShort {
                needed: 6,
                available: 3
            })
        );
        assert!(Command::set_param(Target::Broadcast, ParamId::TautAngle, 1.0).is_err());
        let cmd = Message::Command(Command {
            target: Target::Node(NodeId::Host),
            kind: CommandKind::Enable,
        });
        assert!(matches!(cmd.encode(), Err(EncodeError::InvalidNode { .. })));
    }
}
