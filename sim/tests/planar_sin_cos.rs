//! The planar fast path's `sin_cos` (musl's, the `libm` crate) against the standard library's
//! (glibc's `sincos`), both within an ulp of the exact values: on the angles the walkers meet
//! they differ by at most one ulp, and they agree exactly at the special values.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use sim::planar::sin_cos;

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
