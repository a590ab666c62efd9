//! `walker.gait`: the gait `walker gait` finds, as its `--json` report.

use crate::convert;
use crate::errors;
use crate::interrupt;
use crate::scene::PyScene;
use pyo3::prelude::*;
use sim::analysis::homotopy::{GaitRule, GaitSource, HomotopySettings};
use sim::analysis::limit_cycle::{Gait, NewtonError};
use sim::analysis::solver_options::SolverOptions;
use sim::report::GaitReport;
use sim::scene::{Scene, SceneError, Setup};
use sim::stride::{SearchBudget, SharedBudget};
use std::sync::Arc;

/// Builds a scene's setup with the numerical options `solver` (`Scene.with_solver`; the
/// defaults: the scene's own integrator, as `walker` does without options), for the library's
/// studies (`sim::analysis::homotopy::SetupFor`), its strides taken from `budget` (a gait rule
/// puts its own in their place). Once `budget` is cancelled (Ctrl-C) its strides fail at once
/// and every later setup is refused, so a study stops at its next stride or search (a stability
/// map's cells, the rule's homotopy steps).
pub fn setup_for<'a>(
    solver: &'a SolverOptions,
    budget: &'a Arc<SearchBudget>,
) -> impl Fn(&Scene) -> Result<Setup, SceneError> + Sync + 'a {
    move |s: &Scene| {
        if budget.is_cancelled() {
            return Err(SceneError::Invalid("interrupted (Ctrl-C)".to_owned()));
        }
        let mut setup = s.setup()?;
        // Checked when the options were set (`Scene.with_solver`): a refusal here is a value
        // the study visits that the options do not suit.
        solver
            .configure(&mut setup.settings)
            .map_err(|e| SceneError::Invalid(e.to_string()))?;
        setup.settings.search_budget = SharedBudget(Some(Arc::clone(budget)));
        Ok(setup)
    }
}

/// `f` of the one gait rule (`sim::analysis::homotopy::GaitRule`) as `walker gait` applies it
/// with the options `solver`: each scene built by [`setup_for`], `solver`'s Newton settings,
/// every stride taken from `budget`.
pub fn with_rule<T>(
    solver: &SolverOptions,
    budget: &Arc<SearchBudget>,
    f: impl FnOnce(&GaitRule<'_>) -> T,
) -> T {
    let setup_for = setup_for(solver, budget);
    let newton = solver.newton();
    let homotopy = HomotopySettings {
        gait_stride_budget: budget.limit_strides(),
        ..solver.homotopy()
    };
    f(&GaitRule::new(&setup_for, &newton, &homotopy).with_budget(Arc::clone(budget)))
}

/// The gait of `scene` by [`with_rule`]'s rule, and where it came from.
///
/// # Errors
/// The scene cannot be built at the values the rule visits.
pub fn rule_gait(
    scene: &Scene,
    solver: &SolverOptions,
    budget: &Arc<SearchBudget>,
) -> Result<Result<(Gait, GaitSource), NewtonError>, SceneError> {
    with_rule(solver, budget, |rule| rule.gait(scene))
}

/// The `walker gait --json` report of `scene`'s gait search (found or not).
///
/// # Errors
/// The scene cannot be built.
pub fn report(
    scene: &Scene,
    solver: &SolverOptions,
    budget: &Arc<SearchBudget>,
) -> Result<GaitReport, SceneError> {
    let sourced = rule_gait(scene, solver, budget)?;
    let setup = setup_for(solver, budget)(scene)?;
    let source = sourced.as_ref().ok().map(|(_, s)| *s);
    let (mut report, _) = GaitReport::of_setup(&setup, scene, &sourced.map(|(g, _)| g), false);
    report.gait_source = source;
    Ok(report)
}

/// The gait search's stride budget: `max_strides` (a count from 1 on) if given, else the
/// scene's solver options' (`Scene.with_solver(max_strides=)`).
///
/// # Errors
/// `walker.InputError`: not an integer from 1 on.
pub fn search_budget(
    py: Python<'_>,
    max_strides: Option<&Bound<'_, PyAny>>,
    solver: &SolverOptions,
) -> PyResult<Arc<SearchBudget>> {
    let strides = match max_strides {
        Some(m) => convert::count_in(py, m, "max_strides", (1, usize::MAX))?,
        None => solver.max_strides,
    };
    Ok(Arc::new(SearchBudget::new(strides)))
}

/// The gait of `scene`: the `walker gait --json` object as a dict (with `jacobian` and
/// `eigenvectors`). The search may take at most `max_strides` strides. Runs without the GIL;
/// Ctrl-C stops it. Raises `walker.SceneError`, `walker.GaitNotFound` or
/// `walker.StrideFailed` (a stride of the search failed).
#[pyfunction]
#[pyo3(signature = (scene, *, max_strides = None))]
pub fn gait<'py>(
    py: Python<'py>,
    scene: &PyScene,
    max_strides: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let budget = search_budget(py, max_strides, &scene.solver)?;
    let (solver, scene) = (&scene.solver, &scene.inner);
    let report = interrupt::run(py, &[&budget], || report(scene, solver, &budget))?
        .map_err(|e| errors::scene_error(py, &e))?;
    let dict = convert::report(py, &report)?;
    if matches!(report.outcome, sim::report::GaitOutcome::NotFound(_)) {
        return Err(errors::gait_not_found(py, &dict));
    }
    Ok(dict)
}
