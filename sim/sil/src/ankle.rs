//! One ankle node with its sim-backed hardware: the firmware behind the board's drivers
//! ([`firmware::runner::AnkleDrivers`]) over [`crate::hal`]'s SPI encoder, contact pin, CAN
//! controller, clock and actuator, and the orchestrator's ends of that hardware (the shaft,
//! the pin, the clock, the CAN and actuator links) through which it sets what the hardware
//! sees before each step and collects what the firmware did after it.

use std::cell::RefCell;
use std::rc::Rc;

use canbus::{BusError, Frame, NodeHandle, SendOutcome};
use firmware::drivers::can::CanPort;
use firmware::drivers::contact::{ActiveLevel, ContactSwitch};
use firmware::drivers::encoder::MagneticEncoder;
use firmware::runner::AnkleDrivers;
use firmware::{AnkleNode, Instant, NodeConfig, TickOutputs};
use protocol::Message;
use sim::engine::control::ActuatorSegment;

use crate::actuator::ActuatorModel;
use crate::bus_side::BusSide;
use crate::config::ActuatorChoice;
use crate::config::SilConfig;
use crate::error::{SilError, TickError};
use crate::gait::AnkleScene;
use crate::hal::{
    ActuatorLink, AnkleActuator, CanLink, PlantLink, Shaft, SimActuator, SimBridges, SimCan,
    SimClock, SimContactPin, SimCurrentSense, SimSpi, SimSpoolEncoder,
};
use crate::report::NodeReport;
use crate::sensors::{AppliedSensorFault, SensorFault, SimEncoder};
use crate::side::Side;
use crate::spool_plant::{PlantTick, SpoolPlant};
use crate::tick::TickTime;
use firmware::drivers::spool_motor::SpoolMotor;

/// The board's drivers over the simulator's hardware.
type SimDrivers =
    AnkleDrivers<MagneticEncoder<SimSpi>, SimContactPin, AnkleActuator, SimCan, SimClock>;

/// The orchestrator's ends of one ankle's hardware (shared with the drivers' ends).
struct Wiring {
    shaft: Shaft,
    contact: SimContactPin,
    clock: SimClock,
    can: Rc<RefCell<CanLink>>,
    actuator: Rc<RefCell<ActuatorLink>>,
    /// The motor plant, with [`ActuatorChoice::SpoolMotor`].
    plant: Option<PlantLink>,
    /// A supply drop still to apply at the first tick in `Hold` [V].
    supply_drop_v: Option<f64>,
    /// The contact switch's and the spool encoder's injected faults, and whether each took
    /// effect yet.
    other_faults: Vec<(SensorFault, bool)>,
    /// Those that took effect.
    other_applied: Vec<AppliedSensorFault>,
    /// The raw contact switch is stuck at this (closed: true).
    contact_stuck: Option<bool>,
}

/// What the ankle's bus node allows at a tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct BusAccess {
    /// Room in the bus node's transmit queue [frames].
    pub tx_room: usize,
    /// The node is bus-off.
    pub bus_off: bool,
    /// The node's fault-confinement state and transmit error counter.
    pub error_state: (canbus::ErrorState, u16),
}

/// What one step of an ankle's firmware did, for the records.
pub(crate) struct AnkleStep {
    /// The firmware's outputs.
    pub outputs: TickOutputs,
    /// The firmware read the peer's `HeelStrike` in this step.
    pub peer_heel_strike: bool,
    /// Frames left in the receive FIFO after the step.
    pub rx_backlog: usize,
}

/// What became of the frames the ankle's CAN controller accepted in a step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct TransmitTally {
    /// Queued on the bus.
    pub queued: u64,
    /// Discarded by a `drop` fault.
    pub dropped: u64,
    /// Not taken by the bus (bus-off, queue full).
    pub lost_at_bus: u64,
}

/// One ankle: its firmware behind its drivers, and the orchestrator's ends of the hardware.
pub(crate) struct Ankle {
    side: Side,
    handle: NodeHandle,
    drivers: SimDrivers,
    wiring: Wiring,
}

impl Ankle {
    /// `side`'s node (disabled until the host's `Enable`), on the bus as `handle`, with its
    /// calibration, sensor faults, actuator and receive FIFO from `config`.
    ///
    /// # Errors
    /// [`SilError::Node`] when the firmware refuses the node's configuration.
    pub fn new(side: Side, handle: NodeHandle, config: &SilConfig) -> Result<Self, SilError> {
        let node =
            AnkleNode::new(NodeConfig::nominal(side.node())).map_err(|e| SilError::Node {
                node: side.node(),
                reason: e,
            })?;
        let (other_faults, faults): (Vec<_>, Vec<_>) = config
            .sensor_faults
            .iter()
            .filter(|f| f.side() == side)
            .copied()
            .partition(|f| {
                matches!(
                    f,
                    SensorFault::ContactStuck { .. } | SensorFault::SpoolStuck { .. }
                )
            });
        let calibration = config.calibration[side.index()];
        let wiring = Wiring {
            shaft: Shaft::new(),
            contact: SimContactPin::new(),
            clock: SimClock::new(),
            can: Rc::new(RefCell::new(CanLink::new(config.rx_queue_frames))),
            actuator: Rc::new(RefCell::new(ActuatorLink::new(ActuatorModel::new(
                config.actuator,
            )))),
            plant: match config.actuator_choice {
                ActuatorChoice::SpoolMotor => {
                    Some(Rc::new(RefCell::new(SpoolPlant::new(config.spool_plant))))
                }
                ActuatorChoice::Servo => None,
            },
            supply_drop_v: config
                .supply_drops
                .iter()
                .find(|d| d.side == side)
                .map(|d| d.supply_v),
            other_faults: other_faults.into_iter().map(|f| (f, false)).collect(),
            other_applied: Vec::new(),
            contact_stuck: None,
        };
        let actuator = match &wiring.plant {
            Some(plant) => AnkleActuator::SpoolMotor(Box::new(SpoolMotor::new(
                SimBridges(Rc::clone(plant)),
                SimSpoolEncoder(Rc::clone(plant)),
                SimCurrentSense(Rc::clone(plant)),
                config.spool_motor,
            ))),
            None => AnkleActuator::Servo(SimActuator::new(Rc::clone(&wiring.actuator))),
        };
        let spi = SimSpi::new(SimEncoder::new(calibration, faults), wiring.shaft.clone());
        let drivers = AnkleDrivers::new(
            node,
            MagneticEncoder::new(spi, calibration),
            ContactSwitch::new(
                wiring.contact.clone(),
                ActiveLevel::Low,
                config.debounce_samples,
            ),
            actuator,
            CanPort::new(SimCan::new(Rc::clone(&wiring.can))),
            wiring.clock.clone(),
        );
        Ok(Ankle {
            side,
            handle,
            drivers,
            wiring,
        })
    }

    /// The ankle's bus node.
    pub fn handle(&self) -> NodeHandle {
        self.handle
    }

    /// The firmware (read-only).
    pub fn node(&self) -> &AnkleNode {
        &self.drivers.node
    }

    /// A frame the bus delivered to this node, into its receive FIFO.
    pub fn deliver(&mut self, frame: Frame) {
        self.wiring.can.borrow_mut().deliver(frame);
    }

    /// The bus carried an error frame; `as_receiver` when this node did not send the frame.
    pub fn error_frame(&mut self, as_receiver: bool) {
        self.wiring.can.borrow_mut().error_frame(as_receiver);
    }

    /// One control tick, as on the board: set what the hardware sees (`scene`, the clock,
    /// the bus node's state, the actuator's tick interval), run one driver step, and see
    /// what the firmware read.
    pub fn step(&mut self, t: TickTime, scene: &AnkleScene, access: BusAccess) -> AnkleStep {
        self.apply_other_faults(t.t_s);
        let w = &self.wiring;
        w.shaft.set(t.t_s, scene.angle_rad);
        w.shaft.set_phase(self.drivers.node.phase());
        w.contact
            .set_closed(w.contact_stuck.unwrap_or(scene.contact_closed));
        w.clock.set(Instant::from_micros(t.t_ns / 1000));
        {
            let mut can = w.can.borrow_mut();
            can.set_tx_room(access.tx_room);
            can.set_bus_off(access.bus_off);
            can.set_error_state(access.error_state.0, access.error_state.1);
        }
        let in_hold = self.drivers.node.phase() == protocol::ReflexPhase::Hold;
        let w = &mut self.wiring;
        if let (Some(plant), true) = (&w.plant, in_hold) {
            if let Some(v) = w.supply_drop_v.take() {
                plant.borrow_mut().drop_supply(v);
            }
        }
        let w = &self.wiring;
        // The string's torque acts on the stance ankle's actuator only.
        match &w.plant {
            Some(plant) => plant.borrow_mut().set_tick(PlantTick {
                t0_s: t.t_s,
                t1_s: t.t_end_s,
                stance: scene.stance,
                ankle_rad: scene.angle_rad,
                engaged: scene.string_engaged,
                load_n_m: scene.string_load_n_m,
            }),
            None => w.actuator.borrow_mut().set_tick(
                t.t_s,
                t.t_end_s,
                scene.angle_rad,
                scene.string_load_n_m,
            ),
        }
        // The firmware, as on the board.
        let outputs = self.drivers.step();
        let peer = self.side.other().node();
        let mut can = self.wiring.can.borrow_mut();
        let peer_heel_strike = can.take_read().any(|f| {
            matches!(
                Message::decode(f.id(), f.data()),
                Ok(Message::HeelStrike(h)) if h.node == peer
            )
        });
        AnkleStep {
            outputs,
            peer_heel_strike,
            rx_backlog: can.rx_backlog(),
        }
    }

    /// The contact switch's and the spool encoder's faults due at `t_s` take effect.
    fn apply_other_faults(&mut self, t_s: f64) {
        let w = &mut self.wiring;
        for (f, fired) in &mut w.other_faults {
            let from_s = match *f {
                SensorFault::ContactStuck { from_s, .. }
                | SensorFault::SpoolStuck { from_s, .. } => from_s,
                _ => continue,
            };
            if *fired || t_s < from_s {
                continue;
            }
            *fired = true;
            match *f {
                SensorFault::ContactStuck { closed, .. } => w.contact_stuck = Some(closed),
                _ => match &w.plant {
                    Some(plant) => plant.borrow_mut().freeze_encoder(),
                    None => w.actuator.borrow_mut().freeze_spool_sensor(),
                },
            }
            w.other_applied.push(AppliedSensorFault {
                side: f.side(),
                kind: f.kind(),
                t_s,
            });
        }
    }

    /// Put the frames the CAN controller accepted in the last step on the bus at `t_ns`.
    ///
    /// # Errors
    /// A refusal of the bus other than bus-off or a full queue.
    pub fn transmit(&mut self, bus: &mut BusSide, t_ns: u64) -> Result<TransmitTally, TickError> {
        let mut tally = TransmitTally::default();
        for frame in self.wiring.can.borrow_mut().take_tx() {
            match bus.send(self.handle, frame, t_ns) {
                Ok(SendOutcome::Queued) => tally.queued += 1,
                Ok(SendOutcome::Dropped) => tally.dropped += 1,
                // Not offered: the controller refuses while bus-off, and it took no more than
                // the queue's room.
                Ok(SendOutcome::BusOff) | Err(BusError::QueueFull { .. }) => {
                    tally.lost_at_bus += 1;
                }
                Err(e) => return Err(TickError::Bus(e)),
            }
        }
        Ok(tally)
    }

    /// The segment the actuator moved the string through over the last step.
    ///
    /// # Errors
    /// When the firmware applied no actuator command.
    pub fn take_segment(&mut self) -> Result<ActuatorSegment, TickError> {
        if let Some(plant) = &self.wiring.plant {
            // The duty the firmware set in this step, integrated over the tick.
            return Ok(plant.borrow_mut().finish_tick());
        }
        self.wiring
            .actuator
            .borrow_mut()
            .take_segment()
            .ok_or(TickError::NoActuatorCommand)
    }

    /// What the power stage did in the last tick (motor plant only).
    pub fn stage_output(&self) -> Option<firmware::drivers::spool_motor::StageOutput> {
        self.wiring.plant.as_ref().map(|p| p.borrow().stage())
    }

    /// The spool encoder's count (motor plant only).
    pub fn spool_counts(&self) -> Option<i32> {
        self.wiring
            .plant
            .as_ref()
            .map(|p| p.borrow().spool_counts())
    }

    /// The injected sensor faults that took effect at this ankle: the encoder's, then the
    /// contact switch's and the spool encoder's.
    pub fn sensor_faults_applied(&self) -> impl Iterator<Item = &AppliedSensorFault> {
        self.drivers
            .encoder
            .device()
            .encoder()
            .applied()
            .iter()
            .chain(self.wiring.other_applied.iter())
    }

    /// Fill in what the firmware, its CAN port, the controller and the actuator counted.
    pub fn fill_report(&self, r: &mut NodeReport) {
        let node = &self.drivers.node;
        r.state = format!("{:?}", node.state());
        r.phase = format!("{:?}", node.phase());
        r.active_faults = crate::report::fault_names(node.faults());
        r.firmware_dropped_tx = node.dropped_tx();
        let port = self.drivers.can.stats();
        r.messages_read = u64::from(port.received);
        r.frames_malformed = u64::from(port.malformed);
        r.port_dropped = u64::from(port.dropped);
        r.port_bus_errors = u64::from(port.bus_errors);
        let link = self.wiring.can.borrow();
        r.frames_refused_queue_full = link.refused_queue_full();
        r.frames_refused_bus_off = link.refused_bus_off();
        r.rx_overflows = link.rx_overflows();
        r.actuator = *self.wiring.actuator.borrow().model().stats();
        r.spool_plant = self.wiring.plant.as_ref().map(|p| *p.borrow().stats());
    }
}
