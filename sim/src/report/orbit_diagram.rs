//! The `walker orbit-diagram` report: the attractor at each parameter value, with its
//! heel-strike states by coordinate name.

use crate::analysis::orbit_diagram::{Attractor, OrbitPoint, OrbitSettings};
use crate::engine::walker::Walker;
use crate::scene::Scene;
use crate::stride::FailureKind;
use serde::Serialize;
use std::collections::BTreeMap;

/// The `walker orbit-diagram --json` object.
#[derive(Clone, Debug, Serialize)]
pub struct OrbitDiagramReport {
    /// Scene name.
    pub scene: String,
    /// The parameter varied.
    pub param: String,
    /// One entry per value, in order.
    pub points: Vec<OrbitPointRecord>,
    /// The bounds the attractors were classified with.
    pub settings: OrbitSettings,
}

/// One value of the diagram.
#[derive(Clone, Debug, Serialize)]
pub struct OrbitPointRecord {
    /// The parameter value.
    pub value: f64,
    /// `periodic`, `chaotic` or `fell`.
    pub attractor: &'static str,
    /// Strides per cycle (`null` unless periodic).
    pub period_strides: Option<usize>,
    /// Heel-strike states on the attractor by name (stride-map entries and the scene's
    /// convention outputs): the cycle, or the last window of a chaotic attractor; empty after
    /// a fall.
    pub samples: BTreeMap<String, Vec<f64>>,
    /// How the walker fell (`null` unless it did).
    pub failure: Option<FellRecord>,
    /// Strides simulated at this value.
    pub strides: usize,
    /// Started from a seed gait rather than the previous value's attractor.
    pub seeded: bool,
}

/// A fall in the orbit diagram.
#[derive(Clone, Debug, Serialize)]
pub struct FellRecord {
    /// Failure kind.
    pub kind: FailureKind,
    /// The stride that failed, counted from 1 at this value.
    pub stride: usize,
    /// When in that stride \[s\].
    pub time_s: f64,
    /// Details.
    pub detail: String,
}

impl OrbitDiagramReport {
    /// The report of `points` of `param` on `scene` (whose walker is `walker`).
    pub fn new(
        scene: &Scene,
        walker: &Walker,
        param: &str,
        points: &[OrbitPoint],
        settings: &OrbitSettings,
    ) -> Self {
        let names = walker.map_names();
        let points = points
            .iter()
            .map(|p| {
                let mut at = scene.clone();
                let conventions_ok = at.set(param, p.value).is_ok();
                let mut samples: BTreeMap<String, Vec<f64>> = BTreeMap::new();
                for v in &p.states {
                    for (k, x) in names.iter().zip(v.iter()) {
                        samples.entry(k.clone()).or_default().push(*x);
                    }
                    let (q, qd) = walker.unpack(v);
                    if conventions_ok {
                        for (k, x) in at.convention_outputs(walker, &q, &qd).unwrap_or_default() {
                            samples.entry(k).or_default().push(x);
                        }
                    }
                }
                let (attractor, period_strides, failure) = match &p.attractor {
                    Attractor::Periodic { period } => ("periodic", Some(*period), None),
                    Attractor::Chaotic => ("chaotic", None, None),
                    Attractor::Fell { stride, failure } => (
                        "fell",
                        None,
                        Some(FellRecord {
                            kind: failure.kind,
                            stride: *stride,
                            time_s: failure.t_stride_s,
                            detail: failure.detail(),
                        }),
                    ),
                };
                OrbitPointRecord {
                    value: p.value,
                    attractor,
                    period_strides,
                    samples,
                    failure,
                    strides: p.strides,
                    seeded: p.seeded,
                }
            })
            .collect();
        Self {
            scene: scene.name().to_string(),
            param: param.to_string(),
            points,
            settings: *settings,
        }
    }
}
