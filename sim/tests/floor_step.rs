//! A floor step at a heel strike (issue 26): the swing foot lands on a floor `h` above (or
//! below) the stance foot's. Checked against the hand-written model of Garcia's simplest
//! walker (`garcia::stride_onto_step`, which shares no code with the engine): the state after
//! the step and the stride time, for steps down and up from the gait.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;
mod garcia;

use nalgebra::DVector;
use sim::scene::Scene;
use sim::stride::{EvaluationPath, StrideOptions, StrideRequest, StrideSettings};

#[test]
fn the_simplest_walker_onto_a_step_matches_the_hand_written_model() {
    for gamma in [0.004, 0.009] {
        let mut scene = Scene::load("simplest").unwrap();
        scene.set("slope_rad", gamma).unwrap();
        let w = scene.setup().unwrap();
        let g = common::gait(&w);
        let (q, qd) = w.walker.unpack(&g.fixed_point);
        let names: Vec<&str> = w
            .walker
            .model()
            .coordinates
            .iter()
            .map(|c| c.name.as_str())
            .collect();
        let at = |n: &str| names.iter().position(|c| *c == n).unwrap();
        let (stance, swing) = (at("stance_leg"), at("swing_leg"));
        // Garcia's variables: θ = stance_leg, φ = −swing_leg.
        let y0 = [q[stance], -q[swing], qd[stance], -qd[swing]];
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
            let (y1, t1) = garcia::stride_onto_step(gamma, y0, h).expect("the model walks");
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
