//! The equations of motion of a planar two-link tree in closed form: a stance leg on the
//! ground and a swing leg on a hip (the compass gait, the simplest walker), with point and
//! distributed masses, welds anywhere. Built once from the planar tree's own data
//! ([`TwoLink::of`], structurally: two coordinates, the second joint below the first link;
//! infinitesimal bodies in their own `ε` part, the simplest walker's limit in closed form);
//! the link pass of [`super::PlanarTree`] and the general engine stay the reference it is
//! tested against (`sim/tests/fast_path.rs`).
//!
//! # Derivation
//!
//! Group 1 is every body rigid with the first joint's link (link `A`, coordinate `a`, axis
//! sign `s₁`, welds below it included), group 2 every body rigid with the second joint's link
//! (`B`, coordinate `b`, sign `s₂`). With every rotation the identity at `q = 0` (the planar
//! tree's convention), link angles are `θ₁ = s₁ q_a` and `θ₂ = θ₁ + φ`, `φ = s₂ q_b`, and
//! rates `ω₁ = s₁ q̇_a`, `ω₂ = ω₁ + s₂ q̇_b`, i.e. `ω = S q̇` with `S = [[s₁, 0], [s₁, s₂]]`.
//! `O₁` is the first joint's (fixed) origin, `O₂ = O₁ + R₁ d` the second's, `d` fixed in link
//! `A`. Each group lumps into its mass `mᵢ`, first moment `hᵢ = Σ m r` and rotational inertia
//! `Jᵢ = Σ (I_zz + m |r|²)` about its joint, `r` the centre of mass from the joint in the
//! group's frame (read off the planar frames at `q = 0`).
//!
//! The engine's TMT method assembles `M̄ = Σ m Jvᵀ Jv + I_zz Jwᵀ Jw` and
//! `f̄ = Σ Jvᵀ m (g − a_bias)`, which is Lagrange's equations of `T − V` written body by body
//! (`Jv`, `Jw` the partial velocities, `a_bias` the convective acceleration `J̇ q̇`). Summing
//! the bodies of each group first: with `v_{O₂} = ω₁ ẑ × R₁ d`,
//!
//! `T = ½ (J₁ + m₂ |d|²) ω₁² + ω₁ ω₂ c(φ) + ½ J₂ ω₂²`,
//! `c(φ) = (R₁ d) · (R₂ h₂) = d · R(φ) h₂ = A cos φ + B sin φ`,
//! `A = d · h₂`, `B = d_y h₂ₓ − dₓ h₂_y`,
//!
//! `V = −g · (R₁ (h₁ + m₂ d) + R₂ h₂) + const`.
//!
//! Lagrange's equations in `θ₁`, `θ₂` (with `∂c/∂θ₂ = −∂c/∂θ₁ = c′(φ) = −A sin φ + B cos φ`):
//!
//! `J₁′ ω̇₁ + c ω̇₂ = Q₁ − c′ ω₂²`, `c ω̇₁ + J₂ ω̇₂ = Q₂ + c′ ω₁²`,
//! `J₁′ = J₁ + m₂ |d|²`, `Q₁ = (R₁ H₁) × g`, `H₁ = h₁ + m₂ d`, `Q₂ = (R₂ h₂) × g`
//!
//! (`u × g = uₓ g_y − u_y gₓ`, the moment of gravity). In the coordinates, `ω̇ = S q̈` and the
//! generalised forces are `Sᵀ` times these (`s₁² = s₂² = 1`):
//!
//! `M̄_aa = J₁′ + 2c + J₂`, `M̄_ab = s₁ s₂ (c + J₂)`, `M̄_bb = J₂`,
//! `f̄_a = s₁ (Q₁ + Q₂ − c′ (ω₂² − ω₁²))`, `f̄_b = s₂ (Q₂ + c′ ω₁²)`,
//!
//! less the joint springs and dampers (`k (q − q_rest) + d q̇`), as in the link pass. Finite
//! and infinitesimal bodies lump separately (the `ε` parts of `M̄`, `f̄`).

use super::chain::{Lumped, SerialChain};
use super::links::{Assembled, PlanarLinks};
use super::trig::sin_cos;
use nalgebra::{SMatrix, SVector};

/// The constants of `M̄` and `f̄` for one part (finite or infinitesimal bodies).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct PartConstants {
    /// `J₁′ + J₂` [kg·m²].
    j_sum_kg_m2: f64,
    /// `J₂` [kg·m²].
    j2_kg_m2: f64,
    /// `A = d · h₂` and `B = d_y h₂ₓ − dₓ h₂_y` [kg·m²].
    a_kg_m2: f64,
    b_kg_m2: f64,
    /// `h₂` (link B's frame) [kg·m].
    h2_kg_m: [f64; 2],
    /// The moments of gravity as `Q₁ = cos θ₁ G₁ − sin θ₁ G₁′` and `Q₂ = cos θ₂ G₂ − sin θ₂ G₂′`:
    /// `G = h × g = h_x g_y − h_y g_x`, `G′ = h · g` (of `H₁` and `h₂`) [N·m].
    gravity_moments_n_m: [f64; 4],
    /// `s₁ s₂`, the sign of `M̄_ab`.
    sign_ab: f64,
    /// The part has any mass or inertia.
    present: bool,
}

impl PartConstants {
    fn of(g1: &Lumped, g2: &Lumped, d: [f64; 2], [gx, gy]: [f64; 2], sign_ab: f64) -> Self {
        let j1p = g1.inertia_kg_m2 + g2.mass_kg * (d[0] * d[0] + d[1] * d[1]);
        let h2 = g2.moment_kg_m;
        let h1 = [
            g1.moment_kg_m[0] + g2.mass_kg * d[0],
            g1.moment_kg_m[1] + g2.mass_kg * d[1],
        ];
        Self {
            j_sum_kg_m2: j1p + g2.inertia_kg_m2,
            j2_kg_m2: g2.inertia_kg_m2,
            a_kg_m2: d[0] * h2[0] + d[1] * h2[1],
            b_kg_m2: d[1] * h2[0] - d[0] * h2[1],
            h2_kg_m: h2,
            gravity_moments_n_m: [
                h1[0] * gy - h1[1] * gx,
                h1[0] * gx + h1[1] * gy,
                h2[0] * gy - h2[1] * gx,
                h2[0] * gx + h2[1] * gy,
            ],
            sign_ab,
            present: *g1 != Lumped::default() || *g2 != Lumped::default(),
        }
    }
}

/// The trigonometry and rates of one evaluation.
struct Angles {
    /// `cos θ₁`, `sin θ₁`.
    c1: f64,
    s1: f64,
    /// `cos θ₂`, `sin θ₂`.
    c2: f64,
    s2: f64,
    /// `cos φ`, `sin φ`.
    cp: f64,
    sp: f64,
    /// `ω₁²` and `ω₂²`.
    w1_sq: f64,
    w2_sq: f64,
}

/// A planar two-link tree's equations of motion in closed form (see the module's derivation).
#[derive(Clone, Debug)]
pub(super) struct TwoLink {
    /// Coordinate of the first joint (on the ground) and its axis sign.
    a: (usize, f64),
    /// Coordinate of the second joint (below link A) and its axis sign.
    b: (usize, f64),
    /// Finite bodies' constants.
    finite: PartConstants,
    /// Infinitesimal bodies' constants.
    eps: PartConstants,
    /// Joint spring and damper per coordinate: stiffness, rest position, damping.
    springs: [(f64, f64, f64); 2],
    /// How `q̈` is solved with both coordinates free and no drive.
    solve: FreeSolve,
    /// The first joint owns coordinate 1 (the tree's order is `(b, a)`).
    swapped: bool,
    /// Any joint spring or damper.
    has_springs: bool,
}

/// How [`TwoLink::free_accelerations`] solves `M̄ q̈ = f̄` with both coordinates free.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum FreeSolve {
    /// Finite bodies only: the 2 × 2 inverse.
    Direct,
    /// The vanishing-mass limit with the finite `M̄`'s null space the second coordinate by
    /// structure (the swing leg's group has no finite mass off its joint, no finite inertia,
    /// no spring or damper: the simplest walker). `M̄ = M + ε M_ε`, `f̄ = f + ε f_ε`,
    /// `q̈ = x₀ + ε x₁ + …`: order 1 gives `M_aa x₀_a = f_a` (row b of `M` and `f_b` are zero),
    /// order ε projected on the null space `e_b` gives `(M_ε x₀)_b = f_ε,b`, i.e.
    /// `x₀_b = (f_ε,b − M_ε,ba x₀_a) / M_ε,bb` — what the general limit solve
    /// (`singular_limit`) finds from the eigenpairs of `M`.
    Limit,
    /// Anything else: the planar tree's solves on the closed-form matrices.
    Assembled,
}

impl TwoLink {
    /// The closed form of `tree`, or `None` when it is not a two-link chain: two coordinates,
    /// the first joint's link on the ground through welds only, the second joint's link below
    /// the first's, every body with mass on one of the two.
    pub(super) fn of(tree: &PlanarLinks) -> Option<Self> {
        let chain = SerialChain::<2>::of(tree)?;
        let [a, b] = chain.joints;
        let [finite, eps] = chain.groups;
        let (d, g, sign_ab) = (chain.offsets_m[0], tree.gravity_m_s2, a.1 * b.1);
        let finite = PartConstants::of(&finite[0], &finite[1], d, g, sign_ab);
        let eps = PartConstants::of(&eps[0], &eps[1], d, g, sign_ab);
        let springs = chain.springs;
        let swing_massless = finite.j2_kg_m2 == 0.0
            && finite.h2_kg_m == [0.0; 2]
            && springs[1].0 == 0.0
            && springs[1].2 == 0.0;
        let solve = match (eps.present, swing_massless) {
            (false, _) => FreeSolve::Direct,
            (true, true) => FreeSolve::Limit,
            (true, false) => FreeSolve::Assembled,
        };
        Some(Self {
            a,
            b,
            finite,
            eps,
            springs,
            solve,
            swapped: a.0 == 1,
            has_springs: chain.has_springs(),
        })
    }

    #[inline(always)]
    fn angles(&self, q: [f64; 2], qd: [f64; 2]) -> Angles {
        let (s1, c1) = sin_cos(self.a.1 * q[0]);
        let (sp, cp) = sin_cos(self.b.1 * q[1]);
        let w1 = self.a.1 * qd[0];
        let w2 = w1 + self.b.1 * qd[1];
        Angles {
            c1,
            s1,
            c2: c1 * cp - s1 * sp,
            s2: s1 * cp + c1 * sp,
            cp,
            sp,
            w1_sq: w1 * w1,
            w2_sq: w2 * w2,
        }
    }

    /// `M̄` (lower triangle `[aa, ba, bb]`) and `f̄` (`[a, b]`) of one part, springs excluded.
    #[inline(always)]
    fn part(&self, k: &PartConstants, t: &Angles) -> ([f64; 3], [f64; 2]) {
        let (sa, sb) = (self.a.1, self.b.1);
        let c = k.a_kg_m2 * t.cp + k.b_kg_m2 * t.sp;
        let c_prime = k.b_kg_m2 * t.cp - k.a_kg_m2 * t.sp;
        // The moments of gravity of R₁ H₁ and R₂ h₂ (`(R u) × g` expanded, constants folded).
        let [g1, g1p, g2, g2p] = k.gravity_moments_n_m;
        let q1 = t.c1 * g1 - t.s1 * g1p;
        let q2 = t.c2 * g2 - t.s2 * g2p;
        let fb = q2 + c_prime * t.w1_sq;
        let fa = q1 - c_prime * t.w2_sq + fb;
        (
            [
                k.j_sum_kg_m2 + 2.0 * c,
                k.sign_ab * (c + k.j2_kg_m2),
                k.j2_kg_m2,
            ],
            [sa * fa, sb * fb],
        )
    }

    /// The finite part's `M̄` (lower triangle) and `f̄` with the springs and dampers, and the
    /// angles, at `q`, `q̇` in the tree's coordinate order.
    #[inline(always)]
    fn finite_part(&self, q: [f64; 2], qd: [f64; 2]) -> ([f64; 3], [f64; 2], Angles) {
        let [qa, qb, qda, qdb] = if self.swapped {
            [q[1], q[0], qd[1], qd[0]]
        } else {
            [q[0], q[1], qd[0], qd[1]]
        };
        let t = self.angles([qa, qb], [qda, qdb]);
        let (m, mut f) = self.part(&self.finite, &t);
        if self.has_springs {
            let [(ka, ra, da), (kb, rb, db)] = self.springs;
            f[0] -= (qa - ra) * ka + qda * da;
            f[1] -= (qb - rb) * kb + qdb * db;
        }
        (m, f, t)
    }

    /// `[v_a, v_b]` from `v` in the tree's coordinate order, or back.
    #[inline(always)]
    fn ordered(&self, v: [f64; 2]) -> [f64; 2] {
        if self.swapped {
            [v[1], v[0]]
        } else {
            v
        }
    }

    /// Both parts of `M̄` and `f̄` as the link pass assembles them (`N` must be 2).
    pub(super) fn assemble<const N: usize>(
        &self,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
    ) -> Assembled<N> {
        let (m, f, t) = self.finite_part([q[0], q[1]], [qd[0], qd[1]]);
        let (me, fe) = if self.eps.present {
            self.part(&self.eps, &t)
        } else {
            ([0.0; 3], [0.0; 2])
        };
        Assembled {
            m: self.matrix(m),
            m_eps: self.matrix(me),
            f: self.vector(f),
            f_eps: self.vector(fe),
        }
    }

    /// The lower triangle `[aa, ba, bb]` as a matrix in the tree's coordinate order.
    fn matrix<const N: usize>(&self, l: [f64; 3]) -> SMatrix<f64, N, N> {
        let mut m = SMatrix::<f64, N, N>::zeros();
        let (a, b) = (self.a.0, self.b.0);
        m[(a, a)] = l[0];
        m[(a, b)] = l[1];
        m[(b, a)] = l[1];
        m[(b, b)] = l[2];
        m
    }

    /// `[a, b]` as a vector in the tree's coordinate order.
    #[inline(always)]
    fn vector<const N: usize>(&self, v: [f64; 2]) -> SVector<f64, N> {
        let v = self.ordered(v);
        SVector::<f64, N>::from_fn(|i, _| if i == 0 { v[0] } else { v[1] })
    }

    /// `q̈` with both coordinates free and no drive, by the 2 × 2 inverse (finite bodies) or
    /// the structural vanishing-mass limit ([`FreeSolve`]); `None` when neither applies or
    /// the matrix is not positive definite there (left to the planar tree's solves and their
    /// errors). `N` must be 2.
    pub(super) fn free_accelerations<const N: usize>(
        &self,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
    ) -> Option<SVector<f64, N>> {
        let (q, qd) = ([q[0], q[1]], [qd[0], qd[1]]);
        match self.solve {
            FreeSolve::Direct => {
                let ([maa, mba, mbb], [fa, fb], _) = self.finite_part(q, qd);
                let det = maa * mbb - mba * mba;
                if !(maa > 0.0 && det > 0.0) {
                    return None;
                }
                Some(self.vector([(mbb * fa - mba * fb) / det, (maa * fb - mba * fa) / det]))
            }
            FreeSolve::Limit => {
                let ([maa, _, _], [fa, _], t) = self.finite_part(q, qd);
                let ([_, eba, ebb], [_, feb]) = self.part(&self.eps, &t);
                if !(maa > 0.0 && ebb > 0.0) {
                    return None;
                }
                let qdd_a = fa / maa;
                Some(self.vector([qdd_a, (feb - eba * qdd_a) / ebb]))
            }
            FreeSolve::Assembled => None,
        }
    }
}
