//! Bounds on the counts and factors the options give: a count sizes memory or work, so a
//! mistyped one (`--points 18446744073709551615`) must be refused before anything is
//! allocated, never panic or abort on allocation.

use crate::input_error::InputError;

/// Most points of a sweep (`walker sweep --points`): the library's bound, which the Python
/// package checks too.
pub use sim::analysis::continuation::{MAX_SWEEP_PERIOD, MAX_SWEEP_POINTS};

/// Most values of an orbit diagram (`walker orbit-diagram --points`): the library's bound,
/// which the Python package checks too.
pub use sim::analysis::orbit_diagram::MAX_ORBIT_POINTS;

/// Most values along one axis of a stability map (`walker stability-map --x K=A:B:N`).
pub const MAX_MAP_AXIS_POINTS: usize = 500;

/// Most cells of a stability map (`N × M`): each is a gait search (the library's bound, which
/// the Python package checks too).
pub use sim::analysis::stability_map::MAX_MAP_CELLS;

/// Most steps of a walk (`walker walk --steps`, `walker sil --steps`): the library's bound,
/// which the Python package checks too.
pub use sim::stride::walk::MAX_WALK_STEPS;

/// Most gait searches of `walker tune --evaluations`.
pub const MAX_TUNE_EVALUATIONS: usize = 10_000;

/// Slowest and fastest pacing of `walker sil --realtime` [multiple of real time]: 0.001 runs
/// a second of walk in a quarter of an hour of wall time, 1000 faster than the simulation
/// itself can go.
pub const REALTIME_RANGE: std::ops::RangeInclusive<f64> = 1e-3..=1e3;

/// `value` of option `flag` (e.g. `--points`) within `min..=max`, else bad input naming both.
pub fn count(flag: &str, value: usize, min: usize, max: usize) -> Result<usize, InputError> {
    if (min..=max).contains(&value) {
        Ok(value)
    } else {
        Err(InputError::Other(format!(
            "{flag} must be between {min} and {max}, got {value}"
        )))
    }
}

/// `value` of option `flag` a finite number within `range`, else bad input naming both.
pub fn within(
    flag: &str,
    value: f64,
    range: &std::ops::RangeInclusive<f64>,
) -> Result<f64, InputError> {
    if value.is_finite() && range.contains(&value) {
        Ok(value)
    } else {
        Err(InputError::Other(format!(
            "{flag} must be a number between {} and {}, got {value:?}",
            range.start(),
            range.end()
        )))
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn counts_and_factors_outside_their_range_are_named() {
        assert_eq!(count("--points", 3, 2, MAX_SWEEP_POINTS).unwrap(), 3);
        let e = count("--points", usize::MAX, 2, MAX_SWEEP_POINTS).unwrap_err();
        assert!(e.to_string().contains("--points"), "{e}");
        assert!(e.to_string().contains(&usize::MAX.to_string()), "{e}");
        assert!(count("--points", 1, 2, MAX_SWEEP_POINTS).is_err());
        assert_eq!(within("--realtime", 1.0, &REALTIME_RANGE).unwrap(), 1.0);
        for bad in [1e-300, 0.0, -1.0, f64::NAN, f64::INFINITY, 1e300] {
            assert!(within("--realtime", bad, &REALTIME_RANGE).is_err(), "{bad}");
        }
    }
}
