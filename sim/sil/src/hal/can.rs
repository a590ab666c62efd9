//! The node's CAN controller: an `embedded_can::nb::Can` between the firmware's
//! `firmware::drivers::can::CanPort` and the simulated bus.
//!
//! The orchestrator and the controller share a [`CanLink`]:
//!
//! * before the node's tick the orchestrator sets the room left in the bus node's transmit
//!   queue ([`CanLink::set_tx_room`]) and whether the node is bus-off;
//! * `transmit` takes a frame while there is room (the orchestrator queues it on the bus at
//!   the tick time after the tick), returns `WouldBlock` when there is none — the port keeps
//!   the frame and offers it again at a later tick — and an error when the node is bus-off;
//! * the orchestrator delivers the frames the bus delivered to this node
//!   ([`CanLink::deliver`]) into a receive FIFO (`SilConfig::rx_queue_frames`, 16 frames by
//!   default: a quarter of the board's `RxBuf<64>` in `firmware/board-g431`, so the
//!   simulator is the more pessimistic; a full FIFO loses the newest frame and counts it);
//!   `receive` yields them raw, so frames that are not protocol messages reach the firmware's
//!   own `malformed` counter. A bus-off controller receives nothing and reports an error.
//!
//! Remote and extended frames cannot be built ([`SimFrame`] is a standard data frame, as
//! every frame on the simulated bus).

use std::cell::RefCell;
use std::collections::VecDeque;
use std::rc::Rc;

use embedded_can::{ErrorKind, Id, StandardId};
use firmware::drivers::can::{BusState, ControllerHealth, ControllerStatus};

/// A standard data frame of the simulated bus as an `embedded_can::Frame`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SimFrame(pub canbus::Frame);

impl embedded_can::Frame for SimFrame {
    fn new(id: impl Into<Id>, data: &[u8]) -> Option<Self> {
        match id.into() {
            Id::Standard(s) => canbus::Frame::new(u32::from(s.as_raw()), data)
                .ok()
                .map(SimFrame),
            Id::Extended(_) => None,
        }
    }

    fn new_remote(_id: impl Into<Id>, _dlc: usize) -> Option<Self> {
        None
    }

    fn is_extended(&self) -> bool {
        false
    }

    fn is_remote_frame(&self) -> bool {
        false
    }

    fn id(&self) -> Id {
        Id::Standard(StandardId::new(self.0.id()).unwrap_or(StandardId::MAX))
    }

    fn dlc(&self) -> usize {
        usize::from(self.0.dlc())
    }

    fn data(&self) -> &[u8] {
        self.0.data()
    }
}

/// Why the controller refused: the node is bus-off.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SimCanError {
    /// The node's transmit error counter passed 255: it takes no part in the bus.
    BusOff,
    /// The controller saw an error frame (its protocol status' last error code), reported
    /// through the receive path once per error frame, as embassy-stm32's buffered FDCAN
    /// driver pushes it into its receive channel.
    ErrorFrame,
}

impl embedded_can::Error for SimCanError {
    fn kind(&self) -> ErrorKind {
        ErrorKind::Other
    }
}

/// State shared by a [`SimCan`] and the orchestrator.
#[derive(Clone, Debug)]
pub struct CanLink {
    rx: VecDeque<canbus::Frame>,
    rx_capacity: usize,
    rx_overflows: u64,
    read: Vec<canbus::Frame>,
    tx: Vec<canbus::Frame>,
    tx_room: usize,
    bus_off: bool,
    error_state: (canbus::ErrorState, u16),
    rx_overflows_reported: u64,
    refused_full: u64,
    refused_bus_off: u64,
    error_frames_pending: u32,
    error_frames_seen: u64,
    rec: u16,
}

/// The receive error counter's ceiling as this model keeps it (ISO 11898-1 lets it grow past
/// 127, error-passive, and stops counting relevance there; FDCAN_ECR.REC has 7 bits plus the
/// RP flag).
const REC_MAX: u16 = 128;

impl CanLink {
    /// A link with a receive FIFO of `rx_capacity` frames (at least 1).
    pub fn new(rx_capacity: usize) -> Self {
        CanLink {
            rx: VecDeque::with_capacity(rx_capacity.max(1)),
            rx_capacity: rx_capacity.max(1),
            rx_overflows: 0,
            read: Vec::new(),
            tx: Vec::new(),
            tx_room: 0,
            bus_off: false,
            error_state: (canbus::ErrorState::ErrorActive, 0),
            rx_overflows_reported: 0,
            refused_full: 0,
            refused_bus_off: 0,
            error_frames_pending: 0,
            error_frames_seen: 0,
            rec: 0,
        }
    }

    /// The bus carried an error frame. Every controller on the bus sees it and reports it
    /// once through its receive path; a receiver's REC grows by 1 (ISO 11898-1 fault
    /// confinement, the receiver's rule; the transmitter's TEC is the bus model's).
    pub fn error_frame(&mut self, as_receiver: bool) {
        self.error_frames_pending = self.error_frames_pending.saturating_add(1);
        self.error_frames_seen += 1;
        if as_receiver {
            self.rec = (self.rec + 1).min(REC_MAX);
        }
    }

    /// Error frames this controller saw.
    pub fn error_frames_seen(&self) -> u64 {
        self.error_frames_seen
    }

    /// The receive error counter.
    pub fn rec(&self) -> u16 {
        self.rec
    }

    /// A frame the bus delivered to this node; false (and counted) when the FIFO is full.
    pub fn deliver(&mut self, frame: canbus::Frame) -> bool {
        // A successful reception takes one off the receive error counter.
        self.rec = self.rec.saturating_sub(1);
        if self.rx.len() >= self.rx_capacity {
            self.rx_overflows += 1;
            return false;
        }
        self.rx.push_back(frame);
        true
    }

    /// Frames waiting in the receive FIFO.
    pub fn rx_backlog(&self) -> usize {
        self.rx.len()
    }

    /// Frames lost to a full receive FIFO.
    pub fn rx_overflows(&self) -> u64 {
        self.rx_overflows
    }

    /// Room in the bus node's transmit queue for this tick's frames.
    pub fn set_tx_room(&mut self, frames: usize) {
        self.tx_room = frames;
    }

    /// Whether the node is bus-off.
    pub fn set_bus_off(&mut self, bus_off: bool) {
        self.bus_off = bus_off;
    }

    /// The bus node's fault-confinement state and transmit error counter, which the
    /// controller reports as the FDCAN's status (PSR) and error counter (ECR) registers do.
    pub fn set_error_state(&mut self, state: canbus::ErrorState, tec: u16) {
        self.error_state = (state, tec);
    }

    /// Frames the controller accepted since the last call, in order.
    pub fn take_tx(&mut self) -> std::vec::Drain<'_, canbus::Frame> {
        self.tx.drain(..)
    }

    /// Frames the firmware read since the last call, in order.
    pub fn take_read(&mut self) -> std::vec::Drain<'_, canbus::Frame> {
        self.read.drain(..)
    }

    /// Transmit calls refused with `WouldBlock` (no room in the bus node's queue).
    pub fn refused_queue_full(&self) -> u64 {
        self.refused_full
    }

    /// Transmit calls refused because the node is bus-off.
    pub fn refused_bus_off(&self) -> u64 {
        self.refused_bus_off
    }
}

/// The controller; it shares its [`CanLink`] with the orchestrator.
#[derive(Clone, Debug)]
pub struct SimCan(Rc<RefCell<CanLink>>);

impl SimCan {
    /// A controller on `link`.
    pub fn new(link: Rc<RefCell<CanLink>>) -> Self {
        SimCan(link)
    }
}

impl ControllerHealth for SimCan {
    /// As the board's driver reports it: the state from the status register, TEC saturated
    /// to the register's 8 bits, REC (one per error frame received, one off per frame
    /// received), and the frames lost to a full FIFO since the last call.
    fn status(&mut self) -> ControllerStatus {
        let mut l = self.0.borrow_mut();
        let lost = l.rx_overflows - l.rx_overflows_reported;
        l.rx_overflows_reported = l.rx_overflows;
        let (state, tec) = l.error_state;
        ControllerStatus {
            state: match state {
                canbus::ErrorState::ErrorActive => BusState::ErrorActive,
                canbus::ErrorState::ErrorPassive => BusState::ErrorPassive,
                canbus::ErrorState::BusOff => BusState::BusOff,
            },
            tx_errors: u8::try_from(tec).unwrap_or(u8::MAX),
            rx_errors: u8::try_from(l.rec).unwrap_or(u8::MAX),
            rx_lost: u32::try_from(lost).unwrap_or(u32::MAX),
        }
    }
}

impl embedded_can::nb::Can for SimCan {
    type Frame = SimFrame;
    type Error = SimCanError;

    fn transmit(&mut self, frame: &SimFrame) -> nb::Result<Option<SimFrame>, SimCanError> {
        let mut l = self.0.borrow_mut();
        if l.bus_off {
            l.refused_bus_off += 1;
            return Err(nb::Error::Other(SimCanError::BusOff));
        }
        if l.tx_room == 0 {
            l.refused_full += 1;
            return Err(nb::Error::WouldBlock);
        }
        l.tx_room -= 1;
        l.tx.push(frame.0);
        Ok(None)
    }

    fn receive(&mut self) -> nb::Result<SimFrame, SimCanError> {
        let mut l = self.0.borrow_mut();
        if l.bus_off {
            return Err(nb::Error::Other(SimCanError::BusOff));
        }
        if l.error_frames_pending > 0 {
            l.error_frames_pending -= 1;
            return Err(nb::Error::Other(SimCanError::ErrorFrame));
        }
        match l.rx.pop_front() {
            Some(f) => {
                l.read.push(f);
                Ok(SimFrame(f))
            }
            None => Err(nb::Error::WouldBlock),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use embedded_can::Frame as _;
    use firmware::drivers::can::CanPort;
    use protocol::{Heartbeat, Message, NodeId, NodeState};

    fn heartbeat(ms: u32) -> Message {
        Message::Heartbeat(Heartbeat {
            node: NodeId::LeftAnkle,
            state: NodeState::Enabled,
            faults: protocol::FaultFlags::NONE,
            uptime_ms: ms,
        })
    }

    #[test]
    fn a_full_bus_queue_blocks_and_the_frame_goes_out_on_a_later_tick() {
        let link = Rc::new(RefCell::new(CanLink::new(16)));
        let mut port = CanPort::new(SimCan::new(Rc::clone(&link)));
        // Tick 1: room for one frame, two messages.
        link.borrow_mut().set_tx_room(1);
        let error = port.transmit(&[heartbeat(1), heartbeat(2)]);
        assert!(
            !error,
            "WouldBlock is not an error: the port keeps the frame"
        );
        let sent: Vec<_> = link.borrow_mut().take_tx().collect();
        assert_eq!(sent.len(), 1);
        assert_eq!(
            Message::decode(sent[0].id(), sent[0].data()),
            Ok(heartbeat(1))
        );
        assert_eq!(link.borrow().refused_queue_full(), 1);
        // Tick 2: no room; nothing new either.
        link.borrow_mut().set_tx_room(0);
        assert!(!port.transmit(&[]));
        assert_eq!(link.borrow_mut().take_tx().count(), 0);
        // Tick 3: room again: the held frame goes first, then the new one.
        link.borrow_mut().set_tx_room(8);
        assert!(!port.transmit(&[heartbeat(3)]));
        let sent: Vec<_> = link.borrow_mut().take_tx().collect();
        let got: Vec<_> = sent
            .iter()
            .map(|f| Message::decode(f.id(), f.data()))
            .collect();
        assert_eq!(got, vec![Ok(heartbeat(2)), Ok(heartbeat(3))]);
        assert_eq!(port.stats().sent, 3);
        assert_eq!(port.stats().dropped, 0);
    }

    #[test]
    fn bus_off_refuses_with_an_error_and_receives_nothing() {
        let link = Rc::new(RefCell::new(CanLink::new(16)));
        let mut port = CanPort::new(SimCan::new(Rc::clone(&link)));
        link.borrow_mut()
            .deliver(canbus::Frame::from(heartbeat(9).encode().unwrap()));
        link.borrow_mut().set_tx_room(8);
        link.borrow_mut().set_bus_off(true);
        assert!(
            !port.transmit(&[heartbeat(1)]),
            "a refused write is counted, the frame kept: the status decides"
        );
        assert_eq!(link.borrow().refused_bus_off(), 1);
        let mut rx = heapless::Vec::new();
        port.receive(&mut rx);
        assert!(rx.is_empty());
        assert_eq!(port.stats().bus_errors, 2);
        link.borrow_mut()
            .set_error_state(canbus::ErrorState::BusOff, 256);
        assert_eq!(port.poll_status(), BusState::BusOff);
        assert_eq!(port.stats().status.tx_errors, 255);
        assert_eq!(port.stats().bus_off_events, 1);
    }

    #[test]
    fn each_error_frame_is_one_receive_error_and_counts_in_rec() {
        let link = Rc::new(RefCell::new(CanLink::new(16)));
        let mut port = CanPort::new(SimCan::new(Rc::clone(&link)));
        link.borrow_mut().error_frame(true);
        link.borrow_mut().error_frame(true);
        link.borrow_mut()
            .deliver(canbus::Frame::from(heartbeat(1).encode().unwrap()));
        // Two error frames, then one good frame: REC 2 − 1.
        assert_eq!(link.borrow().rec(), 1);
        let mut rx = heapless::Vec::new();
        port.receive(&mut rx);
        assert_eq!(
            port.stats().bus_errors,
            1,
            "one error per read, the port stops there"
        );
        port.receive(&mut rx);
        assert_eq!(port.stats().bus_errors, 2);
        port.receive(&mut rx);
        assert_eq!(port.stats().bus_errors, 2, "no error frame left");
        assert_eq!(rx.as_slice(), &[heartbeat(1)]);
        assert_eq!(port.poll_status(), BusState::ErrorActive);
        assert_eq!(port.stats().status.rx_errors, 1);
        // The transmitter sees the error frame too, without a REC step.
        let tx_link = Rc::new(RefCell::new(CanLink::new(16)));
        tx_link.borrow_mut().error_frame(false);
        assert_eq!(tx_link.borrow().rec(), 0);
        assert_eq!(tx_link.borrow().error_frames_seen(), 1);
    }

    #[test]
    fn raw_frames_are_decoded_by_the_firmware_and_the_fifo_is_bounded() {
        let link = Rc::new(RefCell::new(CanLink::new(3)));
        let mut port = CanPort::new(SimCan::new(Rc::clone(&link)));
        let babble = canbus::Frame::new(0x7FF, &[0xBA; 8]).unwrap();
        let good = canbus::Frame::from(heartbeat(5).encode().unwrap());
        let mut l = link.borrow_mut();
        assert!(l.deliver(babble) && l.deliver(good) && l.deliver(babble));
        assert!(!l.deliver(good), "FIFO of 3 full");
        assert_eq!(l.rx_overflows(), 1);
        drop(l);
        let mut rx = heapless::Vec::new();
        port.receive(&mut rx);
        assert_eq!(rx.as_slice(), &[heartbeat(5)]);
        assert_eq!(port.poll_status(), BusState::ErrorActive);
        assert_eq!(port.stats().rx_lost, 1, "the lost frame is reported once");
        assert_eq!(port.poll_status(), BusState::ErrorActive);
        assert_eq!(port.stats().rx_lost, 1);
        assert_eq!(port.stats().malformed, 2);
        assert_eq!(link.borrow_mut().take_read().count(), 3);
        assert_eq!(link.borrow().rx_backlog(), 0);
        assert_eq!(SimFrame(babble).id(), Id::Standard(StandardId::MAX));
        assert!(SimFrame::new_remote(StandardId::ZERO, 0).is_none());
        assert!(SimFrame::new(embedded_can::ExtendedId::ZERO, &[]).is_none());
    }
}
