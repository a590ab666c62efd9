//! Heel strike as a scene states it: which swing-foot point's height is the witness, what is
//! ignored (scuffs), which directions the new contact constrains, the restitution and the
//! release of the old contact. A rule over the model only; the stride loop and the impact
//! equations ([`super::contact_rows`], [`crate::engine::impact`]) act on it.

use crate::engine::model::{JointKind, LinkIndex, PointIndex};

/// A direction of the swing-foot contact constrained at heel strike.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactConstraint {
    /// Translation along floor x.
    X,
    /// Translation along the floor normal y.
    Y,
    /// Translation along floor z.
    Z,
    /// Rotation of the foot link about the floor normal (no spin).
    Yaw,
}

/// What counts as heel strike, and what is ignored.
#[derive(Clone, Debug, PartialEq)]
pub struct HeelStrikeRule {
    /// The swing-foot point whose height above the floor is the witness (falling through 0).
    pub swing_foot: PointIndex,
    /// The link carrying the swing foot (for the yaw constraint).
    pub swing_foot_link: LinkIndex,
    /// A crossing counts only when the swing foot is at least this far ahead of the stance
    /// contact along x \[m\]; crossings behind it are mid-swing scuffs.
    pub min_ahead_m: f64,
    /// Mid-swing scuffs are ignored (the foot passes through the floor, as in Garcia et al.'s
    /// and McGeer's analyses) rather than ending the stride as a failure.
    pub ignore_scuffing: bool,
    /// Constrained directions at the new contact.
    pub constraints: Vec<ContactConstraint>,
    /// Coefficient of restitution `e` of eq. (20).
    pub restitution: f64,
    /// Joints that become free at the old stance contact during the impact (its release).
    pub release: Vec<JointKind>,
    /// The old stance contact point, which must move upward after the impact.
    pub stance_contact: PointIndex,
}
