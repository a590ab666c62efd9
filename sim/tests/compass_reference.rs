//! The hand-written compass gait (tests/compass_model, Goswami, Thuilot & Espiau 1998, sharing
//! no code with the engine) against the engine's `compass` scene at its defaults: the engine's
//! gait is a fixed point of the model's stride, the two gaits agree, and strides onto floor
//! steps agree in the state after heel strike, the stride time and the step length.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;
mod compass_model;

use compass_model::Params;
use sim::scene::Scene;
use sim::stride::StrideRequest;

/// The engine's compass gait in the stride-map order (stance_leg, swing_leg, their rates),
/// with the setup and the coordinates' indices.
fn engine_gait() -> (sim::scene::Setup, sim::analysis::limit_cycle::Gait, [f64; 4], usize, usize) {
    let scene = Scene::load("compass").unwrap();
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
    let y = [q[stance], q[swing], qd[stance], qd[swing]];
    (w, g, y, stance, swing)
}

fn amax(a: &[f64; 4], b: &[f64; 4]) -> f64 {
    (0..4).fold(0.0, |m, i| f64::max(m, (a[i] - b[i]).abs()))
}

#[test]
fn the_engines_compass_gait_is_a_fixed_point_of_the_hand_written_model() {
    let p = Params::goswami();
    let (_, g, y, _, _) = engine_gait();
    eprintln!("engine gait {y:?}, period {} s", g.stride.duration_s);
    let (y1, t1, l1) = compass_model::stride(&p, y).expect("the model walks");
    let residual = amax(&y1, &y);
    eprintln!(
        "model stride from it: residual {residual:e}, time {t1} (engine {}), step length {l1} (engine {})",
        g.stride.duration_s,
        g.stride.step_m.norm()
    );
    assert!(residual < 1e-9, "{y1:?} against {y:?}");
    assert!((t1 - g.stride.duration_s).abs() < 1e-9);
    assert!((l1 - g.stride.step_m.norm()).abs() < 1e-9);
    let ym = compass_model::fixed_point(&p, y).expect("model gait");
    let d = amax(&ym, &y);
    eprintln!("model gait {ym:?}: differs from the engine's by {d:e}");
    assert!(d < 1e-9, "{ym:?} against {y:?}");
}

#[test]
fn strides_onto_steps_agree_with_the_hand_written_model() {
    let p = Params::goswami();
    let (w, _, y, stance, swing) = engine_gait();
    let (q, qd) = {
        let (q, qd) = (
            nalgebra::DVector::from_element(w.walker.model().coordinates.len(), 0.0),
            nalgebra::DVector::from_element(w.walker.model().coordinates.len(), 0.0),
        );
        let (mut q, mut qd) = (q, qd);
        q[stance] = y[0];
        q[swing] = y[1];
        qd[stance] = y[2];
        qd[swing] = y[3];
        (q, qd)
    };
    for h in [-0.05, -0.01, 0.0, 0.005] {
        let r = w
            .walker
            .stride(&q, &qd, StrideRequest::new(&w.settings).floor_step(h))
            .unwrap_or_else(|f| panic!("h {h}: {f}"));
        let engine = [
            r.q_next[stance],
            r.q_next[swing],
            r.qd_next[stance],
            r.qd_next[swing],
        ];
        let (model, t, l) = compass_model::stride_onto_step(&p, y, h).expect("the model walks");
        let e = amax(&engine, &model);
        let dt = (t - r.duration_s).abs();
        let dl = (l - r.step_m.norm()).abs();
        eprintln!("h {h:+}: state error {e:e}, time error {dt:e}, step length error {dl:e}");
        assert!(e < 1e-9, "h {h}: {engine:?} against {model:?}");
        assert!(dt < 1e-9 && dl < 1e-9, "h {h}");
        assert!((r.step_m.y - h).abs() < 1e-9);
    }
}
