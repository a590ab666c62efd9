//! Gait census: the distinct period-1 gaits of a scene at given parameter values (the
//! long-period gait among them, the scene's nominal gait, is [`crate::analysis::homotopy::nominal_gait`]).
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
//!    secant step of [`crate::analysis::homotopy::Secant`] (a corrector step longer than
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

use crate::analysis::homotopy::{at_defaults, follow, is_at_defaults, HomotopySettings, SetupFor};
use crate::analysis::limit_cycle::{Gait, GaitGuess, GaitSearch, NewtonError, NewtonSettings};
use crate::scene::{Scene, SceneError, Setup};
use nalgebra::DVector;
use rayon::prelude::*;

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
    /// The Newton settings of every search.
    pub newton: NewtonSettings,
    /// The census settings that produced it.
    pub settings: CensusSettings,
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
        newton: *newton,
        settings: settings.clone(),
    })
}

/// The scene's guess as a stride-map vector of its setup.
pub fn guess_vector(setup: &Setup) -> DVector<f64> {
    let GaitGuess { q, qd } = &setup.guess;
    setup.walker.pack(q, qd)
}
