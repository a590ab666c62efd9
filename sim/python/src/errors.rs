//! Errors as the Python exceptions of `walker._errors` (`WalkerError` and its subclasses,
//! defined in Python so that they carry docstrings and fields): the message is the one the
//! `walker` command prints after `error:`, and the fields are the values the Rust error holds.

use pyo3::prelude::*;
use sim::scene::SceneError;

/// An exception's attributes: name and value.
type Fields<'py> = Vec<(&'static str, Bound<'py, PyAny>)>;

/// An exception of class `class` (in `walker._errors`) with `message` and, as attributes,
/// `fields`. Should the class itself be unavailable, that import error is what comes back.
pub fn raise(
    py: Python<'_>,
    class: &str,
    message: &str,
    fields: &[(&str, Bound<'_, PyAny>)],
) -> PyErr {
    let built = || -> PyResult<PyErr> {
        let exception = py
            .import("walker._errors")?
            .getattr(class)?
            .call1((message,))?;
        for (name, value) in fields {
            exception.setattr(*name, value)?;
        }
        Ok(PyErr::from_value(exception))
    };
    built().unwrap_or_else(|e| e)
}

/// Bad input other than a scene's: a count out of its bounds, an unknown coordinate or
/// option value (`walker.InputError`, also a `ValueError`).
pub fn input_error(py: Python<'_>, message: &str) -> PyErr {
    raise(py, "InputError", message, &[])
}

/// A scene that cannot be loaded or built, or a parameter that cannot be set
/// (`walker.SceneError`), with `kind` and the values the error names.
pub fn scene_error(py: Python<'_>, e: &SceneError) -> PyErr {
    let message = e.to_string();
    let fields = match scene_error_fields(py, e) {
        Ok(f) => f,
        Err(err) => return err,
    };
    raise(py, "SceneError", &message, &fields)
}

/// [`scene_error`] with another message (the option that gave the value, then the scene's
/// refusal).
pub fn scene_error_with_message(py: Python<'_>, message: &str, e: &SceneError) -> PyErr {
    match scene_error_fields(py, e) {
        Ok(fields) => raise(py, "SceneError", message, &fields),
        Err(err) => err,
    }
}

fn scene_error_fields<'py>(py: Python<'py>, e: &SceneError) -> PyResult<Fields<'py>> {
    let s = |x: &str| x.into_pyobject(py).map(|o| o.into_any());
    let f = |x: f64| x.into_pyobject(py).map(|o| o.into_any());
    Ok(match e {
        SceneError::UnknownScene { name, available } => vec![
            ("kind", s("unknown_scene")?),
            ("name", s(name)?),
            ("available", s(available)?),
        ],
        SceneError::File { path, message } => vec![
            ("kind", s("file")?),
            ("path", s(path)?),
            ("detail", s(message)?),
        ],
        SceneError::UnknownParameter {
            scene,
            name,
            available,
        } => vec![
            ("kind", s("unknown_parameter")?),
            ("scene", s(scene)?),
            ("name", s(name)?),
            ("available", s(available)?),
        ],
        SceneError::NotANumber { name, value } => vec![
            ("kind", s("not_a_number")?),
            ("name", s(name)?),
            ("value", s(value)?),
        ],
        SceneError::OutOfRange {
            name,
            value,
            unit,
            min,
            max,
        } => vec![
            ("kind", s("out_of_range")?),
            ("name", s(name)?),
            ("value", f(*value)?),
            ("unit", s(unit)?),
            ("min", f(*min)?),
            ("max", f(*max)?),
        ],
        _ => vec![("kind", s("invalid")?)],
    })
}

/// A gait search that found no gait: `walker.StrideFailed` when a stride of it failed (the
/// report's `failure`), else `walker.GaitNotFound`; either carries the report (`report`, the
/// CLI's `--json` object with `converged: false`), `newton_iterations` and `failure`.
pub fn gait_not_found(py: Python<'_>, report: &Bound<'_, PyAny>) -> PyErr {
    let fields = || -> PyResult<(String, Fields<'_>)> {
        let message: String = report.get_item("error")?.extract()?;
        let failure = report
            .get_item("failure")
            .unwrap_or_else(|_| py.None().into_bound(py));
        let iterations = report.get_item("newton_iterations")?;
        Ok((
            message,
            vec![
                ("report", report.clone()),
                ("failure", failure),
                ("newton_iterations", iterations),
            ],
        ))
    };
    match fields() {
        Ok((message, fields)) => {
            let class = if fields[1].1.is_none() {
                "GaitNotFound"
            } else {
                "StrideFailed"
            };
            raise(py, class, &message, &fields)
        }
        Err(e) => e,
    }
}
