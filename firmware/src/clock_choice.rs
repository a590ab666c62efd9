//! Which clock the node runs on, decided once at start-up from what the board observed of
//! its crystal: started within the time budget or not, and its frequency measured against
//! the internal oscillator. Then the CAN bit timing for the clock chosen, the oscillator
//! error that timing tolerates, and whether the power stage may ever be enabled.
//!
//! The rules:
//! * a crystal that did not start within the budget is not used (the node runs on the
//!   internal oscillator);
//! * a crystal that started is used when its measured frequency is within
//!   [`ClockPlan::crystal_check_window_ppm`] of one of the frequencies the board may carry;
//!   the window is the measurement's own uncertainty (the internal reference's error), so a
//!   reading outside it is a wrong crystal, not a reference error; otherwise the internal
//!   oscillator;
//! * the CAN timing is computed for the chosen clock's kernel frequency
//!   ([`crate::can_timing::bit_timing`]); the error the node's clock may have is the smaller
//!   of that timing's tolerance and the tolerance of the timing every other node uses (each
//!   node on the bus must stay within the tolerance of every receiver's timing);
//! * the power stage is allowed only when the chosen oscillator's specified error is within
//!   that tolerance. Otherwise the node still speaks on the bus (best effort: it says why),
//!   but refuses `Enable` (fault `ClockTolerance`).

use protocol::{ClockSource, CrystalStatus};

use crate::can_timing::{
    bit_timing, BitTiming, ControllerLimits, TimingTarget, FDCAN_NOMINAL, WALKER_BUS,
};

/// One clock the board can run the CAN controller from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OscillatorSpec {
    /// Nominal frequency of the oscillator \[Hz\].
    pub nominal_hz: u32,
    /// Specified error bound, over the conditions the node runs in \[ppm\].
    pub error_ppm: u32,
    /// The CAN controller's kernel clock when the node runs on this oscillator \[Hz\].
    pub can_kernel_hz: u32,
}

/// The board's clock facts, fixed at build time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ClockPlan {
    /// The crystal frequencies the board may carry, most likely first.
    pub crystals: &'static [OscillatorSpec],
    /// The internal oscillator.
    pub internal: OscillatorSpec,
    /// Largest distance of a measured crystal frequency from a nominal one that still
    /// identifies that crystal \[ppm\]: the measurement's uncertainty.
    pub crystal_check_window_ppm: u32,
    /// The bus's timing target (bit rate, sample point, propagation delay).
    pub can: TimingTarget,
    /// The controller's limits.
    pub limits: ControllerLimits,
    /// Tolerance of the timing the other nodes use \[ppm\].
    pub bus_tolerance_ppm: u32,
}

/// What the board observed of its crystal before choosing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum CrystalObservation {
    /// The crystal was not ready within the start-up budget.
    TimedOut,
    /// The crystal started; its frequency measured against the internal reference \[Hz\].
    Started {
        /// Measured frequency \[Hz\].
        measured_hz: u32,
    },
}

/// Why the power stage may not be enabled on this clock.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ClockRefusal {
    /// The oscillator's specified error exceeds what the CAN timing tolerates.
    ToleranceExceeded {
        /// The oscillator's error bound \[ppm\].
        oscillator_ppm: u32,
        /// What the timing tolerates \[ppm\].
        tolerated_ppm: u32,
    },
    /// No bit timing at all for the kernel clock.
    NoBitTiming {
        /// The kernel clock \[Hz\].
        kernel_hz: u32,
    },
}

/// The outcome: the clock the node runs on and what follows from it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ClockChoice {
    /// Crystal or internal oscillator.
    pub source: ClockSource,
    /// What the crystal check found.
    pub crystal: CrystalStatus,
    /// The crystal's measured frequency \[Hz\], 0 when it did not start.
    pub crystal_measured_hz: u32,
    /// Nominal frequency of the oscillator in use \[Hz\].
    pub oscillator_hz: u32,
    /// The CAN controller's kernel clock \[Hz\].
    pub can_kernel_hz: u32,
    /// The bit timing for that kernel clock (`None`: none fits; the board keeps its
    /// controller's default and the power stage is refused).
    pub timing: Option<BitTiming>,
    /// The oscillator error the bus tolerates for this node \[ppm\].
    pub tolerated_ppm: u32,
    /// The oscillator's specified error \[ppm\].
    pub oscillator_ppm: u32,
    /// `None`: the power stage may be enabled; otherwise why not.
    pub refusal: Option<ClockRefusal>,
}

impl ClockChoice {
    /// A node without a clock choice (the simulator, the QEMU scenarios): source and crystal
    /// unknown, nothing measured, nothing refused.
    pub const SIMULATED: ClockChoice = ClockChoice {
        source: ClockSource::Unknown,
        crystal: CrystalStatus::NotChecked,
        crystal_measured_hz: 0,
        oscillator_hz: 0,
        can_kernel_hz: 0,
        timing: None,
        tolerated_ppm: 0,
        oscillator_ppm: 0,
        refusal: None,
    };

    /// True when the power stage may be enabled.
    pub fn power_stage_allowed(&self) -> bool {
        self.refusal.is_none()
    }
}

/// Distance of `measured_hz` from `nominal_hz` \[ppm of nominal\], saturating.
pub fn deviation_ppm(measured_hz: u32, nominal_hz: u32) -> u32 {
    let diff = u64::from(measured_hz.abs_diff(nominal_hz));
    diff.saturating_mul(1_000_000)
        .checked_div(u64::from(nominal_hz))
        .map_or(u32::MAX, |d| u32::try_from(d).unwrap_or(u32::MAX))
}

/// The crystal a measurement identifies: the nearest nominal frequency within the window.
fn identify(plan: &ClockPlan, measured_hz: u32) -> Option<OscillatorSpec> {
    plan.crystals
        .iter()
        .map(|c| (deviation_ppm(measured_hz, c.nominal_hz), *c))
        .filter(|(d, _)| *d <= plan.crystal_check_window_ppm)
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c)
}

/// Choose the clock (module docs for the rules).
pub fn choose(plan: &ClockPlan, observed: CrystalObservation) -> ClockChoice {
    let (crystal, measured_hz, spec) = match observed {
        CrystalObservation::TimedOut => (CrystalStatus::Timeout, 0, None),
        CrystalObservation::Started { measured_hz } => match identify(plan, measured_hz) {
            Some(c) => (CrystalStatus::Running, measured_hz, Some(c)),
            None => (CrystalStatus::WrongFrequency, measured_hz, None),
        },
    };
    let (source, osc) = match spec {
        Some(c) => (ClockSource::Crystal, c),
        None => (ClockSource::Internal, plan.internal),
    };
    let timing = bit_timing(osc.can_kernel_hz, &plan.can, &plan.limits).ok();
    let own_ppm = timing.map_or(0, |t| {
        t.tolerance_ppm(osc.can_kernel_hz, plan.can.propagation_delay_ns)
    });
    let tolerated_ppm = own_ppm.min(plan.bus_tolerance_ppm);
    let refusal = if timing.is_none() {
        Some(ClockRefusal::NoBitTiming {
            kernel_hz: osc.can_kernel_hz,
        })
    } else if osc.error_ppm > tolerated_ppm {
        Some(ClockRefusal::ToleranceExceeded {
            oscillator_ppm: osc.error_ppm,
            tolerated_ppm,
        })
    } else {
        None
    };
    ClockChoice {
        source,
        crystal,
        crystal_measured_hz: measured_hz,
        oscillator_hz: osc.nominal_hz,
        can_kernel_hz: osc.can_kernel_hz,
        timing,
        tolerated_ppm,
        oscillator_ppm: osc.error_ppm,
        refusal,
    }
}

/// The internal oscillator's error bound \[ppm\]: ±1 %, the factory trim RM0440 gives for the
/// STM32G4's HSI16 (RCC_ICSCR.HSITRIM: "should trim the HSI16 to 16 MHz ± 1 %"). A floor:
/// its drift over temperature (in DS12589, not read here) comes on top.
pub const HSI16_ERROR_PPM: u32 = 10_000;
/// A crystal's error bound \[ppm\]: initial tolerance, temperature and ageing of a common
/// 8 MHz part (±30 + ±50 + a margin); the board's Y2 is not identified.
pub const CRYSTAL_ERROR_PPM: u32 = 100;
/// Tolerance of the timing the other nodes of the walker's bus use (8 MHz crystal, 1 + 13 +
/// 2 tq, SJW 2, 600 ns round trip) \[ppm\]; a test recomputes it.
pub const WALKER_BUS_TOLERANCE_PPM: u32 = 4_854;

/// The B-G431B-ESC1's clocks: an 8 MHz crystal (Zephyr, NuttX, the UM2516 transcription) or a
/// 24 MHz one (ST's Arduino variant's `HSE_VALUE`), each the FDCAN kernel clock itself; the
/// HSI16 through the PLL (÷4 × 85 ÷ 2 = 170 MHz) with the FDCAN on PCLK1 (170 MHz). The
/// crystal is measured against the HSI16, so a reading within the HSI16's own error (plus the
/// crystal's) cannot be told from a good crystal: that is the window.
pub const B_G431B_ESC1: ClockPlan = ClockPlan {
    crystals: &[
        OscillatorSpec {
            nominal_hz: 8_000_000,
            error_ppm: CRYSTAL_ERROR_PPM,
            can_kernel_hz: 8_000_000,
        },
        OscillatorSpec {
            nominal_hz: 24_000_000,
            error_ppm: CRYSTAL_ERROR_PPM,
            can_kernel_hz: 24_000_000,
        },
    ],
    internal: OscillatorSpec {
        nominal_hz: 16_000_000,
        error_ppm: HSI16_ERROR_PPM,
        can_kernel_hz: 170_000_000,
    },
    crystal_check_window_ppm: HSI16_ERROR_PPM.saturating_add(CRYSTAL_ERROR_PPM),
    can: WALKER_BUS,
    limits: FDCAN_NOMINAL,
    bus_tolerance_ppm: WALKER_BUS_TOLERANCE_PPM,
};

/// Frequency of a clock counted against a reference over one window \[Hz\]:
/// `counted_cycles` of the clock while the reference (of `reference_hz`) made
/// `reference_cycles`. Rounded to nearest; `None` for an empty window or a result past u32.
pub fn measured_hz(counted_cycles: u32, reference_cycles: u32, reference_hz: u32) -> Option<u32> {
    let den = u64::from(reference_cycles);
    if den == 0 {
        return None;
    }
    let num = u64::from(counted_cycles)
        .checked_mul(u64::from(reference_hz))?
        .checked_add(den / 2)?;
    u32::try_from(num.checked_div(den)?).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_measurement_counts_cycles_against_the_reference() {
        // 10 ms of a 16 MHz reference: 160 000 cycles; 8 MHz counts 80 000 in it.
        assert_eq!(measured_hz(80_000, 160_000, 16_000_000), Some(8_000_000));
        assert_eq!(measured_hz(80_800, 160_000, 16_000_000), Some(8_080_000));
        assert_eq!(measured_hz(1, 0, 16_000_000), None);
        assert_eq!(measured_hz(u32::MAX, 1, 16_000_000), None, "past u32");
    }

    #[test]
    fn deviation_is_in_ppm_of_the_nominal() {
        assert_eq!(deviation_ppm(8_080_000, 8_000_000), 10_000);
        assert_eq!(deviation_ppm(7_920_000, 8_000_000), 10_000);
        assert_eq!(deviation_ppm(8_000_000, 0), u32::MAX);
    }
}
