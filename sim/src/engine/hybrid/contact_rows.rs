//! The heel-strike constraint rows: the stance-labelled state moved onto the impact model
//! (whose released root joints come first, at rest), and the rows `G` of the constrained
//! directions of the swing foot's contact, in any scalar.

use super::heel_strike::{ContactConstraint, HeelStrikeRule};
use super::konst;
use crate::engine::kinematics::KinematicsOf;
use crate::engine::model::{LinkIndex, Model};
use nalgebra::{DMatrix, DVector, RealField, Vector3};

/// A row whose entries are all below this (in magnitude) is identically zero: a constraint on
/// a direction no coordinate can move.
const ZERO_ROW: f64 = 1e-12;

/// The impact model's state at heel strike and its contact constraint rows.
#[derive(Clone, Debug)]
pub struct HeelStrikeRows<T: nalgebra::Scalar> {
    /// Coordinates of the impact model: the released joints (zero) then the stance ones.
    pub q: DVector<T>,
    /// Velocities of the impact model [rad/s or m/s], ordered as `q`.
    pub qd: DVector<T>,
    /// Free coordinates of the impact model (the released joints are free).
    pub active: Vec<bool>,
    /// Constraint rows `G` (k × n of the impact model), zero rows dropped.
    pub g: DMatrix<T>,
    /// The new contact point, the swing foot, in the floor frame \[m\].
    pub p_contact_m: Vector3<T>,
}

/// The heel-strike rows for the stance-labelled state `q`, `qd` with free coordinates
/// `active`: X, Y, Z from the swing foot's point Jacobian and Yaw (rotation about the floor
/// normal) from its link's angular Jacobian, on `impact_model`. A row that is identically
/// zero (e.g. yaw in a 2D variant) holds trivially and is dropped.
pub fn heel_strike_rows<T: RealField + Copy>(
    impact_model: &Model,
    rule: &HeelStrikeRule,
    q: &DVector<T>,
    qd: &DVector<T>,
    active: &[bool],
) -> HeelStrikeRows<T> {
    let m = impact_model;
    let nr = rule.release.len();
    let n = m.dof();
    let mut qi = DVector::zeros(n);
    let mut qdi = DVector::zeros(n);
    qi.rows_mut(nr, n - nr).copy_from(q);
    qdi.rows_mut(nr, n - nr).copy_from(qd);
    let mut act = vec![true; nr];
    act.extend_from_slice(active);
    let mut kin: KinematicsOf<T> = KinematicsOf::new(m);
    kin.update(m, &qi, &qdi);
    let foot = &m.points[rule.swing_foot.0];
    let p_foot = kin.position_of(foot.link, &foot.p_link_m);
    let jv = kin.point_jacobian(m, foot.link, &p_foot);
    let jw = kin.angular_jacobian(m, LinkIndex(rule.swing_foot_link.0 + nr));
    let zero: T = konst(ZERO_ROW);
    let rows: Vec<_> = rule
        .constraints
        .iter()
        .map(|c| match c {
            ContactConstraint::X => jv.row(0),
            ContactConstraint::Y => jv.row(1),
            ContactConstraint::Z => jv.row(2),
            ContactConstraint::Yaw => jw.row(1),
        })
        .filter(|r| r.iter().any(|x| x.abs() > zero))
        .collect();
    let mut g = DMatrix::zeros(rows.len(), n);
    for (r, row) in rows.iter().enumerate() {
        g.row_mut(r).copy_from(row);
    }
    HeelStrikeRows {
        q: qi,
        qd: qdi,
        active: act,
        g,
        p_contact_m: p_foot,
    }
}
