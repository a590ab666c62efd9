//! `walker.basin`: a slice of the basin of attraction of the gait `walker.gait` finds, as
//! `walker basin --json` reports it (the same library report, [`sim::report::BasinReport`]).

use crate::convert;
use crate::errors;
use crate::gait::{rule_gait, search_budget, setup_for};
use crate::interrupt::{self, Counter};
use crate::refused::Refused;
use crate::scene::PyScene;
use pyo3::prelude::*;
use sim::analysis::robustness::{
    basin_axes, basin_slice, BasinAxis, BasinError, Recovery, ReturnRule, MAX_BASIN_CELL_STRIDES,
};
use sim::analysis::stability_map::MAX_MAP_CELLS;
use sim::report::{BasinReport, GaitReport};
use sim::stride::SearchBudget;
use std::sync::Arc;

/// The basin slice of `scene`'s gait over the stride-map coordinates `x` and `y`, each
/// `(name, values)`: the `walker basin --json` object as a dict. Each cell may take `strides`
/// strides to return. `progress(done, total)`, if given, hears of the cells done. Runs
/// without the GIL on every core; Ctrl-C stops it. Raises `walker.InputError` (an unknown or
/// repeated coordinate, an empty axis, more than `MAX_MAP_CELLS` cells, `strides` out of
/// range), `walker.SceneError`, `walker.GaitNotFound` / `walker.StrideFailed` (no gait).
#[pyfunction]
#[pyo3(signature = (scene, x, y, *, strides = None, max_strides = None, progress = None))]
pub fn basin<'py>(
    py: Python<'py>,
    scene: &PyScene,
    x: (String, Vec<f64>),
    y: (String, Vec<f64>),
    strides: Option<&Bound<'py, PyAny>>,
    max_strides: Option<&Bound<'py, PyAny>>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let strides = match strides {
        Some(v) => convert::count_in(py, v, "strides", (1, MAX_BASIN_CELL_STRIDES))?,
        None => ReturnRule::default().max_strides,
    };
    let (x, y) = (
        BasinAxis {
            name: x.0,
            values: x.1,
        },
        BasinAxis {
            name: y.0,
            values: y.1,
        },
    );
    let cells = x.values.len().saturating_mul(y.values.len());
    if cells > MAX_MAP_CELLS {
        return Err(errors::input_error(
            py,
            &format!("the slice must have at most {MAX_MAP_CELLS} cells, got {cells}"),
        ));
    }
    if let Some(bad) = x.values.iter().chain(&y.values).find(|v| !v.is_finite()) {
        return Err(errors::input_error(
            py,
            &format!("an axis value must be a finite number, got {bad}"),
        ));
    }
    let search = search_budget(py, max_strides, &scene.solver)?;
    let (solver, scene) = (&scene.solver, &scene.inner);
    // The axes before the gait search: a wrong one fails at once.
    let setup = scene.setup().map_err(|e| errors::scene_error(py, &e))?;
    basin_axes(&setup.walker, &x, &y)
        .map_err(|e| errors::input_error(py, &basin_message(scene.name(), e)))?;
    let measuring = Arc::new(SearchBudget::new(usize::MAX));
    let counter = Counter::new(cells, progress);
    let report = interrupt::run_counted(py, &[&search, &measuring], &counter, || {
        let sourced = rule_gait(scene, solver, &search).map_err(Refused::Scene)?;
        let setup = setup_for(solver, &measuring)(scene).map_err(Refused::Scene)?;
        let source = sourced.as_ref().ok().map(|(_, s)| *s);
        let result = sourced.map(|(g, _)| g);
        let (mut gait_report, _) = GaitReport::of_setup(&setup, scene, &result, false);
        gait_report.gait_source = source;
        let Ok(gait) = &result else {
            return Err(Refused::NoGait(Box::new(gait_report)));
        };
        let rule = ReturnRule {
            max_strides: strides,
            ..ReturnRule::default()
        };
        let recovery = Recovery::new(&setup.walker, &setup.settings, gait).with_rule(rule);
        let slice = basin_slice(&recovery, x, y, &|| counter.tick())
            .map_err(|e| Refused::Input(basin_message(scene.name(), e)))?;
        Ok(BasinReport::new(scene.name(), &slice, rule, gait_report))
    })?;
    convert::report(py, &report.map_err(|r| r.into_py_err(py))?)
}

/// An axis refused, in words.
fn basin_message(scene: &str, e: BasinError) -> String {
    match e {
        BasinError::UnknownCoordinate { name, known } => {
            format!("`{name}` is not a stride-map coordinate of {scene} (it has: {known})")
        }
        BasinError::SameAxis(name) => {
            format!("x and y both slice `{name}`: give two different coordinates")
        }
        e @ BasinError::Empty(_) => e.to_string(),
    }
}
