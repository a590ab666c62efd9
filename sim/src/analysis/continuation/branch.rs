//! Following one branch across a parameter range: predictor–corrector steps with step
//! control, bifurcations located between steps, the points at the grid values hit exactly,
//! and the branch's end.

use super::arclength::{BranchPoint, Continuer, CorrectorError, Linearisation, StepControl};
use super::bifurcation::{self, Bifurcation, BifurcationKind};
use super::branch_end::{self, BranchEnd, BranchEndKind};
use super::family::EvalError;
use super::settings::Detection;
use nalgebra::DVector;

/// The parameter range of a sweep and its grid.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    /// First value.
    pub from: f64,
    /// Last value.
    pub to: f64,
    /// The grid values, `from` to `to`.
    pub values: Vec<f64>,
}

impl Grid {
    /// `points` values from `from` to `to`, evenly spaced.
    pub fn new(from: f64, to: f64, points: usize) -> Self {
        let n = points.max(2);
        let values = (0..n)
            .map(|i| {
                if i + 1 == n {
                    to
                } else {
                    from + (to - from) * i as f64 / (n - 1) as f64
                }
            })
            .collect();
        Self { from, to, values }
    }

    /// The grid spacing.
    pub fn spacing(&self) -> f64 {
        (self.to - self.from).abs() / (self.values.len() - 1) as f64
    }

    fn contains(&self, p: f64) -> bool {
        let slack = 1e-12 * (1.0 + self.from.abs().max(self.to.abs()));
        p >= self.from.min(self.to) - slack && p <= self.from.max(self.to) + slack
    }

    /// Fraction of the way from `from` to `to` at `p`, in [0, 1].
    pub fn fraction(&self, p: f64) -> f64 {
        if self.to == self.from {
            return 1.0;
        }
        ((p - self.from) / (self.to - self.from)).clamp(0.0, 1.0)
    }
}

/// A point of a branch at a grid value.
#[derive(Clone, Debug)]
pub struct GridPoint {
    /// The grid value.
    pub value: f64,
    /// The branch's point there.
    pub point: BranchPoint,
}

/// A bifurcation detected between two points of a branch (a test function changed sign) but
/// not located, because a corrector failed during the location.
#[derive(Clone, Debug, PartialEq)]
pub struct Unlocated {
    /// Its kind.
    pub kind: BifurcationKind,
    /// The parameter bracket it lies in: the two points' values, in arclength order.
    pub bracket: (f64, f64),
    /// Why it was not located.
    pub reason: String,
}

/// One branch, followed.
#[derive(Clone, Debug)]
pub struct Branch {
    /// Its id (0: the period-1 branch the sweep starts on; then in order of creation).
    pub id: usize,
    /// Strides per cycle.
    pub period_strides: usize,
    /// The branch and bifurcation it was switched from (`None` for the first).
    pub parent: Option<(usize, f64)>,
    /// Its points at the grid values, in arclength order (past a fold a value can appear
    /// twice).
    pub grid: Vec<GridPoint>,
    /// Bifurcations, in arclength order.
    pub bifurcations: Vec<Bifurcation>,
    /// Bifurcations detected but not located (a corrector failed during location).
    pub unlocated: Vec<Unlocated>,
    /// Grid values the branch crossed where the corrector at that value failed, with why.
    pub missed: Vec<(f64, String)>,
    /// Where and why it ends on the `from` side, when it started after `from` (no gait at the
    /// first grid values) and was followed backward from its start too.
    pub end_before: Option<BranchEnd>,
    /// Where and why it ended (`None`: it left the range).
    pub end: Option<BranchEnd>,
    /// Continuation points computed (steps accepted).
    pub steps: usize,
    /// The step control it was followed with.
    pub step_control: StepControl,
    /// The bifurcations it located.
    pub detect: Detection,
}

impl Branch {
    /// The last parameter value the branch reached before leaving the range or ending.
    pub fn reached(&self) -> Option<f64> {
        self.end.as_ref().map(|e| e.value)
    }
}

fn between(a: f64, b: f64, g: f64) -> bool {
    // (a, b] in either direction.
    (a < g && g <= b) || (b <= g && g < a)
}

/// Joins `back` (the same branch followed backward from its start) in front of `forward`:
/// its grid points and bifurcations in reverse (stability before and after swapped), its end
/// as `end_before`.
pub fn prepend(forward: &mut Branch, back: Branch) {
    let mut grid: Vec<GridPoint> = back.grid.into_iter().skip(1).rev().collect();
    grid.append(&mut forward.grid);
    forward.grid = grid;
    let mut bifurcations: Vec<Bifurcation> = back
        .bifurcations
        .into_iter()
        .rev()
        .map(|mut b| {
            std::mem::swap(&mut b.stable_before, &mut b.stable_after);
            b
        })
        .collect();
    bifurcations.append(&mut forward.bifurcations);
    forward.bifurcations = bifurcations;
    forward.unlocated.extend(back.unlocated);
    forward.missed.extend(back.missed);
    forward.steps += back.steps;
    forward.end_before = back.end;
}

/// Why the step `h` from `a` to `b` is refused (`None`: it is taken): the corrector must move
/// the point by at most `h` from the prediction and the tangent turn by less than
/// `max_turn_deg` (60° by default; more
/// says the step skipped over structure, or jumped to another branch), and a period-`k` cycle
/// (`k > 1`) must not have collapsed onto the period-`k/2` one (its two halves at least 1e-7
/// apart).
fn refused(a: &BranchPoint, b: &BranchPoint, h: f64, max_turn_deg: f64) -> Option<String> {
    let predicted = a.x() + &a.tangent * h;
    let moved = (b.x() - predicted).norm();
    if moved > h {
        return Some(format!(
            "the corrector moved {moved:.3e} from the prediction, more than the step {h:.3e}"
        ));
    }
    let deg = a
        .tangent
        .dot(&b.tangent)
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees();
    if deg > max_turn_deg {
        return Some(format!(
            "the tangent turned by {deg:.3}° (more than {max_turn_deg}°)"
        ));
    }
    let k = b.period_strides();
    if k > 1 && (&b.orbit[k / 2] - &b.orbit[0]).amax() <= 1e-7 {
        return Some(format!(
            "the period-{k} cycle collapsed onto the period-{} one",
            k / 2
        ));
    }
    None
}

/// Follows the branch from `start` across `grid` with at most `budget` steps, calling
/// `progress` with the fraction of the range covered: trial steps along the tangent, halved
/// while refused ([`refused`]) or failed, the accepted ones recorded ([`record_step`]), until
/// the branch leaves the range, closes, ends or the budget runs out.
pub fn follow(
    cont: &Continuer,
    id: usize,
    parent: Option<(usize, f64)>,
    start: (BranchPoint, Linearisation),
    grid: &Grid,
    budget: usize,
    progress: &dyn Fn(f64),
) -> Branch {
    let mut branch = started(cont, id, parent, &start.0, grid);
    let origin = Origin::of(&start.0);
    let min = cont.steps.min;
    let mut cur = start;
    let mut h = cont.steps.initial;
    let mut furthest = grid.fraction(cur.0.value);
    let mut steps = 0;
    while steps < budget {
        h = cont.steps.capped(h, &cur.0.tangent);
        let halved = (h * 0.5).max(min);
        match cont.at_arclength(&cur.0, &cur.1, h, true) {
            // A refused trial is retried with a shorter step; at the smallest step it ends the
            // branch only when its event sequence is the branch's own (a trial with another
            // sequence is never taken as a step: the arm for it locates the event change).
            Ok((p, _))
                if refused(&cur.0, &p, h, cont.steps.max_turn_deg).is_some()
                    && (h > min || p.signature == cur.0.signature) =>
            {
                if h > min {
                    h = halved;
                    continue;
                }
                steps += 1;
                branch.end = Some(smallest_step_refused(
                    &cur.0,
                    &p,
                    h,
                    cont.steps.max_turn_deg,
                ));
                break;
            }
            // Two complex pairs through the unit circle in one step cannot be located one by
            // one (their test function may keep its sign): the step is halved until they
            // come one per step, or the smallest step takes them together.
            Ok((p, _)) if h > min && two_pairs_at_once(cont, &cur.0, &p) => {
                h = halved;
            }
            Ok((p, l)) if p.signature == cur.0.signature => {
                steps += 1;
                record_step(cont, &mut branch, grid, &cur, (&p, &l));
                furthest = furthest.max(grid.fraction(p.value));
                progress(furthest);
                if let Some(end) = end_after(&branch, grid, &origin, &cur.0, &p) {
                    branch.end = end;
                    break;
                }
                h = cont.steps.adapt(h, p.iterations);
                cur = (p, l);
            }
            other => {
                let stride_failed =
                    matches!(other, Err(CorrectorError::Eval(EvalError::Stride(_))));
                let changed = branch_end::is_event_change(&cur.0, &other);
                if (stride_failed || !changed) && h > min {
                    h = halved;
                    continue;
                }
                steps += 1;
                branch.end = Some(failed_step_end(cont, &cur, h, other, changed));
                break;
            }
        }
    }
    if steps >= budget && branch.end.is_none() {
        let detail = format!("the point budget of {budget} steps ran out");
        branch.end = Some(end(BranchEndKind::Budget, cur.0.value, detail, 0.0));
    }
    branch.steps = steps;
    progress(1.0);
    branch
}

/// The end of a branch where even the smallest step `h` from `a` to `b` is refused: taking it
/// could jump to another branch without a word, so the branch ends here.
fn smallest_step_refused(a: &BranchPoint, b: &BranchPoint, h: f64, max_turn_deg: f64) -> BranchEnd {
    let why = refused(a, b, h, max_turn_deg).unwrap_or_default();
    let detail = format!(
        "the smallest step ({h:.3e}) is refused: {why}; a jump to another branch is not taken"
    );
    end(BranchEndKind::NotConverged, a.value, detail, h)
}

/// A branch end without an event (no grazing, no location budget).
fn end(kind: BranchEndKind, value: f64, detail: String, bracket: f64) -> BranchEnd {
    BranchEnd {
        kind,
        value,
        event: None,
        detail,
        bracket,
        grazing: false,
        budget_exhausted: false,
    }
}

/// The branch before its first step: `start` as its point at a grid value when it lies on
/// one.
fn started(
    cont: &Continuer,
    id: usize,
    parent: Option<(usize, f64)>,
    start: &BranchPoint,
    grid: &Grid,
) -> Branch {
    let mut branch = Branch {
        id,
        period_strides: cont.period,
        parent,
        grid: Vec::new(),
        bifurcations: Vec::new(),
        unlocated: Vec::new(),
        missed: Vec::new(),
        end_before: None,
        end: None,
        steps: 0,
        step_control: cont.steps,
        detect: cont.detect,
    };
    let slack = 1e-12 * (1.0 + grid.from.abs().max(grid.to.abs()));
    if let Some(&g) = grid
        .values
        .iter()
        .find(|&&g| (g - start.value).abs() <= slack)
    {
        branch.grid.push(GridPoint {
            value: g,
            point: start.clone(),
        });
    }
    branch
}

/// Records the accepted step from `cur` to `next`: the bifurcations detected between them,
/// located (or why not), and the branch's points at the grid values crossed (or why the
/// corrector there failed).
fn record_step(
    cont: &Continuer,
    branch: &mut Branch,
    grid: &Grid,
    cur: &(BranchPoint, Linearisation),
    (p, l): (&BranchPoint, &Linearisation),
) {
    let detected = bifurcation::crossings(&cur.0, p)
        .into_iter()
        .filter(|k| k.detected_by(&cont.detect));
    for kind in detected {
        match bifurcation::locate(cont, kind, (&cur.0, &cur.1), p) {
            Ok(b) => branch.bifurcations.push(b),
            Err(e) => branch.unlocated.push(Unlocated {
                kind,
                bracket: (cur.0.value, p.value),
                reason: e.to_string(),
            }),
        }
    }
    let mut crossed: Vec<f64> = grid
        .values
        .iter()
        .copied()
        .filter(|&g| between(cur.0.value, p.value, g))
        .collect();
    if p.value < cur.0.value {
        crossed.reverse();
    }
    for g in crossed {
        match cont.at_value(&cur.0, p, l, g) {
            Ok((gp, _)) => branch.grid.push(GridPoint {
                value: g,
                point: gp,
            }),
            Err(e) => branch.missed.push((g, e.to_string())),
        }
    }
}

/// Whether the step from `a` to `b` (same event sequence) takes two complex pairs through the
/// unit circle at once, when Neimark-Sacker bifurcations are located.
fn two_pairs_at_once(cont: &Continuer, a: &BranchPoint, b: &BranchPoint) -> bool {
    cont.detect.neimark_sacker
        && b.signature == a.signature
        && bifurcation::neimark_sacker_crossings(&a.multipliers, &b.multipliers) > 1
}

/// Whether the branch stops after the accepted step from `prev` to `p`, and its end then
/// (`Some(None)`: it left the range past `to`): out of the range, or closed.
fn end_after(
    branch: &Branch,
    grid: &Grid,
    origin: &Origin,
    prev: &BranchPoint,
    p: &BranchPoint,
) -> Option<Option<BranchEnd>> {
    if !grid.contains(p.value) {
        return Some(turned_back(branch, grid, p));
    }
    origin.closed_by(prev, p, &branch.bifurcations).map(Some)
}

/// The end of a branch whose step reached `p`, outside the range: `None` past `to` (it left
/// the range); past `from`, it turned back (at its last fold, if one was located).
fn turned_back(branch: &Branch, grid: &Grid, p: &BranchPoint) -> Option<BranchEnd> {
    let towards_to = (p.value - grid.from) * (grid.to - grid.from) > 0.0;
    if towards_to {
        return None;
    }
    let fold = branch
        .bifurcations
        .iter()
        .rev()
        .find(|b| b.kind == BifurcationKind::Fold);
    let (value, detail) = match fold {
        Some(f) => (
            f.value,
            format!(
                "the branch turns back at a fold at {} and returns to {}",
                f.value, grid.from
            ),
        ),
        None => (p.value, format!("the branch returns to {}", grid.from)),
    };
    Some(end(BranchEndKind::Fold, value, detail, 0.0))
}

/// The end of a branch whose trial step `h` from `cur` failed for good (`other`): the event
/// change located when the event sequence `changed`, else no point beyond.
fn failed_step_end(
    cont: &Continuer,
    cur: &(BranchPoint, Linearisation),
    h: f64,
    other: Result<(BranchPoint, Linearisation), CorrectorError>,
    changed: bool,
) -> BranchEnd {
    if changed {
        return branch_end::locate(cont, (&cur.0, &cur.1), h, other);
    }
    let detail = match other {
        Err(e) => format!("no point beyond: {e}"),
        Ok(_) => "no point beyond".into(),
    };
    end(BranchEndKind::NotConverged, cur.0.value, detail, h)
}

/// Where a branch started: to recognise a closed branch (an isola) coming back to it.
struct Origin {
    /// `(v₀, p)` at the start.
    x: DVector<f64>,
    /// The start's tangent.
    tangent: DVector<f64>,
}

impl Origin {
    fn of(p: &BranchPoint) -> Self {
        Origin {
            x: p.x(),
            tangent: p.tangent.clone(),
        }
    }

    /// The branch's end when the step from `prev` to `next` closed the branch.
    fn closed_by(
        &self,
        prev: &BranchPoint,
        next: &BranchPoint,
        bifurcations: &[Bifurcation],
    ) -> Option<BranchEnd> {
        let folds: Vec<f64> = bifurcations
            .iter()
            .filter(|b| b.kind == BifurcationKind::Fold)
            .map(|b| b.value)
            .collect();
        if !self.passed(&prev.x(), &next.x(), &next.tangent, folds.len()) {
            return None;
        }
        let lo = folds.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = folds.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let detail = format!(
            "the branch is a closed loop: it came back to where it was started, between folds \
             at {lo} and {hi}; no gait of it lies outside that interval"
        );
        Some(end(BranchEndKind::ClosedLoop, next.value, detail, 0.0))
    }

    /// Whether the step from `a` to `b` (tangent `tb` at `b`) passed through the start again,
    /// heading the same way, after at least two folds (a closed curve in `(v, p)` turns at two
    /// folds at least): the segment comes within a tenth of its own length of the start.
    fn passed(&self, a: &DVector<f64>, b: &DVector<f64>, tb: &DVector<f64>, folds: usize) -> bool {
        if folds < 2
            || a.len() != self.x.len()
            || b.len() != self.x.len()
            || tb.len() != self.tangent.len()
        {
            return false;
        }
        let seg = b - a;
        let len2 = seg.norm_squared();
        if len2 == 0.0 || !len2.is_finite() {
            return false;
        }
        let t = ((&self.x - a).dot(&seg) / len2).clamp(0.0, 1.0);
        let gap = (a + &seg * t - &self.x).norm();
        gap <= 0.1 * len2.sqrt() && tb.dot(&self.tangent) > 0.0
    }
}

#[cfg(test)]
mod closed_loop_tests {
    use super::*;

    /// The unit circle in `(v, p)`, started at angle 0 heading counter-clockwise.
    fn origin() -> Origin {
        Origin {
            x: DVector::from_vec(vec![1.0, 0.0]),
            tangent: DVector::from_vec(vec![0.0, 1.0]),
        }
    }

    fn at(angle: f64) -> DVector<f64> {
        DVector::from_vec(vec![angle.cos(), angle.sin()])
    }

    fn tangent(angle: f64) -> DVector<f64> {
        DVector::from_vec(vec![-angle.sin(), angle.cos()])
    }

    #[test]
    fn a_step_over_the_start_after_two_folds_closes_the_branch() {
        let o = origin();
        let (a, b) = (at(-0.1), at(0.1));
        assert!(o.passed(&a, &b, &tangent(0.1), 2));
        // Not before the branch has turned at two folds (the first step leaves the start).
        assert!(!o.passed(&a, &b, &tangent(0.1), 1));
        // Passing the start the other way (tangent reversed) is not a return.
        assert!(!o.passed(&b, &a, &tangent(-0.1).scale(-1.0), 2));
        // A step elsewhere on the curve does not close it.
        assert!(!o.passed(&at(2.0), &at(2.2), &tangent(2.2), 2));
        // Nor a step that passes the start at a distance (another sheet).
        let off = DVector::from_vec(vec![0.0, 0.5]);
        assert!(!o.passed(
            &(at(-0.1) * 1.5 + &off),
            &(at(0.1) * 1.5 + &off),
            &tangent(0.1),
            2
        ));
    }

    #[test]
    fn non_finite_or_mismatched_points_never_close() {
        let o = origin();
        let nan = DVector::from_vec(vec![f64::NAN, 0.0]);
        assert!(!o.passed(&nan, &at(0.1), &tangent(0.1), 2));
        let short = DVector::from_vec(vec![1.0]);
        assert!(!o.passed(&short, &at(0.1), &tangent(0.1), 2));
        assert!(!o.passed(&at(0.1), &at(0.1), &tangent(0.1), 2));
    }
}
