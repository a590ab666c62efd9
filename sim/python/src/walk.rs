//! `walker.walk`: a walk of many strides, as `walker walk --json` reports it, with its path
//! (every integration sample, or one per `path_interval_s`) as numpy arrays.

use crate::convert;
use crate::errors;
use crate::gait::{search_budget, setup_for, with_rule};
use crate::interrupt;
use crate::refused::Refused;
use crate::scene::PyScene;
use nalgebra::DVector;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use sim::analysis::limit_cycle::NewtonError;
use sim::analysis::solver_options::SolverOptions;
use sim::analysis::walk_start::{self as walk_start, GaitStart};
use sim::engine::walker::Walker;
use sim::report::{GaitReport, StartRecord, WalkReport};
use sim::scene::Scene;
use sim::scene::SceneError;
use sim::stride::walk::{Walk, WalkRequest, MAX_WALK_STEPS};
use sim::stride::{Floor, SearchBudget, SharedBudget};
use std::sync::Arc;

/// Where a walk starts.
enum Start {
    /// The gait's fixed point.
    Gait,
    /// The scene's guess.
    Guess,
}

/// Where a walk starts and how it is perturbed.
struct StartSpec {
    kind: Start,
    /// Entries of the start replaced (`--start-state`).
    state: Vec<(String, f64)>,
    /// Entries of the start perturbed (`--perturb`).
    perturb: Vec<(String, f64)>,
}

/// A finished walk and what it started from.
struct Walked {
    report: WalkReport,
    walk: Walk,
    coordinates: Vec<String>,
}

/// Path samples `walker.walk` keeps by default: a million (about 170 MB for the 3D walker's
/// eight coordinates and rates), past which the path stops and `Walk.path_cut_at_time_s` says
/// where (the walk goes on). A default-step compass walk of 100,000 steps would keep 2.7
/// million.
pub const DEFAULT_PATH_SAMPLES: usize = 1_000_000;

/// Most path samples `walker.walk(max_path_samples=...)` may ask for (about 1.7 GB for the
/// 3D walker).
pub const MAX_PATH_SAMPLES: usize = 10_000_000;

/// Walks `steps` strides of `scene` and returns `(report, path)`: `report` is the
/// `walker walk --json` object as a dict (`steps`, `failure`, `start`, `floor`...), `path`
/// a dict of numpy arrays: `time_s` (n), `step` (n, 0-based), `q` and `qdot` (n × coordinates,
/// each sample in its step's stance labelling), `hip_floor_m` (n × 3, the hip in the floor
/// frame), and `coordinates` (the column names of `q`). `start` is `"gait"` (the gait's
/// fixed point), `"guess"` (the scene's guess) or a dict `{stride-map entry: value}` that
/// replaces entries of the gait's fixed point (as `--start-state`); `perturb` adds
/// `{entry: delta}` to the start; `floor` is `plane`, `step:at=K,height_m=H` or
/// `rough:sigma_m=S[,seed=N]`. Runs without the GIL; Ctrl-C stops it. A fall is no error:
/// the report's `failure` says how. Raises `walker.InputError`, `walker.SceneError`,
/// `walker.GaitNotFound` or `walker.StrideFailed` (no gait to start from).
#[pyfunction]
#[pyo3(signature = (scene, steps, *, start = None, perturb = None, floor = "plane", path_interval_s = None, max_strides = None, max_path_samples = None))]
#[allow(clippy::too_many_arguments)]
pub fn walk<'py>(
    py: Python<'py>,
    scene: &PyScene,
    steps: &Bound<'py, PyAny>,
    start: Option<&Bound<'py, PyAny>>,
    perturb: Option<&Bound<'py, PyDict>>,
    floor: &str,
    path_interval_s: Option<f64>,
    max_strides: Option<&Bound<'py, PyAny>>,
    max_path_samples: Option<&Bound<'py, PyAny>>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyDict>)> {
    let steps = convert::count_in(py, steps, "steps", (0, MAX_WALK_STEPS))?;
    let max_path_samples = match max_path_samples {
        Some(m) => convert::count_in(py, m, "max_path_samples", (1, MAX_PATH_SAMPLES))?,
        None => DEFAULT_PATH_SAMPLES,
    };
    let floor: Floor = floor
        .parse()
        .map_err(|e: sim::stride::FloorError| errors::input_error(py, &e.to_string()))?;
    if let Some(dt) = path_interval_s {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(errors::input_error(
                py,
                &format!("path_interval_s must be a positive number of seconds, got {dt}"),
            ));
        }
    }
    let (kind, state) = start_of(py, start)?;
    let spec = StartSpec {
        kind,
        state,
        perturb: entries(perturb)?,
    };
    let search = search_budget(py, max_strides, &scene.solver)?;
    // The walk's own strides are not limited; this budget only stops them on Ctrl-C.
    let walking = Arc::new(SearchBudget::new(usize::MAX));
    let (solver, scene) = (&scene.solver, &scene.inner);
    let walked = interrupt::run(py, &[&search, &walking], || {
        run(
            scene,
            solver,
            steps,
            spec,
            floor,
            (path_interval_s, max_path_samples),
            (&search, &walking),
        )
    })?;
    let walked = walked.map_err(|r| r.into_py_err(py))?;
    Ok((convert::report(py, &walked.report)?, path(py, &walked)?))
}

/// `start` as a kind and the entries it sets.
fn start_of(
    py: Python<'_>,
    start: Option<&Bound<'_, PyAny>>,
) -> PyResult<(Start, Vec<(String, f64)>)> {
    let Some(start) = start else {
        return Ok((Start::Gait, Vec::new()));
    };
    if let Ok(text) = start.cast::<PyString>() {
        return match text.to_str()? {
            "gait" => Ok((Start::Gait, Vec::new())),
            "guess" => Ok((Start::Guess, Vec::new())),
            other => Err(errors::input_error(
                py,
                &format!(
                    "start `{other}`: expected \"gait\", \"guess\" or a dict of stride-map entries"
                ),
            )),
        };
    }
    match start.cast::<PyDict>() {
        Ok(d) => Ok((Start::Gait, entries(Some(d))?)),
        Err(_) => Err(errors::input_error(
            py,
            "start: expected \"gait\", \"guess\" or a dict of stride-map entries",
        )),
    }
}

/// A dict `{name: number}` as pairs.
fn entries(d: Option<&Bound<'_, PyDict>>) -> PyResult<Vec<(String, f64)>> {
    d.into_iter()
        .flat_map(|d| d.iter())
        .map(|(k, v)| Ok((k.extract()?, v.extract()?)))
        .collect()
}

/// The walk, without the GIL.
fn run(
    scene: &Scene,
    solver: &SolverOptions,
    steps: usize,
    spec: StartSpec,
    floor: Floor,
    (path_interval_s, max_path_samples): (Option<f64>, usize),
    (search, walking): (&Arc<SearchBudget>, &Arc<SearchBudget>),
) -> Result<Walked, Refused> {
    let setup = setup_for(solver, walking)(scene).map_err(Refused::Scene)?;
    let walker = &setup.walker;
    let (mut v, record) = match spec.kind {
        Start::Guess => (
            walker.pack(&setup.guess.q, &setup.guess.qd),
            StartRecord::guess(scene.name()),
        ),
        Start::Gait => gait_start(scene, solver, walker, search)
            .map_err(Refused::Scene)?
            .map_err(|e| {
                let report =
                    GaitReport::new(scene, walker, &setup.settings.integrator, &Err(e), None);
                Refused::NoGait(Box::new(report))
            })?,
    };
    let names = walker.map_names();
    let index = |name: &str, what: &str| {
        names.iter().position(|n| n == name).ok_or_else(|| {
            Refused::Input(format!(
                "{what} `{name}`: not an entry of the stride map (entries: {})",
                names.join(", ")
            ))
        })
    };
    let finite = |x: f64, name: &str, what: &str| {
        if x.is_finite() {
            Ok(x)
        } else {
            Err(Refused::Input(format!(
                "{what} `{name}`: {x} is not a finite number"
            )))
        }
    };
    for (name, x) in &spec.state {
        v[index(name, "start")?] = finite(*x, name, "start")?;
    }
    for (name, d) in &spec.perturb {
        let i = index(name, "perturb")?;
        v[i] += finite(*d, name, "perturb")?;
    }
    let (q, qd) = walker.unpack(&v);
    let mut settings = setup.settings.clone();
    settings.search_budget = SharedBudget(Some(Arc::clone(walking)));
    let mut request = WalkRequest::new(&settings, steps)
        .floor(floor)
        .recording(true)
        .max_path_samples(max_path_samples);
    if let Some(dt) = path_interval_s {
        request = request.path_interval(dt);
    }
    let walk = sim::stride::walk::walk(walker, &q, &qd, request);
    let mut report = WalkReport::new(scene, &walk);
    report.start = Some(record);
    report.floor = floor;
    let coordinates = walker
        .model()
        .coordinates
        .iter()
        .map(|c| c.name.clone())
        .collect();
    Ok(Walked {
        report,
        walk,
        coordinates,
    })
}

/// The start from the scene's gait as `walker walk` takes it
/// ([`sim::analysis::walk_start::gait_start`]): its own gait, or when it has none that of the
/// scene it names to start from (the report's `start` names it). When neither has one, the
/// error is the scene's own search's (the `GaitNotFound` report is this scene's).
fn gait_start(
    scene: &Scene,
    solver: &SolverOptions,
    walker: &Walker,
    budget: &Arc<SearchBudget>,
) -> Result<Result<(DVector<f64>, StartRecord), NewtonError>, SceneError> {
    with_rule(solver, budget, |rule| {
        Ok(match walk_start::gait_start(scene, walker, rule)? {
            GaitStart::Own { gait, source } => {
                let record = StartRecord::gait(scene.name(), &gait, source);
                Ok((gait.fixed_point, record))
            }
            GaitStart::Other { start, .. } => {
                let record = StartRecord::gait(start.scene.name(), &start.gait, start.source);
                Ok((start.state, record))
            }
            GaitStart::None { own, .. } => Err(own),
        })
    })
}

/// The walk's path as numpy arrays.
fn path<'py>(py: Python<'py>, walked: &Walked) -> PyResult<Bound<'py, PyDict>> {
    let samples = &walked.walk.path;
    let (n, dof) = (samples.len(), walked.coordinates.len());
    let shape_error = |e: numpy::ndarray::ShapeError| {
        pyo3::exceptions::PyRuntimeError::new_err(format!("walk path: {e}"))
    };
    let matrix = |width: usize, row: &dyn Fn(&sim::stride::walk::PathSample) -> Vec<f64>| {
        let data: Vec<f64> = samples.iter().flat_map(row).collect();
        Array2::from_shape_vec((n, width), data).map_err(shape_error)
    };
    let d = PyDict::new(py);
    d.set_item(
        "time_s",
        PyArray1::from_vec(py, samples.iter().map(|s| s.t_walk_s).collect()),
    )?;
    d.set_item(
        "step",
        PyArray1::from_vec(py, samples.iter().map(|s| s.step as u64).collect()),
    )?;
    d.set_item(
        "q",
        matrix(dof, &|s| s.q.iter().copied().collect())?.into_pyarray(py),
    )?;
    d.set_item(
        "qdot",
        matrix(dof, &|s| s.qd.iter().copied().collect())?.into_pyarray(py),
    )?;
    d.set_item(
        "hip_floor_m",
        matrix(3, &|s| s.hip_floor_m.iter().copied().collect())?.into_pyarray(py),
    )?;
    d.set_item("coordinates", &walked.coordinates)?;
    d.set_item("cut_at_time_s", walked.walk.path_cut_t_walk_s)?;
    Ok(d)
}
