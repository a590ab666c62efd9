//! What a stride is asked to do: [`StrideRequest`], the one argument of
//! [`crate::engine::walker::Walker::stride`] besides the start state.

use super::schedule::Schedule;
use super::settings::StrideSettings;
use crate::engine::control::AnkleController;
use crate::engine::integrators::Sample;

/// What a stride keeps besides its result, and the floor it ends on.
#[derive(Clone, Copy, Debug, Default)]
pub struct StrideOptions {
    /// Keep every accepted sample (in [`super::StrideResult::trajectory`], or in the request's
    /// sink).
    pub record: bool,
    /// Compute the contact load, lateral centre of pressure and swing clearance at every
    /// accepted sample (for reports; costs one more evaluation per step).
    pub contact: bool,
    /// The floor where the swing foot lands, above the stance foot's floor \[m\], measured
    /// along the floor's normal (up positive): a step up (> 0) or down (< 0) at this stride's
    /// heel strike; the floor stays at the new level (the next stride's floor is where its
    /// stance foot stands). The heel strike is the swing foot reaching that level ahead of
    /// the stance contact. Default 0: one plane.
    pub floor_step_m: f64,
}

/// A controller moving the stance ankle's string during a stride.
pub struct StrideControl<'a> {
    /// The controller, sampled at its control ticks (on the grid `k · period` of walk time)
    /// and told of the heel strike.
    pub controller: &'a mut dyn AnkleController,
    /// Walk time at the start of this stride \[s\] (the controller's clock; the stride's own
    /// clock starts at 0).
    pub t_walk_start_s: f64,
}

/// Everything a stride is asked to do: solver settings, what to record, how to choose its
/// steps, and an optional controller.
///
/// ```ignore
/// let r = walker.stride(&q, &qd, StrideRequest::new(&settings).recording())?;
/// ```
pub struct StrideRequest<'a> {
    /// Integrator, event tolerances and time budget.
    pub settings: &'a StrideSettings,
    /// What to record.
    pub options: StrideOptions,
    /// Free, recorded or replayed steps ([`Schedule`]).
    pub schedule: Schedule<'a>,
    /// The stance ankle's string moved by a controller; `None`: the scene's ideal reflex (if
    /// it has one). A controlled stride needs a scene with an `ankle_reflex` section (for the
    /// ankle and toe coordinates; its angles and duration are not used).
    pub control: Option<StrideControl<'a>>,
    /// Where recorded samples go: `None` keeps them in the result; a sink gets them as they
    /// are accepted, so that a failed stride still hands back its samples up to the failure.
    pub sink: Option<&'a mut Vec<Sample>>,
}

impl<'a> StrideRequest<'a> {
    /// A free stride with `settings`, recording nothing, without a controller.
    pub fn new(settings: &'a StrideSettings) -> Self {
        Self {
            settings,
            options: StrideOptions::default(),
            schedule: Schedule::Free,
            control: None,
            sink: None,
        }
    }

    /// Ending on a floor `floor_step_m` above the stance foot's ([`StrideOptions::floor_step_m`]).
    pub fn floor_step(mut self, floor_step_m: f64) -> Self {
        self.options.floor_step_m = floor_step_m;
        self
    }

    /// With these recording options.
    pub fn options(self, options: StrideOptions) -> Self {
        Self { options, ..self }
    }

    /// Recording every accepted sample.
    pub fn recording(self) -> Self {
        let options = StrideOptions {
            record: true,
            ..self.options
        };
        Self { options, ..self }
    }

    /// With its steps recorded or replayed.
    pub fn schedule(self, schedule: Schedule<'a>) -> Self {
        Self { schedule, ..self }
    }

    /// With the stance ankle's string moved by `controller`; `t_walk_start_s` is the walk
    /// time at the start of the stride \[s\].
    pub fn controlled(self, controller: &'a mut dyn AnkleController, t_walk_start_s: f64) -> Self {
        let control = Some(StrideControl {
            controller,
            t_walk_start_s,
        });
        Self { control, ..self }
    }

    /// Recorded samples appended to `sink` (kept up to a failure) instead of the result.
    pub fn sink(self, sink: &'a mut Vec<Sample>) -> Self {
        Self {
            sink: Some(sink),
            ..self
        }
    }
}
