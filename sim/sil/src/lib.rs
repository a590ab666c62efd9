//! Firmware in the loop: the ankle nodes' firmware, on a simulated CAN bus, controlling the
//! simulated walker's stance ankle (see `sim::control` and `docs/sil.md`).
//!
//! Two [`firmware::AnkleNode`]s (left, node 2, and right, node 3) and a host (node 1) sit on a
//! [`canbus::Bus`]. Every control tick:
//!
//! 1. the bus runs up to the tick time; each delivered frame is decoded and queued for every
//!    node but its sender (at most 8 are read per tick, as on the board; the rest wait), the
//!    host sees everything; the candump log and the socketcand server get every event;
//! 2. the host sends its due commands (`Enable` to every ankle at the first tick, the
//!    scheduled ones, frames from socketcand clients);
//! 3. each node runs one [`firmware::runner::AnkleDrivers::step`], as on the board, over
//!    sim-backed hardware ([`hal`]): the orchestrator sets the shaft angle (the encoder's SPI
//!    device quantises it, [`sensors`]), the raw contact switch, the clock and the room in the
//!    bus node's transmit queue, steps the drivers, queues the frames the node's CAN
//!    controller accepted on the bus at the tick time, and takes the segment its actuator
//!    ([`actuator`] behind [`hal::SimActuator`]) moved the string through; the stance ankle's
//!    segment is the tick's [`ActuatorSegment`].
//!
//! The board's `PwmDirActuator` (a P loop over PWM duty and a direction pin) is replaced by the
//! servo model: see [`hal`] for why.
//!
//! The walker model always has its stance leg on the right of its mirrored frame; physically
//! the stance alternates, starting with [`SilConfig::first_stance`], and
//! [`AnkleController::heel_strike`] swaps it.

pub mod actuator;
pub mod config;
pub mod hal;
pub mod history;
pub mod report;
pub mod sensors;

#[cfg(test)]
mod tests;

use std::cell::RefCell;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::rc::Rc;

use canbus::candump::CandumpWriter;
use canbus::socketcand::{ServerConfig, SocketcandServer};
use canbus::{Bus, BusError, BusEvent, ErrorState, Frame, NodeHandle, SendOutcome};
use firmware::drivers::can::CanPort;
use firmware::drivers::contact::{ActiveLevel, ContactSwitch};
use firmware::drivers::encoder::MagneticEncoder;
use firmware::runner::AnkleDrivers;
use firmware::{AnkleNode, Instant, NodeConfig};
use protocol::{
    Command, CommandKind, FaultCode, FaultTransition, Message, NodeId, NodeState, ReflexPhase,
    Target,
};

use sim::control::{ActuatorSegment, AnkleController, AnkleSensing, ControlError};

pub use actuator::{ActuatorModel, ActuatorParams, ActuatorStats};
pub use config::{HostCommand, Side, SilConfig, SwingAnkleModel};
pub use history::BoundedLog;
pub use report::{
    FaultRecord, HistoryElided, HostReport, Landing, NodeReport, PhaseChange, SilReport,
    SocketcandReport, StateChange,
};
pub use sensors::{SensorFault, SensorFaultParseError, SimEncoder, SwingAnkle};

use hal::{ActuatorLink, CanLink, Shaft, SimActuator, SimCan, SimClock, SimContactPin, SimSpi};

/// The integrator of a firmware-in-the-loop walk: DOPRI5 at rtol = atol = 1e-6.
///
/// The control ticks cut every integration step to at most one tick (1 ms), so the tolerance
/// rarely shortens a step further. Over 12 steps of `wisse3d` with the firmware in the loop,
/// against DOPRI5 at 1e-12 (relative differences of the 12-step means): step period, speed
/// and step length agree to 5e-8, the impact loss per step to 2e-7, but the actuator work per
/// step and the cost of transport only to 9e-6 (test `hil-tests/tests/sil_integrator.rs`,
/// bounds 3 × these; docs/sil.md). It costs 6.4 right-hand-side evaluations per tick against
/// 9.6 at 1e-9 and 21.4 at 1e-12. Classical RK4 at one step per tick is cheaper
/// (4 evaluations) but its step period is 0.1 % off and its impact loss 0.7 %.
pub const SIL_INTEGRATOR: sim::integrators::IntegratorChoice =
    sim::integrators::IntegratorChoice::Dopri5 {
        rtol: 1e-6,
        atol: 1e-6,
        h_max_s: 0.01,
    };

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
        /// The offending period [s].
        period_s: f64,
    },
    /// The candump log could not be written.
    #[error("candump log: {0}")]
    Candump(#[from] std::io::Error),
    /// The socketcand server could not start.
    #[error("{0}")]
    Socketcand(#[from] canbus::socketcand::ServerError),
}

/// The board's drivers over the simulator's hardware.
type SimDrivers = AnkleDrivers<SimSpi, SimContactPin, SimActuator, SimCan, SimClock>;

/// One ankle: its firmware behind its drivers, the orchestrator's ends of the hardware, and
/// counters.
struct Ankle {
    side: Side,
    handle: NodeHandle,
    drivers: SimDrivers,
    shaft: Shaft,
    contact: SimContactPin,
    clock: SimClock,
    can: Rc<RefCell<CanLink>>,
    actuator: Rc<RefCell<ActuatorLink>>,
    swing: Option<SwingAnkle>,
    /// The contact switch has been sampled for the debounce length before the first tick.
    settled: bool,
    last_state: NodeState,
    last_phase: ReflexPhase,
    report: NodeReport,
}

/// The firmware of both ankle nodes, on a simulated CAN bus, as the stance ankle's
/// [`AnkleController`].
pub struct FirmwareInTheLoop {
    config: SilConfig,
    period_us: u64,
    bus: Bus,
    host: NodeHandle,
    ankles: [Ankle; 2],
    stance: Side,
    last_t_ns: Option<u64>,
    last_t_s: f64,
    last_heel_strike_s: Option<f64>,
    /// The stance angle at which each side's foot last landed [rad].
    landing_rad: [Option<f64>; 2],
    landing_pending: bool,
    landings: BoundedLog<Landing>,
    schedule: Vec<HostCommand>,
    next_command: usize,
    enabled_sent: bool,
    candump: Option<CandumpWriter<BufWriter<File>>>,
    server: Option<SocketcandServer>,
    ticks: u64,
    heel_strikes: u64,
    frames_delivered: u64,
    bus_off: BoundedLog<(f64, String)>,
    state_history: BoundedLog<StateChange>,
    phase_history: BoundedLog<PhaseChange>,
    faults: BoundedLog<FaultRecord>,
    commands_sent: BoundedLog<(f64, String)>,
    param_acks: BoundedLog<String>,
    host_report: HostReport,
}

fn ctl(e: impl std::fmt::Display) -> ControlError {
    ControlError(format!("firmware in the loop: {e}"))
}

fn names(flags: protocol::FaultFlags) -> Vec<String> {
    FaultCode::ALL
        .iter()
        .filter(|c| flags.contains(**c))
        .map(|c| format!("{c:?}"))
        .collect()
}

impl FirmwareInTheLoop {
    /// Build the bus, the host and both nodes (disabled until the host's `Enable` at the first
    /// tick), open the candump log and start the socketcand server if asked.
    ///
    /// # Errors
    /// [`SilError`]: a bad period, bus configuration or fault (an unknown node, say), a node
    /// the firmware refuses, a log that cannot be created, a server that cannot bind.
    pub fn new(config: SilConfig) -> Result<Self, SilError> {
        let period_us_f = config.period_s * 1e6;
        if !(period_us_f.is_finite() && period_us_f >= 1.0 && period_us_f.fract() == 0.0) {
            return Err(SilError::Period {
                period_s: config.period_s,
            });
        }
        let mut bus = Bus::new(config.bus.clone())?;
        let host = bus.attach("host", Some(NodeId::Host.raw()));
        let mut make = |side: Side| -> Result<Ankle, SilError> {
            let node =
                AnkleNode::new(NodeConfig::nominal(side.node())).map_err(|e| SilError::Node {
                    node: side.node(),
                    reason: format!("{e:?}"),
                })?;
            let handle = bus.attach(side.bus_name(), Some(side.node().raw()));
            let faults = config
                .sensor_faults
                .iter()
                .filter(|f| f.side() == side)
                .copied()
                .collect();
            let calibration = config.calibration[side.index()];
            let shaft = Shaft::new();
            let spi = SimSpi::new(SimEncoder::new(calibration, faults), shaft.clone());
            let contact = SimContactPin::new();
            let clock = SimClock::new();
            let can = Rc::new(RefCell::new(CanLink::new(config.rx_queue_frames)));
            let actuator = Rc::new(RefCell::new(ActuatorLink::new(ActuatorModel::new(
                config.actuator,
            ))));
            let drivers = AnkleDrivers::new(
                node,
                MagneticEncoder::new(spi, calibration),
                ContactSwitch::new(contact.clone(), ActiveLevel::Low, config.debounce_samples),
                SimActuator::new(Rc::clone(&actuator)),
                CanPort::new(SimCan::new(Rc::clone(&can))),
                clock.clone(),
            );
            Ok(Ankle {
                side,
                handle,
                drivers,
                shaft,
                contact,
                clock,
                can,
                actuator,
                swing: None,
                settled: false,
                last_state: NodeState::Disabled,
                last_phase: ReflexPhase::Inactive,
                report: NodeReport::default(),
            })
        };
        let ankles = [make(Side::Left)?, make(Side::Right)?];
        for f in &config.bus_faults {
            bus.add_fault(f.clone())?;
        }
        let mut schedule = config.host_commands.clone();
        schedule.sort_by(|a, b| a.at_s.total_cmp(&b.at_s));
        let candump = match &config.candump {
            Some(path) => Some(CandumpWriter::new(
                BufWriter::new(File::create(path)?),
                "vcan0",
                0,
            )),
            None => None,
        };
        let server = match &config.socketcand {
            Some(addr) => Some(SocketcandServer::bind(
                addr.as_str(),
                ServerConfig::default(),
            )?),
            None => None,
        };
        let cap = config.history_capacity;
        Ok(FirmwareInTheLoop {
            period_us: period_us_f as u64,
            stance: config.first_stance,
            config,
            bus,
            host,
            ankles,
            last_t_ns: None,
            last_t_s: 0.0,
            last_heel_strike_s: None,
            landing_rad: [None, None],
            landing_pending: true,
            landings: BoundedLog::new(cap),
            schedule,
            next_command: 0,
            enabled_sent: false,
            candump,
            server,
            ticks: 0,
            heel_strikes: 0,
            frames_delivered: 0,
            bus_off: BoundedLog::new(cap),
            state_history: BoundedLog::new(cap),
            phase_history: BoundedLog::new(cap),
            faults: BoundedLog::new(cap),
            commands_sent: BoundedLog::new(cap),
            param_acks: BoundedLog::new(cap),
            host_report: HostReport::default(),
        })
    }

    /// Schedule a host command at `t_s` (sent at the first tick at or after it; commands at
    /// equal times keep their order).
    pub fn host_command_at(&mut self, t_s: f64, command: Command) {
        let at = self
            .schedule
            .iter()
            .enumerate()
            .skip(self.next_command)
            .find(|(_, c)| c.at_s > t_s)
            .map_or(self.schedule.len(), |(i, _)| i);
        self.schedule.insert(at, HostCommand { at_s: t_s, command });
    }

    /// Schedule an emergency stop to every ankle at `t_s`.
    pub fn emergency_stop_at(&mut self, t_s: f64) {
        self.host_command_at(
            t_s,
            Command {
                target: Target::Broadcast,
                kind: CommandKind::EmergencyStop,
            },
        );
    }

    /// The side whose foot is the stance foot.
    pub fn stance_side(&self) -> Side {
        self.stance
    }

    /// One node's firmware (read-only).
    pub fn node(&self, side: Side) -> &AnkleNode {
        &self.ankle(side).drivers.node
    }

    /// The configuration.
    pub fn config(&self) -> &SilConfig {
        &self.config
    }

    /// The bus (read-only: statistics, node error states).
    pub fn bus(&self) -> &Bus {
        &self.bus
    }

    /// The live socketcand server's address, if one runs.
    pub fn socketcand_addr(&self) -> Option<std::net::SocketAddr> {
        self.server.as_ref().map(SocketcandServer::local_addr)
    }

    fn ankle(&self, side: Side) -> &Ankle {
        let [l, r] = &self.ankles;
        match side {
            Side::Left => l,
            Side::Right => r,
        }
    }

    /// The report so far.
    pub fn report(&self) -> SilReport {
        let nodes = self
            .ankles
            .iter()
            .map(|a| {
                let mut r = a.report.clone();
                let node = &a.drivers.node;
                r.state = format!("{:?}", node.state());
                r.phase = format!("{:?}", node.phase());
                r.active_faults = names(node.faults());
                r.firmware_dropped_tx = node.dropped_tx();
                let port = a.drivers.can.stats();
                r.messages_read = u64::from(port.received);
                r.frames_malformed = u64::from(port.malformed);
                r.port_dropped = u64::from(port.dropped);
                r.port_bus_errors = u64::from(port.bus_errors);
                let link = a.can.borrow();
                r.frames_refused_queue_full = link.refused_queue_full();
                r.frames_refused_bus_off = link.refused_bus_off();
                r.rx_overflows = link.rx_overflows();
                r.actuator = *a.actuator.borrow().model().stats();
                (a.side, r)
            })
            .collect();
        SilReport {
            ticks: self.ticks,
            heel_strikes: self.heel_strikes,
            stance: self.stance,
            t_end_s: self.last_t_s,
            nodes,
            state_history: self.state_history.to_vec(),
            phase_history: self.phase_history.to_vec(),
            faults: self.faults.to_vec(),
            landings: self.landings.to_vec(),
            frames_delivered: self.frames_delivered,
            bus_off: self.bus_off.to_vec(),
            history_elided: HistoryElided {
                state_history: self.state_history.elided(),
                phase_history: self.phase_history.elided(),
                faults: self.faults.elided(),
                landings: self.landings.elided(),
                bus_off: self.bus_off.elided(),
                commands_sent: self.commands_sent.elided(),
                param_acks: self.param_acks.elided(),
            },
            bus: self.bus.stats(),
            host: HostReport {
                commands_sent: self.commands_sent.to_vec(),
                param_acks: self.param_acks.to_vec(),
                ..self.host_report.clone()
            },
            socketcand: self.server.as_ref().map(|s| {
                let st = s.stats();
                SocketcandReport {
                    clients_accepted: st.clients_accepted,
                    frames_sent: st.frames_sent,
                    frames_dropped: st.frames_dropped,
                    frames_received: st.frames_received,
                }
            }),
        }
    }

    /// Flush the candump log, stop the server and return the report.
    ///
    /// # Errors
    /// [`SilError::Candump`] when the log cannot be flushed.
    pub fn finish(mut self) -> Result<SilReport, SilError> {
        let report = self.report();
        if let Some(w) = self.candump.take() {
            w.finish()?.flush()?;
        }
        if let Some(mut s) = self.server.take() {
            s.shutdown();
        }
        Ok(report)
    }

    fn host_send(&mut self, t_ns: u64, t_s: f64, m: &Message) -> Result<(), ControlError> {
        let raw = m.encode().map_err(|e| ctl(format!("{e:?}")))?;
        match self.bus.send(self.host, Frame::from(raw), t_ns) {
            Ok(_) | Err(BusError::QueueFull { .. }) => {}
            Err(e) => return Err(ctl(e)),
        }
        self.commands_sent.push((t_s, format!("{m:?}")));
        Ok(())
    }

    /// Step 1: the bus up to `t_ns`, deliveries to the inboxes and the host.
    fn run_bus(&mut self, t_ns: u64) -> Result<(), ControlError> {
        // A bus-off controller takes no part in the bus: it receives nothing from then on.
        let mut off = self.ankles.each_ref().map(|a| {
            matches!(
                self.bus.node_error_state(a.handle),
                Some((ErrorState::BusOff, _))
            )
        });
        let events = self.bus.advance_to(t_ns).map_err(ctl)?;
        for ev in &events {
            if let Some(w) = self.candump.as_mut() {
                w.write_event(ev).map_err(ctl)?;
            }
            match ev {
                BusEvent::Delivered(d) => {
                    self.frames_delivered += 1;
                    if let Some(s) = &self.server {
                        s.publish(&d.frame, d.t_end_ns);
                    }
                    if d.from != self.host {
                        let decoded = Message::decode(d.frame.id(), d.frame.data());
                        self.host_observe(d.t_end_ns, &decoded);
                    }
                    for (a, off) in self.ankles.iter_mut().zip(off) {
                        if a.handle != d.from && !off {
                            a.can.borrow_mut().deliver(d.frame);
                        }
                    }
                }
                BusEvent::BusOff { node, t_ns } => {
                    for (a, off) in self.ankles.iter().zip(off.iter_mut()) {
                        *off |= a.handle == *node;
                    }
                    let name = self.bus.node_name(*node).unwrap_or("?").to_string();
                    self.bus_off.push((*t_ns as f64 * 1e-9, name));
                }
                BusEvent::ErrorFrame { .. } => {}
            }
        }
        Ok(())
    }

    fn host_observe(&mut self, t_ns: u64, m: &Result<Message, protocol::DecodeError>) {
        let h = &mut self.host_report;
        let acks = &mut self.param_acks;
        h.frames_seen += 1;
        let Ok(m) = m else {
            h.undecodable_frames += 1;
            return;
        };
        *h.per_class.entry(format!("{:?}", m.class())).or_default() += 1;
        match m {
            Message::Heartbeat(hb) => {
                h.last_heartbeat.insert(
                    format!("{:?}", hb.node),
                    (
                        t_ns as f64 * 1e-9,
                        format!("{:?}", hb.state),
                        names(hb.faults),
                    ),
                );
            }
            Message::Fault(_) => h.fault_events_seen += 1,
            Message::ParamAck(a) => acks.push(format!(
                "{:.3} s {:?} {:?} {:?} {}",
                t_ns as f64 * 1e-9,
                a.node,
                a.param,
                a.status,
                a.value.to_si()
            )),
            _ => {}
        }
    }

    /// Step 2: the host's commands due at `t_s`.
    fn run_host(&mut self, t_ns: u64, t_s: f64) -> Result<(), ControlError> {
        if !self.enabled_sent {
            self.enabled_sent = true;
            for c in self.config.setup_commands.clone() {
                self.host_send(t_ns, t_s, &Message::Command(c))?;
            }
            let enable = Message::Command(Command {
                target: Target::Broadcast,
                kind: CommandKind::Enable,
            });
            self.host_send(t_ns, t_s, &enable)?;
        }
        while let Some(c) = self.schedule.get(self.next_command).copied() {
            if c.at_s > t_s {
                break;
            }
            self.next_command += 1;
            self.host_send(t_ns, t_s, &Message::Command(c.command))?;
        }
        let inbound = self
            .server
            .as_ref()
            .map(SocketcandServer::take_inbound)
            .unwrap_or_default();
        for f in inbound {
            self.host_report.frames_from_clients += 1;
            match self.bus.send(self.host, f, t_ns) {
                Ok(_) | Err(BusError::QueueFull { .. }) => {}
                Err(e) => return Err(ctl(e)),
            }
        }
        Ok(())
    }

    /// Step 3 for one ankle: the hardware's state, one driver step, transmissions, the
    /// actuator's segment.
    fn run_ankle(
        &mut self,
        side: Side,
        t_ns: u64,
        sensing: &AnkleSensing,
    ) -> Result<ActuatorSegment, ControlError> {
        let t_s = sensing.t_walk_s;
        let stance = side == self.stance;
        let landing = self.landing_rad[side.index()]
            .or(self.landing_rad[side.other().index()])
            .unwrap_or(sensing.stance_ankle_rad);
        let trailing = !stance
            && self
                .last_heel_strike_s
                .is_some_and(|h| t_s - h < self.config.trailing_contact_s);
        let swing_model = self.config.swing_ankle;
        let debounce = self.config.debounce_samples;
        let t1_s = t_s + self.period_us as f64 * 1e-6;
        let handle = self.ankle(side).handle;
        let bus_off = matches!(
            self.bus.node_error_state(handle),
            Some((ErrorState::BusOff, _))
        );
        let room = self
            .config
            .bus
            .tx_queue_capacity
            .saturating_sub(self.bus.queued_frames(handle).unwrap_or(0));
        let [l, r] = &mut self.ankles;
        let a = match side {
            Side::Left => l,
            Side::Right => r,
        };
        // The hardware's state at this tick.
        let angle_true = if stance {
            a.swing = Some(SwingAnkle::new(swing_model, t_s, sensing.stance_ankle_rad));
            sensing.stance_ankle_rad
        } else {
            a.swing
                .get_or_insert_with(|| SwingAnkle::new(swing_model, t_s, landing))
                .angle_at(t_s, landing)
        };
        let raw_contact = if stance {
            sensing.stance_foot_on_floor
        } else {
            sensing.swing_foot_on_floor || trailing
        };
        a.shaft.set(t_s, angle_true);
        a.contact.set_closed(raw_contact);
        a.clock.set(Instant::from_micros(t_ns / 1000));
        {
            let mut can = a.can.borrow_mut();
            can.set_tx_room(room);
            can.set_bus_off(bus_off);
        }
        // The string's torque acts on the stance ankle's servo only (the swing foot is
        // massless: its string carries nothing).
        let load_n_m = if stance {
            sensing.string_torque_n_m
        } else {
            0.0
        };
        a.actuator
            .borrow_mut()
            .set_tick(t_s, t1_s, angle_true, load_n_m);
        if !a.settled {
            // Power-up: the switch is sampled for the debounce length before the first tick,
            // so that the firmware's debounced state (which starts open) is the foot's.
            a.settled = true;
            for _ in 0..debounce {
                let _ = a.drivers.contact.sample();
            }
        }
        // The firmware, as on the board.
        let out = a.drivers.step();
        // Records.
        let peer = side.other().node();
        let peer_heel_strike = a.can.borrow_mut().take_read().any(|f| {
            matches!(
                Message::decode(f.id(), f.data()),
                Ok(Message::HeelStrike(h)) if h.node == peer
            )
        });
        a.report.max_rx_backlog = a.report.max_rx_backlog.max(a.can.borrow().rx_backlog());
        if out.state != a.last_state {
            self.state_history.push(StateChange {
                t_s,
                side,
                state: format!("{:?}", out.state),
            });
            a.last_state = out.state;
        }
        if out.phase != a.last_phase {
            let was_loaded = matches!(
                a.last_phase,
                ReflexPhase::Free | ReflexPhase::Push | ReflexPhase::Hold
            );
            if was_loaded && out.phase == ReflexPhase::Swing {
                if peer_heel_strike {
                    a.report.releases_by_peer_heel_strike += 1;
                } else {
                    a.report.releases_by_lift_off += 1;
                }
            }
            if a.last_phase == ReflexPhase::Free && out.phase == ReflexPhase::Push {
                a.report.engagements += 1;
            }
            self.phase_history.push(PhaseChange {
                t_s,
                side,
                phase: format!("{:?}", out.phase),
                stance,
            });
            a.last_phase = out.phase;
        }
        for m in out.transmit.iter() {
            match m {
                Message::Fault(f) => {
                    let raised = f.transition == FaultTransition::Raised;
                    if raised {
                        *a.report
                            .fault_raises
                            .entry(format!("{:?}", f.code))
                            .or_default() += 1;
                    }
                    self.faults.push(FaultRecord {
                        t_s,
                        side,
                        code: format!("{:?}", f.code),
                        raised,
                        detail: f.detail,
                    });
                }
                Message::HeelStrike(_) => a.report.heel_strikes_sent += 1,
                _ => {}
            }
        }
        // Transmissions: what the controller accepted, on the bus at the tick time.
        for frame in a.can.borrow_mut().take_tx() {
            match self.bus.send(a.handle, frame, t_ns) {
                Ok(SendOutcome::Queued) => a.report.frames_queued += 1,
                Ok(SendOutcome::Dropped) => a.report.frames_dropped += 1,
                // Not offered: the controller refuses while bus-off, and it took no more than
                // the queue's room.
                Ok(SendOutcome::BusOff) | Err(BusError::QueueFull { .. }) => {
                    a.report.frames_lost_at_bus += 1;
                }
                Err(e) => return Err(ctl(e)),
            }
        }
        // The actuator's segment over this tick.
        a.actuator
            .borrow_mut()
            .take_segment()
            .ok_or_else(|| ctl("the firmware applied no actuator command"))
    }
}

impl AnkleController for FirmwareInTheLoop {
    fn period_s(&self) -> f64 {
        self.period_us as f64 * 1e-6
    }

    fn tick(&mut self, sensing: &AnkleSensing) -> Result<ActuatorSegment, ControlError> {
        let t_s = sensing.t_walk_s;
        if !(t_s.is_finite() && t_s >= 0.0) {
            return Err(ctl(format!("tick at t = {t_s} s")));
        }
        let t_ns = (t_s * 1e9).round() as u64;
        if let Some(prev) = self.last_t_ns {
            if t_ns < prev {
                return Err(ctl(format!(
                    "tick at {t_s} s is before the previous tick at {} s",
                    prev as f64 * 1e-9
                )));
            }
        }
        self.last_t_ns = Some(t_ns);
        self.last_t_s = t_s;
        if self.landing_pending {
            self.landing_pending = false;
            self.landing_rad[self.stance.index()] = Some(sensing.stance_ankle_rad);
            self.landings.push(Landing {
                t_s,
                side: self.stance,
                angle_rad: sensing.stance_ankle_rad,
            });
        }
        self.run_bus(t_ns)?;
        self.run_host(t_ns, t_s)?;
        let mut stance_segment = None;
        for side in Side::BOTH {
            let seg = self.run_ankle(side, t_ns, sensing)?;
            if side == self.stance {
                stance_segment = Some(seg);
            }
        }
        self.ticks += 1;
        stance_segment.ok_or_else(|| ctl("no stance ankle"))
    }

    fn heel_strike(&mut self, t_s: f64) {
        self.stance = self.stance.other();
        self.last_heel_strike_s = Some(t_s);
        // The landing angle is the new stance angle at the next tick.
        self.landing_pending = true;
        self.heel_strikes += 1;
    }
}
