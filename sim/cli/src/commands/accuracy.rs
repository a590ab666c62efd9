//! `walker accuracy`: speed against error of every integrator, against a tight reference.

use super::print_json;
use crate::export;
use crate::figures;
use crate::options::Common;
use crate::output;
use crate::progress::Progress;
use anyhow::Result;
use clap::Args;
use sim::analysis::accuracy;
use sim::engine::integrators::IntegratorChoice;
use std::process::ExitCode;

/// Options of `walker accuracy`.
#[derive(Args)]
pub struct AccuracyArgs {
    #[command(flatten)]
    pub common: Common,
    /// Write `accuracy.md` and log-log plots (SVG, PNG and PDF) into this folder.
    #[arg(long, value_name = "DIR")]
    pub out: Option<std::path::PathBuf>,
}

/// Picks one error measure from an accuracy point.
type ErrorOf = fn(&accuracy::AccuracyPoint) -> Option<f64>;

/// Runs `walker accuracy`: exit code 1 if there is no gait or no reference gait.
pub fn run(args: AccuracyArgs) -> Result<ExitCode> {
    let AccuracyArgs { common, out } = args;
    let scene = common.scene()?;
    let setup = common.setup(&scene)?;
    // The output folder before the study: a path that cannot be used fails at once.
    if let Some(dir) = &out {
        output::create_dir("--out", dir)?;
    }
    let reference = IntegratorChoice::Dopri5 {
        rtol: 1e-13,
        atol: 1e-13,
        h_max_s: 0.01,
    };
    let period = {
        match setup.find_gait(&common.newton()) {
            Ok(g) => g.stride.duration_s,
            Err(e) => {
                output::note(format_args!("error: no gait: {e}"));
                return Ok(ExitCode::from(1));
            }
        }
    };
    let settings = accuracy::default_settings(period);
    let progress = Progress::after(
        super::walk::PROGRESS_DELAY,
        settings.len(),
        "accuracy (integrator settings)",
        !common.json,
    );
    let studied =
        accuracy::study_with_progress(&setup, reference, &settings, &common.newton(), &|| {
            progress.tick()
        });
    progress.finish();
    let study = match studied {
        Ok(s) => s,
        Err(e) => {
            output::note(format_args!("error: no reference gait: {e}"));
            return Ok(ExitCode::from(1));
        }
    };
    let table = accuracy_table(&study);
    if common.json {
        print_json(&study)?;
    } else {
        output::text(|out| out.write_all(table.as_bytes()))?;
    }
    if let Some(dir) = out {
        output::write_file("--out", &dir.join("accuracy.md"), &table)?;
        let panels: [(&str, &str, ErrorOf); 3] = [
            (
                "fixed_point_error.svg",
                "fixed-point error (∞-norm, rad and rad/s)",
                |p| p.fixed_point_error,
            ),
            ("eigenvalue_error.svg", "eigenvalue error", |p| {
                p.eigenvalue_error
            }),
            (
                "heel_strike_time_error.svg",
                "heel-strike time error (s)",
                |p| p.heel_strike_time_error_s,
            ),
        ];
        for (file, what, f) in panels {
            let plot = figures::accuracy(&scene, &study, f, what);
            let name = file.trim_end_matches(".svg");
            export::write_figure("--out", &dir, name, &plot.to_svg(760.0, 480.0))?;
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// A markdown table of an accuracy study.
fn accuracy_table(study: &accuracy::AccuracyStudy) -> String {
    let fmt = |v: Option<f64>| v.map_or("—".to_string(), |x| format!("{x:.2e}"));
    let mut t = format!(
        "Scene `{}`, reference: dopri5 at rtol = atol = 1e-13, step period {:.6} s.\n\n\
         | integrator | step [s] or rtol | CPU per stride [µs] | evaluations | fixed point | eigenvalues (modulus ≥ 0.05) | heel-strike time [s] |\n\
         | --- | --- | --- | --- | --- | --- | --- |\n",
        study.scene, study.reference_step_period_s
    );
    for p in &study.points {
        t.push_str(&format!(
            "| {} | {:.3e} | {:.0} | {} | {} | {} | {} |\n",
            p.integrator,
            p.step_or_tolerance,
            p.cpu_us_per_stride,
            p.evaluations_per_stride,
            p.failure
                .as_ref()
                .map_or(fmt(p.fixed_point_error), |_| "no gait".into()),
            fmt(p.eigenvalue_error),
            fmt(p.heel_strike_time_error_s)
        ));
    }
    t
}
