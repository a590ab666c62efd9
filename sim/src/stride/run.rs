//! The stride loop, written once for every engine ([`Walker::stride`] picks the engine): from just after one heel strike, step the smooth
//! dynamics of the current phase; at each step run the control tick, the grazing check and
//! the witnesses; locate the earliest triggered event and apply it (an impact, which starts
//! a new phase; a failure; or heel strike, which ends the stride).
//!
//! Times inside a stride are stride time (from its start); a controller's ticks are on its own
//! grid of walk time, shifted by the walk time at the start of the stride.

use super::contact_figures::ContactSummary;
use super::energy::Power;
use super::engine::Engine;
use super::failure::{FailureCause, StrideFailure};
use super::phase::Drive;
use super::request::{StrideControl, StrideOptions};
use super::result::{StrideEvent, StrideResult};
use super::schedule::{Schedule, ScheduleCursor};
use super::settings::StrideSettings;
use super::state::StrideState;
use super::witnesses::{self, StringLimit, Watch, WitnessEvaluator, WitnessValues};
use crate::engine::integrators::{Sample, SystemChange};
use crate::engine::walker::Walker;
use ticks::{Plant, TickEffect, Ticks};

mod ticks;

/// What a stride starts from, whatever its engine: the walker, the settings, what to record,
/// the step schedule and where recorded samples go.
pub(super) struct Start<'w, 'r, 't> {
    pub(super) walker: &'w Walker,
    pub(super) settings: &'r StrideSettings,
    pub(super) options: StrideOptions,
    pub(super) schedule: Schedule<'r>,
    pub(super) trajectory: &'t mut Vec<Sample>,
    /// Storage for the watches a step triggers (the workspace's).
    pub(super) triggered: &'t mut Vec<Watch>,
}

/// What a located event did to the stride.
enum Applied {
    /// An impact named so: a new smooth phase starts from the state after it.
    Impact(String),
    /// A mid-swing scuff the scene ignores: the step is accepted as it was.
    Ignored,
    /// Nothing: the event does not apply to this walker.
    Skipped,
    /// Heel strike: the stride is complete.
    Done(Box<StrideResult>),
}

/// What a step's triggered events come to.
enum Located<S> {
    /// No event: the step is accepted.
    None,
    /// Only a mid-swing scuff the walker ignores wherever it lies in the step.
    IgnoredScuff,
    /// The earliest event and where it lies (`None`: none applies).
    Earliest(Option<(Watch, S)>),
}

/// One stride in progress, on the engine `E` (its state storage and evaluation).
pub(super) struct Run<'w, 'r, 't, E: Engine> {
    walker: &'w Walker,
    settings: &'r StrideSettings,
    options: StrideOptions,
    engine: E,
    schedule: ScheduleCursor<'r>,
    /// Evaluations of earlier phases (the integrator restarts after each impact).
    evaluations: usize,
    /// Integrator steps taken so far (accepted or not), against the step budget.
    steps: usize,
    power: Power,
    contact: ContactSummary,
    wit: E::Witness,
    /// Witness values at `cur`, carried over from the previous step.
    w_cached: Option<WitnessValues>,
    /// The watches the last step triggered (the workspace's storage).
    triggered: &'t mut Vec<Watch>,
    /// The last accepted state.
    cur: E::State,
    /// `cur` is the end of the last step the integrator took (not a state located or
    /// interpolated inside it, nor one after an impact).
    cur_at_step_end: bool,
    /// The step's end the grazing check returned is the end of the integrator's last step
    /// (no probe was taken inside the step, or its probe was adopted).
    next_at_step_end: bool,
    events: Vec<StrideEvent>,
    event_states: Vec<(Sample, Sample)>,
    energy_loss_j: f64,
    trajectory: &'t mut Vec<Sample>,
    /// The controller and its ticks.
    ticks: Ticks<'r>,
}

impl<'w, 'r, 't, E: Engine> Run<'w, 'r, 't, E> {
    /// A stride from `cur` on `engine` (its free coordinates set), its witnesses evaluated by
    /// `wit`.
    pub(super) fn new(
        start: Start<'w, 'r, 't>,
        engine: E,
        wit: E::Witness,
        control: Option<StrideControl<'r>>,
        cur: E::State,
    ) -> Result<Self, StrideFailure> {
        let Start {
            walker,
            settings,
            options,
            schedule,
            trajectory,
            triggered,
        } = start;
        if !cur.is_finite() {
            return Err(StrideFailure::new(0.0, FailureCause::NonFiniteInitialState));
        }
        if options.record {
            trajectory.push(cur.to_sample());
        }
        let ticks = Ticks::new(
            control,
            settings,
            matches!(schedule, Schedule::Free),
            engine.interpolates(),
        )?;
        Ok(Self {
            walker,
            settings,
            options,
            engine,
            schedule: ScheduleCursor::new(schedule),
            evaluations: 0,
            steps: 0,
            power: Power::new(walker.model()),
            contact: ContactSummary::default(),
            wit,
            w_cached: None,
            triggered,
            cur,
            cur_at_step_end: false,
            next_at_step_end: false,
            events: Vec::new(),
            event_states: Vec::new(),
            energy_loss_j: 0.0,
            trajectory,
            ticks,
        })
    }

    /// The loop, run to its end: the stride's result, and the engine and the witnesses'
    /// evaluator (for the next stride to reuse).
    pub(super) fn run(mut self) -> (Result<StrideResult, StrideFailure>, (E, E::Witness)) {
        let r = self.steps_to_the_end();
        (r, (self.engine, self.wit))
    }

    /// The loop: step, check, locate, apply, until heel strike or a failure.
    fn steps_to_the_end(&mut self) -> Result<StrideResult, StrideFailure> {
        loop {
            self.control_tick()?;
            if self.cur.t_s() > self.settings.max_stride_time_s {
                return Err(StrideFailure::new(
                    self.cur.t_s(),
                    FailureCause::TimeBudget {
                        max_stride_time_s: self.settings.max_stride_time_s,
                    },
                ));
            }
            self.check_budgets()?;
            let drive_end_s = self.drive_end_s();
            let next = self.step(drive_end_s)?;
            // Ticks the step ran across: sampled on its interpolant, built from the step just
            // taken (before the grazing probe and event location take other steps), run
            // before the step's events apply.
            let dense = self
                .ticks
                .held_interpolant(&mut self.engine, &self.cur, &next)?;
            let stepped_to_s = next.t_s();
            let (next, w_cur, w_next) = self.grazing_check(next)?;
            // The probe's step was adopted: it is now the integrator's last step, and its own
            // interpolant is the one of the step the stride takes.
            let dense = if next.t_s() == stepped_to_s {
                dense
            } else {
                self.ticks
                    .held_interpolant(&mut self.engine, &self.cur, &next)?
            };
            if self
                .ticks
                .inside_without_interpolant(dense.is_some(), next.t_s())
            {
                // Not expected (a step runs across a tick only with its interpolant, kept for
                // the step adopted above). A tick is never skipped: the step is taken again,
                // ending at the tick.
                self.ticks.end_at_next_tick();
                continue;
            }
            let limit = self.string_limit();
            let mut triggered = std::mem::take(self.triggered);
            witnesses::triggered(
                &mut triggered,
                self.walker,
                (self.engine.active(), self.engine.prescribed().is_some()),
                limit,
                (&self.cur, &w_cur),
                (&next, &w_next),
            );
            let located = self.located(&triggered, &w_cur, &w_next, &next);
            *self.triggered = triggered;
            let Some((watch, mut at)) = (match located? {
                Located::None => {
                    let held = self.held_ticks(dense.as_ref(), (&w_cur, &w_next), next.t_s())?;
                    let at_step_end = held.is_none() && self.next_at_step_end;
                    self.accept(held.unwrap_or(next), drive_end_s)?;
                    self.cur_at_step_end = at_step_end;
                    continue;
                }
                Located::IgnoredScuff => {
                    // Ignored wherever it is: the step is accepted as `apply` would accept
                    // it, without locating the crossing (it would only split the dampers'
                    // trapezoid, and there are none).
                    let at = self.cur.clone();
                    self.accept_ignored(&at, next);
                    continue;
                }
                Located::Earliest(e) => e,
            }) else {
                continue;
            };
            if let Some(at_tick) = self.held_ticks(dense.as_ref(), (&w_cur, &w_next), at.t_s())? {
                // A tick before the event changed the plant's input: the step ends there.
                self.accept(at_tick, drive_end_s)?;
                continue;
            }
            self.engine.snap(&mut at);
            self.power.accumulate(&self.cur, &at);
            match self.apply(watch, &at)? {
                Applied::Done(result) => return Ok(*result),
                Applied::Ignored => {
                    let next = self
                        .held_ticks(dense.as_ref(), (&w_cur, &w_next), next.t_s())?
                        .unwrap_or(next);
                    self.accept_ignored(&at, next);
                }
                Applied::Skipped => {}
                Applied::Impact(name) => self.after_impact(name, at),
            }
        }
    }

    /// A control tick, when one is due at `cur` ([`Ticks::control_tick`]); a string released
    /// there is an event.
    fn control_tick(&mut self) -> Result<(), StrideFailure> {
        let plant = Plant {
            walker: self.walker,
            engine: &mut self.engine,
            wit: &mut self.wit,
            cur: &mut self.cur,
            at_step_end: self.cur_at_step_end,
        };
        if self.ticks.control_tick(plant, self.w_cached)? == TickEffect::Released {
            self.power.close(self.walker.model(), &self.cur);
            self.events.push(StrideEvent {
                name: "string_released".into(),
                t_stride_s: self.cur.t_s(),
            });
            let at = self.cur.to_sample();
            self.event_states.push((at.clone(), at));
        }
        Ok(())
    }

    /// The ticks strictly before `end_s` run on the step's interpolant `dense`
    /// ([`Ticks::held_ticks`]): the state at the first whose output changes the plant's
    /// input, which ends the step there.
    fn held_ticks(
        &mut self,
        dense: Option<&E::Interpolant>,
        ends: (&WitnessValues, &WitnessValues),
        end_s: f64,
    ) -> Result<Option<E::State>, StrideFailure> {
        let plant = Plant {
            walker: self.walker,
            engine: &mut self.engine,
            wit: &mut self.wit,
            cur: &mut self.cur,
            at_step_end: false,
        };
        self.ticks.held_ticks(plant, dense, ends, end_s)
    }

    /// The stride's step and evaluation budgets: a stride that has used either up fails,
    /// naming the budget, so that no stride loops forever (e.g. on steps that do not advance
    /// time).
    fn check_budgets(&self) -> Result<(), StrideFailure> {
        let evaluations = self.evaluations + self.engine.evaluations();
        if self.steps >= self.settings.max_steps {
            return Err(StrideFailure::new(
                self.cur.t_s(),
                FailureCause::StepBudget {
                    max_steps: self.settings.max_steps,
                    evaluations,
                },
            ));
        }
        self.ticks.check_budget(self.cur.t_s())?;
        if evaluations >= self.settings.max_evaluations {
            return Err(StrideFailure::new(
                self.cur.t_s(),
                FailureCause::EvaluationBudget {
                    max_evaluations: self.settings.max_evaluations,
                    steps: self.steps,
                },
            ));
        }
        Ok(())
    }

    /// The ideal drive's profile ends with a jump in its jerk: a breakpoint, so that no step
    /// straddles it (the step sizes stay smooth functions of the initial state, and replayed
    /// schedules stay accurate when the end moves). ∞ when there is none ahead.
    fn drive_end_s(&self) -> f64 {
        match self.engine.prescribed() {
            Some((_, Drive::Profile(p))) if self.cur.t_s() < p.start_s + p.duration_s - 1e-12 => {
                p.start_s + p.duration_s
            }
            _ => f64::INFINITY,
        }
    }

    /// One integrator step from `cur`, up to the next tick or breakpoint (replayed when the
    /// schedule says so).
    fn step(&mut self, drive_end_s: f64) -> Result<E::State, StrideFailure> {
        self.steps += 1;
        let cur = &self.cur;
        let h_limit = (self.ticks.limit_s().min(drive_end_s) - cur.t_s()).max(1e-12);
        let mut next = match self.schedule.replayed() {
            Some(h) => self.engine.step_exact(cur, h.min(h_limit)),
            None => self.engine.advance(cur, h_limit),
        }
        .map_err(|e| StrideFailure::from_integration(e, cur.t_s()))?;
        self.engine.snap(&mut next);
        if !next.is_finite() {
            return Err(StrideFailure::new(next.t_s(), FailureCause::NonFiniteState));
        }
        Ok(next)
    }

    /// A grazing contact: the foot height is positive at both ends of the step but dips below
    /// the floor inside it. The cubic Hermite interpolant of the height (from its values and
    /// rates at both ends) is checked at interior points; if the exact flow confirms a dip, the
    /// step is shortened to end inside it. Returns the step's end and the witness values at
    /// both ends.
    #[inline]
    fn grazing_check(
        &mut self,
        mut next: E::State,
    ) -> Result<(E::State, WitnessValues, WitnessValues), StrideFailure> {
        let cur = &self.cur;
        let w_cur = match self.w_cached {
            Some(w) if w.t_s == cur.t_s() => w,
            _ => self.wit.eval(cur),
        };
        let mut w_next = self.wit.eval(&next);
        let samples = self.settings.event_tolerance.grazing_samples;
        self.next_at_step_end = true;
        if let Some(t) = w_cur.grazing_sample_time(&w_next, samples) {
            // The probe is the integrator's last step now: `next` is its end only if adopted.
            self.next_at_step_end = false;
            let mut s = self
                .engine
                .step_exact(cur, t - cur.t_s())
                .map_err(|e| StrideFailure::from_integration(e, cur.t_s()))?;
            self.engine.snap(&mut s);
            let ws = self.wit.eval(&s);
            if ws.foot_height_m <= 0.0 {
                next = s;
                w_next = ws;
                self.next_at_step_end = true;
            }
        }
        self.w_cached = Some(w_next);
        Ok((next, w_cur, w_next))
    }

    /// The events the step `cur` → `next` triggered (`triggered`), told apart: none, a scuff
    /// that need not be located, or the earliest located event (if any applies).
    fn located(
        &mut self,
        triggered: &[Watch],
        w_cur: &WitnessValues,
        w_next: &WitnessValues,
        next: &E::State,
    ) -> Result<Located<E::State>, StrideFailure> {
        if triggered.is_empty() {
            return Ok(Located::None);
        }
        if self.scuff_need_not_be_located(triggered, w_cur, w_next) {
            return Ok(Located::IgnoredScuff);
        }
        Ok(Located::Earliest(self.earliest(triggered, next)?))
    }

    /// The step triggered only the swing foot's crossing, which the walker ignores as a
    /// mid-swing scuff wherever it lies in the step
    /// ([`WitnessValues::scuff_anywhere_in_step`]), and locating it would change nothing: no
    /// dampers (whose trapezoid the location splits), no drive, no controller.
    fn scuff_need_not_be_located(
        &self,
        triggered: &[Watch],
        w_cur: &WitnessValues,
        w_next: &WitnessValues,
    ) -> bool {
        let hs = self.walker.heel_strike();
        triggered == [Watch::Heel]
            && hs.ignore_scuffing
            && self.power.undamped()
            && self.engine.prescribed().is_none()
            && !self.ticks.controlled()
            && w_cur.scuff_anywhere_in_step(w_next, hs.min_ahead_m)
    }

    /// The string's limit the engagement witness compares with.
    fn string_limit(&self) -> StringLimit {
        match (
            &self.walker.ankle(),
            self.ticks.controlled(),
            self.ticks.segment(),
        ) {
            (None, _, _) => StringLimit::Slack,
            (Some(r), false, _) => StringLimit::Fixed(r.engage_rad),
            (Some(_), true, Some(seg)) if !seg.released => StringLimit::Moving(seg),
            (Some(_), true, _) => StringLimit::Slack,
        }
    }

    /// A step without events: accepted.
    fn accept(&mut self, next: E::State, drive_end_s: f64) -> Result<(), StrideFailure> {
        self.power.accumulate(&self.cur, &next);
        if self.options.contact {
            self.engine
                .add_contact(&mut self.contact, self.walker, &mut self.wit, &next)
                .map_err(|e| StrideFailure::new(next.t_s(), e))?;
        }
        self.schedule.stepped(next.t_s() - self.cur.t_s());
        if next.t_s() >= drive_end_s - 1e-12 {
            // A new smooth phase: the schedule and the integrator's memory restart.
            self.engine.system_changed(SystemChange::Equations);
            self.schedule.next_phase();
        }
        self.record(next);
        Ok(())
    }

    /// A step whose only event was an ignored scuff: accepted (its damping from the scuff on).
    fn accept_ignored(&mut self, at: &E::State, next: E::State) {
        self.power.accumulate(at, &next);
        self.schedule.stepped(next.t_s() - self.cur.t_s());
        self.record(next);
    }

    /// `s` becomes the current state (and is recorded when asked).
    fn record(&mut self, s: E::State) {
        self.cur = s;
        self.cur_at_step_end = false;
        if self.options.record {
            self.trajectory.push(self.cur.to_sample());
        }
    }

    /// Locates each triggered event on the step `cur` → `next` and takes the earliest. A
    /// mid-swing scuff that is ignored must not hide a later event of the same step (a knee
    /// lock, the string's engagement): that one is taken instead. (An engine that hands
    /// several events back leaves them to the reference.)
    fn earliest(
        &mut self,
        triggered: &[Watch],
        next: &E::State,
    ) -> Result<Option<(Watch, E::State)>, StrideFailure> {
        if E::HANDS_BACK && triggered.len() > 1 {
            return Err(StrideFailure::new(
                self.cur.t_s(),
                FailureCause::SeveralEventsHandedBack,
            ));
        }
        let limit = self.string_limit();
        let locate = |run: &mut Self, watch: Watch| {
            let (walker, wit) = (run.walker, &mut run.wit);
            run.engine
                .locate(
                    &run.cur,
                    next,
                    |s: &E::State| witnesses::value(walker, wit, watch, limit, s),
                    &run.settings.event_tolerance,
                )
                .map_err(|e| StrideFailure::from_event(e, run.cur.t_s()))
        };
        if let [watch] = triggered {
            // One event: located, nothing to compare it with.
            return Ok(Some((*watch, locate(self, *watch)?)));
        }
        let mut located: Vec<(Watch, E::State)> = Vec::new();
        for &watch in triggered {
            located.push((watch, locate(self, watch)?));
        }
        located.sort_by(|a, b| a.1.t_s().total_cmp(&b.1.t_s()));
        let hs = self.walker.heel_strike();
        if located.len() > 1
            && located[0].0 == Watch::Heel
            && hs.ignore_scuffing
            && self.wit.eval(&located[0].1).foot_ahead_m < hs.min_ahead_m
        {
            located.remove(0);
        }
        Ok(located.into_iter().next())
    }

    /// Applies the event `watch` located at `at`.
    fn apply(&mut self, watch: Watch, at: &E::State) -> Result<Applied, StrideFailure> {
        let w = self.walker;
        let fail = |cause| Err(StrideFailure::new(at.t_s(), cause));
        match watch {
            Watch::HipLow => fail(FailureCause::HipTooLow {
                hip_ahead_m: self.wit.eval(at).hip_ahead_m,
            }),
            Watch::HipBack => fail(FailureCause::HipBehindStance),
            Watch::HeelDrop => {
                if self.engine.prescribed().is_some() {
                    // The drive still holds the ankle: the push has failed.
                    return fail(FailureCause::HeelReturnedToFloor);
                }
                // The string is slack: the heel lands, an inelastic impact that stops the
                // foot's pitch about its toe; the foot is flat again, the ankle free.
                let Some(r) = &w.ankle() else {
                    return Ok(Applied::Skipped);
                };
                let toe = r.toe_pitch.0;
                let l = w.lock_coordinate(
                    (self.engine.active(), self.engine.prescribed()),
                    &at.to_sample(),
                    toe,
                    0.0,
                )?;
                self.engine.set_active(toe, false);
                self.cur = self.state_after_impact(l.after, "heel_down")?;
                self.energy_loss_j += l.loss_j;
                Ok(Applied::Impact("heel_down".into()))
            }
            Watch::Engage => {
                let Some(r) = &w.ankle() else {
                    return Ok(Applied::Skipped);
                };
                // The string's far end: fixed (ideal reflex) or moving with the actuator.
                let drive = match (self.ticks.controlled(), self.ticks.segment()) {
                    (true, Some(seg)) => Drive::Segment(seg),
                    _ => Drive::Profile(r.extension_from(at.t_s())),
                };
                let e = w.engage_string(self.engine.active(), &at.to_sample(), r, &drive)?;
                self.power.work_j += e.drive_work_j;
                self.energy_loss_j += e.drive_work_j;
                self.cur = self.state_after_impact(e.after, "string_engaged")?;
                self.energy_loss_j += e.dissipated_j;
                for (c, &free) in e.active.iter().enumerate() {
                    self.engine.set_active(c, free);
                }
                self.engine.set_prescribed(Some((r.ankle, drive)));
                self.power.open(w.model(), &self.cur);
                Ok(Applied::Impact("string_engaged".into()))
            }
            Watch::Knee(k) => {
                let c = w.knees()[k].coordinate.0;
                self.power.close(w.model(), at);
                let l = w.lock_coordinate(
                    (self.engine.active(), self.engine.prescribed()),
                    &at.to_sample(),
                    c,
                    w.knees()[k].stop_rad,
                )?;
                self.engine.set_active(c, false);
                self.cur = self.state_after_impact(l.after, "knee lock")?;
                self.power.work_j += l.drive_work_j;
                self.energy_loss_j += l.loss_j;
                if self.engine.prescribed().is_some() {
                    self.power.open(w.model(), &self.cur);
                }
                Ok(Applied::Impact(format!(
                    "knee_lock:{}",
                    w.model().coordinates[c].name
                )))
            }
            Watch::Heel => self.heel_strike(at),
        }
    }

    /// The state after an impact named `what`, in the engine's storage.
    fn state_after_impact(
        &self,
        after: Sample,
        what: &'static str,
    ) -> Result<E::State, StrideFailure> {
        let t_s = after.t_s;
        E::State::from_sample(after).ok_or_else(|| {
            StrideFailure::new(t_s, FailureCause::NonFiniteAfterImpact { impact: what })
        })
    }

    /// The swing foot reached the floor at `at`: a scuff (ignored or a failure), or heel strike,
    /// which ends the stride.
    fn heel_strike(&mut self, at: &E::State) -> Result<Applied, StrideFailure> {
        let w = self.walker;
        let ahead = self.wit.eval(at).foot_ahead_m;
        if ahead < w.heel_strike().min_ahead_m {
            if w.heel_strike().ignore_scuffing {
                return Ok(Applied::Ignored);
            }
            return Err(StrideFailure::new(
                at.t_s(),
                FailureCause::Scuff {
                    foot_ahead_m: ahead,
                },
            ));
        }
        if let Some(knee) = w
            .knees()
            .iter()
            .find(|k| self.engine.active()[k.coordinate.0])
        {
            return Err(StrideFailure::new(
                at.t_s(),
                FailureCause::KneeFreeAtHeelStrike {
                    knee: w.model().coordinates[knee.coordinate.0].name.clone(),
                },
            ));
        }
        self.power.close(w.model(), at);
        self.ticks.heel_strike(at.t_s());
        self.events.push(StrideEvent {
            name: "heel_strike".into(),
            t_stride_s: at.t_s(),
        });
        let at_s = at.to_sample();
        self.event_states.push((at_s.clone(), at_s.clone()));
        if self.options.record {
            self.trajectory.push(at_s.clone());
        }
        self.evaluations += self.engine.evaluations();
        let events = std::mem::take(&mut self.events);
        let mut r = self
            .engine
            .finish(w, (at, at_s), events, self.energy_loss_j)?;
        r.actuator_work_j = self.power.work_j;
        r.event_states = std::mem::take(&mut self.event_states);
        r.evaluations = self.evaluations;
        r.contact = std::mem::take(&mut self.contact);
        r.damping_dissipation_j = self.power.dissipation_j;
        Ok(Applied::Done(Box::new(r)))
    }

    /// After an impact at `at` (the state after it already in `cur`): the event is written
    /// down, and the integrator and the step schedule start a new phase.
    fn after_impact(&mut self, name: String, at: E::State) {
        self.events.push(StrideEvent {
            name,
            t_stride_s: at.t_s(),
        });
        self.event_states
            .push((at.to_sample(), self.cur.to_sample()));
        // The integrator restarts after an impact; its evaluations so far are kept.
        self.evaluations += self.engine.evaluations();
        self.engine.reset();
        self.schedule.next_phase();
        if self.options.record {
            self.trajectory.push(self.cur.to_sample());
        }
    }
}
