//! Why a computation run without the GIL gave no result, turned into the Python exception once
//! the GIL is back: a scene that cannot be built, bad input found during the work, or no gait
//! to start from (with its report).

use crate::convert;
use crate::errors;
use pyo3::prelude::*;
use sim::report::GaitReport;
use sim::scene::SceneError;

/// What the work returned instead of its result.
pub enum Refused {
    /// A scene that cannot be loaded or built (`walker.SceneError`).
    Scene(SceneError),
    /// Bad input, by its message (`walker.InputError`).
    Input(String),
    /// No gait to start from (`walker.GaitNotFound` / `walker.StrideFailed` with the report).
    NoGait(Box<GaitReport>),
}

impl Refused {
    /// The Python exception.
    pub fn into_py_err(self, py: Python<'_>) -> PyErr {
        match self {
            Refused::Scene(e) => errors::scene_error(py, &e),
            Refused::Input(m) => errors::input_error(py, &m),
            Refused::NoGait(report) => match convert::report(py, &*report) {
                Ok(dict) => errors::gait_not_found(py, &dict),
                Err(e) => e,
            },
        }
    }
}

impl From<SceneError> for Refused {
    fn from(e: SceneError) -> Self {
        Refused::Scene(e)
    }
}
