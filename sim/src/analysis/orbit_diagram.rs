//! The orbit diagram: the attractor of the stride map at each value of one parameter, as
//! heel-strike states — the classic picture of a period-doubling cascade.
//!
//! At each value the stride map is iterated from the previous value's attractor (its last
//! heel-strike state), the first [`OrbitSettings::transient_strides`] strides are dropped,
//! and the last [`OrbitSettings::window_strides`] states are examined every time the window
//! fills: the attractor is **periodic** with the smallest period `p ≤`
//! [`OrbitSettings::max_period`] for which every state of the window repeats after `p`
//! strides to [`OrbitSettings::period_tolerance`] (relative, ∞-norm of the stride-map
//! vector), and [`OrbitSettings::cycle_contrast`] times better than after any shorter period
//! dividing `p` (so that a transient still decaying along a multiplier near −1 is not taken
//! for a period-2 cycle); **chaotic** when no such `p` is found within
//! [`OrbitSettings::max_strides`] strides, or within [`OrbitSettings::max_strides_converging`]
//! while the window's smallest repeat error keeps shrinking by the
//! [`OrbitSettings::converging_factor`] (a slow transient near a bifurcation); this also
//! covers a quasi-periodic attractor, a period above the bound, or a transient slower than
//! the budget; **fell** when a stride fails (its kind and the stride's
//! number from the start of that value).
//!
//! # Parallel chunks
//!
//! The values are cut into chunks of [`OrbitSettings::chunk_points`] consecutive values,
//! computed in parallel (rayon); inside a chunk each value starts from the previous one's
//! attractor as above. The first value of a chunk (and a value after a fall) starts instead
//! from a **seed**: the period-1 gait at that value
//! ([`crate::analysis::homotopy::long_period_gait`]), nudged by [`OrbitSettings::seed_nudge`] when it is
//! unstable so that the iteration leaves it along its unstable direction, or the scene's
//! guess where there is no gait. Why this is faithful: the attractors a
//! period-doubling cascade reaches are born from that period-1 gait; an unstable fixed point
//! lies on the boundary of their basin, and its unstable manifold leads onto them, as the
//! previous value's attractor does once the transient is dropped. Where two attractors
//! coexist (hysteresis) the seeded chunk start may land on the other one; `chunk_points` as
//! large as the number of values gives the purely sequential diagram. The chunking does not
//! depend on the number of threads, so neither do the results.

use crate::analysis::homotopy::{long_period_gait, HomotopySettings, SetupFor};
use crate::analysis::limit_cycle::{GaitSearch, NewtonSettings};
use crate::scene::{Scene, SceneError};
use crate::stride::StrideFailure;
use nalgebra::DVector;
use rayon::prelude::*;
use serde::Serialize;
use std::collections::VecDeque;

/// Settings of an orbit diagram (the defaults are the documented bounds).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct OrbitSettings {
    /// Strides dropped at each value before any state is examined.
    pub transient_strides: usize,
    /// States examined at a time (the samples of a chaotic attractor).
    pub window_strides: usize,
    /// The stride budget of one value, transient included (checked at each full window).
    pub max_strides: usize,
    /// A transient still converging (the smallest repeat error of the window below
    /// `converging_factor` times that of the window before) may run on to this many strides.
    pub max_strides_converging: usize,
    /// See [`Self::max_strides_converging`].
    pub converging_factor: f64,
    /// Largest period looked for (at most half the window).
    pub max_period: usize,
    /// States repeat when they agree to this, relative (`|Δv|∞ ≤ tol (1 + |v|∞)`).
    pub period_tolerance: f64,
    /// A period `p` counts only when the states repeat after `p` strides this many times
    /// better than after every shorter period dividing `p` (see `period_of`).
    pub cycle_contrast: f64,
    /// Consecutive values computed in sequence from one seed.
    pub chunk_points: usize,
    /// Relative nudge of an unstable seed gait's first stride-map entry.
    pub seed_nudge: f64,
}

impl Default for OrbitSettings {
    fn default() -> Self {
        Self {
            transient_strides: 200,
            window_strides: 64,
            max_strides: 2000,
            max_strides_converging: 10_000,
            converging_factor: 0.95,
            max_period: 32,
            period_tolerance: 1e-7,
            cycle_contrast: 1e-3,
            chunk_points: 4,
            seed_nudge: 1e-6,
        }
    }
}

/// The attractor at one value.
#[derive(Clone, Debug, PartialEq)]
pub enum Attractor {
    /// A cycle of this many strides.
    Periodic {
        /// Strides per cycle.
        period: usize,
    },
    /// No period up to [`OrbitSettings::max_period`] within the stride budget.
    Chaotic,
    /// A stride failed.
    Fell {
        /// The stride that failed, counted from 1 at this value.
        stride: usize,
        /// How.
        failure: StrideFailure,
    },
}

/// One value of the diagram.
#[derive(Clone, Debug)]
pub struct OrbitPoint {
    /// The parameter value.
    pub value: f64,
    /// What the iteration settled on.
    pub attractor: Attractor,
    /// Heel-strike states (stride-map vectors) on the attractor: the cycle for a periodic
    /// one, the last window for a chaotic one, none after a fall.
    pub states: Vec<DVector<f64>>,
    /// Strides simulated at this value.
    pub strides: usize,
    /// This value started from a seed, not from the previous value's attractor.
    pub seeded: bool,
}

/// Why a diagram could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OrbitError {
    /// A parameter or scene problem.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// Settings that cannot work.
    #[error("orbit-diagram settings: {0}")]
    Settings(String),
}

impl OrbitSettings {
    /// Checks that the bounds fit together.
    ///
    /// # Errors
    /// A zero budget, a window too short for the largest period, a non-positive tolerance.
    pub fn validate(&self) -> Result<(), OrbitError> {
        let bad = |m: &str| Err(OrbitError::Settings(m.to_string()));
        if self.max_period == 0 || self.window_strides < 2 * self.max_period {
            return bad("the window must hold at least two cycles of the largest period");
        }
        if self.max_strides < self.transient_strides + self.window_strides
            || self.max_strides_converging < self.max_strides
        {
            return bad("the stride budgets must cover the transient and one window, in order");
        }
        if !(self.converging_factor > 0.0 && self.converging_factor <= 1.0) {
            return bad("the converging factor must be in (0, 1]");
        }
        if self.chunk_points == 0 {
            return bad("a chunk holds at least one value");
        }
        if !(self.period_tolerance.is_finite() && self.period_tolerance > 0.0) {
            return bad("the period tolerance must be positive");
        }
        if !(self.cycle_contrast > 0.0 && self.cycle_contrast <= 1.0) {
            return bad("the cycle contrast must be in (0, 1]");
        }
        Ok(())
    }
}

/// The largest change of the states of `window` over `p` strides, relative
/// (`|v_i − v_{i−p}|∞ / (1 + |v_i|∞)`).
fn repeat_error(window: &VecDeque<DVector<f64>>, p: usize) -> f64 {
    (p..window.len())
        .map(|i| {
            let (a, b) = (&window[i], &window[i - p]);
            (a - b).amax() / (1.0 + a.amax())
        })
        .fold(0.0, f64::max)
}

/// The smallest period `p ≤ max_period` with which every state of `window` repeats to `tol`
/// while repeating `contrast` times better than after any shorter period that divides `p`
/// (a transient decaying slowly along a multiplier near −1 repeats nearly after two strides,
/// but not `contrast` times better than after one); else the smallest repeat error of any
/// period, to tell a transient still converging.
fn period_of(
    window: &VecDeque<DVector<f64>>,
    max_period: usize,
    tol: f64,
    contrast: f64,
) -> Result<usize, f64> {
    let errors: Vec<f64> = (1..=max_period.min(window.len() / 2))
        .map(|p| repeat_error(window, p))
        .collect();
    (1..=errors.len())
        .find(|&p| {
            let e = errors[p - 1];
            e <= tol
                && (1..p)
                    .filter(|d| p % d == 0)
                    .all(|d| e <= contrast * errors[d - 1])
        })
        .ok_or_else(|| errors.iter().copied().fold(f64::INFINITY, f64::min))
}

/// Iterates the stride map of `scene` from `v` and classifies the attractor.
fn settle(
    scene: &Scene,
    setup_for: &SetupFor<'_>,
    newton: &NewtonSettings,
    v: DVector<f64>,
    settings: &OrbitSettings,
) -> Result<(Attractor, Vec<DVector<f64>>, usize), SceneError> {
    let setup = setup_for(scene)?;
    let search = GaitSearch::new(&setup.walker, &setup.settings, newton);
    let mut v = v;
    let mut window: VecDeque<DVector<f64>> = VecDeque::with_capacity(settings.window_strides);
    let mut last_best = f64::INFINITY;
    let mut k = 0;
    while k < settings.max_strides_converging {
        k += 1;
        v = match search.stride_map(&v) {
            Ok((next, _)) => next,
            Err(failure) => {
                return Ok((Attractor::Fell { stride: k, failure }, Vec::new(), k));
            }
        };
        if k <= settings.transient_strides {
            continue;
        }
        if window.len() == settings.window_strides {
            window.pop_front();
        }
        window.push_back(v.clone());
        if window.len() == settings.window_strides
            && (k - settings.transient_strides).is_multiple_of(settings.window_strides)
        {
            match period_of(
                &window,
                settings.max_period,
                settings.period_tolerance,
                settings.cycle_contrast,
            ) {
                Ok(p) => {
                    let cycle = window.iter().skip(window.len() - p).cloned().collect();
                    return Ok((Attractor::Periodic { period: p }, cycle, k));
                }
                Err(best) => {
                    let converging = best < settings.converging_factor * last_best;
                    last_best = best;
                    if k >= settings.max_strides && !converging {
                        break;
                    }
                }
            }
        }
    }
    Ok((Attractor::Chaotic, window.into(), k))
}

/// The starting state of a seeded value: the long-period gait (nudged if unstable), else the
/// scene's guess.
fn seed(
    scene: &Scene,
    setup_for: &SetupFor<'_>,
    newton: &NewtonSettings,
    settings: &OrbitSettings,
) -> Result<DVector<f64>, SceneError> {
    let homotopy = HomotopySettings::default();
    match long_period_gait(scene, setup_for, newton, &homotopy)? {
        Ok(g) => {
            let mut v = g.fixed_point.clone();
            if !g.stable() && !v.is_empty() {
                v[0] += settings.seed_nudge * (1.0 + v[0].abs());
            }
            Ok(v)
        }
        Err(_) => Ok(crate::analysis::census::guess_vector(&setup_for(scene)?)),
    }
}

/// One chunk of consecutive values, in sequence.
fn chunk(
    scene: &Scene,
    setup_for: &SetupFor<'_>,
    param: &str,
    values: &[f64],
    newton: &NewtonSettings,
    settings: &OrbitSettings,
    progress: &(dyn Fn() + Sync),
) -> Result<Vec<OrbitPoint>, SceneError> {
    let mut scene = scene.clone();
    let mut out = Vec::with_capacity(values.len());
    let mut last: Option<DVector<f64>> = None;
    for &value in values {
        scene.set(param, value)?;
        let seeded = last.is_none();
        let start = match last.take() {
            Some(v) => v,
            None => seed(&scene, setup_for, newton, settings)?,
        };
        let (attractor, states, strides) = settle(&scene, setup_for, newton, start, settings)?;
        last = states.last().cloned();
        out.push(OrbitPoint {
            value,
            attractor,
            states,
            strides,
            seeded,
        });
        progress();
    }
    Ok(out)
}

/// The orbit diagram of `scene` over `values` of `param` (see the [module docs](self));
/// `progress` is called once per value done.
///
/// # Errors
/// An unknown parameter, a value out of its range, a scene that cannot be built, settings
/// that do not fit together.
pub fn orbit_diagram(
    scene: &Scene,
    setup_for: &SetupFor<'_>,
    param: &str,
    values: &[f64],
    newton: &NewtonSettings,
    settings: &OrbitSettings,
    progress: &(dyn Fn() + Sync),
) -> Result<Vec<OrbitPoint>, OrbitError> {
    settings.validate()?;
    let mut check = scene.clone();
    for &v in values {
        check.set(param, v)?;
    }
    let chunks: Vec<Result<Vec<OrbitPoint>, SceneError>> = values
        .par_chunks(settings.chunk_points)
        // One task per chunk: the costly (chaotic) values cluster, so leave the balancing to
        // work stealing rather than to halving the range.
        .with_max_len(1)
        .map(|c| chunk(scene, setup_for, param, c, newton, settings, progress))
        .collect();
    let mut out = Vec::with_capacity(values.len());
    for c in chunks {
        out.extend(c?);
    }
    Ok(out)
}

/// Most values a caller should ask of one orbit diagram (`walker orbit-diagram --points` and
/// `walker.orbit_diagram` in Python refuse more): each iterates up to its stride budget
/// (2,000 strides) and keeps up to a window of states.
pub const MAX_ORBIT_POINTS: usize = 5_000;

/// `points` values evenly spaced from `from` to `to` (both included; `from` alone for one).
pub fn linspace(from: f64, to: f64, points: usize) -> Vec<f64> {
    match points {
        0 => Vec::new(),
        1 => vec![from],
        n => (0..n)
            .map(|i| from + (to - from) * i as f64 / (n - 1) as f64)
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn window(states: impl Iterator<Item = [f64; 2]>) -> VecDeque<DVector<f64>> {
        states.map(|s| DVector::from_row_slice(&s)).collect()
    }

    #[test]
    fn a_decaying_flip_is_no_period_two_cycle_but_a_converged_one_is() {
        // Period 1 approached along a multiplier −0.99 from an amplitude of 1e-6: it repeats
        // after two strides to 4e-8, within the tolerance, but only 50 times better than
        // after one.
        let flip = window((0..64).map(|k| [0.2 + 1e-6 * (-0.99f64).powi(k), -0.2]));
        assert!(period_of(&flip, 32, 1e-7, 1e-3).is_err());
        assert_eq!(
            period_of(&flip, 32, 1e-7, 1.0),
            Ok(2),
            "without the contrast"
        );
        let cycle = window((0..64).map(|k| [0.2 + 1e-3 * (-1f64).powi(k), -0.2]));
        assert_eq!(period_of(&cycle, 32, 1e-7, 1e-3), Ok(2));
        let fixed = window((0..64).map(|_| [0.2, -0.2]));
        assert_eq!(period_of(&fixed, 32, 1e-7, 1e-3), Ok(1));
        let four = window((0..64).map(|k| [0.2 + 1e-3 * [0.0, 1.0, 0.3, 0.7][k % 4], -0.2]));
        assert_eq!(period_of(&four, 32, 1e-7, 1e-3), Ok(4));
    }
}
