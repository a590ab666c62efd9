//! [`StrideWorkspace`]: what repeated strides of one walker reuse, besides what the walker
//! itself compiled once from its model (the trees and the witnesses' planar points,
//! `crate::engine::compiled`) — the reference engine's phase (its copies of the trees, whose
//! assemblies it writes, and the general dynamics workspace), the witnesses' kinematics, and
//! the loop's scratch storage; and the stride's entry points
//! ([`Walker::stride`], [`StrideWorkspace::stride`]), which pick the engine a stride runs on
//! (the fixed-size one where it covers the stride, else the reference) and run the one loop
//! (`stride::run`) on it.
//!
//! The workspace borrows its walker, which is read-only: what it holds stays the model's. [`Walker::stride`] makes one for a single stride; the
//! walk loop and the gait search keep one across their strides.

use super::engine::DynamicEngine;
use super::failure::{FailureCause, StrideFailure};
use super::fast;
use super::phase::Phase;
use super::request::StrideRequest;
use super::result::StrideResult;
use super::run::{Run, Start};
use super::schedule::Schedule;
use super::settings::StrideSettings;
use super::witnesses::{Watch, Witnesses};
use crate::engine::integrators::{IntegratorChoice, Sample};
use crate::engine::walker::Walker;
use crate::engine::EvaluationPath;
use nalgebra::DVector;

/// What repeated strides of one walker reuse (see the module's documentation).
pub struct StrideWorkspace<'w> {
    walker: &'w Walker,
    /// The reference engine of the last stride that ran on it, with the integrator and the
    /// path it was built for.
    reference: Option<(IntegratorChoice, EvaluationPath, DynamicEngine<'w>)>,
    /// The reference engine's witnesses (their kinematics storage).
    pub(super) witnesses: Option<Witnesses<'w>>,
    /// Storage for the watches a step triggers.
    pub(super) triggered: Vec<Watch>,
}

impl<'w> StrideWorkspace<'w> {
    /// An empty workspace for strides of `walker` (filled at its first stride).
    pub fn new(walker: &'w Walker) -> Self {
        Self {
            walker,
            reference: None,
            witnesses: None,
            triggered: Vec::new(),
        }
    }

    /// The walker this workspace runs strides of.
    pub fn walker(&self) -> &'w Walker {
        self.walker
    }

    /// The reference engine for `settings`: the last stride's, restarted (all coordinates
    /// free, none driven, nothing to reuse), when it was built for the same integrator and
    /// path; else a new one.
    pub(super) fn reference_engine(&mut self, settings: &StrideSettings) -> DynamicEngine<'w> {
        match self.reference.take() {
            Some((integrator, path, mut engine))
                if integrator == settings.integrator && path == settings.evaluation =>
            {
                engine.phase.restart();
                engine
            }
            _ => DynamicEngine {
                integrator: settings.integrator.build(),
                phase: Phase::of_walker(self.walker, settings.evaluation),
            },
        }
    }

    /// Keeps the reference engine of a finished stride for the next one.
    pub(super) fn keep_reference(&mut self, settings: &StrideSettings, engine: DynamicEngine<'w>) {
        self.reference = Some((settings.integrator.clone(), settings.evaluation, engine));
    }
}

impl Walker {
    /// Simulates one stride from `q0`, `qd0` (just after heel strike, stance labelling) as
    /// `request` asks: its settings, what it records, its step schedule, its controller. (A
    /// [`StrideWorkspace`] of its own: repeated strides reuse one with
    /// [`StrideWorkspace::stride`].)
    ///
    /// # Errors
    /// A [`StrideFailure`] saying how and when (stride time) the stride failed; samples
    /// recorded into the request's sink up to the failure are kept there.
    pub fn stride(
        &self,
        q0: &DVector<f64>,
        qd0: &DVector<f64>,
        request: StrideRequest<'_>,
    ) -> Result<StrideResult, StrideFailure> {
        StrideWorkspace::new(self).stride(q0, qd0, request)
    }
}

impl StrideWorkspace<'_> {
    /// [`Walker::stride`] of this workspace's walker, on this workspace: the reference
    /// engine's storage is made at the first stride that runs on it (again only when a request
    /// asks for another path or integrator) and reused after.
    ///
    /// # Errors
    /// As [`Walker::stride`].
    pub fn stride(
        &mut self,
        q0: &DVector<f64>,
        qd0: &DVector<f64>,
        request: StrideRequest<'_>,
    ) -> Result<StrideResult, StrideFailure> {
        let walker = self.walker();
        let StrideRequest {
            settings,
            options,
            mut schedule,
            control,
            sink,
        } = request;
        if control.is_some() && walker.ankle().is_none() {
            return Err(StrideFailure::new(0.0, FailureCause::NoAnkleReflex));
        }
        settings.search_budget.take().map_err(|limit_strides| {
            StrideFailure::new(0.0, FailureCause::SearchBudget { limit_strides })
        })?;
        let mut own = Vec::new();
        let keep_in_result = sink.is_none();
        let trajectory = match sink {
            Some(s) => s,
            None => &mut own,
        };
        if fast::covers(walker, settings, options, control.is_some()) {
            let mut triggered = std::mem::take(&mut self.triggered);
            let compiled = walker.compiled(settings.evaluation);
            if let (Some(tree), Some(points)) = (&compiled.planar, &compiled.planar_points) {
                let recorded = trajectory.len();
                let fast_schedule = match &mut schedule {
                    Schedule::Free => Schedule::Free,
                    Schedule::Record(s) => Schedule::Record(s),
                    Schedule::Replay(s) => Schedule::Replay(s),
                };
                let start = Start {
                    walker,
                    settings,
                    options,
                    schedule: fast_schedule,
                    trajectory,
                    triggered: &mut triggered,
                };
                let done = fast::stride(start, tree, points, q0, qd0);
                self.triggered = triggered;
                match done {
                    Some(mut r) => {
                        if keep_in_result {
                            r.trajectory = own;
                        }
                        return Ok(r);
                    }
                    None => trajectory.truncate(recorded),
                }
            } else {
                self.triggered = triggered;
            }
        }
        let cur = Sample {
            t_s: 0.0,
            q: q0.clone(),
            qd: qd0.clone(),
        };
        let mut engine = self.reference_engine(settings);
        engine.integrator.reset();
        for c in walker.initially_locked() {
            engine.phase.active[c.0] = false;
        }
        let mut wit = self
            .witnesses
            .take()
            .unwrap_or_else(|| Witnesses::new(walker));
        wit.floor_step_m = options.floor_step_m;
        let start = Start {
            walker,
            settings,
            options,
            schedule,
            trajectory,
            triggered: &mut self.triggered,
        };
        let (r, parts) = match Run::new(start, engine, wit, control, cur) {
            Ok(run) => run.run(),
            Err(e) => return Err(e),
        };
        let (engine, wit) = parts;
        self.witnesses = Some(wit);
        self.keep_reference(settings, engine);
        let mut r = r?;
        if keep_in_result {
            r.trajectory = own;
        }
        Ok(r)
    }
}
