//! The stride Jacobian of a scene under study: a replay of the nominal stride's steps, the
//! smoothness of each column (central differences at two perturbations, with free and replayed
//! steps), and the eigenvalue moduli by central differences and Richardson extrapolation over
//! perturbation sizes and tolerances
//! (`cargo run --release -p sim --example jacobian_study -- wisse3d`).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use nalgebra::DMatrix;
use sim::analysis::limit_cycle::{GaitSearch, NewtonSettings};
use sim::engine::integrators::IntegratorChoice;
use sim::engine::walker::Walker;
use sim::stride::{Schedule, StepSchedule, StrideRequest, StrideSettings};

fn moduli(j: &DMatrix<f64>) -> Vec<f64> {
    let mut m: Vec<f64> = j
        .clone()
        .complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .collect();
    m.sort_by(|a, b| b.total_cmp(a));
    m.truncate(8);
    m
}

fn main() {
    let name = std::env::args().nth(1).unwrap_or_else(|| "wisse3d".into());
    let scene = sim::scene::Scene::load(&name).expect("scene");
    let setup = scene.setup().expect("build");
    let g = setup.find_gait(&NewtonSettings::default()).expect("gait");
    let w = &setup.walker;
    replay_check(w, &setup.settings, &g.fixed_point);
    smoothness(w, &setup.settings, &g.fixed_point);
    for tol in [1e-12, 1e-13] {
        let settings = setup.settings.with_integrator(IntegratorChoice::Dop853 {
            rtol: tol,
            atol: tol,
            h_max_s: 0.01,
        });
        let newton = NewtonSettings::default();
        let s = GaitSearch::new(w, &settings, &newton)
            .stride_map(&g.fixed_point)
            .unwrap()
            .0;
        for d in [1e-6, 1e-5, 1e-4, 4e-4] {
            let c = |d: f64| {
                let newton = NewtonSettings {
                    perturbation: d,
                    ..Default::default()
                };
                GaitSearch::new(w, &settings, &newton)
                    .stride_jacobian(&g.fixed_point, &s)
                    .unwrap()
            };
            let (j1, j2) = (c(d), c(d / 2.0));
            let rich = (&j2 * 4.0 - &j1) / 3.0;
            let f = |v: Vec<f64>| {
                v.iter()
                    .map(|x| format!("{x:.8}"))
                    .collect::<Vec<_>>()
                    .join(" ")
            };
            println!("tol {tol:e} d {d:e} central   {}", f(moduli(&j1)));
            println!("tol {tol:e} d {d:e} richards. {}", f(moduli(&rich)));
        }
    }
}

fn replay_check(w: &Walker, settings: &StrideSettings, v: &nalgebra::DVector<f64>) {
    let mut sch = StepSchedule::default();
    let (q, qd) = w.unpack(v);
    let request = StrideRequest::new(settings).schedule(Schedule::Record(&mut sch));
    let a = w.stride(&q, &qd, request).unwrap();
    let request = StrideRequest::new(settings).schedule(Schedule::Replay(&sch));
    let b = w.stride(&q, &qd, request).unwrap();
    println!(
        "replay of the nominal: |Δq| = {:e}, phases {:?}, events a {:?} b {:?}",
        (&a.q_next - &b.q_next).amax(),
        sch.phases.iter().map(|p| p.len()).collect::<Vec<_>>(),
        a.events
            .iter()
            .map(|e| (e.name.clone(), e.t_stride_s))
            .collect::<Vec<_>>(),
        b.events
            .iter()
            .map(|e| (e.name.clone(), e.t_stride_s))
            .collect::<Vec<_>>()
    );
}

fn smoothness(w: &Walker, settings: &StrideSettings, v: &nalgebra::DVector<f64>) {
    let mut sch = StepSchedule::default();
    let (q, qd) = w.unpack(v);
    let request = StrideRequest::new(settings).schedule(Schedule::Record(&mut sch));
    w.stride(&q, &qd, request).unwrap();
    let f = |x: &nalgebra::DVector<f64>, replay: bool| {
        let (q, qd) = w.unpack(x);
        let request = if replay {
            StrideRequest::new(settings).schedule(Schedule::Replay(&sch))
        } else {
            StrideRequest::new(settings)
        };
        let r = w.stride(&q, &qd, request).unwrap();
        (
            w.pack(&r.q_next, &r.qd_next),
            r.events.iter().map(|e| e.t_stride_s).collect::<Vec<_>>(),
        )
    };
    let names = w.map_names();
    for k in 0..v.len() {
        let mut line = format!("{:>20}", names[k]);
        for replay in [false, true] {
            let col = |d: f64| {
                let mut a = v.clone();
                a[k] += d;
                let mut b = v.clone();
                b[k] -= d;
                (f(&a, replay).0 - f(&b, replay).0) / (2.0 * d)
            };
            let (c1, c2) = (col(1e-6), col(1e-5));
            line += &format!(
                "  {}: |J(1e-6)-J(1e-5)| = {:.2e}",
                if replay { "replay" } else { "free" },
                (&c1 - &c2).amax()
            );
        }
        println!("{line}");
    }
}
