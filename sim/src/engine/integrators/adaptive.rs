//! The step-size controller shared by the embedded pairs.

use super::system::IntegrationError;

/// The step-size controller of the embedded pairs (DOPRI5, DOP853): from `h`, try a step;
/// accept it when its scaled error is at most 1 and propose the next step
/// `h · clamp(0.9 · err^(−exponent), min, max)` (at most `h_max_s`); otherwise shrink and retry,
/// down to `h_min_s`. Returns the accepted sample and the proposal.
pub(crate) fn adaptive_step<S>(
    mut h: f64,
    limits: StepLimits,
    t_s: f64,
    mut try_step: impl FnMut(f64) -> Result<(S, f64), IntegrationError>,
) -> Result<(S, f64), IntegrationError> {
    loop {
        let (next, err) = try_step(h)?;
        let factor = if err == 0.0 {
            limits.max_factor
        } else {
            (0.9 * err.powf(-limits.exponent)).clamp(limits.min_factor, limits.max_factor)
        };
        if err <= 1.0 && err.is_finite() {
            return Ok((next, (h * factor).min(limits.h_max_s)));
        }
        h *= if err.is_finite() {
            factor.min(0.9)
        } else {
            0.2
        };
        if h < limits.h_min_s {
            return Err(IntegrationError::StepUnderflow { h_s: h, t_s });
        }
    }
}

/// Bounds of [`adaptive_step`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct StepLimits {
    /// Error exponent: 1/(order + 1) of the lower-order estimate.
    pub exponent: f64,
    /// Smallest step-size factor.
    pub min_factor: f64,
    /// Largest step-size factor.
    pub max_factor: f64,
    /// Largest step [s].
    pub h_max_s: f64,
    /// Smallest step before giving up [s].
    pub h_min_s: f64,
}
