//! `walker.sweep`: the gait followed over one parameter by continuation, as
//! `walker sweep --json` reports it.

use crate::convert;
use crate::errors;
use crate::gait::setup_for;
use crate::interrupt::{self, Counter};
use crate::quantity;
use crate::scene::PyScene;
use pyo3::prelude::*;
use sim::analysis::continuation::{
    continuation, ContinuationSettings, SweepError, MAX_SWEEP_PERIOD, MAX_SWEEP_POINTS,
};
use sim::report::SweepReport;
use sim::stride::{SearchBudget, SharedBudget};
use std::sync::Arc;

/// Resolution of the continuation's progress (it reports a fraction done), as the command's.
const PROGRESS_STEPS: usize = 1000;

/// The gait of `scene` followed as `param` (name or alias) goes from `start` to `end` at
/// `points` points, through folds, with its bifurcations located and the period-doubled
/// branches followed up to `max_period` strides per cycle: the `walker sweep --json` object
/// as a dict (`points`, `stability_boundaries`, `branches`, `branch_ends`, ...). Without the
/// GIL; Ctrl-C stops it at the next stride (the continuation's `search_budget`).
/// `quantity` (with `sigma_m` for `mfpt`) also measures a number of every period-1 gait
/// (`walker sweep --quantity`): each point's `quantity`. `progress(done, total)`, if given,
/// hears of the continuation's progress in thousandths, then of the points measured. Raises
/// `walker.SceneError` or `walker.InputError`.
#[pyfunction]
#[pyo3(signature = (scene, param, start, end, points, *, max_period = None, quantity = None, sigma_m = None, progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn sweep<'py>(
    py: Python<'py>,
    scene: &PyScene,
    param: &str,
    start: f64,
    end: f64,
    points: &Bound<'py, PyAny>,
    max_period: Option<&Bound<'py, PyAny>>,
    quantity: Option<String>,
    sigma_m: Option<f64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let (quantity, quantity_options) = quantity::choose(py, quantity.as_deref(), sigma_m)?;
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
    // Ctrl-C cancels this budget: every later stride of the sweep fails at once.
    let cancel = Arc::new(SearchBudget::new(usize::MAX));
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
        .search_budget(SharedBudget(Some(Arc::clone(&cancel))))
        .build()
        .map_err(|e| errors::input_error(py, &e.to_string()))?;
    let swept = Counter::new(PROGRESS_STEPS, progress.as_ref().map(|p| p.clone_ref(py)));
    let result = interrupt::run_counted(py, &[&cancel], &swept, || {
        continuation(scene, param, (start, end, points), &settings, &|fraction| {
            swept.set((fraction * PROGRESS_STEPS as f64) as usize);
        })
    })?
    .map_err(|e| match e {
        SweepError::Scene(s) => errors::scene_error(py, &s),
        other => errors::input_error(py, &other.to_string()),
    })?;
    let mut report = SweepReport::from_continuation(&result);
    if let Some(q) = quantity {
        let measured = Counter::new(SweepReport::measured_points(&result), progress);
        interrupt::run_counted(py, &[&cancel], &measured, || {
            report.measure(
                &result,
                (q, &quantity_options),
                &setup_for(solver, &cancel),
                &solver.newton(),
                &|| measured.tick(),
            )
        })?;
    }
    convert::report(py, &report)
}
