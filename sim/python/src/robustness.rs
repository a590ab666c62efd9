//! `walker.robustness`: how much disturbance the gait `walker.gait` finds survives, as
//! `walker robustness --json` reports it (the same library report,
//! [`sim::report::RobustnessReport`]).

use crate::convert;
use crate::errors;
use crate::gait::{rule_gait, search_budget, setup_for};
use crate::interrupt::{self, Counter};
use crate::scene::PyScene;
use pyo3::prelude::*;
use sim::analysis::robustness::FirstPassageOptions;
use sim::report::{
    GaitOutcome, Measures, RobustnessOptions, RobustnessReport, MAX_MFPT_RUNS, MAX_MFPT_STRIDES,
    MAX_RETURN_STRIDES,
};
use sim::stride::SearchBudget;
use std::sync::Arc;

/// The robustness measures of `scene`'s gait: the `walker robustness --json` object as a dict.
/// Options as the command's (`measures`: names from `gsn`, `steps`, `rates`, `mfpt`;
/// `sigma_m`: roughness values, default 0.001, 0.003 and 0.01 leg lengths). `progress`, if
/// given, is called as `progress(done, total)` with the stages done. Runs without the GIL on
/// every core; Ctrl-C stops it. Raises `walker.InputError` (an option out of its range),
/// `walker.SceneError`, `walker.GaitNotFound` / `walker.StrideFailed` (no gait).
#[pyfunction]
#[pyo3(signature = (
    scene, *, measures = None, sigma_m = None, mfpt_runs = None, mfpt_strides = None,
    mfpt_seed = None, rate_scan_step = 1e-2, return_strides = None, max_strides = None,
    progress = None
))]
#[allow(clippy::too_many_arguments)]
pub fn robustness<'py>(
    py: Python<'py>,
    scene: &PyScene,
    measures: Option<Vec<String>>,
    sigma_m: Option<Vec<f64>>,
    mfpt_runs: Option<&Bound<'py, PyAny>>,
    mfpt_strides: Option<&Bound<'py, PyAny>>,
    mfpt_seed: Option<&Bound<'py, PyAny>>,
    rate_scan_step: f64,
    return_strides: Option<&Bound<'py, PyAny>>,
    max_strides: Option<&Bound<'py, PyAny>>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let defaults = RobustnessOptions::default();
    let count = |v: Option<&Bound<'py, PyAny>>, name: &str, max: usize, default: usize| match v {
        Some(v) => convert::count_in(py, v, name, (1, max)),
        None => Ok(default),
    };
    let seed = match mfpt_seed {
        Some(v) => v.extract::<u64>().map_err(|_| {
            errors::input_error(py, "mfpt_seed must be an integer between 0 and 2**64 - 1")
        })?,
        None => defaults.first_passage.seed,
    };
    let option_error = |e: sim::report::RobustnessOptionError| {
        errors::input_error(py, &e.message(&|name| name.to_owned()))
    };
    let options = RobustnessOptions {
        measures: match &measures {
            Some(names) => {
                Measures::from_names(names.iter().map(String::as_str)).map_err(option_error)?
            }
            None => Measures::default(),
        },
        sigma_m: match sigma_m {
            Some(v) if v.is_empty() => {
                return Err(errors::input_error(
                    py,
                    "sigma_m: give at least one roughness [m], or None for 0.001, 0.003 and \
                     0.01 leg lengths",
                ))
            }
            v => v.unwrap_or_default(),
        },
        first_passage: FirstPassageOptions {
            runs: count(
                mfpt_runs,
                "mfpt_runs",
                MAX_MFPT_RUNS,
                defaults.first_passage.runs,
            )?,
            strides_per_run: count(
                mfpt_strides,
                "mfpt_strides",
                MAX_MFPT_STRIDES,
                defaults.first_passage.strides_per_run,
            )?,
            seed,
        },
        rate_scan_step,
        return_strides: count(
            return_strides,
            "return_strides",
            MAX_RETURN_STRIDES,
            defaults.return_strides,
        )?,
        perturbation: scene.solver.perturbation,
    };
    options.check().map_err(option_error)?;
    let search = search_budget(py, max_strides, &scene.solver)?;
    let measuring = Arc::new(SearchBudget::new(usize::MAX));
    let (solver, scene) = (&scene.solver, &scene.inner);
    let counter = Counter::new(RobustnessReport::stages(&options), progress);
    let report = interrupt::run_counted(py, &[&search, &measuring], &counter, || {
        let sourced = rule_gait(scene, solver, &search)?;
        let setup = setup_for(solver, &measuring)(scene)?;
        Ok(RobustnessReport::measure(
            &setup,
            scene,
            sourced,
            &options,
            &|| counter.tick(),
        ))
    })?
    .map_err(|e| errors::scene_error(py, &e))?;
    let dict = convert::report(py, &report)?;
    if matches!(report.gait.outcome, GaitOutcome::NotFound(_)) {
        return Err(errors::gait_not_found(py, &dict.get_item("gait")?));
    }
    Ok(dict)
}
