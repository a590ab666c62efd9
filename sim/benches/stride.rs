//! Criterion benchmarks: one stride and a whole gait computation (fixed point and
//! eigenvalues) for each scene, with the scene's default integrator.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use sim::limit_cycle::NewtonSettings;
use sim::scene::{Scene, BUILTIN};
use sim::stride::StrideOptions;

fn benches(c: &mut Criterion) {
    for (name, _) in BUILTIN {
        let Ok(walker) = Scene::load(name).and_then(|s| s.build()) else {
            continue;
        };
        let v0 = walker.pack(&walker.guess_q, &walker.guess_qd);
        let Ok(gait) = walker.find_gait(&v0, &NewtonSettings::default()) else {
            continue;
        };
        let (q, qd) = walker.unpack(&gait.fixed_point);
        c.bench_function(&format!("stride/{name}"), |b| {
            b.iter(|| walker.stride(black_box(&q), black_box(&qd), StrideOptions::default()))
        });
        let mut group = c.benchmark_group("gait");
        group.sample_size(10);
        group.bench_function(*name, |b| {
            b.iter(|| walker.find_gait(black_box(&v0), &NewtonSettings::default()))
        });
        group.finish();
    }
}

criterion_group!(stride, benches);
criterion_main!(stride);
