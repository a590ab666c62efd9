//! The two position sensors the board can read without pin conflicts.
//!
//! * Spool: the DC motor's quadrature encoder on the Hall/encoder connector, PB6 (TIM4_CH1,
//!   AF2) and PB7 (TIM4_CH2, AF2), TIM4 in encoder mode, extended to 32 bits in software.
//! * Ankle: an absolute magnetic encoder's PWM output on the board's `PWM` input pad, PA15
//!   (TIM2_CH1, AF1), TIM2 in PWM-input mode (CCR1 period, CCR2 high time).

use embassy_stm32::peripherals::{TIM2, TIM4};
use embassy_stm32::timer::pwm_input::PwmInput;
use embassy_stm32::timer::qei::Qei;
use firmware::drivers::pwm_encoder::{PwmCapture, PwmFrame};
use firmware::drivers::spool_motor::{CounterUnwrap, HardwareError, SpoolEncoder};

/// TIM2's tick rate in PWM-input mode [Hz].
pub const PWM_CAPTURE_TICK_HZ: u32 = 10_000_000;
/// The ankle encoder's nominal PWM frame period [ticks of `PWM_CAPTURE_TICK_HZ`]: about
/// 1 kHz. To check against the sensor's datasheet and a scope at bring-up.
pub const ENCODER_PWM_PERIOD_TICKS: u32 = 10_000;

/// The spool's quadrature counter.
pub struct SpoolQei<'d> {
    qei: Qei<'d, TIM4>,
    unwrap: CounterUnwrap,
}

impl<'d> SpoolQei<'d> {
    /// Wrap the started encoder-mode timer.
    pub fn new(qei: Qei<'d, TIM4>) -> Self {
        SpoolQei {
            qei,
            unwrap: CounterUnwrap::default(),
        }
    }
}

impl SpoolEncoder for SpoolQei<'_> {
    fn spool_counts(&mut self) -> Result<i32, HardwareError> {
        Ok(self.unwrap.update(self.qei.count()))
    }
}

/// TIM2 in PWM-input mode.
pub struct AnklePwmCapture<'d> {
    input: PwmInput<'d, TIM2>,
}

impl<'d> AnklePwmCapture<'d> {
    /// Wrap and enable the capture.
    pub fn new(mut input: PwmInput<'d, TIM2>) -> Self {
        input.enable();
        AnklePwmCapture { input }
    }
}

impl PwmCapture for AnklePwmCapture<'_> {
    fn take_frame(&mut self) -> Option<PwmFrame> {
        // CC1IF: a new period was captured since CCR1 was last read (reading CCR1 clears it).
        let fresh = embassy_stm32::pac::TIM2.sr().read().ccif(0);
        if !fresh {
            return None;
        }
        Some(PwmFrame {
            period_ticks: self.input.get_period_ticks(),
            high_ticks: self.input.get_width_ticks(),
        })
    }
}
