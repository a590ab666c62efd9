//! Hard cases: each ends in a typed outcome or meets an error bound, and each could fail.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use sim::analysis::limit_cycle::{GaitSearch, NewtonSettings};
use sim::engine::integrators::IntegratorChoice;
use sim::stride::{FailureKind, StrideOptions, StrideRequest};

#[test]
fn a_grazing_mid_swing_contact_inside_one_step_is_caught() {
    // The compass gait's point foot passes 3.5 mm through the floor at mid-swing. Shorten the
    // swing foot so that it dips only about 0.5 mm below the floor, for a few milliseconds, and
    // count any touch behind the stance foot as a scuff.
    let (_, mut w) = common::walker("compass");
    let g = common::gait(&w);
    let (q, qd) = common::start_state(&w, &g);
    let c0 = w
        .walker
        .stride(
            &q,
            &qd,
            StrideRequest::new(&w.settings).options(StrideOptions {
                record: false,
                contact: true,
                ..StrideOptions::default()
            }),
        )
        .unwrap();
    let clearance = c0.contact.mid_swing_clearance_m.unwrap();
    assert!(clearance < -1e-3, "{clearance}");
    w.walker = w.walker.clone().with_changes(|model, rules| {
        model.points[rules.heel_strike.swing_foot.0].p_link_m.y += -clearance - 5e-4;
        rules.heel_strike.ignore_scuffing = false;
        rules.heel_strike.min_ahead_m = 0.05;
    });
    let scuffs = |w: &sim::scene::Setup| matches!(common::stride(w, &q, &qd), Err(e) if e.kind == FailureKind::Scuffed);
    assert!(scuffs(&w), "the accurate integrator must see the graze");
    // Long fixed steps: the whole dip lies inside one step.
    w.settings.integrator = IntegratorChoice::Rk4 { h_s: 0.1 };
    assert!(scuffs(&w), "the interior check must catch the graze");
    w.settings.event_tolerance.grazing_samples = 0;
    assert!(
        !scuffs(&w),
        "without the interior check the graze is missed"
    );
}

#[test]
fn a_stiff_pelvic_spring_beyond_meijaards_limit_is_reported_not_integrated() {
    let (mut scene, _) = common::walker("wisse3d");
    scene
        .set("pelvis_yaw_stiffness_n_m_per_rad", 1.0e7)
        .unwrap();
    let mut w = scene.setup().unwrap();
    w.settings.integrator = IntegratorChoice::Meijaard {
        h_s: 1e-3,
        check_every: 1,
    };
    let e = common::stride(&w, &w.guess.q, &w.guess.qd).unwrap_err();
    assert_eq!(e.kind, FailureKind::StepTooLarge, "{e}");
    // For a very stiff spring the fastest mode is the pelvis's yaw against the rest of the
    // walker: λ² ≈ k (M̄⁻¹)_yaw,yaw, with the reduced mass matrix over the free coordinates.
    assert!(e.detail().contains("h_max"), "{}", e.detail());
    let lambda: f64 = e
        .detail()
        .split("λ_max = ")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let mut d = sim::engine::dynamics::Dynamics::new(w.walker.model());
    d.assemble(w.walker.model(), &w.guess.q, &w.guess.qd, None);
    let free: Vec<usize> = (0..w.walker.model().dof())
        .filter(|i| !w.walker.initially_locked().iter().any(|c| c.0 == *i))
        .collect();
    let m = d.mass_matrix.select_rows(&free).select_columns(&free);
    let yaw = free
        .iter()
        .position(|&i| i == w.walker.model().coord_index("pelvis_yaw").unwrap().0)
        .unwrap();
    let expected = (1.0e7 * m.try_inverse().unwrap()[(yaw, yaw)]).sqrt();
    assert!(
        (lambda / expected - 1.0).abs() < 0.05,
        "λ_max {lambda} vs {expected}"
    );
    assert!(lambda > 2.0 / 1e-3, "the step must really exceed the limit");
    // A step inside the limit passes the check.
    w.settings.integrator = IntegratorChoice::Meijaard {
        h_s: 1e-4,
        check_every: 1,
    };
    let r = common::stride(&w, &w.guess.q, &w.guess.qd);
    assert!(
        !matches!(r, Err(ref e) if e.kind == FailureKind::StepTooLarge),
        "{r:?}"
    );
}

#[test]
fn just_past_the_period_doubling_slope_the_walker_settles_into_two_alternating_steps() {
    let (mut scene, _) = common::walker("simplest");
    let (pts, _) = sim::analysis::continuation::sweep(
        &scene,
        "slope",
        0.009,
        0.0155,
        14,
        &NewtonSettings::default(),
    )
    .unwrap();
    let last = pts.last().unwrap();
    let g = last.gait.as_ref().unwrap();
    assert!(!g.stable());
    scene.set("slope", last.value).unwrap();
    let w = scene.setup().unwrap();
    let mut v = g.fixed_point.clone();
    v[0] += 1e-4;
    let (q, qd) = w.walker.unpack(&v);
    let walk = common::walk(&w, &q, &qd, 400, false);
    assert!(walk.failure.is_none(), "{:?}", walk.failure);
    let d: Vec<f64> = walk
        .steps
        .iter()
        .rev()
        .take(4)
        .map(|s| s.duration_s)
        .collect();
    // Period two: alternate steps differ, every other step repeats.
    assert!((d[0] - d[1]).abs() > 1e-3, "{d:?}");
    assert!(
        (d[0] - d[2]).abs() < 1e-8 && (d[1] - d[3]).abs() < 1e-8,
        "{d:?}"
    );
}

#[test]
fn near_zero_slope_gaits_follow_garcias_cube_root_scaling() {
    // Garcia et al. (1998): for small slopes the stance angle at heel strike scales as γ^(1/3).
    let (scene, _) = common::walker("simplest");
    let (pts, _) = sim::analysis::continuation::sweep(
        &scene,
        "slope",
        0.009,
        0.0001,
        30,
        &NewtonSettings::default(),
    )
    .unwrap();
    assert!(
        pts.iter().all(|p| p.gait.is_ok()),
        "a gait was lost on the way down"
    );
    let theta =
        |p: &sim::analysis::continuation::SweepPoint| p.gait.as_ref().unwrap().fixed_point[0];
    let (a, b) = (&pts[pts.len() - 1], &pts[pts.len() - 8]);
    let exponent = (theta(b) / theta(a)).ln() / (b.value / a.value).ln();
    assert!((exponent - 1.0 / 3.0).abs() < 0.01, "exponent {exponent}");
}

#[test]
fn ten_thousand_strides_from_the_fixed_point_do_not_drift() {
    let (_, w) = common::walker("compass");
    let g = common::gait(&w);
    let (q, qd) = common::start_state(&w, &g);
    let walk = common::walk(&w, &q, &qd, 10_000, false);
    assert!(walk.failure.is_none());
    let worst = walk
        .steps
        .iter()
        .map(|s| s.state_deviation)
        .fold(0.0, f64::max);
    assert!(
        worst < 1e-9,
        "largest deviation from the fixed point {worst}"
    );
    let first = walk.steps[0].duration_s;
    assert!(walk
        .steps
        .iter()
        .all(|s| (s.duration_s - first).abs() < 1e-9));
}

#[test]
fn a_non_finite_velocity_is_a_typed_failure() {
    let (_, w) = common::walker("wisse3d");
    let mut qd = w.guess.qd.clone();
    qd[2] = f64::INFINITY;
    let e = common::stride(&w, &w.guess.q, &qd).unwrap_err();
    assert_eq!(e.kind, FailureKind::NonFiniteState);
}

#[test]
fn equations_of_motion_that_overflow_are_a_typed_failure() {
    // A finite start state (it passes the entry check) but gravity beyond f64's range: the
    // first evaluation of the equations of motion overflows inside the integration, and the
    // dynamics error becomes the same typed outcome, not a NaN state.
    let (_, mut w) = common::walker("compass");
    let g = common::gait(&w);
    let (q, qd) = common::start_state(&w, &g);
    w.walker = w
        .walker
        .clone()
        .with_changes(|model, _| model.gravity_floor_m_s2 *= 1e308);
    let e = common::stride(&w, &q, &qd).unwrap_err();
    assert_eq!(e.kind, FailureKind::NonFiniteState, "{e}");
    assert!(!e.detail().contains("initial state"), "{e}");
}

#[test]
fn near_the_boundary_between_knee_lock_first_and_heel_strike_first_outcomes_stay_typed() {
    // Bisect a start perturbation of the kneed walker between a stride whose knee locks before
    // heel strike and one whose heel strikes first, down to 1e-12 rad: every stride on the way
    // ends in one of the two typed outcomes, never anything else. (At this boundary the two
    // events do not coincide: the heel strike jumps earlier, the swing foot touching down
    // while the knee is still bent, so the boundary is a discontinuity of the stride map.)
    let (_, w) = common::walker("kneed2d");
    let g = common::gait(&w);
    let i = w
        .walker
        .map_names()
        .iter()
        .position(|n| n == "stance_leg")
        .unwrap();
    let outcome = |d: f64| {
        let mut v = g.fixed_point.clone();
        v[i] += d;
        let (q, qd) = w.walker.unpack(&v);
        common::stride(&w, &q, &qd)
    };
    let (mut ok, mut bad) = (0.0, -0.5);
    for _ in 0..40 {
        let mid = 0.5 * (ok + bad);
        match outcome(mid) {
            Ok(r) => {
                assert_eq!(r.events[0].name, "knee_lock:swing_knee");
                assert!(r
                    .q_next
                    .iter()
                    .chain(r.qd_next.iter())
                    .all(|v| v.is_finite()));
                ok = mid;
            }
            Err(e) if e.kind == FailureKind::HeelStrikeBeforeKneeLock => bad = mid,
            Err(e) => panic!("unexpected outcome at {mid}: {e}"),
        }
    }
    assert!((ok - bad).abs() < 1e-12);
    let (t_ok, t_bad) = (
        outcome(ok).unwrap().duration_s,
        outcome(bad).unwrap_err().t_stride_s,
    );
    assert!(
        t_bad < t_ok,
        "heel strike jumps earlier across the boundary: {t_bad} vs {t_ok}"
    );
}

#[test]
fn the_3d_walkers_stride_map_is_smooth_across_its_drives_end() {
    // The ideal drive's extension ends with a jump in its jerk. Adaptive steps straddling it
    // made the stride map rough: central differences at 1e-6 and 1e-5 gave pelvic-mode
    // eigenvalues 4e-6 apart (and up to 3e-4 at 1e-13). With the end a breakpoint of the
    // integration both perturbations give the same spectrum. The tuned walker's drive ends
    // inside the stride (string at 0.53 s, 0.2 s extension, heel strike at 0.79 s); the Table I
    // walker's heel strike releases the string before its 0.27 s extension ends.
    let (_, w) = common::walker("wisse3d-tuned");
    let g = common::gait(&w);
    let s = common::stride_map(&w, &g.fixed_point).unwrap().0;
    let moduli = |d: f64| {
        let j = GaitSearch::new(
            &w.walker,
            &w.settings,
            &NewtonSettings {
                perturbation: d,
                ..Default::default()
            },
        )
        .stride_jacobian(&g.fixed_point, &s)
        .unwrap();
        let mut m: Vec<f64> = j.complex_eigenvalues().iter().map(|z| z.norm()).collect();
        m.sort_by(|a, b| b.total_cmp(a));
        m
    };
    let (a, b) = (moduli(1e-6), moduli(1e-5));
    for (x, y) in a.iter().zip(&b).filter(|(x, _)| **x > 0.05) {
        assert!((x - y).abs() < 1e-7, "{x} vs {y}");
    }
}

#[test]
fn event_location_error_is_far_below_the_integration_error() {
    // The heel strike of one stride, located on each integrator's own numerical solution with
    // the default event tolerance and with a tolerance at the limit of f64: their difference
    // is the event location's error. It must be far below the heel-strike time's integration
    // error (against DOPRI5 at 1e-13), or the study's heel-strike column would measure the
    // locator, not the integrator.
    let (_, w) = common::walker("compass");
    let g = common::gait(&w);
    let (q, qd) = common::start_state(&w, &g);
    let mut reference = w.clone();
    reference.settings.integrator = IntegratorChoice::Dopri5 {
        rtol: 1e-13,
        atol: 1e-13,
        h_max_s: 0.01,
    };
    let t_ref = common::stride(&reference, &q, &qd).unwrap().duration_s;
    let period = g.stride.duration_s;
    for integrator in [
        IntegratorChoice::Rk4 { h_s: period / 50.0 },
        IntegratorChoice::Rk4 {
            h_s: period / 200.0,
        },
        IntegratorChoice::Dopri5 {
            rtol: 1e-8,
            atol: 1e-8,
            h_max_s: period / 10.0,
        },
        IntegratorChoice::Dop853 {
            rtol: 1e-8,
            atol: 1e-8,
            h_max_s: period / 10.0,
        },
    ] {
        let mut a = w.clone();
        a.settings.integrator = integrator.clone();
        let t_default = common::stride(&a, &q, &qd).unwrap().duration_s;
        a.settings.event_tolerance.time_s = 1e-16;
        a.settings.event_tolerance.witness = 0.0;
        a.settings.event_tolerance.max_iterations = 200;
        let t_tight = common::stride(&a, &q, &qd).unwrap().duration_s;
        let location = (t_default - t_tight).abs();
        let integration = (t_tight - t_ref).abs();
        assert!(
            location < 1e-3 * integration && location < 1e-12,
            "{}: location {location:e}, integration {integration:e}",
            integrator.label()
        );
    }
}
