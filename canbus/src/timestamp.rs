//! Wall-clock timestamps of simulated events: an origin [ns since the Unix epoch] plus the
//! simulated time \[ns\], checked so that a far origin is an error instead of a wrapped time.

use thiserror::Error;

/// `origin_ns + t_ns` does not fit in a `u64` of nanoseconds (later than
/// 18446744073.709551615 s after the Unix epoch, in the year 2554).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Error)]
#[error(
    "timestamp origin {origin_ns} ns + simulated time {t_ns} ns is later than the latest \
     representable time (u64 nanoseconds since the Unix epoch, 18446744073.709551615 s)"
)]
pub struct TimestampOverflow {
    /// The origin [ns since the Unix epoch].
    pub origin_ns: u64,
    /// The simulated time \[ns\].
    pub t_ns: u64,
}

/// The timestamp of simulated time `t_ns` on a clock starting at `origin_ns`
/// [ns since the Unix epoch].
///
/// # Errors
/// [`TimestampOverflow`] when the sum does not fit.
pub fn stamp_ns(origin_ns: u64, t_ns: u64) -> Result<u64, TimestampOverflow> {
    origin_ns
        .checked_add(t_ns)
        .ok_or(TimestampOverflow { origin_ns, t_ns })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_or_names_both_terms() {
        assert_eq!(
            stamp_ns(1_700_000_000_000_000_000, 5),
            Ok(1_700_000_000_000_000_005)
        );
        assert_eq!(stamp_ns(u64::MAX, 0), Ok(u64::MAX));
        let e = stamp_ns(18_446_744_073_000_000_000, 1_000_000_000).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains("18446744073000000000") && msg.contains("1000000000"),
            "{msg}"
        );
    }
}
