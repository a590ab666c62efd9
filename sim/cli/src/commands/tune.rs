//! `walker tune`: search parameters within bounds for the smallest largest |eigenvalue|.

use super::print_json;
use crate::input_error::InputError;
use crate::limits;
use crate::options::Common;
use crate::output;
use crate::progress::Progress;
use anyhow::Result;
use clap::Args;
use sim::analysis::tune::{tune_with_progress, TuneResult, TuneSettings, TunedParameter};
use std::io::Write;
use std::process::ExitCode;

/// Options of `walker tune`.
#[derive(Args)]
pub struct TuneArgs {
    #[command(flatten)]
    pub common: Common,
    /// A parameter the search may change: `name=min:max` (repeatable, each name once).
    #[arg(long = "vary", value_name = "NAME=MIN:MAX", required = true)]
    pub vary: Vec<String>,
    /// Gait searches allowed (1 to 10,000; the report's `history` has at most this many).
    #[arg(long, default_value_t = 60)]
    pub evaluations: usize,
}

/// Runs `walker tune`.
pub fn run(args: TuneArgs) -> Result<ExitCode> {
    let TuneArgs {
        common,
        vary,
        evaluations,
    } = args;
    let scene = common.scene()?;
    common.setup(&scene)?;
    let evaluations = limits::count(
        "--evaluations",
        evaluations,
        1,
        limits::MAX_TUNE_EVALUATIONS,
    )?;
    let params = vary
        .iter()
        .map(|v| parse_vary(v))
        .collect::<Result<Vec<_>, _>>()?;
    // Each parameter once, whatever name or alias it is given by (`slope`, `slope_rad`).
    let canonical = params
        .iter()
        .map(|p| scene.parameter_name(&p.name))
        .collect::<Result<Vec<_>, _>>()?;
    for (i, (p, name)) in params.iter().zip(&canonical).enumerate() {
        if let Some(q) = params[..i]
            .iter()
            .zip(&canonical)
            .find(|(_, other)| *other == name)
        {
            return Err(InputError::Other(format!(
                "--vary: parameter `{name}` given twice (as `{}` and `{}`; each parameter once)",
                q.0.name, p.name
            ))
            .into());
        }
    }
    let progress = Progress::after(
        super::walk::PROGRESS_DELAY,
        evaluations,
        "tune (gait searches)",
        !common.json,
    );
    let (setup_for, newton) = (common.setup_for(), common.newton());
    let settings = TuneSettings {
        params: &params,
        evaluations,
        setup_for: &setup_for,
        newton: &newton,
        homotopy: &common.homotopy(),
    };
    let result = tune_with_progress(&scene, &settings, &|| progress.tick())?;
    progress.finish();
    if common.json {
        print_json(&result)?;
    } else {
        output::text(|out| print_text(out, &result))?;
    }
    Ok(ExitCode::SUCCESS)
}

fn print_text(out: &mut dyn Write, result: &TuneResult) -> std::io::Result<()> {
    writeln!(out, "{} evaluations", result.history.len())?;
    for (p, v) in result.parameters.iter().zip(&result.best.values) {
        writeln!(
            out,
            "    {:<36} {:>12.6}   (bounds {} .. {})",
            p.name, v, p.min, p.max
        )?;
    }
    match (
        result.best.max_abs_eigenvalue,
        result.best.gait_source,
        result.best.step_period_s,
    ) {
        (Some(m), Some(source), Some(period_s)) => {
            writeln!(out, "best max |λ| = {m:.6}")?;
            writeln!(
                out,
                "gait: {} (step period {period_s:.4} s), as `walker gait` finds at these values",
                source.describe()
            )
        }
        (Some(m), _, _) => writeln!(out, "best max |λ| = {m:.6}"),
        _ => writeln!(out, "no gait found"),
    }
}

/// A `--vary name=min:max` option.
fn parse_vary(v: &str) -> Result<TunedParameter, InputError> {
    let bad = || InputError::Other(format!("--vary `{v}`: expected name=min:max"));
    let (name, range) = v.split_once('=').ok_or_else(bad)?;
    let (lo, hi) = range.split_once(':').ok_or_else(bad)?;
    let (min, max): (f64, f64) = (
        lo.trim().parse().map_err(|_| bad())?,
        hi.trim().parse().map_err(|_| bad())?,
    );
    if !(min.is_finite() && max.is_finite()) {
        return Err(InputError::Other(format!(
            "--vary `{v}`: the bounds must be finite numbers"
        )));
    }
    if min >= max {
        return Err(InputError::Other(format!(
            "--vary `{v}`: min {min} must be below max {max} (name=min:max)"
        )));
    }
    Ok(TunedParameter {
        name: name.trim().to_string(),
        min,
        max,
    })
}
