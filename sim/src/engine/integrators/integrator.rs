//! The [`Integrator`] interface: a step chosen by the integrator, an exact step, dense output.

use super::dense::DenseOutput;
use super::system::{IntegrationError, Sample, SecondOrderSystem};

/// How the equations changed without the state changing ([`Integrator::system_changed`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SystemChange {
    /// Anything may have changed: a derivative kept from the last step is forgotten.
    Equations,
    /// At the current state only what a system solves for after its assembly changed (a
    /// driven coordinate's prescribed acceleration at a control tick whose drive continues the
    /// last one's angle and rate to the bit): the derivative kept from the last step is
    /// solved again on that step's last assembly
    /// ([`SecondOrderSystem::accelerations_again_into`]), when the system still holds it.
    DriveAcceleration,
}

/// One integrator: a step chosen by itself, and an exact step of a given size.
pub trait Integrator {
    /// Name for reports.
    fn name(&self) -> &'static str;
    /// Clears any per-trajectory memory (step-size history, counters). Call at a new start.
    fn reset(&mut self);
    /// The step this integrator would take next from `t_s` \[s\].
    fn proposed_step_s(&self) -> f64;
    /// Takes one accepted step from `from` of size at most `h_limit_s`, returning the new sample.
    fn advance(
        &mut self,
        sys: &mut dyn SecondOrderSystem,
        from: &Sample,
        h_limit_s: f64,
    ) -> Result<Sample, IntegrationError>;
    /// Takes one step of exactly `h_s` (no error control; used to refine an event time
    /// inside the last accepted step).
    fn step_exact(
        &mut self,
        sys: &mut dyn SecondOrderSystem,
        from: &Sample,
        h_s: f64,
    ) -> Result<Sample, IntegrationError>;
    /// Number of right-hand-side evaluations since `reset`.
    fn evaluations(&self) -> usize;
    /// The equations changed without the state changing (e.g. a control tick moved an
    /// actuator), as `change` says: a derivative kept from the last step is forgotten, or
    /// solved again.
    fn system_changed(&mut self, _change: SystemChange) {}
    /// The system's evaluation epoch ([`SecondOrderSystem::evaluation_epoch`]) of the last
    /// stage of the last step taken, when that stage was evaluated at the step's end (first
    /// same as last) and nothing but a [`SystemChange::DriveAcceleration`] happened since:
    /// what a caller at that step's end names to read the system's assembly there. `None`
    /// otherwise (and for integrators whose last stage is not at the step's end).
    fn end_stage_epoch(&self) -> Option<u64> {
        None
    }
    /// The dense output of the last step taken (by `advance` or `step_exact`) when it went
    /// from `from` to `to` and the integrator has a continuous extension; `None` otherwise
    /// (then events are refined with exact steps). Its extra stages count as evaluations.
    fn dense_output(
        &mut self,
        _sys: &mut dyn SecondOrderSystem,
        _from: &Sample,
        _to: &Sample,
    ) -> Option<Result<DenseOutput, IntegrationError>> {
        None
    }
    /// Whether [`Self::interpolant`] can give the solution inside a step (a continuous
    /// extension for sampling, which events need not use).
    fn interpolates(&self) -> bool {
        false
    }
    /// An interpolant of the last step taken when it went from `from` to `to`: the solution
    /// anywhere inside it, for sampling (a controller's ticks inside a step). DOP853's dense
    /// output, DOPRI5's continuous extension (which its event location does not use); `None`
    /// otherwise. Its extra stages, if any, count as evaluations.
    fn interpolant(
        &mut self,
        _sys: &mut dyn SecondOrderSystem,
        _from: &Sample,
        _to: &Sample,
    ) -> Option<Result<DenseOutput, IntegrationError>> {
        None
    }
}
