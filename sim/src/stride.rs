//! One stride: integrate single stance from just after one heel strike to just after the next,
//! with knee locks on the way, then relabel (the stride function of eq. 22).

use crate::actuator::AnkleProfile;
use crate::control::{ActuatorSegment, AnkleController, AnkleSensing};
use crate::dynamics::{Dynamics, DynamicsError};
use crate::events::{locate, Direction, EventError};
use crate::impact::{resolve, resolve_to, ImpactError};
use crate::integrators::{IntegrationError, Integrator, Sample, SecondOrderSystem, StabilityLimit};
use crate::kinematics::Kinematics;
use crate::model::{CoordIndex, Model};
use crate::relabel::LinkStates;
use crate::walker::Walker;
use nalgebra::{DMatrix, DVector, Vector3};
use serde::Serialize;

/// The kinds of failure a stride can end in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FailureKind {
    /// The walker fell with its hip behind the stance contact.
    FellBackward,
    /// The walker fell with its hip ahead of the stance contact.
    FellForward,
    /// The swing foot hit the floor mid-swing (scene does not ignore scuffing).
    Scuffed,
    /// Heel strike came before the swing knee locked.
    HeelStrikeBeforeKneeLock,
    /// After heel strike the old stance foot did not move upward.
    StanceFootDidNotLift,
    /// No heel strike within the stride time budget.
    NoImpactWithinTime,
    /// The state became NaN or infinite, or the mass matrix singular.
    NonFiniteState,
    /// A fixed step exceeded the stability limit of eq. (12).
    StepTooLarge,
    /// An adaptive step fell below its floor.
    StepUnderflow,
    /// At string engagement the heel would be pressed into the floor instead of lifting.
    HeelDidNotLift,
    /// During push-off the heel came back down to the floor.
    HeelReturnedToFloor,
    /// An event could not be located to its tolerance.
    EventNotLocated,
    /// The impact equations were singular.
    ImpactSingular,
    /// The relabelled state could not be matched to the model.
    RelabelFailed,
}

/// A failed stride.
#[derive(Clone, Debug, PartialEq, Serialize, thiserror::Error)]
#[error("{kind:?} at t = {time_s:.6} s: {detail}")]
pub struct StrideFailure {
    /// What happened.
    pub kind: FailureKind,
    /// When, from the start of the stride [s].
    pub time_s: f64,
    /// Details.
    pub detail: String,
}

impl StrideFailure {
    fn new(kind: FailureKind, time_s: f64, detail: impl Into<String>) -> Self {
        Self {
            kind,
            time_s,
            detail: detail.into(),
        }
    }

    fn from_integration(e: IntegrationError, t: f64) -> Self {
        let kind = match &e {
            IntegrationError::Dynamics(_) => FailureKind::NonFiniteState,
            IntegrationError::StepTooLarge { .. } => FailureKind::StepTooLarge,
            IntegrationError::StepUnderflow { .. } => FailureKind::StepUnderflow,
        };
        Self::new(kind, t, e.to_string())
    }

    fn from_event(e: EventError, t: f64) -> Self {
        match e {
            EventError::Integration(i) => Self::from_integration(i, t),
            other => Self::new(FailureKind::EventNotLocated, t, other.to_string()),
        }
    }
}

/// An event inside a stride.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StrideEvent {
    /// `knee_lock:<coordinate>` or `heel_strike`.
    pub name: String,
    /// Time from the start of the stride [s].
    pub time_s: f64,
}

/// A completed stride.
#[derive(Clone, Debug)]
pub struct StrideResult {
    /// The state just before and just after each event of [`Self::events`], in the same
    /// order (for the heel strike both are the pre-impact state).
    pub event_states: Vec<(Sample, Sample)>,
    /// Coordinates at the start of the next stride (relabelled).
    pub q_next: DVector<f64>,
    /// Velocities at the start of the next stride (relabelled).
    pub qd_next: DVector<f64>,
    /// Stride duration [s].
    pub duration_s: f64,
    /// New contact point in the old stance frame [m].
    pub step_m: Vector3<f64>,
    /// Heading change of the relabelled cyclic coordinates [rad].
    pub heading_change_rad: f64,
    /// Events in order.
    pub events: Vec<StrideEvent>,
    /// State just before heel strike (in the stance labelling).
    pub pre_impact: Sample,
    /// Upward velocity of the old stance contact just after impact [m/s].
    pub lift_velocity_m_s: f64,
    /// Mechanical energy lost in all impacts of the stride [J].
    pub impact_energy_loss_j: f64,
    /// Right-hand-side evaluations.
    pub evaluations: usize,
    /// Accepted samples, when recording.
    pub trajectory: Vec<Sample>,
    /// Work done by the ankle actuator (from the energy balance of the engaged intervals) [J].
    pub actuator_work_j: f64,
    /// Energy dissipated by joint dampers (trapezoidal quadrature) [J].
    pub damping_dissipation_j: f64,
    /// Contact figures (with [`StrideOptions::contact`]).
    pub contact: ContactSummary,
}

/// Running actuator work and damper dissipation over accepted steps.
///
/// The damper's dissipation `∫ c q̇² dt` is a trapezoidal quadrature (smooth integrand). The
/// actuator's work is taken from the energy balance of each interval over which the string
/// stays engaged without an impact, `W = E(end) − E(start) + D(start, end)`: exact up to the
/// state's own integration error, whatever the step sizes. (A quadrature of the actuator power
/// `τ q̇` is not: with a controller the drive's acceleration jumps at every control tick, and a
/// trapezoid over one or two steps per tick lost 1.6 % of the work at DOPRI5 1e-9.)
struct Power {
    work_j: f64,
    dissipation_j: f64,
    /// Energy and dissipation so far at the start of the open engaged interval.
    open: Option<(f64, f64)>,
    dynamics: Dynamics,
}

impl Power {
    fn new(model: &Model) -> Self {
        Self {
            work_j: 0.0,
            dissipation_j: 0.0,
            open: None,
            dynamics: Dynamics::new(model),
        }
    }

    /// An engaged interval starts at `s` (after the engagement or a knee-lock impact).
    fn open(&mut self, model: &Model, s: &Sample) {
        self.open = Some((energy(&mut self.dynamics, model, s), self.dissipation_j));
    }

    /// The open interval, if any, ends at `s` (before an impact or at heel strike).
    fn close(&mut self, model: &Model, s: &Sample) {
        if let Some((e0, d0)) = self.open.take() {
            let e1 = energy(&mut self.dynamics, model, s);
            self.work_j += e1 - e0 + (self.dissipation_j - d0);
        }
    }

    fn accumulate(&mut self, damping: &[(usize, f64)], from: &Sample, to: &Sample) {
        let h = to.t_s - from.t_s;
        let diss = |s: &Sample| {
            damping
                .iter()
                .map(|&(i, c)| c * s.qd[i] * s.qd[i])
                .sum::<f64>()
        };
        self.dissipation_j += 0.5 * h * (diss(from) + diss(to));
    }
}

/// How a driven coordinate moves (times are from the start of the stride).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Drive {
    /// The ideal actuator's smooth extension.
    Profile(AnkleProfile),
    /// A controller's actuator over the current control tick.
    Segment(ActuatorSegment),
}

impl Drive {
    /// Angle [rad], rate [rad/s], acceleration [rad/s²] at `t_s`.
    pub fn eval(&self, t_s: f64) -> (f64, f64, f64) {
        match self {
            Drive::Profile(p) => p.eval(t_s),
            Drive::Segment(s) => s.eval(t_s),
        }
    }
}

/// The smooth dynamics of one phase (which coordinates are free).
pub struct Phase<'a> {
    model: &'a Model,
    dynamics: Dynamics,
    /// Which coordinates are free to move.
    pub active: Vec<bool>,
    /// A coordinate driven along a profile (not free, not locked).
    pub prescribed: Option<(CoordIndex, Drive)>,
}

impl<'a> Phase<'a> {
    /// All coordinates active.
    pub fn new(model: &'a Model) -> Self {
        Self {
            model,
            dynamics: Dynamics::new(model),
            active: vec![true; model.dof()],
            prescribed: None,
        }
    }

    /// Puts the prescribed coordinate of `s` exactly on its profile.
    pub fn snap(&self, s: &mut Sample) {
        if let Some((c, p)) = &self.prescribed {
            let (a, ad, _) = p.eval(s.t_s);
            s.q[c.0] = a;
            s.qd[c.0] = ad;
        }
    }

    /// The generalised force [N·m] the prescribed coordinate's actuator exerts at `s`, and the
    /// coordinate's rate: their product is the actuator power.
    pub fn actuator_torque(&mut self, s: &Sample) -> Result<(f64, f64), DynamicsError> {
        let Some((c, _)) = self.prescribed else {
            return Ok((0.0, 0.0));
        };
        let qdd = self.accelerations(s.t_s, &s.q, &s.qd)?;
        let m = &self.dynamics.mass_matrix;
        let tau = (m.row(c.0) * &qdd)[(0, 0)] - self.dynamics.force[c.0];
        Ok((tau, s.qd[c.0]))
    }
}

impl SecondOrderSystem for Phase<'_> {
    fn accelerations(
        &mut self,
        t: f64,
        q: &DVector<f64>,
        qd: &DVector<f64>,
    ) -> Result<DVector<f64>, DynamicsError> {
        let drive = self.prescribed.map(|(c, p)| {
            let (angle_rad, rate_rad_s, acceleration_rad_s2) = p.eval(t);
            crate::hybrid::phase::DriveValues {
                coordinate: c.0,
                angle_rad,
                rate_rad_s,
                acceleration_rad_s2,
            }
        });
        crate::hybrid::phase::accelerations(
            self.model,
            &mut self.dynamics,
            &self.active,
            drive.as_ref(),
            q,
            qd,
        )
    }

    fn stability_limit(
        &mut self,
        _t: f64,
        q: &DVector<f64>,
        qd: &DVector<f64>,
    ) -> Option<StabilityLimit> {
        linearised_limit(self.model, &mut self.dynamics, q, qd, &self.active)
    }
}

/// `λ_max` and `β` of eq. (12) from the linearisation `M̄ δq̈ + C δq̇ + K δq = 0`, with
/// `K = −∂f̄/∂q` and `C = −∂f̄/∂q̇` by central differences. `β` is estimated conservatively as
/// `ρ(M̄⁻¹C) / (2 λ_max)`.
pub fn linearised_limit(
    model: &Model,
    dynamics: &mut Dynamics,
    q: &DVector<f64>,
    qd: &DVector<f64>,
    active: &[bool],
) -> Option<StabilityLimit> {
    let idx: Vec<usize> = (0..q.len()).filter(|&i| active[i]).collect();
    let n = idx.len();
    if n == 0 || model.has_infinitesimal_bodies() {
        return None;
    }
    dynamics.assemble(model, q, qd, None);
    let m = dynamics.mass_matrix.select_rows(&idx).select_columns(&idx);
    let mut k = DMatrix::zeros(n, n);
    let mut c = DMatrix::zeros(n, n);
    let d = 1e-6;
    for (col, &i) in idx.iter().enumerate() {
        for (target, is_q) in [(&mut k, true), (&mut c, false)] {
            let (mut qp, mut qm, mut vp, mut vm) = (q.clone(), q.clone(), qd.clone(), qd.clone());
            if is_q {
                qp[i] += d;
                qm[i] -= d;
            } else {
                vp[i] += d;
                vm[i] -= d;
            }
            dynamics.assemble(model, &qp, &vp, None);
            let fp = dynamics.force.select_rows(&idx);
            dynamics.assemble(model, &qm, &vm, None);
            let fm = dynamics.force.select_rows(&idx);
            target.set_column(col, &((fm - fp) / (2.0 * d)));
        }
    }
    let minv = m.try_inverse()?;
    let mk = (&minv * k).complex_eigenvalues();
    let lambda2 = mk.iter().map(|z| z.norm()).fold(0.0f64, f64::max);
    let damping = (&minv * c)
        .complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max);
    let lambda = lambda2.sqrt();
    let beta = if lambda > 0.0 {
        (damping / (2.0 * lambda)).min(1.0)
    } else {
        0.0
    };
    Some(StabilityLimit {
        lambda_max_rad_s: lambda,
        beta,
    })
}

/// Witness values at a sample: what the stride loop watches.
struct Witnesses<'a> {
    walker: &'a Walker,
    kin: Kinematics,
}

/// Everything the stride loop watches, from one kinematics evaluation of a sample.
#[derive(Clone, Copy, Debug)]
struct WitnessValues {
    t_s: f64,
    foot_height_m: f64,
    foot_height_rate_m_s: f64,
    foot_ahead_m: f64,
    hip_height_margin_m: f64,
    hip_ahead_m: f64,
    hip_forward_velocity_m_s: f64,
}

impl Witnesses<'_> {
    fn update(&mut self, s: &Sample) {
        self.kin.update(&self.walker.model, &s.q, &s.qd);
    }
    fn eval(&mut self, s: &Sample) -> WitnessValues {
        self.update(s);
        let m = &self.walker.model;
        let foot = &m.points[self.walker.heel_strike.swing_foot.0];
        let p_foot = self.kin.position_of(foot.link, &foot.p_link_m);
        let hip = &m.points[self.walker.fall.hip.0];
        let p_hip = self.kin.position_of(hip.link, &hip.p_link_m);
        let p_contact = self
            .kin
            .point_position(m, self.walker.heel_strike.stance_contact);
        let heading = self.heading();
        WitnessValues {
            t_s: s.t_s,
            foot_height_m: p_foot.y,
            foot_height_rate_m_s: self.kin.velocity_of(foot.link, &p_foot).y,
            foot_ahead_m: (p_foot - p_contact).dot(&heading),
            hip_height_margin_m: p_hip.y - self.walker.fall.min_hip_height_m,
            hip_ahead_m: (p_hip - p_contact).dot(&heading),
            hip_forward_velocity_m_s: self.kin.velocity_of(hip.link, &p_hip).dot(&heading),
        }
    }
    /// The walking direction: the stance contact link's forward axis, level with the floor.
    fn heading(&self) -> Vector3<f64> {
        let m = &self.walker.model;
        let link = m.points[self.walker.heel_strike.stance_contact.0].link;
        let mut d = self.kin.r_floor_link[link.0] * Vector3::x();
        d.y = 0.0;
        let n = d.norm();
        if n > 1e-9 {
            d / n
        } else {
            Vector3::x()
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Watch {
    Heel,
    Knee(usize),
    HipLow,
    HipBack,
    Engage,
    HeelDrop,
}

/// The heel-strike impact on the impact model (coordinates: released root first).
#[derive(Clone, Debug)]
pub struct HeelStrikeImpact {
    /// Coordinates of the impact model.
    pub q: DVector<f64>,
    /// Velocities before.
    pub qd_minus: DVector<f64>,
    /// Velocities after.
    pub qd_plus: DVector<f64>,
    /// Contact impulse per constraint row.
    pub impulse: DVector<f64>,
    /// The new contact point in the stance frame [m].
    pub p_contact_m: Vector3<f64>,
    /// Mechanical energy lost [J].
    pub energy_loss_j: f64,
}

/// The outcome of [`Walker::lock_coordinate`].
struct Locked {
    /// The state after the impact.
    after: Sample,
    /// Mechanical energy dissipated [J] (the drive's work included).
    loss_j: f64,
    /// Work of a drive holding the ankle through the impact [J].
    drive_work_j: f64,
}

/// Options for [`Walker::stride`].
#[derive(Clone, Copy, Debug, Default)]
pub struct StrideOptions {
    /// Keep every accepted sample.
    pub record: bool,
    /// Compute the contact load, lateral centre of pressure and swing clearance at every
    /// accepted sample (for reports; costs one more evaluation per step).
    pub contact: bool,
}

/// Contact and clearance figures of a stride (with [`StrideOptions::contact`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ContactSummary {
    /// Largest |lateral centre of pressure| under the stance foot [m].
    pub max_lateral_cop_m: f64,
    /// Smallest normal force on the stance foot [N] (negative: the foot would have to pull).
    pub min_normal_force_n: f64,
    /// Smallest swing-ankle height while it passes within 0.1 m of the stance contact [m].
    pub mid_swing_clearance_m: Option<f64>,
    /// Lateral centre of pressure at each accepted sample `(t_s, cop_m)`.
    pub lateral_cop_trace: Vec<(f64, f64)>,
}

impl ContactSummary {
    fn add(
        &mut self,
        walker: &Walker,
        phase: &mut Phase,
        wit: &mut Witnesses,
        s: &Sample,
    ) -> Result<(), DynamicsError> {
        let qdd = phase.accelerations(s.t_s, &s.q, &s.qd)?;
        let mut s2 = s.clone();
        phase.snap(&mut s2);
        wit.update(&s2);
        let load = crate::contact::ContactLoad::from_motion(&walker.model, &wit.kin, &qdd);
        let cop = load.lateral_cop_m(&wit.heading());
        if self.lateral_cop_trace.is_empty() {
            self.min_normal_force_n = f64::INFINITY;
        }
        self.lateral_cop_trace.push((s.t_s, cop));
        self.max_lateral_cop_m = self.max_lateral_cop_m.max(cop.abs());
        self.min_normal_force_n = self.min_normal_force_n.min(load.force_n.y);
        let w = wit.eval(&s2);
        if w.foot_ahead_m.abs() < 0.1 {
            let h = w.foot_height_m;
            self.mid_swing_clearance_m = Some(self.mid_swing_clearance_m.map_or(h, |m| m.min(h)));
        }
        Ok(())
    }
}

/// The accepted step sizes of a stride, phase by phase (a phase ends at an impact).
///
/// For internal numerical differentiation (Bock): the perturbed strides of the stride
/// Jacobian replay the nominal stride's steps, so that their differences are derivatives of
/// one discrete flow rather than of the adaptive step selection, whose accept/reject decisions
/// flip under a perturbation and make the central difference noisy.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StepSchedule {
    /// Step sizes [s] of each phase, in order.
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
struct ScheduleCursor<'a> {
    schedule: Schedule<'a>,
    phase: usize,
    step: usize,
}

impl<'a> ScheduleCursor<'a> {
    fn new(mut schedule: Schedule<'a>) -> Self {
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
    fn replayed(&self) -> Option<f64> {
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
    fn stepped(&mut self, h_s: f64) {
        if let Schedule::Record(s) = &mut self.schedule {
            if let Some(p) = s.phases.last_mut() {
                p.push(h_s);
            }
        }
        self.step += 1;
    }

    /// A new smooth phase begins (after an impact or at a breakpoint).
    fn next_phase(&mut self) {
        self.phase += 1;
        self.step = 0;
        if let Schedule::Record(s) = &mut self.schedule {
            s.phases.push(Vec::new());
        }
    }
}

impl Walker {
    /// Simulates one stride from `q0`, `qd0` (just after heel strike, stance labelling).
    pub fn stride(
        &self,
        q0: &DVector<f64>,
        qd0: &DVector<f64>,
        options: StrideOptions,
    ) -> Result<StrideResult, StrideFailure> {
        let mut trajectory = Vec::new();
        let mut r = self.stride_recording(q0, qd0, options, &mut trajectory)?;
        r.trajectory = trajectory;
        Ok(r)
    }

    /// As [`Self::stride`], appending accepted samples to `trajectory` when
    /// `options.record`, so that a failed stride keeps its samples up to the failure.
    pub fn stride_recording(
        &self,
        q0: &DVector<f64>,
        qd0: &DVector<f64>,
        options: StrideOptions,
        trajectory: &mut Vec<Sample>,
    ) -> Result<StrideResult, StrideFailure> {
        self.stride_inner(q0, qd0, options, trajectory, None, Schedule::Free)
    }

    /// As [`Self::stride`], with its steps recorded or replayed ([`Schedule`]).
    pub fn stride_scheduled(
        &self,
        q0: &DVector<f64>,
        qd0: &DVector<f64>,
        options: StrideOptions,
        schedule: Schedule<'_>,
    ) -> Result<StrideResult, StrideFailure> {
        let mut trajectory = Vec::new();
        let mut r = self.stride_inner(q0, qd0, options, &mut trajectory, None, schedule)?;
        r.trajectory = trajectory;
        Ok(r)
    }

    /// As [`Self::stride_recording`], with the stance ankle's string moved by `controller`,
    /// sampled at its control ticks (on the grid `k · period` of walk time); `t_walk_s` is the
    /// walk time at the start of this stride. The scene's `ankle_reflex` names the ankle and
    /// toe coordinates; its angles and duration are not used.
    pub fn stride_controlled(
        &self,
        q0: &DVector<f64>,
        qd0: &DVector<f64>,
        options: StrideOptions,
        trajectory: &mut Vec<Sample>,
        controller: &mut dyn AnkleController,
        t_walk_s: f64,
    ) -> Result<StrideResult, StrideFailure> {
        if self.ankle.is_none() {
            return Err(StrideFailure::new(
                FailureKind::NonFiniteState,
                0.0,
                "a controlled stride needs a scene with an ankle_reflex section",
            ));
        }
        self.stride_inner(
            q0,
            qd0,
            options,
            trajectory,
            Some((controller, t_walk_s)),
            Schedule::Free,
        )
    }

    fn stride_inner(
        &self,
        q0: &DVector<f64>,
        qd0: &DVector<f64>,
        options: StrideOptions,
        trajectory: &mut Vec<Sample>,
        mut control: Option<(&mut dyn AnkleController, f64)>,
        schedule: Schedule<'_>,
    ) -> Result<StrideResult, StrideFailure> {
        let mut integrator = self.integrator.build();
        integrator.reset();
        let mut schedule = ScheduleCursor::new(schedule);
        // Evaluations of earlier phases (the integrator restarts after each impact).
        let mut evaluations = 0;
        let mut phase = Phase::new(&self.model);
        for c in &self.initially_locked {
            phase.active[c.0] = false;
        }
        let damping: Vec<(usize, f64)> = self
            .model
            .links
            .iter()
            .filter_map(|l| l.coordinate.map(|c| (c.0, l.joint_force.damping)))
            .filter(|(_, d)| *d != 0.0)
            .collect();
        let mut power = Power::new(&self.model);
        let mut contact = ContactSummary::default();
        // Witness values at `cur`, carried over from the previous step.
        let mut w_cached: Option<WitnessValues> = None;
        let mut wit = Witnesses {
            walker: self,
            kin: Kinematics::new(&self.model),
        };
        let mut cur = Sample {
            t_s: 0.0,
            q: q0.clone(),
            qd: qd0.clone(),
        };
        if cur.q.iter().chain(cur.qd.iter()).any(|v| !v.is_finite()) {
            return Err(StrideFailure::new(
                FailureKind::NonFiniteState,
                0.0,
                "initial state",
            ));
        }
        let mut events = Vec::new();
        let mut event_states: Vec<(Sample, Sample)> = Vec::new();
        let mut energy_loss = 0.0;
        if options.record {
            trajectory.push(cur.clone());
        }
        // Control ticks: on the walk-time grid k · period, handled in stride time.
        let (period_s, t_walk0) = match &control {
            Some((c, t0)) => (c.period_s(), *t0),
            None => (f64::INFINITY, 0.0),
        };
        let mut next_tick = if period_s.is_finite() {
            (t_walk0 / period_s - 1e-9).ceil() * period_s - t_walk0
        } else {
            f64::INFINITY
        };
        // The stance string's limit over the current tick (stride time), from the controller.
        let mut segment: Option<ActuatorSegment> = None;
        loop {
            if let Some((c, t0)) = control.as_mut() {
                if cur.t_s >= next_tick - 1e-12 {
                    let w = wit.eval(&cur);
                    let (a, engaged) = match &self.ankle {
                        Some(r) => (r.ankle.0, phase.prescribed.is_some()),
                        None => (0, false),
                    };
                    let sensing = AnkleSensing {
                        t_s: *t0 + cur.t_s,
                        stance_ankle_rad: cur.q[a],
                        stance_ankle_rate_rad_s: cur.qd[a],
                        stance_foot_on_floor: true,
                        swing_foot_on_floor: w.foot_height_m <= 1e-9,
                        string_engaged: engaged,
                        string_torque_n_m: if engaged {
                            phase
                                .actuator_torque(&cur)
                                .map_err(|e| {
                                    StrideFailure::new(
                                        FailureKind::NonFiniteState,
                                        cur.t_s,
                                        e.to_string(),
                                    )
                                })?
                                .0
                        } else {
                            0.0
                        },
                    };
                    let mut seg = c.tick(&sensing).map_err(|e| {
                        StrideFailure::new(FailureKind::NonFiniteState, cur.t_s, e.to_string())
                    })?;
                    seg.t0_s -= *t0;
                    seg.t1_s -= *t0;
                    if let Some((coord, Drive::Segment(_))) = phase.prescribed {
                        if seg.released {
                            // The string goes slack during the push (an emergency stop, a
                            // fault): no impulse, the ankle is free again, and the foot keeps
                            // pivoting about its toe until the heel comes back down or the
                            // stride ends.
                            power.close(&self.model, &cur);
                            phase.prescribed = None;
                            phase.active[coord.0] = true;
                            integrator.system_changed();
                            events.push(StrideEvent {
                                name: "string_released".into(),
                                time_s: cur.t_s,
                            });
                            event_states.push((cur.clone(), cur.clone()));
                        } else {
                            phase.prescribed = Some((coord, Drive::Segment(seg)));
                            phase.snap(&mut cur);
                        }
                    }
                    // Only an engaged string's new segment changes the vector field; while
                    // the ankle is free the tick only moves the engagement witness, and the
                    // integrator keeps its last stage (first same as last).
                    if phase.prescribed.is_some() {
                        integrator.system_changed();
                    }
                    segment = Some(seg);
                    next_tick += period_s;
                }
            }
            if cur.t_s > self.max_stride_time_s {
                return Err(StrideFailure::new(
                    FailureKind::NoImpactWithinTime,
                    cur.t_s,
                    format!("no heel strike within {} s", self.max_stride_time_s),
                ));
            }
            // The ideal drive's profile ends with a jump in its jerk: a breakpoint, so that no
            // step straddles it (the step sizes stay smooth functions of the initial state,
            // and replayed schedules stay accurate when the end moves).
            let drive_end = match phase.prescribed {
                Some((_, Drive::Profile(p))) if cur.t_s < p.start_s + p.duration_s - 1e-12 => {
                    p.start_s + p.duration_s
                }
                _ => f64::INFINITY,
            };
            let h_limit = (next_tick.min(drive_end) - cur.t_s).max(1e-12);
            let replayed = schedule.replayed();
            let mut next = match replayed {
                Some(h) => integrator.step_exact(&mut phase, &cur, h.min(h_limit)),
                None => integrator.advance(&mut phase, &cur, h_limit),
            }
            .map_err(|e| StrideFailure::from_integration(e, cur.t_s))?;
            phase.snap(&mut next);
            if next.q.iter().chain(next.qd.iter()).any(|v| !v.is_finite()) {
                return Err(StrideFailure::new(
                    FailureKind::NonFiniteState,
                    next.t_s,
                    "state",
                ));
            }
            // A grazing contact: the foot height is positive at both ends of the step but dips
            // below the floor inside it. The cubic Hermite interpolant of the height (from its
            // values and rates at both ends) is checked at interior points; if the exact flow
            // confirms a dip, the step is shortened to end inside it.
            let w_cur = match w_cached {
                Some(w) if w.t_s == cur.t_s => w,
                _ => wit.eval(&cur),
            };
            let mut w_next = wit.eval(&next);
            if w_cur.foot_height_m > 0.0 && w_next.foot_height_m > 0.0 {
                let n = self.event_tolerance.grazing_samples;
                let h = next.t_s - cur.t_s;
                let height_at = |x: f64| {
                    let (x2, x3) = (x * x, x * x * x);
                    (1.0 - 3.0 * x2 + 2.0 * x3) * w_cur.foot_height_m
                        + (x - 2.0 * x2 + x3) * h * w_cur.foot_height_rate_m_s
                        + (3.0 * x2 - 2.0 * x3) * w_next.foot_height_m
                        + (-x2 + x3) * h * w_next.foot_height_rate_m_s
                };
                if let Some(k) = (1..=n).find(|&k| height_at(k as f64 / (n + 1) as f64) <= 0.0) {
                    let t = cur.t_s + h * k as f64 / (n + 1) as f64;
                    let mut s = integrator
                        .step_exact(&mut phase, &cur, t - cur.t_s)
                        .map_err(|e| StrideFailure::from_integration(e, cur.t_s))?;
                    phase.snap(&mut s);
                    let ws = wit.eval(&s);
                    if ws.foot_height_m <= 0.0 {
                        next = s;
                        w_next = ws;
                    }
                }
            }
            w_cached = Some(w_next);
            // Which witnesses changed sign in the right direction over this step?
            let mut triggered: Vec<Watch> = Vec::new();
            if Direction::Falling.triggered(w_cur.foot_height_m, w_next.foot_height_m) {
                triggered.push(Watch::Heel);
            }
            for (k, knee) in self.knees.iter().enumerate() {
                let c = knee.coordinate.0;
                if phase.active[c]
                    && knee
                        .closing
                        .triggered(cur.q[c] - knee.stop_rad, next.q[c] - knee.stop_rad)
                {
                    triggered.push(Watch::Knee(k));
                }
            }
            if Direction::Falling.triggered(w_cur.hip_height_margin_m, w_next.hip_height_margin_m) {
                triggered.push(Watch::HipLow);
            }
            if w_next.hip_ahead_m < 0.0
                && Direction::Falling.triggered(
                    w_cur.hip_forward_velocity_m_s,
                    w_next.hip_forward_velocity_m_s,
                )
            {
                triggered.push(Watch::HipBack);
            }
            if let Some(r) = &self.ankle {
                let (a, toe) = (r.ankle.0, r.toe_pitch.0);
                let flat = !phase.active[toe] && phase.prescribed.is_none();
                let limit = |t: f64| match (&control, &segment) {
                    (None, _) => Some(r.engage_rad),
                    (Some(_), Some(seg)) if !seg.released => Some(seg.eval(t).0),
                    (Some(_), _) => None,
                };
                if let (true, Some(l0), Some(l1)) = (flat, limit(cur.t_s), limit(next.t_s)) {
                    if Direction::Falling.triggered(cur.q[a] - l0, next.q[a] - l1) {
                        triggered.push(Watch::Engage);
                    }
                }
                if phase.active[toe] && Direction::Rising.triggered(cur.q[toe], next.q[toe]) {
                    triggered.push(Watch::HeelDrop);
                }
            }
            if triggered.is_empty() {
                power.accumulate(&damping, &cur, &next);
                if options.contact {
                    contact
                        .add(self, &mut phase, &mut wit, &next)
                        .map_err(|e| {
                            StrideFailure::new(FailureKind::NonFiniteState, next.t_s, e.to_string())
                        })?;
                }
                schedule.stepped(next.t_s - cur.t_s);
                if next.t_s >= drive_end - 1e-12 {
                    // A new smooth phase: the schedule and the integrator's memory restart.
                    integrator.system_changed();
                    schedule.next_phase();
                }
                cur = next;
                if options.record {
                    trajectory.push(cur.clone());
                }
                continue;
            }
            // Locate each and take the earliest.
            let mut located: Vec<(Watch, Sample)> = Vec::new();
            for w in triggered {
                let mut g: Box<dyn FnMut(&Sample) -> f64> = match w {
                    Watch::Heel => Box::new(|s: &Sample| wit.eval(s).foot_height_m),
                    Watch::Knee(k) => {
                        let c = self.knees[k].coordinate.0;
                        let stop = self.knees[k].stop_rad;
                        Box::new(move |s: &Sample| s.q[c] - stop)
                    }
                    Watch::HipLow => Box::new(|s: &Sample| wit.eval(s).hip_height_margin_m),
                    Watch::HipBack => Box::new(|s: &Sample| wit.eval(s).hip_forward_velocity_m_s),
                    Watch::Engage => {
                        let (a, e) = self
                            .ankle
                            .as_ref()
                            .map_or((0, 0.0), |r| (r.ankle.0, r.engage_rad));
                        match (&control, segment) {
                            (Some(_), Some(seg)) => {
                                Box::new(move |s: &Sample| s.q[a] - seg.eval(s.t_s).0)
                            }
                            _ => Box::new(move |s: &Sample| s.q[a] - e),
                        }
                    }
                    Watch::HeelDrop => {
                        let toe = self.ankle.as_ref().map_or(0, |r| r.toe_pitch.0);
                        Box::new(move |s: &Sample| s.q[toe])
                    }
                };
                let s = locate(
                    integrator.as_mut(),
                    &mut phase,
                    &cur,
                    &next,
                    g.as_mut(),
                    &self.event_tolerance,
                )
                .map_err(|e| StrideFailure::from_event(e, cur.t_s))?;
                drop(g);
                located.push((w, s));
            }
            located.sort_by(|a, b| a.1.t_s.total_cmp(&b.1.t_s));
            // A mid-swing scuff that is ignored must not hide a later event of the same step
            // (a knee lock, the string's engagement): take that one instead.
            if located.len() > 1
                && located[0].0 == Watch::Heel
                && self.heel_strike.ignore_scuffing
                && wit.eval(&located[0].1).foot_ahead_m < self.heel_strike.min_ahead_m
            {
                located.remove(0);
            }
            let Some((watch, mut at)) = located.into_iter().next() else {
                continue;
            };
            phase.snap(&mut at);
            power.accumulate(&damping, &cur, &at);
            // The arms that do not end the stride are impacts: each leaves `cur` after it and
            // names the event.
            let event: String = match watch {
                Watch::HipLow => {
                    let kind = if wit.eval(&at).hip_ahead_m >= 0.0 {
                        FailureKind::FellForward
                    } else {
                        FailureKind::FellBackward
                    };
                    return Err(StrideFailure::new(
                        kind,
                        at.t_s,
                        "hip below its minimum height",
                    ));
                }
                Watch::HipBack => {
                    return Err(StrideFailure::new(
                        FailureKind::FellBackward,
                        at.t_s,
                        "hip moved back behind the stance contact",
                    ));
                }
                Watch::HeelDrop => {
                    if phase.prescribed.is_some() {
                        // The drive still holds the ankle: the push has failed.
                        return Err(StrideFailure::new(
                            FailureKind::HeelReturnedToFloor,
                            at.t_s,
                            "the stance heel came back down during push-off",
                        ));
                    }
                    // The string is slack: the heel lands, an inelastic impact that stops the
                    // foot's pitch about its toe; the foot is flat again, the ankle free.
                    let Some(r) = &self.ankle else { continue };
                    let toe = r.toe_pitch.0;
                    let l = self.lock_coordinate(&phase, &at, toe, 0.0)?;
                    phase.active[toe] = false;
                    cur = l.after;
                    energy_loss += l.loss_j;
                    "heel_down".into()
                }
                Watch::Engage => {
                    let Some(r) = &self.ankle else { continue };
                    let (a, toe) = (r.ankle.0, r.toe_pitch.0);
                    // The string becomes taut: an inelastic impact stops the ankle while the
                    // foot becomes free to pivot about its toe.
                    let mut act = phase.active.clone();
                    act[toe] = true;
                    let mut g = DMatrix::zeros(1, self.model.dof());
                    g[(0, a)] = 1.0;
                    // The string's far end: fixed (ideal reflex) or moving with the actuator.
                    let drive = match (&control, segment) {
                        (Some(_), Some(seg)) => Drive::Segment(seg),
                        _ => Drive::Profile(AnkleProfile {
                            start_s: at.t_s,
                            duration_s: r.duration_s,
                            from_rad: r.engage_rad,
                            to_rad: r.final_rad,
                        }),
                    };
                    let (p_rad, v_rad_s, _) = drive.eval(at.t_s);
                    let mut dynamics = Dynamics::new(&self.model);
                    let before = energy(&mut dynamics, &self.model, &at);
                    let target = DVector::from_element(1, v_rad_s);
                    let imp =
                        resolve_to(&mut dynamics, &self.model, &at.q, &at.qd, &act, &g, &target)
                            .map_err(|e| {
                                StrideFailure::new(
                                    FailureKind::ImpactSingular,
                                    at.t_s,
                                    e.to_string(),
                                )
                            })?;
                    // The string's impulse on the ankle, with its far end moving at the drive's
                    // rate, is work the actuator does (zero for the ideal drive, which starts
                    // at rest).
                    let drive_work = imp.impulse[0] * v_rad_s;
                    power.work_j += drive_work;
                    energy_loss += drive_work;
                    let mut q = at.q.clone();
                    q[a] = p_rad;
                    let mut qd = imp.qd_plus;
                    qd[a] = v_rad_s;
                    if qd[toe] > 0.0 {
                        return Err(StrideFailure::new(
                            FailureKind::HeelDidNotLift,
                            at.t_s,
                            format!(
                                "at string engagement the heel moves down ({:.3e} rad/s)",
                                qd[toe]
                            ),
                        ));
                    }
                    cur = Sample { t_s: at.t_s, q, qd };
                    energy_loss += before - energy(&mut dynamics, &self.model, &cur);
                    act[a] = false;
                    phase.active = act;
                    phase.prescribed = Some((r.ankle, drive));
                    power.open(&self.model, &cur);
                    "string_engaged".into()
                }
                Watch::Knee(k) => {
                    let c = self.knees[k].coordinate.0;
                    power.close(&self.model, &at);
                    let l = self.lock_coordinate(&phase, &at, c, self.knees[k].stop_rad)?;
                    phase.active[c] = false;
                    cur = l.after;
                    power.work_j += l.drive_work_j;
                    energy_loss += l.loss_j;
                    if phase.prescribed.is_some() {
                        power.open(&self.model, &cur);
                    }
                    format!("knee_lock:{}", self.model.coordinates[c].name)
                }
                Watch::Heel => {
                    let ahead = wit.eval(&at).foot_ahead_m;
                    if ahead < self.heel_strike.min_ahead_m {
                        if self.heel_strike.ignore_scuffing {
                            power.accumulate(&damping, &at, &next);
                            schedule.stepped(next.t_s - cur.t_s);
                            cur = next;
                            if options.record {
                                trajectory.push(cur.clone());
                            }
                            continue;
                        }
                        return Err(StrideFailure::new(
                            FailureKind::Scuffed,
                            at.t_s,
                            format!("swing foot touched the floor {ahead:.4} m ahead of the stance contact"),
                        ));
                    }
                    if let Some(knee) = self.knees.iter().find(|k| phase.active[k.coordinate.0]) {
                        return Err(StrideFailure::new(
                            FailureKind::HeelStrikeBeforeKneeLock,
                            at.t_s,
                            format!(
                                "knee `{}` still free at heel strike",
                                self.model.coordinates[knee.coordinate.0].name
                            ),
                        ));
                    }
                    power.close(&self.model, &at);
                    if let Some((c, t0)) = control.as_mut() {
                        c.heel_strike(*t0 + at.t_s);
                    }
                    events.push(StrideEvent {
                        name: "heel_strike".into(),
                        time_s: at.t_s,
                    });
                    event_states.push((at.clone(), at.clone()));
                    if options.record {
                        trajectory.push(at.clone());
                    }
                    evaluations += integrator.evaluations();
                    let mut r = self.finish_stride(
                        at,
                        &phase.active,
                        events,
                        energy_loss,
                        integrator.as_ref(),
                    )?;
                    r.actuator_work_j = power.work_j;
                    r.event_states = event_states;
                    r.evaluations = evaluations;
                    r.contact = contact;
                    r.damping_dissipation_j = power.dissipation_j;
                    return Ok(r);
                }
            };
            events.push(StrideEvent {
                name: event,
                time_s: at.t_s,
            });
            event_states.push((at.clone(), cur.clone()));
            // The integrator restarts after an impact; its evaluations so far are kept.
            evaluations += integrator.evaluations();
            integrator.reset();
            schedule.next_phase();
            if options.record {
                trajectory.push(cur.clone());
            }
        }
    }

    /// An inelastic impact that locks coordinate `c` at `value` (a knee at its stop, a foot
    /// landing flat), the other free coordinates as `phase` has them.
    fn lock_coordinate(
        &self,
        phase: &Phase,
        at: &Sample,
        c: usize,
        value: f64,
    ) -> Result<Locked, StrideFailure> {
        let mut g = DMatrix::zeros(1, self.model.dof());
        g[(0, c)] = 1.0;
        let mut dynamics = Dynamics::new(&self.model);
        let before = energy(&mut dynamics, &self.model, at);
        let imp = resolve(
            &mut dynamics,
            &self.model,
            &at.q,
            &at.qd,
            &phase.active,
            &g,
            0.0,
        )
        .map_err(|e| StrideFailure::new(FailureKind::ImpactSingular, at.t_s, e.to_string()))?;
        // A drive holding the ankle through the impact takes an impulse and does work on it
        // (impulse × its rate, which the impact does not change): the actuator's work, not part
        // of the impact's loss.
        let drive_work_j = match phase.prescribed {
            Some((a, _)) => {
                let dqd = &imp.qd_plus - &at.qd;
                (dynamics.mass_matrix.row(a.0) * dqd)[(0, 0)] * at.qd[a.0]
            }
            None => 0.0,
        };
        let mut qd = imp.qd_plus;
        qd[c] = 0.0;
        let mut q = at.q.clone();
        q[c] = value;
        let after = Sample { t_s: at.t_s, q, qd };
        let loss_j = before - energy(&mut dynamics, &self.model, &after) + drive_work_j;
        Ok(Locked {
            after,
            loss_j,
            drive_work_j,
        })
    }

    /// The heel-strike impact at `at` (stance labelling) with the stance contact released:
    /// eq. (21) on the impact model. Does not check the lift or relabel.
    pub fn heel_strike_impact(
        &self,
        at: &Sample,
        active: &[bool],
    ) -> Result<HeelStrikeImpact, ImpactError> {
        let hs = &self.heel_strike;
        let m = &self.impact_model;
        let crate::hybrid::contact_rows::HeelStrikeRows {
            q,
            qd,
            active: act,
            g,
            p_contact_m: p_foot,
        } = crate::hybrid::contact_rows::heel_strike_rows(m, hs, &at.q, &at.qd, active);
        let mut dynamics = Dynamics::new(m);
        let before = energy(
            &mut dynamics,
            m,
            &Sample {
                t_s: at.t_s,
                q: q.clone(),
                qd: qd.clone(),
            },
        );
        let imp = resolve(&mut dynamics, m, &q, &qd, &act, &g, hs.restitution)?;
        let after = energy(
            &mut dynamics,
            m,
            &Sample {
                t_s: at.t_s,
                q: q.clone(),
                qd: imp.qd_plus.clone(),
            },
        );
        Ok(HeelStrikeImpact {
            q,
            qd_minus: qd,
            qd_plus: imp.qd_plus,
            impulse: imp.impulse,
            p_contact_m: p_foot,
            energy_loss_j: before - after,
        })
    }

    /// Heel-strike impact, lift check, relabelling.
    fn finish_stride(
        &self,
        at: Sample,
        active: &[bool],
        events: Vec<StrideEvent>,
        mut energy_loss: f64,
        integrator: &dyn Integrator,
    ) -> Result<StrideResult, StrideFailure> {
        let t = at.t_s;
        let hs = &self.heel_strike;
        let nr = hs.release.len();
        let m = &self.impact_model;
        let HeelStrikeImpact {
            q,
            qd_plus,
            p_contact_m: p_foot,
            energy_loss_j,
            ..
        } = self
            .heel_strike_impact(&at, active)
            .map_err(|e| StrideFailure::new(FailureKind::ImpactSingular, t, e.to_string()))?;
        energy_loss += energy_loss_j;
        let mut kin = Kinematics::new(m);
        kin.update(m, &q, &qd_plus);
        let sc = &m.points[hs.stance_contact.0];
        let p_sc = kin.position_of(sc.link, &sc.p_link_m);
        let lift = kin.velocity_of(sc.link, &p_sc).y;
        if lift <= 0.0 {
            return Err(StrideFailure::new(
                FailureKind::StanceFootDidNotLift,
                t,
                format!("old stance contact moves {lift:.3e} m/s upward after impact"),
            ));
        }
        let states = LinkStates::from_kinematics(&kin, nr, &p_foot);
        let solved = self
            .relabel
            .solve(&self.model, &states, &self.guess_q)
            .or_else(|_| self.relabel.solve(&self.model, &states, &at.q))
            .map_err(|e| StrideFailure::new(FailureKind::RelabelFailed, t, e.to_string()))?;
        Ok(StrideResult {
            q_next: solved.q,
            qd_next: solved.qd,
            duration_s: t,
            step_m: p_foot,
            heading_change_rad: solved.cyclic_values.first().copied().unwrap_or(0.0),
            events,
            pre_impact: at,
            lift_velocity_m_s: lift,
            impact_energy_loss_j: energy_loss,
            evaluations: integrator.evaluations(),
            trajectory: Vec::new(),
            event_states: Vec::new(),
            actuator_work_j: 0.0,
            damping_dissipation_j: 0.0,
            contact: ContactSummary::default(),
        })
    }
}

fn energy(dynamics: &mut Dynamics, model: &Model, s: &Sample) -> f64 {
    dynamics.assemble(model, &s.q, &s.qd, None);
    dynamics.energy_j(model, &s.q, &s.qd)
}
