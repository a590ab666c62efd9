//! The stride Jacobian of a scene under study: a replay of the nominal stride's steps, the
//! smoothness of each column (central differences at two perturbations, with free and replayed
//! steps), and the eigenvalue moduli by central differences and Richardson extrapolation over
//! perturbation sizes and tolerances
//! (`cargo run --release -p sim --example jacobian_study -- wisse3d`).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use nalgebra::DMatrix;
use sim::integrators::IntegratorChoice;
use sim::limit_cycle::NewtonSettings;

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
    let mut w = scene.build().expect("build");
    let g = w
        .find_gait(&w.pack(&w.guess_q, &w.guess_qd), &NewtonSettings::default())
        .expect("gait");
    replay_check(&w, &g.fixed_point);
    smoothness(&w, &g.fixed_point);
    for tol in [1e-12, 1e-13] {
        w.integrator = IntegratorChoice::Dop853 {
            rtol: tol,
            atol: tol,
            h_max_s: 0.01,
        };
        let s = w.stride_map(&g.fixed_point).unwrap().0;
        for d in [1e-6, 1e-5, 1e-4, 4e-4] {
            let c = |d: f64| {
                w.stride_jacobian(
                    &g.fixed_point,
                    &s,
                    &NewtonSettings {
                        perturbation: d,
                        ..Default::default()
                    },
                )
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

fn replay_check(w: &sim::walker::Walker, v: &nalgebra::DVector<f64>) {
    use sim::stride::{Schedule, StepSchedule, StrideOptions};
    let mut sch = StepSchedule::default();
    let (q, qd) = w.unpack(v);
    let a = w
        .stride_scheduled(
            &q,
            &qd,
            StrideOptions::default(),
            Schedule::Record(&mut sch),
        )
        .unwrap();
    let b = w
        .stride_scheduled(&q, &qd, StrideOptions::default(), Schedule::Replay(&sch))
        .unwrap();
    println!(
        "replay of the nominal: |Δq| = {:e}, phases {:?}, events a {:?} b {:?}",
        (&a.q_next - &b.q_next).amax(),
        sch.phases.iter().map(|p| p.len()).collect::<Vec<_>>(),
        a.events
            .iter()
            .map(|e| (e.name.clone(), e.time_s))
            .collect::<Vec<_>>(),
        b.events
            .iter()
            .map(|e| (e.name.clone(), e.time_s))
            .collect::<Vec<_>>()
    );
}

fn smoothness(w: &sim::walker::Walker, v: &nalgebra::DVector<f64>) {
    use sim::stride::{Schedule, StepSchedule, StrideOptions};
    let mut sch = StepSchedule::default();
    let (q, qd) = w.unpack(v);
    w.stride_scheduled(
        &q,
        &qd,
        StrideOptions::default(),
        Schedule::Record(&mut sch),
    )
    .unwrap();
    let f = |x: &nalgebra::DVector<f64>, replay: bool| {
        let (q, qd) = w.unpack(x);
        let r = if replay {
            w.stride_scheduled(&q, &qd, StrideOptions::default(), Schedule::Replay(&sch))
        } else {
            w.stride(&q, &qd, StrideOptions::default())
        }
        .unwrap();
        (
            w.pack(&r.q_next, &r.qd_next),
            r.events.iter().map(|e| e.time_s).collect::<Vec<_>>(),
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
