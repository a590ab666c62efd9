//! Criterion benchmarks: one stride per scene and integrator, and a whole gait computation
//! (fixed point and eigenvalues) per scene and adaptive integrator (the fixed-step ones do not
//! reach Newton's tolerance). Results and the machine are in docs/performance.md.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use sim::analysis::limit_cycle::{GaitSearch, NewtonSettings};
use sim::engine::integrators::IntegratorChoice;
use sim::scene::Scene;
use sim::stride::EvaluationPath;
use sim::stride::StrideRequest;
use std::time::Duration;

const SCENES: [&str; 5] = ["simplest", "compass", "kneed2d", "wisse2d", "wisse3d"];

fn benches(c: &mut Criterion) {
    for name in SCENES {
        let Ok(setup) = Scene::load(name).and_then(|s| s.setup()) else {
            continue;
        };
        let walker = &setup.walker;
        let v0 = walker.pack(&setup.guess.q, &setup.guess.qd);
        let newton = NewtonSettings::default();
        let search = GaitSearch::new(walker, &setup.settings, &newton);
        let Ok(gait) = search.find(&v0) else {
            continue;
        };
        let (q, qd) = walker.unpack(&gait.fixed_point);
        let period = gait.stride.duration_s;
        let mut group = c.benchmark_group(format!("stride/{name}"));
        // Short times keep the whole `cargo bench` moderate on the shared 2-core machine.
        group.warm_up_time(Duration::from_millis(500));
        group.measurement_time(Duration::from_secs(2));
        for (label, integrator) in [
            ("default", setup.settings.integrator.clone()),
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
                "dop853_1e-10",
                IntegratorChoice::Dop853 {
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
            let settings = setup.settings.with_integrator(integrator);
            if label == "default" {
                // The same stride on the general engine with events estimated on the Hermite
                // interpolant (the path before the planar fast path and dense output).
                let mut general = settings.clone();
                general.evaluation = EvaluationPath::General;
                general.event_tolerance.dense_output = false;
                group.bench_function("default_general_hermite", |b| {
                    b.iter(|| {
                        let request = StrideRequest::new(&general);
                        walker.stride(black_box(&q), black_box(&qd), request)
                    })
                });
            }
            group.bench_function(label, |b| {
                b.iter(|| {
                    let request = StrideRequest::new(&settings);
                    walker.stride(black_box(&q), black_box(&qd), request)
                })
            });
            if (label == "default" || label == "dop853_1e-10")
                && walker.takes_fixed_size_stride(&settings, Default::default())
            {
                // The same stride in the general loop (the planar evaluation, no fixed-size
                // stride): what the fixed-size stride buys.
                let mut general_loop = settings.clone();
                general_loop.evaluation = EvaluationPath::GeneralLoop;
                group.bench_function(format!("{label}_general_loop"), |b| {
                    b.iter(|| {
                        let request = StrideRequest::new(&general_loop);
                        walker.stride(black_box(&q), black_box(&qd), request)
                    })
                });
                if sim::engine::PlanarTree::of(walker.model()).is_some_and(|t| t.has_closed_form())
                {
                    // The fixed-size stride on the planar link pass instead of the two-link
                    // closed form: what the closed form buys.
                    let mut link_pass = settings.clone();
                    link_pass.evaluation = EvaluationPath::LinkPass;
                    group.bench_function(format!("{label}_link_pass"), |b| {
                        b.iter(|| {
                            let request = StrideRequest::new(&link_pass);
                            walker.stride(black_box(&q), black_box(&qd), request)
                        })
                    });
                }
            }
        }
        group.finish();
        let mut group = c.benchmark_group(format!("gait/{name}"));
        // Short times keep the whole `cargo bench` moderate on the shared 2-core machine.
        group.warm_up_time(Duration::from_millis(500));
        group.measurement_time(Duration::from_secs(2));
        group.sample_size(10);
        group.bench_function("default", |b| b.iter(|| search.find(black_box(&v0))));
        for (label, integrator) in [
            (
                "dopri5_1e-10",
                IntegratorChoice::Dopri5 {
                    rtol: 1e-10,
                    atol: 1e-10,
                    h_max_s: period / 10.0,
                },
            ),
            (
                "dop853_1e-10",
                IntegratorChoice::Dop853 {
                    rtol: 1e-10,
                    atol: 1e-10,
                    h_max_s: period / 10.0,
                },
            ),
            (
                // Eigenvalues to about 5e-7 on the 3D walker (docs/accuracy.md).
                "dop853_1e-8",
                IntegratorChoice::Dop853 {
                    rtol: 1e-8,
                    atol: 1e-8,
                    h_max_s: period / 10.0,
                },
            ),
        ] {
            let settings = setup.settings.with_integrator(integrator);
            let search = GaitSearch::new(walker, &settings, &newton);
            if search.find(&v0).is_err() {
                continue;
            }
            group.bench_function(label, |b| b.iter(|| search.find(black_box(&v0))));
            if label == "dop853_1e-8" {
                // The stepping Jacobian by central differences (2n strides instead of n): what
                // the forward-difference stepping buys, in the same run.
                let central = NewtonSettings {
                    forward_stepping: false,
                    ..newton
                };
                let search = GaitSearch::new(walker, &settings, &central);
                group.bench_function(format!("{label}_central_stepping"), |b| {
                    b.iter(|| search.find(black_box(&v0)))
                });
            }
        }
        group.finish();
    }
}

criterion_group!(stride, benches);
criterion_main!(stride);
