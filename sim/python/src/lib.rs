//! The `walker._walker` extension module: the simulator's scenes, gaits, walks and walks with
//! the firmware in the loop for Python.
//!
//! Each function runs the same library calls as the `walker` command and hands back the same
//! report (`sim::report`), converted from its JSON form into Python dicts and lists, plus numpy
//! arrays where the data is numeric and large (a walk's path). The pure-Python package
//! `walker` (python/walker/) wraps these into objects with numpy arrays and pandas tables;
//! users import `walker`, not this module.
//!
//! Long computations run with the GIL released, stop on Ctrl-C and report their progress to a
//! Python callable (the `interrupt` module).

// pyo3's macros expand to `unsafe` blocks (the CPython ABI); this crate writes none itself.
#![allow(unsafe_code)]

mod basin;
mod convert;
mod errors;
mod gait;
mod gaits;
mod interrupt;
mod optimize;
mod orbit_diagram;
mod quantity;
mod refused;
mod robustness;
mod scene;
mod sil_walk;
mod stability_map;
mod sweep;
mod walk;

use pyo3::prelude::*;

/// The extension module `walker._walker`.
#[pymodule]
fn _walker(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<scene::PyScene>()?;
    m.add_function(wrap_pyfunction!(scene::scenes, m)?)?;
    m.add_function(wrap_pyfunction!(scene::_restore_scene, m)?)?;
    m.add_function(wrap_pyfunction!(gait::gait, m)?)?;
    m.add_function(wrap_pyfunction!(walk::walk, m)?)?;
    m.add_function(wrap_pyfunction!(gaits::gaits, m)?)?;
    m.add_function(wrap_pyfunction!(sweep::sweep, m)?)?;
    m.add_function(wrap_pyfunction!(orbit_diagram::orbit_diagram, m)?)?;
    m.add(
        "MAX_ORBIT_POINTS",
        sim::analysis::orbit_diagram::MAX_ORBIT_POINTS,
    )?;
    m.add_function(wrap_pyfunction!(stability_map::stability_map, m)?)?;
    m.add_function(wrap_pyfunction!(robustness::robustness, m)?)?;
    m.add_function(wrap_pyfunction!(basin::basin, m)?)?;
    m.add_function(wrap_pyfunction!(optimize::optimize, m)?)?;
    m.add_function(wrap_pyfunction!(optimize::optimize_evaluate, m)?)?;
    m.add_function(wrap_pyfunction!(quantity::check_quantity, m)?)?;
    m.add(
        "MAX_OPTIMIZE_EVALUATIONS",
        sim::report::MAX_OPTIMIZE_EVALUATIONS,
    )?;
    m.add(
        "DEFAULT_INITIAL_STEP",
        sim::analysis::optimize::INITIAL_STEP,
    )?;
    m.add(
        "MAX_BASIN_CELL_STRIDES",
        sim::analysis::robustness::MAX_BASIN_CELL_STRIDES,
    )?;
    m.add("MAX_MAP_CELLS", sim::analysis::stability_map::MAX_MAP_CELLS)?;
    m.add(
        "DEFAULT_GAIT_STRIDE_BUDGET",
        sim::analysis::homotopy::DEFAULT_GAIT_STRIDE_BUDGET,
    )?;
    m.add("MAX_WALK_STEPS", sim::stride::walk::MAX_WALK_STEPS)?;
    m.add("DEFAULT_PATH_SAMPLES", walk::DEFAULT_PATH_SAMPLES)?;
    m.add("MAX_PATH_SAMPLES", walk::MAX_PATH_SAMPLES)?;
    m.add_function(wrap_pyfunction!(sil_walk::sil, m)?)?;
    m.add_function(wrap_pyfunction!(sil_walk::dbc, m)?)?;
    m.add("DEFAULT_SIL_FRAMES", sil_walk::DEFAULT_SIL_FRAMES)?;
    m.add("MAX_SIL_FRAMES", sil_walk::MAX_SIL_FRAMES)?;
    Ok(())
}
