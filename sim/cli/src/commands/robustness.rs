//! `walker robustness`: how much disturbance the gait `walker gait` finds survives: the gait
//! sensitivity norm, the largest step down and up, the largest change of each rate, and the
//! mean first-passage time on rough floors (docs/robustness.md).

use super::{print_json, shown};
use crate::input_error::InputError;
use crate::options::Common;
use crate::output;
use crate::progress::Progress;
use crate::search_progress;
use anyhow::Result;
use clap::Args;
use sim::analysis::robustness::FirstPassageOptions;
use sim::report::{Measures, RobustnessOptionError, RobustnessOptions, RobustnessReport};
use std::io::Write;
use std::process::ExitCode;

/// Options of `walker robustness`.
#[derive(Args)]
pub struct RobustnessArgs {
    #[command(flatten)]
    pub common: Common,
    /// A rough floor's standard deviation for the mean first-passage time, in metres (repeatable;
    /// default: 0.001, 0.003 and 0.01 leg lengths).
    #[arg(long = "sigma-m", value_name = "SIGMA", allow_hyphen_values = true)]
    pub sigma_m: Vec<f64>,
    /// Monte Carlo walks per roughness.
    #[arg(long, default_value_t = 100)]
    pub mfpt_runs: usize,
    /// Most strides of one Monte Carlo walk (a walk that takes them all is censored).
    #[arg(long, default_value_t = 200)]
    pub mfpt_strides: usize,
    /// The first Monte Carlo walk's floor seed (walk r has seed + r).
    #[arg(long, default_value_t = 0)]
    pub mfpt_seed: u64,
    /// The measures to take, comma-separated: `gsn`, `steps` (step down and up), `rates`
    /// (the change of each rate), `mfpt`; the others are reported as `null`.
    #[arg(long, value_name = "LIST", default_value = "gsn,steps,rates,mfpt")]
    pub measures: String,
    /// The scan's grid step of the rate thresholds, in natural rates sqrt(g/L), up to 0.25 of
    /// them (the step thresholds scan every 0.001 leg lengths up to 0.25; both are bisected
    /// to 1e-7 of their scale).
    #[arg(long, value_name = "FRACTION", default_value_t = 1e-2)]
    pub rate_scan_step: f64,
    /// Strides a disturbed walker may take to come back within 1e-6 of the gait (the
    /// issue's rule: 100; a gait with max |λ| near 1 returns slowly).
    #[arg(long, value_name = "STRIDES", default_value_t = 100)]
    pub return_strides: usize,
}

/// Runs `walker robustness`: exit code 1 when no gait is found or a measure fails.
pub fn run(args: RobustnessArgs) -> Result<ExitCode> {
    let RobustnessArgs {
        common,
        sigma_m,
        mfpt_runs,
        mfpt_strides,
        mfpt_seed,
        measures,
        rate_scan_step,
        return_strides,
    } = args;
    let flag = |field: &str| format!("--{}", field.replace('_', "-"));
    let option_error = |e: RobustnessOptionError| InputError::Other(e.message(&flag));
    let options = RobustnessOptions {
        measures: Measures::from_names(measures.split(',')).map_err(option_error)?,
        sigma_m,
        first_passage: FirstPassageOptions {
            runs: mfpt_runs,
            strides_per_run: mfpt_strides,
            seed: mfpt_seed,
        },
        rate_scan_step,
        return_strides,
        perturbation: common.perturbation,
    };
    options.check().map_err(option_error)?;
    let scene = common.scene()?;
    let setup = common.setup(&scene)?;
    let sourced = search_progress::rule_gait(&common, &common.setup_for(), &scene)?;
    let progress = Progress::new(
        RobustnessReport::stages(&options),
        "robustness measures",
        !common.json,
    );
    let report = RobustnessReport::measure(&setup, &scene, sourced, &options, &|| progress.tick());
    progress.finish();
    let code = if report.complete() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    };
    finish(&common, &report, code)
}

fn finish(common: &Common, report: &RobustnessReport, code: ExitCode) -> Result<ExitCode> {
    if common.json {
        print_json(report)?;
    } else {
        output::text(|out| print_text(out, report))?;
    }
    Ok(code)
}

fn print_text(out: &mut dyn Write, r: &RobustnessReport) -> std::io::Result<()> {
    writeln!(out, "scene: {}", r.scene)?;
    let g = match &r.gait.outcome {
        sim::report::GaitOutcome::NotFound(e) => {
            return writeln!(out, "no gait found: {}", e.error);
        }
        sim::report::GaitOutcome::Found(g) => g,
    };
    writeln!(
        out,
        "gait: {}, step period {:.6} s, max |λ| = {:.6} ({})",
        r.gait
            .gait_source
            .map_or("the scene's guess", |s| s.describe()),
        shown(g.step_period_s),
        shown(g.max_abs_eigenvalue),
        if g.stable { "stable" } else { "unstable" }
    )?;
    if let Some(n) = &r.gait_sensitivity_norm {
        writeln!(
            out,
            "gait sensitivity norm (floor step): step time {:.6} s/m, step length {:.6} m/m, \
             both {:.6} ({} strides summed)",
            n.step_time, n.step_length, n.both, n.strides_summed
        )?;
    }
    if let Some(s) = &r.step_thresholds {
        writeln!(
            out,
            "return to the gait: within {:e} (∞-norm of the stride-map state) in {} strides",
            r.return_rule.tolerance, r.return_rule.max_strides
        )?;
        for (what, t) in [("down", &s.down), ("up", &s.up)] {
            let beyond = t
                .beyond
                .map_or_else(|| "the scan's limit".to_owned(), |o| o.name());
            let again = t.survived_again_from.map_or_else(
                || "none up to the limit".to_owned(),
                |h| format!("{h:.7} m"),
            );
            writeln!(
                out,
                "largest step {what:<4} survived: {:.7e} m ({:.5e} leg lengths; beyond: {beyond}); \
                 survived again from: {again}",
                t.max,
                t.max / s.leg_length_m
            )?;
        }
    }
    if let Some(v) = &r.velocity_thresholds {
        writeln!(
            out,
            "largest change of each rate survived (rad/s, or m/s for a slide):"
        )?;
        for t in v {
            let shown_max = |t: &sim::analysis::robustness::Threshold| {
                let again = t
                    .survived_again_from
                    .map_or_else(String::new, |a| format!(" (again from {a:.7e})"));
                if t.at_limit {
                    format!("≥{:.7e} (the scan's limit)", t.max)
                } else {
                    format!("{:.7e}{again}", t.max)
                }
            };
            writeln!(
                out,
                "    {:<28} +{}  −{}",
                t.coordinate,
                shown_max(&t.positive),
                shown_max(&t.negative)
            )?;
        }
    }
    if !r.mfpt.is_empty() {
        writeln!(
            out,
            "mean first-passage time on a rough floor (steps, 95 % interval):"
        )?;
        for m in &r.mfpt {
            let steps = m
                .steps
                .map_or_else(|| "no fall".to_owned(), |s| format!("{s:.1}"));
            let high = m
                .ci_high
                .map_or_else(|| "∞".to_owned(), |s| format!("{s:.1}"));
            writeln!(
                out,
                "    σ = {:.6} m: {steps} [{:.1}, {high}] ({} walks, {} fell, {} censored at {} \
                 strides; {} strides)",
                m.sigma_m,
                m.ci_low,
                m.runs,
                m.failed,
                m.censored,
                m.strides_per_run,
                m.strides_simulated
            )?;
        }
    }
    for (what, e) in &r.errors {
        writeln!(out, "{what}: {e}")?;
    }
    Ok(())
}
