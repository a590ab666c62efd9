//! Criterion benchmark: five steps of the 3D walker with both ankle nodes' firmware and the
//! simulated CAN bus in the loop (`walker sil`'s default integrator, steps across the control
//! ticks while the firmware's output holds). Walking time per wall time is the real-time factor
//! in docs/sil.md. `wisse3d_5_steps_every_tick`: the same with every step ending at a tick
//! (`TickStepping::EndAtEveryTick`, the reference scheme and the one before).
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use criterion::{criterion_group, criterion_main, Criterion};
use sil::config::SilConfig;
use sil::FirmwareInTheLoop;
use sim::engine::control::TickStepping;
use sim::scene::Scene;
use sim::stride::walk::WalkRequest;

fn bench(c: &mut Criterion) {
    let scene = Scene::load("wisse3d").unwrap();
    let setup = scene.setup().unwrap();
    let gait = setup.find_gait(&Default::default()).unwrap();
    let walker = &setup.walker;
    let (q, qd) = walker.unpack(&gait.fixed_point);
    let mut group = c.benchmark_group("sil");
    group.sample_size(10);
    for (name, stepping) in [
        ("wisse3d_5_steps", TickStepping::HeldAcrossTicks),
        ("wisse3d_5_steps_every_tick", TickStepping::EndAtEveryTick),
    ] {
        let settings = setup
            .settings
            .with_integrator(sil::SIL_INTEGRATOR)
            .with_tick_stepping(stepping);
        group.bench_function(name, |b| {
            b.iter(|| {
                let mut ctl = FirmwareInTheLoop::new(SilConfig::default()).unwrap();
                let request = WalkRequest::new(&settings, 5).controlled(&mut ctl);
                let walk = sim::stride::walk::walk(walker, &q, &qd, request);
                assert!(walk.failure.is_none());
                walk.steps.len()
            })
        });
    }
    group.finish();
}

criterion_group!(sil, bench);
criterion_main!(sil);
