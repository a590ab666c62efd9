//! Where a branch ends, and why.
//!
//! A branch of fixed points is smooth only while the strides keep one sequence of events. When
//! a corrector converges to a point whose strides have another sequence (the string no longer
//! engages, a heel lands, a knee locks elsewhere), or a stride fails (a scuff becomes a
//! contact, heel strike before knee lock, the old stance foot does not lift, a fall), the
//! branch ends there. The end is located by bisection on the arclength from the last good
//! point, with the corrector at every trial (started from the last good point, so that its
//! iterates stay within the bracket), until the bracket is below [`LOCATION_TOLERANCE`]: the
//! value reported is the last point with the old sequence.

use super::arclength::{BranchPoint, Continuer, CorrectorError, Linearisation};
use super::bifurcation::{LOCATION_BUDGET, LOCATION_TOLERANCE};
use super::family::EvalError;
use serde::Serialize;

/// Why a branch ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BranchEndKind {
    /// The sequence of stride events changed, or a stride failed: the stride map is not smooth
    /// there.
    EventChange,
    /// The branch turned back at a fold and left the parameter range on the side it came from
    /// (the sweep cannot go further in the parameter on it).
    Fold,
    /// The corrector failed at the smallest step without a stride failure.
    NotConverged,
    /// The point budget ran out.
    Budget,
    /// The branch is a closed curve (an isola): it came back to the point it started from,
    /// heading the same way, so following it further would only repeat it.
    ClosedLoop,
}

impl BranchEndKind {
    /// The JSON name.
    pub fn name(self) -> &'static str {
        match self {
            Self::EventChange => "event_change",
            Self::Fold => "fold",
            Self::NotConverged => "not_converged",
            Self::Budget => "budget",
            Self::ClosedLoop => "closed_loop",
        }
    }
}

/// The end of a branch.
#[derive(Clone, Debug, PartialEq)]
pub struct BranchEnd {
    /// Why.
    pub kind: BranchEndKind,
    /// The parameter value (the last point of the branch).
    pub value: f64,
    /// The event (a failure kind, or the event that appears or disappears), when there is one.
    pub event: Option<String>,
    /// What happens there, in words.
    pub detail: String,
    /// Width of the final arclength bracket of the bisection (0 when not located by
    /// bisection; the step when the corrector gave up). It bounds the parameter's bracket,
    /// but not the accuracy of a grazing end ([`Self::grazing`], [`Self::accuracy`]).
    pub bracket: f64,
    /// The bad side of the final bracket is a stride that fails (a swing foot grazing the
    /// floor, an event that is not found), not a converged point with another event
    /// sequence: where the stride starts to fail depends on the integrator's step grid and
    /// event detection (for wisse2d by ~2e-8 in the parameter while the bracket is 1e-9), so
    /// the bisection width does not bound the location's error.
    pub grazing: bool,
    /// The location ran out of its trial budget ([`LOCATION_BUDGET`]) before the bracket
    /// fell below [`LOCATION_TOLERANCE`].
    pub budget_exhausted: bool,
}

impl BranchEnd {
    /// An honest bound on the error of [`Self::value`] in the parameter: the bisection width
    /// for an end between two converged event sequences, `None` (not known) for a grazing
    /// end or an end not located by bisection.
    pub fn accuracy(&self) -> Option<f64> {
        (self.kind == BranchEndKind::EventChange && !self.grazing).then_some(self.bracket)
    }
}

/// What a trial past the end gave: a stride failure or another event sequence.
fn describe(
    from: &BranchPoint,
    trial: &Result<(BranchPoint, Linearisation), CorrectorError>,
) -> Option<(String, String)> {
    match trial {
        Ok((p, _)) if p.signature != from.signature => {
            let (event, change) = from.signature.difference(&p.signature);
            Some((
                event,
                format!(
                    "the stride's event sequence changes: {change} (from `{}` to `{}`)",
                    from.signature, p.signature
                ),
            ))
        }
        Err(CorrectorError::Eval(EvalError::Stride(f))) => Some((
            serde_json::to_value(f.kind)
                .ok()
                .and_then(|v| v.as_str().map(str::to_string))
                .unwrap_or_else(|| format!("{:?}", f.kind)),
            format!("a stride fails: {f}"),
        )),
        _ => None,
    }
}

/// True when `trial` is a stride failure or another event sequence than `from`'s.
pub fn is_event_change(
    from: &BranchPoint,
    trial: &Result<(BranchPoint, Linearisation), CorrectorError>,
) -> bool {
    describe(from, trial).is_some()
}

/// Locates the end between `a` (good) and arclength `s_bad` along `a`'s tangent, where
/// `bad` was a stride failure or a point with another event sequence.
pub fn locate(
    cont: &Continuer,
    (a, a_lin): (&BranchPoint, &Linearisation),
    s_bad: f64,
    bad: Result<(BranchPoint, Linearisation), CorrectorError>,
) -> BranchEnd {
    let (mut lo, mut hi) = (0.0, s_bad);
    let mut good = a.clone();
    let mut reason = describe(a, &bad);
    // Whether the last trial that said why it is bad was a failing stride (rather than a
    // point with another event sequence).
    let stride_fails = |t: &Result<(BranchPoint, Linearisation), CorrectorError>| {
        matches!(t, Err(CorrectorError::Eval(EvalError::Stride(_))))
    };
    let mut grazing = stride_fails(&bad);
    let mut budget_exhausted = true;
    for _ in 0..LOCATION_BUDGET {
        if (hi - lo).abs() < LOCATION_TOLERANCE {
            budget_exhausted = false;
            break;
        }
        let mid = 0.5 * (lo + hi);
        // Start from the last good point moved onto the trial's hyperplane: the corrector's
        // iterates stay within about the bracket of it, so a stride failing at an iterate
        // says the branch fails within the bracket (not at a far Newton excursion).
        let x0 = good.x() + &a.tangent * (mid - lo);
        let trial = cont.at_arclength_from(a, a_lin, mid, &x0, false);
        match &trial {
            Ok((p, _)) if p.signature == a.signature => {
                good = p.clone();
                lo = mid;
            }
            _ => {
                if let Some(r) = describe(a, &trial) {
                    reason = Some(r);
                    grazing = stride_fails(&trial);
                }
                hi = mid;
            }
        }
    }
    let (event, detail) = match reason {
        Some((e, d)) => (Some(e), d),
        None => (None, "the corrector fails beyond this point".into()),
    };
    BranchEnd {
        kind: BranchEndKind::EventChange,
        value: good.value,
        event,
        detail,
        bracket: (hi - lo).abs(),
        grazing,
        budget_exhausted: budget_exhausted && (hi - lo).abs() >= LOCATION_TOLERANCE,
    }
}
