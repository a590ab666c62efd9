//! The control ticks of a controlled stride: at each tick the controller sees the stance ankle
//! and sets the string's limit until the next tick (sample and hold).
//!
//! With [`TickStepping::EndAtEveryTick`] every step ends at the next tick and the controller
//! runs at the step's end. With [`TickStepping::HeldAcrossTicks`] (the default) a step runs
//! across ticks while the limit in force does not move (released, or held at one angle): the
//! ticks inside the step run on the integrator's interpolant there, in order, before any event
//! of the step is applied; the first tick whose output changes the plant's input
//! ([`ActuatorSegment::same_held_input`]) ends the step at that tick, at the interpolated state
//! the controller saw (so the controller is never rolled back), and its output takes effect
//! there. Without an interpolant (RK4, Meijaard), with a step schedule recorded or replayed, or
//! while the limit moves, every step ends at a tick.
//!
//! Every tick runs once, at its time: a step that ran across a tick without an interpolant is
//! taken again, ending at the tick; the controller's period is checked before the stride
//! starts, and the ticks count against the stride's step budget.
//!
//! [`Ticks`] is the clock and the controller of one stride; the stride loop (`stride::run`)
//! hands it the plant ([`Plant`]: the walker, the engine, the witnesses and the current state)
//! at each tick.

use crate::engine::control::{ActuatorSegment, AnkleSensing, TickStepping};
use crate::engine::hermite::{self, Knot};
use crate::engine::integrators::SystemChange;
use crate::engine::walker::Walker;
use crate::stride::engine::{Engine, Interpolant};
use crate::stride::failure::{FailureCause, StrideFailure};
use crate::stride::phase::Drive;
use crate::stride::request::StrideControl;
use crate::stride::settings::StrideSettings;
use crate::stride::state::StrideState;
use crate::stride::witnesses::{WitnessEvaluator, WitnessValues};

/// A tick's time is reached when a sample is within this of it [s].
const TICK_SLACK_S: f64 = 1e-12;

/// The first control tick of a stride [s, stride time]: the first point of the walk-time grid
/// `k · period_s` at or after `t_walk_start_s` − [`TICK_SLACK_S`] (the stride before ran the
/// ticks before its heel strike's time − [`TICK_SLACK_S`], so each tick runs in one stride).
///
/// # Errors
/// [`crate::stride::FailureKind::InvalidControlPeriod`] when the period is not a finite positive time, or so
/// short against the walk time that the tick grid does not advance over the stride's time
/// budget `max_stride_time_s` (the stride's ticks would never end).
fn first_tick_s(
    period_s: f64,
    t_walk_start_s: f64,
    max_stride_time_s: f64,
) -> Result<f64, StrideFailure> {
    if !(period_s.is_finite() && period_s > 0.0) {
        return Err(StrideFailure::new(
            0.0,
            FailureCause::ControlPeriodNotPositive { period_s },
        ));
    }
    let first_s = ((t_walk_start_s - TICK_SLACK_S) / period_s).ceil() * period_s - t_walk_start_s;
    let last_s = first_s.max(0.0) + max_stride_time_s.max(0.0);
    if !first_s.is_finite() || !last_s.is_finite() || last_s + period_s <= last_s {
        return Err(StrideFailure::new(
            0.0,
            FailureCause::ControlPeriodTooShort {
                period_s,
                t_walk_start_s,
            },
        ));
    }
    Ok(first_s)
}

/// The swing foot is on the floor at this height [m] or below.
const ON_FLOOR_M: f64 = 1e-9;

/// Inside a step, the cubic Hermite of the swing foot's height (values and rates at the step's
/// ends) decides "off the floor" without a kinematics update when it is above this [m]: its
/// error over a step of 10 ms is of the order of 1e-8 m (`h⁴/384 · |y⁗|`, the swing foot's
/// `|y⁗|` a few hundred m/s⁴), so the answer is the exact one's.
const CLEAR_OF_FLOOR_M: f64 = 1e-4;

/// The swing foot is clearly off the floor at `t_s` inside the step `from` → `to` (the cubic
/// Hermite of its height above [`CLEAR_OF_FLOOR_M`]).
fn clear_of_floor(from: &WitnessValues, to: &WitnessValues, t_s: f64) -> bool {
    let h = to.t_s - from.t_s;
    if h <= 0.0 {
        return false;
    }
    let knot = |w: &WitnessValues| Knot {
        value: w.foot_height_m,
        rate: w.foot_height_rate_m_s,
    };
    let (height_m, _, _) = hermite::scalar(knot(from), knot(to), h, (t_s - from.t_s) / h);
    height_m > CLEAR_OF_FLOOR_M
}

/// Whether the drive `next` takes over from `ended` at stride time `t_s` with the same angle
/// and rate to the bit (only its acceleration may differ): the state as evaluated is then the
/// same on both sides of the tick, and the next step's first stage is solved on the assembly of
/// the last stage of the step that ended there ([`SystemChange::DriveAcceleration`]).
fn drive_continues(ended: &ActuatorSegment, next: &ActuatorSegment, t_s: f64) -> bool {
    let (a0, v0, _) = ended.eval(t_s);
    let (a1, v1, _) = next.eval(t_s);
    a0.to_bits() == a1.to_bits() && v0.to_bits() == v1.to_bits()
}

/// The largest rounding difference [rad, rad/s] between the ending segment's angle and rate
/// at the tick (its `x = (t − t0)/h` only near 1 in stride time) and its end knot that
/// [`continue_at_tick`] absorbs.
const KNOT_ROUNDING: f64 = 1e-12;

/// The tick's moving segment `next` taking effect at stride time `t_s` after `ended` (the
/// segment in force until then), both engaged: when the firmware's knot is continuous (the end
/// knot of `ended` is exactly the start knot of `next`, angle and rate, checked here per tick),
/// `next` starts at `t_s` from `ended`'s angle and rate at `t_s` exactly (they differ from
/// the knot by rounding only: the two segments' clocks are shifted to stride time by
/// rounding). The plant's angle and rate are then the same bits on both sides of the tick, so
/// the next step's first stage is solved on the assembly of the last stage of the step that
/// ended there ([`drive_continues`]). Any other pair is returned unchanged.
fn continue_at_tick(
    ended: Option<&ActuatorSegment>,
    next: ActuatorSegment,
    t_s: f64,
) -> ActuatorSegment {
    let Some(ended) = ended else {
        return next;
    };
    let continuous = !ended.released
        && !next.released
        && !next.is_held()
        && ended.p1_rad.to_bits() == next.p0_rad.to_bits()
        && ended.v1_rad_s.to_bits() == next.v0_rad_s.to_bits();
    if !continuous {
        return next;
    }
    let (angle_rad, rate_rad_s, _) = ended.eval(t_s);
    if (angle_rad - next.p0_rad).abs() > KNOT_ROUNDING
        || (rate_rad_s - next.v0_rad_s).abs() > KNOT_ROUNDING
        || (t_s - next.t0_s).abs() > TICK_SLACK_S
    {
        return next;
    }
    ActuatorSegment {
        t0_s: t_s,
        t1_s: t_s + (next.t1_s - next.t0_s),
        p0_rad: angle_rad,
        v0_rad_s: rate_rad_s,
        ..next
    }
}

/// What the stance ankle's sensors see at `s` (stride time; `t_walk_start_s` the walk time
/// at the start of the stride). `swing_foot_on_floor`: when already known (the witnesses of
/// this sample, or a foot clear of the floor), else from the kinematics.
fn sense<E: Engine>(
    walker: &Walker,
    wit: &mut E::Witness,
    engine: &mut E,
    t_walk_start_s: f64,
    (s, at_step_end): (&E::State, bool),
    swing_foot_on_floor: Option<bool>,
) -> Result<AnkleSensing, StrideFailure> {
    let swing_foot_on_floor =
        swing_foot_on_floor.unwrap_or_else(|| wit.eval(s).foot_height_m <= ON_FLOOR_M);
    let (a, engaged) = match &walker.ankle() {
        Some(r) => (r.ankle.0, engine.prescribed().is_some()),
        None => (0, false),
    };
    Ok(AnkleSensing {
        t_walk_s: t_walk_start_s + s.t_s(),
        stance_ankle_rad: s.q(a),
        stance_ankle_rate_rad_s: s.qd(a),
        stance_foot_on_floor: true,
        swing_foot_on_floor,
        string_engaged: engaged,
        string_torque_n_m: if engaged {
            engine
                .actuator_torque(s, at_step_end)
                .map_err(|e| StrideFailure::new(s.t_s(), e))?
                .0
        } else {
            0.0
        },
    })
}

/// Whether a stride steps across ticks at all: a controller, `HeldAcrossTicks`, the
/// integrator's own steps (no schedule) and an integrator with an interpolant.
fn held_stepping(
    tick_stepping: TickStepping,
    free_schedule: bool,
    interpolates: bool,
    controlled: bool,
) -> bool {
    tick_stepping == TickStepping::HeldAcrossTicks && free_schedule && interpolates && controlled
}

/// The plant a tick sees and acts on: the walker, the engine (its drive), the witnesses'
/// evaluator and the stride's current state.
pub(super) struct Plant<'a, E: Engine> {
    pub(super) walker: &'a Walker,
    pub(super) engine: &'a mut E,
    pub(super) wit: &'a mut E::Witness,
    pub(super) cur: &'a mut E::State,
    /// `cur` is the end of the last step taken (the loop states it; see
    /// [`Engine::actuator_torque`]).
    pub(super) at_step_end: bool,
}

/// What a tick at the current state did to the string, for the stride loop to write down.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum TickEffect {
    /// No tick was due, or its output took effect without an event.
    Quiet,
    /// The engaged string went slack (the ankle free again): an event at the current state.
    Released,
}

/// The control ticks of one stride: the controller, its tick grid (stride time), the string's
/// limit over the current tick and how steps run across ticks.
pub(super) struct Ticks<'r> {
    control: Option<StrideControl<'r>>,
    /// Control ticks: on the walk-time grid `k · period`, here in stride time [s].
    period_s: f64,
    next_tick_s: f64,
    /// The stance string's limit over the current tick (stride time), from the controller.
    segment: Option<ActuatorSegment>,
    /// Steps may run across ticks ([`TickStepping::HeldAcrossTicks`], possible for this
    /// stride).
    held_stepping: bool,
    /// The output of the tick at `next_tick_s`, run on a step's interpolant, to take effect
    /// when the stride reaches that tick.
    pending: Option<ActuatorSegment>,
    /// The next step ends at the next tick whatever the limit in force (a step ran across a
    /// tick without an interpolant and is taken again); cleared when that tick runs.
    end_at_next_tick: bool,
    /// Control ticks run so far, against the step budget (each tick is a step of the
    /// reference `EndAtEveryTick`).
    count: usize,
    /// The stride's step budget.
    max_steps: usize,
}

impl<'r> Ticks<'r> {
    /// The ticks of a stride run with `settings` under `control` (none: no ticks);
    /// `free_schedule`: the integrator chooses its steps; `interpolates`: it has an
    /// interpolant inside them.
    ///
    /// # Errors
    /// [`crate::stride::FailureKind::InvalidControlPeriod`] (see [`first_tick_s`]).
    pub(super) fn new(
        control: Option<StrideControl<'r>>,
        settings: &StrideSettings,
        free_schedule: bool,
        interpolates: bool,
    ) -> Result<Self, StrideFailure> {
        let (period_s, t_walk0) = match &control {
            Some(c) => (c.controller.period_s(), c.t_walk_start_s),
            None => (f64::INFINITY, 0.0),
        };
        let held_stepping = held_stepping(
            settings.tick_stepping,
            free_schedule,
            interpolates,
            control.is_some(),
        );
        let next_tick_s = match &control {
            Some(_) => first_tick_s(period_s, t_walk0, settings.max_stride_time_s)?,
            None => f64::INFINITY,
        };
        Ok(Self {
            control,
            period_s,
            next_tick_s,
            segment: None,
            held_stepping,
            pending: None,
            end_at_next_tick: false,
            count: 0,
            max_steps: settings.max_steps,
        })
    }

    /// Whether a controller runs the stride.
    pub(super) fn controlled(&self) -> bool {
        self.control.is_some()
    }

    /// The string's limit over the current tick (stride time), once a tick has run.
    pub(super) fn segment(&self) -> Option<ActuatorSegment> {
        self.segment
    }

    /// Tells the controller of the heel strike at stride time `t_s`.
    pub(super) fn heel_strike(&mut self, t_s: f64) {
        if let Some(c) = self.control.as_mut() {
            c.controller.heel_strike(c.t_walk_start_s + t_s);
        }
    }

    /// The next step ends at the next tick whatever the limit in force (a step that ran across
    /// a tick without an interpolant is taken again).
    pub(super) fn end_at_next_tick(&mut self) {
        self.end_at_next_tick = true;
    }

    /// The next step may run across the next tick: held stepping, no tick output waiting to
    /// take effect, and a limit in force that does not move.
    fn held_ahead(&self) -> bool {
        self.held_stepping
            && !self.end_at_next_tick
            && self.pending.is_none()
            && self.segment.is_some_and(|s| s.is_held())
    }

    /// The stride's ticks have used its step budget (each tick is a step of the reference
    /// `EndAtEveryTick`): a period far too short for the stride fails (at stride time `t_s`)
    /// instead of running for ever.
    pub(super) fn check_budget(&self, t_s: f64) -> Result<(), StrideFailure> {
        if self.count < self.max_steps {
            return Ok(());
        }
        Err(StrideFailure::new(
            t_s,
            FailureCause::TickBudget {
                max_steps: self.max_steps,
                period_s: self.period_s,
            },
        ))
    }

    /// A tick lies strictly inside a step of a controlled stride ending at `end_s`, and the
    /// step has no interpolant (`has_interpolant` false) to run it on.
    pub(super) fn inside_without_interpolant(&self, has_interpolant: bool, end_s: f64) -> bool {
        self.control.is_some() && !has_interpolant && self.next_tick_s < end_s - TICK_SLACK_S
    }

    /// The end of the next step as the ticks allow [s]: the next tick, or ∞ across ticks.
    pub(super) fn limit_s(&self) -> f64 {
        if self.held_ahead() {
            f64::INFINITY
        } else {
            self.next_tick_s
        }
    }

    /// A control tick, when one is due at the plant's current state: the controller sees the
    /// stance ankle (or its output at this tick is already known, from the interpolant) and
    /// sets the string's limit until the next tick. `w_cached`: the witnesses of the last
    /// step's end.
    pub(super) fn control_tick<E: Engine>(
        &mut self,
        plant: Plant<'_, E>,
        w_cached: Option<WitnessValues>,
    ) -> Result<TickEffect, StrideFailure> {
        let Some(control) = self.control.as_ref() else {
            return Ok(TickEffect::Quiet);
        };
        let t_s = plant.cur.t_s();
        if t_s < self.next_tick_s - TICK_SLACK_S {
            return Ok(TickEffect::Quiet);
        }
        if t_s > self.next_tick_s + TICK_SLACK_S {
            // Each step ends at or before the next tick, or runs its ticks on its interpolant:
            // a stride past a tick that did not run is a defect, not a result.
            return Err(StrideFailure::new(
                t_s,
                FailureCause::TickPassed {
                    tick_s: self.next_tick_s,
                },
            ));
        }
        let t0 = control.t_walk_start_s;
        let seg = match self.pending.take() {
            Some(seg) => seg,
            None => {
                // The witnesses of the step that ended here, when at this sample's time (an
                // impact since changes the velocities, not the foot's height).
                let on_floor = w_cached
                    .filter(|w| w.t_s == t_s)
                    .map(|w| w.foot_height_m <= ON_FLOOR_M);
                let sensing = sense(
                    plant.walker,
                    plant.wit,
                    plant.engine,
                    t0,
                    (plant.cur, plant.at_step_end),
                    on_floor,
                )?;
                self.tick_controller(&sensing)?
            }
        };
        Ok(self.apply_segment(plant.engine, plant.cur, seg))
    }

    /// The controller's tick: its segment, shifted to stride time.
    fn tick_controller(
        &mut self,
        sensing: &AnkleSensing,
    ) -> Result<ActuatorSegment, StrideFailure> {
        let Some(control) = self.control.as_mut() else {
            return Err(StrideFailure::new(
                sensing.t_walk_s,
                FailureCause::TickWithoutController,
            ));
        };
        self.count += 1;
        let t0 = control.t_walk_start_s;
        let mut seg = control
            .controller
            .tick(sensing)
            .map_err(|e| StrideFailure::new(sensing.t_walk_s - t0, e))?;
        seg.t0_s -= t0;
        seg.t1_s -= t0;
        Ok(seg)
    }

    /// The tick's segment takes effect at `cur`.
    fn apply_segment<E: Engine>(
        &mut self,
        engine: &mut E,
        cur: &mut E::State,
        mut seg: ActuatorSegment,
    ) -> TickEffect {
        let mut effect = TickEffect::Quiet;
        let mut change = SystemChange::Equations;
        if let Some((coord, Drive::Segment(ended))) = engine.prescribed() {
            if seg.released {
                // The string goes slack during the push (an emergency stop, a fault): no
                // impulse, the ankle is free again, and the foot keeps pivoting about its toe
                // until the heel comes back down or the stride ends.
                engine.set_prescribed(None);
                engine.set_active(coord.0, true);
                engine.system_changed(SystemChange::Equations);
                effect = TickEffect::Released;
            } else {
                seg = continue_at_tick(self.segment.as_ref(), seg, cur.t_s());
                if drive_continues(&ended, &seg, cur.t_s()) {
                    change = SystemChange::DriveAcceleration;
                }
                engine.set_prescribed(Some((coord, Drive::Segment(seg))));
                engine.snap(cur);
            }
        }
        // Only an engaged string's new segment changes the vector field; while the ankle is
        // free the tick only moves the engagement witness, and the integrator keeps its last
        // stage (first same as last).
        if engine.prescribed().is_some() {
            engine.system_changed(change);
        }
        self.segment = Some(seg);
        self.end_at_next_tick = false;
        self.next_tick_s += self.period_s;
        effect
    }

    /// The interpolant of the step `cur` → `next` when it ran across a tick (built before the
    /// event location takes other steps).
    pub(super) fn held_interpolant<E: Engine>(
        &self,
        engine: &mut E,
        cur: &E::State,
        next: &E::State,
    ) -> Result<Option<E::Interpolant>, StrideFailure> {
        if !self.held_ahead() || self.next_tick_s >= next.t_s() - TICK_SLACK_S {
            return Ok(None);
        }
        engine
            .interpolant(cur, next)
            .transpose()
            .map_err(|e| StrideFailure::from_integration(e, cur.t_s()))
    }

    /// Runs the ticks strictly before `end_s` on the step's interpolant, in order. While their
    /// outputs give the plant the same input the step stands (`None`); the first that changes
    /// it ends the step there: the interpolated state at that tick is returned, and the tick's
    /// output takes effect when the loop reaches it.
    ///
    /// # Errors
    /// A tick strictly before `end_s` without an interpolant (the stride loop takes such a step
    /// again, ending at the tick, so this is a defect: it is not skipped), the step budget used
    /// up by ticks, or a tick grid that does not advance; the controller's and the sensing's
    /// failures.
    pub(super) fn held_ticks<E: Engine>(
        &mut self,
        plant: Plant<'_, E>,
        dense: Option<&E::Interpolant>,
        ends: (&WitnessValues, &WitnessValues),
        end_s: f64,
    ) -> Result<Option<E::State>, StrideFailure> {
        let Some(control) = self.control.as_ref() else {
            return Ok(None);
        };
        let t0 = control.t_walk_start_s;
        if self.next_tick_s >= end_s - TICK_SLACK_S {
            return Ok(None);
        }
        let Some(dense) = dense else {
            return Err(StrideFailure::new(
                plant.cur.t_s(),
                FailureCause::TickInsideStep {
                    tick_s: self.next_tick_s,
                },
            ));
        };
        while self.next_tick_s < end_s - TICK_SLACK_S {
            self.check_budget(plant.cur.t_s())?;
            let mut s = dense.eval(self.next_tick_s);
            plant.engine.snap(&mut s);
            let clear = clear_of_floor(ends.0, ends.1, s.t_s()).then_some(false);
            let sensing = sense(
                plant.walker,
                plant.wit,
                plant.engine,
                t0,
                (&s, false),
                clear,
            )?;
            let seg = self.tick_controller(&sensing)?;
            match self.segment {
                Some(held) if held.same_held_input(&seg) => {
                    let after_s = self.next_tick_s + self.period_s;
                    if after_s <= self.next_tick_s {
                        return Err(StrideFailure::new(
                            self.next_tick_s,
                            FailureCause::ControlPeriodStalls {
                                period_s: self.period_s,
                            },
                        ));
                    }
                    self.next_tick_s = after_s;
                }
                _ => {
                    self.pending = Some(seg);
                    return Ok(Some(s));
                }
            }
        }
        Ok(None)
    }
}
