//! The cubic Hermite interpolant, written once: from values and rates at the two ends of an
//! interval `[t0, t0 + h]`, the unique cubic through them (eq. 14). The stride locates events
//! on it, checks grazing contacts on it, and a controller's actuator segment is one.

use nalgebra::DVector;

/// The four cubic Hermite basis polynomials at the normalised time `x = (t − t0) / h`, with
/// their first and second derivatives with respect to `x`: the weights of `(p0, h·v0, p1,
/// h·v1)`. The scalar and vector forms below scale them by the interval length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HermiteBasis {
    /// `h00, h10, h01, h11` at `x`.
    pub value: [f64; 4],
    /// Their first derivatives with respect to `x`.
    pub d_dx: [f64; 4],
    /// Their second derivatives with respect to `x`.
    pub d2_dx2: [f64; 4],
}

impl HermiteBasis {
    /// The basis at `x` (0 at the start of the interval, 1 at its end).
    pub fn at(x: f64) -> Self {
        let (x2, x3) = (x * x, x * x * x);
        Self {
            value: [
                1.0 - 3.0 * x2 + 2.0 * x3,
                x - 2.0 * x2 + x3,
                3.0 * x2 - 2.0 * x3,
                -x2 + x3,
            ],
            d_dx: [
                -6.0 * x + 6.0 * x2,
                1.0 - 4.0 * x + 3.0 * x2,
                6.0 * x - 6.0 * x2,
                -2.0 * x + 3.0 * x2,
            ],
            d2_dx2: [
                -6.0 + 12.0 * x,
                -4.0 + 6.0 * x,
                6.0 - 12.0 * x,
                -2.0 + 6.0 * x,
            ],
        }
    }
}

/// One scalar endpoint of a Hermite interval: a value and its rate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Knot {
    /// Value (its own unit).
    pub value: f64,
    /// Rate (unit per second).
    pub rate: f64,
}

/// The scalar interpolant between `a` at the start and `b` at the end of an interval of `h_s`
/// \[s\], at normalised time `x`: value, rate and acceleration.
pub fn scalar(a: Knot, b: Knot, h_s: f64, x: f64) -> (f64, f64, f64) {
    let HermiteBasis {
        value: w,
        d_dx: d,
        d2_dx2: dd,
    } = HermiteBasis::at(x);
    let p = w[0] * a.value + w[1] * h_s * a.rate + w[2] * b.value + w[3] * h_s * b.rate;
    let v = (d[0] * a.value + d[2] * b.value) / h_s + d[1] * a.rate + d[3] * b.rate;
    let acc =
        (dd[0] * a.value + dd[2] * b.value) / (h_s * h_s) + (dd[1] * a.rate + dd[3] * b.rate) / h_s;
    (p, v, acc)
}

/// The vector interpolant of `q` between `(q0, qd0)` at the start and `(q1, qd1)` at the end of
/// an interval of `h_s` \[s\], at normalised time `x`: `q` and its rate.
pub fn vector(
    (q0, qd0): (&DVector<f64>, &DVector<f64>),
    (q1, qd1): (&DVector<f64>, &DVector<f64>),
    h_s: f64,
    x: f64,
) -> (DVector<f64>, DVector<f64>) {
    let HermiteBasis {
        value: w, d_dx: d, ..
    } = HermiteBasis::at(x);
    let q = q0 * w[0] + qd0 * (w[1] * h_s) + q1 * w[2] + qd1 * (w[3] * h_s);
    let qd = q0 * (d[0] / h_s) + qd0 * d[1] + q1 * (d[2] / h_s) + qd1 * d[3];
    (q, qd)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scalar_and_vector_forms_are_exact_for_cubics() {
        let f = |t: f64| 1.0 + 2.0 * t - t * t + 0.5 * t * t * t;
        let df = |t: f64| 2.0 - 2.0 * t + 1.5 * t * t;
        let ddf = |t: f64| -2.0 + 3.0 * t;
        let (t0, t1, t) = (0.3, 1.1, 0.77);
        let (h, x) = (t1 - t0, (t - t0) / (t1 - t0));
        let k = |t: f64| Knot {
            value: f(t),
            rate: df(t),
        };
        let (p, v, a) = scalar(k(t0), k(t1), h, x);
        assert!((p - f(t)).abs() < 1e-14);
        assert!((v - df(t)).abs() < 1e-13);
        assert!((a - ddf(t)).abs() < 1e-12);
        let one = |x: f64| DVector::from_element(1, x);
        let (q, qd) = vector(
            (&one(f(t0)), &one(df(t0))),
            (&one(f(t1)), &one(df(t1))),
            h,
            x,
        );
        assert!((q[0] - f(t)).abs() < 1e-14);
        assert!((qd[0] - df(t)).abs() < 1e-13);
    }
}
