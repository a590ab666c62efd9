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
fn engine_gait() -> (
    sim::scene::Setup,
    sim::analysis::limit_cycle::Gait,
    [f64; 4],
    usize,
    usize,
) {
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

/// Energy is conserved in the swing phase of the model (to 1e-9 relative), as computed from
/// its point masses' positions and velocities, apart from the equations of motion.
#[test]
fn the_compass_model_conserves_energy_in_swing() {
    let p = Params::goswami();
    let y0 = compass_model::fixed_point(&p, [0.27, -0.54, -1.09, 0.7]).unwrap();
    let (_, t, _) = compass_model::stride(&p, y0).unwrap();
    let e0 = compass_model::energy(&p, &y0);
    // Integrate the same equations in small RK4 steps over the stride, by hand.
    let mut y = y0;
    let n = 4000;
    let h = t / n as f64;
    let mut worst: f64 = 0.0;
    for _ in 0..n {
        let f = |y: &[f64; 4]| compass_model::rhs(&p, y);
        let add = |a: &[f64; 4], k: &[f64; 4], s: f64| {
            let mut o = *a;
            for i in 0..4 {
                o[i] += s * k[i];
            }
            o
        };
        let k1 = f(&y);
        let k2 = f(&add(&y, &k1, h / 2.0));
        let k3 = f(&add(&y, &k2, h / 2.0));
        let k4 = f(&add(&y, &k3, h));
        for i in 0..4 {
            y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        worst = worst.max((compass_model::energy(&p, &y) - e0).abs() / e0.abs());
    }
    eprintln!("energy {e0} J, largest relative drift over the stride {worst:e}");
    assert!(worst < 1e-9);
}

/// Across the model's impact: the walker's angular momentum about the new contact and the
/// trailing leg's about the hip are conserved (the model's own law, checked from the points
/// before and after); the rates after it satisfy Goswami et al.'s closed-form impact law
/// Q⁺(α) q̇⁺ = Q⁻(α) q̇⁻ (q = (θ_ns, θ_s), 2α the angle between the legs, a the foot-to-mass
/// and b the mass-to-hip distance; written from the paper, apart from the model's); kinetic
/// energy is lost, and the old stance foot lifts.
#[test]
fn the_compass_model_impact_conserves_angular_momentum() {
    let p = Params::goswami();
    let y0 = compass_model::fixed_point(&p, [0.27, -0.54, -1.09, 0.7]).unwrap();
    let (m, mh, l, b) = (p.leg_mass, p.hip_mass, p.leg_length, p.com_from_hip);
    let a = l - b;
    for h in [-0.05, -0.01, 0.0, 0.005] {
        let (pre, _) = compass_model::swing_onto_step(&p, y0, h).unwrap();
        let post = compass_model::impact(&p, &pre).unwrap();
        let pts_pre = compass_model::points(&p, &pre);
        let pts_post = compass_model::points(&p, &post);
        // (i) about the new contact: the old swing foot before, the origin after.
        let (h_pre, trailing_pre) = compass_model::angular_momenta(&p, &pre, pts_pre[3].r);
        let (h_post, _) = compass_model::angular_momenta(&p, &post, [0.0, 0.0]);
        // (ii) the trailing leg's mass about the hip: the old stance leg's before, the new
        // swing leg's after.
        let rel = |i: usize, pts: &[compass_model::Point; 4]| {
            [pts[i].r[0] - pts[1].r[0], pts[i].r[1] - pts[1].r[1]]
        };
        let cross = |r: [f64; 2], v: [f64; 2]| r[0] * v[1] - r[1] * v[0];
        let trailing_post = m * cross(rel(2, &pts_post), pts_post[2].v);
        assert!((trailing_pre - m * cross(rel(0, &pts_pre), pts_pre[0].v)).abs() < 1e-12);
        // Goswami's law, our absolute rates (the law is linear in them; its angles enter only
        // through cos 2α).
        let c = pre[1].cos();
        let (ws_m, wns_m) = (pre[2], pre[2] + pre[3]);
        let (ws_p, wns_p) = (post[2], post[2] + post[3]);
        let q_minus = [
            -m * a * b * wns_m + (-m * a * b + (mh * l * l + 2.0 * m * a * l) * c) * ws_m,
            -m * a * b * ws_m,
        ];
        let q_plus = [
            m * b * (b - l * c) * wns_p + (m * l * (l - b * c) + m * a * a + mh * l * l) * ws_p,
            m * b * b * wns_p - m * b * l * c * ws_p,
        ];
        let ke = |y: &[f64; 4]| {
            let pts = compass_model::points(&p, y);
            [m, mh, m]
                .iter()
                .zip(pts.iter())
                .map(|(mi, q)| 0.5 * mi * (q.v[0] * q.v[0] + q.v[1] * q.v[1]))
                .sum::<f64>()
        };
        eprintln!(
            "h {h:+}: H about contact {h_pre} -> {h_post}, trailing {trailing_pre} -> {trailing_post}, \
             Goswami Q+q+ {q_plus:?} against Q-q- {q_minus:?}, KE {} -> {}, foot lift {} m/s",
            ke(&pre),
            ke(&post),
            pts_post[3].v[1]
        );
        assert!((h_pre - h_post).abs() < 1e-12 * h_pre.abs());
        assert!((trailing_pre - trailing_post).abs() < 1e-12 * trailing_pre.abs().max(1.0));
        for i in 0..2 {
            assert!((q_plus[i] - q_minus[i]).abs() < 1e-12 * q_minus[i].abs().max(1.0));
        }
        assert!(ke(&post) < ke(&pre));
        assert!(pts_post[3].v[1] > 0.0);
        // the configuration is kept: each point where it was, the legs swapped
        assert!((pts_post[1].r[0] - (pts_pre[1].r[0] - pts_pre[3].r[0])).abs() < 1e-15);
    }
}
