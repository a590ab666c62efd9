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

/// Where a walk "from the gait" starts ([`gait_start`]).
#[derive(Clone, Debug)]
pub enum GaitStart {
    /// The scene's own gait.
    Own {
        /// The gait.
        gait: Box<Gait>,
        /// Where it came from.
        source: GaitSource,
    },
    /// The scene has no gait of its own; the scene it names to start from
    /// (`walk_start_scene`) has one.
    Other {
        /// The scene's own search error.
        own: NewtonError,
        /// The other scene's gait and the start it gives.
        start: Box<OtherSceneStart>,
    },
    /// Neither the scene nor the scene it names (if any) has a gait.
    None {
        /// The scene's own search error.
        own: NewtonError,
        /// The scene it names to start from, and that scene's search error.
        other: Option<(String, NewtonError)>,
    },
}

/// The one rule of a walk from the gait, for `walker walk`, `walker sil` and the Python
/// package: the scene's own gait by `rule`; when it has none and names a scene to start from
/// (`walk_start_scene`), that scene's gait ([`other_scene_gait`]).
///
/// # Errors
/// A scene cannot be loaded or built at the values the rule visits.
pub fn gait_start(
    scene: &Scene,
    walker: &Walker,
    rule: &GaitRule<'_>,
) -> Result<GaitStart, SceneError> {
    let own = match rule.gait(scene)? {
        Ok((gait, source)) => {
            return Ok(GaitStart::Own {
                gait: Box::new(gait),
                source,
            })
        }
        Err(e) => e,
    };
    let Some(other) = &scene.file.walk_start_scene else {
        return Ok(GaitStart::None { own, other: None });
    };
    Ok(match other_scene_gait(other, scene, walker, rule)? {
        Ok(start) => GaitStart::Other {
            own,
            start: Box::new(start),
        },
        Err(e) => GaitStart::None {
            own,
            other: Some((other.clone(), e)),
        },
    })
}
