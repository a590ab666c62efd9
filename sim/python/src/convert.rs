//! Reports into Python objects: a report's JSON form (`sim::report::to_json`, the CLI's
//! `--json`) as dicts, lists, floats, ints, strings and `None`, so that Python reads the very
//! numbers and keys the CLI prints.

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use serde::Serialize;
use serde_json::Value;

/// A count argument `name` as a `usize` within `min..=max`, or `walker.InputError` naming the
/// range (a negative, huge or non-integer value included: Python's own conversion would say
/// "can't convert negative int to unsigned" or "int too large").
pub fn count_in(
    py: Python<'_>,
    value: &Bound<'_, PyAny>,
    name: &str,
    (min, max): (usize, usize),
) -> PyResult<usize> {
    value
        .extract::<i64>()
        .ok()
        .and_then(|v| usize::try_from(v).ok())
        .filter(|v| (min..=max).contains(v))
        .ok_or_else(|| {
            let shown = value
                .repr()
                .map(|r| r.to_string())
                .unwrap_or_else(|_| "?".to_string());
            crate::errors::input_error(
                py,
                &format!("{name} must be an integer between {min} and {max}, got {shown}"),
            )
        })
}

/// `report` as the Python form of its JSON.
pub fn report<'py, T: Serialize + ?Sized>(
    py: Python<'py>,
    report: &T,
) -> PyResult<Bound<'py, PyAny>> {
    let value = sim::report::to_json(report)
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?;
    value_to_py(py, &value)
}

/// A JSON value as a Python object (`null` → `None`, an integer → `int`, any other number →
/// `float`).
pub fn value_to_py<'py>(py: Python<'py>, value: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match value {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => b.into_pyobject(py)?.to_owned().into_any(),
        Value::Number(n) => match (n.as_i64(), n.as_u64()) {
            (Some(i), _) => i.into_pyobject(py)?.into_any(),
            (None, Some(u)) => u.into_pyobject(py)?.into_any(),
            (None, None) => n.as_f64().unwrap_or(f64::NAN).into_pyobject(py)?.into_any(),
        },
        Value::String(s) => s.into_pyobject(py)?.into_any(),
        Value::Array(items) => {
            let list = PyList::empty(py);
            for x in items {
                list.append(value_to_py(py, x)?)?;
            }
            list.into_any()
        }
        Value::Object(map) => {
            let dict = PyDict::new(py);
            for (k, x) in map {
                dict.set_item(k, value_to_py(py, x)?)?;
            }
            dict.into_any()
        }
    })
}
