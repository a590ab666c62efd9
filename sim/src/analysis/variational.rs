//! The stride Jacobian without finite differences: the variational (sensitivity) equations
//! integrated along the stride, with a saltation correction at every event.
//!
//! The sensitivity `Φ = ∂x(t)/∂v` of the state `x = (q, q̇)` to the stride-map start `v`
//! obeys `Φ̈_q = ∂q̈/∂q Φ_q + ∂q̈/∂q̇ Φ_q̇` (with the ideal drive's start time as one more
//! parameter once the string is taut). The right-hand side is the directional derivative of
//! the equations of motion along the columns of `Φ`, computed exactly by forward-mode
//! automatic differentiation: the same generic engine ([`crate::engine::dynamics::DynamicsOf`]) runs
//! on dual numbers (`num_dual::DualSVec64`, [`LANES`] directions at a time). The augmented
//! system `(x, Φ)` is integrated by DOP853 between the events of the nominal stride.
//!
//! At an event `g(x) = 0` with jump `x⁺ = Δ(x⁻)` and vector fields `f⁻`, `f⁺`:
//! `τ = ∂t*/∂v = −(∇g Φ⁻)/(∇g f⁻)` and `Φ⁺ = DΔ (Φ⁻ + f⁻ τ) − f⁺ τ` (the saltation matrix
//! applied to `Φ⁻`). `DΔ` — the knee's and the string's impact equations, and at the heel
//! strike the impact on the released model followed by the geometric relabelling — is again
//! a directional derivative by dual numbers; the relabelling's Gauss-Newton solution is
//! differentiated by the implicit function theorem (one dual step from the converged `f64`
//! solution). The stride-map Jacobian is `D(pack ∘ relabel ∘ Δ_heel) (Φ⁻ + f⁻ τ)`.
//!
//! Supported: models without infinitesimal bodies; knee locks, the ideal string's
//! engagement and its drive, heel strike with mirroring and cyclic coordinates. Not
//! supported (a typed error; the perturbation Jacobian is then the fallback): infinitesimal
//! bodies (the simplest walker), controller-driven strides, the heel coming back down.

use nalgebra::{Const, DMatrix, DVector, SVector, U1};
use num_dual::{Derivative, DualSVec64};

use crate::engine::actuator::AnkleProfile;
use crate::engine::dynamics::{DynamicsError, DynamicsOf};
use crate::engine::hybrid::contact_rows::heel_strike_rows;
use crate::engine::hybrid::impact::{locked_state, solve_finite, unit_row};
use crate::engine::hybrid::phase::DriveValues;
use crate::engine::hybrid::profile::extension;
use crate::engine::hybrid::relabel::{pose_jacobian, pose_residual, row_count, RelabelTargets};
use crate::engine::hybrid::{konst, EngineScalar};
use crate::engine::integrators::{
    Dop853, Integrator, IntegratorChoice, Sample, SecondOrderSystem, SystemChange,
};
use crate::engine::kinematics::KinematicsOf;
use crate::engine::model::Model;
use crate::engine::relabel::{LinkStates, LinkStatesOf};
use crate::engine::walker::Walker;
use crate::stride::{StrideFailure, StrideRequest, StrideResult, StrideSettings};

/// Directions carried by one dual number (more are done in chunks).
pub const LANES: usize = 6;

/// Why the variational Jacobian could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum VariationalError {
    /// The nominal stride failed.
    #[error("stride: {0}")]
    Stride(#[from] StrideFailure),
    /// The stride has a feature the variational equations do not cover.
    #[error("not covered by the variational Jacobian: {0}")]
    Unsupported(String),
    /// A dynamics, impact or integration failure while propagating the sensitivities.
    #[error("variational equations: {0}")]
    Numerical(String),
}

fn num(e: impl std::fmt::Display) -> VariationalError {
    VariationalError::Numerical(e.to_string())
}

fn dual<const N: usize>(re: f64, eps: SVector<f64, N>) -> DualSVec64<N> {
    DualSVec64::new(re, Derivative::some(eps))
}

fn eps<const N: usize>(d: &DualSVec64<N>) -> SVector<f64, N> {
    d.eps.unwrap_generic(Const::<N>, U1)
}

/// `x` with derivative directions: columns `c0 .. c0 + LANES` of `s` (rows as `x`).
fn seed<const N: usize>(x: &DVector<f64>, s: &DMatrix<f64>, c0: usize) -> DVector<DualSVec64<N>> {
    let m = s.ncols();
    DVector::from_fn(x.len(), |i, _| {
        dual(
            x[i],
            SVector::from_fn(|k, _| if c0 + k < m { s[(i, c0 + k)] } else { 0.0 }),
        )
    })
}

fn seed_scalar<const N: usize>(x: f64, row: &[f64], c0: usize) -> DualSVec64<N> {
    dual(
        x,
        SVector::from_fn(|k, _| row.get(c0 + k).copied().unwrap_or(0.0)),
    )
}

/// Writes the derivative parts of `y` into columns `c0 ..` of `out`.
fn harvest<const N: usize>(y: &DVector<DualSVec64<N>>, out: &mut DMatrix<f64>, c0: usize) {
    let m = out.ncols();
    for (i, yi) in y.iter().enumerate() {
        let e = eps(yi);
        for k in 0..N.min(m.saturating_sub(c0)) {
            out[(i, c0 + k)] = e[k];
        }
    }
}

/// Which coordinates are free and which one the ideal drive moves.
#[derive(Clone, Debug)]
struct PhaseSpec {
    active: Vec<bool>,
    drive: Option<(usize, AnkleProfile)>,
}

/// `q̈` of a phase in any scalar, the drive started at `start` [s] (the shared phase
/// accelerations with the drive's values from the shared profile).
fn accelerations<T: EngineScalar>(
    model: &Model,
    dy: &mut DynamicsOf<T>,
    spec: &PhaseSpec,
    t: T,
    start: T,
    q: &DVector<T>,
    qd: &DVector<T>,
) -> Result<DVector<T>, DynamicsError> {
    let drive = spec.drive.as_ref().map(|(a, p)| {
        let (angle_rad, rate_rad_s, acceleration_rad_s2) = extension(p, t, start);
        DriveValues {
            coordinate: *a,
            angle_rad,
            rate_rad_s,
            acceleration_rad_s2,
        }
    });
    crate::engine::hybrid::phase::accelerations(model, dy, &spec.active, drive.as_ref(), q, qd)
}

/// `(q, q̇)` stacked with the sensitivities: `q` part `[q; vec Φ_q]`, `q̇` part
/// `[q̇; vec Φ_q̇]` (column-major), a second-order system for the integrators.
struct Augmented<'a, const N: usize> {
    model: &'a Model,
    spec: PhaseSpec,
    /// Drive start and its sensitivity (one entry per column of `Φ`).
    start: f64,
    start_sens: Vec<f64>,
    n: usize,
    m: usize,
    dy: DynamicsOf<DualSVec64<N>>,
}

impl<const N: usize> SecondOrderSystem for Augmented<'_, N> {
    fn accelerations(
        &mut self,
        t_s: f64,
        qa: &DVector<f64>,
        qda: &DVector<f64>,
    ) -> Result<DVector<f64>, DynamicsError> {
        let (n, m) = (self.n, self.m);
        let q = qa.rows(0, n).into_owned();
        let qd = qda.rows(0, n).into_owned();
        let sq = DMatrix::from_column_slice(n, m, &qa.as_slice()[n..]);
        let sqd = DMatrix::from_column_slice(n, m, &qda.as_slice()[n..]);
        let mut out = DVector::zeros(n + n * m);
        let mut sdd = DMatrix::zeros(n, m);
        for c0 in (0..m.max(1)).step_by(N) {
            let acc = accelerations(
                self.model,
                &mut self.dy,
                &self.spec,
                DualSVec64::<N>::from_re(t_s),
                seed_scalar(self.start, &self.start_sens, c0),
                &seed(&q, &sq, c0),
                &seed(&qd, &sqd, c0),
            )?;
            if c0 == 0 {
                for i in 0..n {
                    out[i] = acc[i].re;
                }
            }
            harvest(&acc, &mut sdd, c0);
        }
        out.rows_mut(n, n * m).copy_from_slice(sdd.as_slice());
        if out.iter().any(|v| !v.is_finite()) {
            return Err(DynamicsError::NonFinite);
        }
        Ok(out)
    }
}

/// The stacked state `[q; q̇]` of a sample.
fn stacked(s: &Sample) -> DVector<f64> {
    let n = s.q.len();
    DVector::from_fn(2 * n, |i, _| if i < n { s.q[i] } else { s.qd[i - n] })
}

/// The stride-map Jacobian at `v` from the variational equations (see the module
/// documentation), with the nominal stride.
///
/// # Errors
/// [`VariationalError`]: the stride fails, a feature outside the method, or a numerical
/// failure of the sensitivity propagation.
pub fn stride_jacobian(
    walker: &Walker,
    v: &DVector<f64>,
    settings: &StrideSettings,
) -> Result<(DMatrix<f64>, StrideResult), VariationalError> {
    // As many directions per dual number as the map has entries (fewer chunks, no
    // wasted lanes), up to LANES.
    // Six directions per dual number measured fastest on wisse3d (12 entries: 84 ms,
    // against 110 ms with 4, 155 ms with 8 and 165 ms with 12).
    if v.len() <= 4 {
        variational::<4>(walker, v, settings)
    } else {
        variational::<LANES>(walker, v, settings)
    }
}

fn variational<const N: usize>(
    walker: &Walker,
    v: &DVector<f64>,
    settings: &StrideSettings,
) -> Result<(DMatrix<f64>, StrideResult), VariationalError> {
    if walker.model().has_infinitesimal_bodies() || walker.impact_model().has_infinitesimal_bodies()
    {
        return Err(VariationalError::Unsupported(
            "infinitesimal bodies (their vanishing-mass limit is solved in f64 only)".into(),
        ));
    }
    let (q0, qd0) = walker.unpack(v);
    let nominal = walker.stride(&q0, &qd0, StrideRequest::new(settings))?;
    let n = walker.model().dof();
    let m = v.len();
    let coords = walker.map_coordinates();
    let half = coords.len();
    // Φ at the start: ∂(q, q̇)/∂v, the unpacking.
    let mut phi = DMatrix::zeros(2 * n, m);
    for (i, c) in coords.iter().enumerate() {
        phi[(c.0, i)] = 1.0;
        phi[(n + c.0, half + i)] = 1.0;
    }
    let mut spec = PhaseSpec {
        active: vec![true; n],
        drive: None,
    };
    for c in walker.initially_locked() {
        spec.active[c.0] = false;
    }
    let (mut start, mut start_sens) = (0.0, vec![0.0; m]);
    let mut from = Sample {
        t_s: 0.0,
        q: q0.clone(),
        qd: qd0.clone(),
    };
    let (rtol, h_max) = match settings.integrator {
        IntegratorChoice::Dop853 { rtol, h_max_s, .. }
        | IntegratorChoice::Dopri5 { rtol, h_max_s, .. } => (rtol, h_max_s),
        _ => (1e-12, 0.05),
    };
    let mut dy_f: DynamicsOf<f64> = DynamicsOf::new(walker.model());
    let mut dy_d: DynamicsOf<DualSVec64<N>> = DynamicsOf::new(walker.model());
    for (event, (before, after)) in nominal.events.iter().zip(&nominal.event_states) {
        // The flow up to the event.
        phi = propagate::<N>(
            walker,
            &spec,
            start,
            &start_sens,
            &from,
            &phi,
            before.t_s,
            rtol,
            h_max,
        )?;
        let t = before.t_s;
        let field = |spec: &PhaseSpec, start: f64, s: &Sample, dy: &mut DynamicsOf<f64>| {
            accelerations(walker.model(), dy, spec, t, start, &s.q, &s.qd)
                .map(|a| DVector::from_fn(2 * n, |i, _| if i < n { s.qd[i] } else { a[i - n] }))
                .map_err(num)
        };
        let f_minus = field(&spec, start, before, &mut dy_f)?;
        let x_minus = stacked(before);
        // τ = −(∇g Φ⁻)/(∇g f⁻), with ∇g by dual numbers.
        let dg = |g: &dyn Fn(&DVector<DualSVec64<N>>) -> DualSVec64<N>,
                  dirs: &DMatrix<f64>|
         -> Vec<f64> {
            let mut out = vec![0.0; dirs.ncols()];
            for c0 in (0..dirs.ncols()).step_by(N) {
                let e = eps(&g(&seed(&x_minus, dirs, c0)));
                for k in 0..N.min(dirs.ncols() - c0) {
                    out[c0 + k] = e[k];
                }
            }
            out
        };
        let tau_of = |g: &dyn Fn(&DVector<DualSVec64<N>>) -> DualSVec64<N>| -> Result<Vec<f64>, VariationalError> {
                let rate = dg(g, &DMatrix::from_column_slice(2 * n, 1, f_minus.as_slice()))[0];
                if rate.abs() < 1e-12 {
                    return Err(num("the event is tangent to the flow"));
                }
                Ok(dg(g, &phi).iter().map(|d| -d / rate).collect())
            };
        let name = event.name.as_str();
        if name == "heel_strike" {
            let foot = walker.model().points[walker.heel_strike().swing_foot.0].clone();
            let model = walker.model();
            let height = move |x: &DVector<DualSVec64<N>>| -> DualSVec64<N> {
                let mut kin: KinematicsOf<DualSVec64<N>> = KinematicsOf::new(model);
                let q = x.rows(0, n).into_owned();
                let qd = x.rows(n, n).into_owned();
                kin.update(model, &q, &qd);
                kin.position_of(foot.link, &foot.p_link_m).y
            };
            let tau = tau_of(&height)?;
            let y = &phi + &f_minus * DMatrix::from_row_slice(1, m, &tau);
            let j = terminal_jacobian::<N>(walker, &spec.active, before, &y)?;
            return Ok((j, nominal));
        }
        let StoppingEvent {
            coordinate: c,
            value,
            impact_active,
            after: new_spec,
        } = stopping_event(walker, &spec, name, t)?;
        let tau = tau_of(&|x: &DVector<DualSVec64<N>>| x[c] - konst::<DualSVec64<N>>(value))?;
        let y = &phi + &f_minus * DMatrix::from_row_slice(1, m, &tau);
        let jump = jump_derivative(
            &x_minus,
            &y,
            |q, qd, dy| {
                let target = DVector::zeros(1);
                let qd_plus = solve_finite(
                    dy,
                    walker.model(),
                    q,
                    qd,
                    &impact_active,
                    &unit_row(n, c),
                    &target,
                )
                .map_err(num)?
                .qd_plus;
                Ok(locked_state(
                    q,
                    qd_plus,
                    c,
                    konst(value),
                    DualSVec64::<N>::from_re(0.0),
                ))
            },
            &mut dy_d,
        )?;
        if new_spec.drive.is_some() && spec.drive.is_none() {
            // The drive started at this event: its start time is a parameter from now on.
            start = t;
            start_sens = tau.clone();
        }
        let f_plus = field(&new_spec, start, after, &mut dy_f)?;
        phi = jump - &f_plus * DMatrix::from_row_slice(1, m, &tau);
        spec = new_spec;
        from = after.clone();
    }
    Err(num("the stride ended without a heel strike"))
}

/// An event other than heel strike: a coordinate reaching a value and an inelastic impact that
/// stops it there.
struct StoppingEvent {
    /// The coordinate.
    coordinate: usize,
    /// The value it reaches [rad].
    value: f64,
    /// The free coordinates of the impact.
    impact_active: Vec<bool>,
    /// The phase after it.
    after: PhaseSpec,
}

/// The stopping event `name` of `walker` at stride time `t` [s] in phase `spec`: the knee at
/// its stop; the ankle at the taut angle (the ideal drive starts at rest there, its far end
/// not moving), the toe set free.
fn stopping_event(
    walker: &Walker,
    spec: &PhaseSpec,
    name: &str,
    t: f64,
) -> Result<StoppingEvent, VariationalError> {
    if let Some(knee) = name.strip_prefix("knee_lock:") {
        let k = walker
            .knees()
            .iter()
            .find(|k| walker.model().coordinates[k.coordinate.0].name == knee)
            .ok_or_else(|| num(format!("unknown knee {knee}")))?;
        let c = k.coordinate.0;
        let mut after = spec.clone();
        after.active[c] = false;
        Ok(StoppingEvent {
            coordinate: c,
            value: k.stop_rad,
            impact_active: spec.active.clone(),
            after,
        })
    } else if name == "string_engaged" {
        let r = walker
            .ankle()
            .ok_or_else(|| num("engagement without an ankle reflex"))?;
        let (a, toe) = (r.ankle.0, r.toe_pitch.0);
        let mut impact_active = spec.active.clone();
        impact_active[toe] = true;
        let mut after_active = impact_active.clone();
        after_active[a] = false;
        Ok(StoppingEvent {
            coordinate: a,
            value: r.engage_rad,
            impact_active,
            after: PhaseSpec {
                active: after_active,
                drive: Some((a, r.extension_from(t))),
            },
        })
    } else {
        Err(VariationalError::Unsupported(format!("event `{name}`")))
    }
}

/// `DΔ · Y` for a jump `Δ(q, q̇)` evaluated in dual numbers at `x⁻` along the columns of
/// `y` (2n × m).
#[allow(clippy::type_complexity)]
fn jump_derivative<const N: usize>(
    x_minus: &DVector<f64>,
    y: &DMatrix<f64>,
    jump: impl Fn(
        &DVector<DualSVec64<N>>,
        &DVector<DualSVec64<N>>,
        &mut DynamicsOf<DualSVec64<N>>,
    ) -> Result<(DVector<DualSVec64<N>>, DVector<DualSVec64<N>>), VariationalError>,
    dy: &mut DynamicsOf<DualSVec64<N>>,
) -> Result<DMatrix<f64>, VariationalError> {
    let n = x_minus.len() / 2;
    let mut out = DMatrix::zeros(2 * n, y.ncols());
    for c0 in (0..y.ncols()).step_by(N) {
        let x = seed(x_minus, y, c0);
        let (q, qd) = jump(&x.rows(0, n).into_owned(), &x.rows(n, n).into_owned(), dy)?;
        let stacked = DVector::from_fn(2 * n, |i, _| if i < n { q[i] } else { qd[i - n] });
        harvest(&stacked, &mut out, c0);
    }
    Ok(out)
}

/// Integrates the state and its sensitivities from `from` to `t_end` in one smooth phase.
#[allow(clippy::too_many_arguments)]
fn propagate<const N: usize>(
    walker: &Walker,
    spec: &PhaseSpec,
    start: f64,
    start_sens: &[f64],
    from: &Sample,
    phi: &DMatrix<f64>,
    t_end: f64,
    rtol: f64,
    h_max: f64,
) -> Result<DMatrix<f64>, VariationalError> {
    let n = walker.model().dof();
    let m = phi.ncols();
    let mut sys = Augmented::<N> {
        model: walker.model(),
        spec: spec.clone(),
        start,
        start_sens: start_sens.to_vec(),
        n,
        m,
        dy: DynamicsOf::new(walker.model()),
    };
    let mut q = DVector::zeros(n + n * m);
    let mut qd = DVector::zeros(n + n * m);
    q.rows_mut(0, n).copy_from(&from.q);
    qd.rows_mut(0, n).copy_from(&from.qd);
    let phi_q = phi.rows(0, n).into_owned();
    let phi_qd = phi.rows(n, n).into_owned();
    q.rows_mut(n, n * m).copy_from_slice(phi_q.as_slice());
    qd.rows_mut(n, n * m).copy_from_slice(phi_qd.as_slice());
    let mut cur = Sample {
        t_s: from.t_s,
        q,
        qd,
    };
    // The sensitivities are under the same error control as the state: controlling the
    // state's error alone lets them drift by 0.1 on the 3D walker (measured).
    let mut integrator = Dop853::new(rtol, rtol, h_max);
    integrator.reset();
    let drive_end = spec
        .drive
        .as_ref()
        .map_or(f64::INFINITY, |(_, p)| start + p.duration_s);
    while cur.t_s < t_end {
        let stop = if cur.t_s < drive_end - 1e-12 {
            t_end.min(drive_end)
        } else {
            t_end
        };
        let next = integrator
            .advance(&mut sys, &cur, stop - cur.t_s)
            .map_err(num)?;
        if next.t_s >= drive_end - 1e-12 && cur.t_s < drive_end - 1e-12 {
            integrator.system_changed(SystemChange::Equations);
        }
        cur = next;
        if (t_end - cur.t_s).abs() < 1e-13 {
            break;
        }
    }
    let mut out = DMatrix::zeros(2 * n, m);
    out.rows_mut(0, n).copy_from_slice(&cur.q.as_slice()[n..]);
    out.rows_mut(n, n).copy_from_slice(&cur.qd.as_slice()[n..]);
    Ok(out)
}

/// `D(pack ∘ relabel ∘ Δ_heel) · Y` at the pre-impact state.
fn terminal_jacobian<const N: usize>(
    walker: &Walker,
    active: &[bool],
    before: &Sample,
    y: &DMatrix<f64>,
) -> Result<DMatrix<f64>, VariationalError> {
    let n = walker.model().dof();
    // The f64 relabelling, for the converged new pose.
    let hs = walker.heel_strike_impact(before, active).map_err(num)?;
    let nr = walker.heel_strike().release.len();
    let mi = walker.impact_model();
    let mut kin: KinematicsOf<f64> = KinematicsOf::new(mi);
    kin.update(mi, &hs.q, &hs.qd_plus);
    let states = LinkStates::from_kinematics(&kin, nr, &hs.p_contact_m);
    let solved = walker
        .relabel()
        .solve(walker.model(), &states, walker.relabel_reference_q())
        .or_else(|_| walker.relabel().solve(walker.model(), &states, &before.q))
        .map_err(num)?;
    let mut q_new = solved.q.clone();
    for (c, x) in walker.relabel().cyclic.iter().zip(&solved.cyclic_values) {
        q_new[c.0] = *x;
    }
    let x_minus = stacked(before);
    let coords = walker.map_coordinates();
    let mut out = DMatrix::zeros(2 * coords.len(), y.ncols());
    for c0 in (0..y.ncols()).step_by(N) {
        let x = seed::<N>(&x_minus, y, c0);
        let packed = terminal_map::<N>(
            walker,
            active,
            &x.rows(0, n).into_owned(),
            &x.rows(n, n).into_owned(),
            &q_new,
        )?;
        harvest(&packed, &mut out, c0);
    }
    Ok(out)
}

/// Heel-strike impact, relabelling and packing in dual numbers, linearised about the
/// converged `f64` new pose `q_new` (cyclic coordinates included).
fn terminal_map<const N: usize>(
    walker: &Walker,
    active: &[bool],
    q: &DVector<DualSVec64<N>>,
    qd: &DVector<DualSVec64<N>>,
    q_new: &DVector<f64>,
) -> Result<DVector<DualSVec64<N>>, VariationalError> {
    let hs = walker.heel_strike();
    let nr = hs.release.len();
    let mi = walker.impact_model();
    let rows = heel_strike_rows(mi, hs, q, qd, active);
    let target = &rows.g * &rows.qd * konst::<DualSVec64<N>>(-hs.restitution);
    let mut dy: DynamicsOf<DualSVec64<N>> = DynamicsOf::new(mi);
    let qd_plus = solve_finite(
        &mut dy,
        mi,
        &rows.q,
        &rows.qd,
        &rows.active,
        &rows.g,
        &target,
    )
    .map_err(num)?
    .qd_plus;
    let mut kin: KinematicsOf<DualSVec64<N>> = KinematicsOf::new(mi);
    kin.update(mi, &rows.q, &qd_plus);
    // The old links' states relative to the new contact, mirrored if the scene mirrors.
    let rel = walker.relabel();
    let model = walker.model();
    let old = LinkStatesOf::from_kinematics(&kin, nr, &rows.p_contact_m);
    let targets = RelabelTargets::new(rel, model, &old);
    // Positions: one Gauss-Newton step from the converged pose (implicit function
    // theorem): Δq = J⁺ r(old), with J the pose Jacobian in f64.
    let nd = model.dof();
    let nrows = row_count(rel);
    let mut kf: KinematicsOf<f64> = KinematicsOf::new(model);
    kf.update(model, q_new, &DVector::zeros(nd));
    let mut jac = DMatrix::zeros(nrows, nd);
    let mut res = DVector::<DualSVec64<N>>::zeros(nrows);
    pose_residual(rel, model, &kf, &targets, &mut res);
    pose_jacobian(rel, model, &kf, &mut jac);
    let svd = jac.clone().svd(true, true);
    let tol = 1e-12 * svd.singular_values.max().max(1e-300);
    let pinv = svd.pseudo_inverse(tol).map_err(num)?;
    let pinv_d: DMatrix<DualSVec64<N>> = pinv.map(konst);
    let q_new_d: DVector<DualSVec64<N>> = q_new.map(konst::<DualSVec64<N>>) + pinv_d * res;
    // Velocities: J(q_new) q̇ = [ω of old twins; v of old points], J now in dual numbers.
    let mut kd: KinematicsOf<DualSVec64<N>> = KinematicsOf::new(model);
    kd.update(model, &q_new_d, &DVector::zeros(nd));
    let mut jd = DMatrix::<DualSVec64<N>>::zeros(nrows, nd);
    pose_jacobian(rel, model, &kd, &mut jd);
    let target = targets.velocity_target();
    // Least squares over the free columns (normal equations; the system is consistent).
    let free: Vec<usize> = (0..nd)
        .filter(|c| !rel.fixed.iter().any(|f| f.0 == *c))
        .filter(|&c| jac.column(c).amax() > 1e-12)
        .collect();
    let jf = jd.select_columns(&free);
    let normal = jf.transpose() * &jf;
    let rhs = jf.transpose() * target;
    let x = normal
        .lu()
        .solve(&rhs)
        .ok_or_else(|| num("singular relabelling velocities"))?;
    let mut qd_new = DVector::<DualSVec64<N>>::zeros(nd);
    for (k, &c) in free.iter().enumerate() {
        qd_new[c] = x[k];
    }
    let coords = walker.map_coordinates();
    let h = coords.len();
    Ok(DVector::from_fn(2 * h, |i, _| {
        if i < h {
            q_new_d[coords[i].0]
        } else {
            qd_new[coords[i - h].0]
        }
    }))
}
