//! `walker walk`: simulate N steps from the gait (or the scene's guess), optionally perturbed.

mod start;

use super::{print_json, walk_exit_code};
use crate::animation::{self, timeline, Animation};
use crate::export;
use crate::figures;
use crate::gait_text::GaitFigures;
use crate::input_error::InputError;
use crate::labels;
use crate::limits;
use crate::options::Common;
use crate::output::{self, PathError};
use crate::path_csv::PathCsv;
use crate::progress::Progress;
use crate::search_progress::SearchProgress;
use anyhow::Result;
use clap::Args;
use sim::analysis::homotopy::GaitRule;
use sim::analysis::walk_start::{gait_start, GaitStart};
use sim::report::{StartRecord, WalkGaitRecord, WalkReport};
use sim::scene::Scene;
use sim::stride::walk::WalkRequest;
use sim::stride::Floor;
use sim::stride::SearchBudget;
use std::io::Write;
use std::process::ExitCode;
use std::sync::Arc;

/// Options of `walker walk`.
#[derive(Args)]
pub struct WalkArgs {
    #[command(flatten)]
    pub common: Common,
    /// Number of steps (at most 100,000).
    #[arg(long)]
    pub steps: usize,
    /// Perturb a start-state entry: `coord=delta` (coordinate or `coord_dot`).
    #[arg(long = "perturb", value_name = "COORD=DELTA")]
    pub perturb: Vec<String>,
    /// Start from `gait` (the fixed point) or `guess` (the scene's guess, no search).
    #[arg(long, default_value = "gait")]
    pub start: String,
    /// Start from the gait of another scene instead, coordinate by coordinate (those this
    /// scene lacks are dropped, those it adds start at 0), e.g. the compensated walker's
    /// leg state for the uncompensated one.
    #[arg(long, value_name = "SCENE")]
    pub start_from_scene: Option<String>,
    /// Set start-state entries from a JSON file: an object of stride-map entries
    /// (`coord` or `coord_dot`, as `walker gait --json` names them) to numbers, or a
    /// `walker gait --json` output (its `fixed_point`). Entries it does not name keep
    /// their values from `--start`; applied before `--perturb`.
    #[arg(long, value_name = "FILE.json")]
    pub start_state: Option<std::path::PathBuf>,
    /// Write the trajectory (every integrator sample) as CSV.
    #[arg(long, value_name = "FILE.csv")]
    pub out: Option<std::path::PathBuf>,
    /// Write the floor path of the hip-axle centre into this folder (SVG, PNG and PDF).
    #[arg(long, value_name = "DIR")]
    pub plot: Option<std::path::PathBuf>,
    /// Also walk this scene (with its own parameters) from its own gait, the same number of
    /// steps, and draw its path in the same figure (e.g. the compensated walker beside the
    /// uncompensated one).
    #[arg(long, value_name = "SCENE")]
    pub plot_with: Option<String>,
    /// Write a self-contained HTML page that plays the walk in 3D (docs/animation.md).
    #[arg(long, value_name = "FILE.html")]
    pub animate: Option<std::path::PathBuf>,
    #[arg(long, value_name = "SPEC", default_value = "plane", help = crate::options::FLOOR_HELP)]
    pub floor: String,
}

/// Runs `walker walk`: exit code 1 if there is no gait to start from, 3 if the walker fell
/// (the report's `failure`).
pub fn run(args: WalkArgs) -> Result<ExitCode> {
    let WalkArgs {
        common,
        steps,
        perturb,
        start,
        start_from_scene,
        start_state,
        out,
        plot,
        plot_with,
        animate,
        floor,
    } = args;
    let floor: Floor = crate::options::floor(&floor)?;
    let steps = limits::count("--steps", steps, 0, limits::MAX_WALK_STEPS)?;
    // Flags the walk would ignore are refused, not dropped in silence.
    if plot_with.is_some() && plot.is_none() {
        return Err(InputError::Other(
            "--plot-with draws into the --plot figure: give --plot DIR too".to_owned(),
        )
        .into());
    }
    if start_from_scene.is_some() && start != "gait" {
        return Err(InputError::Other(format!(
            "--start-from-scene starts from another scene's gait: it cannot be combined with \
             --start {start}"
        ))
        .into());
    }
    let scene = common.scene()?;
    let setup = common.setup(&scene)?;
    let walker = &setup.walker;
    // The output paths before the walk: a path that cannot be used fails at once.
    if let Some(dir) = &plot {
        output::create_dir("--plot", dir)?;
    }
    let animation = animation::open(animate.as_deref(), steps)?;
    let csv = match &out {
        Some(path) => Some((
            path,
            std::fs::File::create(path).map_err(|e| PathError::new("--out", path, e))?,
        )),
        None => None,
    };
    let v0 = walker.pack(&setup.guess.q, &setup.guess.qd);
    let (newton, setup_for) = (common.newton(), common.setup_for());
    let homotopy = common.homotopy();
    let budget = Arc::new(SearchBudget::new(common.max_strides));
    let rule = GaitRule::new(&setup_for, &newton, &homotopy).with_budget(Arc::clone(&budget));
    let search_progress = SearchProgress::watch(&budget, "gait search", !common.json);
    let from_other = |other: &str| start::from_other_scene(other, &scene, walker, &rule);
    let started = match (start_from_scene, start.as_str()) {
        (Some(other), _) => from_other(&other)?,
        (None, "guess") => Some((v0, StartRecord::guess(scene.name()))),
        (None, "gait") => match gait_start(&scene, walker, &rule)? {
            GaitStart::Own { gait, source } => {
                let record = StartRecord::gait(scene.name(), &gait, source);
                Some((gait.fixed_point, record))
            }
            GaitStart::Other { start, .. } => {
                output::note(format_args!(
                    "note: scene `{}` has no gait of its own; starting from the gait of `{}`",
                    scene.name(),
                    start.scene.name()
                ));
                let record = StartRecord::gait(start.scene.name(), &start.gait, start.source);
                Some((start.state, record))
            }
            GaitStart::None {
                other: Some((other, e)),
                ..
            } => {
                output::note(format_args!(
                    "note: scene `{}` has no gait of its own; starting from the gait of `{other}`",
                    scene.name()
                ));
                output::note(format_args!(
                    "error: scene `{other}` has no gait to start from: {e}"
                ));
                None
            }
            GaitStart::None { own, other: None } => {
                output::note(format_args!(
                    "error: no gait to start from: {own} (use --start guess)"
                ));
                None
            }
        },
        (None, other) => {
            return Err(
                InputError::Other(format!("--start `{other}`: expected gait or guess")).into(),
            )
        }
    };
    drop(search_progress);
    let Some((mut v, start_record)) = started else {
        return Ok(ExitCode::from(1));
    };
    let names = walker.map_names();
    if let Some(path) = &start_state {
        for (i, x) in start::read_start_state(path, &names)? {
            v[i] = x;
        }
    }
    let mut perturbed: Vec<usize> = Vec::with_capacity(perturb.len());
    for p in &perturb {
        let (i, d) = start::parse_perturbation(p, &names)?;
        if perturbed.contains(&i) {
            // Two perturbations of one entry were added in silence.
            return Err(InputError::Other(format!(
                "--perturb `{p}`: `{}` is already perturbed (each entry once)",
                names[i]
            ))
            .into());
        }
        perturbed.push(i);
        v[i] += d;
    }
    let (q, qd) = walker.unpack(&v);
    let progress = Progress::after(PROGRESS_DELAY, steps, "walk (steps)", !common.json);
    let mut tick = |_: &sim::stride::walk::StepSummary| progress.tick();
    // The CSV is written as the strides complete (every integrator sample); the figure and
    // the page keep the path thinned to their resolution: memory follows neither the walk's
    // length (for --out) nor the integrator's step.
    let mut csv = csv.map(|(path, file)| (path, PathCsv::new(file, walker)));
    let mut row = |s: &sim::stride::walk::PathSample| {
        if let Some((_, c)) = csv.as_mut() {
            c.row(s);
        }
    };
    let mut request = WalkRequest::new(&setup.settings, steps)
        .floor(floor)
        .recording(plot.is_some() || animation.is_some())
        .path_interval(animation::PATH_SAMPLE_INTERVAL_S)
        .on_step(&mut tick);
    if out.is_some() {
        request = request.on_sample(&mut row);
    }
    let walk = sim::stride::walk::walk(walker, &q, &qd, request);
    progress.finish();
    if let Some((path, c)) = csv {
        c.finish().map_err(|e| PathError::new("--out", path, e))?;
    }
    if let Some(dir) = &plot {
        let mut walks = vec![(scene.clone(), walk.clone())];
        if let Some(other) = &plot_with {
            // The other scene walks with its own defaults, from its own gait.
            let os = Scene::load(other)?;
            let oset = os.setup()?;
            let ow = &oset.walker;
            let v0 = ow.pack(&oset.guess.q, &oset.guess.qd);
            let start = rule.gait(&os)?.map(|(g, _)| g.fixed_point).unwrap_or(v0);
            let (oq, oqd) = ow.unpack(&start);
            let request = WalkRequest::new(&oset.settings, steps)
                .recording(true)
                .path_interval(animation::PATH_SAMPLE_INTERVAL_S);
            let other_walk = sim::stride::walk::walk(ow, &oq, &oqd, request);
            walks.push((os, other_walk));
        }
        let refs: Vec<(&Scene, &sim::stride::walk::Walk)> =
            walks.iter().map(|(s, w)| (s, w)).collect();
        let size = (860.0, 480.0);
        let fig = figures::floor_paths(&refs, size);
        export::write_figure("--plot", dir, "floor_path", &fig.to_svg(size.0, size.1))?;
    }
    if let Some(file) = animation {
        file.write(&Animation {
            scene: &scene,
            walker,
            walk: &walk,
            command: "walk",
            events: timeline::walk_events(&walk),
            firmware: false,
            emergency_stop_sent_s: None,
        })?;
    }
    let mut report = WalkReport::new(&scene, &walk);
    report.start = Some(start_record);
    report.floor = floor;
    if common.json {
        print_json(&report)?;
    } else {
        let gait = WalkGaitRecord::of(walker, &walk, GAIT_STEPS)
            .map(|g| GaitFigures::of_walk(&g, walker.ankle().is_some()));
        output::text(|out| print_text(out, &report, steps, gait.as_ref()))?;
    }
    Ok(walk_exit_code(&walk))
}

/// Steps the text output's gait figures average over (the last ones), as `walker sil`'s.
const GAIT_STEPS: usize = 10;

/// A walk that lasts longer than this shows a progress bar (on a terminal, without `--json`).
pub const PROGRESS_DELAY: std::time::Duration = std::time::Duration::from_secs(1);

/// The legend of the walk table (also in docs/engine.md): the step numbering and what each
/// column means, `deviation` above all.
pub const TABLE_LEGEND: &str = "\
steps are numbered from 1; start_s: walk time at the step's start; length_m: distance between
the feet at heel strike; deviation: the largest difference (∞-norm) between the state after the
step and the walk's start state, over every coordinate [rad, m] and rate [rad/s, m/s] of the
stride map: near 0 while the walker repeats its start state (a gait's fixed point), growing as
it drifts away from it";

fn print_text(
    out: &mut dyn Write,
    r: &WalkReport,
    steps: usize,
    gait: Option<&GaitFigures>,
) -> std::io::Result<()> {
    writeln!(
        out,
        "scene {}: {} of {steps} steps",
        r.scene, r.steps_completed
    )?;
    if let Some(start) = &r.start {
        writeln!(out, "start: {}", start.describe())?;
    }
    if let Some(floor) = r.floor.describe() {
        writeln!(out, "floor: {floor}")?;
    }
    writeln!(
        out,
        "{:>5} {:>10} {:>10} {:>10} {:>12}",
        "step", "start_s", "period_s", "length_m", "deviation"
    )?;
    for s in &r.steps {
        writeln!(
            out,
            "{:>5} {:>10.4} {:>10.5} {:>10.5} {:>12.3e}",
            labels::step_number(s.step),
            s.start_t_walk_s,
            s.duration_s,
            s.step_length_m,
            s.state_deviation
        )?;
    }
    writeln!(out, "{TABLE_LEGEND}")?;
    if let Some(g) = gait {
        match r.steps.len().min(GAIT_STEPS) {
            1 => writeln!(out, "gait of the one step walked:")?,
            n => writeln!(out, "gait, mean over the last {n} steps:")?,
        }
        g.write(out, "    ")?;
    }
    match &r.failure {
        None => writeln!(out, "no failure"),
        Some(f) => writeln!(out, "failure: {}", failure_text(f)),
    }
}

/// A walk's failure for people: its kind in words, the step (numbered from 1), the walk time
/// and the engine's detail ("fell forward in step 2 at t = 1.9297 s: …"). `walker sil` prints
/// it so too.
pub fn failure_text(f: &sim::stride::walk::WalkFailure) -> String {
    format!(
        "{} in {} at t = {:.4} s: {}",
        labels::walk_end_label(f.kind),
        labels::step_label(f.step),
        f.t_walk_s,
        f.detail
    )
}
