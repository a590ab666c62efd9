//! Criterion benchmarks of the parameter studies on 1 and 2 threads in the same run (rayon
//! pools built with `num_threads`): a stability map of the compass gait (4 slopes × 3 hip
//! masses, rows in parallel) and one whole gait of the 3D walker (its stride Jacobian's
//! columns in parallel). Results and the machine: docs/performance.md.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use sim::analysis::homotopy::HomotopySettings;
use sim::analysis::limit_cycle::{GaitSearch, NewtonSettings};
use sim::analysis::stability_map::{stability_map, Axis};
use sim::scene::{Scene, Setup};
use std::time::Duration;

fn benches(c: &mut Criterion) {
    let compass = Scene::load("compass").unwrap();
    let wisse3d = Scene::load("wisse3d").unwrap().setup().unwrap();
    let newton = NewtonSettings::default();
    let homotopy = HomotopySettings::default();
    let x = Axis {
        name: "hip_mass_kg".into(),
        values: vec![9.0, 10.0, 11.0],
    };
    let y = Axis {
        name: "slope_rad".into(),
        values: vec![0.04, 0.045, 0.05, 0.055],
    };
    let setup_for = |s: &Scene| -> Result<Setup, sim::scene::SceneError> { s.setup() };
    let v0 = wisse3d.walker.pack(&wisse3d.guess.q, &wisse3d.guess.qd);
    let search = GaitSearch::new(&wisse3d.walker, &wisse3d.settings, &newton);
    let mut group = c.benchmark_group("parallel");
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(500));
    group.measurement_time(Duration::from_secs(4));
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        group.bench_function(
            format!("stability_map_compass_4x3/{threads}_threads"),
            |b| {
                b.iter(|| {
                    pool.install(|| {
                        let map =
                            stability_map(&compass, &setup_for, &x, &y, &newton, &homotopy, &|| {})
                                .unwrap();
                        black_box(map.rows.len())
                    })
                })
            },
        );
        group.bench_function(format!("gait_wisse3d/{threads}_threads"), |b| {
            b.iter(|| pool.install(|| search.find(black_box(&v0)).unwrap()))
        });
    }
    group.finish();
}

criterion_group!(parallel, benches);
criterion_main!(parallel);
