//! Ankle node firmware of the walker, as a `no_std` library.
//!
//! * [`node::AnkleNode`] — the whole node logic behind one deterministic
//!   `tick(now, inputs) -> outputs` step: commands, sensor plausibility, faults and the safe
//!   state, the stretch reflex ([`reflex`], paper Fig. 8), periodic CAN messages. No hardware.
//! * [`drivers`] — an SPI magnetic angle encoder, a debounced contact switch, the string
//!   actuator (PWM + direction pin, or a position servo) and a CAN port, generic over
//!   embedded-hal 1.0 and embedded-can 0.4.
//! * [`runner::AnkleDrivers`] — wires the drivers to the node, one `step()` per tick.
//! * [`clock_choice`], [`can_timing`] — the clock chosen at start-up (crystal checked with a
//!   timeout and a frequency measurement, or the internal oscillator), the CAN bit timing
//!   computed for it and the oscillator error it tolerates.
//! * [`bench_log`], [`log_limit`] — the defmt bench log: per-kind token buckets, one line per
//!   tick.
//! * [`scenarios`] — scripted sensor traces with a tiny ankle plant; the host tests and the
//!   QEMU binary run the same traces and must produce the same actuator commands bit for bit.
//!
//! No heap, no panics (clippy denies `unwrap`, `expect` and `panic` outside tests), bounded
//! work per tick. The `defmt` feature logs state changes and faults.
//!
//! No silent integer wrap either: clippy's `arithmetic_side_effects`,
//! `cast_possible_truncation`, `cast_possible_wrap` and `cast_sign_loss` are denied for the
//! library (not its unit tests). Arithmetic is checked or saturating, wrapping only where the
//! wrap is the meaning (counts on the encoder's circle, the bus's free-running clocks and
//! counters, a hash), each said where it happens; sensor and wire values convert through
//! `TryFrom` or the saturating [`convert`] functions.
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

pub(crate) mod fmt;

pub mod bench_log;
pub mod can_timing;
pub mod clock_choice;
pub mod convert;
pub mod drivers;
pub mod estimator;
pub mod fault_report;
pub mod following;
pub mod log_limit;
pub mod node;
pub mod param_store;
pub mod params;
pub mod reflex;
pub mod runner;
pub mod scenarios;
pub mod sensors;
pub mod stride_check;
pub mod supervisor;
pub mod time;

pub use node::{AnkleNode, DriverHealth, NodeConfig, TickInputs, TickOutputs};
pub use reflex::ActuatorCommand;
pub use time::{Instant, Monotonic};
