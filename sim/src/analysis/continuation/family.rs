//! A family of stride maps `S(v; p)`: one scene, one of its parameters `p`, and the period-`k`
//! map `Sᵏ` whose fixed points the continuation follows. Everything the continuation asks of
//! the walker goes through here: the walker rebuilt at a parameter value (`Scene::set` +
//! `Scene::setup`), the orbit of `k` strides, its monodromy matrix (the product of the stride
//! Jacobians along the orbit), the parameter derivative `∂Sᵏ/∂p` by central differences, and
//! the sequence of events of the orbit's strides.

use crate::analysis::limit_cycle::{GaitSearch, JacobianMethod, NewtonSettings};
use crate::scene::{Scene, SceneError, Setup};
use crate::stride::{SharedBudget, StrideFailure, StrideResult, StrideSettings};
use nalgebra::{DMatrix, DVector};

/// Why a stride map of the family could not be evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EvalError {
    /// The scene could not be built at this parameter value.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// A stride failed.
    #[error("stride failed: {0}")]
    Stride(#[from] StrideFailure),
}

/// The sequence of events of an orbit's strides (knee locks, the string's engagement, heel
/// landings, heel strike), e.g. `knee_lock:swing_knee → string_engaged → heel_strike`. Two
/// points of one smooth branch have the same signature; where it changes the stride map is
/// not smooth and the branch ends.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EventSignature(pub Vec<String>);

impl EventSignature {
    /// The signature of the strides `strides`, in order (`|` between strides).
    pub fn of(strides: &[StrideResult]) -> Self {
        let mut names = Vec::new();
        for (i, s) in strides.iter().enumerate() {
            if i > 0 {
                names.push("|".to_string());
            }
            names.extend(s.events.iter().map(|e| e.name.clone()));
        }
        Self(names)
    }

    /// Where `other` (the new sequence) first differs from `self`: the event that now comes
    /// there (or the one that no longer occurs), and the change in words.
    pub fn difference(&self, other: &Self) -> (String, String) {
        let (a, b) = (&self.0, &other.0);
        let i = a.iter().zip(b).take_while(|(x, y)| x == y).count();
        match (a.get(i), b.get(i)) {
            (Some(x), Some(y)) => (y.clone(), format!("{y} comes before {x}")),
            (Some(x), None) => (x.clone(), format!("{x} no longer occurs")),
            (None, Some(y)) => (y.clone(), format!("{y} now occurs")),
            (None, None) => (String::new(), "no change".into()),
        }
    }
}

impl std::fmt::Display for EventSignature {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0.join(" → "))
    }
}

/// The orbit of `k` strides from a state: the states it visits and their strides.
#[derive(Clone, Debug)]
pub struct Orbit {
    /// `v₀ = v, v₁ = S(v₀), …, v_{k−1}`.
    pub states: Vec<DVector<f64>>,
    /// `Sᵏ(v)`.
    pub end: DVector<f64>,
    /// The stride from each state.
    pub strides: Vec<StrideResult>,
}

/// A scene with one parameter free, and the settings of every stride-map evaluation.
#[derive(Clone, Debug)]
pub struct Family {
    /// The scene (its other parameters fixed).
    pub scene: Scene,
    /// The parameter `p` (a name or alias the scene accepts).
    pub param: String,
    /// The Jacobian settings (method, perturbation) and Newton tolerances.
    pub newton: NewtonSettings,
    /// Central-difference step of `∂S/∂p` (in the parameter's unit).
    pub dp: f64,
    /// Stride settings used at every parameter value instead of the scene's (e.g. the
    /// command line's `--integrator`, `--rtol`, `--step-s`); `None`: the scene's own at each
    /// value.
    pub stride_settings: Option<StrideSettings>,
    /// The budget the strides take from (none: the scene's settings' own).
    pub search_budget: SharedBudget,
}

impl Family {
    /// The family of `scene`'s stride maps in `param`, with `newton`'s Jacobian settings; the
    /// parameter step of `∂S/∂p` is `newton.perturbation`.
    ///
    /// # Errors
    /// An unknown parameter.
    pub fn new(scene: &Scene, param: &str, newton: &NewtonSettings) -> Result<Self, SceneError> {
        let mut scene = scene.clone();
        let p = scene
            .values
            .get(&scene.parameter_name(param)?)
            .copied()
            .unwrap_or(0.0);
        scene.set(param, p)?;
        Ok(Self {
            scene,
            param: param.to_string(),
            newton: *newton,
            dp: newton.perturbation,
            stride_settings: None,
            search_budget: SharedBudget::default(),
        })
    }

    /// The walker, its stride settings and guess at `p` (the scene rebuilt).
    ///
    /// # Errors
    /// A value the scene rejects.
    pub fn setup_at(&self, p: f64) -> Result<Setup, SceneError> {
        self.setup_of(&self.scene_at(p)?)
    }

    /// `scene`'s setup with this family's stride settings (when it has its own).
    ///
    /// # Errors
    /// A scene that cannot be built.
    pub fn setup_of(&self, scene: &Scene) -> Result<Setup, SceneError> {
        // A cancelled sweep builds nothing more: its first gait's search (which strides on a
        // budget of its own) stops at its next setup.
        if self
            .search_budget
            .0
            .as_ref()
            .is_some_and(|b| b.is_cancelled())
        {
            return Err(SceneError::Invalid(
                "interrupted: the sweep's budget was cancelled".to_owned(),
            ));
        }
        let mut setup = scene.setup()?;
        if let Some(settings) = &self.stride_settings {
            setup.settings = settings.clone();
        }
        if self.search_budget.0.is_some() {
            setup.settings.search_budget = self.search_budget.clone();
        }
        Ok(setup)
    }

    /// The scene with `p` set (to name fixed points in reports).
    ///
    /// # Errors
    /// A value the scene rejects.
    pub fn scene_at(&self, p: f64) -> Result<Scene, SceneError> {
        let mut s = self.scene.clone();
        s.set(&self.param, p)?;
        Ok(s)
    }

    /// The orbit of `k` strides from `v` with `setup`'s walker.
    ///
    /// # Errors
    /// A stride that fails.
    pub fn orbit(&self, setup: &Setup, v: &DVector<f64>, k: usize) -> Result<Orbit, EvalError> {
        let search = GaitSearch::new(&setup.walker, &setup.settings, &self.newton);
        let mut states = Vec::with_capacity(k);
        let mut strides = Vec::with_capacity(k);
        let mut x = v.clone();
        for _ in 0..k {
            let (next, stride) = search.stride_map(&x)?;
            states.push(x);
            strides.push(stride);
            x = next;
        }
        Ok(Orbit {
            states,
            end: x,
            strides,
        })
    }

    /// The monodromy matrix `∂Sᵏ/∂v` of `orbit`: the product of the stride Jacobians along it
    /// (the later strides on the left), with the method used (central differences if any
    /// stride needed them).
    ///
    /// # Errors
    /// A stride that fails.
    pub fn monodromy(
        &self,
        setup: &Setup,
        orbit: &Orbit,
    ) -> Result<(DMatrix<f64>, JacobianMethod), EvalError> {
        let search = GaitSearch::new(&setup.walker, &setup.settings, &self.newton);
        let n = orbit.end.len();
        let mut m = DMatrix::identity(n, n);
        let mut method = self.newton.jacobian;
        for (i, v) in orbit.states.iter().enumerate() {
            let s_v = orbit.states.get(i + 1).unwrap_or(&orbit.end);
            let (j, used) = search.stride_jacobian_by(v, s_v)?;
            if used == JacobianMethod::CentralDifferences {
                method = used;
            }
            m = j * m;
        }
        Ok((m, method))
    }

    /// `∂Sᵏ/∂p` at `(v, p)` by central differences (two rebuilt walkers, run in parallel).
    ///
    /// # Errors
    /// A scene or stride failure on either side.
    pub fn parameter_derivative(
        &self,
        v: &DVector<f64>,
        p: f64,
        k: usize,
    ) -> Result<DVector<f64>, EvalError> {
        let side = |q: f64| -> Result<DVector<f64>, EvalError> {
            let setup = self.setup_at(q)?;
            Ok(self.orbit(&setup, v, k)?.end)
        };
        let (plus, minus) = rayon::join(|| side(p + self.dp), || side(p - self.dp));
        Ok((plus? - minus?) / (2.0 * self.dp))
    }
}
