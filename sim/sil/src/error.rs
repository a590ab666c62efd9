//! Why a firmware-in-the-loop run could not be built ([`SilError`]) or could not go on (a
//! [`ControlError`] from a tick).

use canbus::BusError;
use protocol::NodeId;
use sim::control::ControlError;

/// Why a firmware-in-the-loop controller could not be built or finished.
#[derive(Debug, thiserror::Error)]
pub enum SilError {
    /// The bus refused its configuration or a fault.
    #[error("bus: {0}")]
    Bus(#[from] BusError),
    /// The firmware refused its node configuration.
    #[error("firmware node {node:?}: {reason}")]
    Node {
        /// The node.
        node: NodeId,
        /// The firmware's error, as text.
        reason: String,
    },
    /// The control period is not a positive number of microseconds.
    #[error("control period {period_s} s is not a positive whole number of microseconds")]
    Period {
        /// The offending period \[s\].
        period_s: f64,
    },
    /// The candump log could not be written.
    #[error("candump log: {0}")]
    Candump(#[from] std::io::Error),
    /// The socketcand server could not start.
    #[error("{0}")]
    Socketcand(#[from] canbus::socketcand::ServerError),
}

/// A tick's failure, as the walker's controller interface reports it.
pub(crate) fn control_error(e: impl std::fmt::Display) -> ControlError {
    ControlError(format!("firmware in the loop: {e}"))
}
