//! `walker basin`: a slice of the basin of attraction of the gait `walker gait` finds, through
//! its fixed point, in two stride-map coordinates just after heel strike
//! ([`sim::analysis::robustness::basin`]), as text, JSON or a figure.

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
use crate::search_progress;
use anyhow::Result;
use clap::Args;
use sim::analysis::robustness::{
    basin_axes, basin_slice, BasinAxis, BasinCell, BasinError, Outcome, Recovery, ReturnRule,
    MAX_BASIN_CELL_STRIDES,
};
use sim::report::{BasinReport, GaitReport};
use std::io::Write;
use std::process::ExitCode;

/// Options of `walker basin`.
#[derive(Args)]
pub struct BasinArgs {
    #[command(flatten)]
    pub common: Common,
    /// The x axis: `COORD=FROM:TO:N`, a stride-map coordinate (`walker gait` lists them:
    /// `stance_leg`, `stance_leg_dot`, ...) and N values from FROM to TO (1 to 500).
    #[arg(long, value_name = "COORD=FROM:TO:N", allow_hyphen_values = true)]
    pub x: String,
    /// The y axis: `COORD=FROM:TO:N` (at most 40,000 cells in all).
    #[arg(long, value_name = "COORD=FROM:TO:N", allow_hyphen_values = true)]
    pub y: String,
    /// Strides a cell may take to return to the gait (1 to 10,000).
    #[arg(long, default_value_t = 100)]
    pub strides: usize,
    /// Write the figure (basin.svg, .png, .pdf) into this folder.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<std::path::PathBuf>,
}

/// Parses `COORD=FROM:TO:N` of option `flag`.
fn axis(flag: &str, spec: &str) -> Result<BasinAxis, InputError> {
    let (name, values) =
        grid_axis::parse(flag, spec, "COORD=FROM:TO:N, e.g. stance_leg=0.15:0.25:41")?;
    Ok(BasinAxis { name, values })
}

/// Runs `walker basin`: exit code 1 when no gait is found.
pub fn run(args: BasinArgs) -> Result<ExitCode> {
    let BasinArgs {
        common,
        x,
        y,
        strides,
        plot,
    } = args;
    let scene = common.scene()?;
    let setup = common.setup(&scene)?;
    let (x, y) = (axis("--x", &x)?, axis("--y", &y)?);
    let cells = x.values.len() * y.values.len();
    limits::count("--x N × --y N", cells, 1, limits::MAX_MAP_CELLS)?;
    let strides = limits::count("--strides", strides, 1, MAX_BASIN_CELL_STRIDES)?;
    // The axes before the gait search: a wrong one fails at once.
    basin_axes(&setup.walker, &x, &y).map_err(|e| {
        InputError::Other(match e {
            BasinError::UnknownCoordinate { name, known } => format!(
                "`{name}` is not a stride-map coordinate of {} (it has: {known})",
                scene.name()
            ),
            BasinError::SameAxis(name) => {
                format!("--x and --y both slice `{name}`: give two different coordinates")
            }
            e @ BasinError::Empty(_) => e.to_string(),
        })
    })?;
    if let Some(dir) = &plot {
        output::create_dir("--plot", dir)?;
    }
    let sourced = search_progress::rule_gait(&common, &common.setup_for(), &scene)?;
    let source = sourced.as_ref().ok().map(|(_, s)| *s);
    let result = sourced.map(|(g, _)| g);
    let (mut gait_report, _) = GaitReport::of_setup(&setup, &scene, &result, false);
    gait_report.gait_source = source;
    let gait = match &result {
        Ok(g) => g,
        Err(e) => {
            eprintln!("walker basin: no gait found: {e}");
            if common.json {
                print_json(&gait_report)?;
            }
            return Ok(ExitCode::from(1));
        }
    };
    let rule = ReturnRule {
        max_strides: strides,
        ..ReturnRule::default()
    };
    let recovery = Recovery::new(&setup.walker, &setup.settings, gait).with_rule(rule);
    let progress = Progress::new(cells, "basin (cells)", !common.json);
    let slice = basin_slice(&recovery, x, y, &|| progress.tick())
        .map_err(|e| InputError::Other(e.to_string()))?;
    progress.finish();
    let report = BasinReport::new(scene.name(), &slice, rule, gait_report);
    if let Some(dir) = &plot {
        let fig = HeatMap {
            title: format!(
                "{}: basin of attraction of its gait, {:.1} % of the window returns",
                labels::walker_name(&scene),
                100.0 * slice.fraction_returning
            ),
            x_label: slice.x.name.clone(),
            y_label: slice.y.name.clone(),
            z_label: "strides to return (red) / to fail or settle elsewhere (blue, negative)"
                .into(),
            x: slice.x.values.clone(),
            y: slice.y.values.clone(),
            z: slice
                .cells
                .iter()
                .map(|r| {
                    r.iter()
                        .map(|c| match c {
                            BasinCell::Strides(o @ Outcome::Gait { .. }) => {
                                Some(o.strides() as f64)
                            }
                            BasinCell::Strides(o) => Some(-(o.strides() as f64)),
                            BasinCell::OffSection => None,
                        })
                        .collect()
                })
                .collect(),
            level: 0.0,
            contour_label: "edge of the basin".into(),
            missing_label: "swing foot cannot reach the floor".into(),
        };
        export::write_figure("--plot", dir, "basin", &fig.to_svg(820.0, 620.0))?;
    }
    if common.json {
        print_json(&report)?;
    } else {
        output::text(|out| print_text(out, &report))?;
    }
    Ok(ExitCode::SUCCESS)
}

/// One letter per outcome in the text grid.
fn letter(name: &str) -> char {
    match name {
        "gait" => 'o',
        "periodic" => 'p',
        "fell_forward" => 'F',
        "fell_backward" => 'B',
        "not_settled" => '?',
        "off_section" => ' ',
        _ => 'x',
    }
}

fn print_text(out: &mut dyn Write, r: &BasinReport) -> std::io::Result<()> {
    writeln!(
        out,
        "basin of attraction of the gait `walker gait` finds ({}), rows {} (down), columns {} \
         (across)",
        r.gait
            .gait_source
            .map_or("the scene's guess", |s| s.describe()),
        r.y.name,
        r.x.name
    )?;
    writeln!(
        out,
        "o back on the gait (within {:e} in {} strides), p another periodic motion, F fell \
         forward, B fell backward, ? not settled, x other failure, blank: swing foot off the floor",
        r.return_rule.tolerance, r.return_rule.max_strides
    )?;
    if let Some(c) = &r.solved_coordinate {
        writeln!(out, "{c} solved to keep the swing foot on the floor")?;
    }
    for (yv, row) in r.y.values.iter().zip(&r.outcome) {
        let cells: String = row.iter().map(|n| letter(n)).collect();
        writeln!(out, "{yv:>12.6} {cells}")?;
    }
    writeln!(
        out,
        "{:>12} x from {} to {}",
        "",
        r.x.values.first().copied().unwrap_or(f64::NAN),
        r.x.values.last().copied().unwrap_or(f64::NAN)
    )?;
    writeln!(
        out,
        "fraction of the window returning to the gait: {:.6}",
        r.fraction_returning
    )
}
