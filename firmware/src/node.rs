//! The ankle node: one deterministic `tick(now, inputs) -> outputs` step that handles
//! commands, checks sensors, raises and clears faults, runs the reflex and schedules the
//! node's CAN messages. No hardware here; drivers feed it ([`crate::runner`]) and so can a
//! simulator.

use heapless::Vec;
use protocol::{
    Angle, AngularRate, AnkleState, BootInfo, ClockInfo, Command, CommandAck, CommandKind,
    CommandResult, ConfigSource, FaultCode, FaultEvent, FaultFlags, FaultHistoryEntry,
    FaultTransition, Heartbeat, HeelStrike, Identity, Message, NodeId, NodeState, Opcode, ParamAck,
    ParamStatus, ReflexPhase, ResetCause, Version, PROTOCOL_VERSION,
};

use crate::bench_log::{BenchEvent, BenchLog, StringEdge};
use crate::clock_choice::ClockChoice;
use crate::convert::saturating_i16;
use crate::estimator::{AngleEstimator, EstimatorGains};
use crate::fault_report::FaultReporter;
use crate::following::FollowingErrorMonitor;
use crate::params::ReflexParams;
use crate::reflex::{ActuatorCommand, Reflex, ReflexEvent, ReflexInputs, ReleaseCause};
use crate::sensors::{AngleSample, EncoderError, Plausibility, SensorFindings};
use crate::stride_check::{StrideCheck, StrideInputs};
use crate::time::Instant;

/// Messages the node reads per tick at most (bounded work); callers keep the rest queued.
pub const MAX_RX_PER_TICK: usize = 8;
/// Fault-history entries kept (the newest; older ones drop out).
pub const FAULT_HISTORY_LEN: usize = 8;

/// Capacity of the per-tick transmit list: heel strike, every fault code changing at once,
/// one acknowledgement per received message, state, heartbeat and version, one fault-history
/// dump and one identity (each answered once per tick however often asked), a deferred
/// acknowledgement, the identity's `ClockInfo`.
pub const MAX_TX_PER_TICK: usize =
    1 + FaultCode::ALL.len() + MAX_RX_PER_TICK + 3 + FAULT_HISTORY_LEN + 2 + 1 + 1;

// docs/firmware.md states the value: 38 with 14 fault codes, 8 answers and 8 history records.
const _: () = assert!(MAX_TX_PER_TICK == 38);

/// What the node asks of the layer around it (the board, the driver runner): things it
/// cannot do itself.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NodeRequest {
    /// Store the parameters in force and the encoder zero in flash, then report with
    /// [`AnkleNode::storage_done`].
    SaveParams,
    /// Use this raw reading as the encoder's zero from now on.
    SetEncoderZero {
        /// Counts read at ankle angle zero.
        zero_counts: u16,
    },
}

/// One fault-history record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct HistoryRecord {
    code: FaultCode,
    detail: i16,
    uptime_ms: u32,
    state_after: NodeState,
}

/// Firmware version sent in the [`Version`] message.
pub const FIRMWARE_VERSION: (u8, u8, u8) = (0, 1, 0);

/// Configuration fixed at start-up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeConfig {
    /// Which ankle this is.
    pub node: NodeId,
    /// Period of [`AnkleState`] telemetry \[µs\] (nominal 5 000: 200 Hz).
    pub state_period_us: u64,
    /// Period of the heartbeat \[µs\] (nominal 50 000: 20 Hz).
    pub heartbeat_period_us: u64,
    /// Period of the version message \[µs\] (nominal 5 000 000; also sent at start).
    pub version_period_us: u64,
    /// Build identifier sent in the version message (the board: the first 8 hex digits of
    /// the git commit).
    pub build_id: u32,
    /// Chip unique ID (96 bits), sent in `Identity` and `BootInfo`; zero in simulation.
    pub uid: [u32; 3],
    /// Why the chip last reset.
    pub reset_cause: ResetCause,
    /// Where the parameters in force came from.
    pub params_source: ConfigSource,
    /// Where the encoder zero came from.
    pub calibration_source: ConfigSource,
    /// Estimator gains.
    pub estimator: EstimatorGains,
    /// The clock chosen at start-up ([`crate::clock_choice::choose`]; sent in `ClockInfo`; a
    /// refused power stage raises `ClockTolerance` and keeps the node from being enabled).
    pub clock: ClockChoice,
}

impl NodeConfig {
    /// Nominal configuration for `node` (rates as in `docs/protocol.md`).
    pub fn nominal(node: NodeId) -> Self {
        NodeConfig {
            node,
            state_period_us: 5_000,
            heartbeat_period_us: 50_000,
            version_period_us: 5_000_000,
            build_id: 0,
            uid: [0; 3],
            reset_cause: ResetCause::Unknown,
            params_source: ConfigSource::Defaults,
            calibration_source: ConfigSource::Defaults,
            estimator: EstimatorGains::default(),
            clock: ClockChoice::SIMULATED,
        }
    }
}

/// Why a node could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ConfigError {
    /// Only the two ankles run this firmware.
    NotAnAnkle(NodeId),
    /// A period of zero would send every tick without bound.
    ZeroPeriod,
}

/// Health of the drivers, as seen after the previous tick's outputs were applied.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct DriverHealth {
    /// The actuator driver failed to apply the last command.
    pub actuator_error: bool,
    /// Why, as the `Actuator` fault's detail (`ActuatorError::detail`; 0 when not known).
    pub actuator_error_detail: i16,
    /// A frame could not be queued for transmission (the queue was full).
    pub can_error: bool,
    /// The CAN controller is bus-off (from its status register; error frames and
    /// error-passive are not faults).
    pub can_bus_off: bool,
    /// The actuator moved the string in the last tick (`Actuator::string_moving`: the spool
    /// encoder turned); cross-checked against the ankle angle by the stuck check in hold.
    pub string_moving: bool,
    /// The actuator has a spool sensor (`Actuator::has_spool_sensor`): without one,
    /// `string_moving` is always false and says nothing about the spool.
    pub spool_sensor: bool,
    /// Received frames the controller lost to a full receive buffer since the last tick.
    pub rx_lost: u32,
}

/// Inputs of one tick.
#[derive(Clone, Copy, Debug)]
pub struct TickInputs<'a> {
    /// The encoder read of this tick.
    pub angle: Result<AngleSample, EncoderError>,
    /// Debounced contact switch: true when the foot is on the floor.
    pub contact_closed: bool,
    /// Messages received since the last tick (only the first [`MAX_RX_PER_TICK`] are read).
    pub received: &'a [Message],
    /// Driver health.
    pub drivers: DriverHealth,
}

/// Outputs of one tick.
#[derive(Clone, Debug, PartialEq)]
pub struct TickOutputs {
    /// What the actuator must do.
    pub actuator: ActuatorCommand,
    /// Messages to send, highest priority first.
    pub transmit: Vec<Message, MAX_TX_PER_TICK>,
    /// Node state after the tick.
    pub state: NodeState,
    /// Reflex phase after the tick.
    pub phase: ReflexPhase,
    /// A request for the layer around the node, if any.
    pub request: Option<NodeRequest>,
}

/// The ankle node.
#[derive(Clone, Debug)]
pub struct AnkleNode {
    config: NodeConfig,
    peer: NodeId,
    params: ReflexParams,
    state: NodeState,
    reflex: Reflex,
    faults: FaultFlags,
    plausibility: Plausibility,
    stride: StrideCheck,
    /// This tick's good reading (for the stride check after the reflex).
    sample: Option<AngleSample>,
    estimator: AngleEstimator,
    last_sample_at: Option<Instant>,
    contact: Option<bool>,
    step_count: u16,
    started_at: Option<Instant>,
    last_peer_heartbeat: Option<Instant>,
    next_state_at: Instant,
    next_heartbeat_at: Instant,
    next_version_at: Instant,
    dropped_tx: u32,
    following: FollowingErrorMonitor,
    driven_setpoint: Option<f32>,
    peer_state: Option<(Instant, NodeState)>,
    /// The peer's state when it changed into `Safe` or `EmergencyStop` while this node was
    /// enabled; cleared when this node leaves `Enabled` or the peer is enabled.
    peer_dropped_out: Option<NodeState>,
    rx_lost_total: u32,
    reporter: FaultReporter,
    history: heapless::Deque<HistoryRecord, FAULT_HISTORY_LEN>,
    raised_this_tick: usize,
    identity_due: bool,
    history_due: bool,
    pending_ack: Option<CommandAck>,
    request: Option<NodeRequest>,
    save_in_progress: bool,
    bench: BenchLog,
    /// The current tick's time (for the bench log's events).
    now: Instant,
}

/// Accumulates one tick's transmissions, counting what does not fit.
struct Outbox<'a> {
    list: Vec<Message, MAX_TX_PER_TICK>,
    dropped: &'a mut u32,
}

impl Outbox<'_> {
    fn push(&mut self, m: Message) {
        if self.list.push(m).is_err() {
            *self.dropped = self.dropped.saturating_add(1);
        }
    }
}

/// The contact switch's edges in one tick.
#[derive(Clone, Copy)]
struct ContactEdges {
    /// Open → closed: the own heel strike.
    heel_strike: bool,
    /// Closed → open: the own lift-off.
    lift_off: bool,
}

/// A tick's transmissions in priority order, stable (insertion sort over at most
/// [`MAX_TX_PER_TICK`] entries). Every message of this node carries the same node field, so the
/// class orders the identifiers. Pairs are taken with `get_mut` and a slice pattern: no
/// indexing, no bounds-check panic path.
fn sort_by_priority(transmit: &mut Vec<Message, MAX_TX_PER_TICK>) {
    for i in 1..transmit.len() {
        let mut j = i;
        while let Some(before) = j.checked_sub(1) {
            let Some([a, b]) = transmit.get_mut(before..=j) else {
                break;
            };
            if a.class() <= b.class() {
                break;
            }
            core::mem::swap(a, b);
            j = before;
        }
    }
}

impl AnkleNode {
    /// A disabled node with default parameters.
    ///
    /// # Errors
    /// [`ConfigError::NotAnAnkle`] for the host id, [`ConfigError::ZeroPeriod`] for a zero
    /// message period.
    pub fn new(config: NodeConfig) -> Result<Self, ConfigError> {
        let peer = config
            .node
            .peer()
            .ok_or(ConfigError::NotAnAnkle(config.node))?;
        if config.state_period_us == 0
            || config.heartbeat_period_us == 0
            || config.version_period_us == 0
        {
            return Err(ConfigError::ZeroPeriod);
        }
        Ok(AnkleNode {
            config,
            peer,
            params: ReflexParams::default(),
            state: NodeState::Disabled,
            reflex: Reflex::default(),
            faults: FaultFlags::NONE,
            plausibility: Plausibility::default(),
            stride: StrideCheck::default(),
            sample: None,
            estimator: AngleEstimator::new(config.estimator),
            last_sample_at: None,
            contact: None,
            step_count: 0,
            started_at: None,
            last_peer_heartbeat: None,
            next_state_at: Instant(0),
            next_heartbeat_at: Instant(0),
            // The first Version goes out with the identity at start-up.
            next_version_at: Instant(config.version_period_us),
            dropped_tx: 0,
            following: FollowingErrorMonitor::default(),
            driven_setpoint: None,
            peer_state: None,
            peer_dropped_out: None,
            rx_lost_total: 0,
            reporter: FaultReporter::default(),
            history: heapless::Deque::new(),
            raised_this_tick: 0,
            identity_due: true,
            history_due: false,
            pending_ack: None,
            request: None,
            save_in_progress: false,
            bench: BenchLog::default(),
            now: Instant(0),
        })
    }

    /// This node's id.
    pub fn id(&self) -> NodeId {
        self.config.node
    }
    /// Node state.
    pub fn state(&self) -> NodeState {
        self.state
    }
    /// Reflex phase.
    pub fn phase(&self) -> ReflexPhase {
        self.reflex.phase()
    }
    /// Active faults.
    pub fn faults(&self) -> FaultFlags {
        self.faults
    }
    /// Parameters in force.
    pub fn params(&self) -> &ReflexParams {
        &self.params
    }
    /// Put parameters loaded at start-up (from flash) in force; only before the first tick.
    /// Returns false (and changes nothing) afterwards.
    pub fn restore_params(&mut self, params: ReflexParams) -> bool {
        if self.started_at.is_some() {
            return false;
        }
        self.params = params;
        true
    }

    /// Put an event of the layer around the node (e.g. the CAN controller's state) into the
    /// bench log; written by a later tick, one line per tick.
    pub fn log_event(&mut self, now: Instant, event: BenchEvent) {
        self.bench.record(now, event);
    }

    /// Messages that did not fit a tick's transmit list (should stay 0).
    pub fn dropped_tx(&self) -> u32 {
        self.dropped_tx
    }
    /// Estimated ankle angle \[rad\] and rate [rad/s], `None` before a good sample.
    pub fn estimate(&self) -> Option<(f32, f32)> {
        self.estimator
            .angle_rad()
            .zip(self.estimator.rate_rad_per_s())
    }

    fn set_fault(&mut self, out: &mut Outbox, now: Instant, code: FaultCode, detail: Option<i16>) {
        let present = detail.is_some();
        if present == self.faults.contains(code) {
            return;
        }
        if present {
            self.faults.insert(code);
            self.bench
                .record(now, BenchEvent::FaultRaised(code, detail.unwrap_or(0)));
            if self.history.is_full() {
                let _ = self.history.pop_back();
            }
            let _ = self.history.push_front(HistoryRecord {
                code,
                detail: detail.unwrap_or(0),
                uptime_ms: now.uptime_ms(),
                state_after: self.state,
            });
            self.raised_this_tick = self.raised_this_tick.saturating_add(1);
        } else {
            self.faults.remove(code);
            self.bench.record(now, BenchEvent::FaultCleared(code));
        }
        if let Some(r) = self
            .reporter
            .changed(now, code, present, detail.unwrap_or(0))
        {
            self.send_fault(out, now, r.code, r.transition, r.detail);
        }
    }

    fn send_fault(
        &self,
        out: &mut Outbox,
        now: Instant,
        code: FaultCode,
        transition: FaultTransition,
        detail: i16,
    ) {
        out.push(Message::Fault(FaultEvent {
            node: self.config.node,
            code,
            transition,
            detail,
            uptime_ms: now.uptime_ms(),
        }));
    }

    /// Report the outcome of a [`NodeRequest::SaveParams`]; acknowledged in the next tick.
    pub fn storage_done(&mut self, ok: bool) {
        if self.save_in_progress {
            self.save_in_progress = false;
            self.bench.record(self.now, BenchEvent::Saved(ok));
            self.pending_ack = Some(self.ack(
                Opcode::SaveParams,
                if ok {
                    CommandResult::Done
                } else {
                    CommandResult::Failed
                },
            ));
        }
    }

    /// Fault-history entries held (newest first): code, detail, uptime \[ms\], state after.
    pub fn fault_history(&self) -> impl Iterator<Item = (FaultCode, i16, u32, NodeState)> + '_ {
        self.history
            .iter()
            .map(|r| (r.code, r.detail, r.uptime_ms, r.state_after))
    }

    fn ack(&self, opcode: Opcode, result: CommandResult) -> CommandAck {
        CommandAck {
            node: self.config.node,
            opcode,
            result,
        }
    }

    fn send_identity(&self, out: &mut Outbox) {
        let (major, minor, patch) = FIRMWARE_VERSION;
        let c = &self.config;
        out.push(Message::Version(Version {
            node: c.node,
            protocol: PROTOCOL_VERSION,
            major,
            minor,
            patch,
            build: c.build_id,
        }));
        out.push(Message::Identity(Identity {
            node: c.node,
            uid_low: c.uid[0],
            uid_mid: c.uid[1],
        }));
        out.push(Message::BootInfo(BootInfo {
            node: c.node,
            uid_high: c.uid[2],
            reset_cause: c.reset_cause,
            params_source: c.params_source,
            // The history holds far fewer than 255 entries; saturating were it ever more.
            fault_history_len: u8::try_from(self.history.len()).unwrap_or(u8::MAX),
            calibration_source: c.calibration_source,
        }));
        let clock = &c.clock;
        out.push(Message::ClockInfo(ClockInfo {
            node: c.node,
            source: clock.source,
            crystal: clock.crystal,
            // 100 ppm counts, saturated at 2.55 % (the signal's width).
            oscillator_error_centi_pct: u8::try_from(clock.oscillator_ppm / 100).unwrap_or(u8::MAX),
            tolerated_error_ppm: u16::try_from(clock.tolerated_ppm).unwrap_or(u16::MAX),
            // 10 Hz counts within the signal's 24 bits (167 MHz), saturated past them.
            crystal_freq_10hz: (clock.crystal_measured_hz / 10).min(0xFF_FFFF),
        }));
    }

    fn send_history(&self, out: &mut Outbox) {
        for (k, r) in self.history.iter().enumerate() {
            out.push(Message::FaultHistory(FaultHistoryEntry {
                node: self.config.node,
                entry: u8::try_from(k).unwrap_or(u8::MAX),
                code: r.code,
                state_after: r.state_after,
                detail: r.detail,
                // The signal's 24-bit clock: uptime modulo 2²⁴ ms (wraps after 4.66 h, as the
                // DBC says). Wrapping on purpose; the codec refuses anything wider.
                uptime_ms: r.uptime_ms & 0xFF_FFFF,
            }));
        }
    }

    /// Fault changes held back by the inhibit time (see [`crate::fault_report`]).
    pub fn suppressed_fault_events(&self) -> u32 {
        self.reporter.suppressed()
    }

    fn enter(&mut self, state: NodeState, contact_closed: bool) {
        if state == self.state {
            return;
        }
        self.bench.record(
            self.now,
            BenchEvent::State {
                from: self.state,
                to: state,
            },
        );
        self.state = state;
        if state == NodeState::Enabled {
            self.reflex.start(contact_closed);
        } else {
            self.reflex.stop();
            self.stride.stop();
        }
    }

    fn handle_command(
        &mut self,
        out: &mut Outbox,
        now: Instant,
        cmd: &Command,
        inputs: &TickInputs,
    ) {
        let contact_closed = inputs.contact_closed;
        if !cmd.target.addresses(self.config.node) {
            return;
        }
        match cmd.kind {
            CommandKind::EmergencyStop => self.enter(NodeState::EmergencyStop, contact_closed),
            CommandKind::Disable => self.enter(NodeState::Disabled, contact_closed),
            CommandKind::Enable => {
                // From Disabled or Safe only, and only without a safety-relevant fault;
                // emergency stop needs a Disable first.
                let allowed = matches!(self.state, NodeState::Disabled | NodeState::Safe);
                if allowed && !self.faults.any_safety_relevant() {
                    self.enter(NodeState::Enabled, contact_closed);
                }
            }
            CommandKind::SetParam { param, value } => {
                let status = if self.state == NodeState::Enabled {
                    ParamStatus::NotWhileEnabled
                } else {
                    match self.params.set(param, value) {
                        Ok(()) => ParamStatus::Accepted,
                        Err(s) => s,
                    }
                };
                self.bench.record(
                    now,
                    BenchEvent::ParamWrite {
                        param,
                        value: value.0,
                        status,
                    },
                );
                out.push(Message::ParamAck(ParamAck {
                    node: self.config.node,
                    param,
                    status,
                    value: self.params.wire_value(param),
                }));
            }
            CommandKind::GetParam { param } => out.push(Message::ParamAck(ParamAck {
                node: self.config.node,
                param,
                status: ParamStatus::Read,
                value: self.params.wire_value(param),
            })),
            CommandKind::GetIdentity => self.identity_due = true,
            CommandKind::GetFaultHistory => self.history_due = true,
            CommandKind::ClearErrors => {
                self.history.clear();
                out.push(Message::CommandAck(
                    self.ack(Opcode::ClearErrors, CommandResult::Done),
                ));
            }
            CommandKind::SaveParams => {
                let result = if self.state == NodeState::Enabled {
                    Some(CommandResult::NotWhileEnabled)
                } else if self.save_in_progress || self.request.is_some() {
                    Some(CommandResult::NotAvailable)
                } else {
                    self.save_in_progress = true;
                    self.request = Some(NodeRequest::SaveParams);
                    None
                };
                if let Some(r) = result {
                    out.push(Message::CommandAck(self.ack(Opcode::SaveParams, r)));
                }
            }
            CommandKind::CalibrateEncoderZero => {
                let result = match (self.state, inputs.angle) {
                    (NodeState::Enabled, _) => CommandResult::NotWhileEnabled,
                    (_, Ok(s)) if self.request.is_none() => {
                        self.request = Some(NodeRequest::SetEncoderZero {
                            zero_counts: s.counts,
                        });
                        // The estimator restarts on the new zero.
                        self.estimator.reset();
                        self.last_sample_at = None;
                        CommandResult::Done
                    }
                    _ => CommandResult::NotAvailable,
                };
                out.push(Message::CommandAck(
                    self.ack(Opcode::CalibrateEncoderZero, result),
                ));
            }
        }
    }

    /// One control tick: constant work plus at most [`MAX_RX_PER_TICK`] messages. The stages,
    /// in order: the received messages, the sensors, the peer's liveness and the drivers, the
    /// contact edges, the peer's state and the receive overflow (then the safe state on any
    /// safety-relevant fault), the reflex, the reports due, the periodic messages; the
    /// transmissions in priority order.
    pub fn tick(&mut self, now: Instant, inputs: &TickInputs) -> TickOutputs {
        let mut dropped = self.dropped_tx;
        let mut out = Outbox {
            list: Vec::new(),
            dropped: &mut dropped,
        };
        self.now = now;
        let first_tick = self.started_at.is_none();
        let started = *self.started_at.get_or_insert(now);
        let contact = inputs.contact_closed;
        let phase_before = self.reflex.phase();
        let driven_before = self.driven_setpoint;
        self.raised_this_tick = 0;
        if first_tick {
            // The clock chosen at start-up, before any command: a refused power stage is a
            // standing fault (never cleared), so that not even the first tick's `Enable`
            // passes.
            let clock = &self.config.clock;
            let detail = clock
                .refusal
                .map(|_| i16::try_from(clock.tolerated_ppm).unwrap_or(i16::MAX));
            self.set_fault(&mut out, now, FaultCode::ClockTolerance, detail);
        }
        if let Some(a) = self.pending_ack.take() {
            out.push(Message::CommandAck(a));
        }
        let peer_heel_strike = self.read_messages(&mut out, now, inputs);
        self.check_sensors(&mut out, now, inputs, peer_heel_strike);
        self.check_peer_liveness_and_drivers(&mut out, now, started, inputs);
        let edges = self.contact_edges(&mut out, now, contact);
        self.check_peer_state_and_receive(&mut out, now, inputs);
        // Safe state on any safety-relevant fault.
        if self.state == NodeState::Enabled && self.faults.any_safety_relevant() {
            self.enter(NodeState::Safe, contact);
        }
        let actuator = self.run_reflex(&mut out, now, edges, peer_heel_strike);
        if self.reflex.phase() != phase_before || edges.heel_strike || peer_heel_strike {
            self.log_reflex(now, phase_before, driven_before, edges, peer_heel_strike);
        }
        self.send_due_reports(&mut out, now);
        self.send_periodic(&mut out, now);
        // At most one bench-log line per tick, written in a tick that transmits nothing (a
        // tick that raises a fault, answers a command or sends a heel strike is the tick
        // budget's worst case; the line waits a tick or two in the log's queue), or when the
        // queue is full.
        if out.list.is_empty() || self.bench.pending() >= crate::bench_log::QUEUE_LEN {
            let _ = self.bench.flush_one();
        }
        sort_by_priority(&mut out.list);
        let outputs = TickOutputs {
            actuator,
            transmit: out.list,
            state: self.state,
            phase: self.reflex.phase(),
            request: self.request.take(),
        };
        self.dropped_tx = dropped;
        outputs
    }

    /// The bench log of one tick's reflex events (each kind rate-limited): heel strikes (own
    /// and peer) and the phase change, with the string engaged (a setpoint appears) or
    /// released, the estimated angle and the node's uptime.
    fn log_reflex(
        &mut self,
        now: Instant,
        phase_before: ReflexPhase,
        driven_before: Option<f32>,
        edges: ContactEdges,
        peer_heel_strike: bool,
    ) {
        let at_ms = now.uptime_ms();
        if edges.heel_strike {
            let step = self.step_count;
            self.bench.record(
                now,
                BenchEvent::HeelStrike {
                    own: true,
                    step,
                    at_ms,
                },
            );
        }
        if peer_heel_strike {
            let step = self.step_count;
            self.bench.record(
                now,
                BenchEvent::HeelStrike {
                    own: false,
                    step,
                    at_ms,
                },
            );
        }
        let phase = self.reflex.phase();
        if phase != phase_before {
            let string = match (driven_before, self.driven_setpoint) {
                (None, Some(setpoint)) => StringEdge::Engaged(setpoint),
                (Some(last), None) => StringEdge::Released(last),
                _ => StringEdge::Unchanged,
            };
            let angle_rad = self.estimator.angle_rad().unwrap_or(f32::NAN);
            self.bench.record(
                now,
                BenchEvent::Phase {
                    from: phase_before,
                    to: phase,
                    at_ms,
                    angle_rad,
                    string,
                },
            );
        }
    }

    /// Tick stage 1, messages: commands to this node, the peer's heartbeat and heel strike
    /// (at most [`MAX_RX_PER_TICK`]). Whether the peer announced its heel strike.
    fn read_messages(&mut self, out: &mut Outbox, now: Instant, inputs: &TickInputs) -> bool {
        let mut peer_heel_strike = false;
        for m in inputs.received.iter().take(MAX_RX_PER_TICK) {
            match m {
                Message::Command(c) => self.handle_command(out, now, c, inputs),
                Message::Heartbeat(h) if h.node == self.peer => {
                    self.last_peer_heartbeat = Some(now);
                    let before = self.peer_state.map(|(_, st)| st);
                    self.peer_state = Some((now, h.state));
                    // The edge, not the level: a peer still `Safe` from an earlier event
                    // must not stop this node from being enabled first. The edge is a change
                    // into `Safe`/`EmergencyStop` from a state outside them (normally
                    // `Enabled`; `Disabled` when its `Enabled` heartbeat was not seen).
                    let is_down =
                        |st: NodeState| matches!(st, NodeState::Safe | NodeState::EmergencyStop);
                    if before.is_some_and(|b| !is_down(b))
                        && is_down(h.state)
                        && self.state == NodeState::Enabled
                    {
                        self.peer_dropped_out = Some(h.state);
                    } else if h.state == NodeState::Enabled {
                        self.peer_dropped_out = None;
                    }
                }
                Message::HeelStrike(h) if h.node == self.peer => peer_heel_strike = true,
                _ => {}
            }
        }
        peer_heel_strike
    }

    /// Tick stage 2, sensors: plausibility, then the estimator on good samples. The stuck
    /// check counts ticks where the stride says the ankle must move
    /// ([`StrideCheck::ankle_expected_to_move`]: a walking stance, a swing away from its rest
    /// angle, the push, a hold while the spool turns); the stride check also checks the
    /// contact switch and the spool encoder against the reading (`ContactStuck`,
    /// `SpoolStuck`). A still ankle where nothing says it moves is no fault: a healthy
    /// encoder may sit on one code then.
    fn check_sensors(
        &mut self,
        out: &mut Outbox,
        now: Instant,
        inputs: &TickInputs,
        peer_heel_strike: bool,
    ) {
        let stride_inputs = StrideInputs {
            now,
            phase: self.reflex.phase(),
            sample: inputs.angle.ok(),
            contact_closed: inputs.contact_closed,
            string_moving: inputs.drivers.string_moving,
            spool_sensor: inputs.drivers.spool_sensor,
            peer_heel_strike,
        };
        let driving = self.stride.ankle_expected_to_move(&stride_inputs);
        let found: SensorFindings =
            self.plausibility
                .check(now, &inputs.angle, driving, &self.params);
        self.set_fault(out, now, FaultCode::EncoderComms, found.comms);
        self.set_fault(out, now, FaultCode::EncoderRange, found.range);
        self.set_fault(out, now, FaultCode::EncoderRate, found.rate);
        self.set_fault(out, now, FaultCode::EncoderStuck, found.stuck);
        let plausible = found.range.is_none() && found.rate.is_none();
        self.sample = inputs.angle.ok().filter(|_| plausible);
        let stride = self.stride.check(
            &StrideInputs {
                sample: self.sample,
                ..stride_inputs
            },
            self.params.stuck_timeout_s(),
            self.params.taut_angle_rad(),
        );
        self.set_fault(out, now, FaultCode::ContactStuck, stride.contact);
        self.set_fault(out, now, FaultCode::SpoolStuck, stride.spool);
        // Following error against the previous tick's setpoint, on a plausible reading.
        let measured = match inputs.angle {
            Ok(s) if plausible => Some(s.angle_rad),
            _ => None,
        };
        let following = self.following.check(now, self.driven_setpoint, measured);
        self.set_fault(out, now, FaultCode::FollowingError, following);
        match inputs.angle {
            Ok(s) if found.range.is_none() && found.rate.is_none() => {
                let dt = self
                    .last_sample_at
                    .map(|t| now.secs_since(t))
                    .unwrap_or(0.0);
                self.estimator.update(s.angle_rad, dt);
                self.last_sample_at = Some(now);
            }
            _ => {
                self.estimator.reset();
                self.last_sample_at = None;
            }
        }
    }

    /// Tick stage 3: the peer's liveness (counted from start-up, `started`, until the first
    /// heartbeat) and the drivers' health.
    fn check_peer_liveness_and_drivers(
        &mut self,
        out: &mut Outbox,
        now: Instant,
        started: Instant,
        inputs: &TickInputs,
    ) {
        let peer_seen = self.last_peer_heartbeat.unwrap_or(started);
        let silent_s = now.secs_since(peer_seen);
        let lost = silent_s > self.params.peer_heartbeat_timeout_s();
        // Saturating: a peer silent for more than 32.767 s reads as 32767 ms.
        let silent_ms = saturating_i16(silent_s * 1000.0);
        self.set_fault(
            out,
            now,
            FaultCode::PeerHeartbeatLost,
            lost.then_some(silent_ms),
        );
        self.set_fault(
            out,
            now,
            FaultCode::Actuator,
            inputs
                .drivers
                .actuator_error
                .then_some(inputs.drivers.actuator_error_detail),
        );
        self.set_fault(
            out,
            now,
            FaultCode::CanBus,
            if inputs.drivers.can_bus_off {
                Some(2)
            } else if inputs.drivers.can_error {
                Some(1)
            } else {
                None
            },
        );
    }

    /// Tick stage 4, the contact's edges; the own heel strike is announced in every state.
    fn contact_edges(&mut self, out: &mut Outbox, now: Instant, contact: bool) -> ContactEdges {
        let previous_contact = self.contact.replace(contact);
        let edges = ContactEdges {
            heel_strike: previous_contact == Some(false) && contact,
            lift_off: previous_contact == Some(true) && !contact,
        };
        if edges.heel_strike {
            self.step_count = self.step_count.wrapping_add(1);
            out.push(Message::HeelStrike(HeelStrike {
                node: self.config.node,
                step_count: self.step_count,
                time_us: now.uptime_us(),
            }));
        }
        edges
    }

    /// Tick stage 5, the peer's own state: a peer that dropped from `Enabled` to its safe state
    /// or emergency stop while this node walked cannot walk, so neither can this one. Only that
    /// transition counts (not the level), so after a safe event the ankles can be enabled one
    /// at a time. Then the receive overflow: every lost frame counted, reported as
    /// `CanRxOverflow` with the total (not safety-relevant).
    fn check_peer_state_and_receive(
        &mut self,
        out: &mut Outbox,
        now: Instant,
        inputs: &TickInputs,
    ) {
        if self.state != NodeState::Enabled {
            self.peer_dropped_out = None;
        }
        let peer_detail = self.peer_dropped_out.map(|st| st.raw() as i16);
        self.set_fault(out, now, FaultCode::PeerSafe, peer_detail);
        // Saturating: the total never wraps back below the 32767 the detail saturates at.
        self.rx_lost_total = self.rx_lost_total.saturating_add(inputs.drivers.rx_lost);
        let lost_detail = i16::try_from(self.rx_lost_total).unwrap_or(i16::MAX);
        self.set_fault(
            out,
            now,
            FaultCode::CanRxOverflow,
            (inputs.drivers.rx_lost > 0).then_some(lost_detail),
        );
    }

    /// Tick stage 6, the reflex on the estimated angle and the contact edges; a release by the
    /// own lift-off before the peer's heel strike raises `PeerHeelStrikeLate`. The actuator's
    /// command.
    fn run_reflex(
        &mut self,
        out: &mut Outbox,
        now: Instant,
        edges: ContactEdges,
        peer_heel_strike: bool,
    ) -> ActuatorCommand {
        let angle_rad = self.estimator.angle_rad().unwrap_or(0.0);
        let (actuator, event) = self.reflex.step(
            &ReflexInputs {
                now,
                angle_rad,
                heel_strike: edges.heel_strike,
                lift_off: edges.lift_off,
                peer_heel_strike,
            },
            &self.params,
        );
        self.stride.observe(now, self.sample, edges.lift_off, event);
        match event {
            Some(ReflexEvent::Released(ReleaseCause::OwnLiftOff)) => {
                self.set_fault(out, now, FaultCode::PeerHeelStrikeLate, Some(0));
            }
            Some(ReflexEvent::Released(ReleaseCause::PeerHeelStrike)) => {
                self.set_fault(out, now, FaultCode::PeerHeelStrikeLate, None);
            }
            _ => {}
        }
        if self.state != NodeState::Enabled {
            self.set_fault(out, now, FaultCode::PeerHeelStrikeLate, None);
        }
        self.driven_setpoint = match actuator {
            ActuatorCommand::Position { ankle_angle_rad } => Some(ankle_angle_rad),
            ActuatorCommand::Released => None,
        };
        actuator
    }

    /// Tick stage 7, the reports due: fault events held back by their inhibit time, the state
    /// each of this tick's raises left the node in (into the history), the identity and the
    /// history when asked for.
    fn send_due_reports(&mut self, out: &mut Outbox, now: Instant) {
        let faults = self.faults;
        for r in self.reporter.due(now, |c| faults.contains(c)) {
            self.send_fault(out, now, r.code, r.transition, r.detail);
        }
        let state = self.state;
        for r in self.history.iter_mut().take(self.raised_this_tick) {
            r.state_after = state;
        }
        if core::mem::take(&mut self.identity_due) {
            self.send_identity(out);
        }
        if core::mem::take(&mut self.history_due) {
            self.send_history(out);
        }
    }

    /// Tick stage 8, the periodic messages that are due: ankle state, heartbeat, version.
    fn send_periodic(&mut self, out: &mut Outbox, now: Instant) {
        if now >= self.next_state_at {
            let (a, r) = self.estimate().unwrap_or((0.0, 0.0));
            out.push(Message::AnkleState(AnkleState {
                node: self.config.node,
                angle: Angle::saturating_from_si(a),
                rate: AngularRate::saturating_from_si(r),
                actuator_position: Angle::saturating_from_si(self.reflex.last_setpoint_rad()),
                phase: self.reflex.phase(),
            }));
            self.next_state_at = Instant(now.0.saturating_add(self.config.state_period_us));
        }
        if now >= self.next_heartbeat_at {
            out.push(Message::Heartbeat(Heartbeat {
                node: self.config.node,
                state: self.state,
                faults: self.faults,
                uptime_ms: now.uptime_ms(),
            }));
            self.next_heartbeat_at = Instant(now.0.saturating_add(self.config.heartbeat_period_us));
        }
        if now >= self.next_version_at {
            let (major, minor, patch) = FIRMWARE_VERSION;
            out.push(Message::Version(Version {
                node: self.config.node,
                protocol: PROTOCOL_VERSION,
                major,
                minor,
                patch,
                build: self.config.build_id,
            }));
            self.next_version_at = Instant(now.0.saturating_add(self.config.version_period_us));
        }
    }
}
