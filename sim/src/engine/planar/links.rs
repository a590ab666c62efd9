//! The links and bodies of a small planar tree read off a [`Model`], and their kinematics:
//! every link's frame ([`PlanarLinks::frames`]), point and momentum Jacobians, and the
//! equations of motion assembled by the link pass. The closed forms (`two_link.rs`,
//! `three_link.rs`) are built from these data; [`super::PlanarTree`] holds both.

use crate::engine::model::{JointKind, Model};
use nalgebra::{SMatrix, SVector};

/// Most coordinates a planar tree may have to take the planar fast path (and the fixed-size
/// states of the stride loop: one size per count, 1 to this).
pub const MAX_PLANAR_COORDINATES: usize = 6;
/// Most links (welds included) a tree may have to take the fast path.
pub const MAX_LINKS: usize = 12;

/// One link of a planar tree, with what its kinematics needs. Links are stored parents first;
/// index 0 of the evaluation's link state is the ground, link `i` is slot `i + 1`.
#[derive(Clone, Copy, Debug)]
pub(super) struct PlanarLink {
    /// Slot of the parent in the evaluation's link state (0: the ground).
    pub(super) parent_slot: usize,
    /// Joint origin in the parent frame, x and y [m].
    pub(super) joint_xy_m: [f64; 2],
    /// The coordinate this joint owns and the sign of its axis along z (`None`: a weld).
    pub(super) coordinate: Option<(usize, f64)>,
}

/// One body that carries mass or inertia, with its chain of joints down to the ground.
#[derive(Clone, Copy, Debug)]
pub(super) struct PlanarBody {
    /// Slot of its link in the evaluation's link state.
    pub(super) slot: usize,
    /// Mass [kg] (of the `ε` part for an infinitesimal body).
    pub(super) mass_kg: f64,
    /// Centre of mass in the link frame, x and y [m].
    pub(super) com_xy_m: [f64; 2],
    /// Inertia about the centre of mass along z [kg·m²].
    pub(super) izz_kg_m2: f64,
    /// The body is infinitesimal (its terms go to the `ε` part).
    pub(super) infinitesimal: bool,
    /// `(coordinate, slot of the owning link, axis sign)` along its ancestry; the first
    /// `chain_len` entries are used.
    pub(super) chain: [(usize, usize, f64); MAX_PLANAR_COORDINATES],
    /// Number of joints in the chain.
    pub(super) chain_len: usize,
}

/// Per-link state of one evaluation: angle's cos and sin, angular rate, origin and its bias
/// acceleration (floor x-y).
#[derive(Clone, Copy, Debug, Default)]
struct LinkState {
    cos: f64,
    sin: f64,
    omega_rad_s: f64,
    origin_m: [f64; 2],
    a_bias_m_s2: [f64; 2],
}

impl LinkState {
    /// The ground: at rest, unrotated, at the origin.
    const GROUND: Self = Self {
        cos: 1.0,
        sin: 0.0,
        omega_rad_s: 0.0,
        origin_m: [0.0; 2],
        a_bias_m_s2: [0.0; 2],
    };
}

/// One link's frame in the floor's x-y plane: its angle's cos and sin, angular rate, origin
/// and the origin's velocity ([`PlanarLinks::frames`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinkFrame {
    /// Cosine of the link's angle.
    pub cos: f64,
    /// Sine of the link's angle.
    pub sin: f64,
    /// Angular rate about the floor's z axis [rad/s].
    pub omega_rad_s: f64,
    /// Origin in the floor frame, x and y \[m\].
    pub origin_m: [f64; 2],
    /// Velocity of the origin, x and y [m/s].
    pub velocity_m_s: [f64; 2],
}

impl LinkFrame {
    /// The ground: at rest, unrotated, at the origin.
    const GROUND: Self = Self {
        cos: 1.0,
        sin: 0.0,
        omega_rad_s: 0.0,
        origin_m: [0.0; 2],
        velocity_m_s: [0.0; 2],
    };

    /// `p` (link frame, x and y) turned into the floor frame.
    fn turn(&self, [x, y]: [f64; 2]) -> [f64; 2] {
        [self.cos * x - self.sin * y, self.sin * x + self.cos * y]
    }

    /// Position and velocity in the floor frame (x and y) of the point `p_link_m` (x and y)
    /// fixed in this link [m, m/s].
    pub fn point(&self, p_link_m: [f64; 2]) -> ([f64; 2], [f64; 2]) {
        let r = self.turn(p_link_m);
        let w = self.omega_rad_s;
        (
            [self.origin_m[0] + r[0], self.origin_m[1] + r[1]],
            [
                self.velocity_m_s[0] - w * r[1],
                self.velocity_m_s[1] + w * r[0],
            ],
        )
    }
}

/// The links and bodies of a planar tree, with the joints' springs and dampers and gravity:
/// the data every evaluation of the tree reads.
#[derive(Clone, Debug)]
pub struct PlanarLinks {
    pub(super) links: Vec<PlanarLink>,
    pub(super) bodies: Vec<PlanarBody>,
    /// Joint spring and damper per coordinate: stiffness, rest position, damping.
    pub(super) springs: Vec<(f64, f64, f64)>,
    pub(super) gravity_m_s2: [f64; 2],
    pub(super) dof: usize,
    pub(super) has_infinitesimal: bool,
}

/// `M̄` and `f̄` of one evaluation, finite and infinitesimal parts.
pub(super) struct Assembled<const N: usize> {
    pub(super) m: SMatrix<f64, N, N>,
    pub(super) m_eps: SMatrix<f64, N, N>,
    pub(super) f: SVector<f64, N>,
    pub(super) f_eps: SVector<f64, N>,
}

impl PlanarLinks {
    /// The links of `model`, or `None` when it does not qualify as a planar tree: more than
    /// [`MAX_PLANAR_COORDINATES`] coordinates or [`MAX_LINKS`] links, a prismatic joint, a
    /// revolute axis not along the floor's z axis, or gravity out of the x-y plane.
    pub fn of(model: &Model) -> Option<Self> {
        let dof = model.dof();
        if dof == 0 || dof > MAX_PLANAR_COORDINATES || model.links.len() > MAX_LINKS {
            return None;
        }
        if model.gravity_floor_m_s2.z != 0.0 {
            return None;
        }
        let mut links = Vec::with_capacity(model.links.len());
        let mut bodies = Vec::new();
        let mut springs = vec![(0.0, 0.0, 0.0); dof];
        for (i, link) in model.links.iter().enumerate() {
            let coordinate = match (&link.joint, link.coordinate) {
                (JointKind::Weld, _) => None,
                (JointKind::Revolute { axis_parent }, Some(c)) => {
                    if axis_parent.x != 0.0 || axis_parent.y != 0.0 || axis_parent.z.abs() != 1.0 {
                        return None;
                    }
                    Some((c.0, axis_parent.z))
                }
                _ => return None,
            };
            if let Some(c) = link.coordinate {
                let jf = &link.joint_force;
                springs[c.0] = (jf.stiffness, jf.rest_position, jf.damping);
            }
            let parent_slot = match link.parent {
                // One pass over the links needs parents first.
                Some(p) if p.0 >= i => return None,
                Some(p) => p.0 + 1,
                None => 0,
            };
            links.push(PlanarLink {
                parent_slot,
                joint_xy_m: [link.p_parent_joint_m.x, link.p_parent_joint_m.y],
                coordinate,
            });
            let b = &link.body;
            let rot = b.inertia_com_kg_m2.iter().any(|v| *v != 0.0);
            if b.mass_kg == 0.0 && !rot {
                // Neither mass nor inertia: skipped, as the general engine does.
                continue;
            }
            let mut chain = [(0, 0, 0.0); MAX_PLANAR_COORDINATES];
            let mut chain_len = 0;
            let mut cur = Some(i);
            while let Some(l) = cur {
                if let Some((c, sign)) = links[l].coordinate {
                    *chain.get_mut(chain_len)? = (c, l + 1, sign);
                    chain_len += 1;
                }
                cur = model.links[l].parent.map(|p| p.0);
            }
            bodies.push(PlanarBody {
                slot: i + 1,
                mass_kg: b.mass_kg,
                com_xy_m: [b.p_link_com_m.x, b.p_link_com_m.y],
                izz_kg_m2: b.inertia_com_kg_m2[(2, 2)],
                infinitesimal: b.infinitesimal,
                chain,
                chain_len,
            });
        }
        Some(Self {
            links,
            bodies,
            springs,
            gravity_m_s2: [model.gravity_floor_m_s2.x, model.gravity_floor_m_s2.y],
            dof,
            has_infinitesimal: model.has_infinitesimal_bodies(),
        })
    }

    /// Number of coordinates.
    pub fn dof(&self) -> usize {
        self.dof
    }

    /// The damping coefficient of coordinate `c`'s joint [N·m·s/rad] (zero when undamped).
    pub fn damping(&self, c: usize) -> f64 {
        self.springs.get(c).map_or(0.0, |s| s.2)
    }

    /// Whether the tree has infinitesimal bodies (the vanishing-mass limit).
    pub fn has_infinitesimal(&self) -> bool {
        self.has_infinitesimal
    }

    /// Number of links (welds included).
    pub fn link_count(&self) -> usize {
        self.links.len()
    }

    /// Link `i`'s parent slot (0: the ground, link `j`: `j + 1`) and the coordinate its joint
    /// owns with the sign of its axis along z (`None`: a weld).
    pub fn link_joint(&self, i: usize) -> Option<(usize, Option<(usize, f64)>)> {
        self.links.get(i).map(|l| (l.parent_slot, l.coordinate))
    }

    /// The whole tree's mass \[kg\] and the Jacobian of its linear momentum `Σ m Jv` (x and y
    /// rows) at the frames `fr` ([`Self::frames`] at `q`; only their positions enter): the
    /// coupling of a translation of the root with the coordinates; over the finite bodies, or
    /// the infinitesimal ones (`infinitesimal`, their `ε` parts).
    pub fn momentum_jacobian<const N: usize>(
        &self,
        fr: &[LinkFrame; MAX_LINKS + 1],
        infinitesimal: bool,
    ) -> (f64, SMatrix<f64, 2, N>) {
        let mut total = 0.0;
        let mut jac = SMatrix::<f64, 2, N>::zeros();
        for body in self
            .bodies
            .iter()
            .filter(|b| b.infinitesimal == infinitesimal)
        {
            total += body.mass_kg;
            let (p, _) = fr[body.slot].point(body.com_xy_m);
            for &(c, slot, sign) in &body.chain[..body.chain_len] {
                let o = fr[slot].origin_m;
                if c < N {
                    jac[(0, c)] -= body.mass_kg * sign * (p[1] - o[1]);
                    jac[(1, c)] += body.mass_kg * sign * (p[0] - o[0]);
                }
            }
        }
        (total, jac)
    }

    /// The Jacobian (x and y rows) of the point `p_link_m` fixed in link `link` (model index)
    /// at the frames `fr`: column `c` is `sign · z × (p − o)` for each joint up the chain.
    pub fn point_jacobian<const N: usize>(
        &self,
        fr: &[LinkFrame; MAX_LINKS + 1],
        link: usize,
        p_link_m: [f64; 2],
    ) -> SMatrix<f64, 2, N> {
        let mut jac = SMatrix::<f64, 2, N>::zeros();
        let Some(frame) = fr.get(link + 1) else {
            return jac;
        };
        let (p, _) = frame.point(p_link_m);
        let mut cur = link;
        while let Some(l) = self.links.get(cur) {
            if let Some((c, sign)) = l.coordinate {
                let o = fr[cur + 1].origin_m;
                if c < N {
                    jac[(0, c)] = -sign * (p[1] - o[1]);
                    jac[(1, c)] = sign * (p[0] - o[0]);
                }
            }
            match l.parent_slot {
                0 => break,
                s => cur = s - 1,
            }
        }
        jac
    }

    /// Every link's frame at `q`, `q̇` (for the witnesses of a fixed-size stride): slot 0 is
    /// the ground, link `i` of the model slot `i + 1`.
    pub fn frames<const N: usize>(
        &self,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
    ) -> [LinkFrame; MAX_LINKS + 1] {
        let mut fr = [LinkFrame::GROUND; MAX_LINKS + 1];
        for (i, link) in self.links.iter().enumerate() {
            let parent = fr[link.parent_slot];
            let d = parent.turn(link.joint_xy_m);
            let w = parent.omega_rad_s;
            let mut f = LinkFrame {
                origin_m: [parent.origin_m[0] + d[0], parent.origin_m[1] + d[1]],
                velocity_m_s: [
                    parent.velocity_m_s[0] - w * d[1],
                    parent.velocity_m_s[1] + w * d[0],
                ],
                ..parent
            };
            if let Some((c, sign)) = link.coordinate {
                let (sin_q, cos_q) = (sign * q[c]).sin_cos();
                f.cos = parent.cos * cos_q - parent.sin * sin_q;
                f.sin = parent.sin * cos_q + parent.cos * sin_q;
                f.omega_rad_s = parent.omega_rad_s + sign * qd[c];
            }
            fr[i + 1] = f;
        }
        fr
    }

    /// `M̄ = Σ m Jvᵀ Jv + I_zz Jwᵀ Jw` and `f̄ = Σ Jvᵀ m (g − a_bias)` minus the joint springs and
    /// dampers, body by body, over the planar kinematics (the link pass): the links'
    /// kinematics parents first, then each body's terms over its chain of joints.
    pub(super) fn assemble<const N: usize>(
        &self,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
    ) -> Assembled<N> {
        // All zeros (a memset) but the ground's cos.
        let mut st = [LinkState::default(); MAX_LINKS + 1];
        st[0] = LinkState::GROUND;
        for (i, link) in self.links.iter().enumerate() {
            let parent = st[link.parent_slot];
            let [jx, jy] = link.joint_xy_m;
            let (dx, dy) = (
                parent.cos * jx - parent.sin * jy,
                parent.sin * jx + parent.cos * jy,
            );
            let w2 = parent.omega_rad_s * parent.omega_rad_s;
            let mut s = LinkState {
                origin_m: [parent.origin_m[0] + dx, parent.origin_m[1] + dy],
                a_bias_m_s2: [
                    parent.a_bias_m_s2[0] - w2 * dx,
                    parent.a_bias_m_s2[1] - w2 * dy,
                ],
                ..parent
            };
            if let Some((c, sign)) = link.coordinate {
                let (sin_q, cos_q) = (sign * q[c]).sin_cos();
                s.cos = parent.cos * cos_q - parent.sin * sin_q;
                s.sin = parent.sin * cos_q + parent.cos * sin_q;
                s.omega_rad_s = parent.omega_rad_s + sign * qd[c];
            }
            st[i + 1] = s;
        }
        // Lower triangles of M̄ and M̄_ε (mirrored at the end), and f̄, f̄_ε.
        let mut m = [[[0.0; N]; N]; 2];
        let mut f = [[0.0; N]; 2];
        let [gx, gy] = self.gravity_m_s2;
        for body in &self.bodies {
            let s = st[body.slot];
            let [cx, cy] = body.com_xy_m;
            let (rx, ry) = (s.cos * cx - s.sin * cy, s.sin * cx + s.cos * cy);
            let (px, py) = (s.origin_m[0] + rx, s.origin_m[1] + ry);
            let w2 = s.omega_rad_s * s.omega_rad_s;
            let (ax, ay) = (s.a_bias_m_s2[0] - w2 * rx, s.a_bias_m_s2[1] - w2 * ry);
            let (mass, izz) = (body.mass_kg, body.izz_kg_m2);
            let (fx, fy) = (mass * (gx - ax), mass * (gy - ay));
            let part = usize::from(body.infinitesimal);
            let chain = &body.chain[..body.chain_len];
            // Jv = sign · z × (p − o), Jw = sign, per joint of the chain.
            let mut jv = [(0.0, 0.0); MAX_PLANAR_COORDINATES];
            for (v, &(_, slot, sign)) in jv.iter_mut().zip(chain) {
                let o = st[slot].origin_m;
                *v = (-sign * (py - o[1]), sign * (px - o[0]));
            }
            for (x, &(ci, _, si)) in chain.iter().enumerate() {
                let (vix, viy) = jv[x];
                f[part][ci] += vix * fx + viy * fy;
                for (y, &(cj, _, sj)) in chain[..=x].iter().enumerate() {
                    let (vjx, vjy) = jv[y];
                    let v = mass * (vix * vjx + viy * vjy) + izz * si * sj;
                    // Along a chain to the ground, nearer joints own smaller or larger
                    // coordinates alike: keep the lower triangle.
                    if ci >= cj {
                        m[part][ci][cj] += v;
                    } else {
                        m[part][cj][ci] += v;
                    }
                }
            }
        }
        for (c, &(k, rest, d)) in self.springs.iter().enumerate() {
            f[0][c] -= (q[c] - rest) * k + qd[c] * d;
        }
        let full = |m: &[[f64; N]; N]| SMatrix::<f64, N, N>::from_fn(|i, j| m[i.max(j)][i.min(j)]);
        Assembled {
            m: full(&m[0]),
            m_eps: full(&m[1]),
            f: SVector::from(f[0]),
            f_eps: SVector::from(f[1]),
        }
    }
}
