//! The solver settings of a stride: how it is integrated, how precisely its events are located,
//! and how long it may last. Apart from the walker (the physics), so that the same walker can be
//! run with other settings without being changed.

use super::EvaluationPath;
use crate::engine::control::TickStepping;
use crate::engine::events::EventTolerance;
use crate::engine::integrators::{IntegratorChoice, IntegratorError};
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
    /// `no_impact_within_time` \[s\]. Default: 10 s.
    pub max_stride_time_s: f64,
    /// A stride that has taken this many integrator steps without ending fails with
    /// `step_budget_exceeded`, whatever its stride time (a step that does not advance time
    /// cannot loop forever). Default: [`Self::DEFAULT_MAX_STEPS`].
    pub max_steps: usize,
    /// A stride that has evaluated the equations of motion this many times (integration,
    /// event location, grazing checks) without ending fails with
    /// `evaluation_budget_exceeded`. Default: [`Self::DEFAULT_MAX_EVALUATIONS`].
    pub max_evaluations: usize,
    /// Which evaluation of the equations of motion the smooth phases use. Default:
    /// [`EvaluationPath::Auto`] (the planar fast path when the walker qualifies); `General`
    /// forces the general engine, the reference.
    pub evaluation: EvaluationPath,
    /// How a controlled stride's steps meet the control ticks. Default:
    /// [`TickStepping::HeldAcrossTicks`]; `EndAtEveryTick` is the reference.
    pub tick_stepping: TickStepping,
    /// A budget of strides shared with the other strides of a search (see
    /// [`super::SearchBudget`]); each stride takes one. Default: none. Not serialised, not
    /// compared.
    #[serde(skip)]
    pub search_budget: super::SharedBudget,
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
            max_steps: Self::DEFAULT_MAX_STEPS,
            max_evaluations: Self::DEFAULT_MAX_EVALUATIONS,
            evaluation: EvaluationPath::Auto,
            tick_stepping: TickStepping::default(),
            search_budget: super::SharedBudget::default(),
        }
    }
}

impl StrideSettings {
    /// Default step budget of a stride. The largest stride in the engine's tests took 814
    /// steps (12,606 evaluations, DOP853 on the wisse walkers); the accuracy study's finest
    /// fixed step is a 3,200th of a stride. A million steps lets a fixed step of 5 µs cover a
    /// 5 s stride time budget, and bounds a stride's time (wisse3d: a few µs per evaluation).
    pub const DEFAULT_MAX_STEPS: usize = 1_000_000;
    /// Default evaluation budget of a stride: enough for [`Self::DEFAULT_MAX_STEPS`] steps of
    /// DOP853 (12 evaluations a step) with their event location.
    pub const DEFAULT_MAX_EVALUATIONS: usize = 16_000_000;

    /// Checks that these settings can run a stride: the integrator's settings positive and
    /// finite, and its (largest) step long enough to cover the stride time budget within the
    /// step budget ([`IntegratorChoice::validate_with_budget`]).
    ///
    /// # Errors
    /// [`IntegratorError`] naming the setting and its value.
    pub fn validate(&self) -> Result<(), IntegratorError> {
        self.integrator
            .validate_with_budget(self.max_stride_time_s, self.max_steps)
    }

    /// The same settings with another integrator.
    pub fn with_integrator(&self, integrator: IntegratorChoice) -> Self {
        Self {
            integrator,
            ..self.clone()
        }
    }

    /// The same settings with another way of stepping across control ticks.
    pub fn with_tick_stepping(&self, tick_stepping: TickStepping) -> Self {
        Self {
            tick_stepping,
            ..self.clone()
        }
    }
}
