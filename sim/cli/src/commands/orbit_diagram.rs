//! `walker orbit-diagram`: the attractor of the stride map at each value of one parameter
//! ([`sim::analysis::orbit_diagram`]), as text, JSON or the classic figure.

use super::print_json;
use crate::export;
use crate::figures;
use crate::input_error::InputError;
use crate::limits;
use crate::options::Common;
use crate::output;
use crate::param_range::ParamRange;
use crate::progress::Progress;
use anyhow::Result;
use clap::Args;
use sim::analysis::orbit_diagram::{linspace, orbit_diagram, OrbitError, OrbitSettings};
use sim::report::OrbitDiagramReport;
use std::io::Write;
use std::process::ExitCode;

/// Options of `walker orbit-diagram`.
#[derive(Args)]
pub struct OrbitDiagramArgs {
    #[command(flatten)]
    pub common: Common,
    #[command(flatten)]
    pub range: ParamRange,
    /// Number of values (2 to 5,000).
    #[arg(long)]
    pub points: usize,
    /// Consecutive values computed in sequence from one seed gait (the chunks run in
    /// parallel; as many as --points gives the purely sequential diagram).
    #[arg(long, default_value_t = OrbitSettings::default().chunk_points)]
    pub chunk_points: usize,
    /// The coordinate the figure plots (a stride-map entry or a convention output; default:
    /// the first stride-map entry).
    #[arg(long)]
    pub coordinate: Option<String>,
    /// Write the figure (orbit_diagram.svg, .png and .pdf) into this folder.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<std::path::PathBuf>,
}

/// Runs `walker orbit-diagram`.
pub fn run(args: OrbitDiagramArgs) -> Result<ExitCode> {
    let OrbitDiagramArgs {
        common,
        range,
        points,
        chunk_points,
        coordinate,
        plot,
    } = args;
    let (param, from, to) = range.checked("an orbit diagram")?;
    let scene = common.scene()?;
    let setup = common.setup(&scene)?;
    let param = scene.parameter_name(&param).map_err(InputError::Scene)?;
    let points = limits::count("--points", points, 2, limits::MAX_ORBIT_POINTS)?;
    let chunk_points =
        limits::count("--chunk-points", chunk_points, 1, limits::MAX_ORBIT_POINTS)?.min(points);
    let names = setup.walker.map_names();
    let conventions: Vec<String> = scene
        .convention_outputs(&setup.walker, &setup.guess.q, &setup.guess.qd)
        .map_err(InputError::Scene)?
        .into_iter()
        .map(|(k, _)| k)
        .collect();
    let coordinate = match coordinate {
        None => names.first().cloned().unwrap_or_default(),
        Some(c) if names.contains(&c) || conventions.contains(&c) => c,
        Some(c) => {
            return Err(InputError::Other(format!(
                "--coordinate `{c}`: expected one of {}",
                names
                    .iter()
                    .chain(&conventions)
                    .cloned()
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
            .into())
        }
    };
    if let Some(dir) = &plot {
        output::create_dir("--plot", dir)?;
    }
    let settings = OrbitSettings {
        chunk_points,
        ..OrbitSettings::default()
    };
    let values = linspace(from, to, points);
    let progress = Progress::new(points, "orbit diagram", !common.json);
    let found = orbit_diagram(
        &scene,
        &common.setup_for(),
        &param,
        &values,
        &common.newton(),
        &settings,
        &|| progress.tick(),
    )
    .map_err(|e| match e {
        OrbitError::Scene(s) => InputError::Scene(s),
        other => InputError::Other(other.to_string()),
    })?;
    progress.finish();
    let report = OrbitDiagramReport::new(&scene, &setup.walker, &param, &found, &settings);
    if let Some(dir) = &plot {
        let fig = figures::orbit_diagram(&scene, &report, &coordinate);
        export::write_figure("--plot", dir, "orbit_diagram", &fig.to_svg(900.0, 560.0))?;
    }
    if common.json {
        print_json(&report)?;
    } else {
        output::text(|out| print_text(out, &report, &coordinate))?;
    }
    Ok(ExitCode::SUCCESS)
}

fn print_text(
    out: &mut dyn Write,
    r: &OrbitDiagramReport,
    coordinate: &str,
) -> std::io::Result<()> {
    writeln!(
        out,
        "{:>14} {:>10} {:>7} {:>8}  {} at heel strike (or how it fell)",
        r.param,
        "attractor",
        "period",
        "strides",
        crate::labels::coordinate_label(coordinate)
    )?;
    for p in &r.points {
        let detail = match &p.failure {
            // `f.stride` counts from 1 already (the report's numbering).
            Some(f) => format!(
                "{} in {}",
                crate::labels::failure_label(f.kind),
                crate::labels::step_label(f.stride.saturating_sub(1))
            ),
            None => {
                let ys = p.samples.get(coordinate).map_or(&[][..], Vec::as_slice);
                let (lo, hi) = ys
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &y| {
                        (a.min(y), b.max(y))
                    });
                if p.period_strides == Some(1) {
                    format!("{lo:.8}")
                } else {
                    format!("{lo:.8} .. {hi:.8} ({} samples)", ys.len())
                }
            }
        };
        writeln!(
            out,
            "{:>14.8} {:>10} {:>7} {:>8}  {detail}",
            p.value,
            p.attractor,
            p.period_strides.map_or("-".to_string(), |n| n.to_string()),
            p.strides
        )?;
    }
    Ok(())
}
