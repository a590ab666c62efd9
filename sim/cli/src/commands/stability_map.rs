//! `walker stability-map`: the largest |eigenvalue| of the scene's gait (the one rule of
//! `walker gait`, [`sim::analysis::homotopy::GaitRule`]) at each cell of a grid of
//! two parameters ([`sim::analysis::stability_map`]), as text, JSON or a heat map.

use super::print_json;
use crate::export;
use crate::grid_axis;
use crate::heatmap::HeatMap;
use crate::input_error::InputError;
use crate::labels;
use crate::limits;
use crate::options::Common;
use crate::output;
use crate::progress::Progress;
use anyhow::Result;
use clap::Args;
use sim::analysis::stability_map::{stability_map_of, Axis};
use sim::report::StabilityMapReport;
use sim::scene::Scene;
use std::io::Write;
use std::process::ExitCode;

/// Options of `walker stability-map`.
#[derive(Args)]
pub struct StabilityMapArgs {
    #[command(flatten)]
    pub common: Common,
    /// The x axis: `PARAM=FROM:TO:N` (N values from FROM to TO, 1 to 500).
    #[arg(long, value_name = "PARAM=FROM:TO:N", allow_hyphen_values = true)]
    pub x: String,
    /// The y axis: `PARAM=FROM:TO:N` (at most 40,000 cells in all).
    #[arg(long, value_name = "PARAM=FROM:TO:N", allow_hyphen_values = true)]
    pub y: String,
    /// Write the heat map (stability_map.svg) into this folder.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<std::path::PathBuf>,
    /// Also map a robustness measure of each cell's gait: `gsn`, `step_down`, `step_up`,
    /// `mfpt` (with --sigma-m), or `max_abs_eigenvalue` (docs/robustness.md); the JSON's
    /// `quantity`, and the heat map draws it.
    #[arg(long, value_name = "NAME")]
    pub quantity: Option<String>,
    /// The rough floor's standard deviation of `--quantity mfpt`, in metres.
    #[arg(long = "sigma-m", value_name = "SIGMA", allow_hyphen_values = true)]
    pub sigma_m: Option<f64>,
}

/// Parses `PARAM=FROM:TO:N` for option `flag` of `scene` (the parameter by its canonical name).
fn axis(flag: &str, spec: &str, scene: &Scene) -> Result<Axis, InputError> {
    let (name, values) =
        grid_axis::parse(flag, spec, "PARAM=FROM:TO:N, e.g. slope_rad=0.01:0.02:11")?;
    Ok(Axis {
        name: scene.parameter_name(&name)?,
        values,
    })
}

/// Runs `walker stability-map`.
pub fn run(args: StabilityMapArgs) -> Result<ExitCode> {
    let StabilityMapArgs {
        common,
        x,
        y,
        plot,
        quantity,
        sigma_m,
    } = args;
    let scene = common.scene()?;
    common.setup(&scene)?;
    let (quantity, options) = crate::options::quantity(quantity.as_deref(), sigma_m)?;
    let (x, y) = (axis("--x", &x, &scene)?, axis("--y", &y, &scene)?);
    if x.name == y.name {
        return Err(InputError::Other(format!(
            "--x and --y both vary `{}`: give two different parameters",
            x.name
        ))
        .into());
    }
    let cells = x.values.len() * y.values.len();
    limits::count("--x N × --y N", cells, 1, limits::MAX_MAP_CELLS)?;
    if let Some(dir) = &plot {
        output::create_dir("--plot", dir)?;
    }
    let progress = Progress::new(cells, "stability map", !common.json);
    let homotopy = common.homotopy();
    let map = stability_map_of(
        &scene,
        &common.setup_for(),
        &x,
        &y,
        &common.newton(),
        &homotopy,
        quantity.map(|q| (q, &options)),
        &|| progress.tick(),
    )
    .map_err(InputError::Scene)?;
    progress.finish();
    let report = match &quantity {
        Some(q) => StabilityMapReport::with_quantity(scene.name(), &x, &y, &map, *q, &options),
        None => StabilityMapReport::new(scene.name(), &x, &y, &map),
    };
    if let (Some(dir), Some(q)) = (&plot, &report.quantity) {
        let values: Vec<f64> = q.values.iter().flatten().flatten().copied().collect();
        let mut sorted = values.clone();
        sorted.sort_by(f64::total_cmp);
        let median = sorted.get(sorted.len() / 2).copied().unwrap_or(0.0);
        let fig = HeatMap {
            title: format!(
                "{}: {} of its gait (as walker gait finds it)",
                labels::walker_name(&scene),
                q.name.name()
            ),
            x_label: labels::parameter_label(&scene, &x.name),
            y_label: labels::parameter_label(&scene, &y.name),
            z_label: format!("{} [{}]", q.name.name(), q.name.unit()),
            x: x.values.clone(),
            y: y.values.clone(),
            z: q.values.clone(),
            level: median,
            contour_label: "the median over the map".into(),
            missing_label: "no gait, or not measured".into(),
        };
        let name = format!("stability_map_{}", q.name.name());
        export::write_figure("--plot", dir, &name, &fig.to_svg(820.0, 620.0))?;
    }
    if let Some(dir) = &plot {
        let fig = HeatMap {
            title: format!(
                "{}: stability of its gait (as walker gait finds it)",
                labels::walker_name(&scene)
            ),
            x_label: labels::parameter_label(&scene, &x.name),
            y_label: labels::parameter_label(&scene, &y.name),
            z_label: "largest |λ| of the stride map".into(),
            x: x.values.clone(),
            y: y.values.clone(),
            z: report.max_abs_eigenvalue.clone(),
            level: 1.0,
            contour_label: "|λ| = 1: stability boundary".into(),
            missing_label: "no gait found".into(),
        };
        export::write_figure("--plot", dir, "stability_map", &fig.to_svg(820.0, 620.0))?;
    }
    if common.json {
        print_json(&report)?;
    } else {
        output::text(|out| print_text(out, &report))?;
    }
    Ok(ExitCode::SUCCESS)
}

fn print_text(out: &mut dyn Write, r: &StabilityMapReport) -> std::io::Result<()> {
    writeln!(
        out,
        "max |λ| of the gait `walker gait` finds at each cell ('-': no gait), rows {} (down), columns {} (across)",
        r.y.name, r.x.name
    )?;
    write!(out, "{:>12}", "")?;
    for x in &r.x.values {
        write!(out, " {x:>9.4}")?;
    }
    writeln!(out)?;
    for (y, row) in r.y.values.iter().zip(&r.max_abs_eigenvalue) {
        write!(out, "{y:>12.5}")?;
        for v in row {
            match v {
                Some(v) => write!(out, " {v:>9.4}")?,
                None => write!(out, " {:>9}", "-")?,
            }
        }
        writeln!(out)?;
    }
    if let Some(q) = &r.quantity {
        writeln!(
            out,
            "{} [{}] of the same gaits ('-': no gait or not measured)",
            q.name.name(),
            q.name.unit()
        )?;
        write!(out, "{:>12}", "")?;
        for x in &r.x.values {
            write!(out, " {x:>11.4}")?;
        }
        writeln!(out)?;
        for (y, row) in r.y.values.iter().zip(&q.values) {
            write!(out, "{y:>12.5}")?;
            for v in row {
                match v {
                    Some(v) => write!(out, " {v:>11.5e}")?,
                    None => write!(out, " {:>11}", "-")?,
                }
            }
            writeln!(out)?;
        }
    }
    Ok(())
}
