//! How robust a gait is (issue 26; docs/robustness.md): what disturbances it survives and how
//! fast it forgets them.
//!
//! - [`recovery`]: the one loop every measure here runs: strides from a disturbed state over a
//!   floor, until the walker is back on the gait (within a tolerance), settles on another
//!   periodic motion, falls, or runs out of strides.
//! - [`threshold`]: the largest single disturbance survived (a floor step down or up at the
//!   next heel strike; a change of one rate just after heel strike), by a scan and bisection,
//!   and the first larger one survived again (survival is not monotone).
//! - [`first_passage`]: the mean first-passage time on a rough floor (Byl & Tedrake 2009):
//!   Monte Carlo walks, censored walks counted as exposure, an exact 95 % interval.
//! - [`basin`]: a slice of the basin of attraction through the gait (Schwab & Wisse 2001).
//! - The gait sensitivity norm is [`crate::analysis::gait_sensitivity`].
//!
//! Every measure is pure: the same walker, settings, gait and options give the same numbers
//! bit for bit, whatever the number of threads (rayon); parallel work is collected in order.

pub mod basin;
pub mod first_passage;
pub mod recovery;
pub mod threshold;

pub use basin::{
    basin_axes, basin_slice, BasinAxis, BasinCell, BasinError, BasinSlice, MAX_BASIN_CELL_STRIDES,
};
pub use first_passage::{mean_first_passage, FirstPassage, FirstPassageOptions};
pub use recovery::{Outcome, Recovery, ReturnRule};
pub use threshold::{
    step_threshold, step_thresholds, velocity_thresholds, StepDirection, StepThresholds, Threshold,
    ThresholdOptions, VelocityThreshold,
};
