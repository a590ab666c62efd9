//! `walker.optimize`: CMA-ES over the scene's parameters for an objective of its gait, as
//! `walker optimize --json` reports it (the same library report,
//! [`sim::report::OptimizeReport`]).

use crate::convert;
use crate::errors;
use crate::gait::setup_for;
use crate::interrupt::{self, Counter};
use crate::scene::PyScene;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyCFunction, PyDict, PyTuple};
use sim::analysis::optimize::{EvaluateDrawn, Evaluation, OptimizeError, INITIAL_STEP};
use sim::report::{
    OptimizeOptionError, OptimizeOptions, OptimizeReport, OptimizeRequest, MAX_OPTIMIZE_EVALUATIONS,
};
use sim::stride::SearchBudget;
use std::sync::{Arc, Mutex};

/// The refusal as a Python exception: `walker.SceneError` (with the scene error's fields) for a
/// parameter problem, else `walker.InputError`, each option spelled as its keyword.
fn option_error(py: Python<'_>, e: &OptimizeOptionError) -> PyErr {
    let message = e.message(&|name| name.to_owned());
    match e.scene_error() {
        Some(s) => errors::scene_error_with_message(py, &message, s),
        None => errors::input_error(py, &message),
    }
}

/// The request `walker optimize` would run for these arguments (each refused as the keyword
/// it came from).
#[allow(clippy::too_many_arguments)]
fn request(
    py: Python<'_>,
    scene: &PyScene,
    vary: Vec<String>,
    objective: String,
    constraints: Vec<String>,
    budget: Option<&Bound<'_, PyAny>>,
    seed: Option<&Bound<'_, PyAny>>,
    initial_step: f64,
    sigma_m: Option<f64>,
) -> PyResult<OptimizeRequest> {
    let defaults = OptimizeOptions::default();
    let budget = match budget {
        None => defaults.budget,
        Some(b) => {
            let value: i128 = b.extract().map_err(|_| {
                errors::input_error(
                    py,
                    &format!("budget must be an integer between 1 and {MAX_OPTIMIZE_EVALUATIONS}"),
                )
            })?;
            usize::try_from(value)
                .ok()
                .filter(|v| (1..=MAX_OPTIMIZE_EVALUATIONS).contains(v))
                .ok_or_else(|| {
                    option_error(
                        py,
                        &OptimizeOptionError::Count {
                            option: "budget",
                            value,
                            min: 1,
                            max: MAX_OPTIMIZE_EVALUATIONS,
                        },
                    )
                })?
        }
    };
    let seed = match seed {
        Some(v) => v.extract::<u64>().map_err(|_| {
            errors::input_error(py, "seed must be an integer between 0 and 2**64 - 1")
        })?,
        None => defaults.seed,
    };
    let options = OptimizeOptions {
        vary,
        objective,
        constraints,
        budget,
        seed,
        initial_step,
        sigma_m,
    };
    options
        .request(&scene.inner)
        .map_err(|e| option_error(py, &e))
}

/// CMA-ES over `scene`'s parameters: the `walker optimize --json` object as a dict. `vary`:
/// the ranges `NAME=MIN:MAX`; `objective`: `gsn`, `max_abs_eigenvalue`, `cost_of_transport`,
/// `step_down` or `mfpt` (with `sigma_m`); `constraints`: `NAME<=V` or `NAME>=V`; `budget`
/// candidates evaluated exactly (1 to 10,000), the scene's design once more; `seed` of the
/// draws; `initial_step` normalised. The scene's solver options apply as the command's.
/// `progress(done, total)`, if given, hears of the `budget + 1` evaluations. Runs without the
/// GIL on every core; Ctrl-C stops it at the next gait search. Raises `walker.InputError`,
/// `walker.SceneError` (an unknown parameter, a range outside the parameter's).
///
/// `evaluate`, if given, evaluates each generation's new candidates instead of this
/// process's threads (a cluster's workers: `walker.studies.optimize`): called as
/// `evaluate(designs, cancelled)` with the designs as a list of lists of floats (normalised
/// coordinates) and a callable that turns true once Ctrl-C or `progress` has stopped the
/// search, it returns one `bytes` per design, in order, as `optimize_evaluate` makes them for
/// the same arguments; an exception it raises ends the search and is raised here.
#[pyfunction]
#[pyo3(signature = (
    scene, vary, objective, *, constraints = Vec::new(), budget = None, seed = None,
    initial_step = INITIAL_STEP, sigma_m = None, progress = None, evaluate = None
))]
#[allow(clippy::too_many_arguments)]
pub fn optimize<'py>(
    py: Python<'py>,
    scene: &PyScene,
    vary: Vec<String>,
    objective: String,
    constraints: Vec<String>,
    budget: Option<&Bound<'py, PyAny>>,
    seed: Option<&Bound<'py, PyAny>>,
    initial_step: f64,
    sigma_m: Option<f64>,
    progress: Option<Py<PyAny>>,
    evaluate: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let request = request(
        py,
        scene,
        vary,
        objective,
        constraints,
        budget,
        seed,
        initial_step,
        sigma_m,
    )?;
    let solver = &scene.solver;
    let cancel = Arc::new(SearchBudget::new(usize::MAX));
    let counter = Counter::new(request.budget + 1, progress);
    // The exception `evaluate` raised, raised again once the search has stopped.
    let raised: Mutex<Option<PyErr>> = Mutex::new(None);
    let (counter_ref, raised_ref, cancel_ref) = (&counter, &raised, &cancel);
    let remote = evaluate.as_ref().map(|f| {
        move |drawn: &[Vec<f64>]| -> Result<Vec<Evaluation>, OptimizeError> {
            if cancel_ref.is_cancelled() {
                // Ctrl-C or the progress callable's exception: no more generations
                return Err(OptimizeError::Invalid("interrupted".to_owned()));
            }
            let answer = Python::attach(|py| -> PyResult<Vec<Vec<u8>>> {
                // `cancelled()`: whether Ctrl-C or the progress callable stopped the search,
                // for `evaluate` to stop waiting on its workers
                let budget = Arc::clone(cancel_ref);
                let cancelled = PyCFunction::new_closure(
                    py,
                    None,
                    None,
                    move |_args: &Bound<'_, PyTuple>, _kwargs: Option<&Bound<'_, PyDict>>| {
                        budget.is_cancelled()
                    },
                )?;
                f.call1(py, (drawn.to_vec(), cancelled))?.extract(py)
            });
            match answer {
                Ok(bytes) => {
                    let found = bytes
                        .iter()
                        .map(|b| Evaluation::from_cbor(b))
                        .collect::<Result<Vec<_>, _>>()?;
                    found.iter().for_each(|_| counter_ref.tick());
                    Ok(found)
                }
                Err(e) => {
                    if let Ok(mut slot) = raised_ref.lock() {
                        slot.get_or_insert(e);
                    }
                    Err(OptimizeError::Invalid(
                        "evaluate raised an exception".to_owned(),
                    ))
                }
            }
        }
    });
    let report = interrupt::run_counted(py, &[&cancel], &counter, || {
        OptimizeReport::run_with(
            &scene.inner,
            &request,
            &setup_for(solver, &cancel),
            &solver.newton(),
            &solver.homotopy(),
            &|| counter.tick(),
            remote.as_ref().map(|f| f as &EvaluateDrawn<'_>),
        )
        .map_err(Box::new)
    })?;
    if let Some(e) = raised.lock().ok().and_then(|mut slot| slot.take()) {
        return Err(e);
    }
    let report = report.map_err(|e| option_error(py, &e))?;
    convert::report(py, &report)
}

/// The evaluations of `drawn` (designs in normalised coordinates, a list of lists of floats)
/// for the search `optimize` runs with the same arguments: one `bytes` each, in order — the
/// task of a cluster's worker (`walker.studies.optimize`), a pure function of its arguments.
/// Runs without the GIL on every core the process allows; Ctrl-C stops it, as does an
/// exception of `progress(done, total)` (which is raised). Raises as `optimize`, and
/// `walker.InputError` for a design with another number of coordinates.
#[pyfunction]
#[pyo3(signature = (
    scene, vary, objective, drawn, *, constraints = Vec::new(), budget = None, seed = None,
    initial_step = INITIAL_STEP, sigma_m = None, progress = None
))]
#[allow(clippy::too_many_arguments)]
pub fn optimize_evaluate<'py>(
    py: Python<'py>,
    scene: &PyScene,
    vary: Vec<String>,
    objective: String,
    drawn: Vec<Vec<f64>>,
    constraints: Vec<String>,
    budget: Option<&Bound<'py, PyAny>>,
    seed: Option<&Bound<'py, PyAny>>,
    initial_step: f64,
    sigma_m: Option<f64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Vec<Py<PyBytes>>> {
    let request = request(
        py,
        scene,
        vary,
        objective,
        constraints,
        budget,
        seed,
        initial_step,
        sigma_m,
    )?;
    let solver = &scene.solver;
    let cancel = Arc::new(SearchBudget::new(usize::MAX));
    let counter = Counter::new(drawn.len(), progress);
    let found = interrupt::run_counted(py, &[&cancel], &counter, || {
        request
            .evaluate_drawn(
                &scene.inner,
                &drawn,
                &setup_for(solver, &cancel),
                &solver.newton(),
                &solver.homotopy(),
                &|| counter.tick(),
            )
            .map_err(Box::new)
    })?
    .map_err(|e| option_error(py, &e))?;
    Ok(found.iter().map(|b| PyBytes::new(py, b).unbind()).collect())
}
