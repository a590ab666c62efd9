//! Following a gait along a path in parameter space, and the scene's nominal gait: the one
//! implementation of the guarded secant step ([`Secant`]) and of the homotopy from a scene's
//! defaults ([`follow`]), which both finding a start point ([`crate::analysis::census`],
//! [`nominal_gait`]) and following a branch ([`crate::analysis::continuation`], the stability map's
//! rows) use. A leaf of the analysis layer: it depends on the stride map's Newton search and
//! the scene only.
//!
//! The homotopy follows a gait of the scene at its default values (where its guess is known
//! to work) to the requested values along the straight path
//! `p(s) = p_default + s (p_requested − p_default)`, `s` from 0 to 1, by guarded secant steps
//! (a corrector step longer than [`HomotopySettings::max_correction`] or a period change
//! beyond [`HomotopySettings::max_period_change`] is refused as a jump to another branch) and
//! step halving.

use crate::analysis::limit_cycle::{FixedPoint, Gait, GaitSearch, NewtonError, NewtonSettings};
use crate::engine::model::CoordIndex;
use crate::engine::walker::Walker;
use crate::scene::{Scene, SceneError, Setup};
use crate::stride::{SearchBudget, SharedBudget};
use nalgebra::{DMatrix, DVector};
use std::sync::Arc;

/// Builds the [`Setup`] of a scene at given parameter values: `Scene::setup` and whatever
/// solver settings the caller overrides (the CLI's `--integrator`, `--rtol`, `--step-s`).
pub type SetupFor<'a> = dyn Fn(&Scene) -> Result<Setup, SceneError> + Sync + 'a;

/// How a gait is followed from the defaults to the requested values ([`follow`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HomotopySettings {
    /// The first step along the path, as a fraction of it (0 < · ≤ 1). The default, 1, tries
    /// the whole path at once and halves the step only when the corrector fails or jumps
    /// (the guards below); every caller (`walker gait`, `gaits`, `sweep`, `orbit-diagram`,
    /// `stability-map`) uses the default, so they all return the same gait.
    pub first_step: f64,
    /// Smallest step before the path is given up, as a fraction of it.
    pub min_step: f64,
    /// Largest accepted corrector step, relative: the ∞-norm of the change of the stride-map
    /// vector from the predictor over `1 + |predictor|∞`; a longer one is taken as a jump to
    /// another branch and the step halved.
    pub max_correction: f64,
    /// Largest accepted relative change of the step period in one step; a larger one is
    /// taken as a jump to another branch (the simplest walker's two gaits differ by 25 %).
    pub max_period_change: f64,
    /// Newton searches allowed along one path.
    pub max_solves: usize,
    /// Newton's tolerance at the path's intermediate gaits (at most the caller's looser one):
    /// they only predict the next, and a corrector converged there to the caller's tolerance
    /// (1e-11 by default, near the stride map's noise floor for the 3D walker) spends its
    /// iterations on digits the next predictor discards. The path's end is converged to the
    /// caller's tolerance.
    pub path_tolerance: f64,
    /// Newton iterations allowed in one step (at most the caller's own budget): from a good
    /// predictor Newton converges in a few; more means the step is too long, and halving it
    /// is cheaper than iterating on (a failing search of the 3D walker costs seconds).
    pub max_corrector_iterations: usize,
    /// Stalled iterations ([`NewtonSettings::max_stalled_iterations`]) a corrector of
    /// [`follow_to_point`]'s path allows before its step is halved. From a predictor on the
    /// path, an iteration that no halving makes acceptable, or that takes less than a tenth
    /// off the residual, says the step is too long: halving it is cheaper than iterating on
    /// (a failing wisse3d corrector took 50 to 100 strides with three). `walker sweep`'s
    /// natural steps keep the caller's setting.
    pub max_corrector_stalls: usize,
    /// Strides one gait of [`GaitRule`] (and so [`nominal_gait`]) may take over all its
    /// searches: Newton from the guess, the defaults' gait (a budget of its own), the path.
    /// Default [`DEFAULT_GAIT_STRIDE_BUDGET`]; `walker ... --max-strides`.
    pub gait_stride_budget: usize,
}

impl HomotopySettings {
    /// `newton` with its iteration budget cut to [`Self::max_corrector_iterations`].
    pub fn corrector(&self, newton: &NewtonSettings) -> NewtonSettings {
        NewtonSettings {
            max_iterations: newton.max_iterations.min(self.max_corrector_iterations),
            ..*newton
        }
    }
}

impl Default for HomotopySettings {
    fn default() -> Self {
        Self {
            first_step: 1.0,
            min_step: 1.0 / 256.0,
            max_correction: 0.1,
            max_period_change: 0.1,
            max_solves: 24,
            path_tolerance: 1e-8,
            max_corrector_iterations: 12,
            max_corrector_stalls: 1,
            gait_stride_budget: DEFAULT_GAIT_STRIDE_BUDGET,
        }
    }
}

/// The last (at most two) gaits of a path, at path coordinates `s`: a secant predictor, and
/// one guarded Newton step from it.
///
/// The stride map of one model can change its coordinates along a path: a 3D walker's heading
/// is cyclic on level ground and a state on a slope ([`crate::engine::relabel::Relabel`]).
/// A gait in other coordinates than the last one's starts the path afresh (no secant through
/// both), and a predictor is carried into the coordinates of the walker it is corrected on, a
/// coordinate the gait's map lacks at 0 with its rate (the heading of a straight gait).
#[derive(Clone, Debug, Default)]
pub struct Secant {
    /// `(s, fixed point, step period [s])`, oldest first.
    history: Vec<(f64, DVector<f64>, f64)>,
    /// The stride-map coordinates of the gaits in `history`.
    coordinates: Vec<CoordIndex>,
    /// The matrix the last gait's Newton search stepped with (a stride Jacobian near it):
    /// the next corrector's first Newton matrix ([`GaitSearch::converge`]).
    newton_matrix: Option<DMatrix<f64>>,
}

impl Secant {
    /// Appends the gait `g` at `s` (keeps the last two; only `g` when its stride-map
    /// coordinates differ from the last gait's).
    pub fn push(&mut self, s: f64, g: &Gait) {
        self.push_parts(
            s,
            &g.fixed_point,
            g.stride.duration_s,
            &g.map_coordinates,
            Some(&g.jacobian),
        );
    }

    /// [`Self::push`] for a fixed point whose stride Jacobian was not taken.
    pub fn push_point(&mut self, s: f64, p: &FixedPoint) {
        self.push_parts(
            s,
            &p.fixed_point,
            p.stride.duration_s,
            &p.map_coordinates,
            p.newton_matrix.as_ref(),
        );
    }

    fn push_parts(
        &mut self,
        s: f64,
        v: &DVector<f64>,
        period_s: f64,
        coordinates: &[CoordIndex],
        newton_matrix: Option<&DMatrix<f64>>,
    ) {
        if self.coordinates != coordinates {
            self.history.clear();
            self.coordinates = coordinates.to_vec();
        }
        self.history.push((s, v.clone(), period_s));
        if self.history.len() > 2 {
            self.history.remove(0);
        }
        self.newton_matrix = newton_matrix.cloned();
    }

    /// Forgets the path (the next step has no predictor).
    pub fn clear(&mut self) {
        self.history.clear();
        self.newton_matrix = None;
    }

    /// The predictor at `s` (linear through the last two gaits, the last one alone after
    /// the first) and the last gait's step period; `None` before the first gait.
    pub fn predict(&self, s: f64) -> Option<(DVector<f64>, f64)> {
        match self.history.as_slice() {
            [.., (s0, v0, _), (s1, v1, t1)] => Some((v1 + (v1 - v0) * ((s - s1) / (s1 - s0)), *t1)),
            [.., (_, v, t)] => Some((v.clone(), *t)),
            [] => None,
        }
    }

    /// Newton (budget cut to [`HomotopySettings::max_corrector_iterations`]) at `setup` from
    /// the predictor at `s`; the gait is refused as a jump to another branch when the
    /// corrector moved it by more than [`HomotopySettings::max_correction`] (relative) or its
    /// step period changed by more than [`HomotopySettings::max_period_change`]. `None`
    /// before the first gait.
    pub fn step(
        &self,
        s: f64,
        setup: &Setup,
        newton: &NewtonSettings,
        guard: &HomotopySettings,
    ) -> Option<Result<Gait, NewtonError>> {
        let corrector = guard.corrector(newton);
        let search = GaitSearch::new(&setup.walker, &setup.settings, &corrector);
        Some(
            self.correct(s, setup, newton, guard, None)?
                .and_then(|p| search.gait_at(p)),
        )
    }

    /// [`Self::step`] on a path of [`follow_to_point`], without the stride Jacobian at the
    /// gait found ([`GaitSearch::gait_at`] takes it, with [`HomotopySettings::corrector`]'s
    /// settings). An [`PathPoint::Intermediate`] gait is converged to
    /// [`HomotopySettings::path_tolerance`] from the last gait's Newton matrix (when the
    /// coordinates are the same), the [`PathPoint::End`] to the caller's tolerance from a
    /// Jacobian of its own (a chord iteration on an older matrix converges too slowly to
    /// reach a tight tolerance in the corrector's budget); either stops as soon as an iterate
    /// is farther from the predictor than the guard allows (where the corrector would most
    /// likely end refused; one that overshoots and comes back is refused too).
    pub fn step_to_point(
        &self,
        s: f64,
        setup: &Setup,
        newton: &NewtonSettings,
        guard: &HomotopySettings,
        point: PathPoint,
    ) -> Option<Result<FixedPoint, NewtonError>> {
        self.correct(s, setup, newton, guard, Some(point))
    }

    /// The corrector of [`Self::step`] (`point` `None`: the caller's tolerance, a fresh
    /// Jacobian, no early stop) and of [`Self::step_to_point`].
    fn correct(
        &self,
        s: f64,
        setup: &Setup,
        newton: &NewtonSettings,
        guard: &HomotopySettings,
        point: Option<PathPoint>,
    ) -> Option<Result<FixedPoint, NewtonError>> {
        let (predictor, period) = self.predict(s)?;
        let same_coordinates = setup.walker.map_coordinates() == self.coordinates;
        let predictor = in_coordinates(&predictor, &self.coordinates, &setup.walker);
        let corrector = guard.corrector(newton);
        let on_path = NewtonSettings {
            max_stalled_iterations: guard.max_corrector_stalls,
            ..corrector
        };
        let (corrector, start_matrix) = match point {
            Some(PathPoint::Intermediate) => (
                NewtonSettings {
                    tolerance: corrector.tolerance.max(guard.path_tolerance),
                    ..on_path
                },
                self.newton_matrix.clone().filter(|_| same_coordinates),
            ),
            Some(PathPoint::End) => (on_path, None),
            None => (corrector, None),
        };
        let leash = if point.is_some() {
            guard.max_correction * (1.0 + predictor.amax())
        } else {
            f64::INFINITY
        };
        let g = GaitSearch::new(&setup.walker, &setup.settings, &corrector).converge_within(
            &predictor,
            start_matrix,
            leash,
        );
        Some(g.and_then(|g| {
            let moved = (&g.fixed_point - &predictor).amax();
            let jumped = moved > guard.max_correction * (1.0 + predictor.amax())
                || (g.stride.duration_s - period).abs() > guard.max_period_change * period;
            if jumped {
                Err(NewtonError::NotConverged {
                    iterations: g.iterations,
                    last_step: moved,
                })
            } else {
                Ok(g)
            }
        }))
    }
}

/// Which gait of a path [`Secant::step_to_point`] converges.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PathPoint {
    /// One the path goes on from: only the next predictor uses it.
    Intermediate,
    /// The path's end: the gait returned.
    End,
}

/// The stride-map vector `v` (values then rates of `coordinates`) in `walker`'s stride-map
/// coordinates: itself when they are the same; otherwise coordinate by coordinate, one that
/// `coordinates` lacks at 0 with its rate.
fn in_coordinates(v: &DVector<f64>, coordinates: &[CoordIndex], walker: &Walker) -> DVector<f64> {
    let target = walker.map_coordinates();
    if target == coordinates {
        return v.clone();
    }
    let dof = walker.model().dof();
    let n = coordinates.len();
    let mut q = DVector::zeros(dof);
    let mut qd = DVector::zeros(dof);
    for (i, c) in coordinates.iter().enumerate() {
        if c.0 < dof {
            q[c.0] = v[i];
            qd[c.0] = v[n + i];
        }
    }
    walker.pack(&q, &qd)
}

/// The scene at its default parameter values (parameters that act on nothing keep theirs).
pub fn at_defaults(scene: &Scene) -> Result<Scene, SceneError> {
    let mut s = scene.clone();
    for (name, p) in &scene.file.parameters {
        if !scene.is_unused(name) {
            s.set(name, p.default)?;
        }
    }
    Ok(s)
}

/// Whether every parameter of `scene` has its default value.
pub fn is_at_defaults(scene: &Scene) -> bool {
    scene
        .file
        .parameters
        .iter()
        .all(|(name, p)| scene.values.get(name) == Some(&p.default))
}

/// The scene on the straight path from `from` to `to` at fraction `s` (values of `to` at 1).
fn between(from: &Scene, to: &Scene, s: f64) -> Result<Scene, SceneError> {
    let mut scene = to.clone();
    if s >= 1.0 {
        return Ok(scene);
    }
    for (name, &b) in &to.values {
        let a = from.values.get(name).copied().unwrap_or(b);
        if a != b {
            scene.set(name, a + s * (b - a))?;
        }
    }
    Ok(scene)
}

/// Follows the gait `start` of `from` to the parameter values of `to` (see the
/// [module docs](self)): the gait at `to`, or the last Newton error when the path is given up
/// (the branch ends, folds back, or the budget runs out). Also returns the searches run.
pub fn follow(
    from: &Scene,
    to: &Scene,
    setup_for: &SetupFor<'_>,
    start: &Gait,
    newton: &NewtonSettings,
    settings: &HomotopySettings,
) -> (Result<Gait, NewtonError>, usize) {
    let (end, solves) = follow_to_point(from, to, setup_for, start, newton, settings);
    let corrector = settings.corrector(newton);
    let gait = end.and_then(|(p, setup)| {
        GaitSearch::new(&setup.walker, &setup.settings, &corrector).gait_at(p)
    });
    (gait, solves)
}

/// [`follow`] without the stride Jacobian at the end: the fixed point at `to` and the setup it
/// was found on (whose [`GaitSearch`] with [`HomotopySettings::corrector`]'s settings makes it
/// the gait [`follow`] returns, [`GaitSearch::gait_at`]). No eigenvalue Jacobian is taken
/// along the path; each intermediate corrector starts from the Newton matrix of the gait
/// before, the end's from a Jacobian of its own ([`PathPoint`]).
pub fn follow_to_point(
    from: &Scene,
    to: &Scene,
    setup_for: &SetupFor<'_>,
    start: &Gait,
    newton: &NewtonSettings,
    settings: &HomotopySettings,
) -> (Result<(FixedPoint, Setup), NewtonError>, usize) {
    let mut path = Secant::default();
    path.push(0.0, start);
    let mut s = 0.0;
    let mut step = settings.first_step.clamp(settings.min_step, 1.0);
    let mut solves = 0;
    let mut last_error = NewtonError::NotConverged {
        iterations: 0,
        last_step: f64::INFINITY,
    };
    while solves < settings.max_solves && step >= settings.min_step {
        let s_next = (s + step).min(1.0);
        let Ok(setup) = between(from, to, s_next).and_then(|sc| setup_for(&sc)) else {
            step *= 0.5;
            continue;
        };
        solves += 1;
        let point = if s_next < 1.0 {
            PathPoint::Intermediate
        } else {
            PathPoint::End
        };
        match path.step_to_point(s_next, &setup, newton, settings, point) {
            Some(Ok(p)) => {
                if s_next >= 1.0 {
                    return (Ok((p, setup)), solves);
                }
                s = s_next;
                path.push_point(s, &p);
                step = (step * 2.0).min(1.0);
            }
            Some(Err(e)) if e.budget_spent() => return (Err(e), solves),
            Some(Err(e)) => {
                last_error = e;
                // halved from the step actually tried (the last one was cut at the path's end)
                step = 0.5 * (s_next - s);
            }
            None => break,
        }
    }
    (Err(last_error), solves)
}

/// Two fixed points of one scene closer than this (∞-norm, relative to `1 + |v|∞`) are the
/// same gait found twice ([`GaitRule`]): far above Newton's tolerance, far below the distance
/// between two gaits of a scene.
pub const SAME_GAIT_TOLERANCE: f64 = 1e-6;

/// Whether `a` and `b` are the same gait ([`SAME_GAIT_TOLERANCE`]).
fn same_gait(a: &FixedPoint, b: &FixedPoint) -> bool {
    a.map_coordinates == b.map_coordinates
        && (&a.fixed_point - &b.fixed_point).amax()
            <= SAME_GAIT_TOLERANCE * (1.0 + a.fixed_point.amax())
}

/// Where the gait [`nominal_gait`] returns comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GaitSource {
    /// At the scene's defaults: Newton from the scene's guess.
    Defaults,
    /// Off the defaults: Newton from the scene's guess at the requested values (its period is
    /// the longer, or the defaults' gait could not be followed).
    Guess,
    /// Off the defaults: the scene's gait at its defaults continued to the requested values
    /// ([`follow`]).
    ContinuedFromDefaults,
}

impl GaitSource {
    /// In words, for text output.
    pub fn describe(self) -> &'static str {
        match self {
            Self::Defaults => "the scene's gait at its defaults (Newton from its guess)",
            Self::Guess => "Newton from the scene's guess at these values",
            Self::ContinuedFromDefaults => "the scene's gait continued from its defaults",
        }
    }
}

/// The gait `walker gait` reports, the scene's **nominal** gait: at the scene's defaults,
/// Newton from its guess (as ever); elsewhere the longer-period of Newton from the guess and
/// the defaults' gait followed to the requested values ([`follow`]) — the branch of the
/// scene's nominal gait, which for the simplest walker is Garcia's long-period gait, wherever
/// that branch reaches, not only near the guess (when both searches find the same gait,
/// [`SAME_GAIT_TOLERANCE`], it is that branch's: [`GaitSource::ContinuedFromDefaults`]). Two
/// or three Newton searches in the usual case, the stride Jacobian taken of the kept gait
/// only; every period-1 gait is [`crate::analysis::census::census`]'s job. With where it came
/// from. The one rule for "the gait of this scene at these values": every command and study
/// calls it (a study over many values keeps one [`GaitRule`], which finds the defaults' gait
/// once).
///
/// # Errors
/// The scene cannot be built at its values or at its defaults.
pub fn nominal_gait(
    scene: &Scene,
    setup_for: &SetupFor<'_>,
    newton: &NewtonSettings,
    homotopy: &HomotopySettings,
) -> Result<Result<(Gait, GaitSource), NewtonError>, SceneError> {
    GaitRule::new(setup_for, newton, homotopy).gait(scene)
}

/// A scene at its defaults and its gait there (Newton from its guess).
type DefaultsGait = (Scene, Result<Gait, NewtonError>);

/// [`nominal_gait`] for many values of one scene: the defaults' gait is found once, at the
/// first value off the defaults, and kept (for every scene whose defaults are the same scene;
/// another scene's are found afresh). The same gaits as [`nominal_gait`], to the bit.
///
/// Every gait it finds has a budget of strides ([`HomotopySettings::gait_stride_budget`]) for
/// all its searches (Newton from the guess, the defaults' gait
/// when it is found, the path from the defaults); a search that spends it ends with
/// [`NewtonError::budget_spent`]. [`GaitRule::with_budget`] shares one budget among every gait
/// of the rule instead, for a command that finds one gait and shows its progress.
pub struct GaitRule<'a> {
    setup_for: &'a SetupFor<'a>,
    newton: &'a NewtonSettings,
    homotopy: &'a HomotopySettings,
    defaults: std::sync::OnceLock<Result<DefaultsGait, SceneError>>,
    budget: RuleBudget,
}

/// The strides one gait of [`GaitRule`] may take by default: about a minute of wisse3d
/// strides, hundreds of times what its gait takes (a few hundred), and a stop for a search
/// that would run for hours on a large model.
pub const DEFAULT_GAIT_STRIDE_BUDGET: usize = 100_000;

/// Whose budget a gait of [`GaitRule`] spends.
enum RuleBudget {
    /// A fresh budget of this many strides for each gait.
    PerGait(usize),
    /// One budget for every gait of the rule.
    Shared(Arc<SearchBudget>),
}

impl<'a> GaitRule<'a> {
    /// The rule with these solver settings.
    pub fn new(
        setup_for: &'a SetupFor<'a>,
        newton: &'a NewtonSettings,
        homotopy: &'a HomotopySettings,
    ) -> Self {
        Self {
            setup_for,
            newton,
            homotopy,
            defaults: std::sync::OnceLock::new(),
            budget: RuleBudget::PerGait(homotopy.gait_stride_budget),
        }
    }

    /// Every gait of the rule spends `budget` (whose count shows the searches' progress).
    pub fn with_budget(self, budget: Arc<SearchBudget>) -> Self {
        Self {
            budget: RuleBudget::Shared(budget),
            ..self
        }
    }

    /// The scene's gait at its values, and where it came from ([`nominal_gait`]).
    ///
    /// # Errors
    /// The scene cannot be built at its values or at its defaults.
    pub fn gait(
        &self,
        scene: &Scene,
    ) -> Result<Result<(Gait, GaitSource), NewtonError>, SceneError> {
        let fresh = || {
            SharedBudget(Some(match &self.budget {
                RuleBudget::PerGait(n) => Arc::new(SearchBudget::new(*n)),
                RuleBudget::Shared(b) => Arc::clone(b),
            }))
        };
        // The defaults' gait, kept for every later gait, has a budget of its own: it is spent
        // only when that search alone needs more, never by the search beside it.
        let (budget, defaults_budget) = (fresh(), fresh());
        let spending = |budget: &SharedBudget, sc: &Scene| -> Result<Setup, SceneError> {
            let mut setup = (self.setup_for)(sc)?;
            setup.settings.search_budget = budget.clone();
            Ok(setup)
        };
        let budgeted = |sc: &Scene| spending(&budget, sc);
        let defaults_budgeted = |sc: &Scene| spending(&defaults_budget, sc);
        let found = self.gait_within(scene, &budgeted, &defaults_budgeted)?;
        // The gait's settings go on to other strides: without this search's budget.
        Ok(found.map(|(mut g, source)| {
            g.stride_settings.search_budget = SharedBudget::default();
            (g, source)
        }))
    }

    /// [`Self::gait`] with setups built by `setup_for` (which spend the gait's budget), the
    /// defaults' gait by `defaults_setup_for`.
    fn gait_within(
        &self,
        scene: &Scene,
        setup_for: &SetupFor<'_>,
        defaults_setup_for: &SetupFor<'_>,
    ) -> Result<Result<(Gait, GaitSource), NewtonError>, SceneError> {
        let setup = setup_for(scene)?;
        if is_at_defaults(scene) {
            return Ok(setup
                .find_gait(self.newton)
                .map(|g| (g, GaitSource::Defaults)));
        }
        let defaults = at_defaults(scene)?;
        // Both candidates are converged without their stride Jacobians; only the one kept
        // has its Jacobian taken (the other's is the Jacobian's cost wasted).
        let guess_search = GaitSearch::new(&setup.walker, &setup.settings, self.newton);
        let (from_guess, followed) = rayon::join(
            || guess_search.converge(&setup.walker.pack(&setup.guess.q, &setup.guess.qd), None),
            || -> Result<Result<(FixedPoint, Setup), NewtonError>, SceneError> {
                let found;
                let (defaults, gait) = match self.kept_defaults(&defaults, defaults_setup_for)? {
                    Some(kept) => (&kept.0, &kept.1),
                    None => {
                        found = self.defaults_gait(defaults.clone(), defaults_setup_for)?;
                        (&found.0, &found.1)
                    }
                };
                Ok(match gait {
                    Ok(g) => {
                        follow_to_point(defaults, scene, setup_for, g, self.newton, self.homotopy).0
                    }
                    Err(e) => Err(e.clone()),
                })
            },
        );
        let corrector = self.homotopy.corrector(self.newton);
        let guess_gait = |p: FixedPoint| guess_search.gait_at(p).map(|g| (g, GaitSource::Guess));
        let followed_gait = |(p, end): (FixedPoint, Setup)| {
            GaitSearch::new(&end.walker, &end.settings, &corrector)
                .gait_at(p)
                .map(|g| (g, GaitSource::ContinuedFromDefaults))
        };
        Ok(match (from_guess, followed?) {
            // the longer period is kept; should its Jacobian fail, the other
            (Ok(a), Ok(b)) => {
                // the same gait found twice is the defaults' branch (not whichever period
                // rounding made longer)
                if same_gait(&a, &b.0) || b.0.stride.duration_s > a.stride.duration_s {
                    followed_gait(b).or_else(|e| guess_gait(a).map_err(|_| e))
                } else {
                    guess_gait(a).or_else(|e| followed_gait(b).map_err(|_| e))
                }
            }
            (Ok(a), Err(_)) => guess_gait(a),
            (Err(_), Ok(b)) => followed_gait(b),
            // a spent budget is said, whichever search spent it
            (Err(e), Err(f)) if f.budget_spent() && !e.budget_spent() => Err(f),
            (Err(e), Err(_)) => Err(e),
        })
    }

    /// The kept defaults' gait when `defaults` is the scene it was found for (found now at
    /// the first call); `None` when it is another scene's.
    fn kept_defaults(
        &self,
        defaults: &Scene,
        setup_for: &SetupFor<'_>,
    ) -> Result<Option<&DefaultsGait>, SceneError> {
        let kept = self
            .defaults
            .get_or_init(|| self.defaults_gait(defaults.clone(), setup_for))
            .as_ref()
            .map_err(Clone::clone)?;
        Ok((kept.0.name() == defaults.name()
            && kept.0.file == defaults.file
            && kept.0.values == defaults.values)
            .then_some(kept))
    }

    /// The gait of `defaults` (Newton from its guess).
    fn defaults_gait(
        &self,
        defaults: Scene,
        setup_for: &SetupFor<'_>,
    ) -> Result<DefaultsGait, SceneError> {
        let gait = setup_for(&defaults)?.find_gait(self.newton).map(|mut g| {
            g.stride_settings.search_budget = SharedBudget::default();
            g
        });
        Ok((defaults, gait))
    }
}

/// [`nominal_gait`] without its source: "the long-period gait" of `walker gait`, the sweep's
/// first gait, the orbit diagram's seed and the stability map's seeds.
///
/// # Errors
/// The scene cannot be built at its values or at its defaults.
pub fn long_period_gait(
    scene: &Scene,
    setup_for: &SetupFor<'_>,
    newton: &NewtonSettings,
    homotopy: &HomotopySettings,
) -> Result<Result<Gait, NewtonError>, SceneError> {
    Ok(nominal_gait(scene, setup_for, newton, homotopy)?.map(|(g, _)| g))
}
