//! `walker gaits`: the census of a scene's distinct period-1 gaits, longest step period first
//! ([`sim::analysis::census`]).

use super::{print_json, shown};
use crate::options::Common;
use crate::output;
use crate::progress::Progress;
use anyhow::Result;
use clap::Args;
use sim::analysis::census::{census_units, census_with_progress, CensusSettings};
use sim::report::{GaitOutcome, GaitReport, GaitsReport};
use std::io::Write;
use std::process::ExitCode;

/// Options of `walker gaits`.
#[derive(Args)]
pub struct GaitsArgs {
    #[command(flatten)]
    pub common: Common,
}

/// Runs `walker gaits`: exit code 1 if no gait is found.
pub fn run(args: GaitsArgs) -> Result<ExitCode> {
    let GaitsArgs { common } = args;
    let scene = common.scene()?;
    let setup = common.setup(&scene)?;
    let settings = CensusSettings::default();
    let progress = Progress::after(
        super::walk::PROGRESS_DELAY,
        census_units(&scene, &settings),
        "gaits (Newton searches)",
        !common.json,
    );
    let found = census_with_progress(
        &scene,
        &common.setup_for(),
        &common.newton(),
        &settings,
        &|| progress.tick(),
    )?;
    progress.finish();
    let gaits = found
        .gaits
        .into_iter()
        .map(|g| GaitReport::of_setup(&setup, &scene, &Ok(g), false).0)
        .collect::<Vec<_>>();
    let any = !gaits.is_empty();
    let r = GaitsReport {
        scene: scene.name().to_string(),
        gaits,
        searches: found.searches,
    };
    if common.json {
        print_json(&r)?;
    } else {
        output::text(|out| print_text(out, &r))?;
    }
    Ok(if any {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn print_text(out: &mut dyn Write, r: &GaitsReport) -> std::io::Result<()> {
    writeln!(
        out,
        "scene: {}: {} distinct period-1 gait(s), longest step period first ({} Newton searches)",
        r.scene,
        r.gaits.len(),
        r.searches
    )?;
    writeln!(
        out,
        "{:>3} {:>12} {:>12} {:>10} {:>11} {:>12} {:>9}  fixed point",
        "#", "period [s]", "progress [m]", "step [m]", "speed [m/s]", "max|λ|", "stable"
    )?;
    for (i, g) in r.gaits.iter().enumerate() {
        let GaitOutcome::Found(g) = &g.outcome else {
            continue;
        };
        let fixed: Vec<String> = g
            .fixed_point
            .0
            .iter()
            .map(|(k, v)| format!("{k}={:.6}", shown(*v)))
            .collect();
        writeln!(
            out,
            "{:>3} {:>12.6} {:>12.6} {:>10.6} {:>11.6} {:>12.6} {:>9}  {}",
            i + 1,
            shown(g.step_period_s),
            shown(g.progress_m_per_step),
            shown(g.step_length_m),
            shown(g.speed_m_s),
            shown(g.max_abs_eigenvalue),
            if g.stable { "stable" } else { "unstable" },
            fixed.join(" ")
        )?;
    }
    writeln!(
        out,
        "progress: distance walked forward per step (speed = progress / period); step: \
         distance between the feet at heel strike"
    )
}
