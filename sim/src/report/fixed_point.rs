//! The fixed point of a gait by name, as the reports list it.

use crate::limit_cycle::Gait;
use crate::scene::Scene;
use crate::walker::Walker;
use serde::Serialize;
use std::collections::BTreeMap;

/// The fixed point as `name → value`: the stride-map entries (coordinates and their rates,
/// `_dot`) and the scene's convention outputs (e.g. Goswami's angles), which replace a
/// stride-map entry of the same name.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(transparent)]
pub struct FixedPoint(pub BTreeMap<String, f64>);

impl FixedPoint {
    /// The fixed point of `gait`, named by `walker`'s stride map and `scene`'s conventions.
    pub fn of(scene: &Scene, walker: &Walker, gait: &Gait) -> Self {
        let mut m: BTreeMap<String, f64> = walker
            .map_names()
            .into_iter()
            .zip(gait.fixed_point.iter().copied())
            .collect();
        let (q, qd) = walker.unpack(&gait.fixed_point);
        if let Ok(extra) = scene.convention_outputs(walker, &q, &qd) {
            m.extend(extra);
        }
        Self(m)
    }
}
