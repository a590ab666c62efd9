//! The `walker gaits` report: every distinct period-1 gait a census found, each as
//! `walker gait --json` reports one.

use super::GaitReport;
use serde::Serialize;

/// The `walker gaits --json` object.
#[derive(Clone, Debug, Serialize)]
pub struct GaitsReport {
    /// Scene name.
    pub scene: String,
    /// The gaits, longest step period first, each as `walker gait --json` prints it.
    pub gaits: Vec<GaitReport>,
    /// Newton searches the census ran (its budget: docs/bifurcations.md).
    pub searches: usize,
}
