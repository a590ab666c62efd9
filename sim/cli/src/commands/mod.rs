//! One module per `walker` subcommand: each parses nothing, runs its study through the engine
//! and prints its report as text or JSON.

pub mod accuracy;
pub mod gait;
pub mod scenes;
pub mod sil;
pub mod sweep;
pub mod tune;
pub mod walk;

use anyhow::Result;
use serde::Serialize;
use std::io::Write;

/// Prints a report as pretty JSON on stdout, every object key-sorted
/// ([`sim::report::to_json`]).
pub fn print_json<T: Serialize + ?Sized>(report: &T) -> Result<()> {
    let value = sim::report::to_json(report)?;
    let mut out = std::io::stdout().lock();
    serde_json::to_writer_pretty(&mut out, &value)?;
    writeln!(out)?;
    Ok(())
}

/// A number as the text output shows it: JSON has no non-finite numbers, so a value the JSON
/// writes as `null` reads back (and prints) as NaN.
pub fn shown(x: f64) -> f64 {
    if x.is_finite() {
        x
    } else {
        f64::NAN
    }
}
