//! Criterion benchmark of a short pseudo-arclength sweep: the simplest walker's long-period
//! gait from slope 0.009 to 0.016 on 8 grid values, through its period doubling (located to
//! 1e-9 in arclength), period-1 branch only. Results in docs/bifurcations.md ("Cost").
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use sim::analysis::continuation::{continuation, ContinuationSettings};
use sim::analysis::limit_cycle::NewtonSettings;
use sim::scene::Scene;
use std::time::Duration;

fn benches(c: &mut Criterion) {
    let scene = Scene::load("simplest").unwrap();
    let settings = ContinuationSettings::builder()
        .newton(NewtonSettings::default())
        .max_period(1)
        .build()
        .unwrap();
    let mut group = c.benchmark_group("continuation");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(5));
    group.bench_function("simplest/slope_0.009_0.016_8_points", |b| {
        b.iter(|| {
            let r = continuation(&scene, "slope", (0.009, 0.016, 8), &settings, &|_| {}).unwrap();
            black_box(r.branches.len())
        })
    });
    group.finish();
}

criterion_group!(continuation_benches, benches);
criterion_main!(continuation_benches);
