//! The `walker walk` report: the steps of a walk and its first failure.

use super::StartRecord;
use crate::scene::Scene;
use crate::stride::walk::{StepSummary, Walk, WalkFailure};
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
        }
    }
}
