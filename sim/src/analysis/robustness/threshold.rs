//! The largest single disturbance a gait survives, and the first larger one survived again.
//!
//! A disturbance of size `s ≥ 0` (a floor step down or up at the next heel strike; a change of
//! one rate coordinate just after heel strike) is **survived** when the walker is back on its
//! gait within the [`super::ReturnRule`] (1e-6, 100 strides). Survival is not monotone in `s`,
//! so the threshold is the largest `s` such that every disturbance up to it survives, found by
//! a scan and a bisection:
//!
//! 1. scan `s = i·Δ`, `i = 1, 2, ...` up to the limit; at the first `i` not survived,
//! 2. bisect between `(i−1)·Δ` (survived) and `i·Δ` (not) until the bracket is at most the
//!    resolution; the threshold is the bracket's survived end;
//! 3. scan on from `i + 1` for the first grid value survived again and bisect back to the
//!    failed one: `survived_again_from` is that bracket's survived end (`None` when no grid
//!    value up to the limit survives).
//!
//! "Every disturbance up to it" is therefore checked on the scan's grid (a failure island
//! narrower than `Δ` between two grid values can be missed); the boundary itself is located
//! to the resolution. Step heights: `Δ = 1e-3 L`, limit `0.25 L`, resolution `1e-7 L` (`L` the
//! leg length, [`super::Recovery::leg_length_m`]); rates: `Δ = 1e-2`, limit `0.25` and
//! resolution `1e-7` of the natural rate `sqrt(g/L)` ([`ThresholdOptions`]).

use super::recovery::{Outcome, Recovery, Until};
use crate::stride::StrideWorkspace;
use nalgebra::DVector;
use rayon::prelude::*;
use serde::Serialize;

/// The scan and bisection of a threshold, in multiples of the disturbance's scale.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ThresholdOptions {
    /// The scan's grid step (of the scale).
    pub scan_step: f64,
    /// The largest disturbance tried (of the scale).
    pub limit: f64,
    /// The bisection's final bracket (of the scale).
    pub resolution: f64,
}

impl ThresholdOptions {
    /// For floor steps (scale: the leg length): `Δ = 1e-3`, limit 0.25, resolution 1e-7.
    pub fn steps() -> Self {
        Self {
            scan_step: 1e-3,
            limit: 0.25,
            resolution: 1e-7,
        }
    }

    /// For rate perturbations (scale: `sqrt(g/L)`): `Δ = 1e-2`, limit 0.25, resolution 1e-7.
    pub fn rates() -> Self {
        Self {
            scan_step: 1e-2,
            limit: 0.25,
            resolution: 1e-7,
        }
    }
}

/// A threshold in one direction (the disturbance's units: m, or rad/s and m/s).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Threshold {
    /// The largest disturbance such that every one up to it (on the scan's grid) is
    /// survived; the limit when every grid value up to it is.
    pub max: f64,
    /// How the walker fares just past `max` (the failed end of the bracket); `None` at the
    /// limit.
    pub beyond: Option<Outcome>,
    /// Width of the final bracket (at most the resolution; 0 at the limit).
    pub bracket: f64,
    /// Every grid value up to the limit was survived.
    pub at_limit: bool,
    /// The first disturbance past `max` survived again, located as `max` is; `None` when no
    /// grid value up to the limit is.
    pub survived_again_from: Option<f64>,
    /// Disturbances simulated.
    pub evaluations: usize,
}

/// The step-down and step-up thresholds of a gait.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StepThresholds {
    /// The leg length that scales them \[m\].
    pub leg_length_m: f64,
    /// The largest step down (a positive height: the floor that much lower) \[m\].
    pub down: Threshold,
    /// The largest step up \[m\].
    pub up: Threshold,
}

/// The thresholds of one rate coordinate.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct VelocityThreshold {
    /// The rate coordinate (a stride-map name, `..._dot`).
    pub coordinate: String,
    /// Its index in the stride-map vector.
    pub index: usize,
    /// Increases (rad/s or m/s).
    pub positive: Threshold,
    /// Decreases (a positive size).
    pub negative: Threshold,
}

/// Survival of disturbances of one kind: `survives(ws, s)` for a size `s ≥ 0`.
trait Disturbance: Sync {
    fn outcome(&self, ws: &mut StrideWorkspace<'_>, size: f64) -> Outcome;
}

/// A floor `sign · s` at the first heel strike from the gait, level after.
struct FloorStep<'a> {
    recovery: &'a Recovery<'a>,
    sign: f64,
}

impl Disturbance for FloorStep<'_> {
    fn outcome(&self, ws: &mut StrideWorkspace<'_>, size: f64) -> Outcome {
        let h = self.sign * size;
        let mut floor = |k: usize| if k == 1 { h } else { 0.0 };
        self.recovery
            .follow(ws, self.recovery.fixed_point, &mut floor, Until::Settled)
    }
}

/// The rate at `index` changed by `sign · s` just after heel strike, level floor.
struct RateChange<'a> {
    recovery: &'a Recovery<'a>,
    index: usize,
    sign: f64,
}

impl Disturbance for RateChange<'_> {
    fn outcome(&self, ws: &mut StrideWorkspace<'_>, size: f64) -> Outcome {
        let mut x: DVector<f64> = self.recovery.fixed_point.clone();
        x[self.index] += self.sign * size;
        self.recovery.follow(ws, &x, &mut |_| 0.0, Until::Settled)
    }
}

/// Grid values evaluated together (in parallel, collected in order).
fn batch_len() -> usize {
    2 * rayon::current_num_threads().max(1)
}

/// Scans grid indices `from..=last` for the first whose survival is `wanted`.
fn scan(
    recovery: &Recovery<'_>,
    d: &dyn Disturbance,
    step: f64,
    from: usize,
    last: usize,
    wanted: bool,
    evaluations: &mut usize,
) -> Option<(usize, Outcome)> {
    let mut i = from;
    while i <= last {
        let end = last.min(i + batch_len() - 1);
        let outcomes: Vec<Outcome> = (i..=end)
            .into_par_iter()
            .map_init(
                || StrideWorkspace::new(recovery.walker),
                |ws, j| d.outcome(ws, j as f64 * step),
            )
            .collect();
        for (j, o) in (i..=end).zip(outcomes) {
            *evaluations += 1;
            if o.returned() == wanted {
                return Some((j, o));
            }
        }
        i = end + 1;
    }
    None
}

/// Bisects `[a, b]` (survival `a_survives` at `a`, the opposite at `b`) to `resolution`:
/// returns the final bracket's survived end, its width and the outcome at its failed end.
fn bisect(
    recovery: &Recovery<'_>,
    d: &dyn Disturbance,
    (mut survived, mut failed): (f64, f64),
    mut failed_outcome: Outcome,
    resolution: f64,
    evaluations: &mut usize,
) -> (f64, f64, Outcome) {
    let mut ws = StrideWorkspace::new(recovery.walker);
    // At most 64 halvings: the bracket is then below any resolution a double can hold.
    for _ in 0..64 {
        if (failed - survived).abs() <= resolution {
            break;
        }
        let mid = 0.5 * (survived + failed);
        let o = d.outcome(&mut ws, mid);
        *evaluations += 1;
        if o.returned() {
            survived = mid;
        } else {
            failed = mid;
            failed_outcome = o;
        }
    }
    (survived, (failed - survived).abs(), failed_outcome)
}

/// The threshold of `d` with grid step, limit and resolution in the disturbance's units.
fn threshold(
    recovery: &Recovery<'_>,
    d: &dyn Disturbance,
    options: &ThresholdOptions,
    scale: f64,
) -> Threshold {
    let step = options.scan_step * scale;
    let resolution = options.resolution * scale;
    // Grid indices up to the limit (a bounded scan: at most limit / step values).
    let last = (options.limit / options.scan_step).floor().max(1.0) as usize;
    let mut evaluations = 0;
    let Some((i, fail)) = scan(recovery, d, step, 1, last, false, &mut evaluations) else {
        return Threshold {
            max: last as f64 * step,
            beyond: None,
            bracket: 0.0,
            at_limit: true,
            survived_again_from: None,
            evaluations,
        };
    };
    let (max, bracket, beyond) = bisect(
        recovery,
        d,
        ((i - 1) as f64 * step, i as f64 * step),
        fail,
        resolution,
        &mut evaluations,
    );
    let survived_again_from =
        scan(recovery, d, step, i + 1, last, true, &mut evaluations).map(|(j, _)| {
            let failed_end = (j - 1) as f64 * step;
            let failed_outcome = d.outcome(&mut StrideWorkspace::new(recovery.walker), failed_end);
            evaluations += 1;
            bisect(
                recovery,
                d,
                (j as f64 * step, failed_end),
                failed_outcome,
                resolution,
                &mut evaluations,
            )
            .0
        });
    Threshold {
        max,
        beyond: Some(beyond),
        bracket,
        at_limit: false,
        survived_again_from,
        evaluations,
    }
}

/// A step down or up.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StepDirection {
    /// The floor lower.
    Down,
    /// The floor higher.
    Up,
}

/// The largest step in `direction` the gait survives (module documentation), in metres.
pub fn step_threshold(
    recovery: &Recovery<'_>,
    options: &ThresholdOptions,
    direction: StepDirection,
) -> Threshold {
    let d = FloorStep {
        recovery,
        sign: match direction {
            StepDirection::Down => -1.0,
            StepDirection::Up => 1.0,
        },
    };
    threshold(recovery, &d, options, recovery.leg_length_m())
}

/// The largest step down and up the gait survives (module documentation).
pub fn step_thresholds(recovery: &Recovery<'_>, options: &ThresholdOptions) -> StepThresholds {
    let (down, up) = rayon::join(
        || step_threshold(recovery, options, StepDirection::Down),
        || step_threshold(recovery, options, StepDirection::Up),
    );
    StepThresholds {
        leg_length_m: recovery.leg_length_m(),
        down,
        up,
    }
}

/// The largest change of each rate coordinate, each sign, the gait survives (module
/// documentation), in the stride map's order.
pub fn velocity_thresholds(
    recovery: &Recovery<'_>,
    options: &ThresholdOptions,
) -> Vec<VelocityThreshold> {
    let names = recovery.walker.map_names();
    let n = names.len() / 2;
    let scale = recovery.natural_rate_1_s();
    let mut found: Vec<(usize, Threshold, Threshold)> = (n..2 * n)
        .into_par_iter()
        .map(|index| {
            let at = |sign: f64| {
                let d = RateChange {
                    recovery,
                    index,
                    sign,
                };
                threshold(recovery, &d, options, scale)
            };
            let (positive, negative) = rayon::join(|| at(1.0), || at(-1.0));
            (index, positive, negative)
        })
        .collect();
    found.sort_by_key(|(i, _, _)| *i);
    found
        .into_iter()
        .map(|(index, positive, negative)| VelocityThreshold {
            coordinate: names[index].clone(),
            index,
            positive,
            negative,
        })
        .collect()
}
