//! A simulated classic CAN bus for software-in-the-loop runs, and the tools to watch it.
//!
//! * [`bus::Bus`] — nodes with transmit queues, arbitration by identifier, frame timing at a
//!   bit rate with the actual (or worst-case) stuff bits, error confinement (TEC, error
//!   passive, bus-off), injectable [`fault::FaultSpec`]s (drop, delay, corrupt, babble,
//!   bus-off) and bus-load statistics; deterministic, driven by simulated time.
//! * [`bits`] — the frame's bit stream: CRC-15, stuffing, lengths.
//! * [`candump`] — candump (`candump -L`) log writer and reader, compatible with python-can.
//! * [`socketcand`] — a socketcand-protocol TCP server (python-can's `socketcand` interface
//!   connects to it) that serves delivered frames and accepts frames from clients.
//! * [`spec`] — the `kind:key=value,...` text form of faults, parsed once for every kind.
//! * [`timestamp`] — origin plus simulated time, checked (a far origin is an error).
//! * [`wait_client`] — the bound of `--wait-client` (canbus-demo, `walker sil`), checked once.
//! * [`demo`] — two fake ankle nodes and a host sending the protocol's messages at their
//!   nominal rates (the `canbus-demo` binary).
//!
//! See `docs/canbus.md`.

pub mod bits;
pub mod bus;
pub mod candump;
pub mod demo;
pub mod fault;
pub mod frame;
pub mod protocol_ids;
pub mod rng;
pub mod socketcand;
pub mod spec;
pub mod timestamp;
pub mod wait_client;

pub use bus::{
    Bus, BusConfig, BusError, BusEvent, BusStats, Delivered, ErrorState, NodeHandle, SendOutcome,
    Stuffing,
};
pub use fault::{FaultKind, FaultParseError, FaultSpec, NodeRef};
pub use frame::{Frame, FrameError};
