//! `walker.sil`: a walk with the ankle firmware in the loop, as `walker sil --json` reports
//! it (the report built by the library, `sil::walk`, as the command builds it), with the
//! run's bus frames (what `walker sil --candump` would log) as numpy arrays.

use crate::convert;
use crate::errors;
use crate::gait::{rule_gait, search_budget, setup_for};
use crate::interrupt;
use crate::refused::Refused;
use crate::scene::PyScene;
use ::sil::walk::{SilRun, Specs, WalkPlan};
use ::sil::FrameLog;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sim::analysis::solver_options::SolverOptions;
use sim::report::GaitReport;
use sim::scene::Scene;
use sim::stride::walk::MAX_WALK_STEPS;
use sim::stride::{Floor, SearchBudget, SharedBudget};
use std::sync::Arc;

/// Bus frames `walker.sil` keeps by default: a million (about 30 MB; the nominal `wisse3d`
/// walk puts a few hundred frames a second on the bus).
pub const DEFAULT_SIL_FRAMES: usize = 1_000_000;

/// Most bus frames `walker.sil(max_frames=...)` may ask for.
pub const MAX_SIL_FRAMES: usize = 10_000_000;

impl From<::sil::walk::SilInputError> for Refused {
    fn from(e: ::sil::walk::SilInputError) -> Self {
        Refused::Input(e.0)
    }
}

/// The arguments of one SIL walk.
struct Request {
    steps: usize,
    actuator: ::sil::ActuatorChoice,
    faults: Vec<String>,
    sensor_faults: Vec<String>,
    firmware_params: Vec<String>,
    estop_at: Option<f64>,
    keep_steps: Option<usize>,
    floor: Floor,
    max_frames: usize,
}

/// The walk's report (the `walker sil --json` object) and its frames.
struct Ran {
    report: serde_json::Value,
    frames: FrameLog,
}

/// Walks up to `steps` strides of `scene` with the ankle firmware in the loop, as
/// `walker sil --json` does, and returns `(report, frames)`: `report` is the command's JSON
/// object as a dict, `frames` a dict of numpy arrays of the bus events the run logged (as
/// `--candump` writes them, the first `max_frames`): `time_ns` (bus clock), `id`, `dlc`,
/// `data` (n × 8 bytes), `error` (an error frame or bus-off), with `not_kept` (events past
/// `max_frames`). Runs without the GIL; Ctrl-C stops it at the next step. A fall is no error.
/// Raises `walker.InputError` (the command's message), `walker.SceneError`,
/// `walker.GaitNotFound` or `walker.StrideFailed` (no ideal-actuator gait to start from).
#[pyfunction]
#[pyo3(signature = (scene, steps, *, faults = Vec::new(), sensor_faults = Vec::new(), firmware_params = Vec::new(), actuator = "servo", estop_at = None, floor = "plane", keep_steps = None, max_strides = None, max_frames = None))]
#[allow(clippy::too_many_arguments)]
pub fn sil<'py>(
    py: Python<'py>,
    scene: &PyScene,
    steps: &Bound<'py, PyAny>,
    faults: Vec<String>,
    sensor_faults: Vec<String>,
    firmware_params: Vec<String>,
    actuator: &str,
    estop_at: Option<f64>,
    floor: &str,
    keep_steps: Option<&Bound<'py, PyAny>>,
    max_strides: Option<&Bound<'py, PyAny>>,
    max_frames: Option<&Bound<'py, PyAny>>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyDict>)> {
    // A count too large is refused by the library's check (the command's message); one that
    // is negative or not an integer, which the command cannot be given, here.
    let steps = match steps
        .extract::<i64>()
        .ok()
        .and_then(|v| usize::try_from(v).ok())
    {
        Some(n) => n,
        None => convert::count_in(py, steps, "steps", (0, MAX_WALK_STEPS))?,
    };
    let keep_steps = keep_steps
        .map(|k| convert::count_in(py, k, "keep_steps", (0, usize::MAX)))
        .transpose()?;
    let max_frames = match max_frames {
        Some(m) => convert::count_in(py, m, "max_frames", (0, MAX_SIL_FRAMES))?,
        None => DEFAULT_SIL_FRAMES,
    };
    let (actuator, steps) = ::sil::walk::check_options(actuator, steps, estop_at)
        .map_err(|e| errors::input_error(py, &e.0))?;
    let floor: Floor = floor
        .parse()
        .map_err(|e: sim::stride::FloorError| errors::input_error(py, &e.to_string()))?;
    let request = Request {
        steps,
        actuator,
        faults,
        sensor_faults,
        firmware_params,
        estop_at,
        keep_steps,
        floor,
        max_frames,
    };
    let search = search_budget(py, max_strides, &scene.solver)?;
    // The walk's own strides are not limited; this budget only stops them on Ctrl-C.
    let walking = Arc::new(SearchBudget::new(usize::MAX));
    let (solver, scene) = (&scene.solver, &scene.inner);
    let ran = interrupt::run(py, &[&search, &walking], || {
        run(scene, solver, &request, (&search, &walking))
    })?;
    let ran = ran.map_err(|r| r.into_py_err(py))?;
    Ok((
        convert::value_to_py(py, &ran.report)?,
        frames(py, &ran.frames)?,
    ))
}

/// The walk, without the GIL: the same stages as `walker sil` without options other than
/// these (the scene's setup, the ideal-actuator gait by the one gait rule, the firmware, the
/// walk with `sil::SIL_INTEGRATOR`, the report).
fn run(
    scene: &Scene,
    solver: &SolverOptions,
    r: &Request,
    (search, walking): (&Arc<SearchBudget>, &Arc<SearchBudget>),
) -> Result<Ran, Refused> {
    let actuator_choice = r.actuator;
    let setup = setup_for(solver, walking)(scene).map_err(Refused::Scene)?;
    let walker = &setup.walker;
    let reflex = ::sil::walk::require_ankle(walker, scene.name())?;
    let specs = Specs {
        firmware_params: &r.firmware_params,
        faults: &r.faults,
        sensor_faults: &r.sensor_faults,
    };
    let (config, firmware_params_written) = ::sil::walk::config_from_specs(actuator_choice, specs)?;
    // The ideal-actuator gait with the scene's own (accurate) integrator and the options'
    // Newton settings, as `walker sil` finds it whatever its integrator options.
    let own_integrator = SolverOptions {
        integrator: None,
        step_s: None,
        rtol: None,
        ..solver.clone()
    };
    let ideal_setup = setup_for(&own_integrator, search)(scene).map_err(Refused::Scene)?;
    let (ideal, source) = match rule_gait(scene, &own_integrator, search).map_err(Refused::Scene)? {
        Ok(found) => found,
        Err(e) => {
            let report = GaitReport::new(scene, walker, &setup.settings.integrator, &Err(e), None);
            return Err(Refused::NoGait(Box::new(report)));
        }
    };
    // The SIL integrator unless the scene's options chose one (`Scene.with_solver`), as
    // `walker sil` without --integrator, --rtol or --step-s.
    let chosen = solver.integrator.is_some() || solver.rtol.is_some() || solver.step_s.is_some();
    let mut settings = ::sil::walk::walk_settings(&setup.settings, chosen);
    settings.search_budget = SharedBudget(Some(Arc::clone(walking)));
    let mut ctl =
        ::sil::FirmwareInTheLoop::new(config).map_err(|e| ::sil::walk::setup_error(&e))?;
    if let Some(t) = r.estop_at {
        ctl.emergency_stop_at(t);
    }
    ctl.keep_frames(r.max_frames);
    let plan = WalkPlan {
        steps: r.steps,
        keep_steps: r.keep_steps,
        record: false,
        path_interval_s: None,
        floor: r.floor,
    };
    let (q, qd) = walker.unpack(&ideal.fixed_point);
    let walk = ::sil::walk::walk_with_firmware(walker, (&q, &qd), &settings, &mut ctl, &plan, None);
    let frames = ctl.take_frame_log().unwrap_or_default();
    // No candump log to flush, no server to stop: finishing cannot fail.
    let firmware = ctl.finish().map_err(|e| Refused::Input(e.to_string()))?;
    let warnings = ::sil::scene_profile::profile_mismatches(&reflex, &firmware.nodes);
    let report = SilRun {
        scene: scene.name(),
        walker,
        integrator: &settings.integrator,
        ideal_walker: &ideal_setup.walker,
        ideal: (&ideal, source),
        walk: &walk,
        keep_steps: r.keep_steps,
        firmware: &firmware,
        firmware_params_written,
        warnings: &warnings,
        actuator: actuator_choice,
        floor: r.floor,
    }
    .report();
    let report = sim::report::to_json(&report).map_err(|e| Refused::Input(e.to_string()))?;
    Ok(Ran { report, frames })
}

/// The frames kept as numpy arrays.
fn frames<'py>(py: Python<'py>, log: &FrameLog) -> PyResult<Bound<'py, PyDict>> {
    let f = &log.frames;
    let d = PyDict::new(py);
    d.set_item(
        "time_ns",
        PyArray1::from_vec(py, f.iter().map(|x| x.t_ns).collect()),
    )?;
    d.set_item(
        "id",
        PyArray1::from_vec(py, f.iter().map(|x| x.id).collect()),
    )?;
    d.set_item(
        "dlc",
        PyArray1::from_vec(py, f.iter().map(|x| x.dlc).collect()),
    )?;
    d.set_item(
        "error",
        PyArray1::from_vec(py, f.iter().map(|x| x.error).collect()),
    )?;
    let data = Array2::from_shape_vec((f.len(), 8), f.iter().flat_map(|x| x.data).collect())
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(format!("sil frames: {e}")))?;
    d.set_item("data", data.into_pyarray(py))?;
    d.set_item("not_kept", log.not_kept)?;
    d.set_item("max_frames", log.max_frames)?;
    Ok(d)
}

/// The project's DBC file (`protocol::dbc::render`, what `protocol/walker.dbc` holds): the
/// bus's messages and signals, for `cantools.database.load_string`.
#[pyfunction]
pub fn dbc() -> String {
    protocol::dbc::render()
}
