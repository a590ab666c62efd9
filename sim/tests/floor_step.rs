//! A floor step at a heel strike (issue 26): the swing foot lands on a floor `h` above (or
//! below) the stance foot's. Checked against the hand-written model of Garcia's simplest
//! walker (`garcia::stride_onto_step`, which shares no code with the engine): the state after
//! the step and the stride time, for steps down and up from the gait.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;
mod garcia;
mod robustness_reference;

use nalgebra::DVector;
use sim::scene::Scene;
use sim::stride::{EvaluationPath, StrideOptions, StrideRequest, StrideSettings};

/// The simplest walker's gait at slope `gamma`, with its stance and swing coordinates' indices
/// and its state in Garcia's variables (θ = stance_leg, φ = −swing_leg).
struct Simplest {
    w: sim::scene::Setup,
    g: sim::analysis::limit_cycle::Gait,
    stance: usize,
    swing: usize,
    y: [f64; 4],
}

fn simplest_gait(gamma: f64) -> Simplest {
    let mut scene = Scene::load("simplest").unwrap();
    scene.set("slope_rad", gamma).unwrap();
    let w = scene.setup().unwrap();
    let g = common::gait(&w);
    let (q, qd) = w.walker.unpack(&g.fixed_point);
    let at = |n: &str| {
        w.walker
            .model()
            .coordinates
            .iter()
            .position(|c| c.name == n)
            .unwrap()
    };
    let (stance, swing) = (at("stance_leg"), at("swing_leg"));
    let y = [q[stance], -q[swing], qd[stance], -qd[swing]];
    Simplest {
        w,
        g,
        stance,
        swing,
        y,
    }
}

#[test]
fn the_simplest_walker_onto_a_step_matches_the_hand_written_model() {
    for gamma in [0.004, 0.009] {
        let Simplest {
            w,
            g,
            stance,
            swing,
            y: y0,
        } = simplest_gait(gamma);
        let (q, qd) = w.walker.unpack(&g.fixed_point);
        // the fixed-size engine (the simplest walker takes it) and the general one
        let general = StrideSettings {
            evaluation: EvaluationPath::General,
            ..w.settings.clone()
        };
        assert!(w
            .walker
            .takes_fixed_size_stride(&w.settings, StrideOptions::default()));
        for (h, settings) in [-0.01, -0.003, 0.0, 0.001, 0.003]
            .into_iter()
            .flat_map(|h| [(h, &w.settings), (h, &general)])
        {
            let r = w
                .walker
                .stride(&q, &qd, StrideRequest::new(settings).floor_step(h))
                .unwrap_or_else(|f| panic!("γ {gamma}, h {h}: {f}"));
            let (y1, t1, _) = garcia::stride_onto_step(gamma, y0, h).expect("the model walks");
            let engine = DVector::from_vec(vec![
                r.q_next[stance],
                -r.q_next[swing],
                r.qd_next[stance],
                -r.qd_next[swing],
            ]);
            let model = DVector::from_vec(y1.to_vec());
            let error = (&engine - &model).amax();
            let dt = (r.duration_s - t1).abs();
            eprintln!("γ {gamma} h {h:+}: state error {error:e}, stride time error {dt:e}");
            // measured: 1.3e-12 and 6.2e-12 at most
            assert!(error < 1e-11, "γ {gamma} h {h}: {engine} against {model}");
            assert!(dt < 6e-11, "γ {gamma} h {h}: {} against {t1}", r.duration_s);
            // the step: the new stance foot stands h above the old one, along the normal
            assert!(
                (r.step_m.y - h).abs() < 1e-9,
                "γ {gamma} h {h}: step {:?}",
                r.step_m
            );
        }
    }
}

/// The gait sensitivity norm of the model (Hobbelen & Wisse's definition, written apart from
/// the engine's in tests/robustness_reference, by central differences of the model's stride
/// map over its four state entries and the floor step): (step time, step length, both).
fn model_gsn(gamma: f64, y: [f64; 4]) -> (f64, f64, f64) {
    let mut stride = garcia::engine_stride(gamma);
    let x = garcia::to_engine(&y);
    robustness_reference::gait_sensitivity_norm(&mut stride, &x, 1e-6)
}

#[test]
fn the_gait_sensitivity_norm_of_the_simplest_walker_matches_the_hand_written_model() {
    for gamma in [0.004, 0.009] {
        let Simplest { w, g, y, .. } = simplest_gait(gamma);
        let gsn = sim::analysis::gait_sensitivity::gait_sensitivity_norm(
            &w.walker,
            &w.settings,
            &g,
            1e-6,
        )
        .unwrap();
        let (t, l, both) = model_gsn(gamma, y);
        eprintln!(
            "γ {gamma}: GSN step time {} (model {t}), step length {} (model {l}), both {} (model {both}), {} strides",
            gsn.step_time, gsn.step_length, gsn.both, gsn.strides_summed
        );
        for (ours, theirs) in [(gsn.step_time, t), (gsn.step_length, l), (gsn.both, both)] {
            assert!(
                (ours - theirs).abs() <= 1e-5 * theirs,
                "γ {gamma}: {ours} against {theirs}"
            );
        }
    }
}
