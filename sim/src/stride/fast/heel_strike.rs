//! Heel strike on the planar tree: the general `finish_stride` (impact on the impact model with
//! the stance contact released, lift check, relabelling) for planar walkers with the stance
//! contact released in x and y and a relabelling by link pairs without mirror or cyclic
//! coordinates. The impact is eq. (21) with the root's translation `v0` added to the
//! coordinates (`M_imp = [[m I, Σ m Jv], [·ᵀ, M̄]]`, finite and infinitesimal parts from the
//! planar tree), solved by the general impact's KKT system and vanishing-mass limit (with infinitesimal
//! bodies) or by the same KKT system on fixed-capacity arrays (`impact.rs`, finite bodies); the
//! relabelling is closed-form (each new link takes its old twin's angle and
//! angular velocity, the joint coordinates are the differences along the tree) and then
//! checked against every pair as the general Gauss-Newton is. Anything else, or a check that
//! does not hold, is left to the general `finish_stride` (`None`).

use super::dop853::State;
use super::impact::{FiniteImpact, MAX_ROWS, MAX_VELOCITIES};
use crate::engine::hybrid::impact::kkt_system;
use crate::engine::model::{JointKind, Model, PointIndex};
use crate::engine::planar::{LinkFrame, PlanarTree, MAX_LINKS};
use crate::engine::singular_limit::solve_limit;
use crate::engine::walker::{ContactConstraint, Walker};
use nalgebra::{DMatrix, DVector, SMatrix, SVector, Vector3};

/// What heel strike hands to the stride's result.
pub(super) struct Relabelled {
    /// Coordinates and velocities at the start of the next stride.
    pub(super) q_next: DVector<f64>,
    pub(super) qd_next: DVector<f64>,
    /// The new contact point in the old stance frame [m].
    pub(super) step_m: Vector3<f64>,
    /// Upward velocity of the old stance contact just after the impact [m/s].
    pub(super) lift_velocity_m_s: f64,
    /// Kinetic energy lost in the impact [J].
    pub(super) energy_loss_j: f64,
}

/// Whether the walker's heel strike is one this module covers.
fn covered(walker: &Walker) -> bool {
    let hs = walker.heel_strike();
    let axis = |k: &JointKind, x: f64, y: f64| matches!(k, JointKind::Prismatic { axis_parent } if axis_parent.x == x && axis_parent.y == y && axis_parent.z == 0.0);
    let release_xy =
        hs.release.len() == 2 && axis(&hs.release[0], 1.0, 0.0) && axis(&hs.release[1], 0.0, 1.0);
    let rows = hs.constraints.iter().all(|c| {
        matches!(
            c,
            ContactConstraint::X
                | ContactConstraint::Y
                | ContactConstraint::Z
                | ContactConstraint::Yaw
        )
    });
    let r = walker.relabel();
    release_xy && rows && !r.mirror && r.cyclic.is_empty()
}

/// A point's x-y in its link frame and its height along z (constant on a planar tree: every
/// rotation is about z) [m].
fn point_of(model: &Model, p: PointIndex) -> Option<(usize, [f64; 2], f64)> {
    let point = model.points.get(p.0)?;
    let mut z = point.p_link_m.z;
    let mut cur = Some(point.link.0);
    while let Some(l) = cur {
        let link = model.links.get(l)?;
        z += link.p_parent_joint_m.z;
        cur = link.parent.map(|p| p.0);
    }
    Some((point.link.0, [point.p_link_m.x, point.p_link_m.y], z))
}

/// Absolute angles of every link slot (slot 0 the ground) from `q` or rates from `qd`.
fn link_angles<const N: usize>(tree: &PlanarTree, q: &SVector<f64, N>) -> [f64; MAX_LINKS + 1] {
    let mut a = [0.0; MAX_LINKS + 1];
    for i in 0..tree.links().link_count() {
        if let Some((parent, joint)) = tree.links().link_joint(i) {
            a[i + 1] = a[parent] + joint.map_or(0.0, |(c, sign)| sign * q[c]);
        }
    }
    a
}

/// The impact model's mass matrix `M_imp = [[m I, Σ m Jv], [·ᵀ, M̄]]` (velocities: the root's
/// translation in x and y, then the coordinates) from the tree's mass and momentum Jacobian
/// ([`PlanarTree::momentum_jacobian`]) and `M̄`, as entries `(i, j)`.
fn impact_mass<const N: usize>(
    (mass_kg, jac): (f64, SMatrix<f64, 2, N>),
    m_q: SMatrix<f64, N, N>,
) -> impl Fn(usize, usize) -> f64 {
    move |i, j| match (i < 2, j < 2) {
        (true, true) => {
            if i == j {
                mass_kg
            } else {
                0.0
            }
        }
        (true, false) => jac[(i, j - 2)],
        (false, true) => jac[(j, i - 2)],
        (false, false) => m_q[(i - 2, j - 2)],
    }
}

/// Heel strike at `at` with the free coordinates `active`: the impact, the lift check and the
/// relabelling, or `None` when the general `finish_stride` is to do it.
pub(super) fn heel_strike<const N: usize>(
    walker: &Walker,
    tree: &PlanarTree,
    at: &State<N>,
    active: &[bool; N],
) -> Option<Relabelled> {
    if !covered(walker) {
        return None;
    }
    let hs = walker.heel_strike();
    let model = walker.model();
    let (foot_link, foot_p, foot_z) = point_of(model, hs.swing_foot)?;
    let (sc_link, sc_p, _) = point_of(model, hs.stance_contact)?;
    let fr = tree.links().frames(&at.q, &at.qd);
    let (p_foot, _) = fr.get(foot_link + 1)?.point(foot_p);
    // The impact model's velocities u = (v0, q̇): the root's translation first, at rest.
    let n = N + 2;
    if n > MAX_VELOCITIES {
        return None;
    }
    let (m_q, m_q_eps) = tree.mass_matrices(&at.q);
    let m_imp = impact_mass(tree.links().momentum_jacobian::<N>(&fr, false), m_q);
    let jf = tree.links().point_jacobian::<N>(&fr, foot_link, foot_p);
    // Constraint rows of the contact: x and y (z and yaw rows vanish on a planar tree, and the
    // general rows drop them).
    let mut rows = [0usize; MAX_ROWS];
    let mut k = 0;
    for c in &hs.constraints {
        let d = match c {
            ContactConstraint::X => 0,
            ContactConstraint::Y => 1,
            _ => continue,
        };
        *rows.get_mut(k)? = d;
        k += 1;
    }
    let g = |r: usize, j: usize| {
        let d = rows[r];
        if j < 2 {
            if j == d {
                1.0
            } else {
                0.0
            }
        } else {
            jf[(d, j - 2)]
        }
    };
    let mut u_minus = [0.0; MAX_VELOCITIES];
    u_minus[2..n].copy_from_slice(at.qd.as_slice());
    // G u⁻ · (−e), as the general `&g * &u_minus * (−e)`.
    let mut target = [0.0; MAX_ROWS];
    for (r, t) in target.iter_mut().enumerate().take(k) {
        *t = (0..n).fold(0.0, |acc, j| acc + g(r, j) * u_minus[j]) * (-hs.restitution);
    }
    let mut free = [true; MAX_VELOCITIES];
    free[2..n].copy_from_slice(active);
    let u_plus = if tree.has_infinitesimal() {
        // The general impact's equations and solve (`impact::resolve_to`): the KKT system of
        // the finite part and of the infinitesimal one, and their vanishing-mass limit.
        let free: Vec<usize> = (0..n).filter(|&i| free[i]).collect();
        let g_rows = DMatrix::from_fn(k, n, &g);
        let u = DVector::from_column_slice(&u_minus[..n]);
        let t = DVector::from_column_slice(&target[..k]);
        let (a0, b0) = kkt_system(&DMatrix::from_fn(n, n, &m_imp), &free, &u, &g_rows, &t);
        let m_imp_eps = DMatrix::from_fn(
            n,
            n,
            impact_mass(tree.links().momentum_jacobian::<N>(&fr, true), m_q_eps),
        );
        let no_rows = DMatrix::zeros(k, n);
        let no_target = DVector::zeros(k);
        let (a1, b1) = kkt_system(&m_imp_eps, &free, &u, &no_rows, &no_target);
        let x = solve_limit(&a0, &a1, &b0, &b1, 1e-12).ok()?;
        let mut u_plus = u_minus;
        for (j, &i) in free.iter().enumerate() {
            u_plus[i] = *x.get(j)?;
        }
        u_plus
    } else {
        // Without infinitesimal bodies the limit is the finite system itself, solved directly
        // on fixed-capacity arrays (`impact.rs`). A pivot that is zero up to rounding
        // (redundant contact constraints) hands the heel strike back to the general impact,
        // which reports it.
        FiniteImpact {
            n,
            mass: &m_imp,
            k,
            rows: &g,
            target,
            free: &free[..n],
            u_minus: &u_minus,
        }
        .solve()?
    };
    if u_plus[..n].iter().any(|v| !v.is_finite()) {
        return None;
    }
    // Kinetic energy ½ uᵀ M_imp u (finite bodies).
    let energy = |u: &[f64; MAX_VELOCITIES]| {
        let mu = |i: usize| (0..n).fold(0.0, |acc, j| acc + m_imp(i, j) * u[j]);
        0.5 * (0..n).fold(0.0, |acc, i| acc + u[i] * mu(i))
    };
    let energy_loss_j = energy(&u_minus) - energy(&u_plus);
    let v0 = [u_plus[0], u_plus[1]];
    let qd_plus = SVector::<f64, N>::from_column_slice(&u_plus[2..n]);
    // The old stance contact must lift.
    let fr_plus = tree.links().frames(&at.q, &qd_plus);
    let (_, v_sc) = fr_plus.get(sc_link + 1)?.point(sc_p);
    let lift_velocity_m_s = v0[1] + v_sc[1];
    if lift_velocity_m_s <= 0.0 {
        return None;
    }
    let (q_next, qd_next) = relabel(walker, tree, at, &fr_plus, v0, p_foot)?;
    Some(Relabelled {
        q_next,
        qd_next,
        step_m: Vector3::new(p_foot[0], p_foot[1], foot_z),
        lift_velocity_m_s,
        energy_loss_j,
    })
}

/// The relabelling: every coordinate link of the model takes its old twin's angle and angular
/// velocity (fixed coordinates zero), then every link and point pair is checked as the general
/// solve checks its residuals. `fr_plus`: the old frames after the impact (root at rest; its
/// translation `v0` added to the velocities); `p_foot`: the new contact, the new origin.
fn relabel<const N: usize>(
    walker: &Walker,
    tree: &PlanarTree,
    at: &State<N>,
    fr_plus: &[LinkFrame; MAX_LINKS + 1],
    v0: [f64; 2],
    p_foot: [f64; 2],
) -> Option<(DVector<f64>, DVector<f64>)> {
    let r = walker.relabel();
    let model = walker.model();
    let angle_old = link_angles(tree, &at.q);
    let mut angle_new = [0.0; MAX_LINKS + 1];
    let mut rate_new = [0.0; MAX_LINKS + 1];
    let (mut q, mut qd) = (SVector::<f64, N>::zeros(), SVector::<f64, N>::zeros());
    for i in 0..tree.links().link_count() {
        let (parent, joint) = tree.links().link_joint(i)?;
        let (angle_parent, rate_parent) = (angle_new[parent], rate_new[parent]);
        if let Some((c, sign)) = joint {
            if !r.fixed.iter().any(|f| f.0 == c) {
                let twin = r.pairs.iter().find(|(new, _)| new.0 == i)?.1 .0 + 1;
                q[c] = sign * (angle_old[twin] - angle_parent);
                qd[c] = sign * (fr_plus[twin].omega_rad_s - rate_parent);
            }
            angle_new[i + 1] = angle_parent + sign * q[c];
            rate_new[i + 1] = rate_parent + sign * qd[c];
        } else {
            angle_new[i + 1] = angle_parent;
            rate_new[i + 1] = rate_parent;
        }
    }
    // The checks: link pairs' angles and rates, point pairs' positions and velocities.
    let fr_new = tree.links().frames(&q, &qd);
    let mut pose = 0.0f64;
    let mut rate = 0.0f64;
    let mut target = 0.0f64;
    for (new, old) in &r.pairs {
        pose = pose.max((angle_new[new.0 + 1] - angle_old[old.0 + 1]).abs());
        rate = rate.max((fr_new[new.0 + 1].omega_rad_s - fr_plus[old.0 + 1].omega_rad_s).abs());
        target = target.max(fr_plus[old.0 + 1].omega_rad_s.abs());
    }
    for (new, old) in &r.point_pairs {
        let (ln, pn, _) = point_of(model, *new)?;
        let (lo, po, _) = point_of(model, *old)?;
        let (p_new, v_new) = fr_new.get(ln + 1)?.point(pn);
        let (p_old, v_old) = fr_plus.get(lo + 1)?.point(po);
        for d in 0..2 {
            pose = pose.max((p_new[d] - (p_old[d] - p_foot[d])).abs());
            rate = rate.max((v_new[d] - (v_old[d] + v0[d])).abs());
            target = target.max((v_old[d] + v0[d]).abs());
        }
    }
    // Max norms against the general solve's Euclidean ones, with a margin.
    let consistent = pose <= 0.1 * r.tolerance && rate <= 1e-9 * (1.0 + target);
    consistent.then(|| {
        (
            DVector::from_column_slice(q.as_slice()),
            DVector::from_column_slice(qd.as_slice()),
        )
    })
}
