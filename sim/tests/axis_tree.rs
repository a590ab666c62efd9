//! The 3D fast path (`sim::engine::AxisTree`) against the general engine it stands in for:
//! `M̄`, `f̄` and `q̈` over random states in every phase (each coordinate locked, one driven),
//! on the 3D walker's scenes and on random trees the scene files do not express (joints about
//! x, y and z, welds with offsets, full inertia tensors, bodies welded to the ground, springs
//! and dampers); which models qualify; and the 3D walker's gait found on both.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::type_complexity,
    missing_docs
)]

use nalgebra::{DVector, Matrix3, Vector3};
use sim::analysis::limit_cycle::NewtonSettings;
use sim::engine::dynamics::Dynamics;
use sim::engine::model::{BodyInertia, JointForce, JointKind, Model};
use sim::engine::AxisTree;
use sim::scene::Scene;
use sim::stride::EvaluationPath;
use sim::stride::Phase;

fn noise(k: &mut u64) -> f64 {
    *k = k
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    ((*k >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

fn random_state(n: usize, k: &mut u64) -> (DVector<f64>, DVector<f64>) {
    (
        DVector::from_fn(n, |_, _| 0.6 * noise(k)),
        DVector::from_fn(n, |_, _| 2.0 * noise(k)),
    )
}

/// Largest entrywise difference relative to the largest entry of `reference`.
fn relative_difference(a: &[f64], reference: &[f64]) -> f64 {
    let scale = reference
        .iter()
        .fold(0.0f64, |m, x| m.max(x.abs()))
        .max(1e-300);
    a.iter()
        .zip(reference)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

/// `M̄`, `f̄` and, in every phase, `q̈` of `model` on the fast path and on the general engine
/// over `states` random states; returns the largest relative differences `(M̄ and f̄, q̈)`.
fn compare(model: &Model, states: usize, seed: u64) -> (f64, f64) {
    let n = model.dof();
    let mut tree = AxisTree::of(model).expect("the model qualifies");
    let mut general = Dynamics::new(model);
    let mut k = seed;
    let (mut worst_mf, mut worst_qdd) = (0.0f64, 0.0f64);
    for _ in 0..states {
        let (q, qd) = random_state(n, &mut k);
        let (m, f) = tree.mass_matrix_and_force(&q, &qd);
        general.assemble(model, &q, &qd, None);
        let m_ref: Vec<f64> = (0..n)
            .flat_map(|i| (0..n).map(move |j| (i, j)))
            .map(|(i, j)| general.mass_matrix[(i, j)])
            .collect();
        worst_mf = worst_mf.max(relative_difference(&m, &m_ref));
        worst_mf = worst_mf.max(relative_difference(&f, general.force.as_slice()));
        // Phases: all free; each coordinate locked; each coordinate driven (the others free).
        let mut phases: Vec<(Vec<bool>, Option<DVector<f64>>, Option<usize>)> =
            vec![(vec![true; n], None, None)];
        for c in 0..n {
            let mut active = vec![true; n];
            active[c] = false;
            phases.push((active.clone(), None, None));
            let mut qdd_p = DVector::zeros(n);
            qdd_p[c] = 3.0 * noise(&mut k);
            phases.push((active, Some(qdd_p), Some(c)));
            // The walker's own kind of phase: one coordinate locked, the next one driven.
            if n > 2 {
                let d = (c + 1) % n;
                let mut active = vec![true; n];
                active[c] = false;
                active[d] = false;
                let mut qdd_p = DVector::zeros(n);
                qdd_p[d] = 3.0 * noise(&mut k);
                phases.push((active, Some(qdd_p), Some(d)));
            }
        }
        for (active, qdd_p, driven) in &phases {
            let reference = general.accelerations(model, &q, &qd, active, qdd_p.as_ref());
            let mut qdd = DVector::zeros(n);
            let fast = tree.accelerations_into(&q, &qd, active, qdd_p.as_ref(), *driven, &mut qdd);
            // A free coordinate with nothing to move below it (a massless end link) leaves the
            // free block singular: both must say so.
            let Ok(reference) = reference else {
                assert!(
                    fast.is_err(),
                    "the general engine found a singular M̄, the fast path did not"
                );
                continue;
            };
            fast.unwrap();
            worst_qdd = worst_qdd.max(relative_difference(qdd.as_slice(), reference.as_slice()));
            if let Some(c) = *driven {
                // The actuator's generalised force on the fast path's assembly against the
                // general engine's full one.
                general.assemble(model, &q, &qd, None);
                let tau_ref = (general.mass_matrix.row(c) * &reference)[(0, 0)] - general.force[c];
                let tau = tree
                    .actuator_force(c, &qdd)
                    .expect("the driven row is assembled");
                let scale = general.force.amax().max(general.mass_matrix.amax());
                assert!(
                    (tau - tau_ref).abs() <= 1e-12 * scale.max(tau_ref.abs()),
                    "actuator force {tau} against {tau_ref}"
                );
            }
        }
    }
    (worst_mf, worst_qdd)
}

#[test]
fn the_3d_walkers_equations_of_motion_equal_the_general_engines() {
    for name in [
        "wisse3d",
        "wisse3d-tuned",
        "wisse3d-uncompensated",
        "wisse3d-locked-compensator",
        "wisse2d",
        "kneed2d",
        "compass",
    ] {
        let setup = Scene::load(name).unwrap().setup().unwrap();
        let (mf, qdd) = compare(setup.walker.model(), 60, 17);
        println!("{name}: M̄, f̄ {mf:.2e}, q̈ {qdd:.2e}");
        assert!(mf <= 1e-13, "{name}: M̄, f̄ differ by {mf:e} relative");
        assert!(qdd <= 1e-11, "{name}: q̈ differs by {qdd:e} relative");
    }
}

/// A random tree of `links` links: revolutes about x, y or z (each with a coordinate), welds
/// with offsets, bodies with full inertia tensors and off-axis centres of mass (some massless,
/// one welded to the ground), springs and dampers.
fn random_tree(seed: u64, links: usize) -> Model {
    let mut k = seed;
    let mut model = Model::new(Vector3::new(0.3, -9.81, 0.2));
    let mut names: Vec<String> = Vec::new();
    // A body welded to the ground first: it moves with no coordinate.
    model
        .add_link(
            "base",
            None,
            Vector3::new(0.1, 0.0, -0.05),
            JointKind::Weld,
            JointForce::default(),
            body(&mut k, 1.0),
        )
        .unwrap();
    names.push("base".into());
    for i in 0..links {
        let parent = names
            [((noise(&mut k) * 0.5 + 0.5) * names.len() as f64) as usize % names.len()]
        .clone();
        let name = format!("link{i}");
        let origin = Vector3::new(
            0.3 * noise(&mut k),
            0.3 * noise(&mut k),
            0.3 * noise(&mut k),
        );
        let weld = i % 4 == 3;
        let joint = if weld {
            JointKind::Weld
        } else {
            let mut axis = Vector3::zeros();
            axis[i % 3] = 1.0;
            JointKind::Revolute { axis_parent: axis }
        };
        let force = if weld || i % 3 != 1 {
            JointForce::default()
        } else {
            JointForce {
                stiffness: 2.0 * noise(&mut k).abs(),
                rest_position: 0.1 * noise(&mut k),
                damping: 0.3 * noise(&mut k).abs(),
            }
        };
        let mass = if i % 5 == 2 { 0.0 } else { 1.0 };
        model
            .add_link(
                &name,
                Some(&parent),
                origin,
                joint,
                force,
                body(&mut k, mass),
            )
            .unwrap();
        names.push(name);
    }
    model
}

/// A body of about `scale` kg (none if 0) with a full, positive definite inertia tensor.
fn body(k: &mut u64, scale: f64) -> BodyInertia {
    if scale == 0.0 {
        return BodyInertia::massless();
    }
    // The inertia of a few point masses about their centre (a physical tensor: its
    // principal moments obey the triangle inequality), plus a little isotropic part.
    let mut inertia = Matrix3::identity() * 0.01;
    for _ in 0..3 {
        let r = Vector3::new(0.3 * noise(k), 0.3 * noise(k), 0.3 * noise(k));
        inertia += (Matrix3::identity() * r.norm_squared() - r * r.transpose()) * 0.3;
    }
    BodyInertia {
        mass_kg: scale * (1.0 + 0.5 * noise(k)),
        p_link_com_m: Vector3::new(0.2 * noise(k), 0.2 * noise(k), 0.2 * noise(k)),
        inertia_com_kg_m2: inertia,
        infinitesimal: false,
    }
}

#[test]
fn random_3d_trees_equal_the_general_engine() {
    for seed in 1..=12u64 {
        let model = random_tree(seed, 11);
        let (mf, qdd) = compare(&model, 25, seed * 7919);
        println!(
            "tree {seed} ({} coordinates): M̄, f̄ {mf:.2e}, q̈ {qdd:.2e}",
            model.dof()
        );
        assert!(mf <= 1e-13, "tree {seed}: M̄, f̄ differ by {mf:e} relative");
        assert!(qdd <= 1e-10, "tree {seed}: q̈ differs by {qdd:e} relative");
    }
}

#[test]
fn only_coordinate_axis_revolute_trees_of_finite_bodies_qualify() {
    let base = || {
        let mut m = Model::new(Vector3::new(0.0, -9.81, 0.0));
        m.add_link(
            "a",
            None,
            Vector3::zeros(),
            JointKind::Revolute {
                axis_parent: Vector3::z(),
            },
            JointForce::default(),
            BodyInertia {
                mass_kg: 1.0,
                p_link_com_m: Vector3::new(0.0, 1.0, 0.0),
                inertia_com_kg_m2: Matrix3::identity() * 0.1,
                infinitesimal: false,
            },
        )
        .unwrap();
        m
    };
    assert!(AxisTree::of(&base()).is_some());
    let mut skew = base();
    skew.add_link(
        "b",
        Some("a"),
        Vector3::zeros(),
        JointKind::Revolute {
            axis_parent: Vector3::new(1.0, 1.0, 0.0),
        },
        JointForce::default(),
        BodyInertia::massless(),
    )
    .unwrap();
    assert!(
        AxisTree::of(&skew).is_none(),
        "an axis that is not a coordinate axis"
    );
    let mut slider = base();
    slider
        .add_link(
            "b",
            Some("a"),
            Vector3::zeros(),
            JointKind::Prismatic {
                axis_parent: Vector3::x(),
            },
            JointForce::default(),
            BodyInertia::massless(),
        )
        .unwrap();
    assert!(AxisTree::of(&slider).is_none(), "a prismatic joint");
    let simplest = Scene::load("simplest").unwrap().setup().unwrap();
    assert!(
        AxisTree::of(simplest.walker.model()).is_none(),
        "infinitesimal bodies"
    );
    let empty = Model::new(Vector3::new(0.0, -9.81, 0.0));
    assert!(AxisTree::of(&empty).is_none(), "no coordinates");
}

#[test]
fn the_3d_walker_evaluates_on_the_fast_path_unless_told_otherwise() {
    let setup = Scene::load("wisse3d").unwrap().setup().unwrap();
    let model = setup.walker.model();
    assert!(Phase::with_path(model, EvaluationPath::Auto).is_axis_tree_fast_path());
    assert!(Phase::with_path(model, EvaluationPath::GeneralLoop).is_axis_tree_fast_path());
    assert!(!Phase::with_path(model, EvaluationPath::General).is_axis_tree_fast_path());
    // Planar walkers keep the planar fast path.
    let compass = Scene::load("compass").unwrap().setup().unwrap();
    let phase = Phase::with_path(compass.walker.model(), EvaluationPath::Auto);
    assert!(phase.is_planar_fast_path() && !phase.is_axis_tree_fast_path());
}

/// The 3D walker's gait (fixed point, eigenvalues) found on the fast path and on the general
/// engine, at the scene's settings and at the gait bench's DOP853 1e-8.
#[test]
fn the_3d_walkers_gait_is_the_same_on_both_paths() {
    let scene = Scene::load("wisse3d").unwrap();
    for rtol in [None, Some(1e-8)] {
        let gait = |path: EvaluationPath| {
            let mut setup = scene.setup().unwrap();
            setup.settings.evaluation = path;
            if let Some(r) = rtol {
                let i = setup
                    .settings
                    .integrator
                    .with_tolerance_or_step(Some(r), None);
                setup.settings = setup.settings.with_integrator(i);
            }
            setup.find_gait(&NewtonSettings::default()).unwrap()
        };
        let (fast, general) = (gait(EvaluationPath::Auto), gait(EvaluationPath::General));
        let dx = (&fast.fixed_point - &general.fixed_point).amax();
        let mut lf: Vec<f64> = fast.eigenvalues.iter().map(|z| z.norm()).collect();
        let mut lg: Vec<f64> = general.eigenvalues.iter().map(|z| z.norm()).collect();
        lf.sort_by(f64::total_cmp);
        lg.sort_by(f64::total_cmp);
        let dl = lf
            .iter()
            .zip(&lg)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        println!("rtol {rtol:?}: fixed points {dx:.2e} apart, |λ| {dl:.2e}");
        assert!(dx <= 1e-9, "fixed points {dx:e} apart");
        assert!(dl <= 1e-7, "eigenvalue moduli {dl:e} apart");
    }
}

#[test]
fn non_finite_states_are_errors_as_on_the_general_engine() {
    let setup = Scene::load("wisse3d").unwrap().setup().unwrap();
    let model = setup.walker.model();
    let n = model.dof();
    let mut tree = AxisTree::of(model).unwrap();
    let mut general = Dynamics::new(model);
    let active = vec![true; n];
    let mut qdd = DVector::zeros(n);
    for bad in [f64::NAN, f64::INFINITY] {
        for in_q in [true, false] {
            let (mut q, mut qd) = (DVector::zeros(n), DVector::zeros(n));
            if in_q {
                q[3] = bad;
            } else {
                qd[3] = bad;
            }
            let fast = tree.accelerations_into(&q, &qd, &active, None, None, &mut qdd);
            let reference = general.accelerations(model, &q, &qd, &active, None);
            assert!(
                matches!(fast, Err(sim::engine::dynamics::DynamicsError::NonFinite)),
                "{fast:?}"
            );
            assert!(reference.is_err());
        }
    }
    // Every coordinate locked with a non-finite prescribed acceleration: an error too.
    let mut qdd_p = DVector::zeros(n);
    qdd_p[0] = f64::NAN;
    let zeros = DVector::zeros(n);
    assert!(tree
        .accelerations_into(
            &zeros,
            &zeros,
            &vec![false; n],
            Some(&qdd_p),
            None,
            &mut qdd
        )
        .is_err());
    // Wrong lengths: an error, no panic.
    let short = DVector::zeros(n - 1);
    assert!(tree
        .accelerations_into(&short, &zeros, &active, None, None, &mut qdd)
        .is_err());
    assert!(tree
        .accelerations_into(&zeros, &zeros, &active, Some(&short), None, &mut qdd)
        .is_err());
}
