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

/// Placeholder value used by the no-logger expansion.
#[cfg(not(feature = "defmt"))]
#[allow(dead_code)]
pub(crate) struct Ignore;

// The node's own lines go through `crate::bench_log` (rate-limited, one per tick); these
// stay for direct lines elsewhere.
#[allow(unused_imports)]
pub(crate) use log_info;
#[allow(unused_imports)]
pub(crate) use log_warn;
