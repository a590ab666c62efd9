//! What the one stride loop (`stride::run`) needs of the evaluation behind a state's storage
//! ([`StrideState`], in `state`; its witnesses, [`WitnessEvaluator`], in `witnesses`):
//! [`Engine`] (the smooth phase, its integrator, event location and the heel-strike impact on
//! that storage).
//!
//! Two engines: the reference (`DynamicEngine`: [`Phase`] on `DVector` samples with any
//! integrator, the planar, axis-tree or general evaluation inside it) and the fixed-size one
//! (`stride::fast`: DOP853 on `SVector<N>` states with the planar closed forms or link pass),
//! chosen for each stride from the walker and the settings. The loop's rules (grazing check,
//! triggered witnesses, the ignored-scuff rule, the earliest event, heel strike and scuffs,
//! knee locks, budgets, control ticks) are written once, in the loop, on top of these traits.

use super::contact_figures::ContactSummary;
use super::failure::StrideFailure;
use super::phase::{Drive, Phase};
use super::result::{StrideEvent, StrideResult};
use super::state::StrideState;
use super::witnesses::{WitnessEvaluator, Witnesses};
use crate::engine::dynamics::DynamicsError;
use crate::engine::events::{locate, EventError, EventTolerance};
use crate::engine::integrators::{DenseOutput, IntegrationError, Integrator, Sample, SystemChange};
use crate::engine::model::CoordIndex;
use crate::engine::walker::Walker;

/// The solution inside one step, for a controller's ticks there.
pub(super) trait Interpolant<S> {
    /// The interpolated state at `t_s` (inside the step).
    fn eval(&self, t_s: f64) -> S;
}

impl Interpolant<Sample> for DenseOutput {
    fn eval(&self, t_s: f64) -> Sample {
        DenseOutput::eval(self, t_s)
    }
}

/// No interpolant (an engine that runs no controller).
#[derive(Debug)]
pub(super) enum NoInterpolant {}

impl<S> Interpolant<S> for NoInterpolant {
    fn eval(&self, _t_s: f64) -> S {
        match *self {}
    }
}

/// The smooth phase of a stride on one state storage: its free and driven coordinates, its
/// integrator, event location, and the heel-strike impact.
pub(super) trait Engine {
    /// How a state is stored.
    type State: StrideState;
    /// The solution inside a step, for a controller's ticks.
    type Interpolant: Interpolant<Self::State>;
    /// The witnesses' evaluation on this storage.
    type Witness: WitnessEvaluator<Self::State>;
    /// Whether a failure, or a step that triggers several events, hands the stride back to
    /// the reference engine (which runs it again from its start) instead of being the result.
    const HANDS_BACK: bool;

    /// One step from `cur` chosen by the integrator, at most `h_limit_s` long.
    fn advance(
        &mut self,
        cur: &Self::State,
        h_limit_s: f64,
    ) -> Result<Self::State, IntegrationError>;
    /// One step of exactly `h_s` from `cur`.
    fn step_exact(&mut self, cur: &Self::State, h_s: f64) -> Result<Self::State, IntegrationError>;
    /// Locates the zero of `g` on the step `cur` → `next` (the last one taken).
    fn locate<G: FnMut(&Self::State) -> f64>(
        &mut self,
        cur: &Self::State,
        next: &Self::State,
        g: G,
        tol: &EventTolerance,
    ) -> Result<Self::State, EventError>;
    /// Whether the integrator has an interpolant inside its steps.
    fn interpolates(&self) -> bool;
    /// The interpolant of the last step when it went `cur` → `next`.
    fn interpolant(
        &mut self,
        cur: &Self::State,
        next: &Self::State,
    ) -> Option<Result<Self::Interpolant, IntegrationError>>;
    /// Evaluations since the integrator's last reset.
    fn evaluations(&self) -> usize;
    /// A new phase after an impact: the integrator restarts.
    fn reset(&mut self);
    /// The equations changed without the state changing, as `change` says.
    fn system_changed(&mut self, change: SystemChange);

    /// Which coordinates are free.
    fn active(&self) -> &[bool];
    /// Frees (`true`) or locks coordinate `c`.
    fn set_active(&mut self, c: usize, free: bool);
    /// The driven coordinate and its drive, if any.
    fn prescribed(&self) -> Option<(CoordIndex, Drive)>;
    /// Drives a coordinate (or none).
    fn set_prescribed(&mut self, p: Option<(CoordIndex, Drive)>);
    /// Puts the driven coordinate of `s` exactly on its drive.
    fn snap(&self, s: &mut Self::State);
    /// The driven coordinate's actuator force and rate at `s`; `at_step_end`: the loop states
    /// that `s` is the end of the last step taken (where an integrator whose last stage is
    /// evaluated there left an assembly to read).
    fn actuator_torque(
        &mut self,
        s: &Self::State,
        at_step_end: bool,
    ) -> Result<(f64, f64), DynamicsError>;
    /// Adds the contact figures of the accepted state `s`.
    fn add_contact(
        &mut self,
        summary: &mut ContactSummary,
        walker: &Walker,
        wit: &mut Self::Witness,
        s: &Self::State,
    ) -> Result<(), DynamicsError>;
    /// Heel strike at `at` (`at_sample` the same state as a sample): the impact, the lift
    /// check and the relabelling (the run's own figures are left for the loop).
    fn finish(
        &mut self,
        walker: &Walker,
        at: (&Self::State, Sample),
        events: Vec<StrideEvent>,
        energy_loss_j: f64,
    ) -> Result<StrideResult, StrideFailure>;
}

/// The reference engine: [`Phase`] (the planar, axis-tree or general evaluation) on `DVector`
/// samples, with the stride's integrator.
pub(super) struct DynamicEngine<'w> {
    pub(super) integrator: Box<dyn Integrator>,
    pub(super) phase: Phase<'w>,
}

impl<'w> Engine for DynamicEngine<'w> {
    type State = Sample;
    type Interpolant = DenseOutput;
    type Witness = Witnesses<'w>;
    const HANDS_BACK: bool = false;

    fn advance(&mut self, cur: &Sample, h_limit_s: f64) -> Result<Sample, IntegrationError> {
        self.integrator.advance(&mut self.phase, cur, h_limit_s)
    }

    fn step_exact(&mut self, cur: &Sample, h_s: f64) -> Result<Sample, IntegrationError> {
        self.integrator.step_exact(&mut self.phase, cur, h_s)
    }

    fn locate<G: FnMut(&Sample) -> f64>(
        &mut self,
        cur: &Sample,
        next: &Sample,
        mut g: G,
        tol: &EventTolerance,
    ) -> Result<Sample, EventError> {
        locate(
            self.integrator.as_mut(),
            &mut self.phase,
            cur,
            next,
            &mut g,
            tol,
        )
    }

    fn interpolates(&self) -> bool {
        self.integrator.interpolates()
    }

    fn interpolant(
        &mut self,
        cur: &Sample,
        next: &Sample,
    ) -> Option<Result<DenseOutput, IntegrationError>> {
        self.integrator.interpolant(&mut self.phase, cur, next)
    }

    fn evaluations(&self) -> usize {
        self.integrator.evaluations()
    }

    fn reset(&mut self) {
        self.integrator.reset();
    }

    fn system_changed(&mut self, change: SystemChange) {
        self.integrator.system_changed(change);
    }

    fn active(&self) -> &[bool] {
        &self.phase.active
    }

    fn set_active(&mut self, c: usize, free: bool) {
        self.phase.active[c] = free;
    }

    fn prescribed(&self) -> Option<(CoordIndex, Drive)> {
        self.phase.prescribed
    }

    fn set_prescribed(&mut self, p: Option<(CoordIndex, Drive)>) {
        self.phase.prescribed = p;
    }

    fn snap(&self, s: &mut Sample) {
        self.phase.snap(s);
    }

    fn actuator_torque(
        &mut self,
        s: &Sample,
        at_step_end: bool,
    ) -> Result<(f64, f64), DynamicsError> {
        let assembled = if at_step_end {
            self.integrator.end_stage_epoch()
        } else {
            None
        };
        self.phase.actuator_torque(s, assembled)
    }

    fn add_contact(
        &mut self,
        summary: &mut ContactSummary,
        walker: &Walker,
        wit: &mut Witnesses<'w>,
        s: &Sample,
    ) -> Result<(), DynamicsError> {
        summary.add(walker, &mut self.phase, wit, s)
    }

    fn finish(
        &mut self,
        walker: &Walker,
        (_, at): (&Sample, Sample),
        events: Vec<StrideEvent>,
        energy_loss_j: f64,
    ) -> Result<StrideResult, StrideFailure> {
        walker.finish_stride(at, &self.phase.active, events, energy_loss_j)
    }
}
