//! The fixed point of a gait by name, as the reports list it.

use crate::analysis::limit_cycle::Gait;
use crate::engine::walker::Walker;
use crate::scene::Scene;
use nalgebra::DVector;
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
        Self::of_state(scene, walker, &gait.fixed_point)
    }

    /// The stride-map vector `v` (a state just after heel strike) named the same way.
    pub fn of_state(scene: &Scene, walker: &Walker, v: &DVector<f64>) -> Self {
        let mut m: BTreeMap<String, f64> = walker
            .map_names()
            .into_iter()
            .zip(v.iter().copied())
            .collect();
        let (q, qd) = walker.unpack(v);
        if let Ok(extra) = scene.convention_outputs(walker, &q, &qd) {
            m.extend(extra);
        }
        Self(m)
    }
}
