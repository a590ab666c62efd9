//! Gait census: the distinct period-1 gaits of a scene at given parameter values, and the
//! long-period gait among them.
//!
//! A scene's `guess` is written for its default parameter values; away from them Newton from
//! the guess may converge to another gait (the simplest walker's short-step gait at slope
//! 0.015) or to none. The census therefore combines three searches, each a Newton solve on
//! the stride map ([`GaitSearch`]):
//!
//! 1. **Newton from the guess** at the requested values.
//! 2. **Homotopy from the defaults**: every gait found at the scene's default values (where
//!    the guess is known to work) is followed to the requested values along the straight
//!    path `p(s) = p_default + s (p_requested − p_default)`, `s` from 0 to 1, by the guarded
//!    secant step of [`crate::continuation::Secant`] (a corrector step longer than
//!    [`HomotopySettings::max_correction`] or a period change beyond
//!    [`HomotopySettings::max_period_change`] is refused as a jump to another branch) and
//!    step halving ([`follow`]).
//! 3. **Multi-start** from the guess scaled as a whole and with its rates scaled
//!    ([`CensusSettings::scales`], [`CensusSettings::rate_scales`]), at the defaults (feeding
//!    2) and at the requested values.
//!
//! Converged fixed points closer than [`CensusSettings::distinct_tolerance`] (∞-norm of the
//! stride-map vector) are one gait. The gaits come sorted by step period, longest first.
//!
//! # Budget
//!
//! With `k = 1 + scales + rate_scales` starts, a census runs at most `k` Newton searches at
//! the requested values, `k` at the defaults and, for each distinct gait found at the
//! defaults (at most `k`), at most [`HomotopySettings::max_solves`] along its path; each
//! search is bounded by [`NewtonSettings::max_iterations`] and each stride by the scene's
//! [`crate::stride::StrideSettings`]. The independent searches run in parallel (rayon).

use crate::continuation::Secant;
use crate::limit_cycle::{Gait, GaitGuess, GaitSearch, NewtonError, NewtonSettings};
use crate::scene::{Scene, SceneError, Setup};
use nalgebra::DVector;
use rayon::prelude::*;

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
    /// Newton iterations allowed in one step (at most the caller's own budget): from a good
    /// predictor Newton converges in a few; more means the step is too long, and halving it
    /// is cheaper than iterating on (a failing search of the 3D walker costs seconds).
    pub max_corrector_iterations: usize,
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
            max_corrector_iterations: 12,
        }
    }
}

/// Settings of a census.
#[derive(Clone, Debug, PartialEq)]
pub struct CensusSettings {
    /// Factors applied to the whole guess (coordinates and rates) for extra starts.
    pub scales: Vec<f64>,
    /// Factors applied to the guess's rates only, for extra starts.
    pub rate_scales: Vec<f64>,
    /// Fixed points closer than this (∞-norm) are one gait.
    pub distinct_tolerance: f64,
    /// How gaits are followed from the defaults.
    pub homotopy: HomotopySettings,
}

impl Default for CensusSettings {
    fn default() -> Self {
        Self {
            scales: vec![0.6, 0.8, 0.9, 1.1, 1.25, 1.5],
            rate_scales: vec![0.8, 0.9, 0.95, 1.05, 1.1, 1.2],
            distinct_tolerance: 1e-6,
            homotopy: HomotopySettings::default(),
        }
    }
}

/// The outcome of a census.
#[derive(Clone, Debug)]
pub struct Census {
    /// The distinct gaits at the requested values, longest step period first.
    pub gaits: Vec<Gait>,
    /// Newton searches run (starts and homotopy steps).
    pub searches: usize,
    /// Why the scene's own guess found no gait at the requested values (`None` if it did).
    pub guess_error: Option<NewtonError>,
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
        match path.step(s_next, &setup, newton, settings) {
            Some(Ok(g)) => {
                if s_next >= 1.0 {
                    return (Ok(g), solves);
                }
                s = s_next;
                path.push(s, &g);
                step = (step * 2.0).min(1.0);
            }
            Some(Err(e)) => {
                last_error = e;
                step *= 0.5;
            }
            None => break,
        }
    }
    (Err(last_error), solves)
}

/// The starts of a multi-start search: the guess, the guess scaled as a whole, and the guess
/// with its rates scaled.
fn starts(setup: &Setup, settings: &CensusSettings) -> Vec<DVector<f64>> {
    let g = &setup.guess;
    let pack = |q: DVector<f64>, qd: DVector<f64>| setup.walker.pack(&q, &qd);
    let mut v = vec![pack(g.q.clone(), g.qd.clone())];
    v.extend(settings.scales.iter().map(|&k| pack(&g.q * k, &g.qd * k)));
    v.extend(
        settings
            .rate_scales
            .iter()
            .map(|&k| pack(g.q.clone(), &g.qd * k)),
    );
    v
}

/// Newton from every start, in parallel: the results in the order of the starts.
fn multi_start(
    setup: &Setup,
    newton: &NewtonSettings,
    settings: &CensusSettings,
    on_search: &(dyn Fn() + Sync),
) -> Vec<Result<Gait, NewtonError>> {
    let search = GaitSearch::new(&setup.walker, &setup.settings, newton);
    starts(setup, settings)
        .par_iter()
        .map(|v| {
            let found = search.find(v);
            on_search();
            found
        })
        .collect()
}

/// Adds `g` to `gaits` unless one of them has a fixed point within `tolerance`.
fn add_distinct(gaits: &mut Vec<Gait>, g: Gait, tolerance: f64) {
    let same = |h: &Gait| {
        h.fixed_point.len() == g.fixed_point.len()
            && (&h.fixed_point - &g.fixed_point).amax() < tolerance
    };
    if !gaits.iter().any(same) {
        gaits.push(g);
    }
}

/// Sorts gaits by step period, longest first.
fn sort_by_period(gaits: &mut [Gait]) {
    gaits.sort_by(|a, b| b.stride.duration_s.total_cmp(&a.stride.duration_s));
}

/// Every distinct period-1 gait of `scene` (at its current values) that the searches of the
/// [module docs](self) find, longest step period first.
///
/// # Errors
/// The scene cannot be built at its values or at its defaults.
pub fn census(
    scene: &Scene,
    setup_for: &SetupFor<'_>,
    newton: &NewtonSettings,
    settings: &CensusSettings,
) -> Result<Census, SceneError> {
    census_with_progress(scene, setup_for, newton, settings, &|| {})
}

/// The progress units of a census of `scene` ([`census_with_progress`]): one per multi-start
/// search (at the requested values, and at the defaults when they differ) and one per gait
/// followed from the defaults (at most one per start there).
pub fn census_units(scene: &Scene, settings: &CensusSettings) -> usize {
    let k = 1 + settings.scales.len() + settings.rate_scales.len();
    if is_at_defaults(scene) {
        k
    } else {
        3 * k
    }
}

/// As [`census`], calling `on_unit` after each multi-start search and each followed gait
/// (for a progress bar of [`census_units`]; fewer when fewer gaits are found at the
/// defaults). May be called from several threads at once.
pub fn census_with_progress(
    scene: &Scene,
    setup_for: &SetupFor<'_>,
    newton: &NewtonSettings,
    settings: &CensusSettings,
    on_unit: &(dyn Fn() + Sync),
) -> Result<Census, SceneError> {
    let setup = setup_for(scene)?;
    let here = multi_start(&setup, newton, settings, on_unit);
    let mut searches = here.len();
    let guess_error = here.first().and_then(|r| r.as_ref().err().cloned());
    let mut gaits: Vec<Gait> = Vec::new();
    for g in here.into_iter().flatten() {
        add_distinct(&mut gaits, g, settings.distinct_tolerance);
    }
    if !is_at_defaults(scene) {
        let defaults = at_defaults(scene)?;
        let default_setup = setup_for(&defaults)?;
        let found = multi_start(&default_setup, newton, settings, on_unit);
        searches += found.len();
        let mut origins: Vec<Gait> = Vec::new();
        for g in found.into_iter().flatten() {
            add_distinct(&mut origins, g, settings.distinct_tolerance);
        }
        let followed: Vec<(Result<Gait, NewtonError>, usize)> = origins
            .par_iter()
            .map(|g| {
                let followed = follow(&defaults, scene, setup_for, g, newton, &settings.homotopy);
                on_unit();
                followed
            })
            .collect();
        for (g, n) in followed {
            searches += n;
            if let Ok(g) = g {
                add_distinct(&mut gaits, g, settings.distinct_tolerance);
            }
        }
    }
    sort_by_period(&mut gaits);
    Ok(Census {
        gaits,
        searches,
        guess_error,
    })
}

/// Where the gait [`nominal_gait`] returns comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
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
/// that branch reaches, not only near the guess. Two or three Newton searches in the usual
/// case; every period-1 gait is [`census`]'s job. With where it came from.
///
/// # Errors
/// The scene cannot be built at its values or at its defaults.
pub fn nominal_gait(
    scene: &Scene,
    setup_for: &SetupFor<'_>,
    newton: &NewtonSettings,
    homotopy: &HomotopySettings,
) -> Result<Result<(Gait, GaitSource), NewtonError>, SceneError> {
    let setup = setup_for(scene)?;
    if is_at_defaults(scene) {
        return Ok(setup.find_gait(newton).map(|g| (g, GaitSource::Defaults)));
    }
    let defaults = at_defaults(scene)?;
    let default_setup = setup_for(&defaults)?;
    let (from_guess, followed) = rayon::join(
        || setup.find_gait(newton),
        || match default_setup.find_gait(newton) {
            Ok(g) => follow(&defaults, scene, setup_for, &g, newton, homotopy).0,
            Err(e) => Err(e),
        },
    );
    Ok(match (from_guess, followed) {
        (Ok(a), Ok(b)) => Ok(if b.stride.duration_s > a.stride.duration_s {
            (b, GaitSource::ContinuedFromDefaults)
        } else {
            (a, GaitSource::Guess)
        }),
        (Ok(a), Err(_)) => Ok((a, GaitSource::Guess)),
        (Err(_), Ok(b)) => Ok((b, GaitSource::ContinuedFromDefaults)),
        (Err(e), Err(_)) => Err(e),
    })
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

/// The scene's guess as a stride-map vector of its setup.
pub fn guess_vector(setup: &Setup) -> DVector<f64> {
    let GaitGuess { q, qd } = &setup.guess;
    setup.walker.pack(q, qd)
}
