//! CAN messages between the walker's two ankle nodes and a host.
//!
//! * Identifiers ([`id`]): 11 bits, message class in the high bits (priority order: emergency
//!   stop, heel strike, fault, command, parameter acknowledgement, heartbeat, ankle state,
//!   version), node in the low four bits.
//! * Payloads: little-endian, byte-aligned, scaled integers with stated units ([`values`]).
//! * Every layout is defined once, in [`MESSAGES`]; the codec ([`Message::encode`],
//!   [`Message::decode`]) writes through the same [`signal::SignalSpec`] constants, and the
//!   DBC file (`protocol/walker.dbc`), the bus-load figure ([`busload`]) and the shared test
//!   vectors are generated from it.
//! * `no_std`, no heap, no panics. The `std` feature adds `std::error::Error` impls, the DBC
//!   renderer and the test vectors; `defmt` adds `defmt::Format` impls.
//!
//! Integers are never wrapped silently: clippy's `arithmetic_side_effects`,
//! `cast_possible_truncation`, `cast_possible_wrap` and `cast_sign_loss` are denied for the
//! library (not its unit tests); the codec refuses a raw value outside its signal
//! ([`EncodeError::RawOutOfRange`]) and reads every field through `TryFrom`
//! ([`signal::SignalSpec::get_as`]).
#![no_std]
#![cfg_attr(
    not(test),
    deny(
        clippy::arithmetic_side_effects,
        clippy::cast_possible_truncation,
        clippy::cast_possible_wrap,
        clippy::cast_sign_loss
    )
)]

pub mod busload;
#[cfg(feature = "std")]
pub mod dbc;
pub mod error;
pub mod id;
pub mod messages;
pub mod signal;
pub mod values;
#[cfg(feature = "std")]
pub mod vectors;

pub use error::{DecodeError, EncodeError, RangeError};
pub use id::{accepted_by_ankle, CanId, MessageClass, NodeId, Target, ACCEPTED_BY_ANKLE};
pub use messages::{
    spec, AnkleState, BootInfo, ClockInfo, Command, CommandAck, CommandKind, FaultEvent,
    FaultHistoryEntry, Heartbeat, HeelStrike, Identity, Message, ParamAck, RawFrame, Version,
    BITRATE_BPS, MESSAGES, PROTOCOL_VERSION,
};
pub use values::{
    Angle, AngularRate, ClockSource, CommandResult, ConfigSource, CrystalStatus, FaultCode,
    FaultFlags, FaultTransition, NodeState, Opcode, ParamId, ParamStatus, ParamValue, ReflexPhase,
    ResetCause,
};
