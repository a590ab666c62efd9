//! Every typed failure outcome is reached, by a physical cause where there is one.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use nalgebra::DVector;
use sim::analysis::limit_cycle::{GaitSearch, NewtonError, NewtonSettings};
use sim::engine::events::EventTolerance;
use sim::engine::integrators::IntegratorChoice;
use sim::engine::walker::ContactConstraint;
use sim::scene::Setup;
use sim::stride::FailureKind;

/// The failure of one stride from the gait's start with `name += delta`.
fn perturbed(w: &Setup, name: &str, delta: f64) -> FailureKind {
    let g = common::gait(w);
    let i = w.walker.map_names().iter().position(|n| n == name).unwrap();
    let mut v = g.fixed_point.clone();
    v[i] += delta;
    common::stride_map(w, &v)
        .expect_err("stride must fail")
        .kind
}

#[test]
fn too_slow_falls_backward() {
    let (_, w) = common::walker("compass");
    assert_eq!(
        perturbed(&w, "stance_leg_dot", 0.6),
        FailureKind::FellBackward
    );
}

#[test]
fn too_fast_falls_forward() {
    let (_, w) = common::walker("compass");
    assert_eq!(perturbed(&w, "stance_leg", -0.5), FailureKind::FellForward);
}

#[test]
fn a_bent_knee_scuffs_the_floor() {
    let (_, w) = common::walker("kneed2d");
    assert_eq!(perturbed(&w, "swing_knee", -1.0), FailureKind::Scuffed);
}

#[test]
fn a_short_step_strikes_before_the_knee_locks() {
    let (_, w) = common::walker("kneed2d");
    assert_eq!(
        perturbed(&w, "stance_leg", -0.5),
        FailureKind::HeelStrikeBeforeKneeLock
    );
}

#[test]
fn a_swing_leg_thrown_forward_keeps_the_old_stance_foot_down() {
    let (_, w) = common::walker("compass");
    assert_eq!(
        perturbed(&w, "swing_leg_dot", 3.0),
        FailureKind::StanceFootDidNotLift
    );
}

#[test]
fn no_heel_strike_within_the_time_budget() {
    let (_, mut w) = common::walker("compass");
    w.settings.max_stride_time_s = 0.1;
    let e = common::stride(&w, &w.guess.q, &w.guess.qd).unwrap_err();
    assert_eq!(e.kind, FailureKind::NoImpactWithinTime);
}

#[test]
fn a_non_finite_state_is_caught() {
    let (_, w) = common::walker("compass");
    let mut q = w.guess.q.clone();
    q[0] = f64::NAN;
    let e = common::stride(&w, &q, &w.guess.qd).unwrap_err();
    assert_eq!(e.kind, FailureKind::NonFiniteState);
}

#[test]
fn a_meijaard_step_beyond_the_stability_limit_is_reported() {
    let (_, mut w) = common::walker("compass");
    w.settings.integrator = IntegratorChoice::Meijaard {
        h_s: 1.0,
        check_every: 1,
    };
    let e = common::stride(&w, &w.guess.q, &w.guess.qd).unwrap_err();
    assert_eq!(e.kind, FailureKind::StepTooLarge, "{e}");
    // The same step without the check produces a stride anyway (garbage or failure) - the
    // check is what turns it into a typed error; a small step passes the check.
    w.settings.integrator = IntegratorChoice::Meijaard {
        h_s: 1e-3,
        check_every: 1,
    };
    common::stride(&w, &w.guess.q, &w.guess.qd).unwrap();
}

#[test]
fn an_unreachable_tolerance_underflows_the_adaptive_step() {
    let (_, mut w) = common::walker("compass");
    w.settings.integrator = IntegratorChoice::Dopri5 {
        rtol: 1e-30,
        atol: 1e-30,
        h_max_s: 0.05,
    };
    let e = common::stride(&w, &w.guess.q, &w.guess.qd).unwrap_err();
    assert_eq!(e.kind, FailureKind::StepUnderflow);
}

#[test]
fn an_event_without_refinement_budget_is_not_located() {
    let (_, mut w) = common::walker("compass");
    w.settings.event_tolerance = EventTolerance {
        max_iterations: 0,
        ..Default::default()
    };
    let e = common::stride(&w, &w.guess.q, &w.guess.qd).unwrap_err();
    assert_eq!(e.kind, FailureKind::EventNotLocated);
}

#[test]
fn redundant_contact_constraints_make_the_impact_singular() {
    let (_, mut w) = common::walker("compass");
    w.walker = w.walker.clone().with_changes(|_, rules| {
        rules.heel_strike.constraints = vec![
            ContactConstraint::X,
            ContactConstraint::Y,
            ContactConstraint::X,
        ];
    });
    let e = common::stride(&w, &w.guess.q, &w.guess.qd).unwrap_err();
    assert_eq!(e.kind, FailureKind::ImpactSingular);
}

#[test]
fn an_inconsistent_relabelling_is_an_error_not_a_wrong_state() {
    let (_, mut w) = common::walker("compass");
    let (a, b) = (w.walker.relabel().pairs[0].0, w.walker.relabel().pairs[1].0);
    w.walker = w
        .walker
        .clone()
        .with_changes(|_, rules| rules.relabel.pairs = vec![(a, a), (b, b)]);
    let e = common::stride(&w, &w.guess.q, &w.guess.qd).unwrap_err();
    assert_eq!(e.kind, FailureKind::RelabelFailed);
}

#[test]
fn newton_reports_its_spent_budget_and_failed_strides() {
    let (_, w) = common::walker("compass");
    let v0 = w.walker.pack(&w.guess.q, &w.guess.qd);
    let tight = NewtonSettings {
        max_iterations: 1,
        ..Default::default()
    };
    assert!(matches!(
        GaitSearch::new(&w.walker, &w.settings, &tight).find(&v0),
        Err(NewtonError::NotConverged { iterations: 1, .. })
    ));
    let bad = DVector::from_vec(vec![0.27, -0.54, -3.0, 0.7]);
    assert!(matches!(
        GaitSearch::new(&w.walker, &w.settings, &NewtonSettings::default()).find(&bad),
        Err(NewtonError::StrideFailed { iteration: 0, .. })
    ));
}

#[test]
fn a_drive_that_retracts_lets_the_heel_back_down() {
    // The string engages at the usual angle, but the actuator then pulls the ankle back to
    // -0.2 rad instead of extending it: the foot, pivoting about its toe, comes back down.
    // (The tuned walker: its string engages 0.27 s before heel strike, time enough for a
    // 0.2 s retraction; the Table I walker's engages 0.19 s before it.)
    let (mut scene, w) = common::walker("wisse3d-tuned");
    let g = common::gait(&w);
    scene.set_text("ankle_final_rad=-0.2").unwrap();
    let retracting = scene.setup().unwrap();
    let e = common::stride_map(&retracting, &g.fixed_point).expect_err("must fail");
    assert_eq!(e.kind, FailureKind::HeelReturnedToFloor, "{e}");
    // The same start with the scene's own drive walks on.
    assert!(common::stride_map(&w, &g.fixed_point).is_ok());
}

/// A controller that fails its first tick with an error of its own.
struct Broken;

#[derive(Debug, thiserror::Error)]
#[error("the bus is down")]
struct BusDown;

impl sim::engine::control::AnkleController for Broken {
    fn period_s(&self) -> f64 {
        1e-3
    }
    fn tick(
        &mut self,
        _: &sim::engine::control::AnkleSensing,
    ) -> Result<sim::engine::control::ActuatorSegment, sim::engine::control::ControlError> {
        Err(sim::engine::control::ControlError::controller(
            "broken", BusDown,
        ))
    }
    fn heel_strike(&mut self, _: f64) {}
}

/// A stride of `scene` from its gait's fixed point under the [`Broken`] controller: it fails.
fn broken_controller_stride(scene: &str) -> sim::stride::StrideFailure {
    let (_, w) = common::walker(scene);
    let g = common::gait(&w);
    let (q, qd) = common::start_state(&w, &g);
    let mut ctl = Broken;
    w.walker
        .stride(
            &q,
            &qd,
            sim::stride::StrideRequest::new(&w.settings).controlled(&mut ctl, 0.0),
        )
        .unwrap_err()
}

#[test]
fn a_controlled_stride_on_a_walker_without_an_ankle_reflex_is_a_configuration_error() {
    let e = broken_controller_stride("compass");
    assert_eq!(e.kind, FailureKind::InvalidConfiguration, "{e}");
    assert_eq!(*e.cause, sim::stride::FailureCause::NoAnkleReflex);
    assert_eq!(
        e.detail(),
        "a controlled stride needs a scene with an ankle_reflex section"
    );
}

#[test]
fn a_controller_s_failure_is_its_own_typed_error_not_a_non_finite_state() {
    let e = broken_controller_stride("wisse3d");
    assert_eq!(e.kind, FailureKind::ControlFailed, "{e}");
    assert_eq!(e.detail(), "controller: broken: the bus is down");
    let sim::stride::FailureCause::Control(c) = &*e.cause else {
        panic!("{e}");
    };
    assert!(c.source_error().downcast_ref::<BusDown>().is_some());
}
