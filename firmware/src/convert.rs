//! Saturating conversions of measured and computed floats to the integers of fault details
//! and drivers. Float-to-integer `as` casts in Rust saturate at the target's limits and map
//! NaN to 0 — a saturation, never a wrap; the functions here are the only such casts in the
//! crate, each with its NaN meaning stated.

/// `x` rounded toward zero to an `i16`, saturating at `i16::MIN`/`i16::MAX` (±∞ included);
/// NaN gives 0. For fault details (offending values in fixed units): a detail is a report, so
/// a value past the field reads as the field's limit, and an unmeasurable one as 0.
pub fn saturating_i16(x: f32) -> i16 {
    // Float-to-int `as` saturates and maps NaN to 0: exactly the documented result.
    #[allow(clippy::cast_possible_truncation)]
    let v = x as i16;
    v
}

/// `x` rounded toward zero to an `i32`, saturating at `i32::MIN`/`i32::MAX` (±∞ included);
/// NaN gives 0.
pub fn saturating_i32(x: f32) -> i32 {
    // Float-to-int `as` saturates and maps NaN to 0: exactly the documented result.
    #[allow(clippy::cast_possible_truncation)]
    let v = x as i32;
    v
}

/// A PWM compare value for a duty `fraction` of `max_duty`: the fraction clamped to
/// `[0, 1]` (NaN gives 0, off), times `max_duty`, rounded toward zero. Never above
/// `max_duty`, whatever the fraction.
pub fn duty_from_fraction(fraction: f32, max_duty: u16) -> u16 {
    let f = if fraction.is_nan() {
        0.0
    } else {
        fraction.clamp(0.0, 1.0)
    };
    // 0 ≤ f × max_duty ≤ max_duty ≤ u16::MAX (exact in f32): the cast neither truncates
    // past the range nor loses the sign; rounding toward zero is the intended quantisation.
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let duty = (f * f32::from(max_duty)) as u16;
    duty.min(max_duty)
}
