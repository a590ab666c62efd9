//! Motor current from the board's low-side shunts: phase U's shunt amplified by OPAMP1
//! (inputs PA1/PA3, output PA2 = ADC1_IN3), phase V's by OPAMP2 (PA7/PA5, output PA6 =
//! ADC2_IN3), each an internal PGA (gain 16, biased through VINM0) behind the board's input
//! divider.
//!
//! Scale (from the SimpleFOC B_G431B_ESC1 example's `LowsideCurrentSense(0.003f, -64.0f/7.0f,
//! ...)`; UM2516's schematic was not read here): 3 mΩ shunt, amplifier gain −64/7, 12-bit ADC
//! over 3.3 V. The amplifier output sits at an offset with no current; the offset is measured
//! at start-up with the power stage off.
//!
//! With the sign–magnitude drive ([`firmware::drivers::spool_motor`]) the leg held low carries
//! the motor current all period long and the switching leg carries it during its low-side
//! time, so the larger of the two readings is the motor current, whatever the PWM phase at
//! the sample.

use embassy_stm32::adc::{Adc, AdcChannel, SampleTime};
use embassy_stm32::peripherals::{ADC1, ADC2};
use firmware::drivers::spool_motor::{CurrentSense, HardwareError};

/// Shunt resistance [Ω].
pub const SHUNT_OHM: f32 = 0.003;
/// Amplifier gain magnitude [V/V].
pub const AMPLIFIER_GAIN: f32 = 64.0 / 7.0;
/// ADC full scale [V] over 4096 counts.
pub const ADC_VOLTS_PER_COUNT: f32 = 3.3 / 4096.0;
/// Amperes per ADC count.
pub const AMPS_PER_COUNT: f32 = ADC_VOLTS_PER_COUNT / (SHUNT_OHM * AMPLIFIER_GAIN);
/// Samples averaged for the zero-current offset.
pub const OFFSET_SAMPLES: u32 = 64;

/// The two shunt channels.
pub struct ShuntCurrent<'d, U, V> {
    adc1: Adc<'d, ADC1>,
    adc2: Adc<'d, ADC2>,
    phase_u: U,
    phase_v: V,
    offset_u: f32,
    offset_v: f32,
}

impl<'d, U: AdcChannel<ADC1>, V: AdcChannel<ADC2>> ShuntCurrent<'d, U, V> {
    /// Wrap the converters and the amplifier outputs; measures the zero-current offsets now
    /// (call with the power stage off).
    pub fn new(adc1: Adc<'d, ADC1>, adc2: Adc<'d, ADC2>, phase_u: U, phase_v: V) -> Self {
        let mut s = ShuntCurrent {
            adc1,
            adc2,
            phase_u,
            phase_v,
            offset_u: 0.0,
            offset_v: 0.0,
        };
        let (mut su, mut sv) = (0u32, 0u32);
        for _ in 0..OFFSET_SAMPLES {
            let (u, v) = s.raw();
            su += u as u32;
            sv += v as u32;
        }
        s.offset_u = su as f32 / OFFSET_SAMPLES as f32;
        s.offset_v = sv as f32 / OFFSET_SAMPLES as f32;
        s
    }

    fn raw(&mut self) -> (u16, u16) {
        let u = self
            .adc1
            .blocking_read(&mut self.phase_u, SampleTime::CYCLES24_5);
        let v = self
            .adc2
            .blocking_read(&mut self.phase_v, SampleTime::CYCLES24_5);
        (u, v)
    }

    /// Zero-current offsets [counts] (U, V).
    pub fn offsets(&self) -> (f32, f32) {
        (self.offset_u, self.offset_v)
    }
}

impl<U: AdcChannel<ADC1>, V: AdcChannel<ADC2>> CurrentSense for ShuntCurrent<'_, U, V> {
    fn motor_current_a(&mut self) -> Result<f32, HardwareError> {
        let (u, v) = self.raw();
        // A reading pinned at either rail means a broken amplifier or ADC input.
        if u == 0 || v == 0 || u >= 4095 || v >= 4095 {
            return Err(HardwareError);
        }
        let iu = (u as f32 - self.offset_u).abs() * AMPS_PER_COUNT;
        let iv = (v as f32 - self.offset_v).abs() * AMPS_PER_COUNT;
        Ok(iu.max(iv))
    }
}
