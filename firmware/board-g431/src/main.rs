//! The ankle node on ST's B-G431B-ESC1 (STM32G431CB at 170 MHz from its crystal, or from
//! the internal oscillator when the crystal is absent or wrong; FDCAN1 at 500 kbit/s).
//!
//! One embassy task runs the control loop at 1 kHz: [`firmware::runner::AnkleDrivers::step`]
//! reads the ankle encoder (PWM output on PA15/TIM2) and the contact switch, drains the CAN
//! receive buffer and reads the controller's status, ticks the node, drives the spool motor
//! (two half-bridges on TIM1, spool encoder on TIM4, current from the shunt amplifiers) and
//! queues the node's frames. The independent watchdog is petted only when the tick ran on
//! time ([`firmware::supervisor::LoopSupervisor`]). Pin map, power-up and fault states:
//! `docs/firmware.md` ("Board: B-G431B-ESC1").
//!
//! Which ankle this is comes from the build: `ANKLE_SIDE=right cargo run --release` for the
//! right ankle, left otherwise. `CAN_TERMINATION=on` switches the on-board 120 Ω in (the two
//! nodes at the ends of the bus only).
#![no_std]
#![no_main]

mod boot_pin;
mod can_port;
mod clock_start;
mod crash;
mod current_sense;
mod encoders;
mod overcurrent_break;
mod power_stage;
mod reset_cause;

use defmt_rtt as _;

// defmt log lines carry the embassy uptime in microseconds.
defmt::timestamp!("{=u64:us}", embassy_time::Instant::now().as_micros());

use embassy_embedded_hal::adapter::BlockingAsync;
use embassy_executor::Spawner;
use embassy_stm32::adc::{Adc, AdcConfig};
use embassy_stm32::can::{self, OperatingMode, RxBuf, TxBuf};
use embassy_stm32::flash::Flash;
use embassy_stm32::gpio::{Input, Level, Output, OutputType, Pull, Speed};
use embassy_stm32::opamp::{OpAmp, OpAmpGain, OpAmpSpeed};
use embassy_stm32::peripherals::{FDCAN1, TIM2};
use embassy_stm32::time::{hz, khz};
use embassy_stm32::timer::complementary_pwm::{ComplementaryPwm, ComplementaryPwmPin};
use embassy_stm32::timer::low_level::CountingMode;
use embassy_stm32::timer::pwm_input::PwmInput;
use embassy_stm32::timer::qei::{self, Qei};
use embassy_stm32::timer::simple_pwm::PwmPin;
use embassy_stm32::wdg::IndependentWatchdog;
use embassy_stm32::{bind_interrupts, timer};
use embassy_time::{Duration, Ticker};
use firmware::clock_choice::{choose, B_G431B_ESC1};
use firmware::drivers::can::CanPort;
use firmware::drivers::contact::{ActiveLevel, ContactSwitch};
use firmware::drivers::encoder::AngleSensor;
use firmware::drivers::pwm_encoder::PwmAngleEncoder;
use firmware::drivers::spool_motor::{SpoolMotor, SpoolMotorConfig};
use firmware::node::NodeRequest;
use firmware::param_store::ParamStore;
use firmware::runner::AnkleDrivers;
use firmware::sensors::AngleCalibration;
use firmware::supervisor::LoopSupervisor;
use firmware::{AnkleNode, Instant, Monotonic, NodeConfig};
use protocol::NodeId;

use crate::can_port::{BoardCan, Termination};
use crate::current_sense::ShuntCurrent;
use crate::encoders::{AnklePwmCapture, SpoolQei, ENCODER_PWM_PERIOD_TICKS, PWM_CAPTURE_TICK_HZ};
use crate::power_stage::Tim1Bridges;

bind_interrupts!(struct Irqs {
    FDCAN1_IT0 => can::IT0InterruptHandler<FDCAN1>;
    FDCAN1_IT1 => can::IT1InterruptHandler<FDCAN1>;
    TIM2 => timer::CaptureCompareInterruptHandler<TIM2>;
});

/// Core clock [Hz].
const SYSCLK_HZ: u32 = 170_000_000;
/// Budget of one control tick [cycles]: 2 % of the core at 1 kHz.
const TICK_BUDGET_CYCLES: u32 = 3_400;
/// Control period [µs].
const PERIOD_US: u64 = 1_000;
/// A tick may start this late and still count as on time [µs].
const MAX_LATE_US: u64 = 500;
/// A tick may last this long and still count as on time [µs] (the budget is 20 µs; the
/// margin covers the encoder and ADC reads and CAN queueing).
const MAX_TICK_US: u64 = 200;
/// Independent watchdog timeout [µs]: 50 ticks without a pet on time reset the chip. Longer
/// than a flash page erase (SaveParams stalls the core while it erases).
const WATCHDOG_TIMEOUT_US: u32 = 50_000;

/// Flash kept for parameters and calibration [offsets from the flash base]: the last four
/// 2 KiB pages of the 128 KiB. The linker script (memory.x) gives code only the first
/// 120 KiB, so the binary can never overlap this range.
const PARAM_FLASH: core::ops::Range<u32> = 0x1E000..0x20000;

/// Encoder zero used until one is calibrated and stored (CalibrateEncoderZero, SaveParams).
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

fn termination() -> Termination {
    match option_env!("CAN_TERMINATION") {
        Some("on") => Termination::OnBoard,
        _ => Termination::External,
    }
}

/// embassy-time as the node's monotonic clock.
struct EmbassyClock;

impl Monotonic for EmbassyClock {
    fn now(&mut self) -> Instant {
        Instant::from_micros(embassy_time::Instant::now().as_micros())
    }
}

#[embassy_executor::main]
async fn main(_spawner: Spawner) {
    // Cycle counter first: it times the crystal's start-up and measures it.
    let Some(mut core) = cortex_m::Peripherals::take() else {
        defmt::panic!("core peripherals taken twice");
    };
    core.DCB.enable_trace();
    core.DWT.enable_cycle_counter();
    // The clock: the crystal awaited (bounded) and measured against the HSI16, then the
    // choice (crystal, or the HSI16 with the power stage refused when the CAN timing cannot
    // tolerate it). The power stage's pins are inputs at reset; TIM1 is configured with its
    // main output disabled below, before any other peripheral.
    let observed = clock_start::observe_crystal();
    let clock = choose(&B_G431B_ESC1, observed);
    clock_start::release_unused_crystal(&clock);
    let p = embassy_stm32::init(clock_start::config_for(&clock));
    // PB8 (contact switch) doubles as BOOT0: make the boot mode independent of it first
    // (programs the option bytes and resets once on a board with factory option bytes).
    let boot_pin = boot_pin::ignore_boot0_pin();
    let cause = reset_cause::read_and_clear();
    let id = node_id();
    defmt::info!(
        "ankle node {} starting, reset cause {}, BOOT0 pin {}",
        id,
        cause,
        boot_pin
    );
    if matches!(
        cause,
        protocol::ResetCause::IndependentWatchdog | protocol::ResetCause::WindowWatchdog
    ) {
        defmt::warn!("the last reset was the watchdog's: the control loop stopped running on time");
    }
    defmt::info!(
        "crystal {} -> clock {}: CAN kernel {} Hz, timing {}, tolerates {} ppm, oscillator {} ppm",
        observed,
        clock.source,
        clock.can_kernel_hz,
        clock.timing,
        clock.tolerated_ppm,
        clock.oscillator_ppm
    );
    if let Some(r) = clock.refusal {
        defmt::warn!("power stage refused on this clock: {}", r);
    }

    // Power stage: phases U and V as two half-bridges, W held low; off until driven.
    let pwm = ComplementaryPwm::new(
        p.TIM1,
        Some(PwmPin::new(p.PA8, OutputType::PushPull)),
        Some(ComplementaryPwmPin::new(p.PC13, OutputType::PushPull)),
        Some(PwmPin::new(p.PA9, OutputType::PushPull)),
        Some(ComplementaryPwmPin::new(p.PA12, OutputType::PushPull)),
        None,
        None,
        None,
        None,
        khz(20),
        CountingMode::CenterAlignedBothInterrupts,
    );
    let bridges = Tim1Bridges::new(pwm);
    let _phase_w_high = Output::new(p.PA10, Level::Low, Speed::Low);
    let _phase_w_low = Output::new(p.PB15, Level::Low, Speed::Low);

    // Parameters and encoder zero from flash (defaults when nothing is stored).
    let mut store = match ParamStore::new(
        BlockingAsync::new(Flash::new_blocking(p.FLASH)),
        PARAM_FLASH,
    ) {
        Ok(s) => s,
        Err(e) => defmt::panic!("parameter flash range: {}", e),
    };
    let loaded = store.load(CALIBRATION).await;
    defmt::info!(
        "parameters from {}, encoder zero {} from {}",
        loaded.params_source,
        loaded.calibration.zero_counts,
        loaded.calibration_source
    );

    // Current sense: OPAMP1 (phase U shunt) and OPAMP2 (phase V) as internal PGAs with gain
    // 16, the gain network's ground on the VINM0 bias pins (PA3, PA5), after the board's input
    // divider (4/7): 64/7 in all, as SimpleFOC's B-G431B-ESC1 driver programs them. The board
    // has no external feedback network, so standalone mode would run open loop.
    let mut op1 = OpAmp::new(p.OPAMP1, OpAmpSpeed::Normal);
    let mut op2 = OpAmp::new(p.OPAMP2, OpAmpSpeed::Normal);
    let out1 = op1.pga_biased_ext(p.PA1, p.PA3, p.PA2, OpAmpGain::Mul16);
    let out2 = op2.pga_biased_ext(p.PA7, p.PA5, p.PA6, OpAmpGain::Mul16);
    let current = ShuntCurrent::new(
        Adc::new(p.ADC1, AdcConfig::default()),
        Adc::new(p.ADC2, AdcConfig::default()),
        out1,
        out2,
    );
    let (ou, ov) = current.offsets();
    defmt::info!("current-sense offsets {} / {} counts", ou, ov);
    // Hardware over-current backstop: COMP1/COMP2 on the shunt inputs (PA1, PA7, analogue
    // since the op-amps took them) against DAC3, into TIM1's break input. The stage is off.
    overcurrent_break::arm();
    defmt::info!(
        "over-current break armed: {} A, DAC3 code {}",
        overcurrent_break::BREAK_CURRENT_A,
        overcurrent_break::BREAK_CODE
    );

    // Spool encoder: TIM4 in encoder mode on the Hall/encoder connector (PB6, PB7).
    let qei_cfg = qei::Config {
        ch1_pull: Pull::Up,
        ch2_pull: Pull::Up,
        ..Default::default()
    };
    let spool = SpoolQei::new(Qei::new(p.TIM4, p.PB6, p.PB7, qei_cfg));
    let actuator = SpoolMotor::new(bridges, spool, current, SpoolMotorConfig::default());

    // Ankle encoder: PWM output on the PWM pad (PA15, TIM2_CH1).
    let capture = AnklePwmCapture::new(PwmInput::new_ch1(
        p.TIM2,
        p.PA15,
        Irqs,
        Pull::Down,
        hz(PWM_CAPTURE_TICK_HZ),
    ));
    let encoder = PwmAngleEncoder::new(capture, loaded.calibration, ENCODER_PWM_PERIOD_TICKS, 2);

    // Contact switch: the connector's third pin (PB8, to ground, pull-up), 3 ms debounce.
    let contact = ContactSwitch::new(Input::new(p.PB8, Pull::Up), ActiveLevel::Low, 3);

    // CAN: transceiver enabled (PC11 low), termination as built, the bit timing computed for
    // the chosen clock, filters for this node's identifiers only.
    let _can_shutdown = Output::new(p.PC11, Level::Low, Speed::Low);
    let term = termination();
    let _can_term = Output::new(
        p.PC14,
        if term == Termination::OnBoard {
            Level::High
        } else {
            Level::Low
        },
        Speed::Low,
    );
    let mut cfg = can::CanConfigurator::new(p.FDCAN1, p.PA11, p.PB9, Irqs);
    can_port::configure(&mut cfg, id, clock.timing);
    let can = cfg.start(OperatingMode::NormalOperationMode);
    let (Some(tx_buf), Some(rx_buf)) = (
        cortex_m::singleton!(: TxBuf<32> = TxBuf::<32>::new()),
        cortex_m::singleton!(: RxBuf<64> = RxBuf::<64>::new()),
    ) else {
        defmt::panic!("CAN buffers taken twice");
    };
    let buffered = can.buffered(tx_buf, rx_buf);
    let board_can = BoardCan {
        tx: buffered.writer(),
        rx: buffered.reader(),
    };
    defmt::info!("CAN 500 kbit/s, termination {}", term);

    let mut config = NodeConfig::nominal(id);
    config.build_id = u32::from_str_radix(env!("GIT_HASH"), 16).unwrap_or(0);
    config.uid = reset_cause::unique_id();
    config.reset_cause = cause;
    config.params_source = loaded.params_source;
    config.calibration_source = loaded.calibration_source;
    config.clock = clock;
    let mut node = match AnkleNode::new(config) {
        Ok(n) => n,
        Err(e) => defmt::panic!("node config: {}", e),
    };
    node.restore_params(loaded.params);
    let mut drivers = AnkleDrivers::new(
        node,
        encoder,
        contact,
        actuator,
        CanPort::new(board_can),
        EmbassyClock,
    );

    let mut watchdog = IndependentWatchdog::new(p.IWDG, WATCHDOG_TIMEOUT_US);
    watchdog.unleash();
    let mut supervisor = LoopSupervisor::new(PERIOD_US, MAX_LATE_US, MAX_TICK_US);

    let mut ticker = Ticker::every(Duration::from_hz(1_000));
    let mut worst: u32 = 0;
    let mut n: u32 = 0;
    loop {
        let started = EmbassyClock.now();
        let start = cortex_m::peripheral::DWT::cycle_count();
        let out = drivers.step();
        let cycles = cortex_m::peripheral::DWT::cycle_count().wrapping_sub(start);
        if supervisor.tick(started, EmbassyClock.now()) {
            watchdog.pet();
        }
        // SaveParams: the flash erase stalls the core for milliseconds (the supervisor sees a
        // late tick; the 50 ms watchdog covers it).
        if out.request == Some(NodeRequest::SaveParams) {
            let params = *drivers.node.params();
            let cal = drivers.encoder.calibration();
            let ok = store.save(&params, cal).await.is_ok();
            // Logged by the node (`storage_done`).
            drivers.node.storage_done(ok);
            // The stall made the ticker miss deadlines; without a reset it would fire them
            // back to back, ticks microseconds apart, in which the ankle encoder's PWM
            // capture sees no new period (NoSignal → a false EncoderComms fault). Restart
            // the 1 kHz schedule from now instead.
            ticker.reset();
        }
        worst = worst.max(cycles);
        n = n.wrapping_add(1);
        if n.is_multiple_of(1_000) {
            let stats = drivers.can.stats();
            defmt::info!(
                "state {} phase {} faults {:#06x}; worst tick {} cycles (budget {}, {} MHz); late ticks {}; CAN {} TEC {} REC {} lost {} errors {}",
                out.state,
                out.phase,
                drivers.node.faults().bits(),
                worst,
                TICK_BUDGET_CYCLES,
                SYSCLK_HZ / 1_000_000,
                supervisor.late_ticks(),
                stats.status.state,
                stats.status.tx_errors,
                stats.status.rx_errors,
                stats.rx_lost,
                stats.bus_errors
            );
            worst = 0;
        }
        ticker.next().await;
    }
}
