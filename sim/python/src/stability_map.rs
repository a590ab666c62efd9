//! `walker.stability_map`: the largest |eigenvalue| of the scene's gait over a grid of two
//! parameters, as `walker stability-map --json` reports it.

use crate::convert;
use crate::errors;
use crate::gait::setup_for;
use crate::interrupt;
use crate::scene::PyScene;
use pyo3::prelude::*;
use sim::analysis::homotopy::HomotopySettings;
use sim::analysis::limit_cycle::NewtonSettings;
use sim::analysis::stability_map::{stability_map_of, Axis, MAX_MAP_CELLS};
use sim::report::StabilityMapReport;
use sim::stride::SearchBudget;
use std::sync::Arc;

/// The gait (as `walker.gait` finds it) at every cell of the grid `x` × `y`, each a pair
/// `(parameter name or alias, values)`: the `walker stability-map --json` object as a dict
/// (`x`, `y`: name and values; `max_abs_eigenvalue`, `stable`, `step_period_s`,
/// `gait_source`, `no_gait_reason`: grids indexed `[j][i]` for `y.values[j]`, `x.values[i]`,
/// `None` where there is no gait). Uses every core, without the GIL; Ctrl-C stops it at the
/// next gait search. Raises `walker.SceneError` (an unknown parameter, a value out of range)
/// or `walker.InputError` (the same parameter twice, an empty axis, more than
/// `MAX_MAP_CELLS` cells).
#[pyfunction]
pub fn stability_map<'py>(
    py: Python<'py>,
    scene: &PyScene,
    x: (String, Vec<f64>),
    y: (String, Vec<f64>),
) -> PyResult<Bound<'py, PyAny>> {
    let scene = &scene.inner;
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
    let map = interrupt::run(py, &[&cancel], || {
        stability_map_of(
            scene,
            &setup_for(&cancel),
            &x,
            &y,
            &NewtonSettings::default(),
            &HomotopySettings::default(),
            None,
            &|| {},
        )
    })?
    .map_err(|e| errors::scene_error(py, &e))?;
    convert::report(py, &StabilityMapReport::new(scene.name(), &x, &y, &map))
}
