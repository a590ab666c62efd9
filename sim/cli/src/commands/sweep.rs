//! `walker sweep`: pseudo-arclength continuation of the gait while one parameter changes,
//! through folds, with its bifurcations located, its end named, and the period-doubled
//! branches (docs/bifurcations.md).

use super::print_json;
use crate::export;
use crate::input_error::InputError;
use crate::limits;
use crate::options::Common;
use crate::output;
use crate::param_range::ParamRange;
use crate::progress::Progress;
use crate::sweep_figures::sweep_figures;
use anyhow::Result;
use clap::Args;
use sim::analysis::continuation::{continuation, ContinuationSettings, SweepError};
use sim::report::{SweepPointRecord, SweepReport};
use std::io::Write;
use std::process::ExitCode;

/// Resolution of the sweep's progress bar (the continuation reports a fraction done).
const PROGRESS_STEPS: usize = 1000;

/// Options of `walker sweep`.
#[derive(Args)]
pub struct SweepArgs {
    #[command(flatten)]
    pub common: Common,
    #[command(flatten)]
    pub range: ParamRange,
    /// Number of grid values reported (2 to 10,000); their spacing is the largest
    /// continuation step.
    #[arg(long)]
    pub points: usize,
    /// Longest cycle followed, in strides (1: the period-1 branch only; 2, 4, … follow the
    /// period-doubled branches up to this).
    #[arg(long, default_value_t = 8)]
    pub max_period: usize,
    /// Write the bifurcation diagram (bifurcation_diagram: a state at heel strike against the
    /// parameter) and max |λ| against the parameter (max_multiplier) into this folder, each as
    /// SVG, PNG and PDF.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<std::path::PathBuf>,
    /// The stride-map entry the bifurcation diagram plots (default: the first).
    #[arg(long, value_name = "NAME")]
    pub coordinate: Option<String>,
    /// Also measure a robustness quantity at every period-1 gait of the sweep: `gsn`,
    /// `step_down`, `step_up`, `mfpt` (with --sigma-m), ... (docs/robustness.md); each point's
    /// `quantity` in the JSON, a column in the text.
    #[arg(long, value_name = "NAME")]
    pub quantity: Option<String>,
    /// The rough floor's standard deviation of `--quantity mfpt`, in metres.
    #[arg(long = "sigma-m", value_name = "SIGMA", allow_hyphen_values = true)]
    pub sigma_m: Option<f64>,
}

/// Runs `walker sweep`.
pub fn run(args: SweepArgs) -> Result<ExitCode> {
    let SweepArgs {
        common,
        range,
        points,
        max_period,
        plot,
        coordinate,
        quantity,
        sigma_m,
    } = args;
    let (param, from, to) = range.checked("a sweep")?;
    let scene = common.scene()?;
    let base = common.setup(&scene)?;
    let points = limits::count("--points", points, 2, limits::MAX_SWEEP_POINTS)?;
    let max_period = limits::count("--max-period", max_period, 1, limits::MAX_SWEEP_PERIOD)?;
    let names = base.walker.map_names();
    let coordinate_index = match &coordinate {
        None => 0,
        Some(c) => names.iter().position(|n| n == c).ok_or_else(|| {
            InputError::Other(format!(
                "--coordinate `{c}`: expected one of {}",
                names.join(", ")
            ))
        })?,
    };
    let (quantity, quantity_options) = crate::options::quantity(quantity.as_deref(), sigma_m)?;
    // The figures' folder before the sweep: a path that cannot be used fails at once.
    if let Some(dir) = &plot {
        output::create_dir("--plot", dir)?;
    }
    let newton = common.newton();
    // The command line's integrator choices apply at every parameter value.
    let overridden =
        common.integrator.is_some() || common.rtol.is_some() || common.step_s.is_some();
    let settings = ContinuationSettings::builder()
        .newton(newton)
        .max_period(max_period)
        .stride_settings(overridden.then_some(base.settings))
        .build()
        .map_err(|e| InputError::Other(e.to_string()))?;
    let scene_error = |e: SweepError| match e {
        SweepError::Scene(s) => InputError::Scene(s),
        other => InputError::Other(other.to_string()),
    };
    let progress = Progress::new(PROGRESS_STEPS, "sweep", !common.json);
    let result = continuation(&scene, &param, (from, to, points), &settings, &|fraction| {
        progress.set_fraction(fraction)
    })
    .map_err(scene_error)?;
    progress.finish();
    if let Some(dir) = &plot {
        let name = names.get(coordinate_index).cloned().unwrap_or_default();
        let [diagram, modulus] = sweep_figures(&scene, &result, &name, coordinate_index);
        export::write_figure(
            "--plot",
            dir,
            "bifurcation_diagram",
            &diagram.to_svg(900.0, 560.0),
        )?;
        export::write_figure(
            "--plot",
            dir,
            "max_multiplier",
            &modulus.to_svg(900.0, 560.0),
        )?;
    }
    let mut report = SweepReport::from_continuation(&result);
    if let Some(q) = quantity {
        let progress = Progress::new(
            SweepReport::measured_points(&result),
            "sweep: measuring",
            !common.json,
        );
        report.measure(
            &result,
            (q, &quantity_options),
            &common.setup_for(),
            &common.newton(),
            &|| progress.tick(),
        );
        progress.finish();
    }
    if common.json {
        print_json(&report)?;
    } else {
        output::text(|out| print_text(out, &report))?;
    }
    let unanswered = unanswered_ranges(&report);
    for u in &unanswered {
        output::note(format_args!("sweep: {}", u.describe(param.as_str())));
    }
    let started = report
        .points
        .iter()
        .any(|p| matches!(p, SweepPointRecord::Converged(_)));
    let out_of_budget = report.branch_ends.iter().any(|e| e.kind == "budget");
    Ok(if !started || out_of_budget {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    })
}

/// A run of grid values the sweep did not answer, in parameter order, for one kind of reason
/// (the reason's words before its first colon), with the first value's reason in full.
struct Unanswered {
    count: usize,
    from: f64,
    to: f64,
    kind: String,
    reason: String,
}

impl Unanswered {
    fn describe(&self, param: &str) -> String {
        let (from, to) = (grid_value(self.from), grid_value(self.to));
        if self.count == 1 {
            format!("{param} = {from} unanswered: {}", self.reason)
        } else {
            format!(
                "{} values of {param} from {from} to {to} unanswered: {} (at {from}: {})",
                self.count, self.kind, self.reason
            )
        }
    }
}

/// A grid value for people: without the grid arithmetic's last-digit noise
/// (`-0.4995999599959996` is `-0.4996`), in short form.
fn grid_value(x: f64) -> String {
    let rounded: f64 = format!("{x:.11e}").parse().unwrap_or(x);
    sim::scene::short_number(rounded)
}

/// The values without a gait on branch 0 (no start, a corrector that failed, values past its
/// ends), grouped into runs of one reason in parameter order; an answered value ends a run.
fn unanswered_ranges(r: &SweepReport) -> Vec<Unanswered> {
    let mut on_branch_0: Vec<(f64, Option<&str>)> = r
        .points
        .iter()
        .filter_map(|p| match p {
            SweepPointRecord::Failed(e) if e.branch == 0 => {
                Some((e.value, Some(e.reason.as_str())))
            }
            SweepPointRecord::Converged(g) if g.branch == 0 => Some((g.value, None)),
            _ => None,
        })
        .collect();
    on_branch_0.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut runs: Vec<Unanswered> = Vec::new();
    let mut open = false;
    for (value, reason) in on_branch_0 {
        let Some(reason) = reason else {
            open = false;
            continue;
        };
        let kind = reason.split(':').next().unwrap_or(reason);
        match runs.last_mut() {
            Some(run) if open && run.kind == kind => {
                run.count += 1;
                run.to = value;
            }
            _ => runs.push(Unanswered {
                count: 1,
                from: value,
                to: value,
                kind: kind.to_string(),
                reason: reason.to_string(),
            }),
        }
        open = true;
    }
    runs
}

/// A row's parameter value.
fn row_value(p: &SweepPointRecord) -> f64 {
    match p {
        SweepPointRecord::Converged(g) => g.value,
        SweepPointRecord::Failed(e) => e.value,
    }
}

fn print_text(out: &mut dyn Write, r: &SweepReport) -> std::io::Result<()> {
    let param = &r.param;
    writeln!(
        out,
        "{:>14} {:>7} {:>7} {:>10} {:>8}",
        param, "branch", "period", "max|λ|", "stable"
    )?;
    // Rows in parameter order (the JSON keeps the branches' order).
    let mut rows: Vec<&SweepPointRecord> = r.points.iter().collect();
    rows.sort_by(|a, b| row_value(a).total_cmp(&row_value(b)));
    for p in rows {
        match p {
            SweepPointRecord::Converged(g) => {
                // the --quantity column: its value, or why it has none
                let measured =
                    g.quantity
                        .as_ref()
                        .map_or_else(String::new, |q| match (&q.value, &q.error) {
                            (Some(v), _) => format!("  {}={v:.6e}", q.name),
                            (None, Some(e)) => format!("  {}: {e}", q.name),
                            (None, None) => String::new(),
                        });
                writeln!(
                    out,
                    "{:>14.6} {:>7} {:>7} {:>10.6} {:>8}{measured}",
                    g.value, g.branch, g.period_strides, g.max_abs_eigenvalue, g.stable
                )?
            }
            SweepPointRecord::Failed(e) => writeln!(
                out,
                "{:>14.6} {:>7} {:>7} {:>10} {:>8}  {}",
                e.value, e.branch, "-", "-", "-", e.reason
            )?,
        }
    }
    for b in &r.stability_boundaries {
        let m: Vec<String> = b
            .multipliers
            .iter()
            .map(|[re, im]| {
                if *im == 0.0 {
                    format!("{re:.6}")
                } else {
                    format!("{re:.6}{im:+.6}i")
                }
            })
            .collect();
        writeln!(
            out,
            "{} on branch {} (period {}) at {} = {:.10} (stability {}); multipliers {}{}",
            b.kind.replace('_', " "),
            b.branch,
            b.period_strides,
            param,
            b.value,
            b.change,
            m.join(", "),
            if b.budget_exhausted {
                " (the location ran out of its trial budget)"
            } else {
                ""
            }
        )?;
    }
    for e in &r.branch_ends {
        let accuracy = match e.accuracy {
            Some(a) if e.kind == "event_change" => format!(" (to {a:.1e})"),
            _ if e.grazing => {
                " (grazing: the location depends on the integrator's event detection, \
                 beyond its bracket)"
                    .to_string()
            }
            _ => String::new(),
        };
        writeln!(
            out,
            "branch {} (period {}) ends at {} = {:.10}{}: {} — {}{}",
            e.branch,
            e.period_strides,
            param,
            e.value,
            accuracy,
            e.kind.replace('_', " "),
            e.detail,
            if e.budget_exhausted {
                " (the location ran out of its trial budget)"
            } else {
                ""
            }
        )?;
    }
    for u in &r.unlocated {
        writeln!(
            out,
            "{} on branch {} (period {}) between {} = {:.10} and {:.10}, not located: {}",
            u.kind.replace('_', " "),
            u.branch,
            u.period_strides,
            param,
            u.bracket[0],
            u.bracket[1],
            u.reason
        )?;
    }
    for f in &r.switch_failures {
        writeln!(
            out,
            "period doubling on branch {} (period {}) at {} = {:.10}: no period-{} branch — {}",
            f.branch,
            f.period_strides,
            param,
            f.value,
            2 * f.period_strides,
            f.reason
        )?;
    }
    Ok(())
}
