//! The joint chain of a planar tree, written once for everything built on it: its joints,
//! parents first, with each link's nearest joint above it ([`Joints`]); and for a serial
//! chain (each joint's link below the previous joint's) the bodies lumped per joint at
//! `q = 0` with the joints' springs and dampers ([`SerialChain`]). The closed forms
//! (`two_link.rs`, `three_link.rs`) and the fixed-size stride's witnesses
//! (`points.rs`) read them.

use super::links::{LinkFrame, PlanarLinks, MAX_LINKS, MAX_PLANAR_COORDINATES};
use nalgebra::SVector;

/// One joint of a planar tree.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct ChainJoint {
    /// Its link (model index; slot `link + 1` of the frames).
    pub(crate) link: usize,
    /// The coordinate it owns.
    pub(crate) coordinate: usize,
    /// The sign of its axis along z.
    pub(crate) sign: f64,
    /// The nearest joint above it, an index into [`Joints::all`] (`None`: on the ground
    /// through welds only).
    pub(crate) parent: Option<usize>,
}

/// A planar tree's joints, parents first, and each link's nearest joint above it (itself
/// included).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Joints {
    joints: [ChainJoint; MAX_PLANAR_COORDINATES],
    len: usize,
    /// Per link: its nearest joint above (itself included), an index into `joints`.
    owner: [Option<usize>; MAX_LINKS],
}

impl Joints {
    /// The joints of `tree`; `None` when it has more than [`MAX_PLANAR_COORDINATES`] joints or
    /// [`MAX_LINKS`] links.
    pub(crate) fn of(tree: &PlanarLinks) -> Option<Self> {
        let mut j = Self {
            joints: [ChainJoint::default(); MAX_PLANAR_COORDINATES],
            len: 0,
            owner: [None; MAX_LINKS],
        };
        for (i, link) in tree.links.iter().enumerate() {
            let above = match link.parent_slot {
                0 => None,
                s => *j.owner.get(s - 1)?,
            };
            *j.owner.get_mut(i)? = match link.coordinate {
                Some((coordinate, sign)) => {
                    *j.joints.get_mut(j.len)? = ChainJoint {
                        link: i,
                        coordinate,
                        sign,
                        parent: above,
                    };
                    j.len += 1;
                    Some(j.len - 1)
                }
                None => above,
            };
        }
        Some(j)
    }

    /// Every joint, parents first.
    pub(crate) fn all(&self) -> &[ChainJoint] {
        &self.joints[..self.len]
    }

    /// The nearest joint above link `link` (model index; itself included), an index into
    /// [`Self::all`]; `None` when the link is welded to the ground or not in the tree.
    pub(crate) fn owner(&self, link: usize) -> Option<usize> {
        self.owner.get(link).copied().flatten()
    }

    /// The joints as a serial chain of `K`: exactly `K` joints, the first on the ground
    /// through welds only, each further one below the previous one; else `None`.
    fn serial<const K: usize>(&self) -> Option<[ChainJoint; K]> {
        let all = self.all();
        let serial = all.len() == K
            && all
                .iter()
                .enumerate()
                .all(|(k, j)| j.parent == k.checked_sub(1));
        serial.then(|| std::array::from_fn(|k| all[k]))
    }
}

/// The bodies rigid with one joint's link, lumped about that joint in its link's frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Lumped {
    /// Mass [kg].
    pub(super) mass_kg: f64,
    /// First moment `Σ m r` about the joint [kg·m].
    pub(super) moment_kg_m: [f64; 2],
    /// Rotational inertia `Σ (I_zz + m |r|²)` about the joint [kg·m²].
    pub(super) inertia_kg_m2: f64,
}

/// A planar tree that is a serial chain of `K` joints, its bodies lumped per joint: what the
/// closed forms are built from.
#[derive(Clone, Copy, Debug)]
pub(super) struct SerialChain<const K: usize> {
    /// Each joint's coordinate and axis sign, the ground's first.
    pub(super) joints: [(usize, f64); K],
    /// `dₖ`: joint `k + 1`'s origin from joint `k`'s at `q = 0` (every rotation the identity
    /// there, so in joint `k`'s link frame), the last one zero [m].
    pub(super) offsets_m: [[f64; 2]; K],
    /// Per part (finite bodies, then infinitesimal ones with their `ε` masses) and joint, the
    /// bodies rigid with the joint's link lumped about it (in the tree's body order).
    pub(super) groups: [[Lumped; K]; 2],
    /// Joint spring and damper per joint: stiffness, rest position, damping.
    pub(super) springs: [(f64, f64, f64); K],
}

impl<const K: usize> SerialChain<K> {
    /// The serial chain of `tree`, or `None` when it is not one of `K` joints on its `K`
    /// coordinates with every body with mass rigid with one of the joints' links.
    pub(super) fn of(tree: &PlanarLinks) -> Option<Self> {
        if tree.dof != K {
            return None;
        }
        let joints = Joints::of(tree)?;
        let chain = joints.serial::<K>()?;
        // Frames at q = 0: every rotation the identity, so origins give the offsets.
        let fr: [LinkFrame; MAX_LINKS + 1] =
            tree.frames(&SVector::<f64, K>::zeros(), &SVector::zeros());
        let origin: [[f64; 2]; K] = std::array::from_fn(|k| fr[chain[k].link + 1].origin_m);
        let offsets_m = std::array::from_fn(|k| match origin.get(k + 1) {
            Some(next) => [next[0] - origin[k][0], next[1] - origin[k][1]],
            None => [0.0; 2],
        });
        let mut groups = [[Lumped::default(); K]; 2];
        for body in &tree.bodies {
            let k = joints.owner(body.slot - 1)?;
            let (o, at) = (fr[body.slot].origin_m, origin[k]);
            let r = [
                o[0] - at[0] + body.com_xy_m[0],
                o[1] - at[1] + body.com_xy_m[1],
            ];
            let g = &mut groups[usize::from(body.infinitesimal)][k];
            let m = body.mass_kg;
            g.mass_kg += m;
            g.moment_kg_m[0] += m * r[0];
            g.moment_kg_m[1] += m * r[1];
            g.inertia_kg_m2 += body.izz_kg_m2 + m * (r[0] * r[0] + r[1] * r[1]);
        }
        let spring = |c: usize| tree.springs.get(c).copied().unwrap_or((0.0, 0.0, 0.0));
        Some(Self {
            joints: std::array::from_fn(|k| (chain[k].coordinate, chain[k].sign)),
            offsets_m,
            groups,
            springs: std::array::from_fn(|k| spring(chain[k].coordinate)),
        })
    }

    /// Any joint spring or damper.
    pub(super) fn has_springs(&self) -> bool {
        self.springs.iter().any(|&(k, _, d)| k != 0.0 || d != 0.0)
    }
}
