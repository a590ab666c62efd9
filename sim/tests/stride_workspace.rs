//! A reused `StrideWorkspace` gives, stride for stride, the same results to the bit as a fresh
//! stride (`Walker::stride`, which makes a workspace of its own): over chains of strides on
//! every planar and 3D scene, with the settings changing between strides (the evaluation path,
//! the integrator), after strides that failed, and off the gait on a steep slope.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use nalgebra::DVector;
use sim::engine::integrators::IntegratorChoice;
use sim::stride::{
    EvaluationPath, StrideFailure, StrideRequest, StrideResult, StrideSettings, StrideWorkspace,
};

/// The bits of everything a stride returns that a later stride or a report reads.
fn fingerprint(r: &Result<StrideResult, StrideFailure>) -> Vec<u64> {
    let mut v = Vec::new();
    match r {
        Ok(r) => {
            v.push(0);
            v.extend(r.q_next.iter().chain(r.qd_next.iter()).map(|x| x.to_bits()));
            v.extend(r.step_m.iter().map(|x| x.to_bits()));
            for x in [
                r.duration_s,
                r.heading_change_rad,
                r.lift_velocity_m_s,
                r.impact_energy_loss_j,
                r.actuator_work_j,
                r.damping_dissipation_j,
            ] {
                v.push(x.to_bits());
            }
            v.push(r.evaluations as u64);
            for e in &r.events {
                v.extend(e.name.bytes().map(u64::from));
                v.push(e.t_stride_s.to_bits());
            }
            for s in &r.trajectory {
                v.push(s.t_s.to_bits());
                v.extend(s.q.iter().chain(s.qd.iter()).map(|x| x.to_bits()));
            }
        }
        Err(e) => {
            v.push(1);
            v.push(e.t_stride_s.to_bits());
            v.extend(
                format!("{:?} {}", e.kind, e.detail())
                    .bytes()
                    .map(u64::from),
            );
        }
    }
    v
}

/// Settings that differ from the scene's in the evaluation path or the integrator, taken in
/// turn so that the workspace must rebuild (or keep) what it compiled between strides.
fn settings_in_turn(base: &StrideSettings) -> Vec<StrideSettings> {
    let general = StrideSettings {
        evaluation: EvaluationPath::General,
        ..base.clone()
    };
    let general_loop = StrideSettings {
        evaluation: EvaluationPath::GeneralLoop,
        ..base.clone()
    };
    let dopri5 = StrideSettings {
        integrator: IntegratorChoice::Dopri5 {
            rtol: 1e-9,
            atol: 1e-11,
            h_max_s: 0.05,
        },
        ..base.clone()
    };
    vec![
        base.clone(),
        general,
        base.clone(),
        general_loop,
        dopri5,
        base.clone(),
    ]
}

/// Chains `strides` strides from the scene's guess, each run both fresh and on one reused
/// workspace (recording the trajectory every other stride), and compares them.
fn reused_equals_fresh(scene: &str, strides: usize) {
    let (_, w) = common::walker(scene);
    let turns = settings_in_turn(&w.settings);
    let mut ws = StrideWorkspace::new(&w.walker);
    let (mut q, mut qd) = (w.guess.q.clone(), w.guess.qd.clone());
    let mut completed = 0;
    for k in 0..strides {
        let settings = &turns[k % turns.len()];
        let request = || {
            let r = StrideRequest::new(settings);
            if k % 2 == 1 {
                r.recording()
            } else {
                r
            }
        };
        let fresh = w.walker.stride(&q, &qd, request());
        let reused = ws.stride(&q, &qd, request());
        assert_eq!(
            fingerprint(&fresh),
            fingerprint(&reused),
            "{scene}: stride {k} on a reused workspace differs from a fresh one"
        );
        match fresh {
            Ok(r) => {
                completed += 1;
                (q, qd) = (r.q_next, r.qd_next);
            }
            Err(_) => (q, qd) = (w.guess.q.clone(), w.guess.qd.clone()),
        }
    }
    // The chain walks: most strides complete (the guess is near the gait), so the comparison
    // covers completed strides, not only failures.
    assert!(
        2 * completed >= strides,
        "{scene}: only {completed} of {strides} strides completed"
    );
}

#[test]
fn a_reused_workspace_gives_the_fresh_strides_of_every_scene() {
    for (scene, strides) in [
        ("simplest", 12),
        ("compass", 12),
        ("kneed2d", 12),
        ("wisse2d", 8),
        ("wisse3d", 6),
    ] {
        reused_equals_fresh(scene, strides);
    }
}

#[test]
fn a_failed_stride_leaves_nothing_behind_in_the_workspace() {
    for scene in ["compass", "kneed2d", "wisse3d"] {
        let (_, w) = common::walker(scene);
        let (q, qd) = (w.guess.q.clone(), w.guess.qd.clone());
        let mut ws = StrideWorkspace::new(&w.walker);
        let first = ws.stride(&q, &qd, StrideRequest::new(&w.settings));
        // A start state that is not finite, then one thrown far off the gait: both fail.
        let mut bad = qd.clone();
        bad[0] = f64::NAN;
        let failed = ws.stride(&q, &bad, StrideRequest::new(&w.settings));
        assert!(failed.is_err(), "{scene}: a NaN start state must fail");
        let thrown = DVector::from_element(qd.len(), 40.0);
        let wild = ws.stride(&q, &thrown, StrideRequest::new(&w.settings));
        assert_eq!(
            fingerprint(&wild),
            fingerprint(
                &w.walker
                    .stride(&q, &thrown, StrideRequest::new(&w.settings))
            ),
            "{scene}: a stride thrown off the gait differs on the reused workspace"
        );
        let again = ws.stride(&q, &qd, StrideRequest::new(&w.settings));
        assert_eq!(
            fingerprint(&first),
            fingerprint(&again),
            "{scene}: the stride after failures differs from the same stride before them"
        );
    }
}

#[test]
fn strides_off_the_gait_on_a_steep_slope_equal_fresh_ones() {
    // The compass's guess on a steep slope, and faster and faster after each failure: strides
    // that fall or meet what the fixed-size engine does not cover (which it hands back to the
    // reference engine); whatever happens, reused and fresh agree.
    let (mut scene, _) = common::walker("compass");
    scene
        .set("slope_rad", 0.2)
        .expect("a steep slope is in range");
    let w = scene.setup().expect("steep compass builds");
    let mut ws = StrideWorkspace::new(&w.walker);
    let (mut q, mut qd) = (w.guess.q.clone(), w.guess.qd.clone());
    for k in 0..8 {
        let fresh = w.walker.stride(&q, &qd, StrideRequest::new(&w.settings));
        let reused = ws.stride(&q, &qd, StrideRequest::new(&w.settings));
        assert_eq!(fingerprint(&fresh), fingerprint(&reused), "stride {k}");
        match fresh {
            Ok(r) => (q, qd) = (r.q_next, r.qd_next),
            Err(_) => {
                qd *= 1.3;
            }
        }
    }
}
