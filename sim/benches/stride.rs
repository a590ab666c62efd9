//! Criterion benchmarks: one stride per scene and integrator, and a whole gait computation
//! (fixed point and eigenvalues) per scene with its default integrator. Results and the machine
//! are in docs/performance.md.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use sim::integrators::IntegratorChoice;
use sim::limit_cycle::NewtonSettings;
use sim::scene::Scene;
use sim::stride::StrideOptions;

const SCENES: [&str; 5] = ["simplest", "compass", "kneed2d", "wisse2d", "wisse3d"];

fn benches(c: &mut Criterion) {
    for name in SCENES {
        let Ok(walker) = Scene::load(name).and_then(|s| s.build()) else {
            continue;
        };
        let v0 = walker.pack(&walker.guess_q, &walker.guess_qd);
        let Ok(gait) = walker.find_gait(&v0, &NewtonSettings::default()) else {
            continue;
        };
        let (q, qd) = walker.unpack(&gait.fixed_point);
        let period = gait.stride.duration_s;
        let mut group = c.benchmark_group(format!("stride/{name}"));
        for (label, integrator) in [
            ("default", walker.integrator.clone()),
            (
                "meijaard_h_T/400",
                IntegratorChoice::Meijaard {
                    h_s: period / 400.0,
                    check_every: 0,
                },
            ),
            (
                "rk4_h_T/100",
                IntegratorChoice::Rk4 {
                    h_s: period / 100.0,
                },
            ),
            (
                "dopri5_1e-10",
                IntegratorChoice::Dopri5 {
                    rtol: 1e-10,
                    atol: 1e-10,
                    h_max_s: period / 10.0,
                },
            ),
            (
                "dop853_1e-8",
                IntegratorChoice::Dop853 {
                    rtol: 1e-8,
                    atol: 1e-8,
                    h_max_s: period / 10.0,
                },
            ),
        ] {
            let mut w = walker.clone();
            w.integrator = integrator;
            group.bench_function(label, |b| {
                b.iter(|| w.stride(black_box(&q), black_box(&qd), StrideOptions::default()))
            });
        }
        group.finish();
        let mut group = c.benchmark_group("gait");
        group.sample_size(10);
        group.bench_function(name, |b| {
            b.iter(|| walker.find_gait(black_box(&v0), &NewtonSettings::default()))
        });
        group.finish();
    }
}

criterion_group!(stride, benches);
criterion_main!(stride);
