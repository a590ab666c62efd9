//! `walker.Scene`: a scene file with its parameter values, read-only; `with_params` makes a
//! new one.

use crate::convert;
use crate::errors;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sim::analysis::solver_options::{
    jacobian_method, jacobian_name, SolverOptionError, SolverOptions,
};
use sim::report::{SceneCatalogue, SceneEntry};
use sim::scene::text_file::read_text_file;
use sim::scene::{Scene, SceneError, BUILTIN, MAX_SCENE_FILE_BYTES};

/// A scene: a walker described by a scene file (built-in or a path), with parameter values.
#[pyclass(name = "Scene", module = "walker._walker", frozen)]
#[derive(Clone)]
pub struct PyScene {
    /// The library's scene.
    pub inner: Scene,
    /// What `Scene.load` was given (a built-in name or a path), for `repr`.
    source: String,
    /// The text of a scene file loaded by path, as parsed (`None` for a built-in scene): a
    /// pickled scene carries it, so a process on another machine builds the same scene.
    text: Option<String>,
    /// The numerical options of every study of this scene (`with_solver`).
    pub solver: SolverOptions,
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
        let builtin = BUILTIN.iter().any(|(n, _)| *n == name_or_path);
        let text = if builtin || !name_or_path.ends_with(".toml") {
            None
        } else {
            Some(
                read_text_file(
                    std::path::Path::new(name_or_path),
                    MAX_SCENE_FILE_BYTES,
                    "a scene file",
                )
                .map_err(|e| {
                    errors::scene_error(
                        py,
                        &SceneError::File {
                            path: name_or_path.to_owned(),
                            message: e.to_string(),
                        },
                    )
                })?,
            )
        };
        let inner = match &text {
            Some(t) => Scene::parse(name_or_path, t),
            None => Scene::load(name_or_path),
        }
        .map_err(|e| errors::scene_error(py, &e))?;
        // Built once, so a scene that cannot be built is refused here, not at first use.
        inner.setup().map_err(|e| errors::scene_error(py, &e))?;
        Ok(Self {
            inner,
            source: name_or_path.to_owned(),
            text,
            solver: SolverOptions::default(),
        })
    }

    /// Pickling (`pickle`, `copy`, Ray and multiprocessing ship scenes to other processes):
    /// the scene's source (built-in name or path), its file text when loaded by path (the
    /// other process need not have the file), every parameter value (bit for bit) and the
    /// solver options.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let restore = py.import("walker._walker")?.getattr("_restore_scene")?;
        let values = PyDict::new(py);
        for (k, v) in &self.inner.values {
            values.set_item(k, v)?;
        }
        let o = &self.solver;
        let solver = PyDict::new(py);
        solver.set_item("integrator", o.integrator.clone())?;
        solver.set_item("step_s", o.step_s)?;
        solver.set_item("rtol", o.rtol)?;
        solver.set_item("newton_tol", o.newton_tol)?;
        solver.set_item("newton_max_iter", o.newton_max_iter)?;
        solver.set_item("max_strides", o.max_strides)?;
        solver.set_item("perturbation", o.perturbation)?;
        solver.set_item("frozen_steps", o.frozen_steps)?;
        solver.set_item("jacobian", jacobian_name(o.jacobian))?;
        let args = (self.source.clone(), self.text.clone(), values, solver).into_pyobject(py)?;
        Ok((restore, args.into_any()))
    }

    /// The scene's name.
    #[getter]
    fn name(&self) -> &str {
        self.inner.name()
    }

    /// The text of the scene file this scene was parsed from (a built-in scene's own text):
    /// what a study file records, by its hash, so that a changed file is not taken for the
    /// same study.
    #[getter]
    fn file_text(&self) -> &str {
        match &self.text {
            Some(t) => t,
            None => BUILTIN
                .iter()
                .find(|(n, _)| *n == self.source)
                .map_or("", |(_, t)| t),
        }
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
            text: self.text.clone(),
            solver: self.solver.clone(),
        })
    }

    /// A new scene whose studies use these numerical options (each `None` keeps this scene's):
    /// `integrator` (`meijaard`, `rk4`, `dopri5`, `dop853`), its fixed `step_s` [s] or its
    /// tolerance `rtol`, Newton's `newton_tol` and `newton_max_iter`, the gait search's
    /// `max_strides`, the Jacobian's `perturbation`, `frozen_steps` and `jacobian`
    /// (`central`, `variational`): the `walker` command's `--integrator`, `--step-s`, `--rtol`,
    /// `--newton-tol`, ... Raises `walker.InputError` for an option out of its range, an
    /// unknown name, or one the integrator would ignore (a step for an adaptive one).
    #[pyo3(signature = (
        *, integrator = None, step_s = None, rtol = None, newton_tol = None,
        newton_max_iter = None, max_strides = None, perturbation = None, frozen_steps = None,
        jacobian = None
    ))]
    #[allow(clippy::too_many_arguments)]
    fn with_solver(
        &self,
        py: Python<'_>,
        integrator: Option<String>,
        step_s: Option<f64>,
        rtol: Option<f64>,
        newton_tol: Option<f64>,
        newton_max_iter: Option<&Bound<'_, PyAny>>,
        max_strides: Option<&Bound<'_, PyAny>>,
        perturbation: Option<f64>,
        frozen_steps: Option<bool>,
        jacobian: Option<String>,
    ) -> PyResult<Self> {
        let refused = |e: SolverOptionError| errors::input_error(py, &e.message(&|n| n.to_owned()));
        let old = &self.solver;
        let count = |v: Option<&Bound<'_, PyAny>>, name: &str, default: usize| match v {
            Some(v) => convert::count_in(py, v, name, (1, usize::MAX)),
            None => Ok(default),
        };
        let solver = SolverOptions {
            integrator: integrator.or_else(|| old.integrator.clone()),
            step_s: step_s.or(old.step_s),
            rtol: rtol.or(old.rtol),
            newton_tol: newton_tol.unwrap_or(old.newton_tol),
            newton_max_iter: count(newton_max_iter, "newton_max_iter", old.newton_max_iter)?,
            max_strides: count(max_strides, "max_strides", old.max_strides)?,
            perturbation: perturbation.unwrap_or(old.perturbation),
            frozen_steps: frozen_steps.unwrap_or(old.frozen_steps),
            jacobian: match jacobian {
                Some(name) => jacobian_method(&name).map_err(refused)?,
                None => old.jacobian,
            },
        };
        let mut setup = self
            .inner
            .setup()
            .map_err(|e| errors::scene_error(py, &e))?;
        solver.configure(&mut setup.settings).map_err(refused)?;
        Ok(Self {
            inner: self.inner.clone(),
            source: self.source.clone(),
            text: self.text.clone(),
            solver,
        })
    }

    /// The numerical options of this scene's studies (`with_solver`): `integrator` (the
    /// integrator the scene's stride runs with, and its settings), `newton_tol`,
    /// `newton_max_iter`, `max_strides`, `perturbation`, `frozen_steps`, `jacobian`.
    #[getter]
    fn solver<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let mut setup = self
            .inner
            .setup()
            .map_err(|e| errors::scene_error(py, &e))?;
        self.solver
            .configure(&mut setup.settings)
            .map_err(|e| errors::input_error(py, &e.to_string()))?;
        let d = PyDict::new(py);
        d.set_item(
            "integrator",
            convert::report(py, &setup.settings.integrator)?,
        )?;
        d.set_item("newton_tol", self.solver.newton_tol)?;
        d.set_item("newton_max_iter", self.solver.newton_max_iter)?;
        d.set_item("max_strides", self.solver.max_strides)?;
        d.set_item("perturbation", self.solver.perturbation)?;
        d.set_item("frozen_steps", self.solver.frozen_steps)?;
        d.set_item("jacobian", jacobian_name(self.solver.jacobian))?;
        Ok(d)
    }

    /// `Scene.load("NAME")`, then `.with_params(k=v, ...)` with every value that is not the
    /// scene file's default and `.with_solver(...)` with every option set: an expression that
    /// builds the same scene.
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
        let mut shown = format!("Scene.load({:?})", self.source);
        if !changed.is_empty() {
            shown += &format!(".with_params({})", changed.join(", "));
        }
        let (o, d) = (&self.solver, SolverOptions::default());
        let mut set: Vec<String> = Vec::new();
        if let Some(k) = &o.integrator {
            set.push(format!("integrator={k:?}"));
        }
        if let Some(h) = o.step_s {
            set.push(format!("step_s={h:?}"));
        }
        if let Some(r) = o.rtol {
            set.push(format!("rtol={r:?}"));
        }
        if o.newton_tol.to_bits() != d.newton_tol.to_bits() {
            set.push(format!("newton_tol={:?}", o.newton_tol));
        }
        if o.newton_max_iter != d.newton_max_iter {
            set.push(format!("newton_max_iter={}", o.newton_max_iter));
        }
        if o.max_strides != d.max_strides {
            set.push(format!("max_strides={}", o.max_strides));
        }
        if o.perturbation.to_bits() != d.perturbation.to_bits() {
            set.push(format!("perturbation={:?}", o.perturbation));
        }
        if o.frozen_steps {
            set.push("frozen_steps=True".to_owned());
        }
        if o.jacobian != d.jacobian {
            set.push(format!("jacobian={:?}", jacobian_name(o.jacobian)));
        }
        if !set.is_empty() {
            shown += &format!(".with_solver({})", set.join(", "));
        }
        shown
    }
}

/// The built-in scenes as `walker scenes --json` lists them (`{"scenes": [...]}`).
#[pyfunction]
pub fn scenes(py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    let catalogue = SceneCatalogue::builtin().map_err(|e| errors::scene_error(py, &e))?;
    convert::report(py, &catalogue)
}

/// A pickled `Scene` ([`PyScene::__reduce__`]): parsed from `text` (or loaded by `source`
/// when it is a built-in scene), every value in `values` set, `solver`'s options applied.
#[pyfunction]
pub fn _restore_scene(
    py: Python<'_>,
    source: String,
    text: Option<String>,
    values: std::collections::BTreeMap<String, f64>,
    solver: &Bound<'_, PyDict>,
) -> PyResult<PyScene> {
    let mut inner = match &text {
        Some(t) => Scene::parse(&source, t),
        None => Scene::load(&source),
    }
    .map_err(|e| errors::scene_error(py, &e))?;
    for (k, v) in &values {
        if inner.values.get(k).map(|d| d.to_bits()) != Some(v.to_bits()) {
            inner.set(k, *v).map_err(|e| errors::scene_error(py, &e))?;
        }
    }
    let scene = PyScene {
        inner,
        source,
        text,
        solver: SolverOptions::default(),
    };
    let kwargs = solver.copy()?;
    scene.with_solver(
        py,
        kwargs
            .get_item("integrator")?
            .map(|v| v.extract())
            .transpose()?
            .flatten(),
        kwargs
            .get_item("step_s")?
            .map(|v| v.extract())
            .transpose()?
            .flatten(),
        kwargs
            .get_item("rtol")?
            .map(|v| v.extract())
            .transpose()?
            .flatten(),
        kwargs
            .get_item("newton_tol")?
            .map(|v| v.extract())
            .transpose()?,
        kwargs.get_item("newton_max_iter")?.as_ref(),
        kwargs.get_item("max_strides")?.as_ref(),
        kwargs
            .get_item("perturbation")?
            .map(|v| v.extract())
            .transpose()?,
        kwargs
            .get_item("frozen_steps")?
            .map(|v| v.extract())
            .transpose()?,
        kwargs
            .get_item("jacobian")?
            .map(|v| v.extract())
            .transpose()?,
    )
}
