//! The gait sensitivity norm of Hobbelen & Wisse (2007, IEEE T-RO 23(6)): how much a walker's
//! gait indicators respond to a disturbance, summed over every stride after it, from the
//! linearised stride map at the gait. Here the disturbance is a floor step `e` at the end of a
//! stride ([`crate::stride::StrideOptions::floor_step_m`]) and the indicators
//! `g = (step time, step length)`. With the stride map `x⁺ = S(x, e)` on the state just after
//! heel strike and `g(x, e)` the indicators of that stride,
//! `A = ∂S/∂x`, `B = ∂S/∂e`, `C = ∂g/∂x`, `D = ∂g/∂e` at the gait, and
//! `GSN = sqrt(‖D‖² + Σ_{k≥0} ‖C A^k B‖²)`: the response of the indicators, stride by
//! stride, to a unit step, in 2-norm. Every derivative by central differences of the stride
//! map (the floor step enters every state coordinate, so the full stride-map vector is used).

use crate::analysis::limit_cycle::Gait;
use crate::engine::walker::Walker;
use crate::stride::{StrideFailure, StrideRequest, StrideSettings, StrideWorkspace};
use nalgebra::{DMatrix, DVector};

/// The gait sensitivity norm for each indicator alone and for both.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct GaitSensitivity {
    /// With the step time alone \[s/m\].
    pub step_time: f64,
    /// With the step length alone \[m/m\].
    pub step_length: f64,
    /// With both (2-norm of the pair).
    pub both: f64,
    /// The disturbance: `floor_step`.
    pub disturbance: &'static str,
    /// Strides of the response summed (until a term is below 1e-16 of the sum).
    pub strides_summed: usize,
}

/// Most strides of the response summed (a gait with `max |λ|` near 1 decays slowly).
const MAX_TERMS: usize = 100_000;

/// The stride from `v` onto a floor `e` above: the next state and the indicators.
fn stride(
    walker: &Walker,
    settings: &StrideSettings,
    ws: &mut StrideWorkspace<'_>,
    v: &DVector<f64>,
    e: f64,
) -> Result<(DVector<f64>, [f64; 2]), StrideFailure> {
    let (q, qd) = walker.unpack(v);
    let r = ws.stride(&q, &qd, StrideRequest::new(settings).floor_step(e))?;
    Ok((
        walker.pack(&r.q_next, &r.qd_next),
        [r.duration_s, r.step_m.norm()],
    ))
}

/// The gait sensitivity norm of `gait` (of `walker`, strides with `settings`), derivatives by
/// central differences with step `perturbation` (of the state's entries and of the floor).
///
/// # Errors
/// A perturbed stride that fails.
pub fn gait_sensitivity_norm(
    walker: &Walker,
    settings: &StrideSettings,
    gait: &Gait,
    perturbation: f64,
) -> Result<GaitSensitivity, StrideFailure> {
    let v = &gait.fixed_point;
    let n = v.len();
    let d = perturbation;
    let mut ws = StrideWorkspace::new(walker);
    let mut a = DMatrix::zeros(n, n);
    let mut c = DMatrix::zeros(2, n);
    for k in 0..n {
        let (mut vp, mut vm) = (v.clone(), v.clone());
        vp[k] += d;
        vm[k] -= d;
        let (sp, gp) = stride(walker, settings, &mut ws, &vp, 0.0)?;
        let (sm, gm) = stride(walker, settings, &mut ws, &vm, 0.0)?;
        a.set_column(k, &((sp - sm) / (2.0 * d)));
        for i in 0..2 {
            c[(i, k)] = (gp[i] - gm[i]) / (2.0 * d);
        }
    }
    let (sp, gp) = stride(walker, settings, &mut ws, v, d)?;
    let (sm, gm) = stride(walker, settings, &mut ws, v, -d)?;
    let b = (sp - sm) / (2.0 * d);
    let dg = [(gp[0] - gm[0]) / (2.0 * d), (gp[1] - gm[1]) / (2.0 * d)];
    // Σ ‖C A^k B‖², each indicator's sum kept apart
    let mut sums = [dg[0] * dg[0], dg[1] * dg[1]];
    let mut x = b;
    let mut strides_summed = 0;
    for _ in 0..MAX_TERMS {
        let y = &c * &x;
        let term = [y[0] * y[0], y[1] * y[1]];
        sums[0] += term[0];
        sums[1] += term[1];
        strides_summed += 1;
        if term[0] + term[1] <= 1e-16 * (sums[0] + sums[1]) {
            break;
        }
        x = &a * x;
    }
    Ok(GaitSensitivity {
        step_time: sums[0].sqrt(),
        step_length: sums[1].sqrt(),
        both: (sums[0] + sums[1]).sqrt(),
        disturbance: "floor_step",
        strides_summed,
    })
}
