//! The node's CAN port over any `embedded_can::nb::Can` controller: decodes what arrives,
//! queues what must go, and hands the controller frames in priority order.

use embedded_can::nb::Can;
use embedded_can::Error as _;
use heapless::{Deque, Vec};
use protocol::{DecodeError, Message, RawFrame};

use crate::node::MAX_RX_PER_TICK;

/// The controller's fault-confinement state (ISO 11898-1), read from its status register.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BusState {
    /// Both error counters below 128: the node takes part normally.
    #[default]
    ErrorActive,
    /// An error counter at 128 or more: the node still sends and receives, but signals errors
    /// passively. Reported, not a fault.
    ErrorPassive,
    /// Transmit error counter past 255: the controller has left the bus.
    BusOff,
}

/// What the controller reports about its health, as the real driver does: the error
/// counters and the confinement state from the status registers (not the last error code),
/// and the frames lost because the receive FIFO was full.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ControllerStatus {
    /// Fault-confinement state.
    pub state: BusState,
    /// Transmit error counter (TEC).
    pub tx_errors: u8,
    /// Receive error counter (REC).
    pub rx_errors: u8,
    /// Frames lost to a full receive FIFO since the last call.
    pub rx_lost: u32,
}

/// A controller that can report its status (implemented by the board's FDCAN adapter and the
/// simulator's bus).
pub trait ControllerHealth {
    /// The current status; `rx_lost` counts since the previous call.
    fn status(&mut self) -> ControllerStatus;
}

/// Frames the port holds while the controller's mailboxes are full.
pub const TX_QUEUE_LEN: usize = 32;

/// Counters of the port (wrapping).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CanStats {
    /// Frames decoded.
    pub received: u32,
    /// Frames that were not messages of this protocol.
    pub malformed: u32,
    /// Last decode error seen.
    pub last_decode_error: Option<DecodeError>,
    /// Frames handed to the controller.
    pub sent: u32,
    /// Frames dropped because the queue was full or could not be built.
    pub dropped: u32,
    /// Error frames and other protocol errors the driver reported (counted, not faults).
    pub bus_errors: u32,
    /// Frames lost because the receive FIFO was full.
    pub rx_lost: u32,
    /// Last status read from the controller.
    pub status: ControllerStatus,
    /// Times the controller went bus-off.
    pub bus_off_events: u32,
}

/// A CAN controller with a transmit queue.
pub struct CanPort<C> {
    can: C,
    queue: Deque<RawFrame, TX_QUEUE_LEN>,
    stats: CanStats,
}

impl<C: Can + ControllerHealth> CanPort<C> {
    /// Read the controller's status; counts lost frames and bus-off entries. Returns the
    /// state.
    pub fn poll_status(&mut self) -> BusState {
        let st = self.can.status();
        self.stats.rx_lost = self.stats.rx_lost.wrapping_add(st.rx_lost);
        if st.state == BusState::BusOff && self.stats.status.state != BusState::BusOff {
            self.stats.bus_off_events = self.stats.bus_off_events.wrapping_add(1);
        }
        self.stats.status = st;
        st.state
    }
}

impl<C: Can> CanPort<C> {
    /// Wrap a started controller (500 kbit/s, accepting standard identifiers).
    pub fn new(can: C) -> Self {
        CanPort {
            can,
            queue: Deque::new(),
            stats: CanStats::default(),
        }
    }

    /// The counters.
    pub fn stats(&self) -> CanStats {
        self.stats
    }

    /// The controller.
    pub fn inner(&mut self) -> &mut C {
        &mut self.can
    }

    /// Read up to [`MAX_RX_PER_TICK`] frames; malformed ones are counted and skipped, and so
    /// are the protocol errors the driver reports through the receive path (an error frame
    /// on the bus is normal CAN life, not a fault: the error counters decide, see
    /// [`Self::poll_status`]).
    pub fn receive(&mut self, out: &mut Vec<Message, MAX_RX_PER_TICK>) {
        // Bounded: at most twice the capacity of reads (malformed frames included).
        for _ in 0..2 * MAX_RX_PER_TICK {
            if out.is_full() {
                break;
            }
            match self.can.receive() {
                Ok(frame) => match Message::from_frame(&frame) {
                    Ok(m) => {
                        self.stats.received = self.stats.received.wrapping_add(1);
                        let _ = out.push(m);
                    }
                    Err(e) => {
                        self.stats.malformed = self.stats.malformed.wrapping_add(1);
                        self.stats.last_decode_error = Some(e);
                    }
                },
                Err(nb::Error::WouldBlock) => break,
                Err(nb::Error::Other(e)) => {
                    let _ = e.kind();
                    self.stats.bus_errors = self.stats.bus_errors.wrapping_add(1);
                    break;
                }
            }
        }
    }

    /// Queue `messages` and hand the controller as many queued frames as it takes.
    /// Returns true when a frame was dropped (the queue was full: the node cannot say what it
    /// must). A controller error on a write keeps the frame queued and is only counted.
    pub fn transmit(&mut self, messages: &[Message]) -> bool {
        let mut error = false;
        for m in messages {
            match m.encode() {
                Ok(f) if self.queue.push_back(f).is_ok() => {}
                _ => {
                    self.stats.dropped = self.stats.dropped.wrapping_add(1);
                    error = true;
                }
            }
        }
        for _ in 0..TX_QUEUE_LEN {
            let Some(raw) = self.queue.pop_front() else {
                break;
            };
            let Some(frame) = raw.to_frame::<C::Frame>() else {
                self.stats.dropped = self.stats.dropped.wrapping_add(1);
                error = true;
                continue;
            };
            match self.can.transmit(&frame) {
                Ok(replaced) => {
                    self.stats.sent = self.stats.sent.wrapping_add(1);
                    // A lower-priority pending frame was pushed out: send it later.
                    if let Some(old) = replaced {
                        let requeued = Message::from_frame(&old)
                            .ok()
                            .and_then(|m| m.encode().ok())
                            .map(|f| self.queue.push_front(f).is_ok());
                        if requeued != Some(true) {
                            self.stats.dropped = self.stats.dropped.wrapping_add(1);
                            error = true;
                        }
                        self.stats.sent = self.stats.sent.wrapping_sub(1);
                    }
                }
                Err(nb::Error::WouldBlock) => {
                    let _ = self.queue.push_front(raw);
                    break;
                }
                Err(nb::Error::Other(_)) => {
                    let _ = self.queue.push_front(raw);
                    self.stats.bus_errors = self.stats.bus_errors.wrapping_add(1);
                    break;
                }
            }
        }
        error
    }
}
