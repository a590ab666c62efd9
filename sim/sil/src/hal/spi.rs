//! The encoder's SPI device: an AS5047P as `firmware::drivers::encoder::MagneticEncoder`
//! talks to it.
//!
//! One transaction (chip select low to high) is one 16-bit frame, most significant byte
//! first. The chip answers each frame with the answer to the *previous* command (pipelined):
//! the driver sends `READ ANGLECOM` and then a `NOP`, and the angle comes back in the `NOP`'s
//! frame. Answers carry even parity in bit 15 and the error flag in bit 14. A command with
//! wrong parity, or a frame that is not 16 bits, sets the error flag in the next answer
//! (the chip's PARERR / FRERR). Writes are not emulated (the firmware never writes): a write
//! command is answered with 0 like an unknown register. The first answer after power-up is 0.
//!
//! The angle is latched when the `READ ANGLECOM` frame ends: [`SimEncoder::read`] of the
//! shaft's true angle at that tick (its quantisation, glitch and stuck faults), so one
//! encoder read per tick as before. [`SimEncoder::link_fault`] adds the link's faults: failed
//! transactions (`EncoderError::Bus`) and a corrupted answer (`EncoderError::Parity`).

use std::cell::Cell;
use std::rc::Rc;

use embedded_hal::spi::{ErrorKind, ErrorType, Operation, SpiDevice};
use firmware::drivers::encoder::{even_parity, ANGLECOM};
use protocol::ReflexPhase;

use crate::sensors::SimEncoder;

/// Register address of the uncompensated angle (answered like [`ANGLECOM`]).
const ANGLEUNC: u16 = 0x3FFE;
/// Register address of the error flags (cleared on read).
const ERRFL: u16 = 0x0001;
/// ERRFL bit: framing error.
const FRERR: u16 = 0x0001;
/// ERRFL bit: parity error of a command.
const PARERR: u16 = 0x0004;

/// The true state of the ankle's shaft, set by the orchestrator before each tick: time \[s\] and
/// angle \[rad\]. Shared with a [`SimSpi`].
#[derive(Clone, Debug)]
pub struct Shaft(Rc<Cell<(f64, f64)>>, Rc<Cell<ReflexPhase>>);

impl Default for Shaft {
    fn default() -> Self {
        Shaft(Rc::default(), Rc::new(Cell::new(ReflexPhase::Inactive)))
    }
}

impl Shaft {
    /// A shaft at angle 0 at time 0.
    pub fn new() -> Self {
        Self::default()
    }

    /// Set the time \[s\] and true ankle angle \[rad\] the next reads see.
    pub fn set(&self, t_s: f64, angle_rad: f64) {
        self.0.set((t_s, angle_rad));
    }

    /// Time \[s\] and true angle \[rad\].
    pub fn get(&self) -> (f64, f64) {
        self.0.get()
    }

    /// The node's reflex phase at the start of the tick (after the previous one), which a
    /// state-triggered fault ([`crate::SensorFault::StuckInPhase`]) waits for.
    pub fn set_phase(&self, phase: ReflexPhase) {
        self.1.set(phase);
    }

    /// The phase set last.
    pub fn phase(&self) -> ReflexPhase {
        self.1.get()
    }
}

/// A failed SPI transaction (injected by [`crate::SensorFault::SpiFailure`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SimSpiError;

impl embedded_hal::spi::Error for SimSpiError {
    fn kind(&self) -> ErrorKind {
        ErrorKind::Other
    }
}

/// The AS5047P on its SPI bus, with chip select (an `SpiDevice`).
#[derive(Clone, Debug)]
pub struct SimSpi {
    encoder: SimEncoder,
    shaft: Shaft,
    /// The answer the next frame shifts out.
    pending: u16,
    /// The chip's error flags (ERRFL), cleared when read.
    errfl: u16,
    transactions: u64,
}

/// `word` with bit 15 set so that the word has even parity.
pub const fn with_parity(word: u16) -> u16 {
    let w = word & 0x7FFF;
    if even_parity(w) {
        w
    } else {
        w | 0x8000
    }
}

impl SimSpi {
    /// The chip reading `shaft` through `encoder`.
    pub fn new(encoder: SimEncoder, shaft: Shaft) -> Self {
        SimSpi {
            encoder,
            shaft,
            pending: 0,
            errfl: 0,
            transactions: 0,
        }
    }

    /// The encoder chip (its applied faults).
    pub fn encoder(&self) -> &SimEncoder {
        &self.encoder
    }

    /// Transactions served (failed ones included).
    pub fn transactions(&self) -> u64 {
        self.transactions
    }

    /// The answer to `command`, shifted out in the next frame; `t_s`, `angle_rad`: the shaft.
    fn answer(&mut self, command: u16, t_s: f64, angle_rad: f64, corrupt: bool) -> u16 {
        if !even_parity(command) {
            self.errfl |= PARERR;
            return with_parity(0x4000);
        }
        if command & 0x4000 == 0 {
            return 0;
        }
        match command & 0x3FFF {
            ANGLECOM | ANGLEUNC => {
                let counts = self
                    .encoder
                    .read(t_s, angle_rad, self.shaft.phase())
                    .map_or(0, |s| s.counts & 0x3FFF);
                let word = with_parity(counts);
                if corrupt {
                    word ^ 0x0001
                } else {
                    word
                }
            }
            ERRFL => with_parity(std::mem::take(&mut self.errfl) & 0x3FFF),
            _ => 0,
        }
    }
}

impl ErrorType for SimSpi {
    type Error = SimSpiError;
}

impl SpiDevice for SimSpi {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), SimSpiError> {
        self.transactions += 1;
        let (t_s, angle_rad) = self.shaft.get();
        // A command that latches the angle; only known once the frame is in, but the fault
        // decision (fail or not) is taken for the whole transaction first.
        if self.encoder.link_fault(t_s, false).fail {
            return Err(SimSpiError);
        }
        let out = self.pending.to_be_bytes();
        let mut mosi = [0u8; 2];
        let mut n = 0usize;
        let mut shift = |sent: u8| -> u8 {
            if let Some(b) = mosi.get_mut(n) {
                *b = sent;
            }
            let back = out.get(n).copied().unwrap_or(0);
            n += 1;
            back
        };
        for op in operations.iter_mut() {
            match op {
                Operation::Read(buf) => buf.iter_mut().for_each(|b| *b = shift(0)),
                Operation::Write(buf) => buf.iter().for_each(|b| {
                    shift(*b);
                }),
                Operation::Transfer(read, write) => {
                    let len = read.len().max(write.len());
                    for i in 0..len {
                        let back = shift(write.get(i).copied().unwrap_or(0));
                        if let Some(r) = read.get_mut(i) {
                            *r = back;
                        }
                    }
                }
                Operation::TransferInPlace(buf) => buf.iter_mut().for_each(|b| *b = shift(*b)),
                Operation::DelayNs(_) => {}
            }
        }
        if n != 2 {
            self.errfl |= FRERR;
            self.pending = with_parity(0x4000);
            return Ok(());
        }
        let command = u16::from_be_bytes(mosi);
        let latches = even_parity(command) && matches!(command & 0x7FFF, 0x7FFF | 0x7FFE);
        let corrupt = latches && self.encoder.link_fault(t_s, true).corrupt;
        self.pending = self.answer(command, t_s, angle_rad, corrupt);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sensors::SensorFault;
    use crate::side::Side;
    use firmware::drivers::encoder::{parse_answer, read_command, MagneticEncoder, NOP};
    use firmware::sensors::with_simulated_noise;
    use firmware::sensors::EncoderError;
    use firmware::sensors::SIMULATED_CALIBRATION as CALIBRATION;

    fn word(spi: &mut SimSpi, command: u16) -> u16 {
        let mut buf = command.to_be_bytes();
        spi.transfer_in_place(&mut buf).unwrap();
        u16::from_be_bytes(buf)
    }

    #[test]
    fn answers_are_pipelined_with_even_parity() {
        let shaft = Shaft::new();
        let mut spi = SimSpi::new(SimEncoder::new(CALIBRATION, vec![]), shaft.clone());
        let (a1, a2) = (-0.055, 0.2);
        shaft.set(0.0, a1);
        // Power-up: the first frame answers nothing (0).
        assert_eq!(word(&mut spi, read_command(ANGLECOM)), 0);
        // The angle latched by that command comes back in the next frame, whatever the shaft
        // does in between.
        shaft.set(0.001, a2);
        let w = word(&mut spi, read_command(NOP));
        assert!(even_parity(w), "{w:#06x}");
        assert_eq!(w & 0x4000, 0, "no error flag");
        // Read n of the chip carries the sensor's noise for n (firmware::sensors).
        let noisy = |a: f64, n| with_simulated_noise(CALIBRATION.counts(a as f32), n);
        assert_eq!(parse_answer(w), Ok(noisy(a1, 0)));
        // A NOP's own answer is 0; ANGLECOM twice: the second frame carries the first's angle.
        assert_eq!(word(&mut spi, read_command(ANGLECOM)), 0);
        let w = word(&mut spi, read_command(ANGLECOM));
        assert_eq!(parse_answer(w), Ok(noisy(a2, 1)));
        // Every answer the chip can give has even parity.
        for (n, a) in [-0.3, -0.1, 0.0, 0.05, 0.3].into_iter().enumerate() {
            shaft.set(0.002, a);
            word(&mut spi, read_command(ANGLECOM));
            let w = word(&mut spi, read_command(NOP));
            assert!(even_parity(w));
            assert_eq!(parse_answer(w), Ok(noisy(a, n as u32 + 3)));
        }
    }

    #[test]
    fn the_firmware_driver_reads_the_quantised_angle() {
        let shaft = Shaft::new();
        let spi = SimSpi::new(SimEncoder::new(CALIBRATION, vec![]), shaft.clone());
        let mut enc = MagneticEncoder::new(spi, CALIBRATION);
        let lsb = std::f64::consts::TAU / 16384.0;
        for (k, a) in [-0.2, -0.0801, 0.0, 0.123_456].into_iter().enumerate() {
            shaft.set(k as f64 * 1e-3, a);
            let s = enc.read().unwrap();
            assert_eq!(
                s.counts,
                with_simulated_noise(CALIBRATION.counts(a as f32), k as u32)
            );
            assert!((f64::from(s.angle_rad) - a).abs() <= 1.5 * lsb + 1e-6);
        }
        assert_eq!(enc.release().transactions(), 8, "two frames per read");
    }

    #[test]
    fn bad_commands_set_the_error_flag_in_the_next_answer() {
        let shaft = Shaft::new();
        let mut spi = SimSpi::new(SimEncoder::new(CALIBRATION, vec![]), shaft);
        // 0x7FFF: ANGLECOM with the parity bit wrong.
        word(&mut spi, 0x7FFF);
        let w = word(&mut spi, read_command(NOP));
        assert_eq!(parse_answer(w), Err(EncoderError::ErrorFlag { word: w }));
        // A 24-bit frame is a framing error.
        let mut three = [0xFF, 0xFF, 0x00];
        spi.transfer_in_place(&mut three).unwrap();
        let w = word(&mut spi, read_command(ERRFL));
        assert!(matches!(
            parse_answer(w),
            Err(EncoderError::ErrorFlag { .. })
        ));
        // ERRFL reports both, and reading it clears them.
        let w = word(&mut spi, read_command(ERRFL));
        assert_eq!(parse_answer(w), Ok(PARERR | FRERR));
        let w = word(&mut spi, read_command(NOP));
        assert_eq!(parse_answer(w), Ok(0));
    }

    #[test]
    fn link_faults_reach_the_driver_as_bus_and_parity_errors() {
        let faults = vec![
            SensorFault::SpiFailure {
                side: Side::Left,
                from_s: 0.002,
                until_s: 0.004,
            },
            SensorFault::Parity {
                side: Side::Left,
                at_s: 0.005,
            },
        ];
        let shaft = Shaft::new();
        let spi = SimSpi::new(SimEncoder::new(CALIBRATION, faults), shaft.clone());
        let mut enc = MagneticEncoder::new(spi, CALIBRATION);
        let reads: Vec<_> = (0..7)
            .map(|k| {
                shaft.set(k as f64 * 1e-3, 0.01);
                enc.read()
            })
            .collect();
        assert!(reads[1].is_ok());
        assert_eq!(reads[2], Err(EncoderError::Bus(ErrorKind::Other)));
        assert_eq!(reads[3], Err(EncoderError::Bus(ErrorKind::Other)));
        assert!(reads[4].is_ok());
        assert!(matches!(reads[5], Err(EncoderError::Parity { .. })));
        assert!(reads[6].is_ok(), "one corrupted answer only");
    }
}
