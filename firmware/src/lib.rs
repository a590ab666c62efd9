//! Ankle node firmware of the walker, as a `no_std` library.
//!
//! * [`node::AnkleNode`] — the whole node logic behind one deterministic
//!   `tick(now, inputs) -> outputs` step: commands, sensor plausibility, faults and the safe
//!   state, the stretch reflex ([`reflex`], paper Fig. 8), periodic CAN messages. No hardware.
//! * [`drivers`] — an SPI magnetic angle encoder, a debounced contact switch, the string
//!   actuator (PWM + direction pin, or a position servo) and a CAN port, generic over
//!   embedded-hal 1.0 and embedded-can 0.4.
//! * [`runner::AnkleDrivers`] — wires the drivers to the node, one `step()` per tick.
//! * [`scenarios`] — scripted sensor traces with a tiny ankle plant; the host tests and the
//!   QEMU binary run the same traces and must produce the same actuator commands bit for bit.
//!
//! No heap, no panics (clippy denies `unwrap`, `expect` and `panic` outside tests), bounded
//! work per tick. The `defmt` feature logs state changes and faults.
#![no_std]

pub(crate) mod fmt;

pub mod drivers;
pub mod estimator;
pub mod fault_report;
pub mod following;
pub mod node;
pub mod param_store;
pub mod params;
pub mod reflex;
pub mod runner;
pub mod scenarios;
pub mod sensors;
pub mod supervisor;
pub mod time;

pub use node::{AnkleNode, DriverHealth, NodeConfig, TickInputs, TickOutputs};
pub use reflex::ActuatorCommand;
pub use time::{Instant, Monotonic};
