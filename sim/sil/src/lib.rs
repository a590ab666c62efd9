//! Firmware in the loop: the ankle nodes' firmware, on a simulated CAN bus, controlling the
//! simulated walker's stance ankle (see `sim::engine::control` and `docs/sil.md`).
//!
//! Two [`firmware::AnkleNode`]s (left, node 2, and right, node 3) and a host (node 1) sit on a
//! [`canbus::Bus`]. Every control tick of [`FirmwareInTheLoop`]:
//!
//! 1. the bus runs up to the tick time; each delivered frame is decoded and queued for every
//!    node but its sender (at most 8 are read per tick, as on the board; the rest wait), the
//!    host sees everything; the candump log and the socketcand server get every event
//!    (`bus_side`);
//! 2. the host sends its due commands (`Enable` to every ankle at the first tick, the
//!    scheduled ones, frames from socketcand clients; `host`);
//! 3. each node runs one [`firmware::runner::AnkleDrivers::step`], as on the board, over
//!    sim-backed hardware ([`hal`]; `ankle`): the orchestrator sets the shaft angle (the
//!    encoder's SPI device quantises it, [`sensors`]), the raw contact switch (both from the
//!    stance/swing bookkeeping, `gait`), the clock and the room in the bus node's transmit
//!    queue, steps the drivers, records what changed (`records`), queues the frames the
//!    node's CAN controller accepted on the bus at the tick time, and takes the segment its
//!    actuator ([`actuator`] behind [`hal::SimActuator`]) moved the string through; the stance
//!    ankle's segment is the tick's [`ActuatorSegment`](sim::engine::control::ActuatorSegment).
//!
//! The board's `PwmDirActuator` (a P loop over PWM duty and a direction pin) is replaced by the
//! servo model: see [`hal`] for why.
//!
//! The walker model always has its stance leg on the right of its mirrored frame; physically
//! the stance alternates, starting with [`SilConfig::first_stance`], and
//! [`AnkleController::heel_strike`](sim::engine::control::AnkleController::heel_strike) swaps it.

pub mod actuator;
mod ankle;
mod bus_side;
pub mod config;
mod error;
pub mod firmware_param;
pub mod frames;
mod gait;
pub mod hal;
pub mod history;
mod host;
mod integrator;
mod orchestrator;
mod records;
pub mod report;
pub mod scene_profile;
pub mod sensors;
pub mod side;
pub mod spool_plant;
pub mod swing;
mod tick;
pub mod walk;

#[cfg(test)]
mod tests;

pub use actuator::{ActuatorModel, ActuatorParams, ActuatorStats};
pub use canbus::wait_client::{wait_client_timeout, MAX_WAIT_CLIENT_S};
pub use config::{ActuatorChoice, HostCommand, SilConfig, SupplyDropInHold, READ_BACK_PARAMS};
pub use error::{SilError, TickError};
/// What the firmware's spool-motor driver set the power stage to.
pub use firmware::drivers::spool_motor::StageOutput;
pub use firmware_param::{FirmwareParam, FirmwareParamError};
pub use frames::{BusFrame, FrameLog};
pub use history::BoundedLog;
pub use integrator::SIL_INTEGRATOR;
pub use orchestrator::FirmwareInTheLoop;
pub use report::{
    FallCause, FaultRecord, HistoryElided, HostReport, Landing, NodeParameters, NodeReport,
    PhaseChange, SilReport, SocketcandReport, StateChange,
};
pub use sensors::{
    AppliedSensorFault, DrivenPhase, SensorFault, SensorFaultParseError, SimEncoder,
};
pub use side::Side;
pub use spool_plant::{SpoolPlant, SpoolPlantParams, SpoolPlantStats};
pub use swing::{SwingAnkle, SwingAnkleModel};
