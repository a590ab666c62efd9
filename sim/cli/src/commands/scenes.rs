//! `walker scenes`: list the scenes and their parameters.

use super::print_json;
use crate::output;
use anyhow::Result;
use sim::report::SceneCatalogue;
use std::io::Write;
use std::process::ExitCode;

/// Runs `walker scenes`, as JSON with `as_json`.
pub fn run(as_json: bool) -> Result<ExitCode> {
    let catalogue = SceneCatalogue::builtin()?;
    if as_json {
        print_json(&catalogue)?;
    } else {
        output::text(|out| print_text(out, &catalogue))?;
    }
    Ok(ExitCode::SUCCESS)
}

fn print_text(out: &mut dyn Write, catalogue: &SceneCatalogue) -> std::io::Result<()> {
    for s in &catalogue.scenes {
        writeln!(out, "{} — {}", s.name, s.summary)?;
        for p in &s.parameters {
            // The default as JSON writes it (`1.0`, `0.009`; `null` if not finite).
            writeln!(
                out,
                "    {:<24} default {} [{}]  {}",
                p.name,
                serde_json::Value::from(p.default),
                p.unit,
                p.doc
            )?;
        }
    }
    Ok(())
}
