//! Logging shim: the macros expand to `defmt` calls with the `defmt` feature and to nothing
//! (arguments still type-checked) without it, so the library builds for the host, the
//! simulator and the QEMU binary without a logger.
#![allow(unused_macros)]

#[cfg(feature = "defmt")]
macro_rules! log_info {
    ($($t:tt)*) => { defmt::info!($($t)*) };
}
#[cfg(not(feature = "defmt"))]
macro_rules! log_info {
    ($fmt:literal $(, $arg:expr)* $(,)?) => {{
        if false {
            let _ = ($crate::fmt::Ignore, $(&$arg),*);
        }
    }};
}

#[cfg(feature = "defmt")]
macro_rules! log_warn {
    ($($t:tt)*) => { defmt::warn!($($t)*) };
}
#[cfg(not(feature = "defmt"))]
macro_rules! log_warn {
    ($fmt:literal $(, $arg:expr)* $(,)?) => {{
        if false {
            let _ = ($crate::fmt::Ignore, $(&$arg),*);
        }
    }};
}

/// A bench-log line through a [`crate::log_limit::LogLimiter`]: `log_limited!(limiter, kind,
/// now, "format", args...)`. Logged while the kind's bucket has a token; the first line
/// after a suppression is followed by the count left out. Without the `defmt` feature
/// nothing is evaluated but the arguments' types (the limiter is not consulted).
#[cfg(feature = "defmt")]
macro_rules! log_limited {
    ($limiter:expr, $kind:expr, $now:expr, $($t:tt)*) => {{
        if let $crate::log_limit::Allowance::Log { suppressed } = $limiter.allow($kind, $now) {
            defmt::info!($($t)*);
            if suppressed > 0 {
                defmt::warn!("{} earlier {} lines left out (rate limit)", suppressed, $kind);
            }
        }
    }};
}
#[cfg(not(feature = "defmt"))]
macro_rules! log_limited {
    ($limiter:expr, $kind:expr, $now:expr, $fmt:literal $(, $arg:expr)* $(,)?) => {{
        if false {
            let _ = (&$limiter, $kind, $now, $(&$arg),*);
        }
    }};
}

/// Placeholder value used by the no-logger expansion.
#[cfg(not(feature = "defmt"))]
#[allow(dead_code)]
pub(crate) struct Ignore;

// The node's own lines go through `crate::bench_log` (rate-limited, one per tick); these
// stay for direct lines elsewhere.
#[allow(unused_imports)]
pub(crate) use log_info;
pub(crate) use log_limited;
#[allow(unused_imports)]
pub(crate) use log_warn;
