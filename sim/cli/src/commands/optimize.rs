//! `walker optimize`: CMA-ES over scene parameters ([`sim::analysis::optimize`]) for an
//! objective of the gait (`gsn`, `max_abs_eigenvalue`, `cost_of_transport`, `step_down`,
//! `mfpt`), every candidate's gait found by the one gait rule of `walker gait`, under
//! constraints on the gait's quantities. Reports the best design with its gait (as
//! `walker gait` reports it), the scene's own design to compare, the history of the best value
//! per generation and every evaluation; `--plot` draws the history.

use super::{print_json, shown};
use crate::export;
use crate::input_error::InputError;
use crate::labels;
use crate::options::Common;
use crate::output;
use crate::plot::{Marker, Plot, Series, Style, PALETTE};
use crate::progress::Progress;
use anyhow::Result;
use clap::Args;
use sim::analysis::optimize::{Generation, Objective, OptimizeError, Sense, INITIAL_STEP};
use sim::report::{OptimizeOptionError, OptimizeOptions, OptimizeReport};
use sim::scene::Scene;
use std::io::Write;
use std::process::ExitCode;

/// Options of `walker optimize`.
#[derive(Args)]
pub struct OptimizeArgs {
    #[command(flatten)]
    pub common: Common,
    /// A parameter the search varies: `NAME=MIN:MAX` (repeatable, each parameter once; the
    /// range inside the scene's own, see `walker scenes S`).
    #[arg(
        long = "vary",
        value_name = "NAME=MIN:MAX",
        required = true,
        allow_hyphen_values = true
    )]
    pub vary: Vec<String>,
    /// What to optimise: gsn (gait sensitivity norm, minimised), max_abs_eigenvalue
    /// (minimised), cost_of_transport (minimised; actuated walkers), step_down (the largest
    /// step down survived, maximised) or mfpt (the mean first-passage time on the rough floor
    /// of --sigma-m, maximised; docs/robustness.md).
    #[arg(long, value_name = "OBJECTIVE")]
    pub objective: String,
    /// A constraint on the gait: `NAME<=V` or `NAME>=V`, NAME one of gsn, step_down, step_up,
    /// max_abs_eigenvalue, mfpt, cost_of_transport, speed_m_s, step_period_s, step_length_m
    /// (repeatable).
    #[arg(
        long = "constraint",
        value_name = "NAME<=V",
        allow_hyphen_values = true
    )]
    pub constraint: Vec<String>,
    /// Candidates evaluated (each a gait search), exactly; the scene's own design is
    /// evaluated once more to compare with (1 to 10,000).
    #[arg(long, default_value_t = 200)]
    pub budget: usize,
    /// Seed of CMA-ES's draws: the same seed gives the same search, bit for bit, whatever the
    /// number of threads.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// CMA-ES's initial step size, in normalised coordinates (each range 0 to 1): above 0, at
    /// most 1. Smaller keeps the first generations near the scene's design (where its gait is
    /// found).
    #[arg(long, default_value_t = INITIAL_STEP)]
    pub initial_step: f64,
    /// The rough floor's standard deviation of `mfpt`, in metres (its Monte Carlo: 100 walks of up
    /// to 200 strides, seeds from 0, as `walker robustness`).
    #[arg(long = "sigma-m", value_name = "SIGMA", allow_hyphen_values = true)]
    pub sigma_m: Option<f64>,
    /// Write the objective's history (history.svg, .png, .pdf) into this folder.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<std::path::PathBuf>,
}

/// Runs `walker optimize`.
pub fn run(args: OptimizeArgs) -> Result<ExitCode> {
    let OptimizeArgs {
        common,
        vary,
        objective,
        constraint,
        budget,
        seed,
        initial_step,
        plot,
        sigma_m,
    } = args;
    let scene = common.scene()?;
    common.setup(&scene)?;
    let options = OptimizeOptions {
        vary,
        objective,
        constraints: constraint,
        budget,
        seed,
        initial_step,
        sigma_m,
    };
    let request = options.request(&scene).map_err(input_error)?;
    if let Some(dir) = &plot {
        output::create_dir("--plot", dir)?;
    }
    let (setup_for, newton, homotopy) = (common.setup_for(), common.newton(), common.homotopy());
    // The scene's own design and every candidate.
    let progress = Progress::new(request.budget + 1, "optimize (gait searches)", !common.json);
    let report = OptimizeReport::run(&scene, &request, &setup_for, &newton, &homotopy, &|| {
        progress.tick()
    })
    .map_err(input_error)?;
    progress.finish();
    if let Some(dir) = &plot {
        let figure = history_plot(&scene, &report);
        export::write_figure("--plot", dir, "history", &figure.to_svg(760.0, 480.0))?;
    }
    if common.json {
        print_json(&report)?;
    } else {
        output::text(|out| print_text(out, &report))?;
    }
    Ok(if report.best.is_some() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// An option the search refuses is bad input (exit 2), each option spelled as its flag.
fn input_error(e: OptimizeOptionError) -> anyhow::Error {
    let flag = |field: &str| match field {
        "constraints" => "--constraint".to_owned(),
        // The command's message for it predates the spelling of options as flags.
        "initial_step" => "the initial step".to_owned(),
        other => format!("--{}", other.replace('_', "-")),
    };
    match e {
        OptimizeOptionError::UnknownParameter(s)
        | OptimizeOptionError::Search(OptimizeError::Scene(s)) => InputError::Scene(s).into(),
        other => InputError::Other(other.message(&flag)).into(),
    }
}

/// The history figure: each generation's best feasible value and the best so far, against
/// the evaluations spent, with the scene's own design's value as a dashed line.
fn history_plot(scene: &Scene, r: &OptimizeReport) -> Plot {
    let objective = r.objective;
    let point = |g: &Generation, v: Option<f64>| (g.evaluations as f64, v.unwrap_or(f64::NAN));
    let mut series = vec![
        Series {
            label: "best so far".into(),
            points: r
                .generations
                .iter()
                .map(|g| point(g, g.best_so_far))
                .collect(),
            style: Style::LINE,
            color: PALETTE[0],
        },
        Series {
            label: "best of each generation".into(),
            points: r
                .generations
                .iter()
                .map(|g| point(g, g.best_value))
                .filter(|p| p.1.is_finite())
                .collect(),
            style: Style::markers(Marker::Circle),
            color: PALETTE[1],
        },
    ];
    if let (Some(v), Some(last)) = (r.default.value, r.generations.last()) {
        series.push(Series {
            label: "the scene's design".into(),
            points: vec![(0.0, v), (last.evaluations as f64, v)],
            style: Style::DASHED,
            color: "#555555",
        });
    }
    let sense = match objective.sense() {
        Sense::Minimise => "minimised",
        Sense::Maximise => "maximised",
    };
    Plot {
        title: format!(
            "{}: {} by CMA-ES",
            labels::walker_name(scene),
            objective_label(objective)
        ),
        caption: Some(format!(
            "{sense}; {} evaluations, feasible designs only",
            r.evaluations.len()
        )),
        x_label: "evaluations".into(),
        y_label: objective_label(objective).into(),
        series,
        ..Plot::default()
    }
}

/// The objective in words, with its unit.
fn objective_label(o: Objective) -> &'static str {
    match o {
        Objective::Gsn => "gait sensitivity norm (s/m, m/m)",
        Objective::MaxAbsEigenvalue => "max |λ|",
        Objective::CostOfTransport => "cost of transport (J/(kg m))",
        Objective::StepDown => "largest step down survived (m)",
        Objective::Mfpt => "mean first-passage time (steps)",
    }
}

fn print_text(out: &mut dyn Write, r: &OptimizeReport) -> std::io::Result<()> {
    writeln!(out, "scene: {}", r.scene)?;
    let sense = match r.sense {
        Sense::Minimise => "minimise",
        Sense::Maximise => "maximise",
    };
    writeln!(
        out,
        "objective: {sense} {} ({}), CMA-ES, seed {}, {} evaluations in {} generations ({} run{})",
        r.objective.name(),
        objective_label(r.objective),
        r.seed,
        r.evaluations.len(),
        r.generations.len(),
        r.runs,
        if r.runs == 1 { "" } else { "s" },
    )?;
    for c in &r.constraints {
        writeln!(out, "constraint: {c}")?;
    }
    let feasible = r.evaluations.iter().filter(|e| e.feasible).count();
    writeln!(
        out,
        "feasible: {feasible} of {} evaluations",
        r.evaluations.len()
    )?;
    let default_value = match (r.default.feasible, r.default.value) {
        (true, Some(v)) => format!("{:.8}", shown(v)),
        _ => format!(
            "infeasible ({})",
            r.default.detail.as_deref().unwrap_or("no value")
        ),
    };
    let Some(best) = &r.best else {
        writeln!(out, "the scene's design: {default_value}")?;
        return writeln!(out, "no feasible design found");
    };
    writeln!(
        out,
        "{:<36} {:>14} {:>14}   bounds",
        "parameter", "scene's design", "best design"
    )?;
    for p in &r.parameters {
        let d = r
            .default
            .parameters
            .get(&p.name)
            .copied()
            .unwrap_or(f64::NAN);
        let b = best.parameters.get(&p.name).copied().unwrap_or(f64::NAN);
        writeln!(
            out,
            "    {:<32} {:>14.6} {:>14.6}   {} .. {}",
            p.name, d, b, p.min, p.max
        )?;
    }
    let value = best.value.map_or(f64::NAN, shown);
    writeln!(out, "best {}: {value:.8}", r.objective.name())?;
    match r.default.value.filter(|_| r.default.feasible) {
        Some(d) => {
            let change = if d != 0.0 {
                format!(" ({:+.2} %)", 100.0 * (value - d) / d.abs())
            } else {
                String::new()
            };
            writeln!(out, "the scene's design: {:.8}{change}", shown(d))?;
        }
        None => writeln!(out, "the scene's design: {default_value}")?,
    }
    if let sim::report::GaitOutcome::Found(g) = &best.gait.outcome {
        writeln!(
            out,
            "best design's gait: max |λ| = {:.6}, step period {:.4} s, speed {:.4} m/s",
            shown(g.max_abs_eigenvalue),
            shown(g.step_period_s),
            shown(g.speed_m_s)
        )?;
    }
    if let Some(s) = best.gait.gait_source {
        writeln!(
            out,
            "gait: {}, as `walker gait` finds at these values",
            s.describe()
        )?;
    }
    Ok(())
}
