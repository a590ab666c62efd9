//! Criterion benchmarks of one integrator step per kind on the compass gait and the 3D walker,
//! from the scene's gait guess in the stride's first phase: a fixed step of T/100 (Meijaard,
//! RK4) or the embedded pairs' own first step at their tolerance (DOPRI5, DOP853). The cost per
//! step against the error per step is in docs/accuracy.md; timings in docs/performance.md.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use sim::engine::integrators::{IntegratorChoice, Sample};
use sim::scene::Scene;
use sim::stride::Phase;

fn benches(c: &mut Criterion) {
    for name in ["compass", "wisse3d"] {
        let setup = Scene::load(name).and_then(|s| s.setup()).unwrap();
        let walker = &setup.walker;
        let mut phase = Phase::new(walker.model());
        for c in walker.initially_locked() {
            phase.active[c.0] = false;
        }
        let start = Sample {
            t_s: 0.0,
            q: setup.guess.q.clone(),
            qd: setup.guess.qd.clone(),
        };
        // A step of about a hundredth of a stride (both walkers take about 0.4-1 s a stride).
        let h_s = 0.005;
        let mut group = c.benchmark_group(format!("integrators/{name}"));
        for (label, choice) in [
            (
                "meijaard_step",
                IntegratorChoice::Meijaard {
                    h_s,
                    check_every: 0,
                },
            ),
            ("rk4_step", IntegratorChoice::Rk4 { h_s }),
            (
                "dopri5_1e-10_step",
                IntegratorChoice::Dopri5 {
                    rtol: 1e-10,
                    atol: 1e-10,
                    h_max_s: h_s,
                },
            ),
            (
                "dop853_1e-12_step",
                IntegratorChoice::Dop853 {
                    rtol: 1e-12,
                    atol: 1e-12,
                    h_max_s: h_s,
                },
            ),
        ] {
            let mut integrator = choice.build();
            group.bench_function(label, |b| {
                b.iter(|| {
                    integrator.reset();
                    integrator
                        .advance(&mut phase, black_box(&start), h_s)
                        .unwrap()
                })
            });
        }
        group.finish();
    }
}

criterion_group!(integrators, benches);
criterion_main!(integrators);
