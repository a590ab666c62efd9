//! `walker`: find gaits, walk, sweep parameters, list scenes.
//!
//! Bad input (unknown scene, unknown or ill-typed parameter, non-physical value) exits with
//! code 2 and a message naming the problem; a gait that cannot be found exits with code 1; a
//! walk (`walk`, `sil`) that ended early because the walker fell exits with code 3. A closed
//! pipe on standard output ends the command quietly with code 0, any other write error with
//! code 1 and a message. Each subcommand lives in its own module under [`commands`].

mod animation;
mod axis;
mod commands;
mod export;
mod figures;
mod gait_text;
mod grid_axis;
mod heatmap;
mod input_error;
mod labels;
mod limits;
mod options;
mod output;
mod param_range;
mod path_csv;
mod plot;
mod progress;
#[cfg(test)]
mod readme_commands;
mod search_progress;
mod svg_text;
mod sweep_figures;

use anyhow::Result;
use clap::{Parser, Subcommand};
use commands::{
    accuracy, basin, gait, gaits, optimize, orbit_diagram, robustness, scenes, sil, stability_map,
    sweep, tune, walk,
};
use input_error::InputError;
use sim::scene::SceneError;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "walker",
    version,
    about = "Passive dynamic walker simulator (Wisse, Schwab & van der Linde 2001)",
    after_help = "Exit codes: 0 success; 1 no gait found, or an error writing output; 2 bad input; \
                  3 the walk (`walk`, `sil`) ended early: the walker fell (the JSON's `failure` \
                  says how)."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Find the periodic gait of a scene and its stability.
    Gait(gait::GaitArgs),
    /// Census: every distinct period-1 gait found (Newton from the guess, continuation from
    /// the defaults, multi-start), longest step period first.
    Gaits(gaits::GaitsArgs),
    /// Simulate N steps from the gait (or the scene's guess), optionally perturbed.
    #[command(after_help = WALK_EXIT_CODES)]
    Walk(walk::WalkArgs),
    /// Continuation: follow the gait while one parameter changes.
    Sweep(sweep::SweepArgs),
    /// Orbit diagram: the attractor (periodic, chaotic or a fall) at each value of one
    /// parameter, from the previous value's attractor.
    OrbitDiagram(orbit_diagram::OrbitDiagramArgs),
    /// Stability map: max |λ| of the gait `walker gait` finds at each cell of a grid of two
    /// parameters (every cell by the same rule).
    StabilityMap(stability_map::StabilityMapArgs),
    /// Search parameters within bounds for the smallest largest |eigenvalue| (Nelder-Mead).
    Tune(tune::TuneArgs),
    /// How much disturbance the gait survives: gait sensitivity norm, largest step down and
    /// up, largest change of each rate, mean first-passage time on rough floors.
    Robustness(robustness::RobustnessArgs),
    /// A slice of the gait's basin of attraction in two stride-map coordinates just after
    /// heel strike: which states return to the gait, and in how many strides.
    Basin(basin::BasinArgs),
    /// Design optimisation: CMA-ES over scene parameters for an objective of the gait (gsn,
    /// step_down, mfpt, max_abs_eigenvalue, cost_of_transport), every candidate's gait by
    /// `walker gait`'s rule, under constraints on the gait.
    Optimize(optimize::OptimizeArgs),
    /// Speed against error: every integrator over a range of steps or tolerances, errors of
    /// the fixed point, eigenvalues and heel-strike time against a tight reference.
    Accuracy(accuracy::AccuracyArgs),
    /// Software in the loop: the ankle firmware (two nodes on a simulated CAN bus) actuates
    /// the walker; compared with the ideal-actuator gait.
    #[command(after_help = WALK_EXIT_CODES)]
    Sil(sil::SilArgs),
    /// List the scenes (one line each), or with NAME one scene's parameters (units,
    /// defaults, ranges).
    Scenes {
        /// A scene's name (or a scene file's path): show its parameters in full.
        name: Option<String>,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
}

/// The exit codes of a walk, as `walker walk --help` and `walker sil --help` state them.
const WALK_EXIT_CODES: &str = "Exit codes: 0 every step walked; 1 no gait to start from, or an \
                               error writing output; 2 bad input; 3 the walker fell before the \
                               last step (the report's `failure` says how; the JSON is the same).";

fn run(cli: Cli) -> Result<ExitCode> {
    match cli.command {
        Command::Scenes { name, json } => scenes::run(name.as_deref(), json),
        Command::Gait(args) => gait::run(args),
        Command::Gaits(args) => gaits::run(args),
        Command::Walk(args) => walk::run(args),
        Command::Sweep(args) => sweep::run(args),
        Command::OrbitDiagram(args) => orbit_diagram::run(args),
        Command::StabilityMap(args) => stability_map::run(args),
        Command::Tune(args) => tune::run(args),
        Command::Robustness(args) => robustness::run(args),
        Command::Basin(args) => basin::run(args),
        Command::Optimize(args) => optimize::run(args),
        Command::Accuracy(args) => accuracy::run(args),
        Command::Sil(args) => sil::run(args),
    }
}

/// Exit codes: 0 on success, 2 for bad input, 1 for any other error (and for a command's own
/// "nothing found", which it returns itself), 3 for a walk that ended early (returned by
/// `walk` and `sil` themselves). A broken pipe on standard output is a quiet success.
fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            if e.downcast_ref::<output::StdoutError>()
                .is_some_and(output::StdoutError::is_broken_pipe)
            {
                return ExitCode::SUCCESS;
            }
            output::note(format_args!("error: {e}"));
            if e.downcast_ref::<InputError>().is_some() || e.downcast_ref::<SceneError>().is_some()
            {
                ExitCode::from(2)
            } else {
                ExitCode::from(1)
            }
        }
    }
}
