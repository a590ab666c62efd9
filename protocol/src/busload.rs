//! Bus load of the nominal message rates, worst-case bit stuffing included.
//!
//! Worst-case length of a classic CAN data frame with an 11-bit identifier and `s` data bytes
//! (Davis, Burns, Bril & Lukkien, "Controller Area Network (CAN) schedulability analysis:
//! refuted, revisited and revised", Real-Time Systems 35, 2007, eq. 1 with g = 34):
//!
//! ```text
//! bits(s) = g + 8s + 13 + floor((g + 8s − 1) / 4)
//! ```
//!
//! `g + 8s` bits are exposed to stuffing (start of frame to CRC), at most one stuff bit per four
//! after the first; 13 bits of CRC delimiter, ACK, end of frame and interframe space are not.

use crate::messages::MESSAGES;
use crate::signal::MessageSpec;

/// Stuffable header bits of a standard-identifier data frame.
const G_STANDARD: u32 = 34;

/// Worst-case length of a standard data frame with `dlc` data bytes \[bits\], stuffing included.
/// Any `dlc` (even past the 8 of classic CAN) gives the formula's value: at most 2,605 bits
/// for 255, so the saturating operations never saturate.
pub const fn worst_case_frame_bits(dlc: u8) -> u32 {
    let exposed = G_STANDARD.saturating_add((dlc as u32).saturating_mul(8));
    exposed
        .saturating_add(13)
        .saturating_add(exposed.saturating_sub(1) / 4)
}

/// Length of the same frame without any stuff bits \[bits\].
pub const fn unstuffed_frame_bits(dlc: u8) -> u32 {
    G_STANDARD
        .saturating_add((dlc as u32).saturating_mul(8))
        .saturating_add(13)
}

/// One message's share of the bus.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MessageLoad {
    /// The message.
    pub spec: &'static MessageSpec,
    /// How many identifiers carry it at the nominal rate.
    pub identifiers: u32,
    /// Worst-case frame length \[bits\].
    pub frame_bits: u32,
    /// Bits per second over all its identifiers [bit/s].
    pub bits_per_s: f64,
}

/// Bus load of every message at its nominal rate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BusLoad {
    /// Bit rate the load is computed for [bit/s].
    pub bitrate_bps: u32,
    /// Total worst-case bits per second [bit/s].
    pub bits_per_s: f64,
    /// Total without stuff bits [bit/s].
    pub unstuffed_bits_per_s: f64,
}

impl BusLoad {
    /// Worst-case load as a fraction of the bit rate.
    pub fn fraction(&self) -> f64 {
        self.bits_per_s / self.bitrate_bps as f64
    }
}

/// Identifiers of a message that run at the nominal rate. For commands only one target is
/// addressed at a time (a broadcast replaces the per-ankle frames).
fn active_identifiers(spec: &MessageSpec) -> u32 {
    match spec.direction {
        // A handful of nodes; saturating, never truncating, were there more than 2³² − 1.
        crate::signal::Direction::FromNode(n) => u32::try_from(n.len()).unwrap_or(u32::MAX),
        crate::signal::Direction::ToNode(_) => 1,
    }
}

/// Per-message loads, in [`MESSAGES`] order.
pub fn message_loads() -> impl Iterator<Item = MessageLoad> {
    MESSAGES.iter().map(|spec| {
        let identifiers = active_identifiers(spec);
        let frame_bits = worst_case_frame_bits(spec.dlc);
        MessageLoad {
            spec,
            identifiers,
            frame_bits,
            bits_per_s: spec.nominal_rate_hz * identifiers as f64 * frame_bits as f64,
        }
    })
}

/// Total load of the nominal rates at `bitrate_bps`.
pub fn nominal_load(bitrate_bps: u32) -> BusLoad {
    let mut bits = 0.0;
    let mut unstuffed = 0.0;
    for l in message_loads() {
        bits += l.bits_per_s;
        unstuffed +=
            l.spec.nominal_rate_hz * l.identifiers as f64 * unstuffed_frame_bits(l.spec.dlc) as f64;
    }
    BusLoad {
        bitrate_bps,
        bits_per_s: bits,
        unstuffed_bits_per_s: unstuffed,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_lengths_match_published_values() {
        // Davis et al. 2007: 8 data bytes, 11-bit id: 135 bits worst case; 0 bytes: 55 bits.
        assert_eq!(worst_case_frame_bits(8), 135);
        assert_eq!(worst_case_frame_bits(0), 55);
        assert_eq!(unstuffed_frame_bits(8), 111);
    }

    #[test]
    fn nominal_load_is_well_below_half_the_bus() {
        let l = nominal_load(crate::BITRATE_BPS);
        assert!(
            l.fraction() > 0.05 && l.fraction() < 0.5,
            "{}",
            l.fraction()
        );
        assert!(l.unstuffed_bits_per_s < l.bits_per_s);
    }
}
