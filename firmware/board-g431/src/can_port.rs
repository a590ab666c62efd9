//! FDCAN1 on the board's transceiver (PA11 RX, PB9 TX; PC11 the transceiver's shutdown
//! input, PC14 the switchable 120 Ω termination).
//!
//! Bit timing (classic CAN, 500 kbit/s): computed at start-up for the kernel clock actually
//! chosen ([`firmware::can_timing::bit_timing`], through [`firmware::clock_choice`]). On the
//! 8 MHz crystal (FDCAN kernel = HSE): prescaler 1, 16 tq = sync 1 + seg1 13 + seg2 2,
//! sample point 87.5 % (CiA 301), SJW 2, tolerated oscillator error 0.485 % (ISO 11898-1's
//! two conditions). On the HSI16 (PLL to 170 MHz, kernel = PCLK1): prescaler 20, 1 + 14 + 2,
//! 88.2 %, 0.457 % — the HSI16's ±1 % exceeds it, so the node speaks but refuses `Enable`.
//!
//! Acceptance: only the identifiers the node reads ([`protocol::accepted_by_ankle`]) into
//! FIFO 0; every other standard frame, every extended and every remote frame is rejected by
//! the global filter, so other traffic cannot fill the receive path.
//!
//! Errors: the driver reports the last error code through the receive path; the adapter
//! counts those (`CanStats::bus_errors`) and nothing more. The node's `CanBus` fault comes
//! from the protocol status register (bus-off) read every tick; error-passive is reported in
//! the stats. Recovery: the controller's automatic bus-off recovery is on (it rejoins after
//! 128 × 11 recessive bits, ISO 11898-1); the node goes `Safe` at bus-off and stays there
//! until the host enables it again. Frames lost to a full hardware FIFO (FDCAN_IR.RF0L) are
//! counted every tick.

use core::num::{NonZeroU16, NonZeroU8};

use embassy_stm32::can::config::{GlobalFilter, NominalBitTiming, NonMatchingFilter};
use embassy_stm32::can::filter::{Action, FilterType, StandardFilter, StandardFilterSlot};
use embassy_stm32::can::{BufferedCanReceiver, BufferedCanSender, CanConfigurator, Frame};
use firmware::can_timing::BitTiming;
use firmware::drivers::can::{BusState, ControllerHealth, ControllerStatus};
use protocol::NodeId;

/// Termination of the bus at this board (a parameter: set for the two nodes at the ends of
/// the bus only).
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum Termination {
    /// The on-board 120 Ω switched in (PC14 high).
    OnBoard,
    /// Terminated elsewhere (PC14 low).
    External,
}

/// The library's bit timing as the driver's registers: `None` when a field does not fit
/// (never for a timing computed within [`firmware::can_timing::FDCAN_NOMINAL`]).
pub fn nominal(t: BitTiming) -> Option<NominalBitTiming> {
    Some(NominalBitTiming {
        prescaler: NonZeroU16::new(t.prescaler)?,
        seg1: NonZeroU8::new(u8::try_from(t.seg1_tq).ok()?)?,
        seg2: NonZeroU8::new(u8::try_from(t.seg2_tq).ok()?)?,
        sync_jump_width: NonZeroU8::new(u8::try_from(t.sjw_tq).ok()?)?,
    })
}

/// Bit timing (`None`: no timing fits the clock; the controller keeps its reset timing and
/// the node, refused the power stage, says so), global filter and acceptance filters for
/// `node`.
pub fn configure(cfg: &mut CanConfigurator<'_>, node: NodeId, timing: Option<BitTiming>) {
    let mut config = cfg.config();
    if let Some(t) = timing.and_then(nominal) {
        config = config.set_nominal_bit_timing(t);
    }
    let config = config
        .set_automatic_bus_off_recovery(true)
        .set_global_filter(GlobalFilter {
            handle_standard_frames: NonMatchingFilter::Reject,
            handle_extended_frames: NonMatchingFilter::Reject,
            reject_remote_standard_frames: true,
            reject_remote_extended_frames: true,
        });
    cfg.set_config(config);
    let ids = protocol::accepted_by_ankle(node).unwrap_or([0; protocol::ACCEPTED_BY_ANKLE]);
    const SLOTS: [StandardFilterSlot; 4] = [
        StandardFilterSlot::_0,
        StandardFilterSlot::_1,
        StandardFilterSlot::_2,
        StandardFilterSlot::_3,
    ];
    for (slot, pair) in SLOTS.iter().zip(ids.chunks(2)) {
        let filter = match pair {
            [a, b] => FilterType::DedicatedDual(std_id(*a), std_id(*b)),
            [a] => FilterType::DedicatedSingle(std_id(*a)),
            _ => FilterType::Disabled,
        };
        cfg.properties().set_standard_filter(
            *slot,
            StandardFilter {
                filter,
                action: Action::StoreInFifo0,
            },
        );
    }
}

fn std_id(raw: u16) -> embedded_can::StandardId {
    embedded_can::StandardId::new(raw).unwrap_or(embedded_can::StandardId::ZERO)
}

/// Errors of the adapter (the driver's protocol errors, counted by the port).
#[derive(Debug, Clone, Copy)]
pub struct BoardCanError;

impl embedded_can::Error for BoardCanError {
    fn kind(&self) -> embedded_can::ErrorKind {
        embedded_can::ErrorKind::Other
    }
}

/// embassy's buffered FDCAN seen as a non-blocking `embedded_can::nb::Can` with its status.
pub struct BoardCan {
    /// Sender half.
    pub tx: BufferedCanSender,
    /// Receiver half.
    pub rx: BufferedCanReceiver,
}

impl embedded_can::nb::Can for BoardCan {
    type Frame = Frame;
    type Error = BoardCanError;

    fn transmit(&mut self, frame: &Frame) -> nb::Result<Option<Frame>, BoardCanError> {
        match self.tx.try_write(*frame) {
            Ok(()) => Ok(None),
            Err(_) => Err(nb::Error::WouldBlock),
        }
    }

    fn receive(&mut self) -> nb::Result<Frame, BoardCanError> {
        match self.rx.try_receive() {
            Ok(Ok(envelope)) => Ok(envelope.frame),
            Ok(Err(_)) => Err(nb::Error::Other(BoardCanError)),
            Err(_) => Err(nb::Error::WouldBlock),
        }
    }
}

impl ControllerHealth for BoardCan {
    fn status(&mut self) -> ControllerStatus {
        let regs = embassy_stm32::pac::FDCAN1;
        let ecr = regs.ecr().read();
        let psr = regs.psr().read();
        let state = match (psr.bo(), psr.ep()) {
            (true, _) => BusState::BusOff,
            (false, true) => BusState::ErrorPassive,
            (false, false) => BusState::ErrorActive,
        };
        // RF0L: a frame was lost because FIFO 0 was full; write 1 to clear.
        let lost = regs.ir().read().rfl(0);
        if lost {
            regs.ir().write(|w| w.set_rfl(0, true));
        }
        ControllerStatus {
            state,
            tx_errors: ecr.tec(),
            rx_errors: ecr.rec(),
            rx_lost: u32::from(lost),
        }
    }
}
