//! Speed against error: for each integrator over a range of steps or tolerances, the error of
//! the fixed point, of the eigenvalues and of the heel-strike time against a tight reference,
//! beside the CPU time of one stride.

use crate::analysis::limit_cycle::{Gait, GaitSearch, NewtonError, NewtonSettings};
use crate::engine::integrators::IntegratorChoice;
use crate::scene::Setup;
use crate::stride::StrideRequest;
use nalgebra::Complex;
use serde::Serialize;
use std::time::Instant;

/// Perturbation step of the stride Jacobian, for the reference and every studied setting
/// alike: the central difference's own truncation error (order 1e-8) is then common to all and
/// cancels in the comparison, while a larger step keeps loose settings' integration error from
/// being divided into eigenvalue noise.
pub const STUDY_PERTURBATION: f64 = 1e-4;

/// One integrator setting and its errors.
#[derive(Clone, Debug, Serialize)]
pub struct AccuracyPoint {
    /// Integrator family: `meijaard`, `rk4`, `dopri5`.
    pub integrator: String,
    /// The setting.
    pub setting: IntegratorChoice,
    /// Step \[s\] (fixed-step integrators) or relative tolerance (dopri5).
    pub step_or_tolerance: f64,
    /// CPU time of one stride from the reference fixed point \[µs\]: the minimum of
    /// [`TIMING_REPEATS`] repeats, so that other work on a loaded machine inflates it less.
    pub cpu_us_per_stride: f64,
    /// Right-hand-side evaluations per stride.
    pub evaluations_per_stride: usize,
    /// ∞-norm error of the fixed point, or `None` when no gait was found.
    pub fixed_point_error: Option<f64>,
    /// Largest error of an eigenvalue of modulus at least [`EIGENVALUE_FLOOR`] (each reference
    /// eigenvalue matched to the nearest computed one).
    pub eigenvalue_error: Option<f64>,
    /// Error of the heel-strike time of the stride from the reference fixed point \[s\].
    pub heel_strike_time_error_s: Option<f64>,
    /// Why no gait was found, if none was.
    pub failure: Option<String>,
}

/// The whole study for one scene.
#[derive(Clone, Debug, Serialize)]
pub struct AccuracyStudy {
    /// Scene.
    pub scene: String,
    /// The reference integrator.
    pub reference: IntegratorChoice,
    /// Reference stride duration \[s\].
    pub reference_step_period_s: f64,
    /// Points.
    pub points: Vec<AccuracyPoint>,
}

/// The settings studied: fixed steps for Meijaard and RK4 (halving), tolerances for DOPRI5
/// and DOP853.
pub fn default_settings(period_s: f64) -> Vec<(String, f64, IntegratorChoice)> {
    let mut out = Vec::new();
    for k in 0..6 {
        let h = period_s / (100.0 * 2f64.powi(k));
        out.push((
            "meijaard".into(),
            h,
            IntegratorChoice::Meijaard {
                h_s: h,
                check_every: 0,
            },
        ));
    }
    for k in 0..5 {
        let h = period_s / (25.0 * 2f64.powi(k));
        out.push(("rk4".into(), h, IntegratorChoice::Rk4 { h_s: h }));
    }
    for k in [4, 6, 8, 10, 12] {
        let tol = 10f64.powi(-k);
        out.push((
            "dopri5".into(),
            tol,
            IntegratorChoice::Dopri5 {
                rtol: tol,
                atol: tol,
                h_max_s: period_s / 10.0,
            },
        ));
    }
    for k in [4, 6, 8, 10, 12] {
        let tol = 10f64.powi(-k);
        out.push((
            "dop853".into(),
            tol,
            IntegratorChoice::Dop853 {
                rtol: tol,
                atol: tol,
                h_max_s: period_s / 10.0,
            },
        ));
    }
    out
}

/// Eigenvalues smaller than this are left out of the eigenvalue error: zero eigenvalues of
/// coordinates reset at every stride (a locked knee) form Jordan blocks whose computed values
/// scatter like a root of the Jacobian's error, and they do not decide stability.
pub const EIGENVALUE_FLOOR: f64 = 0.05;

fn max_eigen_error(reference: &[Complex<f64>], other: &[Complex<f64>]) -> f64 {
    reference
        .iter()
        .filter(|r| r.norm() >= EIGENVALUE_FLOOR)
        .map(|r| {
            other
                .iter()
                .map(|o| (o - r).norm())
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

/// Repeats of the timed stride of each setting, in rounds over all settings; the study keeps
/// the fastest (other processes only ever add time).
pub const TIMING_REPEATS: usize = 9;

/// Runs the study: the reference gait with `reference`, then every setting, each gait search
/// starting from the reference fixed point. The other stride settings (event tolerances, time
/// budget) are the setup's.
pub fn study(
    setup: &Setup,
    reference: IntegratorChoice,
    settings: &[(String, f64, IntegratorChoice)],
    newton: &NewtonSettings,
) -> Result<AccuracyStudy, NewtonError> {
    study_with_progress(setup, reference, settings, newton, &|| {})
}

/// As [`study`], calling `on_setting` after each setting of `settings` is done (for a
/// progress bar).
pub fn study_with_progress(
    setup: &Setup,
    reference: IntegratorChoice,
    settings: &[(String, f64, IntegratorChoice)],
    newton: &NewtonSettings,
    on_setting: &dyn Fn(),
) -> Result<AccuracyStudy, NewtonError> {
    let w = &setup.walker;
    let mut stride_settings = setup.settings.with_integrator(reference.clone());
    let study_newton = NewtonSettings {
        perturbation: STUDY_PERTURBATION,
        ..*newton
    };
    let reference_gait: Gait =
        GaitSearch::new(w, &stride_settings, &study_newton).find_from_guess(&setup.guess)?;
    let x_ref = reference_gait.fixed_point.clone();
    let t_ref = reference_gait.stride.duration_s;
    let (q_ref, qd_ref) = w.unpack(&x_ref);
    // CPU time per stride: the fastest of TIMING_REPEATS strides from the reference point,
    // taken in rounds over all settings, so that a burst of other work on the machine slows
    // one repeat of a setting rather than all of them.
    let all: Vec<_> = settings
        .iter()
        .map(|(_, _, setting)| setup.settings.with_integrator(setting.clone()))
        .collect();
    let mut fastest_us = vec![f64::INFINITY; all.len()];
    let mut evaluations = vec![0; all.len()];
    let mut t_hs = vec![None; all.len()];
    for _ in 0..TIMING_REPEATS {
        for (i, s) in all.iter().enumerate() {
            let start = Instant::now();
            let r = w.stride(&q_ref, &qd_ref, StrideRequest::new(s));
            fastest_us[i] = fastest_us[i].min(start.elapsed().as_secs_f64() * 1e6);
            if let Ok(r) = r {
                evaluations[i] = r.evaluations;
                t_hs[i] = Some(r.duration_s);
            }
        }
    }
    let mut points = Vec::new();
    for (i, (family, value, setting)) in settings.iter().enumerate() {
        stride_settings = all[i].clone();
        let gait = GaitSearch::new(w, &stride_settings, &study_newton).find(&x_ref);
        let (fp, ev, failure) = match &gait {
            Ok(g) => (
                Some((&g.fixed_point - &x_ref).amax()),
                Some(max_eigen_error(&reference_gait.eigenvalues, &g.eigenvalues)),
                None,
            ),
            Err(e) => (None, None, Some(e.to_string())),
        };
        points.push(AccuracyPoint {
            integrator: family.clone(),
            setting: setting.clone(),
            step_or_tolerance: *value,
            cpu_us_per_stride: fastest_us[i],
            evaluations_per_stride: evaluations[i],
            fixed_point_error: fp,
            eigenvalue_error: ev,
            heel_strike_time_error_s: t_hs[i].map(|t| (t - t_ref).abs()),
            failure,
        });
        on_setting();
    }
    Ok(AccuracyStudy {
        scene: w.name().to_string(),
        reference,
        reference_step_period_s: t_ref,
        points,
    })
}
