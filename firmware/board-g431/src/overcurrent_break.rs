//! The hardware over-current backstop: the board's phase-U and phase-V shunt signals, through
//! comparators COMP1 and COMP2 against thresholds from DAC3, into TIM1's break input. On a
//! break the timer clears its main output enable (MOE) in hardware, within the break filter's
//! delay and without the CPU: every gate input goes to its idle level (low) — faster than the
//! software limit in `SpoolMotor`, which sees one current sample per 1 ms tick.
//!
//! embassy-stm32 0.6 has no comparator driver and no break configuration, so this is written
//! at register level through its PAC (`embassy_stm32::pac`, stm32-metapac 21, whose register
//! and field documentation cites RM0440). What each write does, and where it comes from:
//!
//! * **Inputs** — COMP1_INP with `INPSEL = 0` is PA1, COMP2_INP with `INPSEL = 0` is PA7
//!   (RM0440 §24.3.2 Table 196; ST's G4 HAL: `COMP_INPUT_PLUS_IO1` "pin PA1 for COMP1, pin PA7
//!   for COMP2"). PA1 and PA7 are the board's shunt-amplifier inputs of phases U and V
//!   (`CURR1_H`, `CURR2_H` in ST's variant file; OPAMP1/OPAMP2 VINP), already analogue from
//!   the op-amps' configuration: the comparators watch the same node as the PGAs.
//! * **Thresholds** — COMP1_INM with `INMSEL = 0b100` is DAC3 channel 1, COMP2_INM with
//!   `INMSEL = 0b100` is DAC3 channel 2 (RM0440 §24.3.2 Table 197; ST's G4 HAL:
//!   `COMP_INPUT_MINUS_DAC3_CH1` "for COMP1/3", `COMP_INPUT_MINUS_DAC3_CH2` "for COMP2/4").
//!   DAC3 is internal-only on the G4: `MODE = 0b011` (normal, internal peripherals only,
//!   buffer off), `HFSEL = 0b10` (AHB above 160 MHz).
//! * **Break** — TIM1_AF1.BKCMP1E / BKCMP2E route comp1_out / comp2_out to the break input
//!   `tim_brk` (OR'ed), not inverted (BKCMPxP = 0); BKINE = 0 (no external BKIN pin);
//!   TIM1_BDTR.BKE = 1, BKP = 1 (active high: a comparator output is high while its input is
//!   above its threshold), BKF = 0b1001 (f_DTS/8, N = 8: the break must last 8 samples at
//!   21.25 MHz, 376 ns, to reject switching ringing), AOE = 0 (MOE stays cleared after a break
//!   until software sets it). On a break the hardware clears MOE; the outputs take their idle
//!   level (OSSI = 1, OISx = OISxN = 0, set by `power_stage`); TIM1_SR.BIF records it.
//!   (RM0440, advanced-control timers: "Using the break function", TIMx_BDTR, TIMx_AF1.)
//! * **Corroboration**: public motor-control code for this board configures the same three
//!   comparators the same way ("COMP1: PA1(+) vs DAC3_CH1(−) — U-phase, COMP2: PA7(+) vs
//!   DAC3_CH2(−) — V-phase, COMP4: PB0(+) vs DAC3_CH2(−) — W-phase", found through the code
//!   index; not an ST document). Phase W is not driven here, so COMP4 is left off.
//!
//! **Threshold**: [`BREAK_CURRENT_A`] = 12 A through either shunt (3 × the 4 A software
//! limit): the shunt voltage reaches the pin through the board's input network (R64 22 kΩ to
//! 3.3 V, R67 1.5 kΩ to the shunt, R80 2.2 kΩ to ground, per the third-party transcription of
//! the MB1419 schematic cited in docs/firmware.md), `V_pin = V_bias + k·R_shunt·I` with
//! `V_bias` = 0.1286 V and `k` = 4/7; at 12 A that is 0.1491 V, DAC code 185. The sign: with
//! the sign–magnitude drive the leg held low carries the motor current downwards through its
//! shunt (positive), so COMP2 (phase V) watches positive duty and COMP1 (phase U) negative
//! duty; a shoot-through in either leg is positive on its shunt. The network, the bias and
//! the comparator's offset (a few mV against 1.7 mV per ampere) are unverified: **bring-up
//! item 15** measures the trip current.
//!
//! Nothing here has run on a board: it cross-builds and passes clippy; QEMU has no STM32G4.

use embassy_stm32::pac;
use embassy_stm32::pac::comp::vals::{Hysteresis, Inm, Polarity};
use embassy_stm32::pac::dac::vals::Mode as DacMode;
use embassy_stm32::pac::timer::vals::{Bkinp, Bkp, FilterValue};

use crate::current_sense::SHUNT_OHM;

/// Trip current through either shunt [A].
pub const BREAK_CURRENT_A: f32 = 12.0;
/// The board's input network: bias at the comparator input with no current [V]
/// (3.3 V · (1/22 kΩ) / (1/22 kΩ + 1/1.5 kΩ + 1/2.2 kΩ)).
pub const INPUT_BIAS_V: f32 = 3.3 * (1.0 / 22.0) / (1.0 / 22.0 + 1.0 / 1.5 + 1.0 / 2.2);
/// The board's input network: volts at the pin per volt across the shunt (4/7).
pub const INPUT_GAIN: f32 = (1.0 / 1.5) / (1.0 / 22.0 + 1.0 / 1.5 + 1.0 / 2.2);
/// DAC3 full scale [V] (VREF+ = 3.3 V) over 4095 codes.
pub const DAC_VOLTS_PER_CODE: f32 = 3.3 / 4095.0;

/// The DAC code of a trip current (rounded; saturating).
pub const fn threshold_code(current_a: f32) -> u16 {
    let volts = INPUT_BIAS_V + INPUT_GAIN * SHUNT_OHM * current_a;
    let code = volts / DAC_VOLTS_PER_CODE + 0.5;
    if code <= 0.0 {
        0
    } else if code >= 4095.0 {
        4095
    } else {
        code as u16
    }
}

/// The DAC code of [`BREAK_CURRENT_A`].
pub const BREAK_CODE: u16 = threshold_code(BREAK_CURRENT_A);

/// Arm the break: DAC3 thresholds, COMP1/COMP2, TIM1's break input. Call with the stage off
/// (MOE cleared) and after the op-amps have put PA1 and PA7 in analogue mode.
pub fn arm() {
    // Clocks: DAC3 on AHB2; the comparators are clocked with SYSCFG (APB2).
    pac::RCC.ahb2enr().modify(|w| w.set_dac3en(true));
    pac::RCC.apb2enr().modify(|w| w.set_syscfgen(true));
    let _ = pac::RCC.ahb2enr().read(); // the clock is on before the first DAC access

    // DAC3: both channels internal-only, unbuffered, HFSEL for a 170 MHz AHB.
    pac::DAC3.mcr().modify(|w| {
        w.set_hfsel(0b10);
        w.set_mode(0, DacMode::NORMAL_INT_BUFDIS);
        w.set_mode(1, DacMode::NORMAL_INT_BUFDIS);
    });
    pac::DAC3.dhr12r(0).write(|w| w.set_dhr(BREAK_CODE));
    pac::DAC3.dhr12r(1).write(|w| w.set_dhr(BREAK_CODE));
    pac::DAC3.cr().modify(|w| {
        w.set_en(0, true);
        w.set_en(1, true);
    });
    // DACRDY comes within a few µs of EN; bounded wait (no hang if it never does).
    for _ in 0..10_000 {
        let sr = pac::DAC3.sr().read();
        if sr.dacrdy(0) && sr.dacrdy(1) {
            break;
        }
    }

    // COMP1: PA1 against DAC3_CH1; COMP2: PA7 against DAC3_CH2. Not inverted, no blanking.
    for comp in [pac::COMP1, pac::COMP2] {
        comp.csr().write(|w| {
            w.set_inpsel(false);
            w.set_inmsel(Inm::DACA);
            w.set_polarity(Polarity::NOT_INVERTED);
            w.set_hyst(Hysteresis::NONE);
            w.set_en(true);
        });
    }

    // TIM1: comparator outputs to the break input, active high, filtered; no automatic
    // re-enable. Written with MOE cleared.
    pac::TIM1.af1().modify(|w| {
        w.set_bkine(false);
        w.set_bkcmpe(0, true);
        w.set_bkcmpe(1, true);
        w.set_bkcmpp(0, Bkinp::NOT_INVERTED);
        w.set_bkcmpp(1, Bkinp::NOT_INVERTED);
    });
    pac::TIM1.bdtr().modify(|w| {
        w.set_moe(false);
        w.set_aoe(false);
        w.set_bkf(0, FilterValue::FDTS_DIV8_N8);
        w.set_bkp(0, Bkp::ACTIVE_HIGH);
        w.set_bke(0, true);
    });
    // A break flagged while arming (a comparator settling) is not an event.
    clear();
}

/// A break has occurred since the flag was last cleared (TIM1_SR.BIF).
pub fn tripped() -> bool {
    pac::TIM1.sr().read().bif(0)
}

/// Clear the break flag (the stage stays off until software sets MOE again). TIM1_SR's flags
/// are cleared by writing 0 and kept by writing 1: all ones but BIF, as ST's HAL
/// `__HAL_TIM_CLEAR_FLAG` does (a read-modify-write could clear a flag set in between).
pub fn clear() {
    const BIF: u32 = 1 << 7;
    pac::TIM1.sr().write_value(pac::timer::regs::SrAdv(!BIF));
}
