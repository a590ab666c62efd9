//! `walker.gaits`: every period-1 gait of a scene, as `walker gaits --json` lists them.

use crate::convert;
use crate::errors;
use crate::gait::setup_for;
use crate::interrupt::{self, Counter};
use crate::scene::PyScene;
use pyo3::prelude::*;
use sim::analysis::census::{census_units, census_with_progress, CensusSettings};
use sim::analysis::solver_options::SolverOptions;
use sim::report::{GaitReport, GaitsReport};
use sim::scene::{Scene, SceneError};
use sim::stride::SearchBudget;
use std::sync::Arc;

/// The `walker gaits --json` report of `scene`; every stride of the census taken from
/// `cancel` (unlimited, there to stop it).
fn report(
    scene: &Scene,
    solver: &SolverOptions,
    cancel: &Arc<SearchBudget>,
    counter: &Counter,
) -> Result<GaitsReport, SceneError> {
    let found = census_with_progress(
        scene,
        &setup_for(solver, cancel),
        &solver.newton(),
        &CensusSettings::default(),
        &|| counter.tick(),
    )?;
    let setup = setup_for(solver, cancel)(scene)?;
    Ok(GaitsReport {
        scene: scene.name().to_string(),
        gaits: found
            .gaits
            .into_iter()
            .map(|g| GaitReport::of_setup(&setup, scene, &Ok(g), false).0)
            .collect(),
        searches: found.searches,
    })
}

/// Every distinct period-1 gait of `scene`, longest step period first: the
/// `walker gaits --json` object as a dict (`gaits`, each as `walker.gait`'s report but without
/// `gait_source`; `searches`). No gait gives an empty list (the command's exit code 1). Runs
/// without the GIL; Ctrl-C stops it; `progress(done, total)`, if given, hears of the Newton
/// searches done. Raises `walker.SceneError`.
#[pyfunction]
#[pyo3(signature = (scene, *, progress = None))]
pub fn gaits<'py>(
    py: Python<'py>,
    scene: &PyScene,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let cancel = Arc::new(SearchBudget::new(usize::MAX));
    let (solver, scene) = (&scene.solver, &scene.inner);
    let counter = Counter::new(census_units(scene, &CensusSettings::default()), progress);
    let report = interrupt::run_counted(py, &[&cancel], &counter, || {
        report(scene, solver, &cancel, &counter)
    })?
    .map_err(|e| errors::scene_error(py, &e))?;
    convert::report(py, &report)
}
