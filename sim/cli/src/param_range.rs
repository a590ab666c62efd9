//! The parameter range a one-parameter study runs over (`walker sweep`, `walker
//! orbit-diagram`): `--param K --from A --to B`, checked once.

use crate::input_error::InputError;
use clap::Args;

/// `--param`, `--from`, `--to`.
#[derive(Args)]
pub struct ParamRange {
    /// Parameter to vary.
    #[arg(long)]
    pub param: String,
    /// First value.
    #[arg(long, allow_negative_numbers = true)]
    pub from: f64,
    /// Last value.
    #[arg(long, allow_negative_numbers = true)]
    pub to: f64,
}

impl ParamRange {
    /// The range, refused when an end is not finite or both ends are equal (`study` names
    /// the command's result in the message, e.g. "a sweep").
    ///
    /// # Errors
    /// [`InputError::Other`] with the reason.
    pub fn checked(self, study: &str) -> Result<(String, f64, f64), InputError> {
        let ParamRange { param, from, to } = self;
        if !(from.is_finite() && to.is_finite()) {
            return Err(InputError::Other("--from and --to must be finite".into()));
        }
        if from == to {
            return Err(InputError::Other(format!(
                "--from and --to are equal ({from}): {study} needs a range"
            )));
        }
        Ok((param, from, to))
    }
}
