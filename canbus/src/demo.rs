//! A demonstration bus: a host and two fake ankle nodes sending the protocol's messages at
//! their nominal rates (AnkleState 200 Hz per ankle, Heartbeat 20 Hz per node, HeelStrike
//! 2 Hz per ankle, Version every 5 s per node), encoded by the protocol crate. The ankles
//! start `Enabled` and follow the host's commands they receive over the bus (Enable,
//! Disable, EmergencyStop), so a client of the socketcand server can drive them.
//!
//! The fake ankle angle is a 1 Hz sinusoid of 0.2 rad (right ankle half a period behind);
//! the reflex phase follows it (Swing, Free, Push, Hold). No physics: the simulator will put
//! the real firmware on the same bus.

use protocol::{
    Angle, AngularRate, CommandKind, FaultFlags, Heartbeat, HeelStrike, Message, NodeId, NodeState,
    ReflexPhase, Version,
};

use crate::bus::{Bus, BusConfig, BusError, BusEvent, NodeHandle};
use crate::fault::FaultSpec;
use crate::frame::Frame;

/// Control tick of the demo \[ns\] (1 kHz, as the firmware's).
pub const TICK_NS: u64 = 1_000_000;
/// AnkleState period \[ns\] (200 Hz).
pub const ANKLE_STATE_PERIOD_NS: u64 = 5_000_000;
/// Heartbeat period \[ns\] (20 Hz).
pub const HEARTBEAT_PERIOD_NS: u64 = 50_000_000;
/// HeelStrike period per ankle \[ns\] (2 Hz).
pub const HEEL_STRIKE_PERIOD_NS: u64 = 500_000_000;
/// Version period \[ns\] (0.2 Hz).
pub const VERSION_PERIOD_NS: u64 = 5_000_000_000;

#[derive(Clone, Debug)]
struct FakeNode {
    id: NodeId,
    handle: NodeHandle,
    state: NodeState,
    /// When in each tick this node sends [ns after the tick's start].
    offset_ns: u64,
    steps: u16,
}

/// The demo bus and its nodes.
#[derive(Clone, Debug)]
pub struct Demo {
    /// The bus.
    pub bus: Bus,
    /// The host node (frames from socketcand clients are sent as this node).
    pub host: NodeHandle,
    nodes: Vec<FakeNode>,
    t_ns: u64,
}

fn periodic(t_ns: u64, offset_ns: u64, period_ns: u64) -> bool {
    t_ns >= offset_ns && (t_ns - offset_ns).is_multiple_of(period_ns)
}

impl Demo {
    /// A bus with `host` (1), `left` (2) and `right` (3) and the given faults.
    ///
    /// # Errors
    /// [`BusError`] from [`Bus::new`] or [`Bus::add_fault`] (a fault naming an unknown node).
    pub fn new(config: BusConfig, faults: &[FaultSpec]) -> Result<Self, BusError> {
        let mut bus = Bus::new(config)?;
        let mut nodes = Vec::new();
        for (id, name, offset_ns) in [
            (NodeId::Host, "host", 300_000),
            (NodeId::LeftAnkle, "left", 0),
            (NodeId::RightAnkle, "right", 100_000),
        ] {
            let handle = bus.attach(name, Some(id.raw()));
            nodes.push(FakeNode {
                id,
                handle,
                state: NodeState::Enabled,
                offset_ns,
                steps: 0,
            });
        }
        for f in faults {
            bus.add_fault(f.clone())?;
        }
        let host = nodes.first().map_or(NodeHandle(0), |n| n.handle);
        Ok(Demo {
            bus,
            host,
            nodes,
            t_ns: 0,
        })
    }

    /// Simulated time \[ns\].
    pub fn now_ns(&self) -> u64 {
        self.t_ns
    }

    /// A fake node's current state.
    pub fn node_state(&self, id: NodeId) -> Option<NodeState> {
        self.nodes.iter().find(|n| n.id == id).map(|n| n.state)
    }

    /// Messages due in the tick starting at `t_ns`, each with its send time (tick start plus
    /// the node's offset within the tick).
    fn messages_due(&mut self, t_ns: u64) -> Vec<(NodeHandle, u64, Message)> {
        let mut out = Vec::new();
        let t_s = t_ns as f64 / 1e9;
        for n in &mut self.nodes {
            let at_ns = t_ns + n.offset_ns;
            let is_ankle = n.id != NodeId::Host;
            // the right ankle's gait lags half a period
            let lag = if n.id == NodeId::RightAnkle { 0.5 } else { 0.0 };
            let phase_of_cycle = (t_s - lag).rem_euclid(1.0);
            let strike_offset_ns = if lag > 0.0 {
                HEEL_STRIKE_PERIOD_NS / 2
            } else {
                0
            };
            if is_ankle && periodic(t_ns, strike_offset_ns, HEEL_STRIKE_PERIOD_NS) {
                n.steps = n.steps.wrapping_add(1);
                out.push((
                    n.handle,
                    at_ns,
                    Message::HeelStrike(HeelStrike {
                        node: n.id,
                        step_count: n.steps,
                        time_us: (at_ns / 1000) as u32,
                    }),
                ));
            }
            if periodic(t_ns, 0, HEARTBEAT_PERIOD_NS) {
                out.push((
                    n.handle,
                    at_ns,
                    Message::Heartbeat(Heartbeat {
                        node: n.id,
                        state: n.state,
                        faults: FaultFlags::NONE,
                        uptime_ms: (t_ns / 1_000_000) as u32,
                    }),
                ));
            }
            if is_ankle && periodic(t_ns, 0, ANKLE_STATE_PERIOD_NS) {
                let w = 2.0 * std::f64::consts::PI;
                let angle = 0.2 * (w * (t_s - lag)).sin();
                let rate = 0.2 * w * (w * (t_s - lag)).cos();
                let phase = if n.state != NodeState::Enabled {
                    ReflexPhase::Inactive
                } else {
                    match phase_of_cycle {
                        p if p < 0.4 => ReflexPhase::Swing,
                        p if p < 0.6 => ReflexPhase::Free,
                        p if p < 0.75 => ReflexPhase::Push,
                        _ => ReflexPhase::Hold,
                    }
                };
                out.push((
                    n.handle,
                    at_ns,
                    Message::AnkleState(protocol::AnkleState {
                        node: n.id,
                        angle: Angle::saturating_from_si(angle as f32),
                        rate: AngularRate::saturating_from_si(rate as f32),
                        actuator_position: Angle::saturating_from_si(0.2 * angle.max(0.0) as f32),
                        phase,
                    }),
                ));
            }
            if periodic(t_ns, 0, VERSION_PERIOD_NS) {
                out.push((
                    n.handle,
                    at_ns,
                    Message::Version(Version {
                        node: n.id,
                        protocol: protocol::PROTOCOL_VERSION,
                        major: 0,
                        minor: 1,
                        patch: 0,
                        build: 0xDE40,
                    }),
                ));
            }
        }
        out
    }

    fn react(&mut self, frame: &Frame) {
        let Ok(Message::Command(c)) = Message::decode(frame.id(), frame.data()) else {
            return;
        };
        for n in self.nodes.iter_mut().filter(|n| n.id != NodeId::Host) {
            if !c.target.addresses(n.id) {
                continue;
            }
            n.state = match (c.kind, n.state) {
                (CommandKind::EmergencyStop, _) => NodeState::EmergencyStop,
                (CommandKind::Disable, _) => NodeState::Disabled,
                (CommandKind::Enable, NodeState::EmergencyStop) => NodeState::EmergencyStop,
                (CommandKind::Enable, _) => NodeState::Enabled,
                // Parameters, identity, history, storage: no state change.
                (_, s) => s,
            };
        }
    }

    /// Queue `frame` as the host at the current time (frames from socketcand clients). A full
    /// host queue loses the frame, counted in the bus's `queue_overflows`: a client sending
    /// faster than the bus carries never stops the run.
    ///
    /// # Errors
    /// Any other [`BusError`] from [`Bus::send`].
    pub fn send_from_host(&mut self, frame: Frame) -> Result<(), BusError> {
        self.bus.send_lossy(self.host, frame, self.t_ns)
    }

    /// Run one control tick: queue the messages due at the current time, advance the bus by
    /// [`TICK_NS`], let the fake ankles react to commands delivered, and return the events.
    ///
    /// # Errors
    /// [`BusError`] from the bus (a full transmit queue under a babbling node, say, is
    /// reported, not hidden).
    pub fn tick(&mut self) -> Result<Vec<BusEvent>, BusError> {
        for (h, at_ns, m) in self.messages_due(self.t_ns) {
            if let Ok(raw) = m.encode() {
                match self.bus.send(h, Frame::from(raw), at_ns) {
                    Ok(_) | Err(BusError::QueueFull { .. }) => {}
                    Err(e) => return Err(e),
                }
            }
        }
        self.t_ns += TICK_NS;
        let events = self.bus.advance_to(self.t_ns)?;
        for e in &events {
            if let BusEvent::Delivered(d) = e {
                self.react(&d.frame);
            }
        }
        Ok(events)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nominal_rates_and_load() {
        let mut d = Demo::new(BusConfig::default(), &[]).unwrap();
        let mut delivered = 0;
        while d.now_ns() < 10_000_000_000 {
            delivered += d
                .tick()
                .unwrap()
                .iter()
                .filter(|e| e.delivered().is_some())
                .count();
        }
        let s = d.bus.stats();
        assert_eq!(s.frames, delivered as u64);
        let rate = |id: u16| s.per_id.get(&id).map_or(0.0, |x| x.rate_hz);
        assert!((rate(0x072) - 200.0).abs() < 0.5, "{}", rate(0x072));
        assert!((rate(0x073) - 200.0).abs() < 0.5);
        for hb in [0x061, 0x062, 0x063] {
            assert!((rate(hb) - 20.0).abs() < 0.2, "{hb:x}");
        }
        assert!((rate(0x022) - 2.0).abs() < 0.11 && (rate(0x023) - 2.0).abs() < 0.11);
        // below the worst-case figure of docs/protocol.md (which also counts rarer messages)
        assert!(s.load > 0.05 && s.load < 0.1179, "{}", s.load);
        assert_eq!(s.error_frames, 0);
    }

    #[test]
    fn commands_from_the_host_change_states() {
        let mut d = Demo::new(BusConfig::default(), &[]).unwrap();
        d.tick().unwrap();
        let estop = Message::Command(protocol::Command {
            target: protocol::Target::Node(NodeId::RightAnkle),
            kind: CommandKind::EmergencyStop,
        });
        d.send_from_host(Frame::from(estop.encode().unwrap()))
            .unwrap();
        d.tick().unwrap();
        assert_eq!(
            d.node_state(NodeId::RightAnkle),
            Some(NodeState::EmergencyStop)
        );
        assert_eq!(d.node_state(NodeId::LeftAnkle), Some(NodeState::Enabled));
    }

    #[test]
    fn a_flood_from_the_host_is_counted_not_fatal() {
        let mut d = Demo::new(BusConfig::default(), &[]).unwrap();
        let cap = d.bus.config().tx_queue_capacity;
        for i in 0..cap + 10 {
            d.send_from_host(Frame::new(0x100, &[i as u8]).unwrap())
                .unwrap();
        }
        assert_eq!(d.bus.stats().queue_overflows, 10);
        d.tick().unwrap();
    }
}
