//! The `walker walk` report: the steps of a walk and its first failure.

use super::StartRecord;
use crate::scene::Scene;
use crate::stride::walk::{StepSummary, Walk, WalkFailure};
use crate::stride::Floor;
use serde::Serialize;
use std::collections::BTreeMap;

/// The `walker walk --json` object.
#[derive(Clone, Debug, Serialize)]
pub struct WalkReport {
    /// Scene name.
    pub scene: String,
    /// Parameter values the walker was built with.
    pub parameters: BTreeMap<String, f64>,
    /// Steps completed.
    pub steps_completed: usize,
    /// The first failure (`null` if none).
    pub failure: Option<WalkFailure>,
    /// Summaries of the steps completed.
    pub steps: Vec<StepSummary>,
    /// What the walk started from (`null` when the caller did not say).
    pub start: Option<StartRecord>,
    /// The floor walked over (`{"kind": "plane"}`, `step` with `at_heel_strike` and
    /// `height_m`, `rough` with `sigma_m` and `seed`); each step's `floor_step_m` is the level
    /// it landed on.
    pub floor: Floor,
}

impl WalkReport {
    /// The report of `walk` by a walker built from `scene`.
    pub fn new(scene: &Scene, walk: &Walk) -> Self {
        Self {
            scene: scene.name().to_string(),
            parameters: scene.values.clone(),
            steps_completed: walk.steps_completed,
            failure: walk.failure.clone(),
            steps: walk.steps.clone(),
            start: None,
            floor: Floor::Plane,
        }
    }
}
