//! The 3D fast path: the equations of motion `M̄ q̈ = f̄` of a tree whose every joint is a
//! revolute about one of its parent frame's coordinate axes (x, y or z) or a weld — the 3D
//! walker's — on fixed-capacity arrays, without allocation.
//!
//! The same TMT sums as the general engine ([`crate::engine::dynamics`]), regrouped:
//! - **frames**: one per coordinate (the link of a revolute joint); a weld does not rotate, so
//!   every link welded to a frame's link, directly or through other welds, moves with that
//!   frame, and its bodies are **lumped** once, when the tree is built, into one body per frame
//!   (mass, centre of mass and inertia about it in the frame's axes: the parallel-axis sum);
//! - **kinematics** per frame from its parent's, parents first: the rotation by turning two of
//!   the parent's columns by one `sin_cos` (the joint's axis is a coordinate axis), the origin,
//!   the angular velocity and the bias accelerations (the velocities of points are not needed:
//!   `M̄` and `f̄` read only accelerations);
//! - per lumped body, `M̄ += m J_vᵀ J_v + J_ωᵀ I J_ω` and `f̄ += J_vᵀ m (g − a_bias) + J_ωᵀ
//!   (−I α_bias − ω × I ω)` over the body's chain of frames (the only nonzero Jacobian columns),
//!   on the lower triangle, mirrored once; the joints' springs and dampers last.
//!
//! As the general engine's partial assembly, only the rows and columns a solve reads are
//! computed (the free coordinates, the prescribed ones with a nonzero acceleration and the
//! driven one, whose row the actuator torque reads), and the solve is the same active-set
//! Cholesky, on fixed-size rows. Models with infinitesimal bodies
//! or prismatic joints do not qualify ([`AxisTree::of`]). The general engine stays the
//! reference: `sim/tests/axis_tree.rs` checks `M̄`, `f̄` and `q̈` against it over random
//! states in every phase, and strides and gaits on both.

use crate::engine::dynamics::DynamicsError;
use crate::engine::model::{JointKind, Model};
use crate::engine::planar::sin_cos;
use crate::engine::singular_limit::LimitSolveError;
use nalgebra::{DVector, Matrix3, Vector3};

/// Most coordinates a tree may have to take the 3D fast path.
pub const MAX_AXIS_TREE_COORDINATES: usize = 12;

/// One frame: the link of a revolute joint about a coordinate axis, with what its kinematics
/// needs. Frames are stored parents first.
#[derive(Clone, Copy, Debug)]
struct Frame {
    /// The parent frame (`None`: the ground, the floor's frame at its origin).
    parent: Option<usize>,
    /// The joint's axis in the parent frame: 0 x, 1 y, 2 z.
    axis: usize,
    /// The joint's origin in the parent frame's axes, from the parent frame's origin [m].
    origin_m: Vector3<f64>,
    /// The coordinate the joint owns.
    coordinate: usize,
}

/// The bodies moving with one frame, lumped.
#[derive(Clone, Copy, Debug)]
struct LumpedBody {
    /// The frame they move with.
    frame: usize,
    /// Total mass [kg].
    mass_kg: f64,
    /// Centre of mass in the frame's axes, from its origin [m].
    com_m: Vector3<f64>,
    /// Inertia tensor about the centre of mass, in the frame's axes [kg·m²].
    inertia_com_kg_m2: Matrix3<f64>,
    /// Whether the inertia tensor is nonzero.
    rotational: bool,
    /// The body's chain of frames (root first, its own last): `chains[start..end]`.
    chain: (usize, usize),
}

/// One body's Jacobian column: `(coordinate, linear at the c.m., angular, I_floor · angular)`.
type JacobianColumn = (usize, Vector3<f64>, Vector3<f64>, Vector3<f64>);

/// A joint spring and damper on one coordinate.
#[derive(Clone, Copy, Debug)]
struct JointSpring {
    coordinate: usize,
    stiffness: f64,
    rest_position: f64,
    damping: f64,
}

/// Each frame's kinematics at one evaluation (floor axes), one array per quantity.
#[derive(Clone, Copy, Debug)]
struct FrameStates {
    r_floor_frame: [Matrix3<f64>; MAX_AXIS_TREE_COORDINATES],
    p_floor_m: [Vector3<f64>; MAX_AXIS_TREE_COORDINATES],
    axis_floor: [Vector3<f64>; MAX_AXIS_TREE_COORDINATES],
    omega_rad_s: [Vector3<f64>; MAX_AXIS_TREE_COORDINATES],
    alpha_bias_rad_s2: [Vector3<f64>; MAX_AXIS_TREE_COORDINATES],
    a_bias_m_s2: [Vector3<f64>; MAX_AXIS_TREE_COORDINATES],
}

/// A tree of coordinate-axis revolutes and welds, with its evaluation's workspace.
#[derive(Clone, Debug)]
pub struct AxisTree {
    dof: usize,
    frames: Vec<Frame>,
    bodies: Vec<LumpedBody>,
    /// The bodies' chains of frames, one after the other.
    chains: Vec<usize>,
    springs: Vec<JointSpring>,
    gravity_floor_m_s2: Vector3<f64>,
    states: FrameStates,
    /// `M̄` (its leading `dof × dof` block; the lower triangle assembled, then mirrored).
    mass_matrix: [[f64; MAX_AXIS_TREE_COORDINATES]; MAX_AXIS_TREE_COORDINATES],
    /// `f̄`.
    force: [f64; MAX_AXIS_TREE_COORDINATES],
    /// The coordinates whose rows and columns the last assembly computed.
    assembled: [bool; MAX_AXIS_TREE_COORDINATES],
    /// Scratch: the coordinates the next assembly computes.
    needed: [bool; MAX_AXIS_TREE_COORDINATES],
    /// Scratch for the active-set solve.
    work_m: [[f64; MAX_AXIS_TREE_COORDINATES]; MAX_AXIS_TREE_COORDINATES],
    work_b: [f64; MAX_AXIS_TREE_COORDINATES],
    work_idx: [usize; MAX_AXIS_TREE_COORDINATES],
    /// Scratch: one body's needed Jacobian columns `(coordinate, linear, angular, I ω-column)`.
    cols: [JacobianColumn; MAX_AXIS_TREE_COORDINATES],
}

/// The coordinate axis `axis` is, if it is one (0 x, 1 y, 2 z).
fn coordinate_axis(axis: &Vector3<f64>) -> Option<usize> {
    match (axis.x, axis.y, axis.z) {
        (1.0, 0.0, 0.0) => Some(0),
        (0.0, 1.0, 0.0) => Some(1),
        (0.0, 0.0, 1.0) => Some(2),
        _ => None,
    }
}

/// Whether every entry is finite.
fn finite(x: &[f64]) -> bool {
    x.iter().all(|v| v.is_finite())
}

/// `a · b` written out.
#[inline(always)]
fn dot3(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.x * b.x + a.y * b.y + a.z * b.z
}

impl AxisTree {
    /// The tree of `model`, if it qualifies: 1 to `MAX_AXIS_TREE_COORDINATES` coordinates, every joint
    /// a revolute about a coordinate axis of its parent frame (owning a coordinate) or a weld,
    /// no infinitesimal bodies.
    pub fn of(model: &Model) -> Option<Self> {
        let dof = model.dof();
        if dof == 0 || dof > MAX_AXIS_TREE_COORDINATES || model.has_infinitesimal_bodies() {
            return None;
        }
        // For each link: the frame it moves with and its origin in that frame's axes, from the
        // frame's origin (the floor's, for links welded to the ground).
        let mut frame_of: Vec<Option<usize>> = Vec::with_capacity(model.links.len());
        let mut offset_of: Vec<Vector3<f64>> = Vec::with_capacity(model.links.len());
        let mut frames: Vec<Frame> = Vec::with_capacity(dof);
        let mut springs = Vec::new();
        for (i, link) in model.links.iter().enumerate() {
            let parent = match link.parent {
                Some(p) if p.0 < i => Some(p.0),
                Some(_) => return None,
                None => None,
            };
            let (parent_frame, parent_offset) = match parent {
                Some(p) => (frame_of[p], offset_of[p]),
                None => (None, Vector3::zeros()),
            };
            let origin_m = parent_offset + link.p_parent_joint_m;
            match (&link.joint, link.coordinate) {
                (JointKind::Weld, None) => {
                    frame_of.push(parent_frame);
                    offset_of.push(origin_m);
                }
                (JointKind::Revolute { axis_parent }, Some(c)) => {
                    let axis = coordinate_axis(axis_parent)?;
                    frame_of.push(Some(frames.len()));
                    offset_of.push(Vector3::zeros());
                    frames.push(Frame {
                        parent: parent_frame,
                        axis,
                        origin_m,
                        coordinate: c.0,
                    });
                    let jf = &link.joint_force;
                    if jf.stiffness != 0.0 || jf.damping != 0.0 {
                        springs.push(JointSpring {
                            coordinate: c.0,
                            stiffness: jf.stiffness,
                            rest_position: jf.rest_position,
                            damping: jf.damping,
                        });
                    }
                }
                _ => return None,
            }
        }
        if frames.len() != dof {
            return None;
        }
        // Lump each frame's bodies: mass, first moment, then the inertia about the joint
        // centre of mass by the parallel-axis sum.
        let mut lumped: Vec<(f64, Vector3<f64>, Vec<usize>)> =
            vec![(0.0, Vector3::zeros(), Vec::new()); dof];
        for (i, link) in model.links.iter().enumerate() {
            let b = &link.body;
            let rotational = b.inertia_com_kg_m2.iter().any(|v| *v != 0.0);
            // An infinitesimal body (here of zero mass: the model has none with mass) goes to
            // the general engine's infinitesimal part, which a model without infinitesimal
            // mass never reads: it has no effect there, and none here.
            if b.infinitesimal || (b.mass_kg == 0.0 && !rotational) {
                continue;
            }
            let Some(f) = frame_of[i] else { continue };
            let com = offset_of[i] + b.p_link_com_m;
            lumped[f].0 += b.mass_kg;
            lumped[f].1 += com * b.mass_kg;
            lumped[f].2.push(i);
        }
        let mut bodies = Vec::new();
        let mut chains = Vec::new();
        for (f, (mass_kg, moment, links)) in lumped.into_iter().enumerate() {
            if links.is_empty() {
                continue;
            }
            let com_m = if mass_kg > 0.0 {
                moment / mass_kg
            } else {
                Vector3::zeros()
            };
            let mut inertia = Matrix3::zeros();
            for &i in &links {
                let b = &model.links[i].body;
                let r = offset_of[i] + b.p_link_com_m - com_m;
                inertia += b.inertia_com_kg_m2
                    + (Matrix3::identity() * r.norm_squared() - r * r.transpose()) * b.mass_kg;
            }
            let start = chains.len();
            let mut chain = Vec::new();
            let mut cur = Some(f);
            while let Some(c) = cur {
                chain.push(c);
                cur = frames[c].parent;
            }
            chains.extend(chain.into_iter().rev());
            bodies.push(LumpedBody {
                frame: f,
                mass_kg,
                com_m,
                inertia_com_kg_m2: inertia,
                rotational: inertia.iter().any(|v| *v != 0.0),
                chain: (start, chains.len()),
            });
        }
        Some(Self {
            dof,
            frames,
            bodies,
            chains,
            springs,
            gravity_floor_m_s2: model.gravity_floor_m_s2,
            states: FrameStates {
                r_floor_frame: [Matrix3::identity(); MAX_AXIS_TREE_COORDINATES],
                p_floor_m: [Vector3::zeros(); MAX_AXIS_TREE_COORDINATES],
                axis_floor: [Vector3::zeros(); MAX_AXIS_TREE_COORDINATES],
                omega_rad_s: [Vector3::zeros(); MAX_AXIS_TREE_COORDINATES],
                alpha_bias_rad_s2: [Vector3::zeros(); MAX_AXIS_TREE_COORDINATES],
                a_bias_m_s2: [Vector3::zeros(); MAX_AXIS_TREE_COORDINATES],
            },
            mass_matrix: [[0.0; MAX_AXIS_TREE_COORDINATES]; MAX_AXIS_TREE_COORDINATES],
            force: [0.0; MAX_AXIS_TREE_COORDINATES],
            assembled: [false; MAX_AXIS_TREE_COORDINATES],
            needed: [true; MAX_AXIS_TREE_COORDINATES],
            work_m: [[0.0; MAX_AXIS_TREE_COORDINATES]; MAX_AXIS_TREE_COORDINATES],
            work_b: [0.0; MAX_AXIS_TREE_COORDINATES],
            work_idx: [0; MAX_AXIS_TREE_COORDINATES],
            cols: [(0, Vector3::zeros(), Vector3::zeros(), Vector3::zeros());
                MAX_AXIS_TREE_COORDINATES],
        })
    }

    /// Number of coordinates.
    pub fn dof(&self) -> usize {
        self.dof
    }

    /// Each frame's rotation, origin, axis, angular velocity and bias accelerations at `q`,
    /// `q̇`, parents first.
    fn kinematics(&mut self, q: &[f64], qd: &[f64]) {
        let st = &mut self.states;
        for (f, frame) in self.frames.iter().enumerate() {
            let (qi, qdi) = (q[frame.coordinate], qd[frame.coordinate]);
            let (s, c) = sin_cos(qi);
            let (i, j) = match frame.axis {
                0 => (1, 2),
                1 => (2, 0),
                _ => (0, 1),
            };
            match frame.parent {
                Some(p) => {
                    let r_p = st.r_floor_frame[p];
                    let d = r_p * frame.origin_m;
                    let (w_p, al_p) = (st.omega_rad_s[p], st.alpha_bias_rad_s2[p]);
                    let a = r_p.column(frame.axis).into_owned();
                    let (ci, cj) = (r_p.column(i).into_owned(), r_p.column(j).into_owned());
                    let mut r = r_p;
                    r.set_column(i, &(ci * c + cj * s));
                    r.set_column(j, &(cj * c - ci * s));
                    st.r_floor_frame[f] = r;
                    st.p_floor_m[f] = st.p_floor_m[p] + d;
                    st.axis_floor[f] = a;
                    st.omega_rad_s[f] = w_p + a * qdi;
                    st.alpha_bias_rad_s2[f] = al_p + w_p.cross(&a) * qdi;
                    st.a_bias_m_s2[f] =
                        st.a_bias_m_s2[p] + al_p.cross(&d) + w_p.cross(&w_p.cross(&d));
                }
                None => {
                    // On the ground: the parent frame is the floor's, at rest.
                    let mut r = Matrix3::zeros();
                    r[(frame.axis, frame.axis)] = 1.0;
                    r[(i, i)] = c;
                    r[(j, i)] = s;
                    r[(i, j)] = -s;
                    r[(j, j)] = c;
                    let mut a = Vector3::zeros();
                    a[frame.axis] = 1.0;
                    st.r_floor_frame[f] = r;
                    st.p_floor_m[f] = frame.origin_m;
                    st.axis_floor[f] = a;
                    st.omega_rad_s[f] = a * qdi;
                    st.alpha_bias_rad_s2[f] = Vector3::zeros();
                    st.a_bias_m_s2[f] = Vector3::zeros();
                }
            }
        }
    }

    /// Assembles the rows and columns of `M̄`, `f̄` marked in `self.needed` at `q`, `q̇`.
    fn assemble(&mut self, q: &[f64], qd: &[f64]) {
        self.kinematics(q, qd);
        let n = self.dof;
        const S: usize = MAX_AXIS_TREE_COORDINATES;
        self.assembled = self.needed;
        self.mass_matrix = [[0.0; S]; S];
        self.force = [0.0; S];
        let g = self.gravity_floor_m_s2;
        let st = &self.states;
        for body in &self.bodies {
            let bf = body.frame;
            let rf = &st.r_floor_frame[bf];
            let r = rf * body.com_m;
            let p_com = st.p_floor_m[bf] + r;
            let w = st.omega_rad_s[bf];
            let alpha = st.alpha_bias_rad_s2[bf];
            let a_bias = st.a_bias_m_s2[bf] + alpha.cross(&r) + w.cross(&w.cross(&r));
            let mass = body.mass_kg;
            let f_lin = (g - a_bias) * mass;
            let (i_w, torque) = if body.rotational {
                let i_w = rf * body.inertia_com_kg_m2 * rf.transpose();
                (i_w, -(i_w * alpha) - w.cross(&(i_w * w)))
            } else {
                (Matrix3::zeros(), Vector3::zeros())
            };
            let mut k = 0;
            for &fr in &self.chains[body.chain.0..body.chain.1] {
                let c = self.frames[fr].coordinate;
                if !self.needed[c] {
                    continue;
                }
                let a = st.axis_floor[fr];
                let jv = a.cross(&(p_com - st.p_floor_m[fr]));
                self.cols[k] = (c, jv, a, i_w * a);
                k += 1;
            }
            for x in 0..k {
                let (ci, jvi, jwi, iw_jwi) = self.cols[x];
                self.force[ci] += dot3(&jvi, &f_lin) + dot3(&jwi, &torque);
                for &(cj, jvj, jwj, _) in &self.cols[..=x] {
                    let v = mass * dot3(&jvi, &jvj) + dot3(&jwj, &iw_jwi);
                    self.mass_matrix[ci.max(cj)][ci.min(cj)] += v;
                }
            }
        }
        for row in 0..n {
            for col in row + 1..n {
                self.mass_matrix[row][col] = self.mass_matrix[col][row];
            }
        }
        for s in &self.springs {
            let c = s.coordinate;
            self.force[c] -= (q[c] - s.rest_position) * s.stiffness + qd[c] * s.damping;
        }
    }

    /// Marks in `self.needed` the coordinates a solve reads: the free ones, the prescribed ones
    /// with a nonzero acceleration, and `also` (a driven coordinate, whose row the actuator
    /// torque reads).
    fn mark_needed(
        &mut self,
        active: &[bool],
        qdd_prescribed: Option<&[f64]>,
        also: Option<usize>,
    ) {
        for j in 0..self.dof {
            self.needed[j] =
                active[j] || qdd_prescribed.is_some_and(|p| p[j] != 0.0) || also == Some(j);
        }
    }

    /// `q̈` [rad/s²] at `q`, `q̇`: the coordinates where `active` is true free, the others
    /// given by `qdd_prescribed` (zero if `None`), assembling only what the solve reads (and
    /// the row and column of `driven`, when given). As the general engine's
    /// `accelerations_of_free_into`.
    ///
    /// # Errors
    /// As the general engine: [`DynamicsError::NonFinite`] for a non-finite `q`, `q̇` or
    /// result, [`DynamicsError::Singular`] when the free block of `M̄` is not positive
    /// definite (or a vector has the wrong length).
    #[allow(clippy::too_many_arguments)]
    pub fn accelerations_into(
        &mut self,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        active: &[bool],
        qdd_prescribed: Option<&DVector<f64>>,
        driven: Option<usize>,
        qdd: &mut DVector<f64>,
    ) -> Result<(), DynamicsError> {
        let n = self.dof;
        if q.len() != n || qd.len() != n || active.len() != n || qdd.len() != n {
            return Err(LimitSolveError::Degenerate { nullity: 0 }.into());
        }
        if qdd_prescribed.is_some_and(|p| p.len() != n) {
            return Err(LimitSolveError::Degenerate { nullity: 0 }.into());
        }
        if !finite(q.as_slice()) || !finite(qd.as_slice()) {
            return Err(DynamicsError::NonFinite);
        }
        let prescribed = qdd_prescribed.map(|p| p.as_slice());
        self.mark_needed(active, prescribed, driven);
        self.assemble(q.as_slice(), qd.as_slice());
        self.solve(active, prescribed, qdd.as_mut_slice())?;
        if !finite(qdd.as_slice()) {
            return Err(DynamicsError::NonFinite);
        }
        Ok(())
    }

    /// The solve of [`Self::accelerations_into`] on the last assembly, for other prescribed
    /// accelerations at the same `q`, `q̇` (the caller vouches for them). `Ok(false)`, nothing
    /// written, when the last assembly did not compute a row or column the solve reads.
    ///
    /// # Errors
    /// As [`Self::accelerations_into`].
    pub fn accelerations_on_assembly_into(
        &mut self,
        active: &[bool],
        qdd_prescribed: Option<&DVector<f64>>,
        qdd: &mut DVector<f64>,
    ) -> Result<bool, DynamicsError> {
        let n = self.dof;
        if active.len() != n || qdd.len() != n || qdd_prescribed.is_some_and(|p| p.len() != n) {
            return Ok(false);
        }
        let prescribed = qdd_prescribed.map(|p| p.as_slice());
        self.mark_needed(active, prescribed, None);
        if (0..n).any(|j| self.needed[j] && !self.assembled[j]) {
            return Ok(false);
        }
        self.solve(active, prescribed, qdd.as_mut_slice())?;
        if !finite(qdd.as_slice()) {
            return Err(DynamicsError::NonFinite);
        }
        Ok(true)
    }

    /// `M̄_c · q̈ − f̄_c` [N·m]: the generalised force a driven coordinate `c`'s actuator
    /// exerts for `q̈` on the last assembly; `None` if it did not compute row `c`.
    pub fn actuator_force(&self, c: usize, qdd: &DVector<f64>) -> Option<f64> {
        if c >= self.dof || !self.assembled[c] || qdd.len() != self.dof {
            return None;
        }
        let row = &self.mass_matrix[c][..self.dof];
        Some(row.iter().zip(qdd.iter()).map(|(m, a)| m * a).sum::<f64>() - self.force[c])
    }

    /// `M̄_aa q̈_a = f̄_a − M̄_ap q̈_p` on the assembly (reading only the prescribed
    /// coordinates marked needed), into `qdd`.
    fn solve(
        &mut self,
        active: &[bool],
        qdd_prescribed: Option<&[f64]>,
        qdd: &mut [f64],
    ) -> Result<(), DynamicsError> {
        let n = self.dof;
        match qdd_prescribed {
            Some(p) => qdd.copy_from_slice(p),
            None => qdd.fill(0.0),
        }
        let mut k = 0;
        for (j, &a) in active.iter().enumerate() {
            if a {
                self.work_idx[k] = j;
                k += 1;
            }
        }
        for r in 0..k {
            let i = self.work_idx[r];
            let m_row = &self.mass_matrix[i][..n];
            let mut b = self.force[i];
            if qdd_prescribed.is_some() {
                for j in 0..n {
                    if !active[j] && self.needed[j] {
                        b -= m_row[j] * qdd[j];
                    }
                }
            }
            self.work_b[r] = b;
            for x in 0..k {
                self.work_m[r][x] = m_row[self.work_idx[x]];
            }
        }
        if !cholesky_solve(&mut self.work_m, k, &mut self.work_b) {
            return Err(LimitSolveError::Degenerate { nullity: 1 }.into());
        }
        for r in 0..k {
            qdd[self.work_idx[r]] = self.work_b[r];
        }
        Ok(())
    }

    /// `M̄` and `f̄` assembled in full at `q`, `q̇` (row-major `M̄`), for tests and comparisons.
    pub fn mass_matrix_and_force(
        &mut self,
        q: &DVector<f64>,
        qd: &DVector<f64>,
    ) -> (Vec<f64>, Vec<f64>) {
        let n = self.dof;
        self.needed = [true; MAX_AXIS_TREE_COORDINATES];
        self.assemble(q.as_slice(), qd.as_slice());
        let m = (0..n)
            .flat_map(|i| (0..n).map(move |j| (i, j)))
            .map(|(i, j)| self.mass_matrix[i][j])
            .collect();
        (m, self.force[..n].to_vec())
    }

    /// How many lumped bodies the tree has (one per frame that carries mass or inertia).
    pub fn lumped_bodies(&self) -> usize {
        self.bodies.len()
    }
}

/// Solves `A x = b` for the leading `k × k` block of a symmetric positive definite `A`,
/// overwriting `A`'s lower triangle with its Cholesky factor and `b` with `x`: the general
/// engine's in-place solve (`dynamics.rs`, the same operations in the same order) on
/// fixed-size rows, with the block's size a constant so that its loops unroll. Returns false
/// if `A` is not positive definite (NaN included) or `k` is larger than the capacity.
fn cholesky_solve(
    a: &mut [[f64; MAX_AXIS_TREE_COORDINATES]; MAX_AXIS_TREE_COORDINATES],
    k: usize,
    b: &mut [f64; MAX_AXIS_TREE_COORDINATES],
) -> bool {
    match k {
        0 => true,
        1 => cholesky_solve_k::<1>(a, b),
        2 => cholesky_solve_k::<2>(a, b),
        3 => cholesky_solve_k::<3>(a, b),
        4 => cholesky_solve_k::<4>(a, b),
        5 => cholesky_solve_k::<5>(a, b),
        6 => cholesky_solve_k::<6>(a, b),
        7 => cholesky_solve_k::<7>(a, b),
        8 => cholesky_solve_k::<8>(a, b),
        9 => cholesky_solve_k::<9>(a, b),
        10 => cholesky_solve_k::<10>(a, b),
        11 => cholesky_solve_k::<11>(a, b),
        12 => cholesky_solve_k::<12>(a, b),
        _ => false,
    }
}

/// [`cholesky_solve`] for a block of `K` rows (`K ≤ MAX_AXIS_TREE_COORDINATES`). Indexed loops: the
/// same operations in the same order as the general engine's solve.
#[inline(always)]
#[allow(clippy::needless_range_loop)]
fn cholesky_solve_k<const K: usize>(
    a: &mut [[f64; MAX_AXIS_TREE_COORDINATES]; MAX_AXIS_TREE_COORDINATES],
    b: &mut [f64; MAX_AXIS_TREE_COORDINATES],
) -> bool {
    for j in 0..K {
        let mut d = a[j][j];
        for p in 0..j {
            d -= a[j][p] * a[j][p];
        }
        // Also rejects NaN (which is not greater than zero).
        if d.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return false;
        }
        let d = d.sqrt();
        a[j][j] = d;
        for i in j + 1..K {
            let mut v = a[i][j];
            for p in 0..j {
                v -= a[i][p] * a[j][p];
            }
            a[i][j] = v / d;
        }
    }
    for i in 0..K {
        let mut v = b[i];
        for p in 0..i {
            v -= a[i][p] * b[p];
        }
        b[i] = v / a[i][i];
    }
    for i in (0..K).rev() {
        let mut v = b[i];
        for p in i + 1..K {
            v -= a[p][i] * b[p];
        }
        b[i] = v / a[i][i];
    }
    true
}
