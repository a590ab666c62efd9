//! The `walker basin --json` report: a slice of the basin of attraction of a gait
//! ([`basin_slice`](crate::analysis::robustness::basin_slice)) as grids of outcome names,
//! stride counts and periods.

use super::GaitReport;
use crate::analysis::robustness::{BasinAxis, BasinCell, BasinSlice, Outcome, ReturnRule};
use serde::Serialize;

/// The `walker basin --json` object (the contract's fields, then details). Grids have one row
/// per `y` value, one cell per `x` value.
#[derive(Serialize)]
pub struct BasinReport {
    /// Scene name.
    pub scene: String,
    /// The columns' stride-map coordinate and values.
    pub x: BasinAxis,
    /// The rows' stride-map coordinate and values.
    pub y: BasinAxis,
    /// Each cell's outcome: `gait`, `periodic`, the failure kind, `not_settled`,
    /// `off_section`.
    pub outcome: Vec<Vec<String>>,
    /// Strides each cell took (to return, settle or fail).
    pub strides: Vec<Vec<usize>>,
    /// The period of a `periodic` cell, else `null`.
    pub period: Vec<Vec<Option<usize>>>,
    /// Cells back on the gait over all cells.
    pub fraction_returning: f64,
    /// The position coordinate solved to keep the swing foot on the floor.
    pub solved_coordinate: Option<String>,
    /// The rule a cell's return to the gait is judged by.
    pub return_rule: ReturnRule,
    /// The gait, as `walker gait` reports it.
    pub gait: GaitReport,
}

impl BasinReport {
    /// The report of `slice` of scene `scene`'s gait (`gait`), each cell judged by `rule`.
    pub fn new(scene: &str, slice: &BasinSlice, rule: ReturnRule, gait: GaitReport) -> Self {
        Self {
            scene: scene.to_owned(),
            x: slice.x.clone(),
            y: slice.y.clone(),
            outcome: slice
                .cells
                .iter()
                .map(|r| r.iter().map(BasinCell::name).collect())
                .collect(),
            strides: slice
                .cells
                .iter()
                .map(|r| r.iter().map(BasinCell::strides).collect())
                .collect(),
            period: slice
                .cells
                .iter()
                .map(|r| {
                    r.iter()
                        .map(|c| match c {
                            BasinCell::Strides(Outcome::Periodic { period, .. }) => Some(*period),
                            _ => None,
                        })
                        .collect()
                })
                .collect(),
            fraction_returning: slice.fraction_returning,
            solved_coordinate: slice.solved_coordinate.clone(),
            return_rule: rule,
            gait,
        }
    }
}
