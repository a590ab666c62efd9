//! `walker.Scene`: a scene file with its parameter values, read-only; `with_params` makes a
//! new one.

use crate::convert;
use crate::errors;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sim::report::{SceneCatalogue, SceneEntry};
use sim::scene::Scene;

/// A scene: a walker described by a scene file (built-in or a path), with parameter values.
#[pyclass(name = "Scene", module = "walker._walker", frozen)]
#[derive(Clone)]
pub struct PyScene {
    /// The library's scene.
    pub inner: Scene,
    /// What `Scene.load` was given (a built-in name or a path), for `repr`.
    source: String,
}

#[pymethods]
impl PyScene {
    /// Loads a built-in scene by name (`walker.scenes()` lists them) or a scene file by path
    /// (a `str` or an `os.PathLike`). Raises `walker.SceneError` when it cannot be loaded or
    /// built, `walker.InputError` for a path that is not UTF-8.
    #[staticmethod]
    fn load(py: Python<'_>, name_or_path: std::path::PathBuf) -> PyResult<Self> {
        let name_or_path = name_or_path.to_str().ok_or_else(|| {
            errors::input_error(
                py,
                &format!("scene path {} is not UTF-8", name_or_path.display()),
            )
        })?;
        let inner = Scene::load(name_or_path).map_err(|e| errors::scene_error(py, &e))?;
        // Built once, so a scene that cannot be built is refused here, not at first use.
        inner.setup().map_err(|e| errors::scene_error(py, &e))?;
        Ok(Self {
            inner,
            source: name_or_path.to_owned(),
        })
    }

    /// The scene's name.
    #[getter]
    fn name(&self) -> &str {
        self.inner.name()
    }

    /// The parameter values, `{name: value}` (units in `parameters()`).
    #[getter]
    fn values<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in &self.inner.values {
            d.set_item(k, v)?;
        }
        Ok(d)
    }

    /// The scene as `walker scenes NAME --json` describes it: name, summary, reference,
    /// degrees of freedom, coordinates, and `parameters` (each with name, default, unit, doc,
    /// min, max, aliases).
    fn describe<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let entry = SceneEntry::of(&self.inner).map_err(|e| errors::scene_error(py, &e))?;
        convert::report(py, &entry)
    }

    /// The parameter table as a pandas DataFrame indexed by name: `value` (this scene's),
    /// `default`, `unit`, `min`, `max` (`None` where unbounded), `doc`, `aliases`.
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let entry = SceneEntry::of(&self.inner).map_err(|e| errors::scene_error(py, &e))?;
        let rows = pyo3::types::PyList::empty(py);
        for p in &entry.parameters {
            let row = convert::report(py, p)?;
            row.set_item("value", self.inner.values.get(&p.name).copied())?;
            rows.append(row)?;
        }
        let columns = [
            "name", "value", "default", "unit", "min", "max", "doc", "aliases",
        ];
        let kwargs = PyDict::new(py);
        kwargs.set_item("columns", columns)?;
        py.import("pandas")?
            .getattr("DataFrame")?
            .call((rows,), Some(&kwargs))?
            .call_method1("set_index", ("name",))
    }

    /// A new scene with the given parameters (by name or alias) set; this one is unchanged.
    /// Raises `walker.SceneError` for an unknown parameter, a value that is not a finite
    /// number or is out of its range, or values the walker cannot be built with.
    #[pyo3(signature = (**params))]
    fn with_params(&self, py: Python<'_>, params: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut inner = self.inner.clone();
        let mut given: Vec<(String, String)> = Vec::new();
        for (key, value) in params.into_iter().flat_map(|d| d.iter()) {
            let key: String = key.extract()?;
            let name = inner
                .parameter_name(&key)
                .map_err(|e| errors::scene_error(py, &e))?;
            if let Some((_, first)) = given.iter().find(|(n, _)| *n == name) {
                return Err(errors::input_error(
                    py,
                    &format!(
                        "`{key}`: parameter `{name}` is already set by `{first}` (each \
                         parameter once)"
                    ),
                ));
            }
            let value: f64 = value.extract().map_err(|_| {
                errors::input_error(
                    py,
                    &format!("parameter `{name}`: `{value}` is not a number"),
                )
            })?;
            inner
                .set(&name, value)
                .map_err(|e| errors::scene_error(py, &e))?;
            given.push((name, key));
        }
        inner.setup().map_err(|e| errors::scene_error(py, &e))?;
        Ok(Self {
            inner,
            source: self.source.clone(),
        })
    }

    /// `Scene.load("NAME")`, then `.with_params(k=v, ...)` with every value that is not the
    /// scene file's default: an expression that builds the same scene.
    fn __repr__(&self) -> String {
        let changed: Vec<String> = SceneEntry::of(&self.inner)
            .map(|entry| {
                entry
                    .parameters
                    .iter()
                    .filter_map(|p| {
                        let v = *self.inner.values.get(&p.name)?;
                        (v.to_bits() != p.default.to_bits()).then(|| format!("{}={v:?}", p.name))
                    })
                    .collect()
            })
            .unwrap_or_default();
        let load = format!("Scene.load({:?})", self.source);
        if changed.is_empty() {
            load
        } else {
            format!("{load}.with_params({})", changed.join(", "))
        }
    }
}

/// The built-in scenes as `walker scenes --json` lists them (`{"scenes": [...]}`).
#[pyfunction]
pub fn scenes(py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    let catalogue = SceneCatalogue::builtin().map_err(|e| errors::scene_error(py, &e))?;
    convert::report(py, &catalogue)
}
