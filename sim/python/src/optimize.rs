//! `walker.optimize`: CMA-ES over the scene's parameters for an objective of its gait, as
//! `walker optimize --json` reports it (the same library report,
//! [`sim::report::OptimizeReport`]).

use crate::convert;
use crate::errors;
use crate::gait::setup_for;
use crate::interrupt::{self, Counter};
use crate::scene::PyScene;
use pyo3::prelude::*;
use sim::analysis::optimize::INITIAL_STEP;
use sim::report::{OptimizeOptionError, OptimizeOptions, OptimizeReport, MAX_OPTIMIZE_EVALUATIONS};
use sim::stride::SearchBudget;
use std::sync::Arc;

/// The refusal as a Python exception: `walker.SceneError` (with the scene error's fields) for a
/// parameter problem, else `walker.InputError`, each option spelled as its keyword.
fn option_error(py: Python<'_>, e: &OptimizeOptionError) -> PyErr {
    let message = e.message(&|name| name.to_owned());
    match e.scene_error() {
        Some(s) => errors::scene_error_with_message(py, &message, s),
        None => errors::input_error(py, &message),
    }
}

/// CMA-ES over `scene`'s parameters: the `walker optimize --json` object as a dict. `vary`:
/// the ranges `NAME=MIN:MAX`; `objective`: `gsn`, `max_abs_eigenvalue`, `cost_of_transport`,
/// `step_down` or `mfpt` (with `sigma_m`); `constraints`: `NAME<=V` or `NAME>=V`; `budget`
/// candidates evaluated exactly (1 to 10,000), the scene's design once more; `seed` of the
/// draws; `initial_step` normalised. The scene's solver options apply as the command's.
/// `progress(done, total)`, if given, hears of the `budget + 1` evaluations. Runs without the
/// GIL on every core; Ctrl-C stops it at the next gait search. Raises `walker.InputError`,
/// `walker.SceneError` (an unknown parameter, a range outside the parameter's).
#[pyfunction]
#[pyo3(signature = (
    scene, vary, objective, *, constraints = Vec::new(), budget = None, seed = None,
    initial_step = INITIAL_STEP, sigma_m = None, progress = None
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
) -> PyResult<Bound<'py, PyAny>> {
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
    let (solver, scene) = (&scene.solver, &scene.inner);
    let request = options.request(scene).map_err(|e| option_error(py, &e))?;
    let cancel = Arc::new(SearchBudget::new(usize::MAX));
    let counter = Counter::new(request.budget + 1, progress);
    let report = interrupt::run_counted(py, &[&cancel], &counter, || {
        OptimizeReport::run(
            scene,
            &request,
            &setup_for(solver, &cancel),
            &solver.newton(),
            &solver.homotopy(),
            &|| counter.tick(),
        )
        .map_err(Box::new)
    })?
    .map_err(|e| option_error(py, &e))?;
    convert::report(py, &report)
}
