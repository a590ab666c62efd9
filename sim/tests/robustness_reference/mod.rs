//! Reference robustness measures of a gait (issue 26), written apart from the engine's
//! `sim::analysis::robustness` over any stride map given as a closure, so that they can be
//! taken on the hand-written models (tests/garcia, tests/compass_model) and compared with the
//! engine's. Nothing here uses the engine.
//!
//! The stride map: `stride(x, h)` takes a state just after heel strike in the engine's
//! stride-map order `x = (stance_leg, swing_leg, stance_leg_dot, swing_leg_dot)` (swing_leg
//! relative to the stance leg) and a floor step `h` (the landing floor `h` above the stance
//! foot's, along the normal), and gives the state after the next heel strike, the stride time
//! and the step length, or `None` when the walker falls.
//!
//! Definitions (the engine's implement the same):
//! - [`returns`]: stride 1 from `x0` onto `first_h`, strides 2.. onto a level floor; it returns
//!   at the first stride `k ≤ max_strides` with `‖x_k − x*‖∞ ≤ tol`.
//! - [`threshold`]: the scan of a disturbance size `s = iΔ`, `i = 1, 2, …, n_max`; at the first
//!   `i` that does not survive, bisection between `(i−1)Δ` and `iΔ` to a bracket `≤ tol`, the
//!   threshold its surviving end; then the scan goes on for the first grid value that survives
//!   again, bisected between the last failed grid value and it, `survived_again_from` that
//!   bracket's surviving end. If all grid values survive, the threshold is `n_max Δ`.
//! - [`step_threshold`]: `Δ = 1e-3 l`, `s_max = 0.25 l`, tolerance `1e-7 l`; from the fixed
//!   point, the first stride onto `h = −s` (down) or `+s` (up), survival = [`returns`] with
//!   100 strides and 1e-6.
//! - [`velocity_threshold`]: `x0 = x* ± δ e_j` (j = 2 or 3, a rate), all strides level;
//!   `Δv = 1e-3 √(g/l)`, `δ_max = √(g/l)`, tolerance `1e-7 √(g/l)`.
//! - [`basin_slice`]: see there.
//! - [`gait_sensitivity_norm`]: Hobbelen & Wisse's, by central differences.
#![allow(dead_code)]

/// A state in the stride-map order.
pub type X = [f64; 4];

fn dist(a: &X, b: &X) -> f64 {
    (0..4).fold(0.0, |m, i| f64::max(m, (a[i] - b[i]).abs()))
}

/// The stride (1-based) after which the walker, started at `x0` with its first stride onto
/// `first_h` and the rest onto a level floor, is within `tol` (∞-norm) of `fixed_point`;
/// `None` if it falls or is not within it after `max_strides` strides.
pub fn returns<F>(
    stride: &mut F,
    x0: &X,
    first_h: f64,
    fixed_point: &X,
    max_strides: usize,
    tol: f64,
) -> Option<usize>
where
    F: FnMut(&X, f64) -> Option<(X, f64, f64)>,
{
    let mut x = *x0;
    for k in 1..=max_strides {
        let h = if k == 1 { first_h } else { 0.0 };
        x = stride(&x, h)?.0;
        if dist(&x, fixed_point) <= tol {
            return Some(k);
        }
    }
    None
}

/// A threshold found by [`threshold`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Threshold {
    /// The largest disturbance that survives (the bracket's surviving end), or the scan's end
    /// when every grid value survives.
    pub threshold: f64,
    /// Every grid value up to the scan's end survived.
    pub all_survived: bool,
    /// The smallest disturbance beyond the threshold that survives again (the bracket's
    /// surviving end), if a grid value beyond the first failure survives.
    pub survived_again_from: Option<f64>,
    /// The final bracket of the first bisection, (surviving end, failing end); `None` when
    /// every grid value survived.
    pub bracket: Option<(f64, f64)>,
    /// The final bracket of the second, (failing end, surviving end).
    pub again_bracket: Option<(f64, f64)>,
    /// How many disturbances were tried.
    pub trials: usize,
}

/// Bisects `[lo, hi]` where `survives(lo) != survives(hi)` to a bracket of width `≤ tol`;
/// the final bracket `(lo, hi)`.
fn bisect(
    survives: &mut impl FnMut(f64) -> bool,
    (mut lo, mut hi): (f64, f64),
    lo_survives: bool,
    tol: f64,
    trials: &mut usize,
) -> (f64, f64) {
    while hi - lo > tol {
        let mid = 0.5 * (lo + hi);
        *trials += 1;
        if survives(mid) == lo_survives {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (lo, hi)
}

/// The threshold of a disturbance of size `s` (see the module's definitions): grid `iΔ` for
/// `i = 1..=n_max`, bisection to `tol`.
pub fn threshold(
    mut survives: impl FnMut(f64) -> bool,
    delta: f64,
    n_max: usize,
    tol: f64,
) -> Threshold {
    let grid = |i: usize| i as f64 * delta;
    let mut trials = 0;
    let mut first_fail = None;
    for i in 1..=n_max {
        trials += 1;
        if !survives(grid(i)) {
            first_fail = Some(i);
            break;
        }
    }
    let Some(i) = first_fail else {
        return Threshold {
            threshold: grid(n_max),
            all_survived: true,
            survived_again_from: None,
            bracket: None,
            again_bracket: None,
            trials,
        };
    };
    let bracket = bisect(
        &mut survives,
        (grid(i - 1), grid(i)),
        true,
        tol,
        &mut trials,
    );
    let mut again_bracket = None;
    for j in i + 1..=n_max {
        trials += 1;
        if survives(grid(j)) {
            again_bracket = Some(bisect(
                &mut survives,
                (grid(j - 1), grid(j)),
                false,
                tol,
                &mut trials,
            ));
            break;
        }
    }
    Threshold {
        threshold: bracket.0,
        all_survived: false,
        survived_again_from: again_bracket.map(|b| b.1),
        bracket: Some(bracket),
        again_bracket,
        trials,
    }
}

/// Which way the floor steps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// The landing floor is lower: `h = −s`.
    Down,
    /// The landing floor is higher: `h = +s`.
    Up,
}

/// The step-down or step-up threshold of the gait `fixed_point` [m]: `Δ = 1e-3 l`,
/// `s_max = 0.25 l`, bisection to `1e-7 l`; survival = [`returns`] (100 strides, 1e-6).
pub fn step_threshold<F>(stride: &mut F, fixed_point: &X, leg_length: f64, step: Step) -> Threshold
where
    F: FnMut(&X, f64) -> Option<(X, f64, f64)>,
{
    let sign = match step {
        Step::Down => -1.0,
        Step::Up => 1.0,
    };
    threshold(
        |s| returns(stride, fixed_point, sign * s, fixed_point, 100, 1e-6).is_some(),
        1e-3 * leg_length,
        250,
        1e-7 * leg_length,
    )
}

/// The threshold of a velocity perturbation `x0 = x* + sign·δ·e_coordinate` (coordinate 2 or
/// 3, a rate) [rad/s]: `Δv = 1e-3 √(g/l)`, `δ_max = √(g/l)`, bisection to `1e-7 √(g/l)`; all
/// strides onto a level floor; survival = [`returns`] (100 strides, 1e-6).
pub fn velocity_threshold<F>(
    stride: &mut F,
    fixed_point: &X,
    coordinate: usize,
    sign: f64,
    gravity: f64,
    leg_length: f64,
) -> Threshold
where
    F: FnMut(&X, f64) -> Option<(X, f64, f64)>,
{
    let unit = (gravity / leg_length).sqrt();
    threshold(
        |d| {
            let mut x0 = *fixed_point;
            x0[coordinate] += sign * d;
            returns(stride, &x0, 0.0, fixed_point, 100, 1e-6).is_some()
        },
        1e-3 * unit,
        1000,
        1e-7 * unit,
    )
}

/// What became of a start state of a basin slice.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Within the tolerance of the gait after this many strides.
    Gait { strides: usize },
    /// Not within the tolerance of the gait after all the strides allowed (`K`), and
    /// `‖x_K − x_{K−p}‖∞ ≤ tol` for this smallest `p` in 1..=8.
    Periodic { period: usize },
    /// A stride failed.
    Fell,
    /// Neither within the strides allowed.
    NotSettled,
}

/// A slice of the basin of attraction over two stride-map coordinates.
#[derive(Clone, Debug)]
pub struct BasinSlice {
    /// The two coordinates (indices into the stride-map state).
    pub axes: [usize; 2],
    /// The grid's values along the first axis (cell centres).
    pub xs: Vec<f64>,
    /// Along the second.
    pub ys: Vec<f64>,
    /// The outcomes, `cells[j * xs.len() + i]` for `(xs[i], ys[j])`.
    pub cells: Vec<Outcome>,
    /// Cells `Gait` over all cells.
    pub fraction_returning: f64,
}

/// The outcome of a walk from `x0` on a level floor (see [`Outcome`]): after each stride
/// `k = 1..=max_strides` (`K`), the gait if `‖x_k − x*‖∞ ≤ tol` (the walk ends there), a fall
/// if the stride failed; after all `K` strides, periodic with the smallest `p ≤ 8` (`K − p ≥ 0`,
/// `x_0 = x0`) with `‖x_K − x_{K−p}‖∞ ≤ tol`, else not settled.
///
/// Periodicity is judged only at the end: a walk that spirals into the gait (complex
/// multipliers) has `‖x_k − x_{k−p}‖∞ ≤ tol` at some stride while still farther than `tol`
/// from the gait, a stride or a few before it gets within `tol`; judged there, such a walk
/// would be called periodic (period 1 to 4 seen on the simplest walker's basin at 0.009).
pub fn outcome<F>(stride: &mut F, x0: &X, fixed_point: &X, max_strides: usize, tol: f64) -> Outcome
where
    F: FnMut(&X, f64) -> Option<(X, f64, f64)>,
{
    let mut history = vec![*x0];
    for k in 1..=max_strides {
        let Some((x, _, _)) = stride(&history[k - 1], 0.0) else {
            return Outcome::Fell;
        };
        if dist(&x, fixed_point) <= tol {
            return Outcome::Gait { strides: k };
        }
        history.push(x);
    }
    let k = max_strides;
    match (1..=8.min(k)).find(|&p| dist(&history[k], &history[k - p]) <= tol) {
        Some(period) => Outcome::Periodic { period },
        None => Outcome::NotSettled,
    }
}

/// Solves the section's position constraint for swing_leg: the swing foot at floor level,
/// `foot_height(x) = 0`, by Newton's method in `x[1]` (derivative by central differences)
/// from the gait's leg spread scaled with the stance angle, `x*[1] · x[0] / x*[0]`. `None` if
/// it does not converge to 1e-14.
pub fn on_section(foot_height: &impl Fn(&X) -> f64, x: &X, fixed_point: &X) -> Option<X> {
    let mut y = *x;
    y[1] = fixed_point[1] * x[0] / fixed_point[0];
    for _ in 0..50 {
        let f = foot_height(&y);
        if f.abs() <= 1e-14 {
            return Some(y);
        }
        let d = 1e-7;
        let (mut yp, mut ym) = (y, y);
        yp[1] += d;
        ym[1] -= d;
        let slope = (foot_height(&yp) - foot_height(&ym)) / (2.0 * d);
        if slope == 0.0 || !slope.is_finite() {
            return None;
        }
        y[1] -= f / slope;
    }
    None
}

/// A basin slice: an `n[0] × n[1]` grid of cell centres over `range[0]` of coordinate
/// `axes[0]` and `range[1]` of `axes[1]`. Each cell's start state is the gait's `x*` with the
/// two coordinates set, then (unless swing_leg, coordinate 1, is one of the axes) swing_leg
/// solved from the section's position constraint `foot_height = 0` ([`on_section`]); the
/// rates not set keep the gait's values. Outcome by [`outcome`] with `max_strides` and `tol`;
/// a cell whose constraint cannot be solved counts as `Fell`.
#[allow(clippy::too_many_arguments)]
pub fn basin_slice<F>(
    stride: &mut F,
    foot_height: impl Fn(&X) -> f64,
    fixed_point: &X,
    axes: [usize; 2],
    range: [(f64, f64); 2],
    n: [usize; 2],
    max_strides: usize,
    tol: f64,
) -> BasinSlice
where
    F: FnMut(&X, f64) -> Option<(X, f64, f64)>,
{
    let centres = |(lo, hi): (f64, f64), n: usize| -> Vec<f64> {
        (0..n)
            .map(|i| lo + (i as f64 + 0.5) * (hi - lo) / n as f64)
            .collect()
    };
    let xs = centres(range[0], n[0]);
    let ys = centres(range[1], n[1]);
    let mut cells = Vec::with_capacity(xs.len() * ys.len());
    for &yv in &ys {
        for &xv in &xs {
            let mut x0 = *fixed_point;
            x0[axes[0]] = xv;
            x0[axes[1]] = yv;
            let start = if axes.contains(&1) {
                Some(x0)
            } else {
                on_section(&foot_height, &x0, fixed_point)
            };
            cells.push(match start {
                Some(s) => outcome(stride, &s, fixed_point, max_strides, tol),
                None => Outcome::Fell,
            });
        }
    }
    let returning = cells
        .iter()
        .filter(|c| matches!(c, Outcome::Gait { .. }))
        .count();
    BasinSlice {
        axes,
        fraction_returning: returning as f64 / cells.len() as f64,
        xs,
        ys,
        cells,
    }
}

/// The gait sensitivity norm (Hobbelen & Wisse 2007) of the gait `fixed_point` for a floor
/// step, indicators step time and step length, by central differences (step `d`) of the
/// stride map over its four state entries and the floor step: `(step time, step length,
/// both)`. The first stride's response includes the step's direct effect on the indicators;
/// the sum runs until a term is below 1e-16 of the sum (at most 100 000 strides).
pub fn gait_sensitivity_norm<F>(stride: &mut F, fixed_point: &X, d: f64) -> (f64, f64, f64)
where
    F: FnMut(&X, f64) -> Option<(X, f64, f64)>,
{
    let y = *fixed_point;
    let mut map = |y: X, e: f64| stride(&y, e).expect("the gait survives a small disturbance");
    let mut a = [[0.0; 4]; 4];
    let mut c = [[0.0; 4]; 2];
    for k in 0..4 {
        let (mut yp, mut ym) = (y, y);
        yp[k] += d;
        ym[k] -= d;
        let (sp, tp, lp) = map(yp, 0.0);
        let (sm, tm, lm) = map(ym, 0.0);
        for i in 0..4 {
            a[i][k] = (sp[i] - sm[i]) / (2.0 * d);
        }
        c[0][k] = (tp - tm) / (2.0 * d);
        c[1][k] = (lp - lm) / (2.0 * d);
    }
    let (sp, tp, lp) = map(y, d);
    let (sm, tm, lm) = map(y, -d);
    let mut x: Vec<f64> = (0..4).map(|i| (sp[i] - sm[i]) / (2.0 * d)).collect();
    let dg = [(tp - tm) / (2.0 * d), (lp - lm) / (2.0 * d)];
    let mut sums = [dg[0] * dg[0], dg[1] * dg[1]];
    for _ in 0..100_000 {
        let y0: f64 = (0..4).map(|k| c[0][k] * x[k]).sum();
        let y1: f64 = (0..4).map(|k| c[1][k] * x[k]).sum();
        sums[0] += y0 * y0;
        sums[1] += y1 * y1;
        if y0 * y0 + y1 * y1 <= 1e-16 * (sums[0] + sums[1]) {
            break;
        }
        x = (0..4)
            .map(|i| (0..4).map(|k| a[i][k] * x[k]).sum())
            .collect();
    }
    (sums[0].sqrt(), sums[1].sqrt(), (sums[0] + sums[1]).sqrt())
}
