//! The bit stream of a classic standard data frame: CRC-15, bit stuffing, frame length.
//!
//! Fields in transmission order: start of frame (1, dominant), identifier (11), RTR (1), IDE
//! (1), r0 (1), DLC (4), data (8 × DLC), CRC (15) — these `34 + 8·DLC` bits are subject to bit
//! stuffing (after five equal bits the transmitter inserts one of the opposite level, which
//! itself counts towards the next run) — then CRC delimiter (1), ACK slot (1), ACK delimiter
//! (1), end of frame (7) and the interframe space (3), 13 bits that are never stuffed.

use crate::frame::Frame;

/// Bits of a standard data frame exposed to stuffing, before stuffing, without data.
pub const STUFFED_HEADER_BITS: u32 = 34;
/// Fixed-form tail: CRC delimiter, ACK slot, ACK delimiter, end of frame, interframe space.
pub const TAIL_BITS: u32 = 13;

/// CRC-15/CAN (polynomial 0x4599, initial value 0) over a sequence of bits.
pub fn crc15(bits: &[bool]) -> u16 {
    let mut crc: u16 = 0;
    for &b in bits {
        let next = b ^ ((crc >> 14) & 1 == 1);
        crc = (crc << 1) & 0x7FFF;
        if next {
            crc ^= 0x4599;
        }
    }
    crc
}

/// The most bits exposed to stuffing: a frame of 8 data bytes.
const MAX_STUFFED_BITS: usize = STUFFED_HEADER_BITS as usize + 64;

/// A frame's unstuffed bits in a fixed buffer (no allocation: the bus counts the stuff bits
/// of every frame it sends).
struct UnstuffedBits {
    bits: [bool; MAX_STUFFED_BITS],
    len: usize,
}

impl UnstuffedBits {
    fn push(&mut self, value: u32, n: u32) {
        for i in (0..n).rev() {
            self.bits[self.len] = (value >> i) & 1 == 1;
            self.len += 1;
        }
    }

    /// From start of frame to the end of the CRC field.
    fn of(frame: &Frame) -> Self {
        let mut b = UnstuffedBits {
            bits: [false; MAX_STUFFED_BITS],
            len: 0,
        };
        b.push(0, 1); // SOF
        b.push(u32::from(frame.id()), 11);
        b.push(0, 3); // RTR (data frame), IDE (standard), r0
        b.push(u32::from(frame.dlc()), 4);
        for &byte in frame.data() {
            b.push(u32::from(byte), 8);
        }
        let crc = crc15(b.as_slice());
        b.push(u32::from(crc), 15);
        b
    }

    fn as_slice(&self) -> &[bool] {
        &self.bits[..self.len]
    }
}

/// The unstuffed bits from start of frame to the end of the CRC field (`true` = recessive).
pub fn unstuffed_bits(frame: &Frame) -> Vec<bool> {
    UnstuffedBits::of(frame).as_slice().to_vec()
}

/// Walks `bits` as a transmitter sends them: `emit(bit, is_stuff)` for each bit on the wire,
/// a stuff bit of the opposite level after five equal bits (which counts towards the next run).
fn transmit(bits: &[bool], mut emit: impl FnMut(bool, bool)) {
    let mut run = 0u32;
    let mut last = None;
    for &b in bits {
        emit(b, false);
        if Some(b) == last {
            run += 1;
        } else {
            run = 1;
            last = Some(b);
        }
        if run == 5 {
            emit(!b, true);
            last = Some(!b);
            run = 1;
        }
    }
}

/// Insert stuff bits as a transmitter does.
pub fn stuff(bits: &[bool]) -> Vec<bool> {
    let mut out = Vec::with_capacity(bits.len() + bits.len() / 4 + 1);
    transmit(bits, |b, _| out.push(b));
    out
}

/// Number of stuff bits the frame carries on the wire.
pub fn stuff_bit_count(frame: &Frame) -> u32 {
    let mut count = 0;
    transmit(UnstuffedBits::of(frame).as_slice(), |_, is_stuff| {
        count += u32::from(is_stuff)
    });
    count
}

/// Length of the frame on the wire \[bits\], with its actual stuff bits and the 3-bit
/// interframe space.
pub fn actual_frame_bits(frame: &Frame) -> u32 {
    STUFFED_HEADER_BITS + 8 * u32::from(frame.dlc()) + TAIL_BITS + stuff_bit_count(frame)
}

/// Worst-case length \[bits\] (Davis et al. 2007), as [`protocol::busload::worst_case_frame_bits`].
pub fn worst_case_frame_bits(dlc: u8) -> u32 {
    protocol::busload::worst_case_frame_bits(dlc)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn destuff(bits: &[bool]) -> Vec<bool> {
        let mut out = Vec::new();
        let mut run = 0;
        let mut last = None;
        let mut skip = false;
        for &b in bits {
            if skip {
                skip = false;
                last = Some(b);
                run = 1;
                continue;
            }
            out.push(b);
            if Some(b) == last {
                run += 1;
            } else {
                run = 1;
                last = Some(b);
            }
            if run == 5 {
                skip = true;
            }
        }
        out
    }

    #[test]
    fn crc_of_known_frame() {
        // Residue property: CRC over message + its own CRC is zero.
        let f = Frame::new(0x123, &[0xDE, 0xAD, 0xBE, 0xEF]).unwrap();
        let bits = unstuffed_bits(&f);
        assert_eq!(crc15(&bits), 0);
        assert_eq!(bits.len(), 34 + 32);
    }

    #[test]
    fn all_zero_frame_is_heavily_stuffed() {
        // id 0, dlc 0: SOF + 18 dominant bits, then the CRC.
        let f = Frame::new(0, &[]).unwrap();
        assert!(stuff_bit_count(&f) >= 4);
        assert!(actual_frame_bits(&f) <= worst_case_frame_bits(0));
    }

    proptest! {
        #[test]
        fn the_stuff_bit_count_is_the_stuffed_stream_s_extra_length(id in 0u32..0x800, data in proptest::collection::vec(any::<u8>(), 0..=8)) {
            let f = Frame::new(id, &data).unwrap();
            let raw = unstuffed_bits(&f);
            prop_assert_eq!(raw.len(), 34 + 8 * data.len());
            prop_assert_eq!(stuff_bit_count(&f) as usize, stuff(&raw).len() - raw.len());
        }

        #[test]
        fn stuffing_is_bounded_and_reversible(id in 0u32..0x800, data in proptest::collection::vec(any::<u8>(), 0..=8)) {
            let f = Frame::new(id, &data).unwrap();
            let raw = unstuffed_bits(&f);
            let wire = stuff(&raw);
            // no six equal bits in a row on the wire
            for w in wire.windows(6) {
                prop_assert!(!w.iter().all(|&b| b == w[0]));
            }
            prop_assert_eq!(destuff(&wire), raw);
            let bits = actual_frame_bits(&f);
            prop_assert!(bits >= protocol::busload::unstuffed_frame_bits(f.dlc()));
            prop_assert!(bits <= worst_case_frame_bits(f.dlc()));
            prop_assert_eq!(crc15(&unstuffed_bits(&f)), 0);
        }
    }
}
