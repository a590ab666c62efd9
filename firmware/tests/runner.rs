//! The driver layer end to end with fake hardware: SPI encoder words, a contact pin, PWM and
//! direction pin, and a CAN controller with a receive queue and a transmit log.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use std::cell::{Cell, RefCell};
use std::collections::VecDeque;
use std::convert::Infallible;
use std::rc::Rc;

use embedded_can::{Frame, Id, StandardId};
use embedded_hal::spi::{ErrorType, Operation, SpiDevice};
use firmware::drivers::actuator::{PwmDirActuator, PwmDirGains};
use firmware::drivers::can::{BusState, CanPort, ControllerHealth, ControllerStatus};
use firmware::drivers::contact::{ActiveLevel, ContactSwitch};
use firmware::drivers::encoder::{read_command, MagneticEncoder, ANGLECOM};
use firmware::runner::AnkleDrivers;
use firmware::scenarios::CALIBRATION;
use firmware::{AnkleNode, Instant, Monotonic, NodeConfig};
use protocol::*;

#[derive(Default)]
struct World {
    angle_rad: Cell<f32>,
    contact_closed: Cell<bool>,
    spi_fails: Cell<bool>,
    duty: Cell<u16>,
    dir_high: Cell<bool>,
    rx: RefCell<VecDeque<TestFrame>>,
    tx: RefCell<Vec<TestFrame>>,
    tx_room: Cell<usize>,
    bus_error: Cell<bool>,
    bus_state: Cell<BusState>,
    now_us: Cell<u64>,
}

#[derive(Debug, Clone)]
struct TestFrame {
    id: Id,
    data: Vec<u8>,
}

impl Frame for TestFrame {
    fn new(id: impl Into<Id>, data: &[u8]) -> Option<Self> {
        (data.len() <= 8).then(|| TestFrame {
            id: id.into(),
            data: data.to_vec(),
        })
    }
    fn new_remote(_: impl Into<Id>, _: usize) -> Option<Self> {
        None
    }
    fn is_extended(&self) -> bool {
        matches!(self.id, Id::Extended(_))
    }
    fn is_remote_frame(&self) -> bool {
        false
    }
    fn id(&self) -> Id {
        self.id
    }
    fn dlc(&self) -> usize {
        self.data.len()
    }
    fn data(&self) -> &[u8] {
        &self.data
    }
}

struct Spi(Rc<World>, u16);
#[derive(Debug)]
struct SpiErr;
impl embedded_hal::spi::Error for SpiErr {
    fn kind(&self) -> embedded_hal::spi::ErrorKind {
        embedded_hal::spi::ErrorKind::Other
    }
}
impl ErrorType for Spi {
    type Error = SpiErr;
}
impl SpiDevice for Spi {
    fn transaction(&mut self, ops: &mut [Operation<'_, u8>]) -> Result<(), SpiErr> {
        if self.0.spi_fails.get() {
            return Err(SpiErr);
        }
        for op in ops {
            if let Operation::TransferInPlace(buf) = op {
                let cmd = u16::from_be_bytes([buf[0], buf[1]]);
                // Answer the previous command (AS5047P pipelining).
                let counts = CALIBRATION.counts(self.0.angle_rad.get());
                let answer = if self.1 == read_command(ANGLECOM) {
                    counts
                } else {
                    0
                };
                let answer = if answer.count_ones() % 2 == 1 {
                    answer | 0x8000
                } else {
                    answer
                };
                buf.copy_from_slice(&answer.to_be_bytes());
                self.1 = cmd;
            }
        }
        Ok(())
    }
}

struct Pin(Rc<World>);
impl embedded_hal::digital::ErrorType for Pin {
    type Error = Infallible;
}
impl embedded_hal::digital::InputPin for Pin {
    fn is_high(&mut self) -> Result<bool, Infallible> {
        Ok(!self.0.contact_closed.get()) // active low
    }
    fn is_low(&mut self) -> Result<bool, Infallible> {
        Ok(self.0.contact_closed.get())
    }
}

struct Pwm(Rc<World>);
impl embedded_hal::pwm::ErrorType for Pwm {
    type Error = Infallible;
}
impl embedded_hal::pwm::SetDutyCycle for Pwm {
    fn max_duty_cycle(&self) -> u16 {
        1000
    }
    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Infallible> {
        self.0.duty.set(duty);
        Ok(())
    }
}

struct Dir(Rc<World>);
impl embedded_hal::digital::ErrorType for Dir {
    type Error = Infallible;
}
impl embedded_hal::digital::OutputPin for Dir {
    fn set_low(&mut self) -> Result<(), Infallible> {
        self.0.dir_high.set(false);
        Ok(())
    }
    fn set_high(&mut self) -> Result<(), Infallible> {
        self.0.dir_high.set(true);
        Ok(())
    }
}

struct Can(Rc<World>);
#[derive(Debug)]
struct CanErr;
impl embedded_can::Error for CanErr {
    fn kind(&self) -> embedded_can::ErrorKind {
        embedded_can::ErrorKind::Bit
    }
}
impl embedded_can::nb::Can for Can {
    type Frame = TestFrame;
    type Error = CanErr;
    fn transmit(&mut self, frame: &TestFrame) -> nb::Result<Option<TestFrame>, CanErr> {
        if self.0.tx_room.get() == 0 {
            return Err(nb::Error::WouldBlock);
        }
        self.0.tx_room.set(self.0.tx_room.get() - 1);
        self.0.tx.borrow_mut().push(frame.clone());
        Ok(None)
    }
    fn receive(&mut self) -> nb::Result<TestFrame, CanErr> {
        if self.0.bus_error.replace(false) {
            return Err(nb::Error::Other(CanErr));
        }
        self.0
            .rx
            .borrow_mut()
            .pop_front()
            .ok_or(nb::Error::WouldBlock)
    }
}

impl ControllerHealth for Can {
    fn status(&mut self) -> ControllerStatus {
        ControllerStatus {
            state: self.0.bus_state.get(),
            tx_errors: 0,
            rx_errors: 0,
            rx_lost: 0,
        }
    }
}

struct Clock(Rc<World>);
impl Monotonic for Clock {
    fn now(&mut self) -> Instant {
        Instant::from_micros(self.0.now_us.get())
    }
}

type Drivers = AnkleDrivers<MagneticEncoder<Spi>, Pin, PwmDirActuator<Pwm, Dir>, Can, Clock>;

fn setup() -> (Rc<World>, Drivers) {
    let w = Rc::new(World::default());
    w.angle_rad.set(0.1);
    w.tx_room.set(1000);
    let d = AnkleDrivers::new(
        AnkleNode::new(NodeConfig::nominal(NodeId::LeftAnkle)).unwrap(),
        MagneticEncoder::new(Spi(w.clone(), 0), CALIBRATION),
        ContactSwitch::new(Pin(w.clone()), ActiveLevel::Low, 3),
        PwmDirActuator::new(Pwm(w.clone()), Dir(w.clone()), PwmDirGains::default()),
        CanPort::new(Can(w.clone())),
        Clock(w.clone()),
    );
    (w, d)
}

fn send(w: &World, m: Message) {
    let f = m.encode().unwrap();
    w.rx.borrow_mut().push_back(TestFrame {
        id: Id::Standard(StandardId::new(f.id.raw()).unwrap()),
        data: f.payload().to_vec(),
    });
}

fn step(w: &World, d: &mut Drivers) -> firmware::TickOutputs {
    if w.now_us.get().is_multiple_of(50_000) {
        send(
            w,
            Message::Heartbeat(Heartbeat {
                node: NodeId::RightAnkle,
                state: NodeState::Enabled,
                faults: FaultFlags::NONE,
                uptime_ms: 0,
            }),
        );
    }
    let o = d.step();
    w.now_us.set(w.now_us.get() + 1000);
    o
}

fn sent(w: &World) -> Vec<Message> {
    w.tx.borrow()
        .iter()
        .map(|f| Message::from_frame(f).expect("the node sends only valid frames"))
        .collect()
}

#[test]
fn reflex_through_real_drivers() {
    let (w, mut d) = setup();
    step(&w, &mut d);
    send(
        &w,
        Message::Command(Command {
            target: Target::Broadcast,
            kind: CommandKind::Enable,
        }),
    );
    assert_eq!(step(&w, &mut d).state, NodeState::Enabled);
    // Foot down: the debouncer needs 3 samples.
    w.contact_closed.set(true);
    let phases: Vec<_> = (0..4).map(|_| step(&w, &mut d).phase).collect();
    assert_eq!(phases[..2], [ReflexPhase::Swing, ReflexPhase::Swing]);
    assert_eq!(phases[3], ReflexPhase::Free);
    assert!(sent(&w)
        .iter()
        .any(|m| matches!(m, Message::HeelStrike(h) if h.node == NodeId::LeftAnkle)));
    // Ankle rolls forward to the taut angle: the motor starts pulling (direction high).
    let mut pushed = false;
    for _ in 0..400 {
        let o = step(&w, &mut d);
        if o.phase == ReflexPhase::Push {
            pushed = true;
            break;
        }
        w.angle_rad.set(w.angle_rad.get() - 0.001);
    }
    assert!(pushed);
    w.angle_rad.set(w.angle_rad.get() - 0.02); // lagging the setpoint
    step(&w, &mut d);
    assert!(
        w.duty.get() > 0 && w.dir_high.get(),
        "motor shortens the string"
    );
    // Released by the peer's heel strike: duty 0.
    send(
        &w,
        Message::HeelStrike(HeelStrike {
            node: NodeId::RightAnkle,
            step_count: 1,
            time_us: 0,
        }),
    );
    let o = step(&w, &mut d);
    assert_eq!(o.phase, ReflexPhase::Swing);
    assert_eq!(w.duty.get(), 0);
    assert_eq!(d.node.faults(), FaultFlags::NONE);
}

#[test]
fn malformed_frames_are_counted_and_skipped() {
    let (w, mut d) = setup();
    w.rx.borrow_mut().push_back(TestFrame {
        id: Id::Standard(StandardId::new(0x072).unwrap()),
        data: vec![0; 3],
    });
    w.rx.borrow_mut().push_back(TestFrame {
        id: Id::Standard(StandardId::new(0x7FF).unwrap()),
        data: vec![],
    });
    step(&w, &mut d);
    let s = d.can.stats();
    assert_eq!(s.malformed, 2);
    assert_eq!(
        s.last_decode_error,
        Some(DecodeError::UnknownId { raw: 0x7FF })
    );
    assert!(s.received >= 1, "the heartbeat still arrives");
}

#[test]
fn full_controller_queues_then_sends_in_order() {
    let (w, mut d) = setup();
    w.tx_room.set(0);
    step(&w, &mut d);
    assert!(w.tx.borrow().is_empty());
    w.tx_room.set(1000);
    step(&w, &mut d);
    let classes: Vec<_> = sent(&w).iter().map(Message::class).collect();
    // Tick 0's heartbeat, state, version and identity, then tick 1's (nothing periodic due at 1 ms).
    assert_eq!(
        classes,
        [
            MessageClass::Heartbeat,
            MessageClass::AnkleState,
            MessageClass::Version,
            MessageClass::Identity,
            MessageClass::BootInfo,
            MessageClass::ClockInfo
        ]
    );
    assert_eq!(d.can.stats().dropped, 0);
}

#[test]
fn encoder_and_bus_errors_become_faults() {
    let (w, mut d) = setup();
    step(&w, &mut d);
    w.spi_fails.set(true);
    step(&w, &mut d);
    assert!(d.node.faults().contains(FaultCode::EncoderComms));
    w.spi_fails.set(false);
    step(&w, &mut d);
    step(&w, &mut d);
    assert!(!d.node.faults().contains(FaultCode::EncoderComms));
    // One error frame reported through the receive path: counted, not a fault.
    w.bus_error.set(true);
    step(&w, &mut d);
    assert!(!d.node.faults().contains(FaultCode::CanBus));
    assert_eq!(d.can.stats().bus_errors, 1);
    // Error-passive: reported in the stats, not a fault.
    w.bus_state.set(BusState::ErrorPassive);
    step(&w, &mut d);
    assert!(!d.node.faults().contains(FaultCode::CanBus));
    assert_eq!(d.can.stats().status.state, BusState::ErrorPassive);
    // Bus-off from the status register: a fault.
    w.bus_state.set(BusState::BusOff);
    step(&w, &mut d);
    assert!(d.node.faults().contains(FaultCode::CanBus));
    assert_eq!(d.can.stats().bus_off_events, 1);
    w.bus_state.set(BusState::ErrorActive);
    step(&w, &mut d);
    assert!(!d.node.faults().contains(FaultCode::CanBus));
}

fn enable(w: &World, d: &mut Drivers) {
    send(
        w,
        Message::Command(Command {
            target: Target::Broadcast,
            kind: CommandKind::Enable,
        }),
    );
    assert_eq!(step(w, d).state, NodeState::Enabled);
}

#[test]
fn boot_with_the_foot_down_sends_no_heel_strike() {
    let (w, mut d) = setup();
    w.contact_closed.set(true);
    for _ in 0..100 {
        step(&w, &mut d);
    }
    enable(&w, &mut d);
    for _ in 0..100 {
        step(&w, &mut d);
    }
    assert!(
        !sent(&w).iter().any(|m| matches!(m, Message::HeelStrike(_))),
        "a foot already down at power-up is no heel strike"
    );
    // The next real strike is announced.
    w.contact_closed.set(false);
    for _ in 0..10 {
        step(&w, &mut d);
    }
    w.contact_closed.set(true);
    for _ in 0..10 {
        step(&w, &mut d);
    }
    let strikes = sent(&w)
        .iter()
        .filter(|m| matches!(m, Message::HeelStrike(_)))
        .count();
    assert_eq!(strikes, 1);
}

#[test]
fn one_error_frame_is_no_safe_state_but_bus_off_is() {
    let (w, mut d) = setup();
    step(&w, &mut d);
    enable(&w, &mut d);
    w.bus_error.set(true);
    for _ in 0..20 {
        assert_eq!(step(&w, &mut d).state, NodeState::Enabled);
    }
    assert_eq!(d.can.stats().bus_errors, 1);
    w.bus_state.set(BusState::ErrorPassive);
    for _ in 0..20 {
        assert_eq!(step(&w, &mut d).state, NodeState::Enabled);
    }
    w.bus_state.set(BusState::BusOff);
    let o = step(&w, &mut d);
    assert_eq!(o.state, NodeState::Safe);
    assert_eq!(o.actuator, firmware::ActuatorCommand::Released);
    assert!(d.node.faults().contains(FaultCode::CanBus));
}

/// Records how the runner drives its actuator.
#[derive(Default)]
struct Recording {
    applied: Cell<u32>,
    stopped: Cell<u32>,
}
struct RecordingActuator(Rc<Recording>);
impl firmware::drivers::actuator::Actuator for RecordingActuator {
    fn apply(
        &mut self,
        _: firmware::ActuatorCommand,
        _: Option<f32>,
    ) -> Result<(), firmware::drivers::actuator::ActuatorError> {
        self.0.applied.set(self.0.applied.get() + 1);
        Ok(())
    }
    fn stop(&mut self) -> Result<(), firmware::drivers::actuator::ActuatorError> {
        self.0.stopped.set(self.0.stopped.get() + 1);
        Ok(())
    }
}

#[test]
fn emergency_stop_switches_the_actuator_off_at_once_instead_of_releasing() {
    let w = Rc::new(World::default());
    w.angle_rad.set(0.1);
    w.tx_room.set(1000);
    let rec = Rc::new(Recording::default());
    let mut d = AnkleDrivers::new(
        AnkleNode::new(NodeConfig::nominal(NodeId::LeftAnkle)).unwrap(),
        MagneticEncoder::new(Spi(w.clone(), 0), CALIBRATION),
        ContactSwitch::new(Pin(w.clone()), ActiveLevel::Low, 3),
        RecordingActuator(rec.clone()),
        CanPort::new(Can(w.clone())),
        Clock(w.clone()),
    );
    d.step();
    assert_eq!((rec.applied.get(), rec.stopped.get()), (1, 0));
    send(
        &w,
        Message::Command(Command {
            target: Target::Broadcast,
            kind: CommandKind::EmergencyStop,
        }),
    );
    assert_eq!(d.step().state, NodeState::EmergencyStop);
    assert_eq!(
        (rec.applied.get(), rec.stopped.get()),
        (1, 1),
        "stopped in the tick the emergency stop was read, not applied"
    );
    d.step();
    assert_eq!((rec.applied.get(), rec.stopped.get()), (1, 2));
}
