//! `walker.stability_map`: the largest |eigenvalue| of the scene's gait over a grid of two
//! parameters, as `walker stability-map --json` reports it.

use crate::convert;
use crate::errors;
use crate::gait::setup_for;
use crate::interrupt::{self, Counter};
use crate::quantity;
use crate::scene::PyScene;
use pyo3::prelude::*;
use sim::analysis::stability_map::{stability_map_of, Axis, MAX_MAP_CELLS};
use sim::report::StabilityMapReport;
use sim::stride::SearchBudget;
use std::sync::Arc;

/// The gait (as `walker.gait` finds it) at every cell of the grid `x` × `y`, each a pair
/// `(parameter name or alias, values)`: the `walker stability-map --json` object as a dict
/// (`x`, `y`: name and values; `max_abs_eigenvalue`, `stable`, `step_period_s`,
/// `gait_source`, `no_gait_reason`: grids indexed `[j][i]` for `y.values[j]`, `x.values[i]`,
/// `None` where there is no gait). `quantity` also maps a robustness measure or another number
/// of each cell's gait (`walker stability-map --quantity`; `mfpt` with `sigma_m`): the dict's
/// `quantity`. `progress(done, total)`, if given, hears of the cells done. Uses every core,
/// without the GIL; Ctrl-C stops it at the next gait search. Raises `walker.SceneError` (an
/// unknown parameter, a value out of range) or `walker.InputError` (the same parameter twice,
/// an empty axis, more than `MAX_MAP_CELLS` cells, an unknown quantity, `sigma_m` without
/// `mfpt`).
#[pyfunction]
#[pyo3(signature = (scene, x, y, *, quantity = None, sigma_m = None, progress = None))]
pub fn stability_map<'py>(
    py: Python<'py>,
    scene: &PyScene,
    x: (String, Vec<f64>),
    y: (String, Vec<f64>),
    quantity: Option<String>,
    sigma_m: Option<f64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let (quantity, options) = quantity::choose(py, quantity.as_deref(), sigma_m)?;
    let (solver, scene) = (&scene.solver, &scene.inner);
    let axis = |(name, values): (String, Vec<f64>)| -> PyResult<Axis> {
        Ok(Axis {
            name: scene
                .parameter_name(&name)
                .map_err(|e| errors::scene_error(py, &e))?,
            values,
        })
    };
    let (x, y) = (axis(x)?, axis(y)?);
    if x.name == y.name {
        return Err(errors::input_error(
            py,
            &format!(
                "x and y both vary `{}`: give two different parameters",
                x.name
            ),
        ));
    }
    let cells = x.values.len() * y.values.len();
    if !(1..=MAX_MAP_CELLS).contains(&cells) {
        return Err(errors::input_error(
            py,
            &format!("the map must have between 1 and {MAX_MAP_CELLS} cells, got {cells}"),
        ));
    }
    let cancel = Arc::new(SearchBudget::new(usize::MAX));
    let counter = Counter::new(cells, progress);
    let map = interrupt::run_counted(py, &[&cancel], &counter, || {
        stability_map_of(
            scene,
            &setup_for(solver, &cancel),
            &x,
            &y,
            &solver.newton(),
            &solver.homotopy(),
            quantity.map(|q| (q, &options)),
            &|| counter.tick(),
        )
    })?
    .map_err(|e| errors::scene_error(py, &e))?;
    let report = match quantity {
        Some(q) => StabilityMapReport::with_quantity(scene.name(), &x, &y, &map, q, &options),
        None => StabilityMapReport::new(scene.name(), &x, &y, &map),
    };
    convert::report(py, &report)
}
