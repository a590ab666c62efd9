//! The power stage: TIM1 drives two of the board's three half-bridges (phase U: PA8 TIM1_CH1
//! high side, PC13 TIM1_CH1N low side; phase V: PA9 TIM1_CH2, PA12 TIM1_CH2N) in
//! complementary PWM with dead time; phase W (PA10, PB15) is held low as plain outputs.
//!
//! Off means the timer's main output enable (MOE) cleared with the off-state selection for
//! idle (OSSI) set and idle levels low: every gate input driven low, all six switches open.
//! The stage is off from construction until the first `drive`, and [`power_stage_off`]
//! clears MOE from any context (panic and HardFault handlers included) without needing the
//! driver object.
//!
//! The over-current comparators ([`crate::overcurrent_break`]) clear MOE in hardware; `drive`
//! sees the break flag, keeps the stage off and reports a [`HardwareError`] (the node raises
//! `Actuator` and goes `Safe`); `off` clears the flag, so the next `drive` may switch on again.

use embassy_stm32::peripherals::TIM1;
use embassy_stm32::timer::complementary_pwm::ComplementaryPwm;
use embassy_stm32::timer::complementary_pwm::Ossi;
use embassy_stm32::timer::Channel;
use firmware::drivers::spool_motor::{HalfBridges, HardwareError};

/// Dead time inserted between a leg's high- and low-side switching [timer ticks at 170 MHz]:
/// 85 ticks = 500 ns. To check against the gate driver and MOSFET switching times at bring-up.
pub const DEAD_TIME_TICKS: u16 = 85;

/// Clear TIM1's main output enable: all gate inputs go to their idle level (low). Safe to call
/// from any context, any number of times; touches only TIM1's BDTR register.
pub fn power_stage_off() {
    embassy_stm32::pac::TIM1.bdtr().modify(|w| w.set_moe(false));
}

/// Two half-bridges (U and V) on TIM1.
pub struct Tim1Bridges<'d> {
    pwm: ComplementaryPwm<'d, TIM1>,
    enabled: bool,
}

impl<'d> Tim1Bridges<'d> {
    /// Take the configured timer; the outputs are switched off here.
    pub fn new(mut pwm: ComplementaryPwm<'d, TIM1>) -> Self {
        pwm.set_master_output_enable(false);
        pwm.set_off_state_selection_idle(Ossi::IDLE_LEVEL);
        // Idle levels: OISx = OISxN = 0 (the reset value, left alone): with MOE cleared both
        // the high- and the low-side inputs go low. (`IdlePolarity` would set one of them.)
        pwm.set_dead_time(DEAD_TIME_TICKS);
        pwm.set_duty(Channel::Ch1, 0);
        pwm.set_duty(Channel::Ch2, 0);
        pwm.enable(Channel::Ch1);
        pwm.enable(Channel::Ch2);
        power_stage_off();
        Tim1Bridges {
            pwm,
            enabled: false,
        }
    }
}

impl HalfBridges for Tim1Bridges<'_> {
    fn drive(&mut self, signed_duty: f32) -> Result<(), HardwareError> {
        if signed_duty.is_nan() {
            return Err(HardwareError);
        }
        if crate::overcurrent_break::tripped() {
            // The hardware has already cleared MOE: stay off, report it.
            power_stage_off();
            self.enabled = false;
            return Err(HardwareError);
        }
        let max = self.pwm.get_max_duty();
        // Float-to-int `as` saturates; min() keeps set_duty's assertion unreachable.
        let duty = ((signed_duty.abs().min(1.0) * max as f32) as u32).min(max);
        let (a, b) = if signed_duty >= 0.0 {
            (duty, 0)
        } else {
            (0, duty)
        };
        self.pwm.set_duty(Channel::Ch1, a);
        self.pwm.set_duty(Channel::Ch2, b);
        if !self.enabled {
            self.pwm.set_master_output_enable(true);
            self.enabled = true;
        }
        Ok(())
    }

    fn off(&mut self) {
        power_stage_off();
        crate::overcurrent_break::clear();
        self.enabled = false;
        self.pwm.set_duty(Channel::Ch1, 0);
        self.pwm.set_duty(Channel::Ch2, 0);
    }
}
