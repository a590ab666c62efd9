//! Sim-backed implementations of the hardware traits the board's drivers use, so that each
//! simulated ankle runs the firmware exactly as the board does: one
//! [`firmware::runner::AnkleDrivers::step`] per control tick, over
//!
//! * [`SimSpi`] — an `embedded_hal::spi::SpiDevice` emulating the AS5047P encoder for
//!   `firmware::drivers::encoder::MagneticEncoder`: 16-bit frames, most significant byte
//!   first, the answer to a command in the *next* frame (pipelined), even parity in bit 15 and
//!   the error flag in bit 14; the counts come from [`crate::SimEncoder`] (its quantisation
//!   and its faults);
//! * [`SimContactPin`] — an `embedded_hal::digital::InputPin`, active low as on the board
//!   (switch to ground, pull-up), for `firmware::drivers::contact::ContactSwitch`, which
//!   debounces it;
//! * [`SimCan`] — an `embedded_can::nb::Can` controller for `firmware::drivers::can::CanPort`:
//!   `transmit` hands frames to the orchestrator, which queues them on the [`canbus::Bus`] at
//!   the tick time (`WouldBlock` when the bus node's transmit queue has no room, an error when
//!   the node is bus-off); `receive` yields the raw frames the bus delivered to this node
//!   (the firmware decodes them and counts malformed ones itself);
//! * [`SimClock`] — `firmware::time::Monotonic`, the tick time;
//! * [`SimBridges`], [`SimSpoolEncoder`], [`SimCurrentSense`] — the board's power stage,
//!   spool encoder and current sense over [`crate::spool_plant::SpoolPlant`] (a DC gear motor,
//!   spool and string), for the firmware's own `SpoolMotor` driver
//!   ([`crate::config::ActuatorChoice::SpoolMotor`]);
//! * [`SimActuator`] — `firmware::drivers::actuator::Actuator` over the simulator's
//!   [`crate::ActuatorModel`], a position servo (rate limit and first-order lag) that follows
//!   the setpoint and leaves the string slack when released: the default
//!   ([`crate::config::ActuatorChoice::Servo`]). It follows the setpoint, not the measured
//!   angle, so a frozen reading changes nothing it does.
//!
//! [`AnkleActuator`] is either, behind the firmware's `Actuator` trait.
//!
//! Every piece shares its state with the orchestrator ([`crate::FirmwareInTheLoop`]) through
//! `Rc<Cell<..>>` / `Rc<RefCell<..>>` handles: the simulation is single-threaded, and the
//! orchestrator sets the sensor state before each `step` and collects frames and the
//! actuator's segment after it.

pub mod actuator;
pub mod can;
pub mod clock;
pub mod contact;
pub mod spi;
pub mod spool;

pub use actuator::{ActuatorLink, AnkleActuator, SimActuator};
pub use can::{CanLink, SimCan, SimCanError, SimFrame};
pub use clock::SimClock;
pub use contact::SimContactPin;
pub use spi::{Shaft, SimSpi, SimSpiError};
pub use spool::{PlantLink, SimBridges, SimCurrentSense, SimSpoolEncoder, SimSpoolMotor};
