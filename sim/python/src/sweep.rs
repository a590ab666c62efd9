//! `walker.sweep`: the gait followed over one parameter by continuation, as
//! `walker sweep --json` reports it.

use crate::convert;
use crate::errors;
use crate::interrupt;
use crate::scene::PyScene;
use pyo3::prelude::*;
use sim::analysis::continuation::{
    continuation, ContinuationSettings, SweepError, MAX_SWEEP_PERIOD, MAX_SWEEP_POINTS,
};
use sim::report::SweepReport;
use sim::stride::SearchBudget;
use std::sync::Arc;

/// The gait of `scene` followed as `param` (name or alias) goes from `start` to `end` at
/// `points` points, through folds, with its bifurcations located and the period-doubled
/// branches followed up to `max_period` strides per cycle: the `walker sweep --json` object
/// as a dict (`points`, `stability_boundaries`, `branches`, `branch_ends`, ...). Without the
/// GIL; the continuation has no cancel hook, so Ctrl-C raises `KeyboardInterrupt` when the
/// sweep ends. Raises `walker.SceneError` or `walker.InputError`.
#[pyfunction]
#[pyo3(signature = (scene, param, start, end, points, *, max_period = None))]
pub fn sweep<'py>(
    py: Python<'py>,
    scene: &PyScene,
    param: &str,
    start: f64,
    end: f64,
    points: &Bound<'py, PyAny>,
    max_period: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let points = convert::count_in(py, points, "points", (2, MAX_SWEEP_POINTS))?;
    let max_period = match max_period {
        Some(m) => convert::count_in(py, m, "max_period", (1, MAX_SWEEP_PERIOD))?,
        None => 1,
    };
    let (solver, scene) = (&scene.solver, &scene.inner);
    if !(start.is_finite() && end.is_finite()) || start == end {
        return Err(errors::input_error(
            py,
            &format!("start and end must be two different finite numbers, got {start} and {end}"),
        ));
    }
    // The scene's integrator options apply at every parameter value, as the command's do.
    let overridden =
        solver.integrator.is_some() || solver.rtol.is_some() || solver.step_s.is_some();
    let stride_settings = if overridden {
        let mut setup = scene.setup().map_err(|e| errors::scene_error(py, &e))?;
        solver
            .configure(&mut setup.settings)
            .map_err(|e| errors::input_error(py, &e.to_string()))?;
        Some(setup.settings)
    } else {
        None
    };
    let settings = ContinuationSettings::builder()
        .newton(solver.newton())
        .max_period(max_period)
        .stride_settings(stride_settings)
        .build()
        .map_err(|e| errors::input_error(py, &e.to_string()))?;
    let nothing_to_cancel = Arc::new(SearchBudget::new(usize::MAX));
    let result = interrupt::run(py, &[&nothing_to_cancel], || {
        continuation(scene, param, (start, end, points), &settings, &|_| {})
    })?
    .map_err(|e| match e {
        SweepError::Scene(s) => errors::scene_error(py, &s),
        other => errors::input_error(py, &other.to_string()),
    })?;
    convert::report(py, &SweepReport::from_continuation(&result))
}
