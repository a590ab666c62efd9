//! The planar fast path (`sim::engine::planar`) against the general engine, its reference: which scenes
//! take it, the equations of motion at many states and phases, one stride, and a whole gait
//! (fixed point and eigenvalues).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use nalgebra::DVector;
use sim::analysis::limit_cycle::{GaitSearch, NewtonSettings};
use sim::engine::integrators::SecondOrderSystem;
use sim::scene::{Scene, Setup};
use sim::stride::{Drive, Phase, StrideRequest};
use sim::{engine::PlanarTree, stride::EvaluationPath};

/// The scenes that take the planar fast path (wisse2d too: its drive and ankle are planar).
const PLANAR: [&str; 4] = ["simplest", "compass", "kneed2d", "wisse2d"];

fn setup(name: &str) -> Setup {
    Scene::load(name).unwrap().setup().unwrap()
}

/// A deterministic pseudo-random number in [-1, 1).
fn noise(k: &mut u64) -> f64 {
    *k = k
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    ((*k >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

#[test]
fn the_planar_scenes_qualify_and_the_3d_walker_does_not() {
    for name in PLANAR {
        let s = setup(name);
        assert!(PlanarTree::of(s.walker.model()).is_some(), "{name}");
        assert!(Phase::new(s.walker.model()).is_planar_fast_path(), "{name}");
        assert!(
            !Phase::with_path(s.walker.model(), EvaluationPath::General).is_planar_fast_path(),
            "{name}"
        );
    }
    let s = setup("wisse3d");
    assert!(PlanarTree::of(s.walker.model()).is_none());
    assert!(!Phase::new(s.walker.model()).is_planar_fast_path());
}

#[test]
fn equations_of_motion_agree_with_the_general_engine() {
    let mut seed = 7u64;
    for name in PLANAR {
        let s = setup(name);
        let model = s.walker.model();
        let n = model.dof();
        let mut fast = Phase::new(model);
        let mut general = Phase::with_path(model, EvaluationPath::General);
        // Every phase: all free, each coordinate locked in turn, and one driven.
        let mut masks = vec![vec![true; n]];
        for i in 0..n {
            let mut m = vec![true; n];
            m[i] = false;
            masks.push(m);
        }
        let mut compared = 0;
        for (mi, mask) in masks.iter().enumerate() {
            for trial in 0..50 {
                let q = DVector::from_fn(n, |i, _| s.guess.q[i] + 0.5 * noise(&mut seed));
                let qd = DVector::from_fn(n, |i, _| s.guess.qd[i] + 2.0 * noise(&mut seed));
                fast.active.clone_from(mask);
                general.active.clone_from(mask);
                let driven = (mi > 0 && trial % 2 == 1).then(|| {
                    let c = mask.iter().position(|a| !a).unwrap();
                    let seg = sim::engine::control::ActuatorSegment {
                        t0_s: 0.0,
                        t1_s: 1.0,
                        p0_rad: 0.2,
                        v0_rad_s: -1.0,
                        p1_rad: 0.5,
                        v1_rad_s: 2.0,
                        released: false,
                    };
                    (sim::engine::model::CoordIndex(c), Drive::Segment(seg))
                });
                fast.prescribed = driven;
                general.prescribed = driven;
                let t = 0.3;
                let (a, b) = match (
                    fast.accelerations(t, &q, &qd),
                    general.accelerations(t, &q, &qd),
                ) {
                    (Ok(a), Ok(b)) => (a, b),
                    (Err(a), Err(b)) => {
                        assert_eq!(a, b, "{name}: both paths fail alike");
                        continue;
                    }
                    (a, b) => panic!("{name}: fast {a:?} against general {b:?}"),
                };
                let scale = 1.0 + b.amax();
                assert!(
                    (&a - &b).amax() <= 1e-13 * scale,
                    "{name} mask {mask:?}: fast {a} general {b}"
                );
                compared += 1;
            }
        }
        assert!(compared >= 50 * masks.len() / 2, "{name}: {compared}");
    }
}

#[test]
fn a_stride_and_a_gait_agree_with_the_general_engine() {
    for name in PLANAR {
        let s = setup(name);
        let walker = &s.walker;
        let mut general = s.settings.clone();
        general.evaluation = EvaluationPath::General;
        let newton = NewtonSettings::default();
        let v0 = walker.pack(&s.guess.q, &s.guess.qd);
        let g_fast = GaitSearch::new(walker, &s.settings, &newton)
            .find(&v0)
            .unwrap();
        let g_gen = GaitSearch::new(walker, &general, &newton)
            .find(&v0)
            .unwrap();
        // One stride from the same state.
        let (q, qd) = walker.unpack(&g_gen.fixed_point);
        let a = walker
            .stride(&q, &qd, StrideRequest::new(&s.settings))
            .unwrap();
        let b = walker
            .stride(&q, &qd, StrideRequest::new(&general))
            .unwrap();
        let va = walker.pack(&a.q_next, &a.qd_next);
        let vb = walker.pack(&b.q_next, &b.qd_next);
        // Measured: strides 3.4e-15 (compass), stride times 1.4e-15, fixed points 1.1e-14
        // (compass), eigenvalues 4.7e-9 (compass); bounds about ten times those.
        let stride_diff = (&va - &vb).amax();
        assert!(stride_diff < 3e-14, "{name}: stride {stride_diff:e}");
        let dt = (a.duration_s - b.duration_s).abs();
        assert!(dt < 3e-14, "{name}: stride time {dt:e}");
        let fp = (&g_fast.fixed_point - &g_gen.fixed_point).amax();
        assert!(fp < 1e-13, "{name}: fixed point {fp:e}");
        let mut ea: Vec<_> = g_fast.eigenvalues.iter().map(|z| (z.re, z.im)).collect();
        let mut eb: Vec<_> = g_gen.eigenvalues.iter().map(|z| (z.re, z.im)).collect();
        ea.sort_by(|x, y| x.partial_cmp(y).unwrap());
        eb.sort_by(|x, y| x.partial_cmp(y).unwrap());
        let ev = ea
            .iter()
            .zip(&eb)
            .map(|(x, y)| (x.0 - y.0).hypot(x.1 - y.1))
            .fold(0.0f64, f64::max);
        eprintln!(
            "{name}: stride {stride_diff:e} (time {dt:e}), fixed point {fp:e}, eigenvalues {ev:e}"
        );
        // The eigenvalues come from central differences with δ = 1e-6: a difference of 1e-14
        // between the two paths' strides moves them by about 1e-14 / 1e-6 · |J| (1e-8), the
        // central differences' own noise (docs/accuracy.md), not a difference of the models.
        assert!(ev < 5e-8, "{name}: eigenvalues {ev:e}");
    }
}

#[test]
fn events_located_on_the_dense_output_agree_with_exact_step_refinement() {
    // The same stride, its events estimated on DOP853's dense output (the default) and on the
    // Hermite interpolant, both refined on exact steps, the latter at the limit of f64: the
    // heel-strike states agree far below the integration error (against DOP853 at 1e-14), at
    // the scenes' default tolerance and at 1e-8, with fewer evaluations.
    for name in PLANAR {
        let s = setup(name);
        let walker = &s.walker;
        let newton = NewtonSettings::default();
        let v0 = walker.pack(&s.guess.q, &s.guess.qd);
        let gait = GaitSearch::new(walker, &s.settings, &newton)
            .find(&v0)
            .unwrap();
        let (q, qd) = walker.unpack(&gait.fixed_point);
        let mut reference = s.settings.clone();
        reference.integrator = sim::engine::integrators::IntegratorChoice::Dop853 {
            rtol: 1e-14,
            atol: 1e-14,
            h_max_s: 0.05,
        };
        reference.event_tolerance.dense_output = false;
        let exact_ref = walker
            .stride(&q, &qd, StrideRequest::new(&reference))
            .unwrap();
        for rtol in [1e-12, 1e-8] {
            let mut dense = s.settings.clone();
            dense.integrator = dense.integrator.with_tolerance_or_step(Some(rtol), None);
            assert!(dense.event_tolerance.dense_output);
            let mut exact = dense.clone();
            exact.event_tolerance.dense_output = false;
            exact.event_tolerance.time_s = 1e-16;
            exact.event_tolerance.witness = 0.0;
            exact.event_tolerance.max_iterations = 200;
            let a = walker.stride(&q, &qd, StrideRequest::new(&dense)).unwrap();
            let b = walker.stride(&q, &qd, StrideRequest::new(&exact)).unwrap();
            let state = |r: &sim::stride::StrideResult| {
                let (before, _) = r.event_states.last().unwrap().clone();
                let mut v = before.q.clone_owned();
                v.extend(before.qd.iter().copied());
                v
            };
            let location = (state(&a) - state(&b)).amax();
            let integration = (state(&b) - state(&exact_ref)).amax();
            let dt = (a.duration_s - b.duration_s).abs();
            eprintln!(
                "{name} rtol {rtol:e}: heel-strike state dense − exact {location:e} (time {dt:e}), \
                 integration error {integration:e}, evaluations {} against {}",
                a.evaluations, b.evaluations
            );
            assert!(location < 1e-10, "{name} {rtol:e}: {location:e}");
            assert!(
                location < (1e-3 * integration).max(1e-13),
                "{name} {rtol:e}: location {location:e}, integration {integration:e}"
            );
            assert!(a.evaluations < b.evaluations, "{name}");
        }
    }
}

/// `q̈` of `model` by the planar tree `tree` and by the general engine over random states,
/// every phase (all free, each coordinate locked, one driven): the largest difference
/// relative to `1 + |q̈|`, and the number of states compared.
fn compare_with_general(
    model: &sim::engine::model::Model,
    tree: &PlanarTree,
    center: (&DVector<f64>, &DVector<f64>),
    seed: &mut u64,
) -> (f64, usize) {
    let n = model.dof();
    let mut general = Phase::with_path(model, EvaluationPath::General);
    let mut dynamics = sim::engine::dynamics::Dynamics::new(model);
    let (mut worst, mut compared) = (0.0f64, 0);
    let mut masks = vec![vec![true; n]];
    for i in 0..n {
        let mut m = vec![true; n];
        m[i] = false;
        masks.push(m);
    }
    for (mi, mask) in masks.iter().enumerate() {
        for trial in 0..50 {
            let q = DVector::from_fn(n, |i, _| center.0[i] + 0.8 * noise(seed));
            let qd = DVector::from_fn(n, |i, _| center.1[i] + 3.0 * noise(seed));
            general.active.clone_from(mask);
            let driven = mi > 0 && trial % 2 == 1;
            let c = mask.iter().position(|a| !a).unwrap_or(0);
            let seg = sim::engine::control::ActuatorSegment {
                t0_s: 0.0,
                t1_s: 1.0,
                p0_rad: 0.2,
                v0_rad_s: -1.0,
                p1_rad: 0.5,
                v1_rad_s: 2.0,
                released: false,
            };
            general.prescribed =
                driven.then_some((sim::engine::model::CoordIndex(c), Drive::Segment(seg)));
            let t = 0.3;
            let values = driven.then(|| {
                let (angle_rad, rate_rad_s, acceleration_rad_s2) = seg.eval(t);
                sim::engine::DriveValues {
                    coordinate: c,
                    angle_rad,
                    rate_rad_s,
                    acceleration_rad_s2,
                }
            });
            let a = tree.accelerations(&mut dynamics, mask, values.as_ref(), &q, &qd);
            match (a, general.accelerations(t, &q, &qd)) {
                (Ok(a), Ok(b)) => {
                    worst = worst.max((&a - &b).amax() / (1.0 + b.amax()));
                    compared += 1;
                }
                (Err(a), Err(b)) => assert_eq!(a, b, "both paths fail alike"),
                (a, b) => panic!("planar {a:?} against general {b:?}"),
            }
        }
    }
    (worst, compared)
}

#[test]
fn the_closed_forms_agree_with_the_link_pass_and_the_general_engine() {
    // Which trees have one: the two-link chains, found from the model (the simplest walker's
    // with its infinitesimal feet: the vanishing-mass limit in closed form), and the
    // three-link serial chain of finite bodies (kneed2d; wisse2d's tree is not one).
    for (name, closed) in [
        ("compass", true),
        ("simplest", true),
        ("kneed2d", true),
        ("wisse2d", false),
    ] {
        let s = setup(name);
        let tree = PlanarTree::of(s.walker.model()).unwrap();
        assert_eq!(tree.has_closed_form(), closed, "{name}");
        assert!(!tree.link_pass_only().has_closed_form());
        let path = PlanarTree::for_path(s.walker.model(), EvaluationPath::LinkPass).unwrap();
        assert!(!path.has_closed_form());
    }
    // The scenes as they are, then variants the scene files cannot express: distributed
    // masses (I_zz), centres of mass off the legs' axes, an axis along −z, a spring and a
    // damper at the hip, other masses and lengths.
    let mut seed = 23u64;
    for name in ["compass", "simplest", "kneed2d"] {
        for variant in 0..4 {
            let mut s = Scene::load(name).unwrap();
            if variant >= 2 && name == "compass" {
                s.set("leg_com_from_hip_m", 0.3).unwrap();
                s.set("hip_mass_kg", 2.5).unwrap();
            }
            if variant >= 2 && name == "simplest" {
                s.set("leg_length_m", 1.7).unwrap();
                s.set("hip_mass_kg", 3.0).unwrap();
            }
            if variant >= 2 && name == "kneed2d" {
                s.set("shank_mass_kg", 0.4).unwrap();
                s.set("thigh_length_m", 0.6).unwrap();
                s.set("shank_com_from_knee_m", 0.3).unwrap();
            }
            let s = s.setup().unwrap();
            let mut model = s.walker.model().clone();
            if variant % 2 == 1 {
                for (i, link) in model.links.iter_mut().enumerate() {
                    let k = i as f64 + 1.0;
                    link.body.p_link_com_m.x += 0.07 * k;
                    if !link.body.infinitesimal && link.body.mass_kg > 0.0 {
                        link.body.inertia_com_kg_m2[(2, 2)] = 0.05 * k;
                        link.body.inertia_com_kg_m2[(0, 0)] = 0.02 * k;
                    }
                    link.p_parent_joint_m.x += 0.03 * k;
                }
                let swing = model.links.len() - 1;
                if let sim::engine::model::JointKind::Revolute { axis_parent } =
                    &mut model.links[swing].joint
                {
                    axis_parent.z = -1.0;
                }
                if name != "simplest" {
                    // (A spring on the simplest walker's massless swing leg has no limit.)
                    model.links[swing].joint_force.stiffness = 3.0;
                    model.links[swing].joint_force.rest_position = 0.1;
                    model.links[swing].joint_force.damping = 0.4;
                }
            }
            let closed = PlanarTree::of(&model).unwrap();
            assert!(closed.has_closed_form(), "{name} {variant}");
            let link_pass = closed.clone().link_pass_only();
            let center = (&s.guess.q, &s.guess.qd);
            let (to_general, n1) = compare_with_general(&model, &closed, center, &mut seed);
            let (pass_to_general, _) = compare_with_general(&model, &link_pass, center, &mut seed);
            // The closed form against the link pass on the same states, all phases.
            let mut sd = seed;
            let (mut to_pass, mut dyn_a, mut dyn_b) = (
                0.0f64,
                sim::engine::dynamics::Dynamics::new(&model),
                sim::engine::dynamics::Dynamics::new(&model),
            );
            let n = model.dof();
            let free = vec![true; n];
            for _ in 0..200 {
                let q = DVector::from_fn(n, |i, _| s.guess.q[i] + 0.8 * noise(&mut sd));
                let qd = DVector::from_fn(n, |i, _| s.guess.qd[i] + 3.0 * noise(&mut sd));
                let a = closed.accelerations(&mut dyn_a, &free, None, &q, &qd);
                let b = link_pass.accelerations(&mut dyn_b, &free, None, &q, &qd);
                let (a, b) = (a.unwrap(), b.unwrap());
                to_pass = to_pass.max((&a - &b).amax() / (1.0 + b.amax()));
            }
            eprintln!(
                "{name} variant {variant}: closed form − link pass {to_pass:e}, closed form − \
                 general {to_general:e} ({n1} states), link pass − general {pass_to_general:e}"
            );
            assert!(n1 >= 100, "{name} {variant}: {n1}");
            assert!(to_pass <= 1e-13, "{name} {variant}: {to_pass:e}");
            assert!(to_general <= 1e-13, "{name} {variant}: {to_general:e}");
        }
    }
}
