//! Why a firmware-in-the-loop run could not be built ([`SilError`]) or could not go on (a
//! [`TickError`], which the walker's controller interface carries as a [`ControlError`]).

use canbus::candump::WriteError;
use canbus::timestamp::TimestampOverflow;
use canbus::BusError;
use firmware::node::ConfigError;
use protocol::{EncodeError, NodeId};
use sim::engine::control::ControlError;

/// Why a firmware-in-the-loop controller could not be built or finished.
#[derive(Debug, thiserror::Error)]
pub enum SilError {
    /// The bus refused its configuration or a fault.
    #[error("bus: {0}")]
    Bus(#[from] BusError),
    /// The firmware refused its node configuration.
    #[error("firmware node {node:?}: {reason:?}")]
    Node {
        /// The node.
        node: NodeId,
        /// The firmware's error.
        reason: ConfigError,
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

/// Why the firmware in the loop could not run a control tick.
#[derive(Debug, thiserror::Error)]
pub enum TickError {
    /// The tick's time is not a finite, non-negative walk time.
    #[error("tick at t = {t_s} s")]
    InvalidTime {
        /// The tick's walk time \[s\].
        t_s: f64,
    },
    /// The tick comes before the previous one.
    #[error("tick at {t_s} s is before the previous tick at {previous_s} s")]
    BeforePrevious {
        /// The tick's walk time \[s\].
        t_s: f64,
        /// The previous tick's walk time (on the bus's nanosecond clock) \[s\].
        previous_s: f64,
    },
    /// The bus refused to run or to take a frame.
    #[error(transparent)]
    Bus(#[from] BusError),
    /// The candump log could not be written.
    #[error(transparent)]
    Candump(#[from] WriteError),
    /// The socketcand server could not stamp a frame.
    #[error(transparent)]
    Socketcand(#[from] TimestampOverflow),
    /// The host could not encode one of its messages.
    #[error("{0:?}")]
    Encode(EncodeError),
    /// The firmware applied no actuator command in the tick.
    #[error("the firmware applied no actuator command")]
    NoActuatorCommand,
    /// Neither ankle is the stance ankle.
    #[error("no stance ankle")]
    NoStanceAnkle,
}

/// The name the firmware in the loop goes by in a [`ControlError`].
const CONTROLLER: &str = "firmware in the loop";

/// A tick's failure, as the walker's controller interface reports it.
impl From<TickError> for ControlError {
    fn from(e: TickError) -> Self {
        ControlError::controller(CONTROLLER, e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_refused_node_keeps_the_firmware_s_error() {
        let e = SilError::Node {
            node: NodeId::Host,
            reason: ConfigError::NotAnAnkle(NodeId::Host),
        };
        assert_eq!(e.to_string(), "firmware node Host: NotAnAnkle(Host)");
    }

    #[test]
    fn a_tick_s_failure_reads_as_the_firmware_in_the_loop_s() {
        let e = ControlError::from(TickError::NoStanceAnkle);
        assert_eq!(
            e.to_string(),
            "controller: firmware in the loop: no stance ankle"
        );
        assert!(matches!(
            e.source_error().downcast_ref::<TickError>(),
            Some(TickError::NoStanceAnkle)
        ));
    }
}
