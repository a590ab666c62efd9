//! `walker sil`: software in the loop. The ankle firmware (two nodes on a simulated CAN bus)
//! actuates the walker; its gait is compared with the ideal-actuator gait.

use super::walk::{failure_text, PROGRESS_DELAY};
use super::{print_json, shown, walk_exit_code};
use crate::animation::{self, timeline, Animation};
use crate::gait_text::GaitFigures;
use crate::input_error::InputError;
use crate::labels;
use crate::limits;
use crate::options::Common;
use crate::output::{self, PathError};
use crate::progress::Progress;
use crate::search_progress;
use anyhow::Result;
use clap::Args;
use sil::walk::{SilRun, SilWalkReport, WalkPlan};
use sim::analysis::homotopy::GaitSource;
use sim::analysis::limit_cycle::Gait;
use sim::scene::Setup;
use sim::stride::walk::{StepSummary, Walk};
use std::collections::BTreeMap;
use std::io::Write;
use std::process::ExitCode;

/// Options of `walker sil`.
#[derive(Args)]
pub struct SilArgs {
    #[command(flatten)]
    pub common: Common,
    /// Number of steps (at most 100,000).
    #[arg(long)]
    pub steps: usize,
    /// A bus fault, e.g. `drop:id=0x022,count=5` (the left ankle's heel strikes; repeatable;
    /// docs/canbus.md). A `drop`, `delay` or `corrupt` filter must name an identifier a node
    /// sends (heel strike 0x022/0x023, heartbeat 0x061-0x063, ankle state 0x072/0x073, ...).
    #[arg(long = "fault", value_name = "SPEC")]
    pub faults: Vec<String>,
    /// A sensor fault (repeatable; docs/sil.md): the ankle encoder's
    /// `glitch:side=left,at_ms=500[,delta_rad=0.1]`, `stuck:side=left,from_ms=500`,
    /// `stuck:side=left,state=hold` (frozen from the first tick that node is in Hold),
    /// `spi:side=right,from_ms=500[,until_ms=700]`, `parity:side=right,at_ms=500`; the contact
    /// switch's `contact:side=left,from_ms=500,state=closed|open`; the spool encoder's
    /// `spool:side=left,from_ms=500`.
    #[arg(long = "sensor-fault", value_name = "SPEC")]
    pub sensor_faults: Vec<String>,
    /// Host emergency stop to every ankle at this walk time, in seconds (finite, not negative).
    #[arg(
        long,
        value_name = "SECONDS",
        allow_negative_numbers = true,
        help = "Host emergency stop to every ankle at this walk time [s] (finite, not negative)"
    )]
    pub estop_at: Option<f64>,
    /// Write the bus traffic as a candump log.
    #[arg(long, value_name = "FILE")]
    pub candump: Option<std::path::PathBuf>,
    /// Serve the bus live over the socketcand protocol on this address (127.0.0.1:PORT).
    #[arg(long, value_name = "ADDR")]
    pub socketcand: Option<String>,
    /// With `--socketcand`: put frames the server's clients send on the bus as the host's (a
    /// control channel for any local process: a sent `EmergencyStop_ALL` stops the walker).
    /// Without it the server is read-only and refuses them.
    #[arg(long)]
    pub socketcand_allow_send: bool,
    /// With `--socketcand`: before the walk starts, wait up to this long, in seconds, for a
    /// client (e.g. the bus monitor) to connect in rawmode (0 to 86400); if none does, the walk
    /// starts anyway and says so on standard error.
    #[arg(
        long,
        value_name = "SECONDS",
        allow_negative_numbers = true,
        help = "With `--socketcand`: before the walk starts, wait up to this long [s] for a client (e.g. the bus monitor) to connect in rawmode (0 to 86400); if none does, the walk starts anyway and says so on standard error"
    )]
    pub wait_client: Option<f64>,
    /// Slow the simulation to this multiple of real time (e.g. 1 for a live monitor; 0.001 to
    /// 1000); by default it runs as fast as it can.
    #[arg(long, value_name = "FACTOR", allow_negative_numbers = true)]
    pub realtime: Option<f64>,
    /// Write a firmware parameter to both ankles over the bus before enabling them
    /// (repeatable; by default the nodes run with the firmware's own parameters):
    /// `taut_angle_rad`, `extended_angle_rad`, `push_duration_s`, `max_push_rate_rad_per_s`,
    /// `peer_heartbeat_timeout_s`, `max_angular_rate_rad_per_s`, `stuck_timeout_s`; e.g.
    /// `--firmware-param taut_angle_rad=-0.07`. Checked against each parameter's range and
    /// the writes before it.
    #[arg(
        long = "firmware-param",
        value_name = "NAME=VALUE",
        allow_hyphen_values = true
    )]
    pub firmware_params: Vec<String>,
    /// Keep only the last N step summaries in the JSON's `steps` (default: all); the gait
    /// figures use the last 10 and `steps_completed` counts every step. For long runs:
    /// memory and output stay bounded.
    #[arg(long, value_name = "N")]
    pub keep_steps: Option<usize>,
    /// The ankles' actuator: `servo` (default: a position servo that follows the setpoint)
    /// or `motor` (the firmware's own spool-motor driver over a DC gear motor, spool and
    /// string model; the nominal walk goes 200 steps with it, within 0.1 % of the servo's
    /// period and speed; released or stopped, its string stays on the unpowered spool).
    /// docs/sil.md.
    #[arg(long, value_name = "MODEL", default_value = "servo")]
    pub actuator: String,
    /// Write a self-contained HTML page that plays the walk in 3D with the ankle nodes'
    /// states and the bus events as they happen (docs/animation.md).
    #[arg(long, value_name = "FILE.html")]
    pub animate: Option<std::path::PathBuf>,
    #[arg(long, value_name = "SPEC", default_value = "plane", help = crate::options::FLOOR_HELP)]
    pub floor: String,
}

/// Runs `walker sil`: exit code 1 if there is no ideal-actuator gait to start from, 3 if the
/// walker fell (the report's `failure`). The stages: the options checked, the firmware's
/// configuration, the ideal-actuator gait, the firmware started, the walk, the report.
pub fn run(args: SilArgs) -> Result<ExitCode> {
    let (actuator_choice, steps) =
        check_options(&args.actuator, args.steps, args.estop_at, args.realtime)?;
    let animation = animation::open(args.animate.as_deref(), steps)?;
    let floor = crate::options::floor(&args.floor)?;
    let wait_client = wait_client_timeout(args.wait_client, args.socketcand.is_some())?;
    let common = &args.common;
    let candump = &args.candump;
    let scene = common.scene()?;
    let Setup {
        walker, settings, ..
    } = common.setup(&scene)?;
    let reflex = sil::walk::require_ankle(&walker, scene.name()).map_err(input)?;
    let (config, firmware_params_written) = sil_config(actuator_choice, &args)?;
    let Some((ideal_setup, ideal, source)) = ideal_gait(&scene, common)? else {
        return Ok(ExitCode::from(1));
    };
    let integrator_chosen =
        common.integrator.is_some() || common.rtol.is_some() || common.step_s.is_some();
    let stride_settings = sil::walk::walk_settings(&settings, integrator_chosen);
    let mut ctl = start_firmware(config, candump, args.estop_at, wait_client)?;
    let plan = WalkPlan {
        steps,
        keep_steps: args.keep_steps,
        record: animation.is_some(),
        path_interval_s: Some(crate::animation::PATH_SAMPLE_INTERVAL_S),
        floor,
    };
    let (q, qd) = walker.unpack(&ideal.fixed_point);
    let walk = walk_with_firmware(
        &walker,
        (&q, &qd),
        &stride_settings,
        &mut ctl,
        &plan,
        (args.realtime, !common.json),
    );
    let firmware = ctl.finish().map_err(|e| match candump_error(candump, e) {
        // Only the log's flush can fail here: not bad input.
        InputError::Other(m) => anyhow::anyhow!(m),
        other => anyhow::Error::from(other),
    })?;
    if let Some(file) = animation {
        file.write(&Animation {
            scene: &scene,
            walker: &walker,
            walk: &walk,
            command: "sil",
            events: walk_and_firmware_events(&walk, &firmware),
            firmware: true,
            emergency_stop_sent_s: sil::walk::emergency_stop_sent_s(&firmware),
        })?;
    }
    let warnings = sil::scene_profile::profile_mismatches(&reflex, &firmware.nodes);
    for w in &warnings {
        output::note(format_args!("warning: {w}"));
    }
    let ran = SilRun {
        scene: scene.name(),
        walker: &walker,
        integrator: &stride_settings.integrator,
        ideal_walker: &ideal_setup.walker,
        ideal: (&ideal, source),
        walk: &walk,
        keep_steps: args.keep_steps,
        firmware: &firmware,
        firmware_params_written,
        warnings: &warnings,
        actuator: actuator_choice,
        floor,
    };
    write_report(&ran.report(), common.json, steps)?;
    Ok(walk_exit_code(&walk))
}

/// The library's bad input as the command's.
fn input(e: sil::walk::SilInputError) -> InputError {
    InputError::Other(e.0)
}

/// The walk's and the firmware's events in time order, for the animation.
fn walk_and_firmware_events(walk: &Walk, firmware: &sil::SilReport) -> Vec<timeline::Event> {
    let mut events = timeline::walk_events(walk);
    events.extend(timeline::firmware_events(firmware));
    events.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
    events
}

/// The options checked in order: the actuator's name, the number of steps, the emergency
/// stop's time (the library's checks, `sil::walk::check_options`), the pace against real
/// time. The actuator and the steps.
fn check_options(
    actuator: &str,
    steps: usize,
    estop_at: Option<f64>,
    realtime: Option<f64>,
) -> Result<(sil::ActuatorChoice, usize), InputError> {
    let checked = sil::walk::check_options(actuator, steps, estop_at).map_err(input)?;
    if let Some(r) = realtime {
        limits::within("--realtime", r, &limits::REALTIME_RANGE)?;
    }
    Ok(checked)
}

/// The ideal-actuator gait with the scene's own (accurate) integrator (the walk with the
/// firmware uses `sil::SIL_INTEGRATOR`, DOPRI5 at 1e-6, at most one step per 1 ms control
/// tick, unless an integrator is given on the command line), by the one gait rule (what
/// `walker gait` reports at these values), with where it came from; `None`, said on standard
/// error, when there is none to start from.
fn ideal_gait(
    scene: &sim::scene::Scene,
    common: &Common,
) -> Result<Option<(Setup, Gait, GaitSource)>> {
    let ideal_setup = scene.setup()?;
    let own_integrator = |s: &sim::scene::Scene| s.setup();
    let found = search_progress::rule_gait(common, &own_integrator, scene)?;
    match found {
        Ok((g, source)) => Ok(Some((ideal_setup, g, source))),
        Err(e) => {
            output::note(format_args!(
                "error: no ideal-actuator gait to start from: {e}"
            ));
            Ok(None)
        }
    }
}

/// How long to wait for a socketcand client: only with a socketcand server.
fn wait_client_timeout(
    wait_client: Option<f64>,
    serving: bool,
) -> Result<Option<std::time::Duration>, InputError> {
    match wait_client {
        None => Ok(None),
        Some(_) if !serving => Err(InputError::Other(
            "--wait-client needs --socketcand ADDR".to_owned(),
        )),
        Some(w) => Ok(Some(
            sil::wait_client_timeout(w).map_err(InputError::Other)?,
        )),
    }
}

/// The firmware in the loop's configuration from the options (the firmware's own parameters
/// unless some are written; the bus's and the encoders' faults, the candump log and the
/// socketcand address) and the parameters written, by name [SI units].
fn sil_config(
    actuator_choice: sil::ActuatorChoice,
    args: &SilArgs,
) -> Result<(sil::config::SilConfig, BTreeMap<&'static str, f64>), InputError> {
    let specs = sil::walk::Specs {
        firmware_params: &args.firmware_params,
        faults: &args.faults,
        sensor_faults: &args.sensor_faults,
    };
    let (mut config, firmware_params_written) =
        sil::walk::config_from_specs(actuator_choice, specs).map_err(input)?;
    if args.socketcand_allow_send && args.socketcand.is_none() {
        return Err(InputError::Other(
            "--socketcand-allow-send needs --socketcand ADDR".to_owned(),
        ));
    }
    if let Some(addr) = &args.socketcand {
        let parsed: std::net::SocketAddr = addr
            .parse()
            .map_err(|_| InputError::Other(format!("--socketcand `{addr}`: expected IP:PORT")))?;
        if !parsed.ip().is_loopback() {
            return Err(InputError::Other(format!(
                "--socketcand `{addr}`: only loopback addresses are served"
            )));
        }
    }
    config.candump = args.candump.clone();
    config.socketcand = args.socketcand.clone();
    config.socketcand_allow_send = args.socketcand_allow_send;
    Ok((config, firmware_params_written))
}

/// The firmware in the loop, built from `config` (its errors are about the configuration
/// given: fault nodes, log path, address), the emergency stop scheduled, the socketcand
/// server announced and, when asked, a client waited for.
fn start_firmware(
    config: sil::config::SilConfig,
    candump: &Option<std::path::PathBuf>,
    estop_at: Option<f64>,
    wait_client: Option<std::time::Duration>,
) -> Result<sil::FirmwareInTheLoop, InputError> {
    let allows_send = config.socketcand_allow_send;
    let mut ctl = sil::FirmwareInTheLoop::new(config).map_err(|e| candump_error(candump, e))?;
    if let Some(t) = estop_at {
        ctl.emergency_stop_at(t);
    }
    if let Some(addr) = ctl.socketcand_addr() {
        output::note(format_args!(
            "socketcand: serving the bus on {addr} (channel vcan0, {})",
            if allows_send {
                "clients may send frames: --socketcand-allow-send"
            } else {
                "read-only"
            }
        ));
    }
    if let Some(timeout) = wait_client {
        output::note(format_args!(
            "socketcand: waiting up to {} s for a client",
            timeout.as_secs_f64()
        ));
        match ctl.wait_for_socketcand_client(timeout) {
            Some(true) => output::note(format_args!(
                "socketcand: client connected; the walk starts"
            )),
            _ => output::note(format_args!(
                "socketcand: no client within {} s; the walk starts without one",
                timeout.as_secs_f64()
            )),
        }
    }
    Ok(ctl)
}

/// The walk with the firmware (`sil::walk::walk_with_firmware`), paced to real time when
/// `realtime` says so, with a progress bar when `show_progress`.
fn walk_with_firmware(
    walker: &sim::engine::walker::Walker,
    start: (&nalgebra::DVector<f64>, &nalgebra::DVector<f64>),
    stride_settings: &sim::stride::StrideSettings,
    ctl: &mut sil::FirmwareInTheLoop,
    plan: &WalkPlan,
    (realtime, show_progress): (Option<f64>, bool),
) -> Walk {
    let progress = Progress::after(
        PROGRESS_DELAY,
        plan.steps,
        "sil walk (steps)",
        show_progress,
    );
    let mut tick = |_: &StepSummary| progress.tick();
    let walk = match realtime {
        None => sil::walk::walk_with_firmware(
            walker,
            start,
            stride_settings,
            ctl,
            plan,
            Some(&mut tick),
        ),
        Some(factor) => {
            // Step by step, sleeping so that walk time keeps pace with wall time.
            let started = std::time::Instant::now();
            let mut paced = sim::engine::control::Paced::new(ctl, factor, started);
            sil::walk::walk_with_firmware(
                walker,
                start,
                stride_settings,
                &mut paced,
                plan,
                Some(&mut tick),
            )
        }
    };
    progress.finish();
    walk
}

/// The report as JSON or as text.
fn write_report(report: &SilWalkReport<'_>, json: bool, steps: usize) -> Result<()> {
    if json {
        print_json(report)?;
    } else {
        output::text(|out| print_text(out, report, steps))?;
    }
    Ok(())
}

/// An error of the firmware in the loop's set-up as bad input; a candump log's error names
/// the `--candump` path.
fn candump_error(candump: &Option<std::path::PathBuf>, e: sil::SilError) -> InputError {
    match (e, candump) {
        (sil::SilError::Candump(io), Some(path)) => {
            InputError::Other(PathError::new("--candump", path, io).to_string())
        }
        (e, _) => input(sil::walk::setup_error(&e)),
    }
}

fn print_text(out: &mut dyn Write, r: &SilWalkReport<'_>, steps: usize) -> std::io::Result<()> {
    match r.emergency_stop_sent_s {
        None => writeln!(
            out,
            "scene {}: {} of {steps} steps with the firmware actuating",
            r.scene, r.steps_completed
        )?,
        Some(t) => {
            writeln!(
                out,
                "scene {}: {} of {steps} steps, {} of them with the firmware actuating before the emergency stop",
                r.scene, r.steps_completed, r.steps_before_emergency_stop
            )?;
            writeln!(out, "{}", labels::emergency_stop_label(t))?;
        }
    }
    if let Some(floor) = r.floor.describe() {
        writeln!(out, "floor: {floor}")?;
    }
    if let Some(f) = r.failure {
        writeln!(out, "failure: {}", failure_text(f))?;
        match &r.fall_cause {
            Some(c) => writeln!(
                out,
                "cause: {:?} node raised {} (detail {}) at t = {:.4} s, {:.4} s before the failure",
                c.side, c.code, c.detail, c.t_s, c.before_failure_s
            )?,
            None => writeln!(
                out,
                "cause: no node raised a safety-relevant fault before it"
            )?,
        }
    }
    let before_stop = if r.emergency_stop_sent_s.is_some() {
        " before the emergency stop"
    } else {
        ""
    };
    match &r.gait {
        Some(g) => {
            writeln!(
                out,
                "firmware's gait, mean over the last {} steps{before_stop}:",
                g.steps_averaged
            )?;
            GaitFigures::of_walk(g, true).write(out, "    ")?;
        }
        None => writeln!(out, "firmware's gait: no step completed{before_stop}")?,
    }
    writeln!(
        out,
        "ideal actuator's gait (max |λ| = {:.6}):",
        shown(r.ideal_gait.max_abs_eigenvalue)
    )?;
    writeln!(out, "    start: {}", r.start.describe())?;
    GaitFigures::of_ideal(&r.ideal_gait).write(out, "    ")?;
    for (side, n) in r.nodes {
        let p = &n.parameters;
        let shown_opt =
            |v: Option<f64>| v.map_or_else(|| "not reported".to_owned(), |v| v.to_string());
        writeln!(
            out,
            "{side:?} node reports: taut {} rad, extended {} rad, push {} s (effective {} s)",
            shown_opt(p.taut_angle_rad),
            shown_opt(p.extended_angle_rad),
            shown_opt(p.push_duration_s),
            shown_opt(p.effective_push_duration_s)
        )?;
    }
    writeln!(
        out,
        "bus load {:.2} %, {} frames, {} node fault events",
        100.0 * r.bus_load,
        r.frames,
        r.node_faults.len()
    )
}
