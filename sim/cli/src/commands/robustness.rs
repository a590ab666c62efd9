//! `walker robustness`: how much disturbance the gait `walker gait` finds survives: the gait
//! sensitivity norm, the largest step down and up, the largest change of each rate, and the
//! mean first-passage time on rough floors (docs/robustness.md).

use super::{print_json, shown};
use crate::input_error::InputError;
use crate::limits;
use crate::options::Common;
use crate::output;
use crate::progress::Progress;
use crate::search_progress;
use anyhow::Result;
use clap::Args;
use serde::Serialize;
use sim::analysis::gait_sensitivity::{gait_sensitivity_norm, GaitSensitivity};
use sim::analysis::robustness::{
    mean_first_passage, step_thresholds, velocity_thresholds, FirstPassage, FirstPassageOptions,
    Recovery, StepThresholds, ThresholdOptions, VelocityThreshold,
};
use sim::report::GaitReport;
use std::collections::BTreeMap;
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

/// The measures `--measures` names.
#[derive(Clone, Copy, Debug, Default)]
struct Measures {
    gsn: bool,
    steps: bool,
    rates: bool,
    mfpt: bool,
}

impl Measures {
    fn parse(list: &str) -> Result<Self, InputError> {
        let mut m = Measures::default();
        for name in list.split(',').map(str::trim) {
            let slot = match name {
                "gsn" => &mut m.gsn,
                "steps" => &mut m.steps,
                "rates" => &mut m.rates,
                "mfpt" => &mut m.mfpt,
                other => {
                    return Err(InputError::Other(format!(
                        "--measures: unknown measure `{other}` (expected gsn, steps, rates, mfpt)"
                    )))
                }
            };
            *slot = true;
        }
        Ok(m)
    }
}

/// Most Monte Carlo walks per roughness, and most strides of one.
const MAX_MFPT_RUNS: usize = 100_000;
const MAX_MFPT_STRIDES: usize = 1_000_000;
/// Most Monte Carlo strides per roughness (runs × strides per run).
const MAX_MFPT_TOTAL_STRIDES: usize = 100_000_000;
/// Most roughness values.
const MAX_SIGMAS: usize = 64;

/// A threshold pair as the contract gives it.
#[derive(Serialize)]
struct Signs {
    positive: f64,
    negative: f64,
}

/// Where survival starts again past each step threshold (`null`: not up to the limit).
#[derive(Serialize)]
struct Again {
    down: Option<f64>,
    up: Option<f64>,
}

/// The report (the contract's fields first; `step_thresholds` and `velocity_thresholds` with
/// every detail).
#[derive(Serialize)]
struct RobustnessReport {
    scene: String,
    gait: GaitReport,
    gait_sensitivity_norm: Option<GaitSensitivity>,
    step_down_max_m: Option<f64>,
    step_up_max_m: Option<f64>,
    survived_again_from_m: Option<Again>,
    velocity_perturbation_max: Option<BTreeMap<String, Signs>>,
    mfpt: Vec<FirstPassage>,
    step_thresholds: Option<StepThresholds>,
    velocity_thresholds: Option<Vec<VelocityThreshold>>,
    return_rule: sim::analysis::robustness::ReturnRule,
    /// A measure that could not be computed, and why.
    errors: BTreeMap<String, String>,
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
    let return_strides = limits::count("--return-strides", return_strides, 1, 100_000)?;
    let measures = Measures::parse(&measures)?;
    if !(rate_scan_step.is_finite()
        && (1e-6..=ThresholdOptions::rates().limit).contains(&rate_scan_step))
    {
        return Err(InputError::Other(format!(
            "--rate-scan-step must be from 1e-6 to 0.25 natural rates (the scan's limit), got {}",
            sim::scene::short_number(rate_scan_step)
        ))
        .into());
    }
    let scene = common.scene()?;
    let setup = common.setup(&scene)?;
    let runs = limits::count("--mfpt-runs", mfpt_runs, 1, MAX_MFPT_RUNS)?;
    let strides = limits::count("--mfpt-strides", mfpt_strides, 1, MAX_MFPT_STRIDES)?;
    if runs.saturating_mul(strides) > MAX_MFPT_TOTAL_STRIDES {
        return Err(InputError::Other(format!(
            "--mfpt-runs × --mfpt-strides must be at most {MAX_MFPT_TOTAL_STRIDES} strides, got \
             {runs} × {strides}"
        ))
        .into());
    }
    if !measures.mfpt && !sigma_m.is_empty() {
        return Err(InputError::Other(
            "--sigma-m is the rough floor of the mean first-passage time: add mfpt to --measures"
                .into(),
        )
        .into());
    }
    if sigma_m.len() > MAX_SIGMAS {
        return Err(InputError::Other(format!(
            "--sigma-m given {} times; at most {MAX_SIGMAS}",
            sigma_m.len()
        ))
        .into());
    }
    if let Some(bad) = sigma_m.iter().find(|s| !(s.is_finite() && **s >= 0.0)) {
        return Err(InputError::Other(format!(
            "--sigma-m {}: a standard deviation must be a finite number ≥ 0",
            sim::scene::short_number(*bad)
        ))
        .into());
    }
    let walker = &setup.walker;
    let sourced = search_progress::rule_gait(&common, &common.setup_for(), &scene)?;
    let source = sourced.as_ref().ok().map(|(_, s)| *s);
    let result = sourced.map(|(g, _)| g);
    let (mut gait_report, _) = GaitReport::of_setup(&setup, &scene, &result, false);
    gait_report.gait_source = source;
    let mut report = RobustnessReport {
        scene: scene.name().to_owned(),
        gait: gait_report,
        gait_sensitivity_norm: None,
        step_down_max_m: None,
        step_up_max_m: None,
        survived_again_from_m: None,
        velocity_perturbation_max: None,
        mfpt: Vec::new(),
        step_thresholds: None,
        velocity_thresholds: None,
        return_rule: sim::analysis::robustness::ReturnRule::default(),
        errors: BTreeMap::new(),
    };
    let Ok(gait) = &result else {
        return finish(&common, &report, ExitCode::from(1));
    };
    if !gait.stable() {
        // every measure here asks how a disturbance dies out: at an unstable gait it grows
        report.errors.insert(
            "gait".into(),
            format!(
                "the gait is unstable (max |λ| = {}): no robustness measure is defined there",
                gait.max_abs_eigenvalue()
            ),
        );
        return finish(&common, &report, ExitCode::from(1));
    }
    let rule = sim::analysis::robustness::ReturnRule {
        max_strides: return_strides,
        ..Default::default()
    };
    report.return_rule = rule;
    let recovery = Recovery::new(walker, &setup.settings, gait).with_rule(rule);
    let leg_m = recovery.leg_length_m();
    let sigmas = if sigma_m.is_empty() {
        // rounded to 12 significant digits: a leg length of 0.9999999999999999 m gives 0.001
        let round = |x: f64| format!("{x:.12e}").parse::<f64>().unwrap_or(x);
        vec![
            round(1e-3 * leg_m),
            round(3e-3 * leg_m),
            round(1e-2 * leg_m),
        ]
    } else {
        sigma_m
    };
    let progress = Progress::new(3 + sigmas.len(), "robustness measures", !common.json);
    if measures.gsn {
        match gait_sensitivity_norm(walker, &setup.settings, gait, common.perturbation) {
            Ok(g) => report.gait_sensitivity_norm = Some(g),
            Err(e) => {
                report
                    .errors
                    .insert("gait_sensitivity_norm".into(), e.to_string());
            }
        }
    }
    progress.tick();
    if measures.steps {
        steps_into(&mut report, &recovery);
    }
    progress.tick();
    if measures.rates {
        let options = ThresholdOptions {
            scan_step: rate_scan_step,
            ..ThresholdOptions::rates()
        };
        rates_into(&mut report, &recovery, &options);
    }
    progress.tick();
    let options = FirstPassageOptions {
        runs,
        strides_per_run: strides,
        seed: mfpt_seed,
    };
    for sigma in sigmas.into_iter().filter(|_| measures.mfpt) {
        match mean_first_passage(&recovery, sigma, &options) {
            Ok(m) => report.mfpt.push(m),
            Err(e) => {
                report
                    .errors
                    .insert(format!("mfpt sigma_m={sigma}"), e.to_string());
            }
        }
        progress.tick();
    }
    progress.finish();
    let code = if report.errors.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    };
    finish(&common, &report, code)
}

/// The step thresholds into the report.
fn steps_into(report: &mut RobustnessReport, recovery: &Recovery<'_>) {
    let steps = step_thresholds(recovery, &ThresholdOptions::steps());
    report.step_down_max_m = Some(steps.down.max);
    report.step_up_max_m = Some(steps.up.max);
    report.survived_again_from_m = Some(Again {
        down: steps.down.survived_again_from,
        up: steps.up.survived_again_from,
    });
    report.step_thresholds = Some(steps);
}

/// The rate thresholds into the report.
fn rates_into(report: &mut RobustnessReport, recovery: &Recovery<'_>, options: &ThresholdOptions) {
    let rates = velocity_thresholds(recovery, options);
    report.velocity_perturbation_max = Some(
        rates
            .iter()
            .map(|v| {
                (
                    v.coordinate.clone(),
                    Signs {
                        positive: v.positive.max,
                        negative: v.negative.max,
                    },
                )
            })
            .collect(),
    );
    report.velocity_thresholds = Some(rates);
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
