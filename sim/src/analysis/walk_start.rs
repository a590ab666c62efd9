//! A walk's start from another scene's gait: a scene without a gait of its own (the 3D walker
//! without its compensator) starts from that of the scene it names (`walk_start_scene`), or
//! one the caller names, its state mapped onto this walker's stride map by name.

use super::homotopy::{GaitRule, GaitSource};
use super::limit_cycle::{Gait, NewtonError};
use crate::engine::walker::Walker;
use crate::scene::{Scene, SceneError};
use nalgebra::DVector;

/// The gait of another scene and the start state it gives this walker.
#[derive(Clone, Debug)]
pub struct OtherSceneStart {
    /// The start state: this walker's stride-map entries, each the other gait's fixed-point
    /// entry of the same name (0 where the other walker has none).
    pub state: DVector<f64>,
    /// The other scene, with this scene's values of the parameters they share.
    pub scene: Scene,
    /// Its gait.
    pub gait: Gait,
    /// Where its gait came from.
    pub source: GaitSource,
}

/// The gait of scene `other` (with `scene`'s values of the parameters both have) by `rule`,
/// mapped onto `walker`'s stride-map entries by name; the gait search's error if it has none.
///
/// # Errors
/// `other` cannot be loaded or built, or takes none of `scene`'s values.
pub fn other_scene_gait(
    other: &str,
    scene: &Scene,
    walker: &Walker,
    rule: &GaitRule<'_>,
) -> Result<Result<OtherSceneStart, NewtonError>, SceneError> {
    let mut other_scene = Scene::load(other)?;
    for (k, val) in &scene.values {
        if other_scene.file.parameters.contains_key(k) {
            other_scene.set(k, *val)?;
        }
    }
    let other_walker = other_scene.setup()?.walker;
    let (gait, source) = match rule.gait(&other_scene)? {
        Ok(g) => g,
        Err(e) => return Ok(Err(e)),
    };
    let names = walker.map_names();
    let other_names = other_walker.map_names();
    let mut state = DVector::zeros(names.len());
    for (i, n) in names.iter().enumerate() {
        if let Some(j) = other_names.iter().position(|m| m == n) {
            state[i] = gait.fixed_point[j];
        }
    }
    Ok(Ok(OtherSceneStart {
        state,
        scene: other_scene,
        gait,
        source,
    }))
}
