//! The ankle's extension profile (paper Fig. 8), written once for both of its users: the
//! simulator's ideal ankle drive (`sim::hybrid::profile`, in `f64` and in the dual numbers of
//! its sensitivities) and the firmware's push setpoint (`firmware::reflex`, in `f32`).
//!
//! The profile is the quintic minimum-jerk smooth step
//! `s(x) = 10x³ − 15x⁴ + 6x⁵` of the normalised time `x = elapsed / duration`, with zero rate
//! and zero acceleration at both ends; the angle goes from `from` at `x = 0` to `to` at
//! `x = 1` and stays there. Its peak slope `ds/dx` is [`PEAK_SLOPE`] (at `x = ½`), so the
//! peak angular rate is `PEAK_SLOPE · (to − from) / duration`.
//!
//! The code is generic over any scalar with the four arithmetic operations and an order; the
//! caller passes `lift`, which turns the profile's small constants (`0`, `1`, `2`, `6`, `10`,
//! `15`, `30`, `60`, all exact in `f32`) into its scalar: `|c| c` for `f32`,
//! `|c| T::from_f64(f64::from(c))` for a `nalgebra::RealField`. (A trait of this crate could
//! not be implemented for every `RealField` in the simulator: the orphan rule.)
//!
//! No dependencies, no allocation, no panics: it builds for the board's `no_std` target.
#![no_std]

use core::cmp::Ordering;
use core::ops::{Add, Div, Mul, Sub};

/// The profile's peak slope `max ds/dx` (at `x = ½`: `30 · ¼ · ¼`) [-].
pub const PEAK_SLOPE: f64 = 1.875;

/// What the profile needs of a scalar: copies, the four operations, an order (a dual number
/// is ordered by its value).
pub trait Scalar:
    Copy
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
{
}

impl<T> Scalar for T where
    T: Copy + PartialOrd + Add<Output = T> + Sub<Output = T> + Mul<Output = T> + Div<Output = T>
{
}

/// The normalised smooth step at one instant: `s` and its derivatives in `x`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blend<T> {
    /// `s(x)` in [0, 1] [-].
    pub s: T,
    /// `ds/dx` [-].
    pub ds_dx: T,
    /// `d²s/dx²` [-].
    pub d2s_dx2: T,
}

/// The minimum-jerk blend at normalised time `x`: 0 at rest for `x ≤ 0` (and for a NaN
/// `x`), 1 at rest for `x ≥ 1`, else `s = x³(10 − 15x + 6x²)`, `ds/dx = 30x²(1 − x)²`,
/// `d²s/dx² = 60x(1 − x)(1 − 2x)`. `s` is clamped to [0, 1] against rounding (a value one
/// unit in the last place above 1 near `x = 1`).
pub fn blend<T: Scalar>(x: T, lift: impl Fn(f32) -> T) -> Blend<T> {
    let zero = lift(0.0);
    let one = lift(1.0);
    // Not "x <= 0": a NaN time (unordered) gives the start, at rest.
    if x.partial_cmp(&zero) != Some(Ordering::Greater) {
        return Blend {
            s: zero,
            ds_dx: zero,
            d2s_dx2: zero,
        };
    }
    if x >= one {
        return Blend {
            s: one,
            ds_dx: zero,
            d2s_dx2: zero,
        };
    }
    let (x2, x3) = (x * x, x * x * x);
    let s = x3 * (lift(10.0) - lift(15.0) * x + lift(6.0) * x2);
    let s = if s > one {
        one
    } else if s < zero {
        zero
    } else {
        s
    };
    Blend {
        s,
        ds_dx: lift(30.0) * x2 * (one - x) * (one - x),
        d2s_dx2: lift(60.0) * x * (one - x) * (one - lift(2.0) * x),
    }
}

/// One extension: from angle `from` to angle `to` over `duration` (any consistent units:
/// rad and s for both users).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extension<T> {
    /// Angle at the start \[rad\].
    pub from: T,
    /// Angle at the end, held after \[rad\].
    pub to: T,
    /// Duration \[s\], positive.
    pub duration: T,
}

/// The extension at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample<T> {
    /// Angle \[rad\].
    pub angle: T,
    /// Rate [rad/s].
    pub rate: T,
    /// Acceleration [rad/s²].
    pub acceleration: T,
}

impl<T: Scalar> Extension<T> {
    /// The normalised time `elapsed / duration` [-].
    fn x(&self, elapsed: T) -> T {
        elapsed / self.duration
    }

    /// The angle `elapsed` \[s\] after the start (`from` before it, `to` after the end).
    pub fn angle(&self, elapsed: T, lift: impl Fn(f32) -> T) -> T {
        let b = blend(self.x(elapsed), lift);
        self.from + (self.to - self.from) * b.s
    }

    /// Angle, rate and acceleration `elapsed` \[s\] after the start (at rest before the start
    /// and after the end).
    pub fn sample(&self, elapsed: T, lift: impl Fn(f32) -> T) -> Sample<T> {
        let d = self.duration;
        let b = blend(self.x(elapsed), lift);
        let span = self.to - self.from;
        Sample {
            angle: self.from + span * b.s,
            rate: span * b.ds_dx / d,
            acceleration: span * b.d2s_dx2 / (d * d),
        }
    }
}

/// The duration \[s\] an extension over `span` \[rad\] needs so that its peak rate
/// (`PEAK_SLOPE · span / duration`) stays within `max_rate` [rad/s]: `duration` itself when
/// that is long enough, else the stretched one (the firmware's rate bound; the host's report
/// of it).
pub fn duration_within_rate<T: Scalar>(
    span: T,
    duration: T,
    max_rate: T,
    lift: impl Fn(f32) -> T,
) -> T {
    let by_rate = lift(PEAK_SLOPE as f32) * span / max_rate;
    if by_rate > duration {
        by_rate
    } else {
        duration
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn id(c: f32) -> f32 {
        c
    }

    fn f64_of(c: f32) -> f64 {
        f64::from(c)
    }

    #[test]
    fn blend_ends_at_rest_and_is_bounded_and_monotone() {
        for x in [-1.0_f32, 0.0, f32::NAN] {
            assert_eq!(
                blend(x, id),
                Blend {
                    s: 0.0,
                    ds_dx: 0.0,
                    d2s_dx2: 0.0
                },
                "{x}"
            );
        }
        for x in [1.0_f32, 2.0] {
            assert_eq!(blend(x, id).s, 1.0);
            assert_eq!(blend(x, id).ds_dx, 0.0);
        }
        let mut last = 0.0_f32;
        for k in 1..=1000 {
            let s = blend(k as f32 / 1000.0, id).s;
            assert!((0.0..=1.0).contains(&s));
            assert!(s >= last - 1e-6, "monotone up to rounding");
            assert!(
                (s - last) * 1000.0 <= PEAK_SLOPE as f32 + 1e-3,
                "peak slope"
            );
            last = s;
        }
        // Peak slope at the middle, and the middle is half-way.
        let mid = blend(0.5_f64, f64_of);
        assert_eq!(mid.s, 0.5);
        assert_eq!(mid.ds_dx, PEAK_SLOPE);
        assert_eq!(mid.d2s_dx2, 0.0);
    }

    #[test]
    fn rate_and_acceleration_are_the_derivatives_of_the_angle() {
        let e = Extension {
            from: -0.08_f64,
            to: 0.2,
            duration: 0.27,
        };
        let h = 1e-6;
        for t in [0.02, 0.1, 0.135, 0.2, 0.26] {
            let s = e.sample(t, f64_of);
            let (p, m) = (e.sample(t + h, f64_of), e.sample(t - h, f64_of));
            assert!(
                ((p.angle - m.angle) / (2.0 * h) - s.rate).abs() < 1e-6,
                "{t}"
            );
            assert!(((p.rate - m.rate) / (2.0 * h) - s.acceleration).abs() < 1e-4);
            assert_eq!(s.angle, e.angle(t, f64_of));
        }
        assert_eq!(e.angle(-0.1, f64_of), -0.08);
        assert_eq!(e.angle(0.27, f64_of), 0.2);
        assert_eq!(e.sample(0.3, f64_of).rate, 0.0);
        // Peak rate 1.875 · 0.28 / 0.27 at half time.
        let peak = e.sample(0.135, f64_of).rate;
        assert!((peak - PEAK_SLOPE * 0.28 / 0.27).abs() < 1e-12, "{peak}");
    }

    #[test]
    fn the_rate_bound_stretches_only_a_too_fast_extension() {
        // 1.875 · 0.28 / 4 = 0.13125 s < 0.27 s: not stretched.
        assert_eq!(duration_within_rate(0.28_f32, 0.27, 4.0, id), 0.27);
        assert!((duration_within_rate(0.28_f32, 0.27, 1.0, id) - 0.525).abs() < 1e-6);
        assert_eq!(duration_within_rate(0.28_f64, 0.27, 4.0, f64_of), 0.27);
    }
}
