//! Events as witness functions with a direction rule, estimated on the integrator's dense output
//! where it has one (DOP853), otherwise by cubic Hermite interpolation (eq. 14), and refined by
//! exact integrator steps.

use crate::engine::integrators::{IntegrationError, Integrator, Sample, SecondOrderSystem};
use nalgebra::DVector;
use serde::Serialize;

/// Which sign change of a witness function triggers its event.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    /// From strictly negative to zero or positive.
    Rising,
    /// From strictly positive to zero or negative.
    Falling,
}

impl Direction {
    /// Whether the values at the two ends of a step trigger the event.
    pub fn triggered(self, g_before: f64, g_after: f64) -> bool {
        match self {
            Direction::Rising => g_before < 0.0 && g_after >= 0.0,
            Direction::Falling => g_before > 0.0 && g_after <= 0.0,
        }
    }
}

/// Tolerances for event location.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct EventTolerance {
    /// Stop refining when the bracket is this narrow \[s\].
    pub time_s: f64,
    /// Or when the witness is this close to zero (its own unit).
    pub witness: f64,
    /// Refinement iterations allowed.
    pub max_iterations: usize,
    /// Interior points of each step at which the swing-foot height is also checked on the
    /// Hermite interpolant, so that a foot that dips below the floor and comes back up within
    /// one step (a grazing contact) is not missed (0: endpoints only).
    pub grazing_samples: usize,
    /// Estimate the crossing on the integrator's dense output when it has one (DOP853's
    /// seventh-order continuous extension: four more evaluations per located step), so that
    /// the refinement on exact steps starts next to the root and takes one Newton step; false:
    /// estimate on the cubic Hermite interpolant (eq. 14), several exact steps to refine.
    pub dense_output: bool,
}

impl Default for EventTolerance {
    fn default() -> Self {
        Self {
            time_s: 1e-13,
            witness: 1e-14,
            max_iterations: 60,
            grazing_samples: 4,
            dense_output: true,
        }
    }
}

/// Cubic Hermite interpolation of `q` (and its derivative) between two samples, eq. (14)
/// ([`crate::engine::hermite::vector`] at the normalised time of `t_s`).
pub fn hermite(a: &Sample, b: &Sample, t_s: f64) -> (DVector<f64>, DVector<f64>) {
    let h = b.t_s - a.t_s;
    crate::engine::hermite::vector((&a.q, &a.qd), (&b.q, &b.qd), h, (t_s - a.t_s) / h)
}

/// Why an event could not be located.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EventError {
    /// A refinement step failed.
    #[error(transparent)]
    Integration(#[from] IntegrationError),
    /// The refinement did not meet its tolerance within its budget.
    #[error("event not located within {iterations} iterations (bracket {bracket_s:e} s)")]
    NotLocated {
        /// Iterations used.
        iterations: usize,
        /// Final bracket width \[s\].
        bracket_s: f64,
    },
    /// An integrator that locates events on its dense output had none for the step (the
    /// step asked about is not the last one it took).
    #[error("no dense output of the step from {from_s} s to {to_s} s to locate the event on")]
    NoDenseOutput {
        /// The step's start \[s\].
        from_s: f64,
        /// The step's end \[s\].
        to_s: f64,
    },
}

/// Finds the crossing of `g` between samples `a` and `b` (with `g(a)`, `g(b)` of opposite
/// sign) on the integrator's own solution: a first estimate — on the dense output of the step
/// when the integrator has one and `tol.dense_output` asks for it (its root, and the witness's
/// slope there for one Newton correction), else on the cubic Hermite interpolant — then the
/// Illinois method on exact integrator steps from `a`. Returns the sample at the event.
pub fn locate(
    integrator: &mut dyn Integrator,
    sys: &mut dyn SecondOrderSystem,
    a: &Sample,
    b: &Sample,
    g: &mut dyn FnMut(&Sample) -> f64,
    tol: &EventTolerance,
) -> Result<Sample, EventError> {
    let (ga, gb) = (g(a), g(b));
    let dense = match tol.dense_output {
        true => integrator.dense_output(sys, a, b).transpose()?,
        false => None,
    };
    let (guess, slope) = match dense {
        Some(d) => {
            let (t, slope) = root_on_dense(|t| g(&d.eval(t)), (a.t_s, ga), (b.t_s, gb), d.h_s, tol);
            (t, Some(slope))
        }
        None => (root_on_hermite(a, b, ga, g, tol), None),
    };
    refine((a.t_s, ga), (b, b.t_s, gb), (guess, slope), tol, |t| {
        let s = integrator.step_exact(sys, a, t - a.t_s)?;
        let gt = g(&s);
        Ok((s, gt))
    })
}

/// The refinement of an event's estimate `guess` (with the witness's slope there when it came
/// from a dense output): the Illinois method on exact steps (`exact(t)`: the sample at `t` and
/// its witness value), bracketed by the step's start `(t_a, g_a)` and its end `b` (at `t_b`,
/// witness `g_b`). Written once for [`locate`] and the fixed-size stride.
///
/// # Errors
/// [`EventError`]: a failed step, or no convergence within the tolerance's budget.
pub(crate) fn refine<S: Clone>(
    (t_a, ga): (f64, f64),
    (b, t_b, gb): (&S, f64, f64),
    (guess, slope): (f64, Option<f64>),
    tol: &EventTolerance,
    mut exact: impl FnMut(f64) -> Result<(S, f64), IntegrationError>,
) -> Result<S, EventError> {
    // Refinement: Illinois regula falsi on the exact flow, bracketed by [a, b].
    let mut bracket = Illinois::new((t_a, ga), (t_b, gb));
    let mut best = b.clone();
    let mut t = guess;
    for it in 0..tol.max_iterations {
        let (s, gt) = if (t - t_b).abs() == 0.0 {
            (b.clone(), gb)
        } else {
            exact(t)?
        };
        best = s;
        if gt.abs() <= tol.witness || bracket.width() <= tol.time_s {
            return Ok(best);
        }
        let t_prev = t;
        bracket.update(t, gt);
        t = bracket.secant();
        // After the dense estimate: one Newton correction with the dense output's slope.
        if let (0, Some(d)) = (it, slope) {
            if d != 0.0 && d.is_finite() {
                t = t_prev - gt / d;
            }
        }
        if !bracket.strictly_inside(t) {
            t = bracket.midpoint();
        }
        if it + 1 == tol.max_iterations {
            break;
        }
    }
    if bracket.width() <= 1e3 * tol.time_s {
        return Ok(best);
    }
    Err(EventError::NotLocated {
        iterations: tol.max_iterations,
        bracket_s: bracket.width(),
    })
}

/// The crossing's estimate on the cubic Hermite interpolant of the step (eq. 14): bisection,
/// cheap since no dynamics is evaluated.
fn root_on_hermite(
    a: &Sample,
    b: &Sample,
    ga: f64,
    g: &mut dyn FnMut(&Sample) -> f64,
    tol: &EventTolerance,
) -> f64 {
    let (mut lo, mut hi) = (a.t_s, b.t_s);
    let mut glo = ga;
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        let (q, qd) = hermite(a, b, mid);
        let gm = g(&Sample { t_s: mid, q, qd });
        if (gm <= 0.0) == (glo <= 0.0) {
            lo = mid;
            glo = gm;
        } else {
            hi = mid;
        }
        if hi - lo < tol.time_s {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// The crossing's estimate on the dense output of a step of `h_s` [s] (`g_at(t)`: the witness
/// on the dense output at `t`): the Illinois method (no evaluation of the equations of motion
/// per iteration, at most 60), until the witness is within its tolerance or the bracket
/// narrower than the time tolerance; and the witness's slope there along the dense output
/// (central difference).
pub(crate) fn root_on_dense(
    mut g_at: impl FnMut(f64) -> f64,
    start: (f64, f64),
    end: (f64, f64),
    h_s: f64,
    tol: &EventTolerance,
) -> (f64, f64) {
    let mut bracket = Illinois::new(start, end);
    let mut t = bracket.midpoint();
    for _ in 0..60 {
        t = bracket.secant();
        if !bracket.strictly_inside(t) {
            t = bracket.midpoint();
        }
        let gt = g_at(t);
        if gt.abs() <= tol.witness || bracket.width() <= tol.time_s {
            break;
        }
        bracket.update(t, gt);
    }
    let e = 1e-6 * h_s;
    let slope = (g_at(t + e) - g_at(t - e)) / (2.0 * e);
    (t, slope)
}

/// A sign-change bracket `[(t0, g0), (t1, g1)]` of the witness, narrowed by the Illinois
/// variant of regula falsi: the end that stays twice in a row has its witness value halved.
struct Illinois {
    t0: f64,
    g0: f64,
    t1: f64,
    g1: f64,
    /// Which end moved last (−1: `t0`, 1: `t1`, 0: none yet).
    side: i8,
}

impl Illinois {
    fn new((t0, g0): (f64, f64), (t1, g1): (f64, f64)) -> Self {
        Illinois {
            t0,
            g0,
            t1,
            g1,
            side: 0,
        }
    }

    /// `|t1 − t0|`.
    fn width(&self) -> f64 {
        (self.t1 - self.t0).abs()
    }

    fn midpoint(&self) -> f64 {
        0.5 * (self.t0 + self.t1)
    }

    /// Whether `t` lies strictly between the ends.
    fn strictly_inside(&self, t: f64) -> bool {
        t > self.t0.min(self.t1) && t < self.t0.max(self.t1)
    }

    /// The regula falsi point (the midpoint when the ends' values are equal).
    fn secant(&self) -> f64 {
        if self.g1 != self.g0 {
            self.t0 - self.g0 * (self.t1 - self.t0) / (self.g1 - self.g0)
        } else {
            self.midpoint()
        }
    }

    /// Replaces the end on the side of `gt`'s sign by `(t, gt)`.
    fn update(&mut self, t: f64, gt: f64) {
        if (gt <= 0.0) == (self.g0 <= 0.0) {
            self.t0 = t;
            self.g0 = gt;
            if self.side == -1 {
                self.g1 *= 0.5;
            }
            self.side = -1;
        } else {
            self.t1 = t;
            self.g1 = gt;
            if self.side == 1 {
                self.g0 *= 0.5;
            }
            self.side = 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hermite_is_exact_for_cubics() {
        let f = |t: f64| 1.0 + 2.0 * t - t * t + 0.5 * t * t * t;
        let df = |t: f64| 2.0 - 2.0 * t + 1.5 * t * t;
        let s = |t: f64| Sample {
            t_s: t,
            q: DVector::from_element(1, f(t)),
            qd: DVector::from_element(1, df(t)),
        };
        let (q, qd) = hermite(&s(0.3), &s(1.1), 0.77);
        assert!((q[0] - f(0.77)).abs() < 1e-14);
        assert!((qd[0] - df(0.77)).abs() < 1e-13);
    }

    #[test]
    fn direction_rules() {
        assert!(Direction::Falling.triggered(1.0, 0.0));
        assert!(!Direction::Falling.triggered(0.0, -1.0));
        assert!(Direction::Rising.triggered(-1.0, 0.0));
        assert!(!Direction::Rising.triggered(1.0, 2.0));
    }
}
