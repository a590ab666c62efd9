//! The options every scene command shares, and the settings they stand for.

use crate::input_error::InputError;
use clap::Args;
use sim::analysis::limit_cycle::NewtonSettings;
use sim::analysis::solver_options::{jacobian_method, SolverOptionError, SolverOptions};
use sim::scene::{Scene, SceneError, Setup};
use sim::stride::StrideSettings;

/// Scene, parameters, output form, integrator and gait-search options.
#[derive(Args)]
pub struct Common {
    /// Scene name (see `walker scenes`) or path to a scene .toml file.
    #[arg(long)]
    pub scene: String,
    /// Set a parameter: `key=value` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
    /// Integrator: meijaard, rk4, dopri5 or dop853 (default: the scene's).
    #[arg(long)]
    pub integrator: Option<String>,
    /// Fixed step for meijaard/rk4, in seconds.
    #[arg(
        long,
        allow_hyphen_values = true,
        help = "Fixed step for meijaard/rk4 [s]"
    )]
    pub step_s: Option<f64>,
    /// Relative and absolute tolerance for dopri5 and dop853.
    #[arg(long, allow_hyphen_values = true)]
    pub rtol: Option<f64>,
    /// Newton tolerance on |Δv|.
    #[arg(long, default_value_t = 1e-11)]
    pub newton_tol: f64,
    /// Newton iteration budget.
    #[arg(long, default_value_t = 30)]
    pub newton_max_iter: usize,
    /// Strides one gait search may take, over all its Newton searches and the path from the
    /// scene's defaults; past them it stops and says so (exit 1). On a terminal a search
    /// that lasts over a second shows these strides as its progress.
    #[arg(long, value_name = "STRIDES", default_value_t = sim::analysis::homotopy::DEFAULT_GAIT_STRIDE_BUDGET)]
    pub max_strides: usize,
    /// Perturbation step of the stride Jacobian.
    #[arg(long, default_value_t = 1e-6)]
    pub perturbation: f64,
    /// The perturbed strides of the stride Jacobian replay the nominal stride's steps
    /// (internal numerical differentiation) instead of choosing their own.
    #[arg(long)]
    pub frozen_steps: bool,
    /// The stride Jacobian: `central` differences or the `variational` equations (exact
    /// derivatives; strides they do not cover fall back to central differences, and the JSON's
    /// `jacobian_method` says which was used).
    #[arg(long, default_value = "central")]
    pub jacobian: String,
}

impl Common {
    /// The scene with the `--set` parameters applied.
    pub fn scene(&self) -> Result<Scene, InputError> {
        let mut scene = Scene::load(&self.scene)?;
        // Each parameter once: a second `--set` of one parameter (by name or alias) was
        // dropped in silence, the last one winning.
        let mut given: Vec<(String, &str)> = Vec::new();
        for s in &self.set {
            let name = scene.set_text(s).map_err(|e| match e {
                SceneError::NotAnAssignment { text } => {
                    InputError::Other(format!("`--set {text}`: expected key=value"))
                }
                other => other.into(),
            })?;
            if let Some((_, first)) = given.iter().find(|(n, _)| *n == name) {
                return Err(InputError::Other(format!(
                    "`--set {s}`: parameter `{name}` is already set by `--set {first}` (each \
                     parameter once)"
                )));
            }
            given.push((name, s));
        }
        Ok(scene)
    }

    /// The walker of `scene` with the integrator options applied; checks every numeric option.
    pub fn setup(&self, scene: &Scene) -> Result<Setup, InputError> {
        let mut w = scene.setup()?;
        self.configure(&mut w.settings)?;
        Ok(w)
    }

    /// [`Self::setup`] as the engine's studies build a scene at other parameter values
    /// ([`sim::analysis::homotopy::SetupFor`]); an option error (already refused by [`Self::setup`] before
    /// any study starts) comes back as [`SceneError::Invalid`].
    pub fn setup_for(&self) -> impl Fn(&Scene) -> Result<Setup, SceneError> + Sync + '_ {
        move |scene: &Scene| {
            let mut w = scene.setup()?;
            self.configure(&mut w.settings)
                .map_err(|e| SceneError::Invalid(e.to_string()))?;
            Ok(w)
        }
    }

    /// The numerical options as the library takes them (`jacobian` read later, by
    /// [`Self::configure`]).
    fn solver(&self) -> SolverOptions {
        SolverOptions {
            integrator: self.integrator.clone(),
            step_s: self.step_s,
            rtol: self.rtol,
            newton_tol: self.newton_tol,
            newton_max_iter: self.newton_max_iter,
            max_strides: self.max_strides,
            perturbation: self.perturbation,
            frozen_steps: self.frozen_steps,
            jacobian: jacobian_method(&self.jacobian).unwrap_or_default(),
        }
    }

    /// Applies the integrator options to a scene's stride settings; checks every numeric
    /// option ([`SolverOptions::configure`]).
    fn configure(&self, settings: &mut StrideSettings) -> Result<(), InputError> {
        let flag = |field: &str| format!("--{}", field.replace('_', "-"));
        let refused = |e: SolverOptionError| InputError::Other(e.message(&flag));
        jacobian_method(&self.jacobian).map_err(refused)?;
        self.solver().configure(settings).map_err(refused)
    }

    /// How a gait is followed from the scene's defaults, with the gait's budget of strides
    /// (`--max-strides`).
    pub fn homotopy(&self) -> sim::analysis::homotopy::HomotopySettings {
        self.solver().homotopy()
    }

    /// The gait search's settings.
    pub fn newton(&self) -> NewtonSettings {
        self.solver().newton()
    }
}

/// The help of `--floor` (`walker walk`, `walker sil`).
pub const FLOOR_HELP: &str = "The floor: `plane` (default), `step:at=K,height_m=H` (the K-th \
    heel strike lands on a step of H m, up positive, measured along the slope's normal; the \
    floor stays there), `rough:sigma_m=S[,seed=N]` (at every heel strike the level changes by \
    a normal draw of standard deviation S m, reproducible from the seed)";

/// A `--floor` option's floor, or bad input naming the option.
pub fn floor(spec: &str) -> Result<sim::stride::Floor, InputError> {
    spec.parse()
        .map_err(|e: sim::stride::FloorError| InputError::Other(format!("--{e}")))
}

/// `--quantity NAME` and `--sigma-m S` of a study (`walker stability-map`, `walker sweep`):
/// the quantity, checked against what it needs, and its options; `--sigma-m` without
/// `--quantity mfpt` is refused (it would be ignored).
pub fn quantity(
    name: Option<&str>,
    sigma_m: Option<f64>,
) -> Result<
    (
        Option<sim::analysis::quantity::Quantity>,
        sim::analysis::quantity::QuantityOptions,
    ),
    InputError,
> {
    use sim::analysis::quantity::{Quantity, QuantityOptions};
    let options = QuantityOptions {
        sigma_m,
        ..Default::default()
    };
    let quantity = name
        .map(|name| {
            let q = Quantity::parse(name).ok_or_else(|| {
                InputError::Other(format!(
                    "--quantity `{name}`: expected one of {}",
                    Quantity::names()
                ))
            })?;
            q.check(&options)
                .map_err(|e| InputError::Other(format!("--quantity {q}: {e}")))?;
            Ok::<_, InputError>(q)
        })
        .transpose()?;
    if sigma_m.is_some() && quantity != Some(Quantity::Mfpt) {
        return Err(InputError::Other(
            "--sigma-m is the rough floor of --quantity mfpt: give --quantity mfpt too".into(),
        ));
    }
    Ok((quantity, options))
}
