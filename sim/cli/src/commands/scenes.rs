//! `walker scenes`: list the scenes and their parameters.

use super::print_json;
use anyhow::Result;
use sim::report::SceneCatalogue;
use std::process::ExitCode;

/// Runs `walker scenes`, as JSON with `as_json`.
pub fn run(as_json: bool) -> Result<ExitCode> {
    let catalogue = SceneCatalogue::builtin()?;
    if as_json {
        print_json(&catalogue)?;
    } else {
        for s in &catalogue.scenes {
            println!("{} — {}", s.name, s.summary);
            for p in &s.parameters {
                // The default as JSON writes it (`1.0`, `0.009`; `null` if not finite).
                println!(
                    "    {:<24} default {} [{}]  {}",
                    p.name,
                    serde_json::Value::from(p.default),
                    p.unit,
                    p.doc
                );
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}
