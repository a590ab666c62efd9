//! The sine and cosine of the planar fast path: musl's `sincos` (the `libm` crate, FreeBSD's
//! `k_sin`/`k_cos` kernels, an error below one ulp), which for `|x| ≤ π/4` goes straight to the
//! two polynomial kernels and for larger angles through the medium-range `rem_pio2`. glibc's
//! `sincos` (what `f64::sin_cos` calls) spends about 112 instructions a call on its general
//! dispatch; this one 61 (callgrind; docs/performance.md, fifth round). Both are within an ulp
//! of the exact values, and they differ from each other by at most one ulp on the angles the
//! walkers meet (`sim/tests/planar_sin_cos.rs` checks it over `[-4π, 4π]`).
//!
//! Used by the two- and three-link closed forms (`two_link.rs`, `three_link.rs`) and the
//! fixed-size stride's witnesses. The
//! link pass and [`super::PlanarTree::frames`] keep the standard library's: the link pass is
//! checked against the general engine (which uses it) to 1e-13 relative, and wisse2d's
//! ill-conditioned `q̈` turns a one-ulp difference in an angle into 2.6e-13 of it.

/// `(sin x, cos x)` for an angle `x` [rad], within an ulp of the exact values.
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    libm::sincos(x)
}
