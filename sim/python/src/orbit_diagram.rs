//! `walker.orbit_diagram`: the attractor of the stride map at each value of one parameter, as
//! `walker orbit-diagram --json` reports it.

use crate::convert;
use crate::errors;
use crate::gait::setup_for;
use crate::interrupt;
use crate::scene::PyScene;
use pyo3::prelude::*;
use sim::analysis::orbit_diagram::{
    orbit_diagram as diagram, OrbitError, OrbitSettings, MAX_ORBIT_POINTS,
};
use sim::report::OrbitDiagramReport;
use sim::stride::SearchBudget;
use std::sync::Arc;

/// The stride map iterated at each of `values` of parameter `param` (name or alias), each
/// value starting from the last one's attractor: the `walker orbit-diagram --json` object as
/// a dict (`param`, `points`: per value its `attractor` — periodic, chaotic or fell —,
/// `period_strides`, `samples` by name, `failure`; `settings`). Uses every core, without the
/// GIL; Ctrl-C stops it. Raises `walker.SceneError` or `walker.InputError` (fewer than 2 or
/// more than `MAX_ORBIT_POINTS` values, a value that is not finite).
#[pyfunction]
pub fn orbit_diagram<'py>(
    py: Python<'py>,
    scene: &PyScene,
    param: &str,
    values: Vec<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let (solver, scene) = (&scene.solver, &scene.inner);
    let param = scene
        .parameter_name(param)
        .map_err(|e| errors::scene_error(py, &e))?;
    if !(2..=MAX_ORBIT_POINTS).contains(&values.len()) {
        return Err(errors::input_error(
            py,
            &format!(
                "values: an orbit diagram needs between 2 and {MAX_ORBIT_POINTS} values, got {}",
                values.len()
            ),
        ));
    }
    if let Some(v) = values.iter().find(|v| !v.is_finite()) {
        return Err(errors::input_error(
            py,
            &format!("values: {v} is not a finite number"),
        ));
    }
    let settings = OrbitSettings {
        chunk_points: OrbitSettings::default().chunk_points.min(values.len()),
        ..OrbitSettings::default()
    };
    let cancel = Arc::new(SearchBudget::new(usize::MAX));
    let found = interrupt::run(py, &[&cancel], || {
        diagram(
            scene,
            &setup_for(solver, &cancel),
            &param,
            &values,
            &solver.newton(),
            &settings,
            &|| {},
        )
    })?;
    let found = found.map_err(|e| match e {
        OrbitError::Scene(s) => errors::scene_error(py, &s),
        other => errors::input_error(py, &other.to_string()),
    })?;
    let setup = setup_for(solver, &cancel)(scene).map_err(|e| errors::scene_error(py, &e))?;
    convert::report(
        py,
        &OrbitDiagramReport::new(scene, &setup.walker, &param, &found, &settings),
    )
}
