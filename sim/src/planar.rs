//! The planar fast path: the equations of motion `M̄ q̈ = f̄` of a small planar tree — every
//! joint a revolute about the floor's z axis or a weld, gravity in the x-y plane — with
//! fixed-size matrices (`nalgebra::SMatrix`, the number of coordinates a const generic), one
//! `sin_cos` per joint instead of 3 × 3 rotations, and no allocation but the returned `q̈`.
//!
//! The general engine ([`crate::dynamics`]) stays the reference: a phase selects this path
//! automatically when its model qualifies ([`PlanarTree::of`]), and `sim/tests/fast_path.rs`
//! checks both against each other on the equations of motion and on whole gaits.
//!
//! Planar kinematics: a link's angle is its parent's plus `±q` (the sign of its axis along z),
//! its origin its parent's plus the joint offset turned by the parent's angle. With every
//! angular velocity along z the angular bias acceleration is zero and the bias acceleration of a
//! point `p` fixed in a link is the link origin's minus `ω² (p − o)`; the gyroscopic torque
//! `ω × I ω` has no z component, so only each body's `I_zz` enters.

use crate::dynamics::{Dynamics, DynamicsError};
use crate::hybrid::phase::DriveValues;
use crate::model::{JointKind, Model};
use crate::singular_limit::{
    cholesky_solve, solve_limit_fixed, LimitSolveError, NULL_EIGENVALUE_REL_TOL,
};
use nalgebra::{DVector, SMatrix, SVector};

mod chain;
mod three_link;
mod trig;
mod two_link;

pub use crate::stride::EvaluationPath;
pub(crate) use chain::Joints;
pub use trig::sin_cos;

/// Most coordinates a planar tree may have to take the planar fast path (and the fixed-size
/// states of the stride loop: one size per count, 1 to this).
pub const MAX_PLANAR_COORDINATES: usize = 6;
/// Most links (welds included) a tree may have to take the fast path.
pub const MAX_LINKS: usize = 12;

/// One link of a planar tree, with what its kinematics needs. Links are stored parents first;
/// index 0 of the evaluation's link state is the ground, link `i` is slot `i + 1`.
#[derive(Clone, Copy, Debug)]
struct PlanarLink {
    /// Slot of the parent in the evaluation's link state (0: the ground).
    parent_slot: usize,
    /// Joint origin in the parent frame, x and y [m].
    joint_xy_m: [f64; 2],
    /// The coordinate this joint owns and the sign of its axis along z (`None`: a weld).
    coordinate: Option<(usize, f64)>,
}

/// One body that carries mass or inertia, with its chain of joints down to the ground.
#[derive(Clone, Copy, Debug)]
struct PlanarBody {
    /// Slot of its link in the evaluation's link state.
    slot: usize,
    /// Mass [kg] (of the `ε` part for an infinitesimal body).
    mass_kg: f64,
    /// Centre of mass in the link frame, x and y [m].
    com_xy_m: [f64; 2],
    /// Inertia about the centre of mass along z [kg·m²].
    izz_kg_m2: f64,
    /// The body is infinitesimal (its terms go to the `ε` part).
    infinitesimal: bool,
    /// `(coordinate, slot of the owning link, axis sign)` along its ancestry; the first
    /// `chain_len` entries are used.
    chain: [(usize, usize, f64); MAX_PLANAR_COORDINATES],
    /// Number of joints in the chain.
    chain_len: usize,
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
/// and the origin's velocity ([`PlanarTree::frames`]).
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

/// A small planar tree, ready for fast evaluations: built once from a [`Model`] that qualifies.
#[derive(Clone, Debug)]
pub struct PlanarTree {
    links: Vec<PlanarLink>,
    bodies: Vec<PlanarBody>,
    /// Joint spring and damper per coordinate: stiffness, rest position, damping.
    springs: Vec<(f64, f64, f64)>,
    gravity_m_s2: [f64; 2],
    dof: usize,
    has_infinitesimal: bool,
    /// The closed form of a two-link chain (the compass, the simplest walker), when the tree
    /// is one.
    two_link: Option<two_link::TwoLink>,
    /// The closed form of a three-link serial chain of finite bodies (kneed2d), when the tree
    /// is one.
    three_link: Option<three_link::ThreeLink>,
}

/// `M̄` and `f̄` of one evaluation, finite and infinitesimal parts.
struct Assembled<const N: usize> {
    m: SMatrix<f64, N, N>,
    m_eps: SMatrix<f64, N, N>,
    f: SVector<f64, N>,
    f_eps: SVector<f64, N>,
}

impl PlanarTree {
    /// The planar tree of `model`, or `None` when it does not qualify: more than
    /// [`MAX_PLANAR_COORDINATES`] coordinates or [`MAX_LINKS`] links, a prismatic joint, a revolute
    /// axis not along the floor's z axis, or gravity out of the x-y plane.
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
        let mut tree = Self {
            links,
            bodies,
            springs,
            gravity_m_s2: [model.gravity_floor_m_s2.x, model.gravity_floor_m_s2.y],
            dof,
            has_infinitesimal: model.has_infinitesimal_bodies(),
            two_link: None,
            three_link: None,
        };
        tree.two_link = two_link::TwoLink::of(&tree);
        tree.three_link = three_link::ThreeLink::of(&tree);
        Some(tree)
    }

    /// The planar tree `path` asks for: `None` for [`EvaluationPath::General`] (or when the
    /// model does not qualify), the link pass alone for [`EvaluationPath::LinkPass`], else
    /// [`Self::of`] (with the closed form when the tree has one).
    pub fn for_path(model: &Model, path: EvaluationPath) -> Option<Self> {
        match path {
            EvaluationPath::General => None,
            EvaluationPath::LinkPass => Self::of(model).map(Self::link_pass_only),
            EvaluationPath::Auto | EvaluationPath::GeneralLoop => Self::of(model),
        }
    }

    /// The same tree without its closed form: every evaluation by the link pass.
    pub fn link_pass_only(mut self) -> Self {
        self.two_link = None;
        self.three_link = None;
        self
    }

    /// Whether the tree evaluates by a closed form (a two-link chain: the compass, and the
    /// simplest walker with its vanishing-mass limit in closed form; a three-link serial chain
    /// of finite bodies: kneed2d) rather than by its link pass.
    pub fn has_closed_form(&self) -> bool {
        self.two_link.is_some() || self.three_link.is_some()
    }

    /// Number of coordinates.
    pub fn dof(&self) -> usize {
        self.dof
    }

    /// `q̈` at `q`, `q̇` exactly as [`crate::hybrid::phase::accelerations`] defines it (free,
    /// locked and driven coordinates). Models with infinitesimal bodies assemble here and solve
    /// their vanishing-mass limit in `limit` (the general workspace, its matrices overwritten).
    ///
    /// # Errors
    /// [`DynamicsError`]: a non-finite state or result, a singular reduced mass matrix.
    pub fn accelerations(
        &self,
        limit: &mut Dynamics,
        active: &[bool],
        drive: Option<&DriveValues<f64>>,
        q: &DVector<f64>,
        qd: &DVector<f64>,
    ) -> Result<DVector<f64>, DynamicsError> {
        let mut out = DVector::zeros(q.len());
        self.accelerations_into(limit, active, drive, q, qd, &mut out)?;
        Ok(out)
    }

    /// [`Self::accelerations`] written into `out` (no allocation for finite bodies).
    ///
    /// # Errors
    /// As [`Self::accelerations`]; also a state or `out` whose length is not the model's.
    pub fn accelerations_into(
        &self,
        limit: &mut Dynamics,
        active: &[bool],
        drive: Option<&DriveValues<f64>>,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        out: &mut DVector<f64>,
    ) -> Result<(), DynamicsError> {
        match self.dof {
            1 => self.accelerations_n::<1>(limit, active, drive, q, qd, out),
            2 => self.accelerations_n::<2>(limit, active, drive, q, qd, out),
            3 => self.accelerations_n::<3>(limit, active, drive, q, qd, out),
            4 => self.accelerations_n::<4>(limit, active, drive, q, qd, out),
            5 => self.accelerations_n::<5>(limit, active, drive, q, qd, out),
            _ => self.accelerations_n::<6>(limit, active, drive, q, qd, out),
        }
    }

    fn accelerations_n<const N: usize>(
        &self,
        limit: &mut Dynamics,
        active: &[bool],
        drive: Option<&DriveValues<f64>>,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        out: &mut DVector<f64>,
    ) -> Result<(), DynamicsError> {
        if q.len() != N || qd.len() != N || out.len() != N {
            return Err(DynamicsError::NonFinite);
        }
        let qs = SVector::<f64, N>::from_iterator(q.iter().copied());
        let qds = SVector::<f64, N>::from_iterator(qd.iter().copied());
        let qdd = self.accelerations_fixed(move || limit, active, drive, &qs, &qds)?;
        out.copy_from_slice(qdd.as_slice());
        Ok(())
    }

    /// [`Self::accelerations`] on fixed-size states (`N` must be [`Self::dof`]): the fixed-size
    /// stride's entry point. `limit` hands out the general workspace, asked for only when a
    /// model with infinitesimal bodies has a coordinate locked or driven.
    ///
    /// # Errors
    /// As [`Self::accelerations`]; also `N` or `active`'s length not the model's.
    pub fn accelerations_fixed<'d, const N: usize>(
        &self,
        limit: impl FnOnce() -> &'d mut Dynamics,
        active: &[bool],
        drive: Option<&DriveValues<f64>>,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
    ) -> Result<SVector<f64, N>, DynamicsError> {
        if drive.is_none() && active.iter().all(|&a| a) {
            if let Some(qdd) = self.free_closed_form(q, qd) {
                return Ok(qdd);
            }
        }
        if N != self.dof || active.len() != N {
            return Err(DynamicsError::NonFinite);
        }
        if q.iter().chain(qd.iter()).any(|v| !v.is_finite()) {
            return Err(DynamicsError::NonFinite);
        }
        let (mut qs, mut qds) = (*q, *qd);
        let mut qdd = SVector::<f64, N>::zeros();
        if let Some(d) = drive {
            qs[d.coordinate] = d.angle_rad;
            qds[d.coordinate] = d.rate_rad_s;
            qdd[d.coordinate] = d.acceleration_rad_s2;
        }
        let a = self.assemble::<N>(&qs, &qds);
        if self.has_infinitesimal && drive.is_none() && active.iter().all(|&a| a) {
            // Every coordinate free: the vanishing-mass limit on the fixed-size matrices.
            qdd = solve_limit_fixed(&a.m, &a.m_eps, &a.f, &a.f_eps, NULL_EIGENVALUE_REL_TOL)
                .map_err(DynamicsError::Singular)?;
        } else if self.has_infinitesimal {
            let limit = limit();
            limit.mass_matrix.copy_from(&a.m);
            limit.mass_matrix_infinitesimal.copy_from(&a.m_eps);
            limit.force.copy_from(&a.f);
            limit.force_infinitesimal.copy_from(&a.f_eps);
            let prescribed = drive.map(|_| DVector::from_iterator(N, qdd.iter().copied()));
            let solved = limit.solve_assembled_limit(active, prescribed.as_ref())?;
            if solved.len() != N {
                return Err(DynamicsError::NonFinite);
            }
            qdd = SVector::from_iterator(solved.iter().copied());
        } else {
            solve_active(&a.m, &a.f, active, &mut qdd)?;
        }
        if qdd.iter().any(|v| !v.is_finite()) {
            return Err(DynamicsError::NonFinite);
        }
        Ok(qdd)
    }

    /// `q̈` by the tree's closed form with every coordinate free and no drive (the two-link
    /// chain's, [`Self::has_closed_form`]), or `None` when it has none, `N` is not its size,
    /// or the result is not finite (a state that is not finite gives one that is not; then
    /// [`Self::accelerations_fixed`] reports the error): the fixed-size stride's shortcut,
    /// equal to [`Self::accelerations_fixed`] wherever it answers.
    #[inline]
    pub fn free_closed_form<const N: usize>(
        &self,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
    ) -> Option<SVector<f64, N>> {
        let qdd = match (&self.two_link, &self.three_link) {
            (Some(t), _) if N == 2 => t.free_accelerations(q, qd)?,
            (_, Some(t)) if N == 3 => {
                let a = t.assemble(q, qd);
                let (mut m, mut f) = (a.m, a.f);
                if !cholesky_solve(&mut m, &mut f) {
                    return None;
                }
                f
            }
            _ => return None,
        };
        qdd.iter().all(|v| v.is_finite()).then_some(qdd)
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

    /// The mass matrix `M̄` at `q`, finite and infinitesimal parts (for the impacts of a
    /// fixed-size stride).
    pub fn mass_matrices<const N: usize>(
        &self,
        q: &SVector<f64, N>,
    ) -> (SMatrix<f64, N, N>, SMatrix<f64, N, N>) {
        let a = self.assemble::<N>(q, &SVector::zeros());
        (a.m, a.m_eps)
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
    /// dampers, body by body, over the planar kinematics.
    fn assemble<const N: usize>(&self, q: &SVector<f64, N>, qd: &SVector<f64, N>) -> Assembled<N> {
        match (&self.two_link, &self.three_link) {
            (Some(t), _) if N == 2 => t.assemble(q, qd),
            (_, Some(t)) if N == 3 => t.assemble(q, qd),
            _ => self.assemble_link_pass(q, qd),
        }
    }

    /// [`Self::assemble`] by the link pass: the links' kinematics parents first, then each
    /// body's terms over its chain of joints.
    fn assemble_link_pass<const N: usize>(
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

/// Solves `M̄_aa q̈_a = f̄_a − M̄_ap q̈_p` for the active coordinates, writing them into `qdd`
/// (which holds the prescribed accelerations, zero when locked): a fixed-size Cholesky
/// factorisation of `M̄` with the rows and columns of the coordinates that are not free
/// replaced by the identity's, whose solution there is `q̈_p` itself.
fn solve_active<const N: usize>(
    m: &SMatrix<f64, N, N>,
    f: &SVector<f64, N>,
    active: &[bool],
    qdd: &mut SVector<f64, N>,
) -> Result<(), DynamicsError> {
    let mut reduced = *m;
    let mut b = *f;
    for j in (0..N).filter(|&j| !active[j]) {
        if qdd[j] != 0.0 {
            for i in 0..N {
                b[i] -= m[(i, j)] * qdd[j];
            }
        }
    }
    for j in (0..N).filter(|&j| !active[j]) {
        reduced.fill_row(j, 0.0);
        reduced.fill_column(j, 0.0);
        reduced[(j, j)] = 1.0;
        b[j] = qdd[j];
    }
    if !cholesky_solve(&mut reduced, &mut b) {
        return Err(DynamicsError::Singular(LimitSolveError::Degenerate {
            nullity: 1,
        }));
    }
    *qdd = b;
    Ok(())
}
