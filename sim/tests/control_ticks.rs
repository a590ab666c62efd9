//! The control-tick contract (`sim::engine::control`): every tick runs, once, at its exact time, in
//! order, whichever way the steps meet the ticks (`TickStepping`), also over steps whose
//! swing foot grazes the floor (the grazing probe takes another step of the integrator); and a
//! controller whose period cannot make ticks is refused, not looped on.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use nalgebra::DVector;
use sim::engine::control::{
    ActuatorSegment, AnkleController, AnkleSensing, ControlError, SampledReflex, TickStepping,
};
use sim::engine::integrators::IntegratorChoice;
use sim::scene::Setup;
use sim::stride::walk::WalkRequest;
use sim::stride::{FailureKind, StrideRequest, StrideSettings};

/// The walker's sampled reflex, writing down the walk time at which each of its ticks runs
/// (and each heel strike).
struct Recording {
    inner: SampledReflex,
    period_s: f64,
    ticks_s: Vec<f64>,
    heel_strikes_s: Vec<f64>,
}

impl Recording {
    fn new(period_s: f64, inner: SampledReflex) -> Self {
        Self {
            inner,
            period_s,
            ticks_s: Vec::new(),
            heel_strikes_s: Vec::new(),
        }
    }
}

impl AnkleController for Recording {
    fn period_s(&self) -> f64 {
        self.period_s
    }
    fn tick(&mut self, sensing: &AnkleSensing) -> Result<ActuatorSegment, ControlError> {
        self.ticks_s.push(sensing.t_walk_s);
        self.inner.tick(sensing)
    }
    fn heel_strike(&mut self, t_walk_s: f64) {
        self.heel_strikes_s.push(t_walk_s);
        self.inner.heel_strike(t_walk_s);
    }
}

/// The firmware-in-the-loop integrator (`sil::SIL_INTEGRATOR`): long steps at a loose
/// tolerance, whose cubic of the swing foot's height dips below the floor where the foot
/// passes close to it, so that the grazing probe takes a step of its own.
const SIL_LIKE: IntegratorChoice = IntegratorChoice::Dopri5 {
    rtol: 1e-6,
    atol: 1e-6,
    h_max_s: 0.01,
};

/// Walks up to `steps` strides of wisse3d from `(q, qd)` with the 1 kHz sampled reflex and
/// returns the recorded tick times, the walk's end (walk time of its last heel strike, or of
/// its failure) and whether it failed.
fn walk_ticks(
    w: &Setup,
    start: &(DVector<f64>, DVector<f64>),
    settings: &StrideSettings,
    steps: usize,
) -> (Vec<f64>, f64, bool) {
    let reflex = w.walker.ankle().cloned().unwrap();
    let period_s = 1e-3;
    let mut ctl = Recording::new(period_s, SampledReflex::new(period_s, &reflex));
    let request = WalkRequest::new(settings, steps).controlled(&mut ctl);
    let walk = sim::stride::walk::walk(&w.walker, &start.0, &start.1, request);
    assert_eq!(ctl.heel_strikes_s.len(), walk.steps_completed);
    let end_s = match (&walk.failure, walk.steps.last()) {
        (Some(f), _) => f.t_walk_s,
        (None, Some(last)) => last.start_t_walk_s + last.duration_s,
        (None, None) => 0.0,
    };
    (ctl.ticks_s, end_s, walk.failure.is_some())
}

/// The ticks are `k · period` for `k = 0, 1, 2, …` (each once, in order, at its time to
/// rounding), up to the walk's end.
fn assert_every_tick_once_at_its_time(ticks_s: &[f64], period_s: f64, end_s: f64, what: &str) {
    for (k, &t_s) in ticks_s.iter().enumerate() {
        let due_s = k as f64 * period_s;
        assert!(
            (t_s - due_s).abs() < 1e-9,
            "{what}: tick {k} ran at walk time {t_s} s, due at {due_s} s (previous: {:?})",
            ticks_s.get(k.wrapping_sub(1))
        );
    }
    let last_s = ticks_s.last().copied().unwrap_or(f64::NAN);
    assert!(
        last_s <= end_s + 1e-9 && end_s - last_s <= period_s + 1e-9,
        "{what}: last tick at {last_s} s, the walk ends at {end_s} s"
    );
}

#[test]
fn every_tick_runs_once_at_its_time_in_both_schemes_also_across_grazing_steps() {
    let (_, w) = common::walker("wisse3d");
    let start = common::start_state(&w, &common::gait(&w));
    let schemes = [TickStepping::HeldAcrossTicks, TickStepping::EndAtEveryTick];
    // The gait, 6 steps, with the scene's integrator and the firmware-in-the-loop one.
    for (name, integrator) in [
        ("scene's", w.settings.integrator.clone()),
        ("sil", SIL_LIKE),
    ] {
        for stepping in schemes {
            let settings = w
                .settings
                .with_integrator(integrator.clone())
                .with_tick_stepping(stepping);
            let (ticks_s, end_s, failed) = walk_ticks(&w, &start, &settings, 6);
            assert!(!failed, "{name} {stepping:?}");
            let what = format!("{name} integrator, {stepping:?}");
            assert_every_tick_once_at_its_time(&ticks_s, 1e-3, end_s, &what);
        }
    }
    // Starts off the gait (its velocities scaled), whose swing foot passes closer to the floor
    // or scuffs (ignored in wisse3d), so that steps end near the floor and the grazing probe
    // takes steps of its own; a walk may fail, its ticks up to the failure are checked.
    for stepping in schemes {
        let settings = w
            .settings
            .with_integrator(SIL_LIKE)
            .with_tick_stepping(stepping);
        for scale in (0..=20).map(|i| 0.8 + 0.02 * f64::from(i)) {
            let scaled = (start.0.clone(), &start.1 * scale);
            let (ticks_s, end_s, _) = walk_ticks(&w, &scaled, &settings, 3);
            let what = format!("velocities x {scale}, {stepping:?}");
            assert_every_tick_once_at_its_time(&ticks_s, 1e-3, end_s, &what);
        }
    }
}

#[test]
fn a_period_that_makes_no_ticks_is_refused_before_the_stride() {
    let (_, w) = common::walker("wisse3d");
    let (q, qd) = (w.guess.q.clone(), w.guess.qd.clone());
    let reflex = w.walker.ankle().cloned().unwrap();
    for period_s in [0.0, -1e-3, f64::NAN, f64::INFINITY, 1e-300] {
        for t_walk_start_s in [0.0, 12.5] {
            let mut ctl = Recording::new(period_s, SampledReflex::new(1e-3, &reflex));
            let request = StrideRequest::new(&w.settings).controlled(&mut ctl, t_walk_start_s);
            let e = w.walker.stride(&q, &qd, request).unwrap_err();
            assert_eq!(e.kind, FailureKind::InvalidControlPeriod, "{period_s}: {e}");
            assert!(ctl.ticks_s.is_empty(), "{period_s}");
            assert_eq!(
                serde_json::to_value(e.kind).unwrap(),
                serde_json::json!("invalid_control_period")
            );
        }
    }
}

#[test]
fn a_period_far_too_short_for_the_stride_ends_in_the_step_budget() {
    // 1e-13 s advances the grid, but a stride would take some 10¹² ticks: the ticks count
    // against the step budget in both schemes (in `HeldAcrossTicks` they run inside steps).
    let (_, mut w) = common::walker("wisse3d");
    let (q, qd) = (w.guess.q.clone(), w.guess.qd.clone());
    let reflex = w.walker.ankle().cloned().unwrap();
    w.settings.max_steps = 2_000;
    for stepping in [TickStepping::HeldAcrossTicks, TickStepping::EndAtEveryTick] {
        let settings = w.settings.with_tick_stepping(stepping);
        let mut ctl = Recording::new(1e-13, SampledReflex::new(1e-3, &reflex));
        let request = StrideRequest::new(&settings).controlled(&mut ctl, 0.0);
        let e = w.walker.stride(&q, &qd, request).unwrap_err();
        assert_eq!(e.kind, FailureKind::StepBudgetExceeded, "{stepping:?}: {e}");
        assert!(e.detail().contains("max_steps = 2000"), "{}", e.detail());
        assert!(ctl.ticks_s.len() <= 2_000, "{}", ctl.ticks_s.len());
    }
}
