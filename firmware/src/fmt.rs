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
    ($($t:tt)*) => {{
        if false {
            let _ = ($crate::fmt::Ignore);
        }
    }};
}

#[cfg(feature = "defmt")]
macro_rules! log_warn {
    ($($t:tt)*) => { defmt::warn!($($t)*) };
}
#[cfg(not(feature = "defmt"))]
macro_rules! log_warn {
    ($($t:tt)*) => {{
        if false {
            let _ = ($crate::fmt::Ignore);
        }
    }};
}

/// Placeholder value used by the no-logger expansion.
#[cfg(not(feature = "defmt"))]
pub(crate) struct Ignore;

pub(crate) use log_info;
pub(crate) use log_warn;
