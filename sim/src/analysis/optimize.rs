//! Design optimisation: CMA-ES over a scene's parameters, every candidate's gait found by the
//! one gait rule ([`GaitRule`], as `walker gait` finds it), for an [`Objective`] of the gait
//! (the gait sensitivity norm, the largest |eigenvalue|, the cost of transport, ...) under
//! [`Constraint`]s on its quantities.
//!
//! # The search
//! CMA-ES (Hansen's covariance matrix adaptation evolution strategy, the `cmaes` crate) runs
//! in **normalised coordinates**: each varied parameter `p ∈ [MIN, MAX]` is `u = (p − MIN) /
//! (MAX − MIN) ∈ [0, 1]`. The first run starts at the scene's design (its values, clamped to
//! the box) with step size [`OptimizeSettings::initial_step`] (default [`INITIAL_STEP`]) and
//! the default population `4 + ⌊3 ln n⌋`. When a run stops by itself (its spread of values or
//! of points has collapsed, ...) the search is restarted with twice the population (IPOP,
//! Auger & Hansen 2005), from the best feasible design so far, at the initial step size. Every
//! run's random draws come from `--seed` (run `k` is seeded by [`run_seed`]); each generation
//! is evaluated in parallel (rayon) in the order CMA-ES drew it, and listed in CMA-ES's ranking
//! (ties by their coordinates): the same seed gives the same search, bit for
//! bit, whatever the number of threads.
//!
//! # The budget
//! `budget` is the number of candidates evaluated, exactly: a generation that no longer fits
//! is drawn with a population of what is left (from the current mean and step size, an
//! isotropic last generation), and a single evaluation left over is spent on the
//! distribution's mean. The scene's own design is evaluated once more, outside the budget, to
//! compare with.
//!
//! # Bounds
//! A candidate outside the box is **clipped and penalised**: its design is the nearest point of
//! the box (that design is what is evaluated and recorded), and CMA-ES ranks it by its value
//! plus [`BOUND_PENALTY`] times the squared distance (normalised) it lay outside. A design on
//! the boundary can so be the optimum, and the search is pushed back inside.
//!
//! # Infeasible candidates
//! A candidate whose gait is not found (or whose search spends its budget of strides, or whose
//! stride fails), whose gait is unstable (`max |λ| ≥ 1`), whose objective is undefined, or that
//! violates a constraint is **infeasible**: recorded with a typed [`Infeasibility`] and
//! ranked behind every feasible candidate, the ones with a gait by how far they are from being
//! feasible (`max |λ|` beyond 1, the relative violation of the constraints), those without
//! one by their distance from the start design, so CMA-ES moves back to where gaits are found.
//! The run never stops on one.

use crate::analysis::homotopy::{GaitRule, GaitSource, HomotopySettings, SetupFor};
use crate::analysis::limit_cycle::{Gait, NewtonError, NewtonSettings};
pub use crate::analysis::quantity::{Quantity, QuantityError, QuantityOptions};
use crate::scene::{Scene, SceneError, Setup};
use nalgebra::DVector;
use rayon::prelude::*;
use serde::{Deserialize, Serialize, Serializer};
use std::collections::{BTreeMap, HashMap};
use std::sync::Mutex;

/// The default initial step size of CMA-ES in normalised coordinates (a quarter of each
/// range; [`OptimizeSettings::initial_step`]).
pub const INITIAL_STEP: f64 = 0.25;

/// The weight of the squared distance (normalised) a candidate lay outside the box.
pub const BOUND_PENALTY: f64 = 100.0;

/// The rank of a candidate whose gait was found but is infeasible (unstable, a constraint
/// violated, objective undefined), before its measure of infeasibility is added.
const INFEASIBLE_WITH_GAIT: f64 = 1e6;

/// The rank of a candidate without a gait, before its distance from the start is added.
const INFEASIBLE_WITHOUT_GAIT: f64 = 1e9;

pub use crate::analysis::quantity::GSN_PERTURBATION;

/// Whether an objective is minimised or maximised.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Sense {
    /// Smaller is better.
    Minimise,
    /// Larger is better.
    Maximise,
}

/// What is optimised: a quantity of the gait, minimised or maximised.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Objective {
    /// The gait sensitivity norm, minimised.
    Gsn,
    /// The largest step down survived, maximised.
    StepDown,
    /// The largest |eigenvalue|, minimised.
    MaxAbsEigenvalue,
    /// The mean first-passage time on a rough floor, maximised.
    Mfpt,
    /// The cost of transport, minimised.
    CostOfTransport,
}

impl Objective {
    /// Every objective.
    pub const ALL: [Self; 5] = [
        Self::Gsn,
        Self::StepDown,
        Self::MaxAbsEigenvalue,
        Self::Mfpt,
        Self::CostOfTransport,
    ];

    /// The gait quantity it is.
    pub fn quantity(self) -> Quantity {
        match self {
            Self::Gsn => Quantity::Gsn,
            Self::StepDown => Quantity::StepDown,
            Self::MaxAbsEigenvalue => Quantity::MaxAbsEigenvalue,
            Self::Mfpt => Quantity::Mfpt,
            Self::CostOfTransport => Quantity::CostOfTransport,
        }
    }

    /// Whether smaller or larger is better.
    pub fn sense(self) -> Sense {
        match self {
            Self::StepDown | Self::Mfpt => Sense::Maximise,
            Self::Gsn | Self::MaxAbsEigenvalue | Self::CostOfTransport => Sense::Minimise,
        }
    }

    /// Its name.
    pub fn name(self) -> &'static str {
        self.quantity().name()
    }

    /// The objective named `name`.
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|o| o.name() == name)
    }

    /// Its value at `gait` ([`Quantity::evaluate`]).
    ///
    /// # Errors
    /// As [`Quantity::evaluate`].
    pub fn evaluate(
        self,
        setup: &Setup,
        gait: &Gait,
        options: &QuantityOptions,
    ) -> Result<f64, QuantityError> {
        self.quantity().evaluate(setup, gait, options)
    }

    /// `value` as CMA-ES minimises it (negated when maximised).
    fn minimised(self, value: f64) -> f64 {
        match self.sense() {
            Sense::Minimise => value,
            Sense::Maximise => -value,
        }
    }

    /// Whether `a` is better than `b`.
    pub fn better(self, a: f64, b: f64) -> bool {
        self.minimised(a) < self.minimised(b)
    }
}

impl Serialize for Objective {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.name())
    }
}

/// Which side of its bound a constrained quantity must stay.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Relation {
    /// `quantity <= bound`.
    #[serde(rename = "<=")]
    AtMost,
    /// `quantity >= bound`.
    #[serde(rename = ">=")]
    AtLeast,
}

/// A constraint on a quantity of the gait: `NAME<=V` or `NAME>=V`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Constraint {
    /// The constrained quantity.
    pub quantity: Quantity,
    /// `<=` or `>=`.
    pub relation: Relation,
    /// The bound.
    pub bound: f64,
}

/// A constraint that could not be read.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("constraint `{text}`: {why}")]
pub struct ConstraintParseError {
    /// What was given.
    pub text: String,
    /// What is wrong, in words.
    pub why: String,
}

impl Constraint {
    /// Reads `NAME<=V` or `NAME>=V`.
    ///
    /// # Errors
    /// No relation, an unknown quantity, a bound that is not a finite number.
    pub fn parse(text: &str) -> Result<Self, ConstraintParseError> {
        let bad = |why: String| ConstraintParseError {
            text: text.to_owned(),
            why,
        };
        let (name, relation, bound) = if let Some((n, b)) = text.split_once("<=") {
            (n, Relation::AtMost, b)
        } else if let Some((n, b)) = text.split_once(">=") {
            (n, Relation::AtLeast, b)
        } else {
            return Err(bad("expected NAME<=V or NAME>=V".to_owned()));
        };
        let name = name.trim();
        let quantity = Quantity::parse(name).ok_or_else(|| {
            bad(format!(
                "unknown quantity `{name}` (expected one of {})",
                Quantity::ALL.map(Quantity::name).join(", ")
            ))
        })?;
        let bound = bound
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|b| b.is_finite())
            .ok_or_else(|| bad(format!("bound `{}` is not a finite number", bound.trim())))?;
        Ok(Self {
            quantity,
            relation,
            bound,
        })
    }

    /// How far `value` is beyond the bound, relative to the bound's size (0 when satisfied).
    pub fn violation(&self, value: f64) -> f64 {
        let excess = match self.relation {
            Relation::AtMost => value - self.bound,
            Relation::AtLeast => self.bound - value,
        };
        if excess > 0.0 {
            excess / self.bound.abs().max(1e-12)
        } else if excess.is_nan() {
            f64::INFINITY
        } else {
            0.0
        }
    }
}

impl std::fmt::Display for Constraint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let r = match self.relation {
            Relation::AtMost => "<=",
            Relation::AtLeast => ">=",
        };
        write!(f, "{}{r}{}", self.quantity, self.bound)
    }
}

/// A parameter the search varies, within `[min, max]`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct VariedParameter {
    /// The parameter's name (canonical).
    pub name: String,
    /// Lower bound.
    pub min: f64,
    /// Upper bound.
    pub max: f64,
}

impl VariedParameter {
    /// The value at normalised coordinate `u` (0 at `min`, 1 at `max`).
    pub fn value(&self, u: f64) -> f64 {
        self.min + u * (self.max - self.min)
    }

    /// The normalised coordinate of `value`.
    pub fn normalised(&self, value: f64) -> f64 {
        (value - self.min) / (self.max - self.min)
    }
}

/// Why a candidate is infeasible.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Infeasibility {
    /// The gait rule found no gait.
    NoGait,
    /// The gait search spent its budget of strides (`--max-strides`).
    SearchBudgetSpent,
    /// A stride the objective or a constraint needed failed.
    StrideFailed,
    /// The gait is unstable: `max |λ| ≥ 1`.
    Unstable,
    /// The objective has no value here.
    ObjectiveUndefined,
    /// A constraint is violated.
    ConstraintViolated,
}

/// One evaluated design.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Evaluation {
    /// Its place in the list of evaluations (0 first; the scene's design has none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub index: Option<usize>,
    /// The generation it belongs to (counted over every run from 0; none for the scene's
    /// design).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub generation: Option<usize>,
    /// The design: every varied parameter's value.
    pub parameters: BTreeMap<String, f64>,
    /// The candidate as CMA-ES drew it, in normalised coordinates (may lie outside [0, 1]:
    /// then the design is its nearest point of the box).
    pub normalised: Vec<f64>,
    /// How far (normalised, Euclidean) the candidate lay outside the box.
    pub outside_bounds: f64,
    /// The objective's value at the design (`null` where it was not computed: no gait, an
    /// unstable gait, an undefined objective).
    pub value: Option<f64>,
    /// Whether the design is feasible (a stable gait, the objective defined, every constraint
    /// met).
    pub feasible: bool,
    /// Why it is not (`null` when feasible).
    pub reason: Option<Infeasibility>,
    /// The reason in words.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub detail: Option<String>,
    /// What CMA-ES ranked (minimised): the objective (negated when maximised) plus the bound
    /// penalty, or the rank of an infeasible candidate.
    pub fitness: f64,
    /// Where the gait came from, as `walker gait`'s `gait_source` (`null`: no gait).
    pub gait_source: Option<GaitSource>,
    /// The gait's largest |eigenvalue| (`null`: no gait).
    pub max_abs_eigenvalue: Option<f64>,
    /// The constrained quantities' values at the gait, by name (those computed).
    pub constrained: BTreeMap<String, f64>,
}

/// One generation of the search.
#[derive(Clone, Debug, Serialize)]
pub struct Generation {
    /// Counted over every run, from 0.
    pub generation: usize,
    /// The run it belongs to (0 the first; each restart, and the last short generation, a new
    /// one).
    pub run: usize,
    /// Candidates in it.
    pub population: usize,
    /// The best feasible value in it (`null`: none feasible).
    pub best_value: Option<f64>,
    /// The best feasible value so far.
    pub best_so_far: Option<f64>,
    /// Its feasible candidates.
    pub feasible: usize,
    /// Evaluations so far.
    pub evaluations: usize,
    /// The step size (normalised) it was drawn with.
    pub sigma: f64,
}

/// The best design and its gait.
#[derive(Clone, Debug)]
pub struct BestDesign {
    /// Its index in [`OptimizeResult::evaluations`].
    pub index: usize,
    /// The scene at the design.
    pub scene: Scene,
    /// Its gait (by the gait rule).
    pub gait: Gait,
    /// Where the gait came from.
    pub source: GaitSource,
}

/// The outcome of a search.
#[derive(Clone, Debug)]
pub struct OptimizeResult {
    /// What was varied.
    pub parameters: Vec<VariedParameter>,
    /// The scene's own design, evaluated outside the budget.
    pub default: Evaluation,
    /// Every candidate, generation by generation; in each generation in the order CMA-ES
    /// ranked them (best first).
    pub evaluations: Vec<Evaluation>,
    /// Every generation.
    pub generations: Vec<Generation>,
    /// The best feasible candidate (`None`: none was feasible).
    pub best: Option<BestDesign>,
    /// Runs of CMA-ES (1 + restarts, counting the last short generation as a run).
    pub runs: usize,
}

/// How a search runs.
pub struct OptimizeSettings<'a> {
    /// What it varies.
    pub params: &'a [VariedParameter],
    /// What it optimises.
    pub objective: Objective,
    /// What every feasible design must meet.
    pub constraints: &'a [Constraint],
    /// Candidates evaluated (at least 1).
    pub budget: usize,
    /// The seed of every random draw.
    pub seed: u64,
    /// CMA-ES's initial step size in normalised coordinates (0 < · ≤ 1; default
    /// [`INITIAL_STEP`]); each restart starts with it again. Smaller for a design whose gait
    /// is found only near the start.
    pub initial_step: f64,
    /// Builds the setup at each design (the caller's solver overrides).
    pub setup_for: &'a SetupFor<'a>,
    /// The fixed-point search.
    pub newton: &'a NewtonSettings,
    /// How the defaults' gait is followed (and the gait's budget of strides).
    pub homotopy: &'a HomotopySettings,
    /// What the quantities need besides the gait (the rough floor of `mfpt`).
    pub quantity_options: QuantityOptions,
}

/// A search that cannot run.
#[derive(Debug, thiserror::Error)]
pub enum OptimizeError {
    /// The scene refuses a parameter or a bound, or cannot be built.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The objective or a constrained quantity cannot be had as asked (`mfpt` without its
    /// rough floor).
    #[error("{what} {quantity}: {why}")]
    Quantity {
        /// `objective` or `constraint`.
        what: &'static str,
        /// The quantity.
        quantity: Quantity,
        /// Why.
        why: QuantityError,
    },
    /// The initial step size is not above 0 and at most 1.
    #[error("the initial step must be above 0 and at most 1 (normalised), got {0}")]
    InitialStep(f64),
    /// Anything else wrong with the request.
    #[error("{0}")]
    Invalid(String),
}

/// The seed of run `run` of a search seeded `seed` (a SplitMix64 step, so runs draw apart).
pub fn run_seed(seed: u64, run: usize) -> u64 {
    let mut z = seed.wrapping_add((run as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Checks a request before any gait is searched: every parameter known and once, bounds
/// ordered and inside the scene's ranges, the objective and constraints available, a budget.
///
/// # Errors
/// What is wrong, in words.
pub fn check(scene: &Scene, settings: &OptimizeSettings<'_>) -> Result<(), OptimizeError> {
    if settings.params.is_empty() {
        return Err(OptimizeError::Invalid(
            "nothing to vary (give at least one NAME=MIN:MAX)".to_owned(),
        ));
    }
    if !(settings.initial_step > 0.0 && settings.initial_step <= 1.0) {
        return Err(OptimizeError::InitialStep(settings.initial_step));
    }
    if settings.budget == 0 {
        return Err(OptimizeError::Invalid(
            "the budget must be at least 1 evaluation".to_owned(),
        ));
    }
    let mut check = scene.clone();
    for (i, p) in settings.params.iter().enumerate() {
        if !(p.min.is_finite() && p.max.is_finite()) || p.min >= p.max {
            return Err(OptimizeError::Invalid(format!(
                "`{}`: min {} must be below max {} (both finite)",
                p.name, p.min, p.max
            )));
        }
        if settings.params[..i].iter().any(|q| q.name == p.name) {
            return Err(OptimizeError::Invalid(format!(
                "parameter `{}` given twice (each parameter once)",
                p.name
            )));
        }
        check.set(&p.name, p.min)?;
        check.set(&p.name, p.max)?;
    }
    let asked = std::iter::once(("objective", settings.objective.quantity())).chain(
        settings
            .constraints
            .iter()
            .map(|c| ("constraint", c.quantity)),
    );
    for (what, quantity) in asked {
        quantity
            .check(&settings.quantity_options)
            .map_err(|why| OptimizeError::Quantity {
                what,
                quantity,
                why,
            })?;
    }
    let wants_cost = settings.objective.quantity() == Quantity::CostOfTransport
        || settings
            .constraints
            .iter()
            .any(|c| c.quantity == Quantity::CostOfTransport);
    if wants_cost && (settings.setup_for)(scene)?.walker.ankle().is_none() {
        return Err(OptimizeError::Invalid(format!(
            "cost_of_transport: scene `{}` has no actuated ankle (its energy comes from the \
             slope); `walker gait` reports a cost of transport for actuated walkers only",
            scene.name()
        )));
    }
    Ok(())
}

/// Evaluates designs: the gait rule, the objective, the constraints.
struct Evaluator<'a> {
    scene: &'a Scene,
    settings: &'a OptimizeSettings<'a>,
    rule: GaitRule<'a>,
    start: Vec<f64>,
    on_evaluation: &'a (dyn Fn() + Sync),
}

impl<'a> Evaluator<'a> {
    /// The evaluator of the search `settings` from `scene`'s design.
    fn new(
        scene: &'a Scene,
        settings: &'a OptimizeSettings<'a>,
        on_evaluation: &'a (dyn Fn() + Sync),
    ) -> Self {
        let start = settings
            .params
            .iter()
            .map(|p| {
                p.normalised(scene.values.get(&p.name).copied().unwrap_or(p.min))
                    .clamp(0.0, 1.0)
            })
            .collect();
        Self {
            scene,
            settings,
            rule: GaitRule::new(settings.setup_for, settings.newton, settings.homotopy),
            start,
            on_evaluation,
        }
    }

    /// The designs CMA-ES drew (normalised), evaluated in parallel, in the order drawn.
    fn evaluate_drawn(&self, drawn: &[Vec<f64>]) -> Result<Vec<Evaluation>, SceneError> {
        drawn.par_iter().map(|u| self.candidate(u)).collect()
    }

    /// The design at normalised `u` (clipped to the box), evaluated.
    fn candidate(&self, u: &[f64]) -> Result<Evaluation, SceneError> {
        let clipped: Vec<f64> = u.iter().map(|x| x.clamp(0.0, 1.0)).collect();
        let outside = u
            .iter()
            .zip(&clipped)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            .sqrt();
        let scene = self.design(&clipped)?;
        let from_start = clipped
            .iter()
            .zip(&self.start)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>();
        let mut e = self.evaluate(scene, u.to_vec(), outside, from_start)?;
        (self.on_evaluation)();
        e.fitness += BOUND_PENALTY * outside * outside;
        Ok(e)
    }

    /// The scene at the design `clipped` (normalised, inside the box).
    fn design(&self, clipped: &[f64]) -> Result<Scene, SceneError> {
        let mut scene = self.scene.clone();
        for (p, c) in self.settings.params.iter().zip(clipped) {
            // The ends exactly: `min + 1 (max - min)` need not round to `max`.
            let v = if *c <= 0.0 {
                p.min
            } else if *c >= 1.0 {
                p.max
            } else {
                p.value(*c).clamp(p.min, p.max)
            };
            scene.set(&p.name, v)?;
        }
        Ok(scene)
    }

    /// Evaluates `scene`'s design (drawn as `normalised`, `outside` the box by so much,
    /// squared distance `from_start` from the start once clipped).
    fn evaluate(
        &self,
        scene: Scene,
        normalised: Vec<f64>,
        outside: f64,
        from_start: f64,
    ) -> Result<Evaluation, SceneError> {
        let objective = self.settings.objective;
        let parameters = self
            .settings
            .params
            .iter()
            .map(|p| {
                (
                    p.name.clone(),
                    scene.values.get(&p.name).copied().unwrap_or(0.0),
                )
            })
            .collect();
        let mut e = Evaluation {
            index: None,
            generation: None,
            parameters,
            normalised,
            outside_bounds: outside,
            value: None,
            feasible: false,
            reason: None,
            detail: None,
            fitness: INFEASIBLE_WITHOUT_GAIT + from_start,
            gait_source: None,
            max_abs_eigenvalue: None,
            constrained: BTreeMap::new(),
        };
        let infeasible = |mut e: Evaluation, why: Infeasibility, detail: String| {
            e.reason = Some(why);
            e.detail = Some(detail);
            Ok(e)
        };
        let (gait, source) = match self.rule.gait(&scene)? {
            Ok(found) => found,
            Err(err) => {
                let why = if err.budget_spent() {
                    Infeasibility::SearchBudgetSpent
                } else {
                    Infeasibility::NoGait
                };
                return infeasible(e, why, no_gait_words(&err));
            }
        };
        let setup = (self.settings.setup_for)(&scene)?;
        let max_abs = gait.max_abs_eigenvalue();
        e.gait_source = Some(source);
        e.max_abs_eigenvalue = Some(max_abs);
        if !gait.stable() {
            e.fitness = INFEASIBLE_WITH_GAIT + max_abs;
            return infeasible(
                e,
                Infeasibility::Unstable,
                format!("the gait is unstable: max |λ| = {max_abs:.6} ≥ 1"),
            );
        }
        let value = match objective.evaluate(&setup, &gait, &self.settings.quantity_options) {
            Ok(v) if v.is_finite() => v,
            Ok(v) => {
                e.fitness = INFEASIBLE_WITH_GAIT + 1.0;
                return infeasible(
                    e,
                    Infeasibility::ObjectiveUndefined,
                    format!("{} is not a finite number ({v})", objective.name()),
                );
            }
            Err(QuantityError::StrideFailed(why)) => {
                e.fitness = INFEASIBLE_WITH_GAIT + 1.0;
                return infeasible(
                    e,
                    Infeasibility::StrideFailed,
                    format!("{}: {why}", objective.name()),
                );
            }
            Err(err) => {
                e.fitness = INFEASIBLE_WITH_GAIT + 1.0;
                return infeasible(e, Infeasibility::ObjectiveUndefined, err.to_string());
            }
        };
        e.value = Some(value);
        let mut violation = 0.0;
        let mut violated: Vec<String> = Vec::new();
        for c in self.settings.constraints {
            let q = if c.quantity == objective.quantity() {
                Ok(value)
            } else if let Some(v) = e.constrained.get(c.quantity.name()) {
                Ok(*v)
            } else {
                c.quantity
                    .evaluate(&setup, &gait, &self.settings.quantity_options)
            };
            match q {
                Ok(v) => {
                    e.constrained.insert(c.quantity.name().to_owned(), v);
                    let d = c.violation(v);
                    if d > 0.0 {
                        violation += d;
                        violated.push(format!("{c} violated: {} = {v}", c.quantity));
                    }
                }
                Err(err) => {
                    violation += 1.0;
                    violated.push(format!("{c}: {err}"));
                }
            }
        }
        if !violated.is_empty() {
            e.fitness = INFEASIBLE_WITH_GAIT + violation.min(1e5);
            return infeasible(e, Infeasibility::ConstraintViolated, violated.join("; "));
        }
        e.feasible = true;
        e.fitness = objective.minimised(value);
        Ok(e)
    }
}

/// Why the gait rule found no gait, in words.
fn no_gait_words(e: &NewtonError) -> String {
    if e.budget_spent() {
        format!("the gait search spent its budget of strides (--max-strides): {e}")
    } else {
        format!("no gait found: {e}")
    }
}

/// The search's state between generations: the list so far and the best.
struct Progress {
    evaluations: Vec<Evaluation>,
    generations: Vec<Generation>,
    /// The best feasible evaluation's index.
    best: Option<usize>,
}

impl Progress {
    /// Appends one generation's candidates (in any order: they are put in CMA-ES's ranking,
    /// ties by their normalised coordinates, so the list is the same whatever the threads).
    fn push(
        &mut self,
        objective: Objective,
        run: usize,
        sigma: f64,
        mut candidates: Vec<Evaluation>,
    ) {
        candidates.sort_by(|a, b| {
            a.fitness.total_cmp(&b.fitness).then_with(|| {
                a.normalised
                    .iter()
                    .zip(&b.normalised)
                    .map(|(x, y)| x.total_cmp(y))
                    .find(|o| o.is_ne())
                    .unwrap_or(std::cmp::Ordering::Equal)
            })
        });
        let generation = self.generations.len();
        let population = candidates.len();
        let mut best_value: Option<f64> = None;
        let mut feasible = 0;
        for mut e in candidates {
            let index = self.evaluations.len();
            e.index = Some(index);
            e.generation = Some(generation);
            if let (true, Some(v)) = (e.feasible, e.value) {
                feasible += 1;
                if best_value.is_none_or(|b| objective.better(v, b)) {
                    best_value = Some(v);
                }
                let better = self.best.is_none_or(|b| {
                    self.evaluations[b]
                        .value
                        .is_none_or(|bv| objective.better(v, bv))
                });
                if better {
                    self.best = Some(index);
                }
            }
            self.evaluations.push(e);
        }
        let best_so_far = self.best.and_then(|b| self.evaluations[b].value);
        self.generations.push(Generation {
            generation,
            run,
            population,
            best_value,
            best_so_far,
            feasible,
            evaluations: self.evaluations.len(),
            sigma,
        });
    }
}

/// Evaluates designs CMA-ES drew, in normalised coordinates: their evaluations in the order
/// given (each as [`evaluate_drawn`] makes it, wherever it runs). [`optimize_with`] calls it
/// once per generation with the candidates not evaluated yet; a cluster's front end sends
/// them to its workers (`walker.studies.optimize(executor="ray")`).
pub type EvaluateDrawn<'a> =
    dyn Fn(&[Vec<f64>]) -> Result<Vec<Evaluation>, OptimizeError> + Sync + 'a;

/// The evaluations of `drawn` (designs in normalised coordinates, as CMA-ES drew them) for the
/// search `settings` from `scene`'s design: what [`optimize`] computes for them, bit for bit,
/// in parallel (rayon), `on_evaluation` called after each. A pure function of its arguments:
/// the task of a cluster's worker.
///
/// # Errors
/// A request [`check`] refuses, or a scene that cannot be built at a design.
pub fn evaluate_drawn(
    scene: &Scene,
    settings: &OptimizeSettings<'_>,
    drawn: &[Vec<f64>],
    on_evaluation: &(dyn Fn() + Sync),
) -> Result<Vec<Evaluation>, OptimizeError> {
    check(scene, settings)?;
    if let Some(bad) = drawn.iter().find(|u| u.len() != settings.params.len()) {
        return Err(OptimizeError::Invalid(format!(
            "a design has {} coordinates where {} parameters are varied",
            bad.len(),
            settings.params.len()
        )));
    }
    Ok(Evaluator::new(scene, settings, on_evaluation).evaluate_drawn(drawn)?)
}

impl Evaluation {
    /// The evaluation as CBOR bytes, every number bit for bit (infinities and NaN included):
    /// how a cluster's worker returns it ([`Self::from_cbor`]).
    pub fn to_cbor(&self) -> Vec<u8> {
        let mut out = Vec::new();
        // writing to a Vec cannot fail, and every field serialises
        if ciborium::into_writer(self, &mut out).is_err() {
            out.clear();
        }
        out
    }

    /// The evaluation [`Self::to_cbor`] wrote.
    ///
    /// # Errors
    /// Bytes that are not such an evaluation, in words.
    pub fn from_cbor(bytes: &[u8]) -> Result<Self, OptimizeError> {
        ciborium::from_reader(bytes).map_err(|e| {
            OptimizeError::Invalid(format!("not an evaluation of walker optimize: {e}"))
        })
    }
}

/// The key of a drawn design in the evaluations found so far: its coordinates' bits.
fn drawn_key(u: &[f64]) -> Vec<u64> {
    u.iter().map(|x| x.to_bits()).collect()
}

/// Where one pass of the search ([`search`]) ended.
enum Pass {
    /// Every candidate had its evaluation: the search is done.
    Done(Progress, usize),
    /// These designs (sorted, distinct) of the first generation with a candidate not
    /// evaluated yet.
    Missing(Vec<Vec<f64>>),
}

/// One pass of the search from the start, with the evaluations found so far (`evaluated`,
/// by [`drawn_key`]): CMA-ES's draws depend only on the seed and on the ranks of the earlier
/// generations, so a pass repeats the earlier passes' draws and stops at the first generation
/// it cannot rank (returning its designs), or runs to the end.
fn search(
    settings: &OptimizeSettings<'_>,
    start: &[f64],
    evaluated: &HashMap<Vec<u64>, Evaluation>,
) -> Result<Pass, OptimizeError> {
    let missing: Mutex<Vec<Vec<f64>>> = Mutex::new(Vec::new());
    let outcomes: Mutex<Vec<Evaluation>> = Mutex::new(Vec::new());
    let objective = |x: &DVector<f64>| -> f64 {
        match evaluated.get(&drawn_key(x.as_slice())) {
            Some(e) => {
                if let Ok(mut v) = outcomes.lock() {
                    v.push(e.clone());
                }
                e.fitness
            }
            None => {
                if let Ok(mut m) = missing.lock() {
                    m.push(x.as_slice().to_vec());
                }
                0.0
            }
        }
    };
    let take_missing = || -> Option<Vec<Vec<f64>>> {
        let mut m = missing
            .lock()
            .map(|mut m| std::mem::take(&mut *m))
            .unwrap_or_default();
        if m.is_empty() {
            return None;
        }
        m.sort_by_cached_key(|u| drawn_key(u));
        m.dedup_by(|a, b| drawn_key(a) == drawn_key(b));
        Some(m)
    };
    let take = || -> Vec<Evaluation> {
        outcomes
            .lock()
            .map(|mut v| std::mem::take(&mut *v))
            .unwrap_or_default()
    };
    let n = settings.params.len();
    let mut state = Progress {
        evaluations: Vec::with_capacity(settings.budget),
        generations: Vec::new(),
        best: None,
    };
    let lambda0 = 4 + (3.0 * (n as f64).ln()).floor() as usize;
    let (mut run, mut lambda) = (0, lambda0);
    let (mut mean, mut sigma) = (start.to_vec(), settings.initial_step);
    let mut remaining = settings.budget;
    while remaining >= 2 {
        let population = lambda.min(remaining);
        let mut cma = cmaes::CMAESOptions::new(mean.clone(), sigma)
            .population_size(population)
            .seed(run_seed(settings.seed, run))
            .build(&objective)
            .map_err(|e| OptimizeError::Invalid(format!("CMA-ES refused its options: {e:?}")))?;
        let mut stopped = false;
        while remaining >= population {
            let drawn_with = cma.sigma();
            let stop = cma.next_parallel();
            if let Some(m) = take_missing() {
                return Ok(Pass::Missing(m));
            }
            let candidates = take();
            remaining -= candidates.len().min(remaining);
            state.push(settings.objective, run, drawn_with, candidates);
            if stop.is_some() {
                stopped = true;
                break;
            }
        }
        run += 1;
        if stopped {
            // IPOP: twice the population, from the best design so far, at the first step.
            lambda *= 2;
            mean = state.best.map_or_else(
                || start.to_vec(),
                |b| {
                    state.evaluations[b]
                        .normalised
                        .iter()
                        .map(|u| u.clamp(0.0, 1.0))
                        .collect()
                },
            );
            sigma = settings.initial_step;
        } else {
            // A last, shorter generation from where this run is.
            mean = cma.mean().as_slice().to_vec();
            sigma = cma.sigma();
            lambda = remaining;
        }
    }
    if remaining == 1 {
        // One evaluation left: the distribution's mean.
        match evaluated.get(&drawn_key(&mean)) {
            Some(e) => state.push(settings.objective, run, 0.0, vec![e.clone()]),
            None => return Ok(Pass::Missing(vec![mean])),
        }
        run += 1;
    }
    Ok(Pass::Done(state, run))
}

/// Optimises `settings.objective` over `settings.params` from `scene`'s design (see the
/// [module docs](self)), calling `on_evaluation` after each evaluation (from any thread): the
/// scene's own design first, then every candidate, `budget + 1` calls in all. The calls have
/// no effect on the search.
///
/// # Errors
/// A request [`check`] refuses, or a scene that cannot be built at a design.
pub fn optimize(
    scene: &Scene,
    settings: &OptimizeSettings<'_>,
    on_evaluation: &(dyn Fn() + Sync),
) -> Result<OptimizeResult, OptimizeError> {
    optimize_with(scene, settings, on_evaluation, None)
}

/// [`optimize`] with each generation's new candidates evaluated by `evaluate` (a cluster's
/// workers) instead of on this machine's threads: the same search, bit for bit, since an
/// evaluation is a pure function of its design ([`evaluate_drawn`]). `on_evaluation` hears of
/// the evaluations made here (the scene's design, and the candidates when `evaluate` is
/// `None`). The search is repeated from its start for each generation (the candidates CMA-ES
/// draws depend only on the seed and the earlier generations' ranks; the `cmaes` crate
/// evaluates inside its step, so a pass stops at the first generation not evaluated yet, its
/// candidates are evaluated, and the next pass ranks them): CMA-ES's own work grows with the
/// square of the generations, microseconds each against a gait's milliseconds.
///
/// # Errors
/// A request [`check`] refuses, a scene that cannot be built at a design, or `evaluate`'s
/// error (or its answer for another number of designs).
pub fn optimize_with(
    scene: &Scene,
    settings: &OptimizeSettings<'_>,
    on_evaluation: &(dyn Fn() + Sync),
    evaluate: Option<&EvaluateDrawn<'_>>,
) -> Result<OptimizeResult, OptimizeError> {
    check(scene, settings)?;
    let params = settings.params;
    let evaluator = Evaluator::new(scene, settings, &|| {});
    // The scene's own design, as given (it may lie outside the box).
    let given: Vec<f64> = params
        .iter()
        .map(|p| p.normalised(scene.values.get(&p.name).copied().unwrap_or(p.min)))
        .collect();
    let default = evaluator.evaluate(scene.clone(), given, 0.0, 0.0)?;
    on_evaluation();
    let evaluator = Evaluator {
        on_evaluation,
        ..evaluator
    };
    let mut evaluated: HashMap<Vec<u64>, Evaluation> = HashMap::new();
    // Each pass evaluates at least one design, and a search evaluates `budget` designs: at
    // most `budget + 1` passes.
    for _ in 0..=settings.budget {
        let drawn = match search(settings, &evaluator.start, &evaluated)? {
            Pass::Done(state, runs) => {
                return finish(&evaluator, params, default, state, runs);
            }
            Pass::Missing(drawn) => drawn,
        };
        let found = match evaluate {
            Some(f) => f(&drawn)?,
            None => evaluator.evaluate_drawn(&drawn)?,
        };
        if found.len() != drawn.len() {
            return Err(OptimizeError::Invalid(format!(
                "{} evaluations for {} designs",
                found.len(),
                drawn.len()
            )));
        }
        for (u, e) in drawn.iter().zip(found) {
            if drawn_key(&e.normalised) != drawn_key(u) {
                return Err(OptimizeError::Invalid(
                    "an evaluation of another design than the one sent".to_owned(),
                ));
            }
            evaluated.insert(drawn_key(u), e);
        }
    }
    Err(OptimizeError::Invalid(
        "the search did not end within its budget of passes".to_owned(),
    ))
}

/// The result of a finished search: the best design's gait found again (the gait rule
/// gives the same gait for the same design, wherever the design was evaluated).
fn finish(
    evaluator: &Evaluator<'_>,
    params: &[VariedParameter],
    default: Evaluation,
    state: Progress,
    runs: usize,
) -> Result<OptimizeResult, OptimizeError> {
    let best = match state.best {
        Some(index) => {
            let clipped: Vec<f64> = state.evaluations[index]
                .normalised
                .iter()
                .map(|u| u.clamp(0.0, 1.0))
                .collect();
            let scene = evaluator.design(&clipped)?;
            let (gait, source) = evaluator.rule.gait(&scene)?.map_err(|e| {
                OptimizeError::Invalid(format!("the best design's gait was not found again: {e}"))
            })?;
            Some(BestDesign {
                index,
                scene,
                gait,
                source,
            })
        }
        None => None,
    };
    Ok(OptimizeResult {
        parameters: params.to_vec(),
        default,
        evaluations: state.evaluations,
        generations: state.generations,
        best,
        runs,
    })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn constraints_read_both_relations_and_refuse_the_rest() {
        let c = Constraint::parse("speed_m_s>=0.3").unwrap();
        assert_eq!(c.quantity, Quantity::SpeedMS);
        assert_eq!(c.relation, Relation::AtLeast);
        assert_eq!(c.bound, 0.3);
        assert_eq!(c.violation(0.4), 0.0);
        assert!((c.violation(0.15) - 0.5).abs() < 1e-12);
        let c = Constraint::parse(" max_abs_eigenvalue <= 0.5 ").unwrap();
        assert_eq!(c.relation, Relation::AtMost);
        assert_eq!(c.to_string(), "max_abs_eigenvalue<=0.5");
        for bad in ["speed_m_s=0.3", "speed<=1", "gsn<=x", "gsn<=inf", "<=1"] {
            assert!(Constraint::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn objectives_know_their_sense_and_names() {
        for o in Objective::ALL {
            assert_eq!(Objective::parse(o.name()), Some(o));
        }
        assert_eq!(Objective::StepDown.sense(), Sense::Maximise);
        assert_eq!(Objective::Gsn.sense(), Sense::Minimise);
        assert!(Objective::Mfpt.better(2.0, 1.0));
        assert!(Objective::Gsn.better(1.0, 2.0));
        assert_eq!(Objective::StepDown.quantity(), Quantity::StepDown);
    }

    #[test]
    fn run_seeds_differ_and_repeat() {
        assert_eq!(run_seed(0, 0), run_seed(0, 0));
        assert_ne!(run_seed(0, 0), run_seed(0, 1));
        assert_ne!(run_seed(0, 0), run_seed(1, 0));
    }
}
