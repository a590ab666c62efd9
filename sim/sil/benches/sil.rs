//! Criterion benchmark: five steps of the 3D walker with both ankle nodes' firmware and the
//! simulated CAN bus in the loop (`walker sil`'s default integrator). Walking time per wall time
//! is the real-time factor in docs/sil.md.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use criterion::{criterion_group, criterion_main, Criterion};
use sil::config::SilConfig;
use sil::FirmwareInTheLoop;
use sim::scene::Scene;

fn bench(c: &mut Criterion) {
    let scene = Scene::load("wisse3d").unwrap();
    let mut walker = scene.build().unwrap();
    let gait = walker
        .find_gait(
            &walker.pack(&walker.guess_q, &walker.guess_qd),
            &Default::default(),
        )
        .unwrap();
    let (q, qd) = walker.unpack(&gait.fixed_point);
    walker.integrator = sil::SIL_INTEGRATOR;
    let reflex = walker.ankle.clone().unwrap();
    let mut group = c.benchmark_group("sil");
    group.sample_size(10);
    group.bench_function("wisse3d_5_steps", |b| {
        b.iter(|| {
            let mut ctl =
                FirmwareInTheLoop::new(SilConfig::default().with_reflex(&reflex).unwrap()).unwrap();
            let walk = walker.walk_controlled(&q, &qd, 5, false, &mut ctl);
            assert!(walk.failure.is_none());
            walk.steps.len()
        })
    });
    group.finish();
}

criterion_group!(sil, bench);
criterion_main!(sil);
