//! Driver for an AS5047P-style 14-bit magnetic angle encoder on SPI (mode 1, 16-bit frames,
//! most significant byte first, chip select framing each word).
//!
//! A read sends `READ ANGLECOM` (0x3FFF) and then a `NOP` (address 0) whose answer carries the
//! angle: bit 15 even parity over bits 14..0, bit 14 error flag, bits 13..0 the angle in counts.

use embedded_hal::spi::{Error as _, SpiDevice};

use crate::sensors::{AngleCalibration, AngleSample, EncoderError};

/// Register address of the compensated angle.
pub const ANGLECOM: u16 = 0x3FFF;
/// Register address of the no-operation read.
pub const NOP: u16 = 0x0000;

/// True when the 16-bit word has even parity (bit 15 included).
pub const fn even_parity(word: u16) -> bool {
    word.count_ones() & 1 == 0
}

/// The read command for register `addr`, parity bit set.
pub const fn read_command(addr: u16) -> u16 {
    let w = 0x4000 | (addr & 0x3FFF);
    if even_parity(w) {
        w
    } else {
        w | 0x8000
    }
}

/// Check an answer word and extract the 14-bit data.
///
/// # Errors
/// [`EncoderError::Parity`] on a parity mismatch, [`EncoderError::ErrorFlag`] when the
/// sensor's error flag is set.
pub fn parse_answer(word: u16) -> Result<u16, EncoderError> {
    if !even_parity(word) {
        return Err(EncoderError::Parity { word });
    }
    if word & 0x4000 != 0 {
        return Err(EncoderError::ErrorFlag { word });
    }
    Ok(word & 0x3FFF)
}

/// Anything that reads the ankle angle once per control tick: the SPI encoder here, or the
/// PWM-output encoder of [`crate::drivers::pwm_encoder`] (the B-G431B-ESC1 has no free SPI
/// pins).
pub trait AngleSensor {
    /// Read the ankle angle.
    ///
    /// # Errors
    /// [`EncoderError`]; the node raises `EncoderComms`.
    fn read_angle(&mut self) -> Result<AngleSample, EncoderError>;
    /// The calibration in use.
    fn calibration(&self) -> AngleCalibration;
    /// Use `zero_counts` as the reading at ankle angle zero from now on.
    fn set_zero_counts(&mut self, zero_counts: u16);
}

impl<S: SpiDevice> AngleSensor for MagneticEncoder<S> {
    fn read_angle(&mut self) -> Result<AngleSample, EncoderError> {
        self.read()
    }
    fn calibration(&self) -> AngleCalibration {
        self.calibration
    }
    fn set_zero_counts(&mut self, zero_counts: u16) {
        self.calibration.zero_counts = zero_counts;
    }
}

/// The encoder on an SPI device.
pub struct MagneticEncoder<S> {
    spi: S,
    calibration: AngleCalibration,
}

impl<S: SpiDevice> MagneticEncoder<S> {
    /// Wrap an SPI device (mode 1, ≤ 10 MHz).
    pub fn new(spi: S, calibration: AngleCalibration) -> Self {
        MagneticEncoder { spi, calibration }
    }

    /// The SPI device.
    pub fn device(&self) -> &S {
        &self.spi
    }

    /// Give the SPI device back.
    pub fn release(self) -> S {
        self.spi
    }

    fn word(&mut self, command: u16) -> Result<u16, EncoderError> {
        let mut buf = command.to_be_bytes();
        self.spi
            .transfer_in_place(&mut buf)
            .map_err(|e| EncoderError::Bus(e.kind()))?;
        Ok(u16::from_be_bytes(buf))
    }

    /// Read the ankle angle (two 16-bit transactions).
    ///
    /// # Errors
    /// [`EncoderError::Bus`] when SPI fails, else as [`parse_answer`].
    pub fn read(&mut self) -> Result<AngleSample, EncoderError> {
        self.word(read_command(ANGLECOM))?;
        let counts = parse_answer(self.word(read_command(NOP))?)?;
        Ok(AngleSample {
            counts,
            angle_rad: self.calibration.angle_rad(counts),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use embedded_hal::spi::{ErrorKind, ErrorType, Operation};

    #[derive(Debug)]
    struct Fail;
    impl embedded_hal::spi::Error for Fail {
        fn kind(&self) -> ErrorKind {
            ErrorKind::ModeFault
        }
    }

    /// Answers each 16-bit word with the next scripted word; records the commands.
    struct FakeSpi {
        answers: [u16; 2],
        sent: [u16; 2],
        n: usize,
        fail: bool,
    }
    impl ErrorType for FakeSpi {
        type Error = Fail;
    }
    impl SpiDevice for FakeSpi {
        fn transaction(&mut self, ops: &mut [Operation<'_, u8>]) -> Result<(), Fail> {
            if self.fail {
                return Err(Fail);
            }
            for op in ops {
                if let Operation::TransferInPlace(buf) = op {
                    self.sent[self.n] = u16::from_be_bytes([buf[0], buf[1]]);
                    buf.copy_from_slice(&self.answers[self.n].to_be_bytes());
                    self.n += 1;
                }
            }
            Ok(())
        }
    }

    fn with_parity(w: u16) -> u16 {
        if even_parity(w) {
            w
        } else {
            w | 0x8000
        }
    }

    #[test]
    fn commands_carry_even_parity() {
        assert_eq!(read_command(ANGLECOM), 0xFFFF);
        assert_eq!(read_command(NOP), 0xC000);
    }

    #[test]
    fn reads_angle_with_two_words() {
        let cal = AngleCalibration {
            zero_counts: 1000,
            reversed: false,
        };
        let mut e = MagneticEncoder::new(
            FakeSpi {
                answers: [0, with_parity(1000 + 4096)],
                sent: [0; 2],
                n: 0,
                fail: false,
            },
            cal,
        );
        let s = e.read().unwrap();
        assert_eq!(s.counts, 5096);
        assert!((s.angle_rad - core::f32::consts::FRAC_PI_2).abs() < 1e-6);
        let spi = e.release();
        assert_eq!(spi.sent, [0xFFFF, 0xC000]);
    }

    #[test]
    fn parity_error_flag_and_bus_errors() {
        assert_eq!(
            parse_answer(0x0001),
            Err(EncoderError::Parity { word: 0x0001 })
        );
        assert_eq!(
            parse_answer(0xC000),
            Err(EncoderError::ErrorFlag { word: 0xC000 })
        );
        assert_eq!(parse_answer(with_parity(123)), Ok(123));
        let cal = AngleCalibration {
            zero_counts: 0,
            reversed: false,
        };
        let mut e = MagneticEncoder::new(
            FakeSpi {
                answers: [0; 2],
                sent: [0; 2],
                n: 0,
                fail: true,
            },
            cal,
        );
        assert_eq!(e.read(), Err(EncoderError::Bus(ErrorKind::ModeFault)));
    }
}
