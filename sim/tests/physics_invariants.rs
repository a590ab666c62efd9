//! Physics checked against physics: energy in passive phases and integrator orders, angular
//! momentum across heel strike, the mass matrix, mirroring.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use nalgebra::{DVector, Matrix3, Vector3};
use proptest::prelude::*;
use sim::analysis::limit_cycle::GaitSearch;
use sim::engine::dynamics::Dynamics;
use sim::engine::integrators::{IntegratorChoice, Sample, SecondOrderSystem};
use sim::engine::model::{BodyInertia, JointForce, JointKind, Model};
use sim::engine::relabel::LinkStates;
use sim::scene::Setup;
use sim::stride::Phase;

/// Integrates `sys` over `[0, t_end]` in `n` equal steps.
fn integrate(
    ch: &IntegratorChoice,
    sys: &mut dyn SecondOrderSystem,
    s0: &Sample,
    t_end: f64,
    n: usize,
) -> Sample {
    let mut integ = ch.build();
    let h = t_end / n as f64;
    let mut s = s0.clone();
    for _ in 0..n {
        s = integ.step_exact(sys, &s, h).unwrap();
    }
    s
}

fn reference(sys: &mut dyn SecondOrderSystem, s0: &Sample, t_end: f64) -> Sample {
    let mut integ = IntegratorChoice::Dopri5 {
        rtol: 1e-14,
        atol: 1e-14,
        h_max_s: 0.01,
    }
    .build();
    let mut s = s0.clone();
    while s.t_s < t_end - 1e-15 {
        s = integ.advance(sys, &s, t_end - s.t_s).unwrap();
    }
    s
}

/// Observed orders log2(e(h)/e(h/2)) of an error measure over halving steps.
fn orders(errors: &[f64]) -> Vec<f64> {
    errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect()
}

fn energy(model: &Model, s: &Sample) -> f64 {
    let mut d = Dynamics::new(model);
    d.assemble(model, &s.q, &s.qd, None);
    d.energy_j(model, &s.q, &s.qd)
}

fn compass_swing() -> (Setup, Sample) {
    let (_, w) = common::walker("compass");
    let s0 = Sample {
        t_s: 0.0,
        q: w.guess.q.clone(),
        qd: w.guess.qd.clone(),
    };
    (w, s0)
}

#[test]
fn energy_is_conserved_in_passive_swing_with_error_shrinking_at_each_order() {
    let (w, s0) = compass_swing();
    let t_end = 0.25; // inside single stance (heel strike is at ~0.73 s)
    let e0 = energy(w.walker.model(), &s0);
    let mut sys = Phase::new(w.walker.model());
    // The accuracy reference conserves energy to rounding.
    let r = reference(&mut sys, &s0, t_end);
    assert!((energy(w.walker.model(), &r) - e0).abs() < 1e-11);
    let steps = [50, 100, 200, 400];
    let rk4: Vec<f64> = steps
        .iter()
        .map(|&n| {
            (energy(
                w.walker.model(),
                &integrate(&IntegratorChoice::Rk4 { h_s: 0.0 }, &mut sys, &s0, t_end, n),
            ) - e0)
                .abs()
        })
        .collect();
    for p in orders(&rk4[..3]) {
        assert!((3.7..4.4).contains(&p), "rk4 energy order {p} ({rk4:?})");
    }
    // The compass gait depends strongly on q̇ (Coriolis terms): Meijaard's scheme is first order
    // there, as the paper says (E = O(h)).
    let mj: Vec<f64> = steps
        .iter()
        .map(|&n| {
            let ch = IntegratorChoice::Meijaard {
                h_s: 0.0,
                check_every: 0,
            };
            (energy(w.walker.model(), &integrate(&ch, &mut sys, &s0, t_end, n)) - e0).abs()
        })
        .collect();
    for p in orders(&mj) {
        assert!(
            (0.9..1.4).contains(&p),
            "meijaard energy order {p} ({mj:?})"
        );
    }
    // Dopri5's error shrinks with its tolerance.
    let mut last = f64::INFINITY;
    for rtol in [1e-6, 1e-8, 1e-10] {
        let mut integ = IntegratorChoice::Dopri5 {
            rtol,
            atol: rtol,
            h_max_s: 0.05,
        }
        .build();
        let mut s = s0.clone();
        while s.t_s < t_end - 1e-15 {
            s = integ.advance(&mut sys, &s, t_end - s.t_s).unwrap();
        }
        let e = (energy(w.walker.model(), &s) - e0).abs();
        assert!(e < last && e < 100.0 * rtol, "dopri5 rtol {rtol}: {e}");
        last = e;
    }
}

/// A pendulum: one revolute link with a point mass, optionally damped.
fn pendulum(damping: f64) -> Model {
    let mut m = Model::new(Vector3::new(0.0, -9.81, 0.0));
    m.add_link(
        "arm",
        None,
        Vector3::zeros(),
        JointKind::Revolute {
            axis_parent: Vector3::z(),
        },
        JointForce {
            damping,
            ..Default::default()
        },
        BodyInertia {
            mass_kg: 1.0,
            p_link_com_m: Vector3::new(0.0, -1.0, 0.0),
            ..BodyInertia::massless()
        },
    )
    .unwrap();
    m
}

fn state_errors(model: &Model, ch: &IntegratorChoice, s0: &Sample, t_end: f64) -> Vec<f64> {
    let mut sys = Phase::new(model);
    let r = reference(&mut sys, s0, t_end);
    [40, 80, 160, 320]
        .iter()
        .map(|&n| {
            let s = integrate(ch, &mut sys, s0, t_end, n);
            (&s.q - &r.q).amax().max((&s.qd - &r.qd).amax())
        })
        .collect()
}

#[test]
fn meijaard_is_second_order_without_velocity_dependence_and_first_order_with_strong_damping() {
    let s0 = Sample {
        t_s: 0.0,
        q: DVector::from_element(1, 0.5),
        qd: DVector::from_element(1, 0.0),
    };
    let ch = IntegratorChoice::Meijaard {
        h_s: 0.0,
        check_every: 0,
    };
    let undamped = state_errors(&pendulum(0.0), &ch, &s0, 2.0);
    for p in orders(&undamped) {
        assert!((1.8..2.3).contains(&p), "undamped order {p} ({undamped:?})");
    }
    let damped = state_errors(&pendulum(4.0), &ch, &s0, 2.0);
    for p in orders(&damped) {
        assert!((0.8..1.3).contains(&p), "damped order {p} ({damped:?})");
    }
    let rk4 = state_errors(
        &pendulum(4.0),
        &IntegratorChoice::Rk4 { h_s: 0.0 },
        &s0,
        2.0,
    );
    for p in orders(&rk4) {
        assert!((3.7..4.4).contains(&p), "rk4 order {p} ({rk4:?})");
    }
}

#[test]
fn angular_momentum_about_the_new_contact_is_conserved_across_heel_strike() {
    for name in ["compass", "kneed2d"] {
        let (_, w) = common::walker(name);
        let g = common::gait(&w);
        let active: Vec<bool> = (0..w.walker.model().dof())
            .map(|i| !w.walker.knees().iter().any(|k| k.coordinate.0 == i))
            .collect();
        let imp = w
            .walker
            .heel_strike_impact(&g.stride.pre_impact, &active)
            .unwrap();
        let mut d = Dynamics::new(w.walker.impact_model());
        d.assemble(w.walker.impact_model(), &imp.q, &imp.qd_minus, None);
        let before = d.angular_momentum_about(w.walker.impact_model(), &imp.p_contact_m);
        d.assemble(w.walker.impact_model(), &imp.q, &imp.qd_plus, None);
        let after = d.angular_momentum_about(w.walker.impact_model(), &imp.p_contact_m);
        assert!(
            (before - after).norm() < 1e-12 * (1.0 + before.norm()),
            "{name}: {before} vs {after}"
        );
        // And the impact is dissipative and the new contact is at rest.
        assert!(imp.energy_loss_j > 0.0);
        // Angular momentum about the old contact is NOT conserved (the check could fail).
        d.assemble(w.walker.impact_model(), &imp.q, &imp.qd_minus, None);
        let b0 = d.angular_momentum_about(w.walker.impact_model(), &Vector3::zeros());
        d.assemble(w.walker.impact_model(), &imp.q, &imp.qd_plus, None);
        let a0 = d.angular_momentum_about(w.walker.impact_model(), &Vector3::zeros());
        assert!((b0 - a0).norm() > 1e-3, "{name}");
    }
}

/// A random spatial chain: 2-6 links with random axes, offsets and inertias.
fn random_chain(
    axes: &[[f64; 3]],
    offsets: &[[f64; 3]],
    masses: &[f64],
    inertias: &[[f64; 3]],
) -> Model {
    let mut m = Model::new(Vector3::new(0.0, -9.81, 0.0));
    let mut parent: Option<String> = None;
    for i in 0..axes.len() {
        let name = format!("l{i}");
        let [a, b, c] = inertias[i];
        // Principal moments obeying the triangle inequality.
        let d = Matrix3::from_diagonal(&Vector3::new(a + b, b + c, a + c));
        m.add_link(
            &name,
            parent.as_deref(),
            Vector3::from(offsets[i]),
            JointKind::Revolute {
                axis_parent: Vector3::from(axes[i]),
            },
            JointForce::default(),
            BodyInertia {
                mass_kg: masses[i],
                p_link_com_m: Vector3::from(offsets[i]) * 0.5,
                inertia_com_kg_m2: d,
                infinitesimal: false,
            },
        )
        .unwrap();
        parent = Some(name);
    }
    m
}

fn axis() -> impl Strategy<Value = [f64; 3]> {
    prop::array::uniform3(-1.0..1.0f64)
        .prop_filter("non-zero", |a| a.iter().map(|x| x * x).sum::<f64>() > 0.01)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn mass_matrix_is_symmetric_positive_definite(
        n in 2usize..6,
        axes in prop::collection::vec(axis(), 6),
        offsets in prop::collection::vec(prop::array::uniform3(-0.5..0.5f64), 6),
        masses in prop::collection::vec(0.1..5.0f64, 6),
        inertias in prop::collection::vec(prop::array::uniform3(0.001..0.1f64), 6),
        q in prop::collection::vec(-3.0..3.0f64, 6),
        qd in prop::collection::vec(-3.0..3.0f64, 6),
    ) {
        let m = random_chain(&axes[..n], &offsets[..n], &masses[..n], &inertias[..n]);
        let (q, qd) = (DVector::from_column_slice(&q[..n]), DVector::from_column_slice(&qd[..n]));
        let mut d = Dynamics::new(&m);
        d.assemble(&m, &q, &qd, None);
        let mm = &d.mass_matrix;
        prop_assert!((mm - mm.transpose()).amax() < 1e-12 * mm.amax());
        let eig = mm.clone().symmetric_eigen().eigenvalues;
        prop_assert!(eig.min() > 0.0, "eigenvalues {eig:?}");
        // q̇ᵀ M̄ q̇ equals twice the kinetic energy summed body by body from finite differences
        // of positions and orientations: an independent check of F,q.
        let eps = 1e-6;
        let mut kp = sim::engine::kinematics::Kinematics::new(&m);
        let mut km = sim::engine::kinematics::Kinematics::new(&m);
        kp.update(&m, &(&q + &qd * eps), &qd);
        km.update(&m, &(&q - &qd * eps), &qd);
        let mut two_t = 0.0;
        for (i, l) in m.links.iter().enumerate() {
            let li = sim::engine::model::LinkIndex(i);
            let v = (kp.position_of(li, &l.body.p_link_com_m) - km.position_of(li, &l.body.p_link_com_m)) / (2.0 * eps);
            let rdot = (kp.r_floor_link[i] - km.r_floor_link[i]) / (2.0 * eps);
            let r = (kp.r_floor_link[i] + km.r_floor_link[i]) * 0.5;
            let w_skew = rdot * r.transpose();
            let w = Vector3::new(w_skew[(2, 1)], w_skew[(0, 2)], w_skew[(1, 0)]);
            let iw = r * l.body.inertia_com_kg_m2 * r.transpose();
            two_t += l.body.mass_kg * v.norm_squared() + w.dot(&(iw * w));
        }
        let qmq = qd.dot(&(mm * &qd));
        prop_assert!((qmq - two_t).abs() < 1e-6 * (1.0 + two_t), "{qmq} vs {two_t}");
    }

    #[test]
    fn mirroring_link_states_is_an_involution_and_mirrors_the_body(
        angles in prop::collection::vec(-3.0..3.0f64, 3),
        p in prop::array::uniform3(-1.0..1.0f64),
        w in prop::array::uniform3(-1.0..1.0f64),
        v in prop::array::uniform3(-1.0..1.0f64),
        b in prop::array::uniform3(-1.0..1.0f64),
    ) {
        let s = link_state(&angles, p, w, v);
        let m = s.mirrored();
        // The mirrored state is the mirror image of the body: every point of it, where it is
        // and how it moves (which the identity, or a reflection that forgets ω is an axial
        // vector, or an improper rotation, all fail: `a_wrong_mirror_fails_the_mirror_check`).
        prop_assert!(mirror_residual(&s, &m, &b.into()) < 1e-14);
        let back = m.mirrored();
        prop_assert!((back.r[0] - s.r[0]).amax() < 1e-15);
        prop_assert!((back.p[0] - Vector3::from(p)).amax() < 1e-15);
        prop_assert!((back.w[0] - Vector3::from(w)).amax() < 1e-15);
        prop_assert!((back.v[0] - Vector3::from(v)).amax() < 1e-15);
    }
}

/// One link's state from three Euler angles [rad], its origin [m], angular velocity [rad/s]
/// and origin velocity [m/s].
fn link_state(angles: &[f64], p: [f64; 3], w: [f64; 3], v: [f64; 3]) -> LinkStates {
    let r = sim::engine::rotation_about(&Vector3::x(), angles[0])
        * sim::engine::rotation_about(&Vector3::y(), angles[1])
        * sim::engine::rotation_about(&Vector3::z(), angles[2]);
    LinkStates {
        r: vec![r],
        p: vec![p.into()],
        w: vec![w.into()],
        v: vec![v.into()],
    }
}

/// How far `m` is from the mirror image of `s` about the sagittal plane (z → −z), checked on
/// the body point at `b_link` (link frame of `s`) by kinematics alone: the mirrored link is a
/// proper rotation, and the point of it at the mirrored link coordinates `S b` is where the
/// mirror image of `s`'s point is (`S (p + R b)`), moving as the image moves
/// (`S (v + ω × R b)`). The largest of the three residuals.
fn mirror_residual(s: &LinkStates, m: &LinkStates, b_link: &Vector3<f64>) -> f64 {
    let reflect = |x: &Vector3<f64>| Vector3::new(x.x, x.y, -x.z);
    let (r, p, w, v) = (&s.r[0], &s.p[0], &s.w[0], &s.v[0]);
    let (rm, pm, wm, vm) = (&m.r[0], &m.p[0], &m.w[0], &m.v[0]);
    let arm = r * b_link;
    let arm_m = rm * reflect(b_link);
    let position = (pm + arm_m - reflect(&(p + arm))).amax();
    let velocity = (vm + wm.cross(&arm_m) - reflect(&(v + w.cross(&arm)))).amax();
    let proper = (rm.determinant() - 1.0).abs();
    position.max(velocity).max(proper)
}

#[test]
fn a_wrong_mirror_fails_the_mirror_check() {
    // The check of the property above can fail: the identity, a reflection of ω as if it
    // were a polar vector, and the improper rotation S R each miss it by far.
    let s = link_state(
        &[0.3, -0.7, 1.1],
        [0.2, 0.9, -0.4],
        [0.5, -0.3, 0.8],
        [-0.6, 0.1, 0.7],
    );
    let b = Vector3::new(0.3, -0.2, 0.5);
    assert!(mirror_residual(&s, &s.mirrored(), &b) < 1e-14);
    let reflection = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0));
    let identity = s.clone();
    let mut polar_w = s.mirrored();
    polar_w.w[0] = reflection * s.w[0];
    let mut improper = s.mirrored();
    improper.r[0] = reflection * s.r[0];
    for (name, wrong) in [
        ("identity", &identity),
        ("ω reflected as a polar vector", &polar_w),
        ("S R", &improper),
    ] {
        let e = mirror_residual(&s, wrong, &b);
        assert!(e > 0.1, "{name}: residual {e}");
    }
}

#[test]
fn relabelling_twice_returns_the_configuration() {
    // Relabelling re-roots at the other foot (and mirrors, for 3D walkers); doing it twice must
    // give back the original coordinates, up to the cyclic heading, which it zeroes. Coordinates
    // locked at a stride's start (the toe pitch of a flat foot) are taken at that value, since
    // the swing foot is not modelled.
    for name in ["compass", "kneed2d", "simplest", "wisse2d", "wisse3d"] {
        let (_, w) = common::walker(name);
        let g = common::gait(&w);
        let mut q0 = g.stride.pre_impact.q.clone();
        for c in w.walker.initially_locked() {
            q0[c.0] = 0.0;
        }
        let zero = DVector::zeros(w.walker.model().dof());
        let relabel_once = |q: &DVector<f64>| {
            let mut kin = sim::engine::kinematics::Kinematics::new(w.walker.model());
            kin.update(w.walker.model(), q, &zero);
            let foot = kin.point_position(w.walker.model(), w.walker.heel_strike().swing_foot);
            let states = LinkStates::from_kinematics(&kin, 0, &foot);
            w.walker
                .relabel()
                .solve(w.walker.model(), &states, q)
                .unwrap()
                .q
        };
        let once = relabel_once(&q0);
        assert!(
            (&once - &q0).amax() > 1e-3,
            "{name}: relabelling must change the labels"
        );
        let twice = relabel_once(&once);
        for c in &w.walker.relabel().cyclic {
            q0[c.0] = 0.0;
        }
        assert!((&twice - &q0).amax() < 1e-10, "{name}: {twice} vs {q0}");
    }
}

#[test]
fn stride_jacobian_eigenvalues_converge_as_the_perturbation_shrinks() {
    for name in ["compass", "simplest"] {
        let (_, w) = common::walker(name);
        let g = common::gait(&w);
        let s = common::stride_map(&w, &g.fixed_point).unwrap().0;
        let spectral = |d: f64| {
            let set = sim::analysis::limit_cycle::NewtonSettings {
                perturbation: d,
                ..Default::default()
            };
            let j = GaitSearch::new(&w.walker, &w.settings, &set)
                .stride_jacobian(&g.fixed_point, &s)
                .unwrap();
            j.complex_eigenvalues()
                .iter()
                .map(|z| z.norm())
                .fold(0.0, f64::max)
        };
        let reference = spectral(1e-6);
        let errors: Vec<f64> = [4e-3, 1e-3, 2.5e-4]
            .iter()
            .map(|&d| (spectral(d) - reference).abs())
            .collect();
        // Central differences: the error falls like d², a factor ~16 per quartering of the step.
        assert!(
            errors[0] > 8.0 * errors[1] && errors[1] > 8.0 * errors[2],
            "{name}: {errors:?}"
        );
        assert!(errors[2] < 1e-3, "{name}: {errors:?}");
    }
}
