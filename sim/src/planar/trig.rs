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
//! fixed-size stride's witnesses and the 3D fast path (`crate::axis_tree`). The
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
