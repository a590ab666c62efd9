//! Branch switching at a period doubling: from the located point `x* = (v*, p*)` of a
//! period-`k` branch where a multiplier is −1, the period-`2k` cycle (fixed points of
//! `S²ᵏ`) leaves along the multiplier's eigenvector `e` (for `S²ᵏ` the crossing is a
//! pitchfork, tangent `(e, 0)`). The first point is the corrector of `S²ᵏ` on the hyperplane
//! `e·(v − v*) = h` from the prediction `v* + h e` at `p*`; it is accepted only if it is a
//! genuine period-`2k` cycle (its two halves apart). From there the branch is followed like
//! any other, and its own period doubling gives the period-`4k` branch, up to a depth.

use super::arclength::{BranchPoint, Constraint, Continuer, CorrectorError, Linearisation};
use super::bifurcation::Bifurcation;
use nalgebra::{DMatrix, DVector};

/// The eigenvector of the multiplier nearest −1 of `m` (unit length): the right singular
/// vector of `M + I` of the smallest singular value.
pub fn flip_vector(m: &DMatrix<f64>) -> Option<DVector<f64>> {
    let n = m.nrows();
    let a = m + DMatrix::identity(n, n);
    let svd = a.svd(false, true);
    let v_t = svd.v_t?;
    let (k, _) = svd
        .singular_values
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))?;
    Some(v_t.row(k).transpose())
}

/// Why no period-doubled branch could be started.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SwitchError {
    /// The monodromy matrix gave no eigenvector.
    #[error("no eigenvector of the multiplier −1")]
    NoEigenvector,
    /// The corrector failed.
    #[error(transparent)]
    Corrector(#[from] CorrectorError),
    /// The corrector returned to the period-`k` cycle.
    #[error("the corrector returned to the period-{0} cycle")]
    NotDoubled(usize),
}

/// The first point of the period-`2k` branch born at `pd` (of a period-`k` branch), at
/// distance `h` along the flip eigenvector (retried at `h/8`, the other way, `h/64`);
/// `doubled` continues `S²ᵏ`.
///
/// # Errors
/// [`SwitchError`].
pub fn switch(
    doubled: &Continuer,
    pd: &Bifurcation,
    h: f64,
) -> Result<(BranchPoint, Linearisation), SwitchError> {
    let e = flip_vector(&pd.point.monodromy).ok_or(SwitchError::NoEigenvector)?;
    let x_star = pd.point.x();
    let n = e.len();
    let k = pd.point.period_strides();
    let mut last = SwitchError::NotDoubled(k);
    // Smaller distances first fail less often onto the period-k branch (which the hyperplane
    // also cuts); both orientations of `e` give the same cycle.
    for (h, sign) in [(h, 1.0), (h / 8.0, 1.0), (h / 8.0, -1.0), (h / 64.0, 1.0)] {
        let t0 = DVector::from_fn(n + 1, |i, _| if i < n { sign * e[i] } else { 0.0 });
        let pred = &x_star + &t0 * h;
        let constraint = Constraint {
            c: t0.clone(),
            b: t0.dot(&pred),
        };
        match doubled.correct(&pred, &constraint, None, &t0, true) {
            Ok((p, l)) => {
                let half = &p.orbit[k] - &p.orbit[0];
                if half.amax() >= 1e-3 * h {
                    return Ok((p, l));
                }
                last = SwitchError::NotDoubled(k);
            }
            Err(e) => last = e.into(),
        }
    }
    Err(last)
}
