//! The sine and cosine of the planar fast path: musl's `sincos` (the `libm` crate, FreeBSD's
//! `k_sin`/`k_cos` kernels, an error below one ulp), which for `|x| ≤ π/4` goes straight to the
//! two polynomial kernels and for larger angles through the medium-range `rem_pio2`. glibc's
//! `sincos` (what `f64::sin_cos` calls) spends about 112 instructions a call on its general
//! dispatch; musl's 69 (callgrind; docs/performance.md, fifth round). Both are within an ulp
//! of the exact values, and they differ from each other by at most one ulp on the angles the
//! walkers meet (`sim/tests/planar_sin_cos.rs` checks it over `[-4π, 4π]`).
//!
//! For `2⁻²⁷√2 ≤ |x| ≤ π/4` (the leg angles of a walk) the two kernels are written out here,
//! inlined and sharing `x²` and `x⁴`: the same operations in the same order as `libm`'s
//! `k_sin(x, 0, 0)` and `k_cos(x, 0)`, so bit for bit its results (the unit test below checks
//! it over the range and at its ends), in about 40 instructions instead of 69. Every other
//! argument goes to `libm::sincos`.
//!
//! Used by the two- and three-link closed forms (`two_link.rs`, `three_link.rs`), the
//! fixed-size stride's witnesses and the 3D fast path (`crate::engine::axis_tree`). The
//! link pass and [`super::PlanarTree::frames`] keep the standard library's: the link pass is
//! checked against the general engine (which uses it) to 1e-13 relative, and wisse2d's
//! ill-conditioned `q̈` turns a one-ulp difference in an angle into 2.6e-13 of it.

/// The high word of `|x|`'s bits at and above which the kernels are used: `2⁻²⁷√2` (below it
/// `libm` returns `(x, 1)`).
const KERNEL_LOW: u32 = 0x3e46_a09e;
/// The high word of `|x|`'s bits at and below which no argument reduction is needed: `π/4`.
const KERNEL_HIGH: u32 = 0x3fe9_21fb;

/// FreeBSD's `k_sin` coefficients (`libm`'s `S1 … S6`, by their bits).
const S1: f64 = f64::from_bits(0xbfc55555_55555549);
const S2: f64 = f64::from_bits(0x3f811111_1110f8a6);
const S3: f64 = f64::from_bits(0xbf2a01a0_19c161d5);
const S4: f64 = f64::from_bits(0x3ec71de3_57b1fe7d);
const S5: f64 = f64::from_bits(0xbe5ae5e6_8a2b9ceb);
const S6: f64 = f64::from_bits(0x3de5d93a_5acfd57c);
/// FreeBSD's `k_cos` coefficients (`libm`'s `C1 … C6`, by their bits).
const C1: f64 = f64::from_bits(0x3fa55555_5555554c);
const C2: f64 = f64::from_bits(0xbf56c16c_16c15177);
const C3: f64 = f64::from_bits(0x3efa01a0_19cb1590);
const C4: f64 = f64::from_bits(0xbe927e4f_809c52ad);
const C5: f64 = f64::from_bits(0x3e21ee9e_bdb4b1c4);
const C6: f64 = f64::from_bits(0xbda8fae9_be8838d4);

/// `(sin x, cos x)` for an angle `x` \[rad\], within an ulp of the exact values (`libm`'s
/// `sincos`, bit for bit).
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    let high = ((x.to_bits() >> 32) as u32) & 0x7fff_ffff;
    if (KERNEL_LOW..=KERNEL_HIGH).contains(&high) {
        kernels(x)
    } else {
        libm::sincos(x)
    }
}

/// `libm`'s `k_sin(x, 0, 0)` and `k_cos(x, 0)` for `2⁻²⁷√2 ≤ |x| ≤ π/4`, their operations in
/// their order. `k_cos`'s last term `z·r − x·y` is `z·r` with `y = 0`: `z·r` is a normal
/// number on this range, so subtracting `x·0 = ±0` does not change it.
#[inline(always)]
fn kernels(x: f64) -> (f64, f64) {
    let z = x * x;
    let w = z * z;
    let r_sin = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6);
    let v = z * x;
    let sin = x + v * (S1 + z * r_sin);
    let r_cos = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
    let hz = 0.5 * z;
    let one_minus_hz = 1.0 - hz;
    let cos = one_minus_hz + (((1.0 - one_minus_hz) - hz) + z * r_cos);
    (sin, cos)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bit for bit `libm::sincos` at `x` (signed zeros and NaNs by their bits).
    fn same_as_libm(x: f64) -> bool {
        let (s, c) = sin_cos(x);
        let (s_ref, c_ref) = libm::sincos(x);
        s.to_bits() == s_ref.to_bits() && c.to_bits() == c_ref.to_bits()
    }

    #[test]
    fn the_inlined_kernels_are_libm_sincos_bit_for_bit() {
        let quarter = std::f64::consts::FRAC_PI_4;
        let n = 1_000_000;
        for i in 0..=n {
            let x = -quarter + 2.0 * quarter * i as f64 / n as f64;
            assert!(same_as_libm(x), "{x:e}");
        }
        // The ends of the kernel range, one ulp either side, and outside it.
        let high = |w: u32| f64::from_bits(u64::from(w) << 32);
        let mut edges = vec![
            0.0,
            -0.0,
            1e-300,
            1e-9,
            3.0,
            -100.0,
            f64::NAN,
            f64::INFINITY,
        ];
        for w in [KERNEL_LOW, KERNEL_HIGH, KERNEL_HIGH + 1] {
            let x = high(w);
            for y in [
                x,
                f64::from_bits(x.to_bits() - 1),
                f64::from_bits(x.to_bits() + 1),
            ] {
                edges.extend([y, -y, y + high(w) * 1e-9]);
            }
        }
        edges.push(f64::from_bits((u64::from(KERNEL_HIGH) << 32) | 0xffff_ffff));
        for x in edges {
            assert!(same_as_libm(x), "{x:e}");
        }
        // Small angles on a logarithmic sweep, through the lower end.
        let mut x = 1e-10;
        while x < quarter {
            assert!(same_as_libm(x) && same_as_libm(-x), "{x:e}");
            x *= 1.001;
        }
    }
}

/// The planar fast path's `sin_cos` (musl's, the `libm` crate) against the standard library's
/// (glibc's `sincos`), both within an ulp of the exact values: on the angles the walkers meet
/// they differ by at most one ulp, and they agree exactly at the special values.
#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
mod against_std {
    use super::sin_cos;

    /// Distance in ulps between two finite values of the same sign (or both within an ulp of 0).
    fn ulps(a: f64, b: f64) -> u64 {
        if a == b {
            return 0;
        }
        let key = |x: f64| {
            let bits = x.to_bits() as i64;
            if bits < 0 {
                i64::MIN - bits
            } else {
                bits
            }
        };
        key(a).abs_diff(key(b))
    }

    /// Largest ulp distance of sine and cosine over `n` evenly spaced angles in `[lo, hi]`, and
    /// the fraction of angles where either differs at all.
    fn sweep(lo: f64, hi: f64, n: usize) -> (u64, u64, f64) {
        let (mut worst_sin, mut worst_cos, mut differing) = (0, 0, 0);
        for i in 0..=n {
            let x = lo + (hi - lo) * i as f64 / n as f64;
            let (s, c) = sin_cos(x);
            let (s_ref, c_ref) = x.sin_cos();
            let (ds, dc) = (ulps(s, s_ref), ulps(c, c_ref));
            worst_sin = worst_sin.max(ds);
            worst_cos = worst_cos.max(dc);
            differing += usize::from(ds + dc > 0);
        }
        (worst_sin, worst_cos, differing as f64 / (n + 1) as f64)
    }

    #[test]
    fn sin_cos_is_within_an_ulp_of_the_standard_library_on_walker_angles() {
        // The walkers' joint angles: legs within ±π/4 of the vertical (the kernels alone), hip and
        // knee angles up to ±π, and whole turns either way (argument reduction).
        for (lo, hi) in [
            (-std::f64::consts::FRAC_PI_4, std::f64::consts::FRAC_PI_4),
            (-std::f64::consts::PI, std::f64::consts::PI),
            (-2.0 * std::f64::consts::TAU, 2.0 * std::f64::consts::TAU),
        ] {
            let (s, c, frac) = sweep(lo, hi, 400_000);
            println!("[{lo:.3}, {hi:.3}]: sin {s} ulp, cos {c} ulp, differing at {frac:.4}");
            assert!(s <= 1 && c <= 1, "[{lo}, {hi}]: sin {s} ulp, cos {c} ulp");
            // Not the standard library under another name: some results differ.
            assert!(frac > 0.0, "[{lo}, {hi}]: identical everywhere");
        }
    }

    #[test]
    fn sin_cos_is_exact_at_special_values_and_not_finite_off_them() {
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        let (s, c) = sin_cos(-0.0);
        assert!(s == 0.0 && s.is_sign_negative() && c == 1.0);
        // Tiny angles: sin x = x and cos x = 1 to the last bit.
        for x in [1e-300, -3e-12, 1e-9] {
            assert_eq!(sin_cos(x), (x, 1.0));
        }
        for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let (s, c) = sin_cos(x);
            assert!(s.is_nan() && c.is_nan(), "{x}");
        }
    }
}
