//! CAN bit timing computed from the controller's actual kernel clock, and the oscillator
//! error that timing tolerates.
//!
//! A bit is `1 (sync) + seg1 + seg2` time quanta of `prescaler / kernel_hz` each; `seg1` is
//! the propagation segment plus phase segment 1, `seg2` is phase segment 2, the sample point
//! sits between them. The tolerated oscillator error `df` (each node's, all nodes alike) is
//! the smaller of the two conditions of ISO 11898-1 (Bosch, "The Configuration of the CAN Bit
//! Timing", 1999), `NBT` the quanta per bit:
//!
//! * resynchronisation, at most 10 bits between two edges: `df ≤ SJW / (20·NBT)`;
//! * sampling the bit after an error flag, 13 bits without an edge:
//!   `df ≤ min(PS1, PS2) / (2·(13·NBT − PS2))`, `PS1 = seg1 − prop`, `prop` the quanta that
//!   cover the bus's round-trip propagation delay.
//!
//! The same formulas and conditions as python-can 4.4's `BitTiming.oscillator_tolerance`
//! (whose values the tests compare against).

/// One nominal bit timing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BitTiming {
    /// Kernel clock cycles per time quantum.
    pub prescaler: u16,
    /// Propagation + phase segment 1 \[tq\].
    pub seg1_tq: u16,
    /// Phase segment 2 \[tq\].
    pub seg2_tq: u16,
    /// Synchronisation jump width \[tq\].
    pub sjw_tq: u16,
}

impl BitTiming {
    /// Time quanta per bit (`NBT`): sync + seg1 + seg2.
    pub fn quanta_per_bit(&self) -> u32 {
        u32::from(self.seg1_tq)
            .saturating_add(u32::from(self.seg2_tq))
            .saturating_add(1)
    }

    /// The bit rate this timing gives on `kernel_hz` \[bit/s\], rounded down; 0 for a zero
    /// prescaler.
    pub fn bitrate_bps(&self, kernel_hz: u32) -> u32 {
        let cycles = u32::from(self.prescaler).saturating_mul(self.quanta_per_bit());
        kernel_hz.checked_div(cycles).unwrap_or(0)
    }

    /// Sample point \[‰ of the bit\]: (sync + seg1) / NBT, rounded to nearest.
    pub fn sample_point_permille(&self) -> u32 {
        let before = u32::from(self.seg1_tq).saturating_add(1);
        let nbt = self.quanta_per_bit();
        before
            .saturating_mul(1000)
            .saturating_add(nbt / 2)
            .checked_div(nbt)
            .unwrap_or(0)
    }

    /// Quanta of the propagation segment needed for a round-trip delay of
    /// `propagation_delay_ns` on `kernel_hz` (rounded up).
    pub fn propagation_tq(&self, kernel_hz: u32, propagation_delay_ns: u32) -> u32 {
        // tq = prescaler / kernel_hz; prop = ceil(delay_ns · kernel_hz / (prescaler · 1e9)).
        let num = u64::from(propagation_delay_ns).saturating_mul(u64::from(kernel_hz));
        let den = u64::from(self.prescaler).saturating_mul(1_000_000_000);
        let Some(q) = num.checked_div(den) else {
            return u32::MAX;
        };
        let rounded_up = if num.checked_rem(den).unwrap_or(0) > 0 {
            q.saturating_add(1)
        } else {
            q
        };
        u32::try_from(rounded_up).unwrap_or(u32::MAX)
    }

    /// Tolerated oscillator error \[ppm\] (each node's; rounded down) for a round-trip
    /// propagation delay of `propagation_delay_ns` on `kernel_hz`: the smaller of the two
    /// conditions (module docs). 0 when the propagation segment leaves no phase segment 1.
    pub fn tolerance_ppm(&self, kernel_hz: u32, propagation_delay_ns: u32) -> u32 {
        let nbt = u64::from(self.quanta_per_bit());
        let ps2 = u64::from(self.seg2_tq);
        let prop = u64::from(self.propagation_tq(kernel_hz, propagation_delay_ns));
        let Some(ps1) = u64::from(self.seg1_tq).checked_sub(prop).filter(|p| *p > 0) else {
            return 0;
        };
        let resync = u64::from(self.sjw_tq)
            .saturating_mul(1_000_000)
            .checked_div(nbt.saturating_mul(20))
            .unwrap_or(0);
        let error_flag = ps1
            .min(ps2)
            .saturating_mul(1_000_000)
            .checked_div(nbt.saturating_mul(13).saturating_sub(ps2).saturating_mul(2))
            .unwrap_or(0);
        u32::try_from(resync.min(error_flag)).unwrap_or(u32::MAX)
    }
}

/// What the controller can be programmed to (nominal bit timing registers).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ControllerLimits {
    /// Largest prescaler.
    pub prescaler_max: u16,
    /// Largest seg1 \[tq\].
    pub seg1_max: u16,
    /// Largest seg2 \[tq\].
    pub seg2_max: u16,
    /// Largest SJW \[tq\].
    pub sjw_max: u16,
}

/// The STM32G4 FDCAN's nominal bit timing (NBTP: NBRP 1–512, NTSEG1 1–256, NTSEG2 1–128,
/// NSJW 1–128, each register value plus one).
pub const FDCAN_NOMINAL: ControllerLimits = ControllerLimits {
    prescaler_max: 512,
    seg1_max: 256,
    seg2_max: 128,
    sjw_max: 128,
};

/// Quanta per bit the search considers: CAN 2.0's programmable range (8 to 25), which every
/// controller on the bus supports.
pub const QUANTA_PER_BIT: core::ops::RangeInclusive<u32> = 8..=25;
/// Smallest phase segment 2 \[tq\]: the information processing time (2 tq).
pub const SEG2_MIN_TQ: u32 = 2;

/// What the bit timing must achieve.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TimingTarget {
    /// Bit rate \[bit/s\]; the kernel clock must divide into it exactly.
    pub bitrate_bps: u32,
    /// Sample point wanted \[‰\] (the bus's; CiA 301: 875 at 500 kbit/s).
    pub sample_point_permille: u32,
    /// Farthest the sample point may be from the wanted one \[‰\].
    pub sample_point_window_permille: u32,
    /// Round-trip propagation delay the propagation segment must cover \[ns\]:
    /// 2 × (transceiver loop delay + 5 ns/m × bus length).
    pub propagation_delay_ns: u32,
}

/// The walker's bus: 500 kbit/s, sample point 87.5 % (±2.5 %, CiA 301's 85–90 %), and a
/// round-trip delay of 600 ns (python-can's defaults: 250 ns transceiver loop, 10 m of
/// cable; the walker's bus is shorter).
pub const WALKER_BUS: TimingTarget = TimingTarget {
    bitrate_bps: protocol::BITRATE_BPS,
    sample_point_permille: 875,
    sample_point_window_permille: 25,
    propagation_delay_ns: 600,
};

/// Why no bit timing fits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BitTimingError {
    /// No prescaler divides `kernel_hz` into 8 to 25 quanta per bit at `bitrate_bps` with a
    /// sample point inside the window and a phase segment 1 after the propagation segment.
    NoTiming {
        /// The kernel clock \[Hz\].
        kernel_hz: u32,
        /// The bit rate wanted \[bit/s\].
        bitrate_bps: u32,
    },
}

/// A candidate's rank, smallest best: sample-point distance \[‰\], then the higher tolerance,
/// then the smaller prescaler.
type Preference = (u32, core::cmp::Reverse<u32>, u16);

/// The bit timing for `target` on `kernel_hz` within `limits`: among the exact divisions
/// (prescaler × quanta = kernel_hz / bitrate), the sample point nearest the wanted one; on
/// a tie the higher tolerated error; then the smaller prescaler. SJW = seg2 (the largest
/// the phase segments allow). Bounded: at most 18 × 24 candidates.
///
/// # Errors
/// [`BitTimingError::NoTiming`] when no candidate fits.
pub fn bit_timing(
    kernel_hz: u32,
    target: &TimingTarget,
    limits: &ControllerLimits,
) -> Result<BitTiming, BitTimingError> {
    let none = BitTimingError::NoTiming {
        kernel_hz,
        bitrate_bps: target.bitrate_bps,
    };
    let cycles_per_bit = kernel_hz.checked_div(target.bitrate_bps).ok_or(none)?;
    if kernel_hz.checked_rem(target.bitrate_bps) != Some(0) {
        return Err(none);
    }
    let mut best: Option<(Preference, BitTiming)> = None;
    for nbt in QUANTA_PER_BIT {
        if cycles_per_bit.checked_rem(nbt) != Some(0) {
            continue;
        }
        let Some(prescaler) = cycles_per_bit
            .checked_div(nbt)
            .and_then(|p| u16::try_from(p).ok())
            .filter(|p| (1..=limits.prescaler_max).contains(p))
        else {
            continue;
        };
        for seg2 in SEG2_MIN_TQ..nbt {
            let seg1 = nbt.saturating_sub(seg2).saturating_sub(1);
            let (Ok(seg1_tq), Ok(seg2_tq)) = (u16::try_from(seg1), u16::try_from(seg2)) else {
                continue;
            };
            if seg1_tq == 0 || seg1_tq > limits.seg1_max || seg2_tq > limits.seg2_max {
                continue;
            }
            let t = BitTiming {
                prescaler,
                seg1_tq,
                seg2_tq,
                sjw_tq: seg2_tq.min(limits.sjw_max),
            };
            let distance = t
                .sample_point_permille()
                .abs_diff(target.sample_point_permille);
            if distance > target.sample_point_window_permille {
                continue;
            }
            let tolerance = t.tolerance_ppm(kernel_hz, target.propagation_delay_ns);
            // SJW may not exceed phase segment 1 either.
            let prop = t.propagation_tq(kernel_hz, target.propagation_delay_ns);
            if tolerance == 0 || seg1.saturating_sub(prop) < u32::from(t.sjw_tq) {
                continue;
            }
            let key = (distance, core::cmp::Reverse(tolerance), prescaler);
            if best.as_ref().is_none_or(|(k, _)| key < *k) {
                best = Some((key, t));
            }
        }
    }
    best.map(|(_, t)| t).ok_or(none)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn timing(prescaler: u16, seg1_tq: u16, seg2_tq: u16, sjw_tq: u16) -> BitTiming {
        BitTiming {
            prescaler,
            seg1_tq,
            seg2_tq,
            sjw_tq,
        }
    }

    // Known-good values: python-can 4.4.2, `BitTiming.from_sample_point(f_clock, 500_000,
    // 87.5)` and `.oscillator_tolerance()` (defaults: 250 ns loop delay, 10 m), printed as
    // 0.48543689…%, 0.45662100…%, 0.58365758…% for the timings below.

    #[test]
    fn eight_mhz_gives_the_crystal_timing_the_board_always_used() {
        let t = bit_timing(8_000_000, &WALKER_BUS, &FDCAN_NOMINAL).unwrap();
        assert_eq!(t, timing(1, 13, 2, 2));
        assert_eq!(t.bitrate_bps(8_000_000), 500_000);
        assert_eq!(t.sample_point_permille(), 875);
        assert_eq!(t.tolerance_ppm(8_000_000, 600), 4_854);
    }

    #[test]
    fn sixteen_mhz_gives_prescaler_2_and_the_same_tolerance() {
        let t = bit_timing(16_000_000, &WALKER_BUS, &FDCAN_NOMINAL).unwrap();
        assert_eq!(t, timing(2, 13, 2, 2));
        assert_eq!(t.bitrate_bps(16_000_000), 500_000);
        assert_eq!(t.tolerance_ppm(16_000_000, 600), 4_854);
    }

    #[test]
    fn one_seventy_mhz_gives_prescaler_20_nearest_the_sample_point() {
        let t = bit_timing(170_000_000, &WALKER_BUS, &FDCAN_NOMINAL).unwrap();
        assert_eq!(t, timing(20, 14, 2, 2));
        assert_eq!(t.bitrate_bps(170_000_000), 500_000);
        assert_eq!(t.sample_point_permille(), 882);
        assert_eq!(t.tolerance_ppm(170_000_000, 600), 4_566);
        // The 85 % alternative python-can also reports: 0.5836…%.
        assert_eq!(timing(17, 16, 3, 3).tolerance_ppm(170_000_000, 600), 5_836);
    }

    #[test]
    fn twenty_four_mhz_crystal_keeps_the_sample_point() {
        let t = bit_timing(24_000_000, &WALKER_BUS, &FDCAN_NOMINAL).unwrap();
        // 24 tq at prescaler 2 and 16 tq at prescaler 3 tie (87.5 %, 0.4854 %; python-can
        // picks the second, its seg1 is limited to 16): the smaller prescaler wins.
        assert_eq!(t, timing(2, 20, 3, 3));
        assert_eq!(t.bitrate_bps(24_000_000), 500_000);
        assert_eq!(t.sample_point_permille(), 875);
        assert_eq!(t.tolerance_ppm(24_000_000, 600), 4_854);
    }

    #[test]
    fn a_clock_that_does_not_divide_has_no_timing() {
        let e = bit_timing(8_000_001, &WALKER_BUS, &FDCAN_NOMINAL);
        assert_eq!(
            e,
            Err(BitTimingError::NoTiming {
                kernel_hz: 8_000_001,
                bitrate_bps: 500_000
            })
        );
        assert!(
            bit_timing(3_000_000, &WALKER_BUS, &FDCAN_NOMINAL).is_err(),
            "6 tq"
        );
        assert!(bit_timing(0, &WALKER_BUS, &FDCAN_NOMINAL).is_err());
    }

    #[test]
    fn a_long_bus_leaves_no_phase_segment() {
        // 5 µs round trip: more than a whole 2 µs bit.
        let long = TimingTarget {
            propagation_delay_ns: 5_000,
            ..WALKER_BUS
        };
        assert!(bit_timing(8_000_000, &long, &FDCAN_NOMINAL).is_err());
        assert_eq!(timing(1, 13, 2, 2).tolerance_ppm(8_000_000, 5_000), 0);
    }

    #[test]
    fn the_tolerance_is_the_smaller_condition() {
        // SJW 1 of 16 tq: resynchronisation limits it, 1e6 / 320 = 3125 ppm.
        assert_eq!(timing(1, 13, 2, 1).tolerance_ppm(8_000_000, 600), 3_125);
        // A lower sample point tolerates more: 1 + 9 + 6 tq, SJW 4; PS1 = 9 − 5 tq of
        // propagation = 4 → min(4e6 / 320, 4e6 / (2·(208 − 6))) = min(12500, 9900).
        assert_eq!(timing(1, 9, 6, 4).tolerance_ppm(8_000_000, 600), 9_900);
    }
}
