//! `walker sweep`: continuation, following the gait while one parameter changes.

use super::print_json;
use crate::input_error::InputError;
use crate::limits;
use crate::options::Common;
use crate::output;
use anyhow::Result;
use clap::Args;
use sim::continuation::sweep;
use sim::report::{SweepPointRecord, SweepReport};
use std::io::Write;
use std::process::ExitCode;

/// Options of `walker sweep`.
#[derive(Args)]
pub struct SweepArgs {
    #[command(flatten)]
    pub common: Common,
    /// Parameter to vary.
    #[arg(long)]
    pub param: String,
    /// First value.
    #[arg(long, allow_negative_numbers = true)]
    pub from: f64,
    /// Last value.
    #[arg(long, allow_negative_numbers = true)]
    pub to: f64,
    /// Number of points (2 to 10,000).
    #[arg(long)]
    pub points: usize,
}

/// Runs `walker sweep`.
pub fn run(args: SweepArgs) -> Result<ExitCode> {
    let SweepArgs {
        common,
        param,
        from,
        to,
        points,
    } = args;
    let scene = common.scene()?;
    common.setup(&scene)?;
    if !(from.is_finite() && to.is_finite()) {
        return Err(InputError::Other("--from and --to must be finite".into()).into());
    }
    let points = limits::count("--points", points, 2, limits::MAX_SWEEP_POINTS)?;
    let (pts, bounds) =
        sweep(&scene, &param, from, to, points, &common.newton()).map_err(|e| match e {
            sim::continuation::SweepError::Scene(s) => InputError::Scene(s),
            other => InputError::Other(other.to_string()),
        })?;
    let walker_for = |value: f64| {
        let mut s = scene.clone();
        s.set(&param, value).ok()?;
        let w = s.build().ok()?;
        Some((s, w))
    };
    let report = SweepReport::new(&scene, &walker_for, &param, &pts, &bounds);
    if common.json {
        print_json(&report)?;
    } else {
        output::text(|out| print_text(out, &report))?;
    }
    Ok(ExitCode::SUCCESS)
}

fn print_text(out: &mut dyn Write, r: &SweepReport) -> std::io::Result<()> {
    let param = &r.param;
    writeln!(out, "{:>14} {:>10} {:>8}", param, "max|λ|", "stable")?;
    for p in &r.points {
        match p {
            SweepPointRecord::Converged(g) => writeln!(
                out,
                "{:>14.6} {:>10.6} {:>8}",
                g.value, g.max_abs_eigenvalue, g.stable
            )?,
            SweepPointRecord::Failed(e) => {
                writeln!(out, "{:>14.6} {:>10} {:>8}  {}", e.value, "-", "-", e.error)?
            }
        }
    }
    for b in &r.stability_boundaries {
        writeln!(out, "stability {} at {} ≈ {:.6}", b.change, param, b.value)?;
    }
    Ok(())
}
