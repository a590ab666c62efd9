//! Following gaits while a scene parameter moves: branches of stride-map fixed points, their
//! bifurcations, their ends, and the period-doubled branches born on them
//! (docs/bifurcations.md).
//!
//! By concept:
//! - `natural`: natural-parameter continuation by the guarded secant step of
//!   [`crate::analysis::homotopy`]: [`along`] (a gait along given values, seeded by the long-period gait;
//!   the stability map's rows) and [`sweep`];
//! - `family`: [`Family`], the stride maps `Sᵏ(v; p)` of a scene in one parameter: the walker
//!   rebuilt at `p`, orbits, monodromy matrices, `∂Sᵏ/∂p`, event sequences;
//! - `arclength`: pseudo-arclength predictor and corrector, [`BranchPoint`], [`StepControl`];
//! - `bifurcation`: test functions, [`Bifurcation`] and its location;
//! - `branch_end`: [`BranchEnd`], non-smooth ends located by bisection;
//! - `branch`: [`Branch`], following one branch across a [`Grid`];
//! - `period2`: switching to the period-doubled branch at a period doubling;
//! - `settings`: [`ContinuationSettings`], every setting of a continuation (the Newton ones
//!   inside) in one validated value.
//!
//! [`continuation`] puts them together: the branch through the gait at `from`, followed to
//! `to`, and the period-2, 4, … branches born on it.

mod arclength;
mod bifurcation;
mod branch;
mod branch_end;
mod family;
mod natural;
mod period2;
mod settings;

pub use arclength::{
    BranchPoint, Constraint, Continuer, CorrectorError, Linearisation, StepControl,
};
pub use bifurcation::{
    complex_outside, fold_test, neimark_sacker_crossed, neimark_sacker_crossings,
    neimark_sacker_test, period_doubling_test, Bifurcation, BifurcationKind, LOCATION_BUDGET,
    LOCATION_TOLERANCE,
};
pub use branch::{Branch, Grid, GridPoint, Unlocated};
pub use branch_end::{BranchEnd, BranchEndKind};
pub use family::{EvalError, EventSignature, Family, Orbit};
pub use natural::{along, sweep, AlongPoint, StabilityBoundary, SweepError, SweepPoint};
pub use period2::{flip_vector, SwitchError};
pub use settings::{ContinuationSettings, ContinuationSettingsBuilder, Detection, SettingsError};

use crate::analysis::homotopy::long_period_gait;
use crate::scene::Scene;
use nalgebra::DVector;
use std::collections::VecDeque;

/// The branches of a continuation over a grid.
#[derive(Clone, Debug)]
pub struct Continuation {
    /// The family followed (scene, parameter, settings), which names the points in reports.
    pub family: Family,
    /// The grid.
    pub grid: Grid,
    /// The branches: `[0]` through the first gait found, then the period-doubled ones.
    pub branches: Vec<Branch>,
    /// The grid values where no gait was found to start from, with the reason, before the
    /// first start (`branches[0]` starts at the next value).
    pub no_start: Vec<(f64, String)>,
    /// Period doublings whose doubled branch could not be started.
    pub switch_failures: Vec<SwitchFailure>,
    /// The settings that produced it.
    pub settings: ContinuationSettings,
}

/// A period doubling whose doubled branch was not followed.
#[derive(Clone, Debug, PartialEq)]
pub struct SwitchFailure {
    /// The branch the period doubling is on.
    pub parent: usize,
    /// Strides per cycle on that branch (the doubled branch would have twice as many).
    pub period_strides: usize,
    /// The parameter value of the period doubling.
    pub value: f64,
    /// Why: the switch failed, or the branch budget ([`ContinuationSettings::max_branches`])
    /// was reached.
    pub reason: String,
}

impl Continuation {
    /// The grid values branch 0 did not reach, with the reason (`param`: the parameter's
    /// name, for the text).
    pub fn unreached(&self, param: &str) -> Vec<(f64, String)> {
        let Some(b) = self.branches.first() else {
            let tried = self.no_start.len();
            return self
                .grid
                .values
                .iter()
                .map(|v| match self.no_start.iter().find(|(g, _)| g == v) {
                    Some((_, e)) => (*v, format!("no gait to start from: {e}")),
                    None => (
                        *v,
                        format!(
                            "no gait found to start from at the {tried} values tried across \
                             the range"
                        ),
                    ),
                })
                .collect();
        };
        let describe = |e: &Option<BranchEnd>| match e {
            Some(e) => format!(
                "the branch ends at {param} = {}: {} ({})",
                crate::scene::short_number(e.value),
                e.kind.name(),
                e.detail
            ),
            None => "not reached by the branch".into(),
        };
        let mut out: Vec<(f64, String)> = b
            .missed
            .iter()
            .map(|(g, why)| (*g, format!("the corrector at this value failed: {why}")))
            .collect();
        // The branch's reach on the `from` side: values beyond it are behind its start, past
        // the end it met going back (`end_before`), not past its forward end.
        let toward_to = (self.grid.to - self.grid.from).signum();
        let reach_back = b
            .grid
            .iter()
            .map(|p| p.value * toward_to)
            .fold(f64::INFINITY, f64::min);
        for &g in &self.grid.values {
            let hit = b.grid.iter().any(|p| p.value == g) || b.missed.iter().any(|m| m.0 == g);
            if hit {
                continue;
            }
            let behind = g * toward_to < reach_back;
            let reason = match (self.no_start.iter().find(|(v, _)| *v == g), behind) {
                (Some((_, e)), _) => match &b.end_before {
                    Some(_) => format!("{}; no gait to start from: {e}", describe(&b.end_before)),
                    None => format!("no gait to start from: {e}"),
                },
                (None, true) => describe(&b.end_before),
                (None, false) => describe(&b.end),
            };
            out.push((g, reason));
        }
        out
    }
}

/// Most points a caller should ask of one sweep (`walker sweep --points` and `walker.sweep`
/// in Python refuse more): each is a gait search, and the sweep allocates its list of points
/// up front.
pub const MAX_SWEEP_POINTS: usize = 10_000;

/// Longest period a sweep follows (`--max-period`, strides per cycle of the period-doubled
/// branches).
pub const MAX_SWEEP_PERIOD: usize = 64;

/// Pseudo-arclength continuation of `scene`'s gait in `param` from `from` to `to`: the gait
/// at `from` that `walker gait` returns there ([`long_period_gait`]: the branch of the scene's
/// nominal gait; if none, the next grid value's), followed with the
/// grid spacing `|to − from|/(points − 1)` as the largest step; its points at the grid values,
/// bifurcations and end; then the period-doubled branches. `progress` is called with the
/// fraction done. The result carries `settings`.
///
/// # Errors
/// [`SweepError`]: a bad parameter name or value, fewer than two points.
pub fn continuation(
    scene: &Scene,
    param: &str,
    (from, to, points): (f64, f64, usize),
    settings: &ContinuationSettings,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<Continuation, SweepError> {
    if points < 2 {
        return Err(SweepError::TooFewPoints(points));
    }
    let mut family = Family::new(scene, param, settings.newton())?;
    family.stride_settings = settings.stride_settings().cloned();
    family.search_budget = settings.search_budget().clone();
    family.scene_at(from)?;
    family.scene_at(to)?;
    let grid = Grid::new(from, to, points);
    let mut out = Continuation {
        family: family.clone(),
        grid: grid.clone(),
        branches: Vec::new(),
        no_start: Vec::new(),
        switch_failures: Vec::new(),
        settings: settings.clone(),
    };
    let cont = Continuer {
        family: &family,
        period: 1,
        steps: step_control(&grid, settings),
        detect: settings.detect(),
    };
    let Some((start, i0)) = first_point(&cont, &grid, settings, &mut out.no_start)? else {
        return Ok(out);
    };
    let share = 1.0 / (1.0 + settings.max_period().ilog2() as f64);
    let main = first_branch(&cont, start, &grid, i0, settings, &|f| progress(f * share));
    period_doubled_branches(&cont, main, &mut out, share, progress);
    progress(1.0);
    Ok(out)
}

/// The step control of a continuation over `grid`: the grid spacing is the largest change of
/// the parameter in one step, half of it the first step.
fn step_control(grid: &Grid, settings: &ContinuationSettings) -> StepControl {
    let spacing = grid.spacing().max(1e-12);
    StepControl {
        initial: 0.5 * spacing,
        max: settings.max_arclength_steps() * spacing,
        max_dp: spacing,
        min: spacing * settings.min_step_fraction(),
        max_iterations: settings.corrector_iterations(),
        max_turn_deg: settings.max_turn_deg(),
    }
}

/// A branch's first point, corrected, with its linearisation.
type Start = (BranchPoint, Linearisation);

/// The first point of branch 0 and its grid index: the corrected gait ([`long_period_gait`])
/// at the first grid value, in [`start_order`], that has one (of at most
/// [`ContinuationSettings::start_attempts`]); the values tried before it are added to
/// `no_start` with the reason.
fn first_point(
    cont: &Continuer,
    grid: &Grid,
    settings: &ContinuationSettings,
    no_start: &mut Vec<(f64, String)>,
) -> Result<Option<(Start, usize)>, SweepError> {
    let family = cont.family;
    let setup_for = |s: &Scene| family.setup_of(s);
    for i in start_order(grid.values.len(), settings.start_attempts()) {
        let Some(&g) = grid.values.get(i) else {
            continue;
        };
        let scene = family.scene_at(g)?;
        match long_period_gait(&scene, &setup_for, settings.newton(), settings.homotopy())? {
            Ok(gait) => {
                let n = gait.fixed_point.len();
                let x = DVector::from_fn(n + 1, |i, _| if i < n { gait.fixed_point[i] } else { g });
                let mut c = DVector::zeros(n + 1);
                c[n] = 1.0;
                let along = &c * (grid.to - grid.from).signum();
                let constraint = arclength::Constraint { c, b: g };
                match cont.correct(&x, &constraint, None, &along, true) {
                    Ok(s) => return Ok(Some((s, i))),
                    Err(e) => no_start.push((g, format!("the corrector at the gait failed: {e}"))),
                }
            }
            Err(e) => no_start.push((g, e.to_string())),
        }
    }
    Ok(None)
}

/// The grid indices tried for a sweep's first gait, at most `attempts` of the `n`: the first
/// [`SEQUENTIAL_STARTS`] in order (a start near `from`, as before), then spread over the rest
/// by halving (the van der Corput sequence: the middle, the quarters, the eighths, ...), so a
/// range whose gaits lie in a small part of it far from `from` is still found (the simplest
/// walker from a slope of −0.5 to 0.5, whose gaits lie between 0 and 0.019, found none in its
/// first 32 values).
fn start_order(n: usize, attempts: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..n.min(SEQUENTIAL_STARTS)).collect();
    let rest = n.saturating_sub(SEQUENTIAL_STARTS);
    // each halving level adds as many fractions as all before it: bounded by 2n fractions
    let mut k: u32 = 1;
    let last_k = u32::try_from(n.saturating_mul(2)).unwrap_or(u32::MAX);
    while order.len() < attempts.min(n) && k < last_k {
        // the k-th van der Corput fraction in base 2
        let fraction = f64::from(k.reverse_bits()) / 4_294_967_296.0;
        k += 1;
        let i = SEQUENTIAL_STARTS + (fraction * rest as f64) as usize;
        if i < n && !order.contains(&i) {
            order.push(i);
        }
    }
    order.truncate(attempts);
    order
}

/// Grid values a sweep's start tries in order before it spreads ([`start_order`]).
const SEQUENTIAL_STARTS: usize = 4;

/// Branch 0 from `start` (at grid index `i0`) to the end of the grid, and, for a start after
/// `from`, backward from it toward `from` too (joined in front).
fn first_branch(
    cont: &Continuer,
    start: (BranchPoint, Linearisation),
    grid: &Grid,
    i0: usize,
    settings: &ContinuationSettings,
    progress: &dyn Fn(f64),
) -> Branch {
    let budget = settings.steps_per_branch();
    let back = (i0 > 0).then(|| {
        let back_grid = Grid {
            from: grid.values[i0],
            to: grid.from,
            values: grid.values[..=i0].iter().rev().copied().collect(),
        };
        let mut reversed = start.clone();
        reversed.0.tangent = -&reversed.0.tangent;
        branch::follow(cont, 0, None, reversed, &back_grid, budget, &|_| {})
    });
    let mut main = branch::follow(cont, 0, None, start, grid, budget, progress);
    if let Some(back) = back {
        branch::prepend(&mut main, back);
    }
    main
}

/// Follows the period-doubled branches born on `main` and on them in turn (breadth first, up
/// to [`ContinuationSettings::max_period`] and [`ContinuationSettings::max_branches`]),
/// pushing `main` and them onto `out.branches` and the switches that failed onto
/// `out.switch_failures`.
fn period_doubled_branches(
    cont: &Continuer,
    main: Branch,
    out: &mut Continuation,
    share: f64,
    progress: &(dyn Fn(f64) + Sync),
) {
    let settings = out.settings.clone();
    // Period doublings to switch at: (parent id, the bifurcation, parent period).
    let mut queue: VecDeque<(usize, Bifurcation, usize)> = VecDeque::new();
    let enqueue = |b: &Branch, queue: &mut VecDeque<(usize, Bifurcation, usize)>| {
        for bif in &b.bifurcations {
            if bif.kind == BifurcationKind::PeriodDoubling
                && 2 * b.period_strides <= settings.max_period()
            {
                queue.push_back((b.id, bif.clone(), b.period_strides));
            }
        }
    };
    enqueue(&main, &mut queue);
    out.branches.push(main);
    while let Some((parent, pd, k)) = queue.pop_front() {
        let failure = |reason: String| SwitchFailure {
            parent,
            period_strides: k,
            value: pd.value,
            reason,
        };
        if out.branches.len() >= settings.max_branches() {
            out.switch_failures.push(failure(format!(
                "the branch budget of {} branches was reached",
                settings.max_branches()
            )));
            continue;
        }
        let doubled = Continuer {
            period: 2 * k,
            ..*cont
        };
        match period2::switch(&doubled, &pd, cont.steps.initial) {
            Ok(first) => {
                let id = out.branches.len();
                let done = share * (1.0 + (2 * k).ilog2() as f64 - 1.0);
                let b = branch::follow(
                    &doubled,
                    id,
                    Some((parent, pd.value)),
                    first,
                    &out.grid,
                    settings.steps_per_branch(),
                    &|f| progress((done + f * share).min(1.0)),
                );
                enqueue(&b, &mut queue);
                out.branches.push(b);
            }
            Err(e) => out.switch_failures.push(failure(format!(
                "the period-{} branch could not be started: {e}",
                2 * k
            ))),
        }
    }
}

#[cfg(test)]
mod start_order_tests {
    use super::*;

    #[test]
    fn the_start_tries_the_first_values_then_spreads_over_the_range() {
        let order = start_order(10_000, 64);
        assert_eq!(order.len(), 64);
        assert_eq!(&order[..5], &[0, 1, 2, 3, 4 + 9_996 / 2]);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), 64, "no index twice");
        // spread: no gap between tried indices wider than 1/32 of the range (past the first
        // four), so any run of gaits wider than that is hit
        let widest = sorted.windows(2).map(|w| w[1] - w[0]).max().unwrap();
        assert!(widest <= 10_000 / 32 + 1, "{widest}");
        // a short grid: every index once, in order first
        assert_eq!(start_order(3, 64), vec![0, 1, 2]);
        let all = start_order(20, 64);
        let mut s = all.clone();
        s.sort_unstable();
        assert_eq!(s, (0..20).collect::<Vec<_>>());
        assert!(start_order(10, 0).is_empty());
    }
}
