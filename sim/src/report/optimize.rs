//! The `walker optimize --json` report: CMA-ES over a scene's parameters
//! ([`crate::analysis::optimize`]) with the best design's gait as `walker gait` reports it, the
//! scene's own design to compare, the history and every evaluation; with the options that ask
//! for the search (`NAME=MIN:MAX` ranges, the objective, `NAME<=V` constraints, the budget, the
//! seed, the initial step, the rough floor of `mfpt`), read and checked once here for the
//! command and the Python package.

use super::GaitReport;
use crate::analysis::homotopy::{HomotopySettings, SetupFor};
use crate::analysis::limit_cycle::NewtonSettings;
use crate::analysis::optimize::{
    check, evaluate_drawn, optimize_with, Constraint, ConstraintParseError, EvaluateDrawn,
    Evaluation, Generation, Objective, OptimizeError, OptimizeSettings, Sense, VariedParameter,
    BOUND_PENALTY, INITIAL_STEP,
};
use crate::analysis::quantity::{Quantity, QuantityError, QuantityOptions};
use crate::scene::{Scene, SceneError};
use serde::Serialize;
use std::collections::BTreeMap;

/// Most candidates one search may evaluate (`budget`).
pub const MAX_OPTIMIZE_EVALUATIONS: usize = 10_000;

/// A search as a front end asks for it: the ranges, objective and constraints as text, each
/// read by [`Self::request`].
#[derive(Clone, Debug)]
pub struct OptimizeOptions {
    /// The parameters varied: `NAME=MIN:MAX` each (the name or an alias).
    pub vary: Vec<String>,
    /// The objective's name ([`Objective::ALL`]).
    pub objective: String,
    /// The constraints: `NAME<=V` or `NAME>=V` each.
    pub constraints: Vec<String>,
    /// Candidates evaluated, exactly (1 to [`MAX_OPTIMIZE_EVALUATIONS`]).
    pub budget: usize,
    /// The seed of CMA-ES's draws.
    pub seed: u64,
    /// CMA-ES's initial step size, normalised (above 0, at most 1).
    pub initial_step: f64,
    /// The rough floor's standard deviation of `mfpt` \[m\].
    pub sigma_m: Option<f64>,
}

impl Default for OptimizeOptions {
    /// `walker optimize`'s defaults, with nothing varied and the objective `gsn`.
    fn default() -> Self {
        Self {
            vary: Vec::new(),
            objective: Objective::Gsn.name().to_owned(),
            constraints: Vec::new(),
            budget: 200,
            seed: 0,
            initial_step: INITIAL_STEP,
            sigma_m: None,
        }
    }
}

/// An option of [`OptimizeOptions`] that cannot be had, the option by its field name (`vary`,
/// `objective`, `constraints`, `budget`, `initial_step`, `sigma_m`), which the command spells
/// as a flag (`--vary`) and the Python package as a keyword.
#[derive(Debug)]
pub enum OptimizeOptionError {
    /// A count outside `min..=max` (signed: a front end may be given a negative one).
    Count {
        /// The option.
        option: &'static str,
        /// Its value.
        value: i128,
        /// Smallest allowed.
        min: usize,
        /// Largest allowed.
        max: usize,
    },
    /// An objective that is not one of [`Objective::ALL`].
    Objective(String),
    /// A range that cannot be read.
    Vary {
        /// The range as given.
        text: String,
        /// What is wrong, in words.
        why: String,
    },
    /// A parameter the scene does not have (by name or alias).
    UnknownParameter(SceneError),
    /// A range whose MIN is not below its MAX.
    VaryOrder {
        /// The range as given.
        text: String,
        /// Its MIN.
        min: f64,
        /// Its MAX.
        max: f64,
    },
    /// A range with an end outside the parameter's own range (the scene's refusal).
    VaryOutside {
        /// The range as given.
        text: String,
        /// The scene's refusal.
        error: SceneError,
    },
    /// A constraint that cannot be read.
    Constraint(ConstraintParseError),
    /// The rough floor given without `mfpt` as the objective or a constraint.
    SigmaWithoutMfpt,
    /// `mfpt` as the objective or a constraint without its rough floor.
    MfptWithoutSigma {
        /// `objective` or `constraint`.
        what: &'static str,
    },
    /// A rough floor that is not a finite number ≥ 0.
    Sigma {
        /// `objective` or `constraint`.
        what: &'static str,
        /// The value.
        value: f64,
    },
    /// An initial step not above 0 and at most 1.
    InitialStep(f64),
    /// The search refuses the request otherwise (a parameter twice, a scene without the
    /// objective's quantity, ...) or a scene that cannot be built.
    Search(OptimizeError),
}

impl OptimizeOptionError {
    /// The message, each option spelled by `spell` (its field name to the front end's
    /// spelling: `--sigma-m` for the command, `sigma_m` for Python).
    pub fn message(&self, spell: &dyn Fn(&str) -> String) -> String {
        let range =
            |text: &str, why: &dyn std::fmt::Display| format!("{} `{text}`: {why}", spell("vary"));
        match self {
            Self::Count {
                option,
                value,
                min,
                max,
            } => format!(
                "{} must be between {min} and {max}, got {value}",
                spell(option)
            ),
            Self::Objective(name) => format!(
                "{} `{name}`: expected one of {}",
                spell("objective"),
                Objective::ALL.map(Objective::name).join(", ")
            ),
            Self::Vary { text, why } => range(text, &format!("{why} (expected NAME=MIN:MAX)")),
            Self::UnknownParameter(e) => e.to_string(),
            Self::VaryOrder { text, min, max } => {
                range(text, &format!("MIN {min} must be below MAX {max}"))
            }
            Self::VaryOutside { text, error } => range(text, error),
            Self::Constraint(e) => format!("{} `{}`: {}", spell("constraints"), e.text, e.why),
            Self::SigmaWithoutMfpt => format!(
                "{} is the rough floor of mfpt: give {} mfpt or an mfpt constraint",
                spell("sigma_m"),
                spell("objective")
            ),
            Self::MfptWithoutSigma { what } => format!(
                "{what} mfpt: mfpt needs the rough floor's standard deviation ({})",
                spell("sigma_m")
            ),
            Self::Sigma { what, value } => format!(
                "{what} mfpt: {} {value}: a standard deviation must be a finite number ≥ 0",
                spell("sigma_m")
            ),
            Self::InitialStep(v) => format!(
                "{} must be above 0 and at most 1 (normalised), got {v}",
                spell("initial_step")
            ),
            Self::Search(e) => e.to_string(),
        }
    }

    /// The scene error inside, if the refusal is the scene's (an unknown parameter, an end out
    /// of the parameter's range, a scene that cannot be built).
    pub fn scene_error(&self) -> Option<&SceneError> {
        match self {
            Self::UnknownParameter(e)
            | Self::VaryOutside { error: e, .. }
            | Self::Search(OptimizeError::Scene(e)) => Some(e),
            _ => None,
        }
    }
}

impl std::fmt::Display for OptimizeOptionError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message(&|name| name.to_owned()))
    }
}

impl std::error::Error for OptimizeOptionError {}

impl From<OptimizeError> for OptimizeOptionError {
    fn from(e: OptimizeError) -> Self {
        match e {
            OptimizeError::InitialStep(v) => Self::InitialStep(v),
            OptimizeError::Quantity {
                what,
                why: QuantityError::NoSigma,
                ..
            } => Self::MfptWithoutSigma { what },
            OptimizeError::Quantity {
                what,
                why: QuantityError::BadSigma(value),
                ..
            } => Self::Sigma { what, value },
            other => Self::Search(other),
        }
    }
}

/// A search read from its [`OptimizeOptions`]: what [`OptimizeSettings`] needs besides the
/// solver.
#[derive(Clone, Debug)]
pub struct OptimizeRequest {
    /// The parameters varied (canonical names).
    pub params: Vec<VariedParameter>,
    /// The objective.
    pub objective: Objective,
    /// The constraints.
    pub constraints: Vec<Constraint>,
    /// Candidates evaluated.
    pub budget: usize,
    /// The seed of CMA-ES's draws.
    pub seed: u64,
    /// CMA-ES's initial step size.
    pub initial_step: f64,
    /// What the quantities need besides the gait (the rough floor of `mfpt`).
    pub quantity_options: QuantityOptions,
}

impl OptimizeOptions {
    /// The options read at `scene` (whose parameters the ranges name): the budget, the
    /// objective, each range, each constraint, the rough floor, in that order. The rest (the
    /// initial step, a parameter twice, the objective's quantity available) is checked by
    /// [`OptimizeReport::run`] before any gait is searched.
    ///
    /// # Errors
    /// The first option that cannot be had.
    pub fn request(&self, scene: &Scene) -> Result<OptimizeRequest, OptimizeOptionError> {
        if !(1..=MAX_OPTIMIZE_EVALUATIONS).contains(&self.budget) {
            return Err(OptimizeOptionError::Count {
                option: "budget",
                value: self.budget as i128,
                min: 1,
                max: MAX_OPTIMIZE_EVALUATIONS,
            });
        }
        let objective = Objective::parse(self.objective.trim())
            .ok_or_else(|| OptimizeOptionError::Objective(self.objective.clone()))?;
        let params = self
            .vary
            .iter()
            .map(|v| parse_vary(v, scene))
            .collect::<Result<Vec<_>, _>>()?;
        let constraints = self
            .constraints
            .iter()
            .map(|c| Constraint::parse(c).map_err(OptimizeOptionError::Constraint))
            .collect::<Result<Vec<_>, _>>()?;
        let uses_mfpt = objective.quantity() == Quantity::Mfpt
            || constraints.iter().any(|c| c.quantity == Quantity::Mfpt);
        if self.sigma_m.is_some() && !uses_mfpt {
            return Err(OptimizeOptionError::SigmaWithoutMfpt);
        }
        Ok(OptimizeRequest {
            params,
            objective,
            constraints,
            budget: self.budget,
            seed: self.seed,
            initial_step: self.initial_step,
            quantity_options: QuantityOptions {
                sigma_m: self.sigma_m,
                ..Default::default()
            },
        })
    }
}

/// A range `NAME=MIN:MAX` (the parameter by its canonical name), both ends inside the scene's
/// own range for it.
///
/// # Errors
/// No `=` or `:`, an end that is not a finite number, MIN not below MAX, an unknown
/// parameter, an end outside the parameter's range.
pub fn parse_vary(v: &str, scene: &Scene) -> Result<VariedParameter, OptimizeOptionError> {
    let bad = |why: &str| OptimizeOptionError::Vary {
        text: v.to_owned(),
        why: why.to_owned(),
    };
    let (name, range) = v.split_once('=').ok_or_else(|| bad("no `=`"))?;
    let name = scene
        .parameter_name(name.trim())
        .map_err(OptimizeOptionError::UnknownParameter)?;
    let (lo, hi) = range
        .split_once(':')
        .ok_or_else(|| bad("no `:` between MIN and MAX"))?;
    let number = |what: &str, s: &str| -> Result<f64, OptimizeOptionError> {
        s.trim()
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| bad(&format!("{what} `{}` is not a finite number", s.trim())))
    };
    let (min, max) = (number("MIN", lo)?, number("MAX", hi)?);
    if min >= max {
        return Err(OptimizeOptionError::VaryOrder {
            text: v.to_owned(),
            min,
            max,
        });
    }
    // Both ends inside the scene's own range (`walker scenes S`).
    let mut check = scene.clone();
    for end in [min, max] {
        check
            .set(&name, end)
            .map_err(|error| OptimizeOptionError::VaryOutside {
                text: v.to_owned(),
                error,
            })?;
    }
    Ok(VariedParameter { name, min, max })
}

/// The `walker optimize --json` object.
#[derive(Clone, Debug, Serialize)]
pub struct OptimizeReport {
    /// Scene name.
    pub scene: String,
    /// The objective.
    pub objective: Objective,
    /// Whether it is minimised or maximised.
    pub sense: Sense,
    /// The parameters varied, with their ranges.
    pub parameters: Vec<VariedParameter>,
    /// The constraints.
    pub constraints: Vec<Constraint>,
    /// The seed of CMA-ES's draws.
    pub seed: u64,
    /// Candidates evaluated.
    pub budget: usize,
    /// How the search ran (its fixed rules), for a reader of the JSON.
    pub method: Method,
    /// The scene's own design (its values with `--set`), evaluated outside the budget.
    pub default: Evaluation,
    /// The best feasible design (`null`: none was feasible).
    pub best: Option<Best>,
    /// The best feasible value after each generation (`null` before the first feasible one).
    pub history: Vec<Option<f64>>,
    /// Every generation.
    pub generations: Vec<Generation>,
    /// Runs of CMA-ES (1 + restarts, counting the last short generation as a run).
    pub runs: usize,
    /// Every candidate, generation by generation, in each in CMA-ES's ranking.
    pub evaluations: Vec<Evaluation>,
}

/// The search's fixed rules.
#[derive(Clone, Debug, Serialize)]
pub struct Method {
    /// The algorithm.
    pub algorithm: &'static str,
    /// The coordinates it runs in.
    pub coordinates: &'static str,
    /// Its initial step size (normalised).
    pub initial_step: f64,
    /// How the box is kept.
    pub bounds: &'static str,
    /// The weight of the squared distance outside the box.
    pub bound_penalty: f64,
    /// When it restarts.
    pub restarts: &'static str,
}

/// The best design.
#[derive(Clone, Debug, Serialize)]
pub struct Best {
    /// Its index in `evaluations`.
    pub index: usize,
    /// Its values of the varied parameters.
    pub parameters: BTreeMap<String, f64>,
    /// The objective's value there.
    pub value: Option<f64>,
    /// Its gait, as `walker gait --json` reports it at these values (with its `gait_source`).
    pub gait: GaitReport,
}

impl OptimizeRequest {
    /// The search's settings for this request, designs built by `setup_for`.
    pub fn settings<'a>(
        &'a self,
        setup_for: &'a SetupFor<'a>,
        newton: &'a NewtonSettings,
        homotopy: &'a HomotopySettings,
    ) -> OptimizeSettings<'a> {
        OptimizeSettings {
            params: &self.params,
            objective: self.objective,
            constraints: &self.constraints,
            budget: self.budget,
            seed: self.seed,
            initial_step: self.initial_step,
            setup_for,
            newton,
            homotopy,
            quantity_options: self.quantity_options,
        }
    }

    /// The evaluations of `drawn` (designs in normalised coordinates) for this search from
    /// `scene`'s design: a cluster worker's task ([`evaluate_drawn`]), each as CBOR bytes
    /// ([`Evaluation::to_cbor`]).
    ///
    /// # Errors
    /// As [`OptimizeReport::run`].
    pub fn evaluate_drawn(
        &self,
        scene: &Scene,
        drawn: &[Vec<f64>],
        setup_for: &SetupFor<'_>,
        newton: &NewtonSettings,
        homotopy: &HomotopySettings,
        on_evaluation: &(dyn Fn() + Sync),
    ) -> Result<Vec<Vec<u8>>, OptimizeOptionError> {
        let settings = self.settings(setup_for, newton, homotopy);
        Ok(evaluate_drawn(scene, &settings, drawn, on_evaluation)?
            .iter()
            .map(Evaluation::to_cbor)
            .collect())
    }
}

impl OptimizeReport {
    /// Runs the search `request` from `scene`'s design, each design built by `setup_for` (the
    /// front end's solver options), gaits found with `newton` and `homotopy`, `on_evaluation`
    /// called after each evaluation (`budget + 1`: the scene's design and every candidate;
    /// from any thread).
    ///
    /// # Errors
    /// A request the search refuses (checked before any gait is searched: the initial step,
    /// a parameter twice, the objective's quantity not available), a scene that cannot be
    /// built at a design.
    pub fn run(
        scene: &Scene,
        request: &OptimizeRequest,
        setup_for: &SetupFor<'_>,
        newton: &NewtonSettings,
        homotopy: &HomotopySettings,
        on_evaluation: &(dyn Fn() + Sync),
    ) -> Result<Self, OptimizeOptionError> {
        Self::run_with(
            scene,
            request,
            setup_for,
            newton,
            homotopy,
            on_evaluation,
            None,
        )
    }

    /// [`Self::run`] with each generation's new candidates evaluated by `evaluate` (a
    /// cluster's workers, each running [`evaluate_drawn`] on the same request):
    /// [`optimize_with`]. The same report, bit for bit.
    ///
    /// # Errors
    /// As [`Self::run`], and `evaluate`'s errors.
    pub fn run_with(
        scene: &Scene,
        request: &OptimizeRequest,
        setup_for: &SetupFor<'_>,
        newton: &NewtonSettings,
        homotopy: &HomotopySettings,
        on_evaluation: &(dyn Fn() + Sync),
        evaluate: Option<&EvaluateDrawn<'_>>,
    ) -> Result<Self, OptimizeOptionError> {
        let settings = request.settings(setup_for, newton, homotopy);
        check(scene, &settings)?;
        let result = optimize_with(scene, &settings, on_evaluation, evaluate)?;
        let best = match &result.best {
            Some(b) => {
                let setup = setup_for(&b.scene).map_err(OptimizeError::Scene)?;
                let (mut gait, _) =
                    GaitReport::of_setup(&setup, &b.scene, &Ok(b.gait.clone()), false);
                gait.gait_source = Some(b.source);
                let e = &result.evaluations[b.index];
                Some(Best {
                    index: b.index,
                    parameters: e.parameters.clone(),
                    value: e.value,
                    gait,
                })
            }
            None => None,
        };
        let objective = request.objective;
        Ok(Self {
            scene: scene.name().to_owned(),
            objective,
            sense: objective.sense(),
            parameters: result.parameters,
            constraints: request.constraints.clone(),
            seed: request.seed,
            budget: request.budget,
            method: Method {
                algorithm: "CMA-ES (cmaes crate), IPOP restarts",
                coordinates: "normalised: (value - MIN) / (MAX - MIN)",
                initial_step: request.initial_step,
                bounds: "clipped to the box, ranked with a penalty on the squared distance \
                         outside",
                bound_penalty: BOUND_PENALTY,
                restarts: "a run that stops by itself restarts with twice the population from \
                           the best feasible design",
            },
            default: result.default,
            best,
            history: result.generations.iter().map(|g| g.best_so_far).collect(),
            generations: result.generations,
            runs: result.runs,
            evaluations: result.evaluations,
        })
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
    use super::*;

    fn flag(field: &str) -> String {
        format!("--{}", field.replace('_', "-"))
    }

    fn refusal(options: OptimizeOptions) -> OptimizeOptionError {
        let scene = Scene::load("compass").unwrap();
        options.request(&scene).expect_err("refused")
    }

    #[test]
    fn options_are_read_and_refusals_name_the_option_per_front_end() {
        let scene = Scene::load("compass").unwrap();
        let options = OptimizeOptions {
            vary: vec!["leg_mass_kg=4:6".into()],
            objective: " max_abs_eigenvalue ".into(),
            constraints: vec!["step_period_s<=0.8".into()],
            ..OptimizeOptions::default()
        };
        let request = options.request(&scene).unwrap();
        assert_eq!(request.params[0].min, 4.0);
        assert_eq!(request.objective, Objective::MaxAbsEigenvalue);
        assert_eq!(request.constraints[0].bound, 0.8);
        let e = refusal(OptimizeOptions {
            budget: 0,
            ..OptimizeOptions::default()
        });
        assert_eq!(
            e.message(&flag),
            "--budget must be between 1 and 10000, got 0"
        );
        assert_eq!(e.to_string(), "budget must be between 1 and 10000, got 0");
        let e = refusal(OptimizeOptions {
            vary: vec!["leg_mass_kg=4:6".into()],
            sigma_m: Some(0.001),
            ..OptimizeOptions::default()
        });
        assert_eq!(
            e.message(&flag),
            "--sigma-m is the rough floor of mfpt: give --objective mfpt or an mfpt constraint"
        );
        let e = refusal(OptimizeOptions {
            vary: vec!["leg_mass_kg=6:4".into()],
            ..OptimizeOptions::default()
        });
        assert_eq!(
            e.to_string(),
            "vary `leg_mass_kg=6:4`: MIN 6 must be below MAX 4"
        );
        let e = refusal(OptimizeOptions {
            vary: vec!["leg_com_from_hip_m=-1:0.5".into()],
            ..OptimizeOptions::default()
        });
        assert!(e.scene_error().is_some(), "{e}");
        let e = refusal(OptimizeOptions {
            vary: vec!["nope=0:1".into()],
            ..OptimizeOptions::default()
        });
        assert!(matches!(e, OptimizeOptionError::UnknownParameter(_)), "{e}");
    }
}
