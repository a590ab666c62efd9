//! Step schedules: the accepted step sizes of a stride, phase by phase, recorded or replayed.

/// The accepted step sizes of a stride, phase by phase (a phase ends at an impact).
///
/// For internal numerical differentiation (Bock): the perturbed strides of the stride
/// Jacobian replay the nominal stride's steps, so that their differences are derivatives of
/// one discrete flow rather than of the adaptive step selection, whose accept/reject decisions
/// flip under a perturbation and make the central difference noisy.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StepSchedule {
    /// Step sizes \[s\] of each phase, in order.
    pub phases: Vec<Vec<f64>>,
}

/// How a stride chooses its steps.
#[derive(Debug, Default)]
pub enum Schedule<'a> {
    /// The integrator's own choice.
    #[default]
    Free,
    /// The integrator's own choice, written down.
    Record(&'a mut StepSchedule),
    /// The steps written down (each phase's last step repeated if the phase runs longer);
    /// the integrator's error control is not used.
    Replay(&'a StepSchedule),
}

/// A stride's place in its step schedule, phase by phase: where a replay reads its next step,
/// where a recording writes it.
pub(super) struct ScheduleCursor<'a> {
    schedule: Schedule<'a>,
    phase: usize,
    step: usize,
}

impl<'a> ScheduleCursor<'a> {
    pub(super) fn new(mut schedule: Schedule<'a>) -> Self {
        if let Schedule::Record(s) = &mut schedule {
            s.phases.clear();
            s.phases.push(Vec::new());
        }
        Self {
            schedule,
            phase: 0,
            step: 0,
        }
    }

    /// The step to take next when replaying (the phase's last one if it runs longer).
    pub(super) fn replayed(&self) -> Option<f64> {
        match &self.schedule {
            Schedule::Replay(s) => s
                .phases
                .get(self.phase)
                .and_then(|p| p.get(self.step).or(p.last()))
                .copied(),
            _ => None,
        }
    }

    /// An accepted step of `h_s` [s].
    pub(super) fn stepped(&mut self, h_s: f64) {
        if let Schedule::Record(s) = &mut self.schedule {
            if let Some(p) = s.phases.last_mut() {
                p.push(h_s);
            }
        }
        self.step += 1;
    }

    /// A new smooth phase begins (after an impact or at a breakpoint).
    pub(super) fn next_phase(&mut self) {
        self.phase += 1;
        self.step = 0;
        if let Schedule::Record(s) = &mut self.schedule {
            s.phases.push(Vec::new());
        }
    }
}
