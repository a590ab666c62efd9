//! The general engine's evaluation (`Dynamics::assemble`, `Kinematics::update`) against the
//! arithmetic it had before issue 15's fifth round, written out here from the model: every
//! joint's rotation by the general axis-angle formula and a full 3 × 3 product, and each body's
//! `m Jvᵀ Jv + Jwᵀ I Jw` added to both triangles of `M̄` over full-length Jacobians. The engine
//! now rotates coordinate-axis joints by mixing two columns, sums one triangle over each body's
//! ancestry and mirrors it: the same equations of motion to rounding.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, missing_docs)]

mod common;

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use sim::engine::dynamics::Dynamics;
use sim::engine::model::{JointKind, LinkIndex, Model};
use sim::engine::rotation_about;

fn noise(k: &mut u64) -> f64 {
    *k = k
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    ((*k >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

/// Rotation, origin, axis, angular and linear velocity, and their bias accelerations, of every
/// link: the recursion of `Kinematics::update` with the general rotation formula.
#[allow(clippy::type_complexity)]
fn reference_kinematics(
    model: &Model,
    q: &DVector<f64>,
    qd: &DVector<f64>,
) -> Vec<(Matrix3<f64>, Vector3<f64>, Vector3<f64>, [Vector3<f64>; 4])> {
    let mut out: Vec<(Matrix3<f64>, Vector3<f64>, Vector3<f64>, [Vector3<f64>; 4])> = Vec::new();
    for link in &model.links {
        let z = Vector3::zeros();
        let (r_p, p_p, [w_p, v_p, al_p, a_p]) = match link.parent {
            Some(p) => (out[p.0].0, out[p.0].1, out[p.0].3),
            None => (Matrix3::identity(), z, [z; 4]),
        };
        let d = r_p * link.p_parent_joint_m;
        let o = p_p + d;
        let v_o = v_p + w_p.cross(&d);
        let a_o = a_p + al_p.cross(&d) + w_p.cross(&w_p.cross(&d));
        let (qi, qdi) = link.coordinate.map_or((0.0, 0.0), |c| (q[c.0], qd[c.0]));
        out.push(match &link.joint {
            JointKind::Revolute { axis_parent } => {
                let a = r_p * axis_parent;
                let r = r_p * rotation_about(axis_parent, qi);
                (
                    r,
                    o,
                    a,
                    [w_p + a * qdi, v_o, al_p + w_p.cross(&a) * qdi, a_o],
                )
            }
            JointKind::Prismatic { axis_parent } => {
                let a = r_p * axis_parent;
                let s = a * qi;
                let a_lin =
                    a_o + al_p.cross(&s) + w_p.cross(&w_p.cross(&s)) + w_p.cross(&a) * (qdi + qdi);
                (
                    r_p,
                    o + s,
                    a,
                    [w_p, v_o + w_p.cross(&s) + a * qdi, al_p, a_lin],
                )
            }
            JointKind::Weld => (r_p, o, z, [w_p, v_o, al_p, a_o]),
        });
    }
    out
}

/// `M̄`, `M̄_ε`, `f̄`, `f̄_ε` summed body by body over full 3 × n Jacobians, both triangles.
fn reference_assembly(
    model: &Model,
    q: &DVector<f64>,
    qd: &DVector<f64>,
) -> (DMatrix<f64>, DMatrix<f64>, DVector<f64>, DVector<f64>) {
    let n = model.dof();
    let kin = reference_kinematics(model, q, qd);
    let (mut m, mut me) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n));
    let (mut f, mut fe) = (DVector::zeros(n), DVector::zeros(n));
    for (i, link) in model.links.iter().enumerate() {
        let b = &link.body;
        let (r, p, _, [w, _, alpha, _]) = kin[i];
        let p_com = p + r * b.p_link_com_m;
        let rel = p_com - p;
        let a_bias = kin[i].3[3] + alpha.cross(&rel) + w.cross(&w.cross(&rel));
        let (mut jv, mut jw) = (DMatrix::zeros(3, n), DMatrix::zeros(3, n));
        for l in model.ancestry(LinkIndex(i)) {
            let lk = &model.links[l.0];
            let Some(c) = lk.coordinate else { continue };
            let a = kin[l.0].2;
            if matches!(lk.joint, JointKind::Revolute { .. }) {
                jv.set_column(c.0, &a.cross(&(p_com - kin[l.0].1)));
                jw.set_column(c.0, &a);
            } else {
                jv.set_column(c.0, &a);
            }
        }
        let i_w = r * b.inertia_com_kg_m2 * r.transpose();
        let body_m = jv.transpose() * &jv * b.mass_kg + jw.transpose() * i_w * &jw;
        let torque = -(i_w * alpha) - w.cross(&(i_w * w));
        let f_lin = (model.gravity_floor_m_s2 - a_bias) * b.mass_kg;
        let body_f = jv.transpose() * f_lin + jw.transpose() * torque;
        if b.infinitesimal {
            me += body_m;
            fe += body_f;
        } else {
            m += body_m;
            f += body_f;
        }
    }
    for link in &model.links {
        if let Some(c) = link.coordinate {
            let jf = &link.joint_force;
            f[c.0] -= (q[c.0] - jf.rest_position) * jf.stiffness + qd[c.0] * jf.damping;
        }
    }
    (m, me, f, fe)
}

fn relative(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (a - b).amax() / b.amax().max(1e-300)
}

#[test]
fn the_general_evaluation_equals_the_reference_arithmetic_on_random_states() {
    let mut seed = 41u64;
    let mut worst = 0.0f64;
    for name in ["wisse3d", "wisse2d", "kneed2d", "compass", "simplest"] {
        let (_, w) = common::walker(name);
        // The stance model and the impact model with its released root (prismatic joints).
        for model in [w.walker.model(), w.walker.impact_model()] {
            let n = model.dof();
            let mut dynamics = Dynamics::new(model);
            for _ in 0..50 {
                let q = DVector::from_fn(n, |_, _| 1.2 * noise(&mut seed));
                let qd = DVector::from_fn(n, |_, _| 3.0 * noise(&mut seed));
                dynamics.assemble(model, &q, &qd, None);
                let (m, me, f, fe) = reference_assembly(model, &q, &qd);
                let kin = reference_kinematics(model, &q, &qd);
                for (i, (r, p, a, _)) in kin.iter().enumerate() {
                    let d = (r - dynamics.kin.r_floor_link[i]).amax()
                        + (p - dynamics.kin.p_floor_link_m[i]).amax()
                        + (a - dynamics.kin.axis_floor[i]).amax();
                    assert!(d < 1e-14, "{name}: link {i} pose differs by {d:e}");
                }
                let dm = relative(&dynamics.mass_matrix, &m);
                let df = (&dynamics.force - &f).amax() / f.amax().max(1.0);
                assert!(dm < 1e-13 && df < 1e-13, "{name}: M̄ {dm:e}, f̄ {df:e}");
                assert_eq!(
                    dynamics.mass_matrix,
                    dynamics.mass_matrix.transpose(),
                    "{name}"
                );
                if model.has_infinitesimal_bodies() {
                    let dme = relative(&dynamics.mass_matrix_infinitesimal, &me);
                    let dfe = (&dynamics.force_infinitesimal - &fe).amax() / fe.amax().max(1.0);
                    assert!(dme < 1e-13 && dfe < 1e-13, "{name}: M̄ε {dme:e}, f̄ε {dfe:e}");
                } else {
                    assert_eq!(dynamics.mass_matrix_infinitesimal.amax(), 0.0);
                }
                worst = worst.max(dm).max(df);
            }
        }
    }
    // Not bit for bit (the coordinate-axis rotations round differently), but to rounding.
    assert!(worst < 1e-14, "{worst:e}");
}

#[test]
fn the_partial_assembly_gives_the_full_assemblys_accelerations_to_the_bit() {
    let mut seed = 5u64;
    let mut compared = 0;
    for name in ["wisse3d", "wisse2d", "kneed2d"] {
        let (_, w) = common::walker(name);
        let model = w.walker.model();
        let n = model.dof();
        let (mut full, mut partial) = (Dynamics::new(model), Dynamics::new(model));
        for trial in 0..60 {
            let q = DVector::from_fn(n, |i, _| w.guess.q[i] + 0.3 * noise(&mut seed));
            let qd = DVector::from_fn(n, |i, _| w.guess.qd[i] + noise(&mut seed));
            // Some coordinates locked, and every third trial one of them driven.
            let active: Vec<bool> = (0..n).map(|_| noise(&mut seed) > -0.4).collect();
            let driven = (trial % 3 == 0)
                .then(|| (0..n).find(|&j| !active[j]))
                .flatten();
            let prescribed = driven.map(|j| {
                let mut p = DVector::zeros(n);
                p[j] = 5.0 * noise(&mut seed);
                p
            });
            let (mut a, mut b) = (DVector::zeros(n), DVector::zeros(n));
            let ra = full.accelerations_into(model, &q, &qd, &active, prescribed.as_ref(), &mut a);
            let rb = partial.accelerations_of_free_into(
                model,
                &q,
                &qd,
                &active,
                prescribed.as_ref(),
                &mut b,
            );
            assert_eq!(ra.is_ok(), rb.is_ok(), "{name}");
            if ra.is_ok() {
                assert_eq!(a, b, "{name}: trial {trial}");
                compared += 1;
            }
        }
    }
    assert!(compared > 100, "{compared}");
}
