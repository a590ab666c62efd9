//! Criterion benchmarks of one evaluation of the equations of motion per scene, at the scene's
//! gait guess (just after heel strike), in the phase the stride starts in: the kinematics
//! alone, the assembly of `M̄` and `f̄`, and the accelerations (assembly and the active-set
//! solve), in `f64` and in the dual numbers of the variational Jacobian (six directions), and
//! for the planar scenes the same accelerations on the planar fast path (`sim::engine::planar`).
//! Results and the machine: docs/performance.md.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use nalgebra::{DVector, SVector};
use num_dual::{Derivative, DualSVec64};
use sim::engine::dynamics::{Dynamics, DynamicsOf};
use sim::engine::kinematics::Kinematics;
use sim::engine::PlanarTree;
use sim::scene::Scene;
use std::time::Duration;

const SCENES: [&str; 5] = ["simplest", "compass", "kneed2d", "wisse2d", "wisse3d"];

fn benches(c: &mut Criterion) {
    for name in SCENES {
        let setup = Scene::load(name).and_then(|s| s.setup()).unwrap();
        let model = setup.walker.model();
        let (q, qd) = (setup.guess.q.clone(), setup.guess.qd.clone());
        let mut active = vec![true; model.dof()];
        for c in setup.walker.initially_locked() {
            active[c.0] = false;
        }
        let mut group = c.benchmark_group(format!("dynamics/{name}"));
        // Short times keep the whole `cargo bench` moderate on the shared 2-core machine.
        group.warm_up_time(Duration::from_millis(500));
        group.measurement_time(Duration::from_secs(2));
        let mut kin = Kinematics::new(model);
        group.bench_function("kinematics", |b| {
            b.iter(|| kin.update(model, black_box(&q), black_box(&qd)))
        });
        let mut dynamics = Dynamics::new(model);
        group.bench_function("assemble", |b| {
            b.iter(|| dynamics.assemble(model, black_box(&q), black_box(&qd), None))
        });
        group.bench_function("accelerations", |b| {
            b.iter(|| {
                dynamics
                    .accelerations(model, black_box(&q), black_box(&qd), &active, None)
                    .unwrap()
            })
        });
        if let Some(tree) = PlanarTree::of(model) {
            let mut out = DVector::zeros(model.dof());
            group.bench_function("accelerations_planar_fast_path", |b| {
                b.iter(|| {
                    tree.accelerations_into(
                        &mut dynamics,
                        &active,
                        None,
                        black_box(&q),
                        black_box(&qd),
                        &mut out,
                    )
                    .unwrap()
                })
            });
            if tree.has_closed_form() {
                // The same evaluation by the planar link pass instead of the two-link closed
                // form (the compass).
                let link_pass = tree.clone().link_pass_only();
                group.bench_function("accelerations_planar_link_pass", |b| {
                    b.iter(|| {
                        link_pass
                            .accelerations_into(
                                &mut dynamics,
                                &active,
                                None,
                                black_box(&q),
                                black_box(&qd),
                                &mut out,
                            )
                            .unwrap()
                    })
                });
            }
        }
        if !model.has_infinitesimal_bodies() {
            // Each coordinate carries a unit direction (mod 6), as the variational equations
            // seed them.
            let seed = |x: &DVector<f64>| {
                DVector::from_fn(x.len(), |i, _| {
                    let eps = SVector::<f64, 6>::from_fn(|k, _| f64::from(u8::from(k == i % 6)));
                    DualSVec64::<6>::new(x[i], Derivative::some(eps))
                })
            };
            let (qdual, qddual) = (seed(&q), seed(&qd));
            let mut dual: DynamicsOf<DualSVec64<6>> = DynamicsOf::new(model);
            group.bench_function("accelerations_dual6", |b| {
                b.iter(|| {
                    dual.accelerations_finite(
                        model,
                        black_box(&qdual),
                        black_box(&qddual),
                        &active,
                        None,
                    )
                    .unwrap()
                })
            });
        }
        group.finish();
    }
}

criterion_group!(dynamics, benches);
criterion_main!(dynamics);
