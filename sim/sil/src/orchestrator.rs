//! [`FirmwareInTheLoop`]: the bus side, the host, both ankles, the gait bookkeeping and the
//! records, ticked in the order the crate documentation gives.

use canbus::{Bus, BusEvent};
use firmware::AnkleNode;
use protocol::{Command, CommandKind, Message, Target};
use sim::engine::control::{ActuatorSegment, AnkleController, AnkleSensing, ControlError};

use crate::ankle::{Ankle, BusAccess};
use crate::bus_side::BusSide;
use crate::config::SilConfig;
use crate::error::{SilError, TickError};
use crate::gait::Gait;
use crate::host::Host;
use crate::records::Records;
use crate::report::{HistoryElided, SilReport};
use crate::side::Side;
use crate::tick::{TickClock, TickTime};

/// The firmware of both ankle nodes, on a simulated CAN bus, as the stance ankle's
/// [`AnkleController`].
pub struct FirmwareInTheLoop {
    config: SilConfig,
    clock: TickClock,
    bus: BusSide,
    host: Host,
    /// Left, right.
    ankles: [Ankle; 2],
    gait: Gait,
    records: Records,
}

impl FirmwareInTheLoop {
    /// Build the bus, the host and both nodes (disabled until the host's `Enable` at the first
    /// tick), open the candump log and start the socketcand server if asked.
    ///
    /// # Errors
    /// [`SilError`]: a bad period, bus configuration or fault (an unknown node, say), a node
    /// the firmware refuses, a log that cannot be created, a server that cannot bind.
    pub fn new(config: SilConfig) -> Result<Self, SilError> {
        let clock = TickClock::new(config.period_s)?;
        let mut bus = BusSide::new(&config.bus, config.history_capacity)?;
        let left = Ankle::new(Side::Left, bus.attach_ankle(Side::Left), &config)?;
        let right = Ankle::new(Side::Right, bus.attach_ankle(Side::Right), &config)?;
        bus.add_faults(&config.bus_faults)?;
        bus.open_outputs(
            config.candump.as_deref(),
            config.socketcand.as_deref(),
            config.socketcand_allow_send,
        )?;
        Ok(FirmwareInTheLoop {
            clock,
            host: Host::new(&config),
            ankles: [left, right],
            gait: Gait::new(&config),
            records: Records::new(config.history_capacity),
            bus,
            config,
        })
    }

    /// Schedule a host command at `t_s` (sent at the first tick at or after it; commands at
    /// equal times keep their order).
    pub fn host_command_at(&mut self, t_s: f64, command: Command) {
        self.host.schedule_at(t_s, command);
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
        self.gait.stance()
    }

    /// One node's firmware (read-only).
    pub fn node(&self, side: Side) -> &AnkleNode {
        self.ankles[side.index()].node()
    }

    /// The configuration.
    pub fn config(&self) -> &SilConfig {
        &self.config
    }

    /// The bus (read-only: statistics, node error states).
    pub fn bus(&self) -> &Bus {
        self.bus.bus()
    }

    /// The live socketcand server's address, if one runs.
    pub fn socketcand_addr(&self) -> Option<std::net::SocketAddr> {
        self.bus.socketcand_addr()
    }

    /// Wait until a socketcand client is in rawmode (and past its grace time), at most
    /// `timeout`: whether one is; `None` when no server runs. For `walker sil --wait-client`,
    /// before the walk starts.
    pub fn wait_for_socketcand_client(&self, timeout: std::time::Duration) -> Option<bool> {
        self.bus.wait_for_socketcand_client(timeout)
    }

    /// What `side`'s power stage did in the last tick, with the motor plant
    /// ([`crate::ActuatorChoice::SpoolMotor`]); `None` with the servo.
    pub fn stage_output(&self, side: Side) -> Option<firmware::drivers::spool_motor::StageOutput> {
        self.ankles[side.index()].stage_output()
    }

    /// `side`'s spool encoder count now, with the motor plant.
    pub fn spool_counts(&self, side: Side) -> Option<i32> {
        self.ankles[side.index()].spool_counts()
    }

    /// Keep the first `max_frames` bus events from now on in memory (delivered frames, error
    /// frames, bus-off events: what `SilConfig::candump`'s log records);
    /// [`FirmwareInTheLoop::take_frame_log`] hands them over. Call it before the walk.
    pub fn keep_frames(&mut self, max_frames: usize) {
        self.bus.keep_frames(max_frames);
    }

    /// The bus events kept ([`FirmwareInTheLoop::keep_frames`]), taken out: `None` if none
    /// were asked for (or they were taken already).
    pub fn take_frame_log(&mut self) -> Option<crate::frames::FrameLog> {
        self.bus.take_frame_log()
    }

    /// The report so far.
    pub fn report(&self) -> SilReport {
        let nodes = Side::BOTH
            .iter()
            .map(|&side| {
                let mut r = self.records.node_report(side);
                self.ankles[side.index()].fill_report(&mut r);
                r.parameters = self.host.parameters(side);
                (side, r)
            })
            .collect();
        let (commands_sent, param_acks) = self.host.elided();
        SilReport {
            ticks: self.clock.ticks(),
            heel_strikes: self.gait.heel_strikes(),
            stance: self.gait.stance(),
            t_end_s: self.clock.last_t_s(),
            nodes,
            state_history: self.records.state_history().to_vec(),
            phase_history: self.records.phase_history().to_vec(),
            faults: self.records.faults().to_vec(),
            landings: self.gait.landings().to_vec(),
            frames_delivered: self.bus.frames_delivered(),
            bus_off: self.bus.bus_off().to_vec(),
            history_elided: HistoryElided {
                state_history: self.records.state_history().elided(),
                phase_history: self.records.phase_history().elided(),
                faults: self.records.faults().elided(),
                landings: self.gait.landings().elided(),
                bus_off: self.bus.bus_off().elided(),
                commands_sent,
                param_acks,
            },
            bus: self.bus.bus().stats(),
            host: self.host.report(),
            socketcand: self.bus.socketcand_report(),
            sensor_faults_applied: self
                .ankles
                .iter()
                .flat_map(|a| a.sensor_faults_applied().cloned())
                .collect(),
        }
    }

    /// Flush the candump log, stop the server and return the report.
    ///
    /// # Errors
    /// [`SilError::Candump`] when the log cannot be flushed.
    pub fn finish(mut self) -> Result<SilReport, SilError> {
        let report = self.report();
        self.bus.close()?;
        Ok(report)
    }

    /// Step 1: the bus up to the tick; each delivered frame to the host (unless it sent it)
    /// and into the receive FIFO of every ankle but its sender and a bus-off one.
    fn run_bus(&mut self, t: TickTime) -> Result<(), TickError> {
        // A bus-off controller takes no part in the bus: it receives nothing from then on.
        let mut off = self
            .ankles
            .each_ref()
            .map(|a| self.bus.is_bus_off(a.handle()));
        for ev in self.bus.advance_to(t.t_ns)? {
            match ev {
                BusEvent::Delivered(d) => {
                    if d.from != self.bus.host() {
                        let decoded = Message::decode(d.frame.id(), d.frame.data());
                        self.host.observe(d.t_end_ns, &decoded);
                    }
                    for (a, off) in self.ankles.iter_mut().zip(off) {
                        if a.handle() != d.from && !off {
                            a.deliver(d.frame);
                        }
                    }
                }
                BusEvent::BusOff { node, .. } => {
                    for (a, off) in self.ankles.iter().zip(off.iter_mut()) {
                        *off |= a.handle() == node;
                    }
                }
                // Every controller on the bus sees the error frame and reports it through its
                // receive path (one error each), a receiver's REC counts it.
                BusEvent::ErrorFrame { from, .. } => {
                    for (a, off) in self.ankles.iter_mut().zip(off) {
                        if !off {
                            let as_receiver = a.handle() != from;
                            a.error_frame(as_receiver);
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// Step 3 for one ankle: what its hardware sees, one driver step, the records, its
    /// transmissions; the segment its actuator moved the string through.
    fn run_ankle(
        &mut self,
        side: Side,
        t: TickTime,
        sensing: &AnkleSensing,
    ) -> Result<ActuatorSegment, TickError> {
        let scene = self.gait.scene(side, sensing);
        let ankle = &mut self.ankles[side.index()];
        let access = BusAccess {
            tx_room: self.bus.tx_room(ankle.handle()),
            bus_off: self.bus.is_bus_off(ankle.handle()),
            error_state: self.bus.error_state(ankle.handle()),
        };
        let step = ankle.step(t, &scene, access);
        self.records.observe(t.t_s, side, scene.stance, &step);
        let tally = ankle.transmit(&mut self.bus, t.t_ns)?;
        self.records.count_transmit(side, tally);
        ankle.take_segment()
    }
}

impl AnkleController for FirmwareInTheLoop {
    fn period_s(&self) -> f64 {
        self.clock.period_s()
    }

    fn tick(&mut self, sensing: &AnkleSensing) -> Result<ActuatorSegment, ControlError> {
        self.run_tick(sensing).map_err(ControlError::from)
    }

    fn heel_strike(&mut self, t_s: f64) {
        self.gait.heel_strike(t_s);
    }
}

impl FirmwareInTheLoop {
    /// One control tick: the bus, the host, each ankle; the stance ankle's segment.
    fn run_tick(&mut self, sensing: &AnkleSensing) -> Result<ActuatorSegment, TickError> {
        let t = self.clock.start(sensing.t_walk_s)?;
        self.gait.start_tick(t.t_s, sensing);
        self.run_bus(t)?;
        self.host.send_due(t, &mut self.bus)?;
        let mut stance_segment = None;
        for side in Side::BOTH {
            let segment = self.run_ankle(side, t, sensing)?;
            if side == self.gait.stance() {
                stance_segment = Some(segment);
            }
        }
        self.clock.finish();
        stance_segment.ok_or(TickError::NoStanceAnkle)
    }
}
