//! The fixed-size stride loop: the general loop's steps (step, grazing check, witnesses,
//! locate, apply) for the cases it covers, on `SVector` states with the planar evaluation
//! called directly. Each function says which part of the general loop (`stride::run`) it
//! mirrors; anything else is a fallback.

use super::dop853::{FixedDop853, FixedSystem, State};
use super::heel_strike::heel_strike;
use super::witness::PlanarWitnesses;
use super::Outcome;
use crate::dynamics::{Dynamics, DynamicsError};
use crate::events::{refine, root_on_dense, Direction};
use crate::integrators::{IntegratorChoice, Sample};
use crate::model::Model;
use crate::planar::{EvaluationPath, PlanarTree};
use crate::stride::phase::Phase;
use crate::stride::request::StrideOptions;
use crate::stride::schedule::{Schedule, ScheduleCursor};
use crate::stride::settings::StrideSettings;
use crate::stride::witnesses::{Watch, WitnessValues};
use crate::stride::{ContactSummary, StrideEvent, StrideFailure, StrideResult};
use crate::walker::Walker;
use nalgebra::{DVector, SVector};

/// What one stride is run with (besides its start state).
pub(super) struct Args<'a> {
    pub(super) walker: &'a Walker,
    pub(super) tree: &'a PlanarTree,
    pub(super) settings: &'a StrideSettings,
    pub(super) options: StrideOptions,
    pub(super) schedule: Schedule<'a>,
    pub(super) trajectory: &'a mut Vec<Sample>,
}

/// The smooth dynamics of a phase on the planar fast path: free coordinates, no drive.
struct FastPhase<'a, const N: usize> {
    tree: &'a PlanarTree,
    model: &'a Model,
    active: [bool; N],
    /// The general workspace, made when a model with infinitesimal bodies has a coordinate
    /// locked (its limit solve is the general one).
    limit: Option<Dynamics>,
}

impl<const N: usize> FixedSystem<N> for FastPhase<'_, N> {
    fn accelerations(
        &mut self,
        _t_s: f64,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
    ) -> Result<SVector<f64, N>, DynamicsError> {
        if self.active.iter().all(|&a| a) {
            if let Some(qdd) = self.tree.free_closed_form(q, qd) {
                return Ok(qdd);
            }
        }
        let (limit, model) = (&mut self.limit, self.model);
        self.tree.accelerations_fixed(
            || limit.get_or_insert_with(|| Dynamics::new(model)),
            &self.active,
            None,
            q,
            qd,
        )
    }
}

/// `s` as a general sample.
fn sample<const N: usize>(s: &State<N>) -> Sample {
    Sample {
        t_s: s.t_s,
        q: DVector::from_column_slice(s.q.as_slice()),
        qd: DVector::from_column_slice(s.qd.as_slice()),
    }
}

/// A general sample as a fixed-size state (`None`: another length, or not finite).
fn state<const N: usize>(t_s: f64, q: &DVector<f64>, qd: &DVector<f64>) -> Option<State<N>> {
    let finite = q.iter().chain(qd.iter()).all(|v| v.is_finite());
    (q.len() == N && qd.len() == N && finite).then(|| State {
        t_s,
        q: SVector::from_iterator(q.iter().copied()),
        qd: SVector::from_iterator(qd.iter().copied()),
    })
}

/// Which events a step triggered.
enum Triggered {
    None,
    One(Watch),
    /// Two or more: the general loop locates each and takes the earliest.
    Several,
}

/// What the swing foot's crossing was.
enum HeelOutcome {
    /// A mid-swing scuff the scene ignores.
    Ignored,
    /// Heel strike: the stride's end.
    Done(Box<Result<StrideResult, StrideFailure>>),
}

/// Runs one stride from `q0`, `qd0` on `N`-sized states.
pub(super) fn stride<const N: usize>(
    args: Args<'_>,
    q0: &DVector<f64>,
    qd0: &DVector<f64>,
) -> Outcome {
    let Args {
        walker,
        tree,
        settings,
        options,
        schedule,
        trajectory,
    } = args;
    let IntegratorChoice::Dop853 {
        rtol,
        atol,
        h_max_s,
    } = settings.integrator
    else {
        return Outcome::Fallback;
    };
    let Some(cur) = state::<N>(0.0, q0, qd0) else {
        return Outcome::Fallback;
    };
    let mut active = [true; N];
    for c in &walker.initially_locked {
        match active.get_mut(c.0) {
            Some(a) => *a = false,
            None => return Outcome::Fallback,
        }
    }
    let Some(wit) = PlanarWitnesses::new::<N>(walker, tree) else {
        return Outcome::Fallback;
    };
    if options.record {
        trajectory.push(sample(&cur));
    }
    let run = Run {
        walker,
        tree,
        settings,
        record: options.record,
        integrator: FixedDop853::new(rtol, atol, h_max_s),
        sys: FastPhase {
            tree,
            model: &walker.model,
            active,
            limit: None,
        },
        schedule: ScheduleCursor::new(schedule),
        evaluations: 0,
        steps: 0,
        damping: SVector::from_fn(|c, _| tree.damping(c)),
        dissipation_j: 0.0,
        wit,
        w_cached: None,
        cur,
        events: Vec::new(),
        event_states: Vec::new(),
        energy_loss_j: 0.0,
        trajectory,
    };
    run.run()
}

/// One stride in progress (the general loop's `Run`, for the cases covered).
struct Run<'a, const N: usize> {
    walker: &'a Walker,
    tree: &'a PlanarTree,
    settings: &'a StrideSettings,
    record: bool,
    integrator: FixedDop853<N>,
    sys: FastPhase<'a, N>,
    schedule: ScheduleCursor<'a>,
    /// Evaluations of earlier phases (the integrator restarts after each impact).
    evaluations: usize,
    /// Integrator steps taken so far, against the step budget.
    steps: usize,
    /// Each coordinate's joint damping [N·m·s/rad].
    damping: SVector<f64, N>,
    /// The dampers' dissipation so far (trapezoidal, as `Power::accumulate`) [J].
    dissipation_j: f64,
    wit: PlanarWitnesses,
    /// Witness values at `cur`, carried over from the previous step.
    w_cached: Option<WitnessValues>,
    /// The last accepted state.
    cur: State<N>,
    events: Vec<StrideEvent>,
    event_states: Vec<(Sample, Sample)>,
    energy_loss_j: f64,
    trajectory: &'a mut Vec<Sample>,
}

impl<const N: usize> Run<'_, N> {
    /// The loop (the general `Run::run` without control ticks and drives).
    fn run(mut self) -> Outcome {
        loop {
            if self.cur.t_s > self.settings.max_stride_time_s || self.budget_used() {
                return Outcome::Fallback;
            }
            let Some(next) = self.step() else {
                return Outcome::Fallback;
            };
            let Some((next, w_cur, w_next)) = self.grazing_check(next) else {
                return Outcome::Fallback;
            };
            let watch = match self.triggered(&next, &w_cur, &w_next) {
                Triggered::None => {
                    self.accept(next);
                    continue;
                }
                Triggered::Several => return Outcome::Fallback,
                Triggered::One(Watch::Heel) if self.scuff_need_not_be_located(&w_cur, &w_next) => {
                    let at = self.cur;
                    self.accept_ignored(&at, next);
                    continue;
                }
                Triggered::One(watch) => watch,
            };
            let Some(at) = self.locate(watch, &next) else {
                return Outcome::Fallback;
            };
            self.accumulate(&self.cur.clone(), &at);
            match watch {
                Watch::Heel => match self.heel_strike(&at) {
                    Some(HeelOutcome::Ignored) => self.accept_ignored(&at, next),
                    Some(HeelOutcome::Done(r)) => return Outcome::Done(r),
                    None => return Outcome::Fallback,
                },
                Watch::Knee(k) => {
                    if let Err(e) = self.knee_lock(k, &at) {
                        return Outcome::Done(Box::new(Err(e)));
                    }
                }
                _ => return Outcome::Fallback,
            }
        }
    }

    /// The step and evaluation budgets are used up (`check_budgets`).
    fn budget_used(&self) -> bool {
        let evaluations = self.evaluations + self.integrator.evaluations();
        self.steps >= self.settings.max_steps || evaluations >= self.settings.max_evaluations
    }

    /// One integrator step from `cur`, replayed when the schedule says so (`step`).
    fn step(&mut self) -> Option<State<N>> {
        self.steps += 1;
        let cur = self.cur;
        let next = match self.schedule.replayed() {
            Some(h) => self.integrator.step_exact(&mut self.sys, &cur, h),
            None => self.integrator.advance(&mut self.sys, &cur, f64::INFINITY),
        }
        .ok()?;
        next.q
            .iter()
            .chain(next.qd.iter())
            .all(|v| v.is_finite())
            .then_some(next)
    }

    /// The grazing check on the foot height's Hermite interpolant (`grazing_check`).
    fn grazing_check(
        &mut self,
        mut next: State<N>,
    ) -> Option<(State<N>, WitnessValues, WitnessValues)> {
        let cur = self.cur;
        let w_cur = match self.w_cached {
            Some(w) if w.t_s == cur.t_s => w,
            _ => self.wit.eval(&cur),
        };
        let mut w_next = self.wit.eval(&next);
        let samples = self.settings.event_tolerance.grazing_samples;
        if let Some(t) = w_cur.grazing_sample_time(&w_next, samples) {
            let s = self
                .integrator
                .step_exact(&mut self.sys, &cur, t - cur.t_s)
                .ok()?;
            let ws = self.wit.eval(&s);
            if ws.foot_height_m <= 0.0 {
                next = s;
                w_next = ws;
            }
        }
        self.w_cached = Some(w_next);
        Some((next, w_cur, w_next))
    }

    /// The swing foot's crossing on the step is a mid-swing scuff the walker ignores wherever
    /// it lies in the step, and without dampers its location would change nothing (the
    /// general loop's `scuff_need_not_be_located`).
    fn scuff_need_not_be_located(&self, w_cur: &WitnessValues, w_next: &WitnessValues) -> bool {
        let hs = &self.walker.heel_strike;
        hs.ignore_scuffing
            && self.damping.iter().all(|&d| d == 0.0)
            && w_cur.scuff_anywhere_in_step(w_next, hs.min_ahead_m)
    }

    /// The events the step `cur` → `next` triggered (`Witnesses::triggered`, no string).
    fn triggered(
        &self,
        next: &State<N>,
        w_cur: &WitnessValues,
        w_next: &WitnessValues,
    ) -> Triggered {
        let mut found = Triggered::None;
        let mut add = |w: Watch| {
            found = match found {
                Triggered::None => Triggered::One(w),
                _ => Triggered::Several,
            }
        };
        if Direction::Falling.triggered(w_cur.foot_height_m, w_next.foot_height_m) {
            add(Watch::Heel);
        }
        for (k, knee) in self.walker.knees.iter().enumerate() {
            let c = knee.coordinate.0;
            let (Some(&free), Some(a), Some(b)) =
                (self.sys.active.get(c), self.cur.q.get(c), next.q.get(c))
            else {
                continue;
            };
            if free && knee.closing.triggered(a - knee.stop_rad, b - knee.stop_rad) {
                add(Watch::Knee(k));
            }
        }
        if Direction::Falling.triggered(w_cur.hip_height_margin_m, w_next.hip_height_margin_m) {
            add(Watch::HipLow);
        }
        if w_next.hip_ahead_m < 0.0
            && Direction::Falling.triggered(
                w_cur.hip_forward_velocity_m_s,
                w_next.hip_forward_velocity_m_s,
            )
        {
            add(Watch::HipBack);
        }
        found
    }

    /// Locates the event `watch` on the step `cur` → `next` ([`crate::events::locate`] with
    /// the dense output): `None` when the step's dense output is not at hand (the general
    /// loop then estimates on the Hermite interpolant) or the location fails.
    fn locate(&mut self, watch: Watch, next: &State<N>) -> Option<State<N>> {
        let cur = self.cur;
        let wit = self.wit;
        let knee = match watch {
            Watch::Knee(k) => self
                .walker
                .knees
                .get(k)
                .map(|k| (k.coordinate.0, k.stop_rad)),
            _ => None,
        };
        let g = |s: &State<N>| match (watch, knee) {
            (Watch::Knee(_), Some((c, stop))) => s.q.get(c).map_or(f64::NAN, |q| q - stop),
            (Watch::HipLow, _) => wit.eval(s).hip_height_margin_m,
            (Watch::HipBack, _) => wit.eval(s).hip_forward_velocity_m_s,
            _ => wit.eval(s).foot_height_m,
        };
        let (ga, gb) = (g(&cur), g(next));
        let dense = self
            .integrator
            .dense_output(&mut self.sys, &cur, next)?
            .ok()?;
        let tol = &self.settings.event_tolerance;
        let (guess, slope) = root_on_dense(
            |t| g(&dense.eval(t)),
            (cur.t_s, ga),
            (next.t_s, gb),
            dense.h_s,
            tol,
        );
        let (integrator, sys) = (&mut self.integrator, &mut self.sys);
        refine(
            (cur.t_s, ga),
            (next, next.t_s, gb),
            (guess, Some(slope)),
            tol,
            |t| {
                let s = integrator.step_exact(sys, &cur, t - cur.t_s)?;
                Ok((s, g(&s)))
            },
        )
        .ok()
    }

    /// The dampers' dissipation over `from` → `to` (`Power::accumulate`).
    fn accumulate(&mut self, from: &State<N>, to: &State<N>) {
        let diss = |s: &State<N>| {
            (0..N)
                .map(|i| self.damping[i] * s.qd[i] * s.qd[i])
                .sum::<f64>()
        };
        self.dissipation_j += 0.5 * (to.t_s - from.t_s) * (diss(from) + diss(to));
    }

    /// A step without events (`accept`).
    fn accept(&mut self, next: State<N>) {
        let cur = self.cur;
        self.accumulate(&cur, &next);
        self.schedule.stepped(next.t_s - cur.t_s);
        self.advance_to(next);
    }

    /// A step whose only event was an ignored scuff (`accept_ignored`).
    fn accept_ignored(&mut self, at: &State<N>, next: State<N>) {
        self.accumulate(at, &next);
        self.schedule.stepped(next.t_s - self.cur.t_s);
        self.advance_to(next);
    }

    /// `s` becomes the current state, recorded when asked (`record`).
    fn advance_to(&mut self, s: State<N>) {
        self.cur = s;
        if self.record {
            self.trajectory.push(sample(&s));
        }
    }

    /// Knee `k` reaches its stop at `at`: the general locking impact, a new phase
    /// (`apply`'s knee lock and `after_impact`).
    fn knee_lock(&mut self, k: usize, at: &State<N>) -> Result<(), StrideFailure> {
        let w = self.walker;
        let (c, stop) = match w.knees.get(k) {
            Some(knee) => (knee.coordinate.0, knee.stop_rad),
            None => (usize::MAX, 0.0),
        };
        let mut phase = Phase::with_path(&w.model, EvaluationPath::General);
        phase.active = self.sys.active.to_vec();
        let at_s = sample(at);
        let l = w.lock_coordinate(&phase, &at_s, c, stop)?;
        let Some(after) = state::<N>(l.after.t_s, &l.after.q, &l.after.qd) else {
            return Err(StrideFailure::new(
                at.t_s,
                crate::stride::FailureCause::NonFiniteAfterKneeLock,
            ));
        };
        if let Some(a) = self.sys.active.get_mut(c) {
            *a = false;
        }
        self.cur = after;
        self.energy_loss_j += l.loss_j;
        self.events.push(StrideEvent {
            name: format!("knee_lock:{}", w.model.coordinates[c].name),
            t_stride_s: at.t_s,
        });
        self.event_states.push((at_s, l.after));
        self.evaluations += self.integrator.evaluations();
        self.integrator.reset();
        self.schedule.next_phase();
        if self.record {
            self.trajectory.push(sample(&self.cur));
        }
        Ok(())
    }

    /// The swing foot reached the floor at `at` (`heel_strike`): an ignored scuff, heel strike
    /// (the general impact and relabelling), or `None` for what the general loop reports as a
    /// failure.
    fn heel_strike(&mut self, at: &State<N>) -> Option<HeelOutcome> {
        let w = self.walker;
        let ahead = self.wit.eval(at).foot_ahead_m;
        if ahead < w.heel_strike.min_ahead_m {
            return w
                .heel_strike
                .ignore_scuffing
                .then_some(HeelOutcome::Ignored);
        }
        let active = self.sys.active;
        if w.knees
            .iter()
            .any(|k| active.get(k.coordinate.0) == Some(&true))
        {
            return None;
        }
        self.events.push(StrideEvent {
            name: "heel_strike".into(),
            t_stride_s: at.t_s,
        });
        let at_s = sample(at);
        self.event_states.push((at_s.clone(), at_s.clone()));
        if self.record {
            self.trajectory.push(at_s.clone());
        }
        self.evaluations += self.integrator.evaluations();
        let events = std::mem::take(&mut self.events);
        let r = match heel_strike::<N>(w, self.tree, at, &active) {
            Some(h) => Ok(StrideResult {
                q_next: h.q_next,
                qd_next: h.qd_next,
                duration_s: at.t_s,
                step_m: h.step_m,
                heading_change_rad: 0.0,
                events,
                pre_impact: at_s,
                lift_velocity_m_s: h.lift_velocity_m_s,
                impact_energy_loss_j: self.energy_loss_j + h.energy_loss_j,
                evaluations: 0,
                trajectory: Vec::new(),
                event_states: Vec::new(),
                actuator_work_j: 0.0,
                damping_dissipation_j: 0.0,
                contact: ContactSummary::default(),
            }),
            None => w.finish_stride(at_s, &active, events, self.energy_loss_j),
        };
        let r = r.map(|mut r| {
            r.event_states = std::mem::take(&mut self.event_states);
            r.evaluations = self.evaluations;
            r.damping_dissipation_j = self.dissipation_j;
            r
        });
        Some(HeelOutcome::Done(Box::new(r)))
    }
}
