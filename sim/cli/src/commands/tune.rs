//! `walker tune`: search parameters within bounds for the smallest largest |eigenvalue|.

use super::print_json;
use crate::input_error::InputError;
use crate::options::Common;
use anyhow::Result;
use clap::Args;
use sim::tune::{tune, TunedParameter};
use std::process::ExitCode;

/// Options of `walker tune`.
#[derive(Args)]
pub struct TuneArgs {
    #[command(flatten)]
    pub common: Common,
    /// A parameter the search may change: `name=min:max` (repeatable).
    #[arg(long = "vary", value_name = "NAME=MIN:MAX", required = true)]
    pub vary: Vec<String>,
    /// Gait searches allowed.
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
    let params = vary
        .iter()
        .map(|v| parse_vary(v))
        .collect::<Result<Vec<_>, _>>()?;
    let result = tune(&scene, &params, evaluations, &common.newton())?;
    if common.json {
        print_json(&result)?;
    } else {
        println!("{} evaluations", result.history.len());
        for (p, v) in result.parameters.iter().zip(&result.best.values) {
            println!(
                "    {:<36} {:>12.6}   (bounds {} .. {})",
                p.name, v, p.min, p.max
            );
        }
        match result.best.max_abs_eigenvalue {
            Some(m) => println!("best max |λ| = {m:.6}"),
            None => println!("no gait found"),
        }
    }
    Ok(ExitCode::SUCCESS)
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
    if !(min.is_finite() && max.is_finite() && min < max) {
        return Err(bad());
    }
    Ok(TunedParameter {
        name: name.trim().to_string(),
        min,
        max,
    })
}
