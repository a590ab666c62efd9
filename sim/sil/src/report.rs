//! What a firmware-in-the-loop run reports (serialisable; enumerations of the protocol as
//! their names).

use std::collections::BTreeMap;

use canbus::BusStats;
use serde::Serialize;

use crate::actuator::ActuatorStats;
use crate::side::Side;

/// A fault raised or cleared by a node (from the node's own `Fault` event, whether or not the
/// bus delivered it).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FaultRecord {
    /// Tick time \[s\].
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

/// The fault that ended a walk: the first safety-relevant fault a node raised (its own
/// `Fault` event) at or before the walk's failure (`walker sil --json`'s `fall_cause`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FallCause {
    /// The node that raised it.
    pub side: Side,
    /// Fault code (`EncoderStuck`, `ContactStuck`, `SpoolStuck`, ...).
    pub code: String,
    /// The event's evidence (`detail`: the stuck counts, the switch's state, the ankle's
    /// motion under a silent spool, ...).
    pub detail: i16,
    /// When it was raised \[s\].
    pub t_s: f64,
    /// How long before the failure \[s\].
    pub before_failure_s: f64,
}

/// A node-state change.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StateChange {
    /// Tick time \[s\].
    pub t_s: f64,
    /// The node.
    pub side: Side,
    /// The new state (`Enabled`, `Safe`, `EmergencyStop`, `Disabled`).
    pub state: String,
}

/// A reflex-phase change.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PhaseChange {
    /// Tick time \[s\].
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
    /// Tick time \[s\].
    pub t_s: f64,
    /// The foot that landed.
    pub side: Side,
    /// Its ankle angle \[rad\].
    pub angle_rad: f64,
}

/// The extension profile's parameters in force on a node, as the node reported them over the
/// bus (its last `ParamAck` for each: the answers to the host's `GetParam` after start-up and
/// after each write). `null` for one the node never reported (a dropped frame, say).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct NodeParameters {
    /// Ankle angle at which the string becomes taut \[rad\] (`TautAngle`).
    pub taut_angle_rad: Option<f64>,
    /// Ankle angle the actuator extends to \[rad\] (`ExtendedAngle`).
    pub extended_angle_rad: Option<f64>,
    /// Nominal duration of the extension \[s\] (`PushDuration`).
    pub push_duration_s: Option<f64>,
    /// Bound on the profile's rate [rad/s] (`MaxPushRate`).
    pub max_push_rate_rad_per_s: Option<f64>,
    /// The duration the node's profile takes with these values \[s\]: the nominal one,
    /// stretched by the rate bound when needed (`ankle_profile::duration_within_rate`, the
    /// firmware's own rule).
    pub effective_push_duration_s: Option<f64>,
}

impl NodeParameters {
    /// From the values reported [SI units], computing the effective duration.
    pub fn from_reported(
        taut_angle_rad: Option<f64>,
        extended_angle_rad: Option<f64>,
        push_duration_s: Option<f64>,
        max_push_rate_rad_per_s: Option<f64>,
    ) -> Self {
        let effective_push_duration_s = match (
            taut_angle_rad,
            extended_angle_rad,
            push_duration_s,
            max_push_rate_rad_per_s,
        ) {
            (Some(taut), Some(extended), Some(duration), Some(rate)) => Some(
                ankle_profile::duration_within_rate(extended - taut, duration, rate, |c| {
                    f64::from(c)
                }),
            ),
            _ => None,
        };
        NodeParameters {
            taut_angle_rad,
            extended_angle_rad,
            push_duration_s,
            max_push_rate_rad_per_s,
            effective_push_duration_s,
        }
    }
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
    /// Frames the controller accepted that the bus did not take (should stay 0: the
    /// controller refuses while bus-off and takes no more than the queue's room).
    pub frames_lost_at_bus: u64,
    /// Transmit attempts the controller refused because the node is bus-off (the firmware's
    /// CAN port keeps the frame queued and reports a bus error).
    pub frames_refused_bus_off: u64,
    /// Transmit attempts the controller refused with `WouldBlock` because the bus node's
    /// transmit queue was full (the firmware's CAN port keeps the frame and offers it again
    /// at the next tick).
    pub frames_refused_queue_full: u64,
    /// Messages the firmware's CAN port decoded (its `received` counter).
    pub messages_read: u64,
    /// Frames the firmware's CAN port read that were not protocol messages (its `malformed`
    /// counter: a babbler's, say).
    pub frames_malformed: u64,
    /// Frames the firmware's CAN port dropped (its own transmit queue of 32 full); each sets
    /// the node's `CanBus` fault.
    pub port_dropped: u64,
    /// Controller errors the firmware's CAN port counted (one per error frame seen, and the
    /// refusals while bus-off).
    pub port_bus_errors: u64,
    /// Delivered frames lost because the node's receive FIFO was full.
    pub rx_overflows: u64,
    /// Largest number of frames left in the receive FIFO after a tick (the port reads at most
    /// 8 messages, 16 frames, per tick).
    pub max_rx_backlog: usize,
    /// Messages the node's transmit list could not hold (firmware counter, should stay 0).
    pub firmware_dropped_tx: u32,
    /// The string actuator of this ankle: the servo model's figures (zero with the motor).
    pub actuator: ActuatorStats,
    /// The motor plant's figures (`null` with the servo model).
    pub spool_plant: Option<crate::spool_plant::SpoolPlantStats>,
    /// The extension profile's parameters in force, as the node reported them.
    pub parameters: NodeParameters,
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
    /// Last heartbeat per ankle: (time \[s\], state, fault names).
    pub last_heartbeat: BTreeMap<String, (f64, String, Vec<String>)>,
    /// `Fault` events seen.
    pub fault_events_seen: u64,
    /// Parameter acknowledgements seen (time, node, parameter, status, value in force; bounded
    /// like the histories).
    pub param_acks: Vec<String>,
    /// Commands the host put on the bus: (time \[s\], command; bounded like the histories).
    pub commands_sent: Vec<(f64, String)>,
    /// Frames injected by socketcand clients.
    pub frames_from_clients: u64,
}

/// Entries left out of each bounded history of a [`SilReport`] (between its first and its most
/// recent entries).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct HistoryElided {
    /// Of `state_history`.
    pub state_history: u64,
    /// Of `phase_history`.
    pub phase_history: u64,
    /// Of `faults`.
    pub faults: u64,
    /// Of `landings`.
    pub landings: u64,
    /// Of `bus_off`.
    pub bus_off: u64,
    /// Of `host.commands_sent`.
    pub commands_sent: u64,
    /// Of `host.param_acks`.
    pub param_acks: u64,
}

impl HistoryElided {
    /// Entries elided over every history.
    pub fn total(&self) -> u64 {
        self.state_history
            + self.phase_history
            + self.faults
            + self.landings
            + self.bus_off
            + self.commands_sent
            + self.param_acks
    }
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
    /// Frames clients tried to send to a read-only server (no `--socketcand-allow-send`).
    pub sends_refused: u64,
    /// Clients dropped for not opening the bus in rawmode in time (or to make room).
    pub clients_dropped_idle: u64,
    /// Clients dropped because they stopped reading.
    pub clients_dropped_stalled: u64,
    /// Connections refused (every place taken by a client in rawmode).
    pub clients_refused: u64,
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
    /// Time of the last tick \[s\].
    pub t_end_s: f64,
    /// The left and the right node.
    pub nodes: BTreeMap<Side, NodeReport>,
    /// Node-state changes (the first and the most recent, up to
    /// `SilConfig::history_capacity`; so for every history below).
    pub state_history: Vec<StateChange>,
    /// Reflex-phase changes.
    pub phase_history: Vec<PhaseChange>,
    /// Faults raised or cleared.
    pub faults: Vec<FaultRecord>,
    /// Landings.
    pub landings: Vec<Landing>,
    /// Frames delivered on the bus.
    pub frames_delivered: u64,
    /// Bus-off events: (time \[s\], node name).
    pub bus_off: Vec<(f64, String)>,
    /// Entries each history left out to stay within its capacity.
    pub history_elided: HistoryElided,
    /// Bus statistics (load, per identifier and per node).
    pub bus: BusStats,
    /// The host's view.
    pub host: HostReport,
    /// The socketcand server, if one ran.
    pub socketcand: Option<SocketcandReport>,
    /// Injected encoder faults that took effect: side, kind, walk time.
    pub sensor_faults_applied: Vec<crate::sensors::AppliedSensorFault>,
}

impl SilReport {
    /// First time `side` entered `state` at or after `t_s` \[s\].
    pub fn first_state_at_or_after(&self, side: Side, state: &str, t_s: f64) -> Option<f64> {
        self.state_history
            .iter()
            .find(|c| c.side == side && c.state == state && c.t_s >= t_s)
            .map(|c| c.t_s)
    }

    /// First time `side` raised fault `code` \[s\].
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

    /// The first safety-relevant fault raised at or before `failure_s` \[s\], as the cause of
    /// a failure then; `None` when no node raised one by then.
    pub fn fall_cause(&self, failure_s: f64) -> Option<FallCause> {
        let safety_relevant = |code: &str| {
            protocol::FaultCode::ALL
                .iter()
                .any(|c| format!("{c:?}") == code && c.is_safety_relevant())
        };
        self.faults
            .iter()
            .find(|f| f.raised && f.t_s <= failure_s && safety_relevant(&f.code))
            .map(|f| FallCause {
                side: f.side,
                code: f.code.clone(),
                detail: f.detail,
                t_s: f.t_s,
                before_failure_s: failure_s - f.t_s,
            })
    }
}

/// The names of the faults in `flags` (`EncoderRate`, ...), in the protocol's order.
pub(crate) fn fault_names(flags: protocol::FaultFlags) -> Vec<String> {
    protocol::FaultCode::ALL
        .iter()
        .filter(|c| flags.contains(**c))
        .map(|c| format!("{c:?}"))
        .collect()
}
