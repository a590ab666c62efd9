//! [`StrideWorkspace`]: what repeated strides of one walker reuse — the structures derived
//! from the model for the stride's evaluation path (the planar tree and the witnesses'
//! geometry of the fixed-size engine; the reference engine's phase, with its planar tree,
//! axis tree and dynamics workspace; the witnesses' kinematics), compiled at the first stride
//! that needs them, and the loop's scratch storage.
//!
//! The workspace borrows its walker: the model cannot change while the workspace lives, so
//! what it compiled stays the model's. [`Walker::stride`] makes one for a single stride; the
//! walk loop and the gait search keep one across their strides.

use super::engine::DynamicEngine;
use super::fast;
use super::phase::Phase;
use super::settings::StrideSettings;
use super::witnesses::{Watch, Witnesses};
use super::EvaluationPath;
use crate::integrators::IntegratorChoice;
use crate::walker::Walker;

/// What repeated strides of one walker reuse (see the module's documentation).
pub struct StrideWorkspace<'w> {
    walker: &'w Walker,
    /// The fixed-size engine's compiled structures, for the path they were compiled for
    /// (`None` inside: the walker does not qualify on that path).
    fixed: Option<(EvaluationPath, Option<fast::Compiled>)>,
    /// The reference engine of the last stride that ran on it, with the integrator and the
    /// path it was built for.
    reference: Option<(IntegratorChoice, EvaluationPath, DynamicEngine<'w>)>,
    /// The reference engine's witnesses (their kinematics storage).
    pub(super) witnesses: Option<Witnesses<'w>>,
    /// Storage for the watches a step triggers.
    pub(super) triggered: Vec<Watch>,
}

impl<'w> StrideWorkspace<'w> {
    /// An empty workspace for strides of `walker` (compiled at its first stride).
    pub fn new(walker: &'w Walker) -> Self {
        Self {
            walker,
            fixed: None,
            reference: None,
            witnesses: None,
            triggered: Vec::new(),
        }
    }

    /// The walker this workspace runs strides of.
    pub fn walker(&self) -> &'w Walker {
        self.walker
    }

    /// The fixed-size engine's structures on `path`, compiled on first use.
    pub(super) fn fixed(&mut self, path: EvaluationPath) -> Option<&fast::Compiled> {
        if !matches!(&self.fixed, Some((p, _)) if *p == path) {
            self.fixed = Some((path, fast::Compiled::of(self.walker, path)));
        }
        self.fixed.as_ref().and_then(|(_, c)| c.as_ref())
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
                phase: Phase::with_path(&self.walker.model, settings.evaluation),
            },
        }
    }

    /// Keeps the reference engine of a finished stride for the next one.
    pub(super) fn keep_reference(&mut self, settings: &StrideSettings, engine: DynamicEngine<'w>) {
        self.reference = Some((settings.integrator.clone(), settings.evaluation, engine));
    }
}
