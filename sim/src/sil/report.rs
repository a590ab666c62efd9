//! What a firmware-in-the-loop run reports (serialisable; enumerations of the protocol as
//! their names).

use std::collections::BTreeMap;

use canbus::BusStats;
use serde::Serialize;

use super::actuator::ActuatorStats;
use super::config::Side;

/// A fault raised or cleared by a node (from the node's own `Fault` event, whether or not the
/// bus delivered it).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FaultRecord {
    /// Tick time [s].
    pub t_s: f64,
    /// The node.
    pub side: Side,
    /// Fault code (`EncoderRate`, `PeerHeartbeatLost`, ...).
    pub code: String,
    /// Raised (true) or cleared.
    pub raised: bool,
    /// The offending raw value of the event.
    pub detail: i16,
}

/// A node-state change.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StateChange {
    /// Tick time [s].
    pub t_s: f64,
    /// The node.
    pub side: Side,
    /// The new state (`Enabled`, `Safe`, `EmergencyStop`, `Disabled`).
    pub state: String,
}

/// A reflex-phase change.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PhaseChange {
    /// Tick time [s].
    pub t_s: f64,
    /// The node.
    pub side: Side,
    /// The new phase (`Inactive`, `Swing`, `Free`, `Push`, `Hold`).
    pub phase: String,
    /// The node was the stance ankle at that tick.
    pub stance: bool,
}

/// A foot landing: the stance ankle angle at the first tick after a heel strike (and at the
/// first tick of the run).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Landing {
    /// Tick time [s].
    pub t_s: f64,
    /// The foot that landed.
    pub side: Side,
    /// Its ankle angle [rad].
    pub angle_rad: f64,
}

/// One ankle node over the run.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct NodeReport {
    /// State at the end.
    pub state: String,
    /// Reflex phase at the end.
    pub phase: String,
    /// Faults active at the end.
    pub active_faults: Vec<String>,
    /// Raises per fault code.
    pub fault_raises: BTreeMap<String, u32>,
    /// Free → Push transitions (string engaged).
    pub engagements: u32,
    /// Releases by the other foot's `HeelStrike` message (the normal case).
    pub releases_by_peer_heel_strike: u32,
    /// Releases by the own contact switch opening first (the fallback).
    pub releases_by_lift_off: u32,
    /// `HeelStrike` messages the node sent.
    pub heel_strikes_sent: u32,
    /// Frames queued on the bus.
    pub frames_queued: u64,
    /// Frames discarded at the sender by a `drop` fault.
    pub frames_dropped: u64,
    /// Frames refused because the node is bus-off.
    pub frames_refused_bus_off: u64,
    /// Frames refused because the transmit queue was full.
    pub frames_refused_queue_full: u64,
    /// Messages received (read by the node).
    pub messages_read: u64,
    /// Largest backlog of received messages left for a later tick (more than 8 in a tick).
    pub max_rx_backlog: usize,
    /// Messages the node's transmit list could not hold (firmware counter, should stay 0).
    pub firmware_dropped_tx: u32,
    /// The string actuator of this ankle.
    pub actuator: ActuatorStats,
}

/// What the host saw on the bus.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct HostReport {
    /// Frames delivered (the host receives every frame, its own excepted).
    pub frames_seen: u64,
    /// Frames that did not decode (a babbler's, say).
    pub undecodable_frames: u64,
    /// Frames seen per message class.
    pub per_class: BTreeMap<String, u64>,
    /// Last heartbeat per ankle: (time [s], state, fault names).
    pub last_heartbeat: BTreeMap<String, (f64, String, Vec<String>)>,
    /// `Fault` events seen.
    pub fault_events_seen: u64,
    /// Parameter acknowledgements seen (time, node, parameter, status, value in force).
    pub param_acks: Vec<String>,
    /// Commands the host put on the bus: (time [s], command).
    pub commands_sent: Vec<(f64, String)>,
    /// Frames injected by socketcand clients.
    pub frames_from_clients: u64,
}

/// Counters of the live socketcand server.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct SocketcandReport {
    /// Clients accepted.
    pub clients_accepted: u64,
    /// Frames written to clients.
    pub frames_sent: u64,
    /// Frames dropped on full client queues.
    pub frames_dropped: u64,
    /// Frames received from clients.
    pub frames_received: u64,
}

/// The whole run.
#[derive(Clone, Debug, Serialize)]
pub struct SilReport {
    /// Control ticks run.
    pub ticks: u64,
    /// Heel strikes (stance swaps) seen.
    pub heel_strikes: u64,
    /// Stance side at the end.
    pub stance: Side,
    /// Time of the last tick [s].
    pub t_end_s: f64,
    /// The left and the right node.
    pub nodes: BTreeMap<Side, NodeReport>,
    /// Every node-state change.
    pub state_history: Vec<StateChange>,
    /// Every reflex-phase change.
    pub phase_history: Vec<PhaseChange>,
    /// Every fault raised or cleared.
    pub faults: Vec<FaultRecord>,
    /// Every landing.
    pub landings: Vec<Landing>,
    /// Frames delivered on the bus.
    pub frames_delivered: u64,
    /// Bus-off events: (time [s], node name).
    pub bus_off: Vec<(f64, String)>,
    /// Bus statistics (load, per identifier and per node).
    pub bus: BusStats,
    /// The host's view.
    pub host: HostReport,
    /// The socketcand server, if one ran.
    pub socketcand: Option<SocketcandReport>,
}

impl SilReport {
    /// First time `side` entered `state` at or after `t_s` [s].
    pub fn first_state_at_or_after(&self, side: Side, state: &str, t_s: f64) -> Option<f64> {
        self.state_history
            .iter()
            .find(|c| c.side == side && c.state == state && c.t_s >= t_s)
            .map(|c| c.t_s)
    }

    /// First time `side` raised fault `code` [s].
    pub fn first_raise(&self, side: Side, code: &str) -> Option<f64> {
        self.faults
            .iter()
            .find(|f| f.side == side && f.code == code && f.raised)
            .map(|f| f.t_s)
    }

    /// The report of one node.
    pub fn node(&self, side: Side) -> Option<&NodeReport> {
        self.nodes.get(&side)
    }
}
