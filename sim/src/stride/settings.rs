//! The solver settings of a stride: how it is integrated, how precisely its events are located,
//! and how long it may last. Apart from the walker (the physics), so that the same walker can be
//! run with other settings without being changed.

use crate::events::EventTolerance;
use crate::integrators::IntegratorChoice;
use serde::Serialize;

/// Solver settings of a stride (after rapier's `IntegrationParameters`: each field with its unit
/// and default). A scene file's `integrator` section sets them ([`crate::scene::Scene::setup`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StrideSettings {
    /// The integrator and its step or tolerances. Default: DOPRI5 with `rtol = atol = 1e-12`
    /// and a largest step of 0.05 s (the scene file's default `kind = "dopri5"`).
    pub integrator: IntegratorChoice,
    /// Tolerances of event location and the grazing check. Default:
    /// [`EventTolerance::default`] (1e-13 s, witness 1e-14, 60 iterations, 4 grazing samples).
    pub event_tolerance: EventTolerance,
    /// A stride that has not ended in heel strike after this much stride time fails with
    /// `no_impact_within_time` [s]. Default: 10 s.
    pub max_stride_time_s: f64,
}

impl Default for StrideSettings {
    fn default() -> Self {
        Self {
            integrator: IntegratorChoice::Dopri5 {
                rtol: 1e-12,
                atol: 1e-12,
                h_max_s: 0.05,
            },
            event_tolerance: EventTolerance::default(),
            max_stride_time_s: 10.0,
        }
    }
}

impl StrideSettings {
    /// The same settings with another integrator.
    pub fn with_integrator(&self, integrator: IntegratorChoice) -> Self {
        Self {
            integrator,
            ..self.clone()
        }
    }
}
