//! Criterion benchmarks of what the studies spend per point, on one thread, beside what the
//! same work costs done plainly (issue 31; results and the machine: docs/performance.md):
//! - `map_cell_wisse3d`: one stability-map cell of the 3D walker (the gait rule with the
//!   defaults' gait already found, as every cell of a map after the first has it), against
//!   `cold_gait_wisse3d`, the gait `walker gait` finds at the same values from nothing (the
//!   scene built, the defaults' gait found, then the cell's);
//! - `basin_cell_compass` / `basin_cell_wisse3d`: one basin cell (a start off the gait
//!   followed back to it, at most 100 strides), against as many plain strides
//!   (`strides_compass`, `strides_wisse3d`, per stride);
//! - `mfpt_batch_compass`: a Monte Carlo batch of first-passage walks on a rough floor,
//!   against as many plain strides on the plane.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use sim::analysis::homotopy::{GaitRule, HomotopySettings};
use sim::analysis::limit_cycle::NewtonSettings;
use sim::analysis::robustness::recovery::Until;
use sim::analysis::robustness::{mean_first_passage, FirstPassageOptions, Recovery};
use sim::scene::{Scene, SceneError, Setup};
use sim::stride::{StrideRequest, StrideWorkspace};
use std::time::Duration;

/// The map cell of the example map (`--x pelvis_yaw_stiffness_n_m_per_rad=0.8:1.3:3
/// --y pelvic_ring_radius_m=0.38:0.44:3`): its corner (1.3, 0.38).
fn cell() -> Scene {
    let mut s = Scene::load("wisse3d").unwrap();
    s.set("pelvis_yaw_stiffness_n_m_per_rad", 1.3).unwrap();
    s.set("pelvic_ring_radius_m", 0.38).unwrap();
    s
}

/// `n` plain strides from the fixed point of `setup`'s gait, each from the last's end.
fn plain_strides(setup: &Setup, v: &nalgebra::DVector<f64>, n: usize) -> usize {
    let w = &setup.walker;
    let mut ws = StrideWorkspace::new(w);
    let (mut q, mut qd) = w.unpack(v);
    for _ in 0..n {
        let r = ws
            .stride(&q, &qd, StrideRequest::new(&setup.settings))
            .unwrap();
        (q, qd) = (r.q_next, r.qd_next);
    }
    n
}

fn benches(c: &mut Criterion) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let newton = NewtonSettings::default();
    let homotopy = HomotopySettings::default();
    let setup_for = |s: &Scene| -> Result<Setup, SceneError> { s.setup() };
    let mut group = c.benchmark_group("studies");
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(500));
    group.measurement_time(Duration::from_secs(5));

    // a map cell against a cold gait at the same values
    let at = cell();
    let rule = GaitRule::new(&setup_for, &newton, &homotopy);
    pool.install(|| rule.gait(&at).unwrap().unwrap());
    group.bench_function("map_cell_wisse3d", |b| {
        b.iter(|| pool.install(|| rule.gait(black_box(&at)).unwrap().unwrap()))
    });
    group.bench_function("cold_gait_wisse3d", |b| {
        b.iter(|| {
            pool.install(|| {
                let fresh = GaitRule::new(&setup_for, &newton, &homotopy);
                fresh.gait(black_box(&at)).unwrap().unwrap()
            })
        })
    });

    for name in ["compass", "wisse3d"] {
        let setup = Scene::load(name).unwrap().setup().unwrap();
        let gait = setup.find_gait(&newton).unwrap();
        let recovery = Recovery::new(&setup.walker, &setup.settings, &gait);
        // a start off the gait: every entry of the stride-map vector 2 % larger
        let start = gait.fixed_point.map(|v| v * 1.02);
        let mut ws = StrideWorkspace::new(&setup.walker);
        let outcome = recovery.follow(&mut ws, &start, &mut |_| 0.0, Until::Settled);
        let strides = outcome.strides();
        group.throughput(Throughput::Elements(strides as u64));
        group.bench_function(format!("basin_cell_{name}"), |b| {
            b.iter(|| recovery.follow(&mut ws, black_box(&start), &mut |_| 0.0, Until::Settled))
        });
        group.bench_function(format!("strides_{name}"), |b| {
            b.iter(|| plain_strides(&setup, black_box(&gait.fixed_point), strides))
        });
        if name == "compass" {
            let options = FirstPassageOptions {
                runs: 4,
                strides_per_run: 50,
                seed: 1,
            };
            let sigma_m = 1e-3;
            let batch = pool.install(|| mean_first_passage(&recovery, sigma_m, &options).unwrap());
            group.throughput(Throughput::Elements(batch.strides_simulated as u64));
            group.bench_function("mfpt_batch_compass", |b| {
                b.iter(|| {
                    pool.install(|| mean_first_passage(&recovery, black_box(sigma_m), &options))
                })
            });
            group.bench_function("mfpt_plain_strides_compass", |b| {
                b.iter(|| plain_strides(&setup, &gait.fixed_point, batch.strides_simulated))
            });
        }
    }
    group.finish();
}

criterion_group!(studies, benches);
criterion_main!(studies);
