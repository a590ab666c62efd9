//! The equations of motion of a planar three-link serial chain in closed form: a stance leg on
//! the ground, a thigh on its hip, a shank on the thigh's knee (the kneed walker), with point
//! and distributed masses and welds anywhere, finite bodies only. Built once from the planar
//! tree's own data ([`ThreeLink::of`], structurally: three coordinates, each joint's link below
//! the previous joint's); the link pass of [`super::PlanarTree`] and the general engine stay
//! the reference it is tested against (`sim/tests/fast_path.rs`).
//!
//! # Derivation
//!
//! The two-link derivation (`two_link.rs`) with one more group. Group `k` (`k = 1, 2, 3`) is
//! every body rigid with joint `k`'s link (axis sign `sₖ`), lumped into its mass `mₖ`, first
//! moment `hₖ` and rotational inertia `Jₖ` about its joint in its link's frame; `dₖ` is joint
//! `k + 1`'s origin from joint `k`'s in group `k`'s frame (`d₃ = 0`), `μₖ = Σ_{l>k} mₗ` the mass
//! below group `k`, `Hₖ = hₖ + μₖ dₖ`. Link angles `θₖ = θₖ₋₁ + sₖ qₖ`, rates `ω = S q̇` with
//! `S[k][i] = sᵢ` for `i ≤ k`. Joint `k`'s origin moves with `Σ_{i<k} ωᵢ ẑ × Rᵢ dᵢ`, so
//!
//! `T = ½ Σ_{k,l} P_kl ωₖ ωₗ`, `P_kk = Jₖ + μₖ |dₖ|²`, `P_kl = (Rₖ dₖ) · (Rₗ Hₗ) = c_kl(θₗ − θₖ)`
//! for `k < l`, `c_kl(φ) = A_kl cos φ + B_kl sin φ`, `A = dₖ · Hₗ`, `B = dₖ_y Hₗₓ − dₖₓ Hₗ_y`,
//!
//! `V = −g · Σₖ Rₖ Hₖ + const`. Lagrange's equations in `θ` (each `c_kl` depends on
//! `θₗ − θₖ` only): `Σₗ P_kl ω̇ₗ = Qₖ − Σ_{l>k} c′_kl ωₗ² + Σ_{l<k} c′_lk ωₗ²`, `Qₖ = (Rₖ Hₖ) × g`
//! — for two groups exactly the two-link equations. In the coordinates `M̄ = Sᵀ P S`,
//! `f̄ = Sᵀ (Q − …)`: `M̄_ij = sᵢ sⱼ Σ_{k≥i, l≥j} P_kl`, `f̄ᵢ = sᵢ Σ_{k≥i} fₖ`, less the joint
//! springs and dampers (`k (q − q_rest) + d q̇`), as in the link pass.

use super::chain::SerialChain;
use super::links::{Assembled, PlanarLinks};
use super::trig::sin_cos;
use nalgebra::{SMatrix, SVector};

/// A planar three-link serial chain's equations of motion in closed form (see the module's
/// derivation).
#[derive(Clone, Debug)]
pub(super) struct ThreeLink {
    /// Coordinate of each joint, ground first, and its axis sign.
    joints: [(usize, f64); 3],
    /// `P_kk` per group [kg·m²].
    diagonal_kg_m2: [f64; 3],
    /// `A_kl`, `B_kl` of the pairs `(1, 2)`, `(2, 3)`, `(1, 3)` [kg·m²].
    pairs_kg_m2: [(f64, f64); 3],
    /// `Gₖ = Hₖ × g` and `G′ₖ = Hₖ · g` per group: `Qₖ = cos θₖ Gₖ − sin θₖ G′ₖ` [N·m].
    gravity_moments_n_m: [(f64, f64); 3],
    /// Joint spring and damper per joint: stiffness, rest position, damping.
    springs: [(f64, f64, f64); 3],
    /// Any joint spring or damper.
    has_springs: bool,
}

impl ThreeLink {
    /// The closed form of `tree`, or `None` when it is not a three-link serial chain of finite
    /// bodies: three coordinates, the first joint's link on the ground through welds only,
    /// each further joint's link below the previous joint's, every body with mass rigid with
    /// one of the three, none infinitesimal.
    pub(super) fn of(tree: &PlanarLinks) -> Option<Self> {
        if tree.has_infinitesimal {
            return None;
        }
        let chain = SerialChain::<3>::of(tree)?;
        let (d, groups) = (chain.offsets_m, chain.groups[0]);
        // The mass below each group (μₖ).
        let below = [
            groups[1].mass_kg + groups[2].mass_kg,
            groups[2].mass_kg,
            0.0,
        ];
        let big_h: [[f64; 2]; 3] = std::array::from_fn(|k| {
            let h = groups[k].moment_kg_m;
            [h[0] + below[k] * d[k][0], h[1] + below[k] * d[k][1]]
        });
        let diagonal_kg_m2 = std::array::from_fn(|k| {
            groups[k].inertia_kg_m2 + below[k] * (d[k][0] * d[k][0] + d[k][1] * d[k][1])
        });
        let pair = |k: usize, l: usize| {
            let (dk, hl) = (d[k], big_h[l]);
            (dk[0] * hl[0] + dk[1] * hl[1], dk[1] * hl[0] - dk[0] * hl[1])
        };
        let [gx, gy] = tree.gravity_m_s2;
        let gravity_moments_n_m = std::array::from_fn(|k| {
            let hk = big_h[k];
            (hk[0] * gy - hk[1] * gx, hk[0] * gx + hk[1] * gy)
        });
        Some(Self {
            joints: chain.joints,
            diagonal_kg_m2,
            pairs_kg_m2: [pair(0, 1), pair(1, 2), pair(0, 2)],
            gravity_moments_n_m,
            springs: chain.springs,
            has_springs: chain.has_springs(),
        })
    }

    /// `M̄` and `f̄` (finite bodies; the `ε` parts zero) at `q`, `q̇` in the tree's coordinate
    /// order (`N` must be 3).
    #[inline]
    pub(super) fn assemble<const N: usize>(
        &self,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
    ) -> Assembled<N> {
        let [(c1, s1), (c2, s2), (c3, s3)] = self.joints;
        let (qa, qb, qc) = (q[c1], q[c2], q[c3]);
        let (sin1, cos1) = sin_cos(s1 * qa);
        let (sin_p2, cos_p2) = sin_cos(s2 * qb);
        let (sin_p3, cos_p3) = sin_cos(s3 * qc);
        // Link angles θ₂ = θ₁ + φ₂, θ₃ = θ₂ + φ₃, and φ₁₃ = φ₂ + φ₃.
        let (cos2, sin2) = (cos1 * cos_p2 - sin1 * sin_p2, sin1 * cos_p2 + cos1 * sin_p2);
        let (cos3, sin3) = (cos2 * cos_p3 - sin2 * sin_p3, sin2 * cos_p3 + cos2 * sin_p3);
        let (cos13, sin13) = (
            cos_p2 * cos_p3 - sin_p2 * sin_p3,
            sin_p2 * cos_p3 + cos_p2 * sin_p3,
        );
        let w1 = s1 * qd[c1];
        let w2 = w1 + s2 * qd[c2];
        let w3 = w2 + s3 * qd[c3];
        let (w1sq, w2sq, w3sq) = (w1 * w1, w2 * w2, w3 * w3);
        // c and c′ of the pairs (1, 2), (2, 3), (1, 3).
        let cc = |(a, b): (f64, f64), cp: f64, sp: f64| (a * cp + b * sp, b * cp - a * sp);
        let (c12, d12) = cc(self.pairs_kg_m2[0], cos_p2, sin_p2);
        let (c23, d23) = cc(self.pairs_kg_m2[1], cos_p3, sin_p3);
        let (c13, d13) = cc(self.pairs_kg_m2[2], cos13, sin13);
        let [(g1, g1p), (g2, g2p), (g3, g3p)] = self.gravity_moments_n_m;
        let f1 = cos1 * g1 - sin1 * g1p - d12 * w2sq - d13 * w3sq;
        let f2 = cos2 * g2 - sin2 * g2p - d23 * w3sq + d12 * w1sq;
        let f3 = cos3 * g3 - sin3 * g3p + d13 * w1sq + d23 * w2sq;
        let [p11, p22, p33] = self.diagonal_kg_m2;
        // Suffix sums U_ij = Σ_{k≥i, l≥j} P_kl (i ≤ j) and Σ_{k≥i} fₖ.
        let u33 = p33;
        let u23 = c23 + p33;
        let u22 = p22 + 2.0 * c23 + p33;
        let u13 = c13 + u23;
        let u12 = c12 + c13 + u22;
        let u11 = p11 + 2.0 * (c12 + c13) + u22;
        let (f3s, f2s) = (f3, f2 + f3);
        let f1s = f1 + f2s;
        let mut m = SMatrix::<f64, N, N>::zeros();
        let mut f = SVector::<f64, N>::zeros();
        let set = |m: &mut SMatrix<f64, N, N>, i: (usize, f64), j: (usize, f64), v: f64| {
            m[(i.0, j.0)] = i.1 * j.1 * v;
            m[(j.0, i.0)] = i.1 * j.1 * v;
        };
        let [ja, jb, jc] = self.joints;
        set(&mut m, ja, ja, u11);
        set(&mut m, ja, jb, u12);
        set(&mut m, ja, jc, u13);
        set(&mut m, jb, jb, u22);
        set(&mut m, jb, jc, u23);
        set(&mut m, jc, jc, u33);
        f[c1] = s1 * f1s;
        f[c2] = s2 * f2s;
        f[c3] = s3 * f3s;
        if self.has_springs {
            for (&(c, _), &(k, rest, damping)) in self.joints.iter().zip(&self.springs) {
                f[c] -= (q[c] - rest) * k + qd[c] * damping;
            }
        }
        Assembled {
            m,
            m_eps: SMatrix::zeros(),
            f,
            f_eps: SVector::zeros(),
        }
    }
}
