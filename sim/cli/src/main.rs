//! `walker`: find gaits, walk, sweep parameters, list scenes.
//!
//! Bad input (unknown scene, unknown or ill-typed parameter, non-physical value) exits with
//! code 2 and a message naming the problem; a gait that cannot be found exits with code 1.

use anyhow::Result;
use clap::{Args, Parser, Subcommand};
use nalgebra::DVector;
use serde_json::{json, Value};
use sim::accuracy;
use sim::continuation::sweep;
mod figures;
mod plot;

use sim::integrators::IntegratorChoice;
use sim::limit_cycle::JacobianMethod;
use sim::limit_cycle::NewtonSettings;
use sim::report::{gait_json, sweep_json, walk_json};
use sim::scene::{Scene, SceneError, Setup, BUILTIN};
use sim::tune::{tune, TunedParameter};
use sim::walk::WalkRequest;
use sim::walker::Walker;
use std::io::Write;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "walker",
    version,
    about = "Passive dynamic walker simulator (Wisse, Schwab & van der Linde 2001)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Find the periodic gait of a scene and its stability.
    Gait {
        #[command(flatten)]
        common: Common,
        /// Write SVG figures (eigenvalues, joint angles over a stride) into this folder.
        #[arg(long, value_name = "DIR")]
        plot: Option<std::path::PathBuf>,
    },
    /// Simulate N steps from the gait (or the scene's guess), optionally perturbed.
    Walk {
        #[command(flatten)]
        common: Common,
        /// Number of steps.
        #[arg(long)]
        steps: usize,
        /// Perturb a start-state entry: `coord=delta` (coordinate or `coord_dot`).
        #[arg(long = "perturb", value_name = "COORD=DELTA")]
        perturb: Vec<String>,
        /// Start from `gait` (the fixed point) or `guess` (the scene's guess, no search).
        #[arg(long, default_value = "gait")]
        start: String,
        /// Start from the gait of another scene instead, coordinate by coordinate (those this
        /// scene lacks are dropped, those it adds start at 0), e.g. the compensated walker's
        /// leg state for the uncompensated one.
        #[arg(long, value_name = "SCENE")]
        start_from_scene: Option<String>,
        /// Set start-state entries from a JSON file: an object of stride-map entries
        /// (`coord` or `coord_dot`, as `walker gait --json` names them) to numbers, or a
        /// `walker gait --json` output (its `fixed_point`). Entries it does not name keep
        /// their values from `--start`; applied before `--perturb`.
        #[arg(long, value_name = "FILE.json")]
        start_state: Option<std::path::PathBuf>,
        /// Write the trajectory (every integrator sample) as CSV.
        #[arg(long, value_name = "FILE.csv")]
        out: Option<std::path::PathBuf>,
        /// Write the floor path of the hip-axle centre as SVG into this folder.
        #[arg(long, value_name = "DIR")]
        plot: Option<std::path::PathBuf>,
        /// Also walk this scene (with its own parameters) from its own gait, the same number of
        /// steps, and draw its path in the same figure (e.g. the compensated walker beside the
        /// uncompensated one).
        #[arg(long, value_name = "SCENE")]
        plot_with: Option<String>,
    },
    /// Continuation: follow the gait while one parameter changes.
    Sweep {
        #[command(flatten)]
        common: Common,
        /// Parameter to vary.
        #[arg(long)]
        param: String,
        /// First value.
        #[arg(long, allow_negative_numbers = true)]
        from: f64,
        /// Last value.
        #[arg(long, allow_negative_numbers = true)]
        to: f64,
        /// Number of points (≥ 2).
        #[arg(long)]
        points: usize,
    },
    /// Search parameters within bounds for the smallest largest |eigenvalue| (Nelder-Mead).
    Tune {
        #[command(flatten)]
        common: Common,
        /// A parameter the search may change: `name=min:max` (repeatable).
        #[arg(long = "vary", value_name = "NAME=MIN:MAX", required = true)]
        vary: Vec<String>,
        /// Gait searches allowed.
        #[arg(long, default_value_t = 60)]
        evaluations: usize,
    },
    /// Speed against error: every integrator over a range of steps or tolerances, errors of
    /// the fixed point, eigenvalues and heel-strike time against a tight reference.
    Accuracy {
        #[command(flatten)]
        common: Common,
        /// Write `accuracy.md` and log-log SVG plots into this folder.
        #[arg(long, value_name = "DIR")]
        out: Option<std::path::PathBuf>,
    },
    /// Software in the loop: the ankle firmware (two nodes on a simulated CAN bus) actuates
    /// the walker; compared with the ideal-actuator gait.
    Sil {
        #[command(flatten)]
        common: Common,
        /// Number of steps.
        #[arg(long)]
        steps: usize,
        /// A bus fault, e.g. `drop:id=0x101,count=5` (repeatable; docs/canbus.md).
        #[arg(long = "fault", value_name = "SPEC")]
        faults: Vec<String>,
        /// An encoder fault (repeatable; docs/sil.md):
        /// `glitch:side=left,at_ms=500[,delta_rad=0.1]`, `stuck:side=left,from_ms=500`,
        /// `spi:side=right,from_ms=500[,until_ms=700]`, `parity:side=right,at_ms=500`.
        #[arg(long = "sensor-fault", value_name = "SPEC")]
        sensor_faults: Vec<String>,
        /// Host emergency stop to every ankle at this walk time [s].
        #[arg(long, value_name = "SECONDS")]
        estop_at: Option<f64>,
        /// Write the bus traffic as a candump log.
        #[arg(long, value_name = "FILE")]
        candump: Option<std::path::PathBuf>,
        /// Serve the bus live over the socketcand protocol on this address (127.0.0.1:PORT).
        #[arg(long, value_name = "ADDR")]
        socketcand: Option<String>,
        /// Slow the simulation to this multiple of real time (e.g. 1 for a live monitor); by
        /// default it runs as fast as it can.
        #[arg(long, value_name = "FACTOR")]
        realtime: Option<f64>,
        /// Keep only the last N step summaries in the JSON's `steps` (default: all); the gait
        /// figures use the last 10 and `steps_completed` counts every step. For long runs:
        /// memory and output stay bounded.
        #[arg(long, value_name = "N")]
        keep_steps: Option<usize>,
    },
    /// List the scenes and their parameters.
    Scenes {
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
}

#[derive(Args)]
struct Common {
    /// Scene name (see `walker scenes`) or path to a scene .toml file.
    #[arg(long)]
    scene: String,
    /// Set a parameter: `key=value` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Print JSON.
    #[arg(long)]
    json: bool,
    /// Integrator: meijaard, rk4, dopri5 or dop853 (default: the scene's).
    #[arg(long)]
    integrator: Option<String>,
    /// Fixed step for meijaard/rk4 [s].
    #[arg(long)]
    step_s: Option<f64>,
    /// Relative and absolute tolerance for dopri5 and dop853.
    #[arg(long)]
    rtol: Option<f64>,
    /// Newton tolerance on |Δv|.
    #[arg(long, default_value_t = 1e-11)]
    newton_tol: f64,
    /// Newton iteration budget.
    #[arg(long, default_value_t = 30)]
    newton_max_iter: usize,
    /// Perturbation step of the stride Jacobian.
    #[arg(long, default_value_t = 1e-6)]
    perturbation: f64,
    /// The perturbed strides of the stride Jacobian replay the nominal stride's steps
    /// (internal numerical differentiation) instead of choosing their own.
    #[arg(long)]
    frozen_steps: bool,
    /// The stride Jacobian: `central` differences or the `variational` equations (exact
    /// derivatives; strides they do not cover fall back to central differences, and the JSON's
    /// `jacobian_method` says which was used).
    #[arg(long, default_value = "central")]
    jacobian: String,
}

/// Bad input: exit code 2.
#[derive(Debug, thiserror::Error)]
enum InputError {
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error("{0}")]
    Other(String),
}

impl Common {
    fn scene(&self) -> Result<Scene, InputError> {
        let mut scene = Scene::load(&self.scene)?;
        for s in &self.set {
            scene.set_text(s)?;
        }
        Ok(scene)
    }

    fn walker(&self, scene: &Scene) -> Result<Setup, InputError> {
        let mut w = scene.setup()?;
        let positive = |name: &str, v: Option<f64>| match v {
            Some(x) if !(x.is_finite() && x > 0.0) => Err(InputError::Other(format!(
                "--{name} must be a positive number, got {x}"
            ))),
            _ => Ok(()),
        };
        positive("step-s", self.step_s)?;
        positive("rtol", self.rtol)?;
        positive("newton-tol", Some(self.newton_tol))?;
        positive("perturbation", Some(self.perturbation))?;
        if !matches!(self.jacobian.as_str(), "central" | "variational") {
            return Err(InputError::Other(format!(
                "--jacobian `{}`: expected central or variational",
                self.jacobian
            )));
        }
        if let Some(kind) = &self.integrator {
            w.settings.integrator =
                IntegratorChoice::from_kind(kind, self.step_s, self.rtol, None, None).ok_or_else(
                    || {
                        InputError::Other(format!(
                            "--integrator `{kind}`: expected meijaard, rk4, dopri5 or dop853"
                        ))
                    },
                )?;
        } else {
            w.settings.integrator = w
                .settings
                .integrator
                .with_tolerance_or_step(self.rtol, self.step_s);
        }
        Ok(w)
    }

    fn newton(&self) -> NewtonSettings {
        NewtonSettings {
            tolerance: self.newton_tol,
            max_iterations: self.newton_max_iter,
            perturbation: self.perturbation,
            central: true,
            max_halvings: 8,
            frozen_steps: self.frozen_steps,
            jacobian: match self.jacobian.as_str() {
                "variational" => JacobianMethod::Variational,
                _ => JacobianMethod::CentralDifferences,
            },
        }
    }
}

fn print_json(v: &Value) -> Result<()> {
    let mut out = std::io::stdout().lock();
    serde_json::to_writer_pretty(&mut out, v)?;
    writeln!(out)?;
    Ok(())
}

fn run(cli: Cli) -> Result<ExitCode> {
    match cli.command {
        Command::Scenes { json } => scenes(json),
        Command::Gait { common, plot } => {
            let scene = common.scene()?;
            let setup = common.walker(&scene)?;
            let walker = &setup.walker;
            let result = setup.find_gait(&common.newton());
            let report = gait_json(&scene, walker, &setup.settings, &result);
            if let (Some(dir), Ok(g)) = (&plot, &result) {
                std::fs::create_dir_all(dir)?;
                let name = scene.name();
                let eig = figures::eigenvalues(
                    walker,
                    g,
                    &format!("{name}: eigenvalues of the stride Jacobian"),
                );
                std::fs::write(dir.join("eigenvalues.svg"), eig.to_svg(640.0, 600.0))?;
                let ang = figures::joint_angles(
                    walker,
                    &setup.settings,
                    g,
                    &format!("{name}: joint angles over one step"),
                );
                std::fs::write(dir.join("joint_angles.svg"), ang.to_svg(820.0, 480.0))?;
            }
            if common.json {
                print_json(&report)?;
            } else {
                print_gait_text(&report);
            }
            Ok(if result.is_ok() {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            })
        }
        Command::Walk {
            common,
            steps,
            perturb,
            start,
            start_from_scene,
            start_state,
            out,
            plot,
            plot_with,
        } => {
            let scene = common.scene()?;
            let setup = common.walker(&scene)?;
            let walker = &setup.walker;
            let v0 = walker.pack(&setup.guess.q, &setup.guess.qd);
            let start_from_scene = match (start_from_scene, start.as_str()) {
                (None, "gait") => match &scene.file.walk_start_scene {
                    Some(other) if setup.find_gait(&common.newton()).is_err() => {
                        eprintln!(
                            "note: scene `{}` has no gait of its own; starting from the gait of `{other}`",
                            scene.name()
                        );
                        Some(other.clone())
                    }
                    _ => None,
                },
                (s, _) => s,
            };
            let mut v = match (start_from_scene, start.as_str()) {
                (Some(other), _) => match start_from_other(&other, &scene, walker, &common)? {
                    Some(v) => v,
                    None => return Ok(ExitCode::from(1)),
                },
                (None, "guess") => v0,
                (None, "gait") => match setup.find_gait(&common.newton()) {
                    Ok(g) => g.fixed_point,
                    Err(e) => {
                        eprintln!("error: no gait to start from: {e} (use --start guess)");
                        return Ok(ExitCode::from(1));
                    }
                },
                (None, other) => {
                    return Err(InputError::Other(format!(
                        "--start `{other}`: expected gait or guess"
                    ))
                    .into())
                }
            };
            let names = walker.map_names();
            if let Some(path) = &start_state {
                for (i, x) in read_start_state(path, &names)? {
                    v[i] = x;
                }
            }
            for p in &perturb {
                let (k, d) = p.split_once('=').ok_or_else(|| {
                    InputError::Other(format!("--perturb `{p}`: expected coord=delta"))
                })?;
                let i = names.iter().position(|n| n == k.trim()).ok_or_else(|| {
                    InputError::Other(format!(
                        "--perturb: unknown coordinate `{}` (known: {})",
                        k.trim(),
                        names.join(", ")
                    ))
                })?;
                let d: f64 = d
                    .trim()
                    .parse()
                    .ok()
                    .filter(|x: &f64| x.is_finite())
                    .ok_or_else(|| {
                        InputError::Other(format!(
                            "--perturb `{p}`: `{}` is not a finite number",
                            d.trim()
                        ))
                    })?;
                v[i] += d;
            }
            let (q, qd) = walker.unpack(&v);
            let request =
                WalkRequest::new(&setup.settings, steps).recording(out.is_some() || plot.is_some());
            let walk = sim::walk::walk(walker, &q, &qd, request);
            if let Some(dir) = &plot {
                std::fs::create_dir_all(dir)?;
                let mut walks = vec![(scene.name().to_string(), walk.clone())];
                if let Some(other) = &plot_with {
                    // The other scene walks with its own defaults, from its own gait.
                    let os = Scene::load(other)?;
                    let oset = os.setup()?;
                    let ow = &oset.walker;
                    let v0 = ow.pack(&oset.guess.q, &oset.guess.qd);
                    let start = oset
                        .find_gait(&common.newton())
                        .map(|g| g.fixed_point)
                        .unwrap_or(v0);
                    let (oq, oqd) = ow.unpack(&start);
                    let request = WalkRequest::new(&oset.settings, steps).recording(true);
                    walks.push((
                        os.name().to_string(),
                        sim::walk::walk(ow, &oq, &oqd, request),
                    ));
                }
                let refs: Vec<(&str, &sim::walk::Walk)> =
                    walks.iter().map(|(n, w)| (n.as_str(), w)).collect();
                let fig = figures::floor_paths(&refs, "path of the hip-axle centre on the floor");
                std::fs::write(dir.join("floor_path.svg"), fig.to_svg(820.0, 420.0))?;
            }
            if let Some(path) = out {
                write_csv(&path, walker, &walk)?;
            }
            let report = walk_json(&scene, &walk);
            if common.json {
                print_json(&report)?;
            } else {
                println!(
                    "scene {}: {} of {steps} steps",
                    scene.name(),
                    walk.steps_completed
                );
                println!(
                    "{:>5} {:>10} {:>10} {:>10} {:>12}",
                    "step", "t_s", "period_s", "length_m", "deviation"
                );
                for s in &walk.steps {
                    println!(
                        "{:>5} {:>10.4} {:>10.5} {:>10.5} {:>12.3e}",
                        s.step, s.start_t_walk_s, s.duration_s, s.step_length_m, s.state_deviation
                    );
                }
                match &walk.failure {
                    None => println!("no failure"),
                    Some(f) => println!(
                        "failure: {:?} in step {} at t = {:.4} s: {}",
                        f.kind, f.step, f.t_walk_s, f.detail
                    ),
                }
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Accuracy { common, out } => {
            let scene = common.scene()?;
            let setup = common.walker(&scene)?;
            let reference = IntegratorChoice::Dopri5 {
                rtol: 1e-13,
                atol: 1e-13,
                h_max_s: 0.01,
            };
            let period = {
                match setup.find_gait(&common.newton()) {
                    Ok(g) => g.stride.duration_s,
                    Err(e) => {
                        eprintln!("error: no gait: {e}");
                        return Ok(ExitCode::from(1));
                    }
                }
            };
            let settings = accuracy::default_settings(period);
            let study = match accuracy::study(&setup, reference, &settings, &common.newton()) {
                Ok(s) => s,
                Err(e) => {
                    eprintln!("error: no reference gait: {e}");
                    return Ok(ExitCode::from(1));
                }
            };
            let table = accuracy_table(&study);
            if common.json {
                print_json(&json!(study))?;
            } else {
                print!("{table}");
            }
            if let Some(dir) = out {
                std::fs::create_dir_all(&dir)?;
                std::fs::write(dir.join("accuracy.md"), &table)?;
                let panels: [(&str, &str, ErrorOf); 3] = [
                    ("fixed_point_error.svg", "fixed-point error [-]", |p| {
                        p.fixed_point_error
                    }),
                    ("eigenvalue_error.svg", "eigenvalue error [-]", |p| {
                        p.eigenvalue_error
                    }),
                    (
                        "heel_strike_time_error.svg",
                        "heel-strike time error [s]",
                        |p| p.heel_strike_time_error_s,
                    ),
                ];
                for (file, what, f) in panels {
                    let plot = figures::accuracy(&study, f, what);
                    std::fs::write(dir.join(file), plot.to_svg(720.0, 480.0))?;
                }
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Sil {
            common,
            steps,
            faults,
            sensor_faults,
            estop_at,
            candump,
            socketcand,
            realtime,
            keep_steps,
        } => {
            let scene = common.scene()?;
            let Setup {
                walker,
                settings: mut stride_settings,
                ..
            } = common.walker(&scene)?;
            let Some(reflex) = walker.ankle.clone() else {
                return Err(InputError::Other(format!(
                    "scene `{}` has no actuated ankles (ankle_reflex)",
                    scene.name()
                ))
                .into());
            };
            let mut config = sil::config::SilConfig::default()
                .with_reflex(&reflex)
                .map_err(|e| InputError::Other(format!("reflex parameters: {e}")))?;
            for f in &faults {
                config = config
                    .with_fault_str(f)
                    .map_err(|e| InputError::Other(format!("--fault `{f}`: {e}")))?;
            }
            for f in &sensor_faults {
                config = config
                    .with_sensor_fault_str(f)
                    .map_err(|e| InputError::Other(format!("--sensor-fault `{f}`: {e}")))?;
            }
            if let Some(addr) = &socketcand {
                let parsed: std::net::SocketAddr = addr.parse().map_err(|_| {
                    InputError::Other(format!("--socketcand `{addr}`: expected IP:PORT"))
                })?;
                if !parsed.ip().is_loopback() {
                    return Err(InputError::Other(format!(
                        "--socketcand `{addr}`: only loopback addresses are served"
                    ))
                    .into());
                }
            }
            if let Some(r) = realtime {
                if !(r.is_finite() && r > 0.0) {
                    return Err(
                        InputError::Other(format!("--realtime must be positive, got {r}")).into(),
                    );
                }
            }
            config.candump = candump;
            config.socketcand = socketcand;
            // The ideal-actuator gait with the scene's own (accurate) integrator; the walk with
            // the firmware uses `sil::SIL_INTEGRATOR` (DOPRI5 at 1e-6, at most one step
            // per 1 ms control tick) unless an integrator is given on the command line.
            let ideal_setup = scene.setup()?;
            let ideal_walker = &ideal_setup.walker;
            let ideal = match ideal_setup.find_gait(&common.newton()) {
                Ok(g) => g,
                Err(e) => {
                    eprintln!("error: no ideal-actuator gait to start from: {e}");
                    return Ok(ExitCode::from(1));
                }
            };
            if common.integrator.is_none() && common.rtol.is_none() && common.step_s.is_none() {
                stride_settings.integrator = sil::SIL_INTEGRATOR;
            }
            // Its errors are about the configuration given (fault nodes, log path, address).
            let mut ctl = sil::FirmwareInTheLoop::new(config)
                .map_err(|e| InputError::Other(format!("software in the loop: {e}")))?;
            if let Some(t) = estop_at {
                ctl.emergency_stop_at(t);
            }
            if let Some(addr) = ctl.socketcand_addr() {
                eprintln!("socketcand: serving the bus on {addr} (channel vcan0)");
            }
            let (q, qd) = walker.unpack(&ideal.fixed_point);
            // The gait figures average the last 10 steps: keep at least those.
            let options = sim::walk::WalkOptions {
                record: false,
                keep_steps: keep_steps.map(|n| n.max(10)),
            };
            let walk = match realtime {
                None => sim::walk::walk(
                    &walker,
                    &q,
                    &qd,
                    WalkRequest::new(&stride_settings, steps)
                        .options(options)
                        .controlled(&mut ctl),
                ),
                Some(factor) => {
                    // Step by step, sleeping so that walk time keeps pace with wall time.
                    let start = std::time::Instant::now();
                    let mut paced = sim::control::Paced::new(&mut ctl, factor, start);
                    sim::walk::walk(
                        &walker,
                        &q,
                        &qd,
                        WalkRequest::new(&stride_settings, steps)
                            .options(options)
                            .controlled(&mut paced),
                    )
                }
            };
            let kept = keep_steps.unwrap_or(usize::MAX).min(walk.steps.len());
            let steps_json = &walk.steps[walk.steps.len() - kept..];
            let report = ctl
                .finish()
                .map_err(|e| anyhow::anyhow!("software in the loop: {e}"))?;
            let sil_gait = sim::report::walk_gait_json(&walker, &walk, 10);
            let ideal_gait = sim::report::ideal_gait_json(ideal_walker, &ideal);
            let out = json!({
                "scene": scene.name(),
                "integrator": stride_settings.integrator,
                "steps_completed": walk.steps_completed,
                "failure": walk.failure,
                "gait": sil_gait,
                "ideal_gait": ideal_gait,
                "node_faults": report.faults,
                "nodes": report.nodes,
                "bus_load": report.bus.load,
                "bus": report.bus,
                "frames": report.frames_delivered,
                "steps": steps_json,
            });
            if common.json {
                print_json(&out)?;
            } else {
                println!(
                    "scene {}: {} of {steps} steps with the firmware actuating",
                    scene.name(),
                    walk.steps_completed
                );
                if let Some(f) = &walk.failure {
                    println!(
                        "failure: {:?} in step {} at t = {:.4} s: {}",
                        f.kind, f.step, f.t_walk_s, f.detail
                    );
                }
                for (label, g) in [("firmware", &out["gait"]), ("ideal", &out["ideal_gait"])] {
                    println!(
                        "{label:>9}: period {:.5} s, step {:.5} m, speed {:.5} m/s, cost of transport {:.5} J/(kg m)",
                        g["step_period_s"].as_f64().unwrap_or(f64::NAN),
                        g["step_length_m"].as_f64().unwrap_or(f64::NAN),
                        g["speed_m_s"].as_f64().unwrap_or(f64::NAN),
                        g["cost_of_transport_J_per_kg_m"].as_f64().unwrap_or(f64::NAN),
                    );
                }
                println!(
                    "bus load {:.2} %, {} frames, {} node fault events",
                    100.0 * report.bus.load,
                    report.frames_delivered,
                    report.faults.len()
                );
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Tune {
            common,
            vary,
            evaluations,
        } => {
            let scene = common.scene()?;
            common.walker(&scene)?;
            let mut params = Vec::new();
            for v in &vary {
                let bad = || InputError::Other(format!("--vary `{v}`: expected name=min:max"));
                let (name, range) = v.split_once('=').ok_or_else(bad)?;
                let (lo, hi) = range.split_once(':').ok_or_else(bad)?;
                let (min, max): (f64, f64) = (
                    lo.trim().parse().map_err(|_| bad())?,
                    hi.trim().parse().map_err(|_| bad())?,
                );
                if !(min.is_finite() && max.is_finite() && min < max) {
                    return Err(bad().into());
                }
                params.push(TunedParameter {
                    name: name.trim().to_string(),
                    min,
                    max,
                });
            }
            let result = tune(&scene, &params, evaluations, &common.newton())?;
            if common.json {
                print_json(&json!(result))?;
            } else {
                println!("{} evaluations", result.history.len());
                for (p, v) in result.parameters.iter().zip(&result.best.values) {
                    println!(
                        "    {:<36} {:>12.6}   (bounds {} .. {})",
                        p.name, v, p.min, p.max
                    );
                }
                match result.best.max_abs_eigenvalue {
                    Some(m) => println!("best max |λ| = {m:.6}"),
                    None => println!("no gait found"),
                }
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Sweep {
            common,
            param,
            from,
            to,
            points,
        } => {
            let scene = common.scene()?;
            common.walker(&scene)?;
            if !(from.is_finite() && to.is_finite()) {
                return Err(InputError::Other("--from and --to must be finite".into()).into());
            }
            if points < 2 {
                return Err(InputError::Other(format!(
                    "--points must be at least 2, got {points}"
                ))
                .into());
            }
            let (pts, bounds) =
                sweep(&scene, &param, from, to, points, &common.newton()).map_err(|e| match e {
                    sim::continuation::SweepError::Scene(s) => InputError::Scene(s),
                    other => InputError::Other(other.to_string()),
                })?;
            let walker_for = |value: f64| {
                let mut s = scene.clone();
                s.set(&param, value).ok()?;
                let w = s.build().ok()?;
                Some((s, w))
            };
            let report = sweep_json(&scene, &walker_for, &param, &pts, &bounds);
            if common.json {
                print_json(&report)?;
            } else {
                println!("{:>14} {:>10} {:>8}", param, "max|λ|", "stable");
                for p in &pts {
                    match &p.gait {
                        Ok(g) => println!(
                            "{:>14.6} {:>10.6} {:>8}",
                            p.value,
                            g.max_abs_eigenvalue(),
                            g.stable()
                        ),
                        Err(e) => println!("{:>14.6} {:>10} {:>8}  {e}", p.value, "-", "-"),
                    }
                }
                for b in &bounds {
                    println!("stability {} at {} ≈ {:.6}", b.change, param, b.value);
                }
            }
            Ok(ExitCode::SUCCESS)
        }
    }
}

/// The gait of scene `other` (with this scene's shared parameter values), mapped onto this
/// walker's stride-map entries by name. `None` (after a message) if it has no gait.
/// The entries a start-state file sets, as (stride-map index, value); every problem with the
/// file is bad input naming it.
fn read_start_state(
    path: &std::path::Path,
    names: &[String],
) -> Result<Vec<(usize, f64)>, InputError> {
    let bad = |why: String| InputError::Other(format!("--start-state `{}`: {why}", path.display()));
    let text = std::fs::read_to_string(path).map_err(|e| bad(e.to_string()))?;
    let doc: Value = serde_json::from_str(&text).map_err(|e| bad(format!("not JSON: {e}")))?;
    // A `walker gait --json` output also lists its scene's conventional outputs (e.g.
    // Goswami's angles) in `fixed_point`: there, only the stride-map entries are read.
    let (obj, from_gait) = match doc.get("fixed_point") {
        Some(f) => (f, true),
        None => (&doc, false),
    };
    let obj = obj
        .as_object()
        .ok_or_else(|| bad("expected an object of entry names to numbers".into()))?;
    let mut out = Vec::with_capacity(obj.len());
    for (k, x) in obj {
        let Some(i) = names.iter().position(|n| n == k) else {
            if from_gait {
                continue;
            }
            return Err(bad(format!(
                "unknown entry `{k}` (known: {})",
                names.join(", ")
            )));
        };
        let x = x
            .as_f64()
            .filter(|x| x.is_finite())
            .ok_or_else(|| bad(format!("`{k}` = {x} is not a finite number")))?;
        out.push((i, x));
    }
    if out.is_empty() {
        return Err(bad("names no entry".into()));
    }
    Ok(out)
}

fn start_from_other(
    other: &str,
    scene: &Scene,
    walker: &Walker,
    common: &Common,
) -> Result<Option<DVector<f64>>> {
    let mut other_scene = Scene::load(other)?;
    for (k, val) in &scene.values {
        if other_scene.file.parameters.contains_key(k) {
            other_scene.set(k, *val)?;
        }
    }
    let oset = other_scene.setup()?;
    let ow = &oset.walker;
    let og = match oset.find_gait(&common.newton()) {
        Ok(g) => g,
        Err(e) => {
            eprintln!("error: scene `{other}` has no gait to start from: {e}");
            return Ok(None);
        }
    };
    let names = walker.map_names();
    let onames = ow.map_names();
    let mut v = DVector::zeros(names.len());
    for (i, n) in names.iter().enumerate() {
        if let Some(j) = onames.iter().position(|m| m == n) {
            v[i] = og.fixed_point[j];
        }
    }
    Ok(Some(v))
}

/// Picks one error measure from an accuracy point.
type ErrorOf = fn(&accuracy::AccuracyPoint) -> Option<f64>;

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

fn scenes(as_json: bool) -> Result<ExitCode> {
    let mut list = Vec::new();
    for (name, _) in BUILTIN {
        let s = Scene::load(name)?;
        let params: Vec<Value> = s
            .file
            .parameters
            .iter()
            .map(|(k, p)| {
                json!({"name": k, "default": p.default, "unit": p.unit, "doc": p.doc,
                       "min": p.min, "max": p.max, "aliases": p.aliases})
            })
            .collect();
        list.push(json!({"name": name, "summary": s.file.scene.summary,
                         "reference": s.file.scene.reference, "parameters": params}));
    }
    if as_json {
        print_json(&json!({ "scenes": list }))?;
    } else {
        for s in &list {
            println!(
                "{} — {}",
                s["name"].as_str().unwrap_or(""),
                s["summary"].as_str().unwrap_or("")
            );
            for p in s["parameters"].as_array().into_iter().flatten() {
                println!(
                    "    {:<24} default {:<10} [{}]  {}",
                    p["name"].as_str().unwrap_or(""),
                    p["default"],
                    p["unit"].as_str().unwrap_or(""),
                    p["doc"].as_str().unwrap_or("")
                );
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}

fn print_gait_text(r: &Value) {
    println!("scene: {}", r["scene"].as_str().unwrap_or(""));
    if r["converged"] != json!(true) {
        println!("no gait found: {}", r["error"].as_str().unwrap_or(""));
        return;
    }
    println!("fixed point (just after heel strike):");
    if let Some(m) = r["fixed_point"].as_object() {
        for (k, v) in m {
            println!("    {k:<28} {:>20.12}", v.as_f64().unwrap_or(f64::NAN));
        }
    }
    println!("eigenvalues of the stride Jacobian:");
    for e in r["eigenvalues"].as_array().into_iter().flatten() {
        let (re, im) = (
            e[0].as_f64().unwrap_or(f64::NAN),
            e[1].as_f64().unwrap_or(f64::NAN),
        );
        println!("    {re:>14.8} {im:>+14.8}i   |λ| = {:.8}", re.hypot(im));
    }
    println!(
        "max |λ| = {:.8} ({}), period {:.6} s, step {:.6} m, speed {:.6} m/s, {} Newton iterations",
        r["max_abs_eigenvalue"].as_f64().unwrap_or(f64::NAN),
        if r["stable"] == json!(true) {
            "stable"
        } else {
            "unstable"
        },
        r["step_period_s"].as_f64().unwrap_or(f64::NAN),
        r["step_length_m"].as_f64().unwrap_or(f64::NAN),
        r["speed_m_s"].as_f64().unwrap_or(f64::NAN),
        r["newton_iterations"],
    );
}

fn write_csv(path: &std::path::Path, walker: &Walker, walk: &sim::walk::Walk) -> Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    let coords: Vec<&str> = walker
        .model
        .coordinates
        .iter()
        .map(|c| c.name.as_str())
        .collect();
    write!(f, "step,time_s")?;
    for c in &coords {
        write!(f, ",{c}")?;
    }
    for c in &coords {
        write!(f, ",{c}_dot")?;
    }
    writeln!(f, ",hip_x_m,hip_y_m,hip_z_m")?;
    for s in &walk.path {
        write!(f, "{},{}", s.step, s.t_walk_s)?;
        for v in s.q.iter().chain(s.qd.iter()) {
            write!(f, ",{v}")?;
        }
        writeln!(
            f,
            ",{},{},{}",
            s.hip_floor_m.x, s.hip_floor_m.y, s.hip_floor_m.z
        )?;
    }
    f.flush()?;
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e}");
            if e.downcast_ref::<InputError>().is_some() || e.downcast_ref::<SceneError>().is_some()
            {
                ExitCode::from(2)
            } else {
                ExitCode::from(1)
            }
        }
    }
}
