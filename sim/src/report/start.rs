//! Where a walk started ([`StartRecord`]): the gait of a scene, found by the one gait rule
//! (`crate::analysis::homotopy::nominal_gait`) with where it came from, or the scene's guess.

use crate::analysis::homotopy::GaitSource;
use crate::analysis::limit_cycle::Gait;
use serde::Serialize;

/// What a walk started from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StartKind {
    /// A gait's fixed point.
    Gait,
    /// The scene's guess (no search).
    Guess,
}

/// Where a walk started: `walker walk`'s and `walker sil`'s `start` object.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StartRecord {
    /// A gait or the scene's guess.
    pub from: StartKind,
    /// The scene whose gait or guess it is (another one with `--start-from-scene`).
    pub scene: String,
    /// Where the gait came from, as `walker gait`'s `gait_source` for that scene at these
    /// values (`null` for the guess).
    pub gait_source: Option<GaitSource>,
    /// The gait's step period \[s\] (`null` for the guess).
    pub gait_step_period_s: Option<f64>,
}

impl StartRecord {
    /// The gait `gait` of scene `scene`, from `source`.
    pub fn gait(scene: &str, gait: &Gait, source: GaitSource) -> Self {
        Self {
            from: StartKind::Gait,
            scene: scene.to_string(),
            gait_source: Some(source),
            gait_step_period_s: Some(gait.stride.duration_s),
        }
    }

    /// The guess of scene `scene`.
    pub fn guess(scene: &str) -> Self {
        Self {
            from: StartKind::Guess,
            scene: scene.to_string(),
            gait_source: None,
            gait_step_period_s: None,
        }
    }

    /// In words, for text output.
    pub fn describe(&self) -> String {
        match (self.from, self.gait_source, self.gait_step_period_s) {
            (StartKind::Gait, Some(source), Some(period_s)) => format!(
                "the gait of `{}` (step period {period_s:.4} s): {}, as `walker gait` finds it",
                self.scene,
                source.describe()
            ),
            (StartKind::Gait, _, _) => format!("the gait of `{}`", self.scene),
            (StartKind::Guess, _, _) => format!("the guess of `{}` (no gait search)", self.scene),
        }
    }
}
