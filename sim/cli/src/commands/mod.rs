//! One module per `walker` subcommand: each parses nothing, runs its study through the engine
//! and prints its report as text or JSON.

pub mod accuracy;
pub mod basin;
pub mod gait;
pub mod gaits;
pub mod optimize;
pub mod orbit_diagram;
pub mod robustness;
pub mod scenes;
pub mod sil;
pub mod stability_map;
pub mod sweep;
pub mod tune;
pub mod walk;

use crate::output;
use anyhow::Result;
use serde::Serialize;
use std::process::ExitCode;

/// Prints a report as pretty JSON on stdout, every object key-sorted
/// ([`sim::report::to_json`]); a write error is an [`output::StdoutError`].
pub fn print_json<T: Serialize + ?Sized>(report: &T) -> Result<()> {
    let value = sim::report::to_json(report)?;
    output::text(|out| {
        // serde_json hands an I/O error back unchanged through this conversion.
        serde_json::to_writer_pretty(&mut *out, &value).map_err(std::io::Error::from)?;
        writeln!(out)
    })?;
    Ok(())
}

/// The exit code of a walk (`walk`, `sil`): 0 if it completed every step, 3 if it ended early
/// because the walker fell (its report's `failure`).
pub fn walk_exit_code(walk: &sim::stride::walk::Walk) -> ExitCode {
    if walk.failure.is_some() {
        ExitCode::from(FELL)
    } else {
        ExitCode::SUCCESS
    }
}

/// Exit code of a walk that ended early: the walker fell.
pub const FELL: u8 = 3;

/// A number as the text output shows it: JSON has no non-finite numbers, so a value the JSON
/// writes as `null` reads back (and prints) as NaN.
pub fn shown(x: f64) -> f64 {
    if x.is_finite() {
        x
    } else {
        f64::NAN
    }
}
