//! An absolute magnetic encoder read through its PWM output (AS5047P/AS5048A style) on one
//! timer input-capture pin.
//!
//! Why PWM: the B-G431B-ESC1 has no SPI bus on free pins (SPI1's PB3/PB4 are the ST-LINK
//! virtual COM port, PB5 belongs to the back-EMF network, PA5–PA7 to the current-sense
//! amplifiers); its `PWM` input pad (PA15, TIM2_CH1) is free and meant for an input signal.
//!
//! Frame (as these sensors describe it; check against the sensor's datasheet before use, it
//! was not read for this code): 4119 PWM clock units per period — 12 units high (init),
//! 4 units error bits (high when there is no error), 4095 units of data (high for `angle`
//! units), 8 units low (exit). So the high time is `16 + angle` units when the sensor is
//! healthy, with a 12-bit angle. The decoder turns the measured high time and period into
//! 12-bit counts and scales them to the node's 14-bit counts.

use crate::drivers::encoder::AngleSensor;
use crate::sensors::{AngleCalibration, AngleSample, EncoderError};

/// PWM clock units per frame.
pub const FRAME_UNITS: u32 = 4119;
/// Units of the init and error-bit fields at the start of the frame.
pub const HEADER_UNITS: u32 = 16;
/// Largest 12-bit angle.
pub const MAX_ANGLE_12: u32 = 4095;

/// One captured PWM frame, in timer ticks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PwmFrame {
    /// High time of the frame \[ticks\].
    pub high_ticks: u32,
    /// Period of the frame \[ticks\].
    pub period_ticks: u32,
}

/// A timer in PWM-input mode: the last complete frame, `None` when no new frame arrived since
/// the previous call.
pub trait PwmCapture {
    /// Take the frame captured since the last call.
    fn take_frame(&mut self) -> Option<PwmFrame>;
}

/// Decode one frame into 14-bit counts.
///
/// # Errors
/// [`EncoderError::NoSignal`] when the period is outside `period_range_ticks` (not this
/// sensor, or a broken line), [`EncoderError::ErrorFlag`] when the high time is shorter than
/// the header (the sensor's error bits are low), with the high time in units as the word.
pub fn decode(frame: PwmFrame, period_range_ticks: (u32, u32)) -> Result<u16, EncoderError> {
    let (lo, hi) = period_range_ticks;
    if frame.period_ticks < lo || frame.period_ticks > hi || frame.period_ticks == 0 {
        return Err(EncoderError::NoSignal);
    }
    // Units of the high time, rounded: high × 4119 / period. In u64 nothing saturates
    // (below 2⁴⁴ + 2³¹); a high time longer than the period (a glitch) gives more than 4119
    // units, saturated to u32 rather than wrapped into a plausible angle, and reads as full
    // scale below.
    let high = u64::from(frame.high_ticks);
    let period = u64::from(frame.period_ticks);
    let units = high
        .saturating_mul(u64::from(FRAME_UNITS))
        .saturating_add(period / 2)
        .checked_div(period)
        .ok_or(EncoderError::NoSignal)?;
    let units = u32::try_from(units).unwrap_or(u32::MAX);
    let Some(data_units) = units.checked_sub(HEADER_UNITS) else {
        // Fewer than 16 units: fits a u16.
        return Err(EncoderError::ErrorFlag {
            word: u16::try_from(units).unwrap_or(u16::MAX),
        });
    };
    // At most 4095 after the `min`: a u16, and × 4 (≤ 16380) cannot saturate.
    let angle12 = u16::try_from(data_units.min(MAX_ANGLE_12)).unwrap_or(u16::MAX);
    Ok(angle12.saturating_mul(4))
}

/// The encoder on a PWM-input timer.
pub struct PwmAngleEncoder<C> {
    capture: C,
    calibration: AngleCalibration,
    period_range_ticks: (u32, u32),
    last: Option<AngleSample>,
    missed: u8,
    max_missed: u8,
}

impl<C: PwmCapture> PwmAngleEncoder<C> {
    /// Wrap a capture timer. `nominal_period_ticks` is the sensor's frame period in timer
    /// ticks; frames more than 20 % off are refused (the sensor's PWM clock is an RC
    /// oscillator, ±10 % is typical). A tick without a new frame reuses the last reading;
    /// `max_missed` such ticks in a row (2 at 1 kHz for a ~1 kHz frame) is `NoSignal`.
    pub fn new(
        capture: C,
        calibration: AngleCalibration,
        nominal_period_ticks: u32,
        max_missed: u8,
    ) -> Self {
        // ±20 %; saturating: a nominal period past u32::MAX / 6 × 5 keeps u32::MAX as the top.
        let lo = (nominal_period_ticks / 5).saturating_mul(4);
        let hi = (nominal_period_ticks / 5).saturating_mul(6);
        PwmAngleEncoder {
            capture,
            calibration,
            period_range_ticks: (lo, hi),
            last: None,
            missed: 0,
            max_missed,
        }
    }
}

impl<C: PwmCapture> AngleSensor for PwmAngleEncoder<C> {
    fn calibration(&self) -> AngleCalibration {
        self.calibration
    }
    fn set_zero_counts(&mut self, zero_counts: u16) {
        self.calibration.zero_counts = zero_counts;
        self.last = None;
    }

    fn read_angle(&mut self) -> Result<AngleSample, EncoderError> {
        match self.capture.take_frame() {
            Some(frame) => {
                self.missed = 0;
                let counts = decode(frame, self.period_range_ticks).inspect_err(|_| {
                    self.last = None;
                })?;
                let s = AngleSample {
                    counts,
                    angle_rad: self.calibration.angle_rad(counts),
                };
                self.last = Some(s);
                Ok(s)
            }
            None => {
                self.missed = self.missed.saturating_add(1);
                match self.last {
                    Some(s) if self.missed <= self.max_missed => Ok(s),
                    _ => Err(EncoderError::NoSignal),
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PERIOD: u32 = 170_000; // 1 kHz frame at 170 MHz

    fn frame_for(angle12: u32) -> PwmFrame {
        PwmFrame {
            high_ticks: ((HEADER_UNITS + angle12) as u64 * PERIOD as u64 / FRAME_UNITS as u64)
                as u32,
            period_ticks: PERIOD,
        }
    }

    #[test]
    fn decodes_every_angle_and_refuses_bad_frames() {
        let range = (PERIOD / 5 * 4, PERIOD / 5 * 6);
        for a in [0u32, 1, 1000, 2048, 4094, 4095] {
            assert_eq!(decode(frame_for(a), range), Ok((a * 4) as u16), "angle {a}");
        }
        let short = PwmFrame {
            high_ticks: PERIOD / 1000,
            period_ticks: PERIOD,
        };
        assert!(matches!(
            decode(short, range),
            Err(EncoderError::ErrorFlag { .. })
        ));
        let wrong_period = PwmFrame {
            high_ticks: 100,
            period_ticks: PERIOD / 2,
        };
        assert_eq!(decode(wrong_period, range), Err(EncoderError::NoSignal));
        let zero = PwmFrame {
            high_ticks: 0,
            period_ticks: 0,
        };
        assert_eq!(decode(zero, (0, 10)), Err(EncoderError::NoSignal));
    }

    struct Script<'a>(&'a [Option<PwmFrame>], usize);
    impl PwmCapture for Script<'_> {
        fn take_frame(&mut self) -> Option<PwmFrame> {
            let f = self.0.get(self.1).copied().flatten();
            self.1 += 1;
            f
        }
    }

    #[test]
    fn a_quiet_line_becomes_no_signal() {
        let frames = [
            Some(frame_for(1000)),
            None,
            None,
            None,
            Some(frame_for(1001)),
        ];
        let cal = AngleCalibration {
            zero_counts: 4000,
            reversed: false,
        };
        let mut e = PwmAngleEncoder::new(Script(&frames, 0), cal, PERIOD, 2);
        assert_eq!(e.read_angle().map(|s| s.counts), Ok(4000));
        assert_eq!(
            e.read_angle().map(|s| s.counts),
            Ok(4000),
            "one missed frame"
        );
        assert_eq!(
            e.read_angle().map(|s| s.counts),
            Ok(4000),
            "two missed frames"
        );
        assert_eq!(e.read_angle(), Err(EncoderError::NoSignal));
        let s = e.read_angle().unwrap();
        assert_eq!(s.counts, 4004);
        assert!((s.angle_rad - 4.0 * core::f32::consts::TAU / 16384.0).abs() < 1e-6);
    }
}
