//! The ankle node on ST's B-G431B-ESC1 (STM32G431CB at 170 MHz, FDCAN1 at 500 kbit/s).
//!
//! One embassy task runs the control loop at 1 kHz: [`firmware::runner::AnkleDrivers::step`]
//! reads the encoder (SPI1) and the contact switch, drains the CAN receive buffer, ticks the
//! node, drives the actuator (TIM1 PWM + direction pin) and queues the node's frames on the
//! buffered FDCAN driver. The DWT cycle counter measures every step; the worst case is logged
//! through defmt once a second.
//!
//! Which ankle this is comes from the build: `ANKLE_SIDE=right cargo run --release` for the
//! right ankle, left otherwise.
//!
//! Pin assignment (check against the board's user manual UM2516 and your wiring before
//! flashing; the inverter pins of the ESC board are reused for a brushed string motor):
//!
//! | function | pin |
//! | --- | --- |
//! | FDCAN1 RX / TX (on-board transceiver) | PA11 / PB9 |
//! | encoder SPI1 SCK / MISO / MOSI, chip select | PB3 / PB4 / PB5, PA15 |
//! | contact switch (to ground, pull-up) | PB6 |
//! | motor PWM (TIM1_CH1, 20 kHz) / direction | PA8 / PB7 |
#![no_std]
#![no_main]

use defmt_rtt as _;
use panic_probe as _;

use embassy_executor::Spawner;
use embassy_stm32::can::{
    self, BufferedCanReceiver, BufferedCanSender, Frame, OperatingMode, RxBuf, TxBuf,
};
use embassy_stm32::gpio::{Input, Level, Output, OutputType, Pull, Speed};
use embassy_stm32::peripherals::FDCAN1;
use embassy_stm32::spi::{self, Spi};
use embassy_stm32::time::{khz, mhz};
use embassy_stm32::timer::low_level::CountingMode;
use embassy_stm32::timer::simple_pwm::{PwmPin, SimplePwm};
use embassy_stm32::{bind_interrupts, rcc, Config};
use embassy_time::{Duration, Ticker};
use embedded_hal_bus::spi::ExclusiveDevice;
use firmware::drivers::actuator::{PwmDirActuator, PwmDirGains};
use firmware::drivers::can::CanPort;
use firmware::drivers::contact::{ActiveLevel, ContactSwitch};
use firmware::drivers::encoder::MagneticEncoder;
use firmware::runner::AnkleDrivers;
use firmware::sensors::AngleCalibration;
use firmware::{AnkleNode, Instant, Monotonic, NodeConfig};
use protocol::NodeId;

bind_interrupts!(struct Irqs {
    FDCAN1_IT0 => can::IT0InterruptHandler<FDCAN1>;
    FDCAN1_IT1 => can::IT1InterruptHandler<FDCAN1>;
});

/// Core clock [Hz].
const SYSCLK_HZ: u32 = 170_000_000;
/// Budget of one control tick [cycles]: 2 % of the core at 1 kHz.
const TICK_BUDGET_CYCLES: u32 = 3_400;

/// Encoder zero: counts at ankle angle 0 (set after mounting the magnet).
const CALIBRATION: AngleCalibration = AngleCalibration {
    zero_counts: 0,
    reversed: false,
};

fn node_id() -> NodeId {
    match option_env!("ANKLE_SIDE") {
        Some("right") => NodeId::RightAnkle,
        _ => NodeId::LeftAnkle,
    }
}

/// embassy-time as the node's monotonic clock.
struct EmbassyClock;

impl Monotonic for EmbassyClock {
    fn now(&mut self) -> Instant {
        Instant::from_micros(embassy_time::Instant::now().as_micros())
    }
}

/// Errors of the buffered FDCAN adapter.
#[derive(Debug, Clone, Copy)]
enum BoardCanError {
    /// The controller reported a bus error (stuff, form, ACK, CRC, bus-off ...).
    Bus,
}

impl embedded_can::Error for BoardCanError {
    fn kind(&self) -> embedded_can::ErrorKind {
        embedded_can::ErrorKind::Other
    }
}

/// embassy's buffered FDCAN seen as a non-blocking `embedded_can::nb::Can`.
struct BoardCan {
    tx: BufferedCanSender,
    rx: BufferedCanReceiver,
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
            Ok(Err(_)) => Err(nb::Error::Other(BoardCanError::Bus)),
            Err(_) => Err(nb::Error::WouldBlock),
        }
    }
}

fn clocks() -> Config {
    let mut config = Config::default();
    // HSI 16 MHz / 4 × 85 / 2 = 170 MHz, boost mode.
    config.rcc.pll = Some(rcc::Pll {
        source: rcc::PllSource::HSI,
        prediv: rcc::PllPreDiv::DIV4,
        mul: rcc::PllMul::MUL85,
        divp: None,
        divq: None,
        divr: Some(rcc::PllRDiv::DIV2),
    });
    config.rcc.sys = rcc::Sysclk::PLL1_R;
    config.rcc.boost = true;
    config.rcc.mux.fdcansel = rcc::mux::Fdcansel::PCLK1;
    config
}

#[embassy_executor::main]
async fn main(_spawner: Spawner) {
    let p = embassy_stm32::init(clocks());
    let id = node_id();
    defmt::info!("ankle node {} starting", id);

    // CAN: 500 kbit/s classic, buffered.
    let mut cfg = can::CanConfigurator::new(p.FDCAN1, p.PA11, p.PB9, Irqs);
    cfg.set_bitrate(protocol::BITRATE_BPS);
    let can = cfg.start(OperatingMode::NormalOperationMode);
    let (Some(tx_buf), Some(rx_buf)) = (
        cortex_m::singleton!(: TxBuf<32> = TxBuf::<32>::new()),
        cortex_m::singleton!(: RxBuf<16> = RxBuf::<16>::new()),
    ) else {
        defmt::panic!("CAN buffers taken twice");
    };
    let buffered = can.buffered(tx_buf, rx_buf);
    let board_can = BoardCan {
        tx: buffered.writer(),
        rx: buffered.reader(),
    };

    // Encoder on SPI1 (mode 1, 10 MHz: the AS5047P maximum).
    let mut spi_cfg = spi::Config::default();
    spi_cfg.frequency = mhz(10);
    spi_cfg.mode = spi::MODE_1;
    let spi_bus = Spi::new_blocking(p.SPI1, p.PB3, p.PB5, p.PB4, spi_cfg);
    let cs = Output::new(p.PA15, Level::High, Speed::VeryHigh);
    // Infallible: the chip-select pin cannot fail.
    let Ok(spi_dev) = ExclusiveDevice::new_no_delay(spi_bus, cs);
    let encoder = MagneticEncoder::new(spi_dev, CALIBRATION);

    // Contact switch: to ground, internal pull-up, 3 ms debounce.
    let contact = ContactSwitch::new(Input::new(p.PB6, Pull::Up), ActiveLevel::Low, 3);

    // Actuator: TIM1_CH1 PWM at 20 kHz + direction pin.
    let pwm = SimplePwm::new(
        p.TIM1,
        Some(PwmPin::new(p.PA8, OutputType::PushPull)),
        None,
        None,
        None,
        khz(20),
        CountingMode::EdgeAlignedUp,
    );
    let mut channels = pwm.split();
    channels.ch1.enable();
    let dir = Output::new(p.PB7, Level::Low, Speed::Low);
    let actuator = PwmDirActuator::new(channels.ch1, dir, PwmDirGains::default());

    let mut config = NodeConfig::nominal(id);
    config.build_id = 0x0001_0000;
    let node = match AnkleNode::new(config) {
        Ok(n) => n,
        Err(e) => defmt::panic!("node config: {}", e),
    };
    let mut drivers = AnkleDrivers::new(
        node,
        encoder,
        contact,
        actuator,
        CanPort::new(board_can),
        EmbassyClock,
    );

    // Cycle counter for the per-tick cost.
    let Some(mut core) = cortex_m::Peripherals::take() else {
        defmt::panic!("core peripherals taken twice");
    };
    core.DCB.enable_trace();
    core.DWT.enable_cycle_counter();

    let mut ticker = Ticker::every(Duration::from_hz(1_000));
    let mut worst: u32 = 0;
    let mut n: u32 = 0;
    loop {
        let start = cortex_m::peripheral::DWT::cycle_count();
        let out = drivers.step();
        let cycles = cortex_m::peripheral::DWT::cycle_count().wrapping_sub(start);
        worst = worst.max(cycles);
        n = n.wrapping_add(1);
        if n % 1_000 == 0 {
            defmt::info!(
                "state {} phase {} faults {:#06x}; worst tick {} cycles (budget {}, {} MHz)",
                out.state,
                out.phase,
                drivers.node.faults().bits(),
                worst,
                TICK_BUDGET_CYCLES,
                SYSCLK_HZ / 1_000_000
            );
            worst = 0;
        }
        ticker.next().await;
    }
}
