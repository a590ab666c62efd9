//! Clock start-up that cannot hang: before `embassy_stm32::init` (the core still on the
//! HSI16, as out of reset) the crystal is switched on and awaited for at most
//! [`HSE_TIMEOUT_CYCLES`]; if it started, the core runs from it for one measurement window
//! in which LPTIM1, clocked by the HSI16, counts the reference: the cycle counter's count of
//! crystal cycles over [`REFERENCE_WINDOW_CYCLES`] HSI16 cycles gives the crystal's frequency
//! (to the HSI16's ±1 %). The core goes back to the HSI16, the timer is put back, and
//! [`firmware::clock_choice::choose`] decides; [`config_for`] turns the choice into embassy's
//! RCC configuration (PLL to 170 MHz from the crystal or from the HSI16; the FDCAN from the
//! crystal, or from PCLK1 on the HSI16). Every wait is a bounded poll.

use cortex_m::peripheral::DWT;
use embassy_stm32::pac::flash::vals::Latency;
use embassy_stm32::pac::lptim::vals::{ClockSource as LptimClock, Presc};
use embassy_stm32::pac::rcc::vals::{Lptimsel, Sw};
use embassy_stm32::pac::{FLASH, LPTIM1, RCC};
use embassy_stm32::{rcc, Config};
use firmware::clock_choice::{
    measured_hz, ClockChoice, ClockPlan, CrystalObservation, B_G431B_ESC1,
};
use protocol::ClockSource;

/// The internal reference's nominal frequency \[Hz\].
const HSI16_HZ: u32 = 16_000_000;
/// Longest wait for HSERDY \[core cycles at 16 MHz\]: 20 ms (a crystal starts in about 2 ms;
/// DS12589's t_SU(HSE) not read here).
pub const HSE_TIMEOUT_CYCLES: u32 = 320_000;
/// Measurement window \[HSI16 cycles\]: 10 ms.
pub const REFERENCE_WINDOW_CYCLES: u32 = 160_000;
/// Polls of a clock-switch status bit before giving up.
const SWITCH_POLLS: u32 = 10_000;
/// Longest measurement window \[crystal cycles\]: 10 ms of a 48 MHz crystal (the HSE's
/// upper limit) and a margin; the window is abandoned past it.
const WINDOW_LIMIT_CYCLES: u32 = 1_000_000;

/// Switch the system clock to `sw` and wait (bounded) for the switch; true when done.
fn switch_sysclk(sw: Sw) -> bool {
    RCC.cfgr().modify(|w| w.set_sw(sw));
    (0..SWITCH_POLLS).any(|_| RCC.cfgr().read().sws() == sw)
}

/// LPTIM1's counter, read until two reads agree (its clock is asynchronous to the bus).
fn lptim_count() -> u16 {
    let mut last = LPTIM1.cnt().read().cnt();
    for _ in 0..8 {
        let now = LPTIM1.cnt().read().cnt();
        if now == last {
            return now;
        }
        last = now;
    }
    last
}

/// Crystal cycles (the core's cycle counter on the crystal) in
/// [`REFERENCE_WINDOW_CYCLES`] of the HSI16 (LPTIM1); `None` when the window did not close
/// within its bound.
fn count_window() -> Option<(u32, u32)> {
    let start_ref = lptim_count();
    let start = DWT::cycle_count();
    let mut reference: u32 = 0;
    let mut last = start_ref;
    loop {
        let now_ref = lptim_count();
        let now = DWT::cycle_count();
        // The 16-bit counter wraps every 4.1 ms; each turn of this loop is far shorter.
        reference = reference.saturating_add(u32::from(now_ref.wrapping_sub(last)));
        last = now_ref;
        let crystal = now.wrapping_sub(start);
        if reference >= REFERENCE_WINDOW_CYCLES {
            return Some((crystal, reference));
        }
        if crystal > WINDOW_LIMIT_CYCLES {
            return None;
        }
    }
}

/// Switch the crystal on, await it, measure it; leave the core on the HSI16, the crystal on
/// only when it started. The DWT cycle counter must be running (`main` starts it first).
pub fn observe_crystal() -> CrystalObservation {
    RCC.cr().modify(|w| w.set_hseon(true));
    let start = DWT::cycle_count();
    let mut ready = false;
    while DWT::cycle_count().wrapping_sub(start) < HSE_TIMEOUT_CYCLES {
        if RCC.cr().read().hserdy() {
            ready = true;
            break;
        }
    }
    if !ready {
        RCC.cr().modify(|w| w.set_hseon(false));
        return CrystalObservation::TimedOut;
    }
    // LPTIM1 on the HSI16, free-running over its 16 bits.
    RCC.ccipr().modify(|w| w.set_lptim1sel(Lptimsel::HSI));
    RCC.apb1enr1().modify(|w| w.set_lptim1en(true));
    LPTIM1.cfgr().write(|w| {
        w.set_cksel(LptimClock::INTERNAL);
        w.set_presc(Presc::DIV1);
    });
    LPTIM1.cr().write(|w| w.set_enable(true));
    // ARR (reset value 1) is written only while enabled and takes effect through the timer's
    // clock domain: wait (bounded) for ARROK before counting, else the first counts wrap at 1.
    LPTIM1.arr().write(|w| w.set_arr(u16::MAX));
    let _ = (0..SWITCH_POLLS).any(|_| LPTIM1.isr().read().arrok());
    LPTIM1.icr().write(|w| w.set_arrokcf(true));
    LPTIM1.cr().write(|w| {
        w.set_enable(true);
        w.set_cntstrt(true);
    });
    // Two wait states cover any HSE up to 48 MHz; embassy's init sets its own after.
    FLASH.acr().modify(|w| w.set_latency(Latency::WS2));
    let counted = if switch_sysclk(Sw::HSE) {
        let window = count_window();
        // Back on the HSI16 (on at reset, never switched off).
        let _ = switch_sysclk(Sw::HSI);
        window
    } else {
        None
    };
    LPTIM1.cr().write(|w| w.set_enable(false));
    RCC.apb1enr1().modify(|w| w.set_lptim1en(false));
    RCC.ccipr().modify(|w| w.set_lptim1sel(Lptimsel::PCLK1));
    let measured = counted
        .and_then(|(crystal, reference)| measured_hz(crystal, reference, HSI16_HZ))
        .unwrap_or(0);
    CrystalObservation::Started {
        measured_hz: measured,
    }
}

/// Switch the crystal off again when the choice does not use it.
pub fn release_unused_crystal(choice: &ClockChoice) {
    if choice.source != ClockSource::Crystal {
        RCC.cr().modify(|w| w.set_hseon(false));
    }
}

/// PLL input frequency \[Hz\]: every source is divided down to it, then × 85 ÷ 2 = 170 MHz.
const PLL_INPUT_HZ: u32 = 4_000_000;

/// Every crystal the plan may choose divides into the PLL input by 1 to 12 (a crystal of
/// 4 to 48 MHz in 4 MHz steps).
const fn crystals_fit_the_pll(plan: &ClockPlan) -> bool {
    let mut i = 0;
    while i < plan.crystals.len() {
        let hz = plan.crystals[i].nominal_hz;
        if !hz.is_multiple_of(PLL_INPUT_HZ) || hz / PLL_INPUT_HZ == 0 || hz / PLL_INPUT_HZ > 12 {
            return false;
        }
        i += 1;
    }
    true
}
const _: () = assert!(crystals_fit_the_pll(&B_G431B_ESC1));

/// The PLL's input divider for a crystal of `hz` (a multiple of 4 MHz, checked above).
fn crystal_prediv(hz: u32) -> rcc::PllPreDiv {
    match hz / PLL_INPUT_HZ {
        1 => rcc::PllPreDiv::DIV1,
        3 => rcc::PllPreDiv::DIV3,
        4 => rcc::PllPreDiv::DIV4,
        5 => rcc::PllPreDiv::DIV5,
        6 => rcc::PllPreDiv::DIV6,
        7 => rcc::PllPreDiv::DIV7,
        8 => rcc::PllPreDiv::DIV8,
        9 => rcc::PllPreDiv::DIV9,
        10 => rcc::PllPreDiv::DIV10,
        11 => rcc::PllPreDiv::DIV11,
        12 => rcc::PllPreDiv::DIV12,
        _ => rcc::PllPreDiv::DIV2,
    }
}

/// embassy's RCC configuration for the choice: 170 MHz either way, boost mode, ADC12 on
/// SYSCLK; PLL input 4 MHz (the crystal ÷ its MHz/4: 8 MHz ÷2, 24 MHz ÷6; the HSI16 ÷4) × 85 ÷ 2; FDCAN from the crystal,
/// or from PCLK1 (170 MHz) on the internal oscillator.
pub fn config_for(choice: &ClockChoice) -> Config {
    let mut config = Config::default();
    let (source, prediv) = if choice.source == ClockSource::Crystal {
        config.rcc.hse = Some(rcc::Hse {
            freq: embassy_stm32::time::Hertz(choice.oscillator_hz),
            mode: rcc::HseMode::Oscillator,
        });
        config.rcc.mux.fdcansel = rcc::mux::Fdcansel::HSE;
        (rcc::PllSource::HSE, crystal_prediv(choice.oscillator_hz))
    } else {
        config.rcc.mux.fdcansel = rcc::mux::Fdcansel::PCLK1;
        (rcc::PllSource::HSI, rcc::PllPreDiv::DIV4)
    };
    config.rcc.pll = Some(rcc::Pll {
        source,
        prediv,
        mul: rcc::PllMul::MUL85,
        divp: None,
        divq: None,
        divr: Some(rcc::PllRDiv::DIV2),
    });
    config.rcc.sys = rcc::Sysclk::PLL1_R;
    config.rcc.boost = true;
    config.rcc.mux.adc12sel = rcc::mux::Adcsel::SYS;
    config
}
