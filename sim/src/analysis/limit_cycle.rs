//! Periodic gaits: the Newton-Raphson fixed point of the stride function, eq. (24)-(26), and
//! the stride Jacobian by perturbation, whose eigenvalues decide stability, eq. (27).
//!
//! The search is its own type, [`GaitSearch`]: a walker, its stride settings and the Newton
//! settings, with the stride map, its Jacobian and the fixed-point iteration as methods. A
//! search usually starts from the scene's [`GaitGuess`] ([`GaitSearch::find_from_guess`]).

use crate::analysis::variational::VariationalError;
use crate::engine::model::CoordIndex;
use crate::engine::walker::Walker;
use crate::stride::{
    FailureCause, FailureKind, Schedule, StepSchedule, StrideFailure, StrideRequest, StrideResult,
    StrideSettings, StrideWorkspace,
};
use nalgebra::{Complex, DMatrix, DVector};
use rayon::prelude::*;
use serde::Serialize;

/// Settings of the fixed-point search.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct NewtonSettings {
    /// Converged when `|Δv| <` this (∞-norm).
    pub tolerance: f64,
    /// Iteration budget.
    pub max_iterations: usize,
    /// Perturbation step of the finite-difference Jacobian.
    pub perturbation: f64,
    /// Central (true) or forward (false) differences.
    pub central: bool,
    /// The Jacobian that only steps Newton (not the one at the converged point, whose
    /// eigenvalues are the gait's) by forward differences that reuse the nominal stride: `n`
    /// strides instead of `2n`. Its `O(perturbation)` error only slows the chord iteration's
    /// linear convergence by about that factor; the fixed point is where the residual
    /// vanishes, as with central differences. False: the stepping Jacobian as `central` says.
    pub forward_stepping: bool,
    /// Step halvings allowed when a full Newton step lands where the stride fails or the
    /// residual grows (0: the plain iteration of eq. 26).
    pub max_halvings: usize,
    /// Internal numerical differentiation: the perturbed strides of the Jacobian replay the
    /// step sizes of the nominal stride ([`StepSchedule`]) instead of choosing their own, so
    /// that the differences do not pick up the adaptive step selection's accept/reject flips.
    pub frozen_steps: bool,
    /// How the stride Jacobian is taken.
    pub jacobian: JacobianMethod,
    /// Consecutive stalled iterations before the search gives up: iterations whose step no
    /// halving made acceptable (the stride from every trial failed or its residual grew), or
    /// whose accepted step took less than a tenth off the residual ([`STALL_FRACTION`]). A
    /// search that has diverged from its start, or crawls on a plateau (at a fold, past the
    /// end of a branch), stops there instead of spending its whole iteration budget.
    pub max_stalled_iterations: usize,
    /// Broyden's rank-one update of the kept Newton matrix after every accepted step, from
    /// the step and the change of the stride map it produced (strides Newton integrates
    /// anyway): the chord iteration's linear convergence (a residual falling 10 to 15 fold an
    /// iteration on the compass's stride map) becomes superlinear at no stride's cost. Steps
    /// shorter than [`CRAWL_FLOOR`] tolerances do not update the matrix (the stride map's
    /// noise would then be a large part of the change). False: the matrix is kept as taken.
    pub broyden: bool,
}

/// How the stride Jacobian is taken.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum JacobianMethod {
    /// Central differences of the stride map (2n strides).
    #[default]
    CentralDifferences,
    /// The variational equations with saltation at every event (one stride with n
    /// sensitivities by forward-mode automatic differentiation; [`crate::analysis::variational`]).
    /// Strides it does not cover fall back to central differences, and the gait says so.
    Variational,
}

impl Default for NewtonSettings {
    fn default() -> Self {
        Self {
            tolerance: 1e-11,
            max_iterations: 30,
            perturbation: 1e-6,
            central: true,
            forward_stepping: true,
            max_halvings: 8,
            frozen_steps: false,
            jacobian: JacobianMethod::CentralDifferences,
            max_stalled_iterations: 3,
            broyden: true,
        }
    }
}

/// An accepted Newton step that leaves more than this fraction of the residual is a stalled
/// iteration ([`NewtonSettings::max_stalled_iterations`]): Newton near a regular fixed point
/// removes most of it, a chord iteration at least three quarters.
pub const STALL_FRACTION: f64 = 0.9;

/// A residual below this many Newton tolerances is never a plateau
/// ([`NewtonSettings::max_stalled_iterations`]): there the stride map's own noise can hold
/// it while the search still converges.
pub const CRAWL_FLOOR: f64 = 1e3;

/// Why no fixed point was found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NewtonError {
    /// A stride failed during the search.
    #[error("{}", stride_failed_words(*iteration, failure))]
    StrideFailed {
        /// Iteration.
        iteration: usize,
        /// The failure.
        failure: StrideFailure,
    },
    /// The budget ran out.
    #[error(
        "Newton did not converge in {iterations} iterations ({})",
        last_correction_words(*last_step)
    )]
    NotConverged {
        /// Iterations used.
        iterations: usize,
        /// Last correction size.
        last_step: f64,
    },
    /// `I − J` is singular.
    #[error("I − J is singular at iteration {iteration}")]
    Singular {
        /// Iteration.
        iteration: usize,
    },
}

impl NewtonError {
    /// The search stopped because its budget of strides was spent
    /// ([`crate::stride::SearchBudget`]), not because of the walker.
    pub fn budget_spent(&self) -> bool {
        matches!(self, Self::StrideFailed { failure, .. }
            if failure.kind == FailureKind::SearchBudgetExhausted)
    }
}

/// A stride that failed in a Newton search, in words; a spent search budget is no stride's
/// failure and is said as such.
fn stride_failed_words(iteration: usize, failure: &StrideFailure) -> String {
    match &*failure.cause {
        FailureCause::SearchBudget { limit_strides } => format!(
            "the search used its budget of {limit_strides} strides at Newton iteration \
             {iteration} (--max-strides allows more)"
        ),
        _ => format!("stride failed at Newton iteration {iteration}: {failure}"),
    }
}

/// The last Newton correction, in words: its size, or that it was not a number (a stride map
/// that diverged gives an infinite or NaN correction, once shown as `last |Δv| = inf`).
fn last_correction_words(last_step: f64) -> String {
    if last_step.is_finite() {
        format!("last |Δv| = {last_step:e}")
    } else {
        "the last correction was not finite: the stride map diverged from the start given".into()
    }
}

/// A periodic gait.
#[derive(Clone, Debug)]
pub struct Gait {
    /// How the Jacobian (and so the eigenvalues) was taken.
    pub jacobian_method: JacobianMethod,
    /// The fixed point (stride-map vector).
    pub fixed_point: DVector<f64>,
    /// The stride Jacobian at the fixed point.
    pub jacobian: DMatrix<f64>,
    /// Its eigenvalues.
    pub eigenvalues: Vec<Complex<f64>>,
    /// Newton iterations.
    pub iterations: usize,
    /// Strides the search integrated: one per iterate and trial step, and those of the
    /// Jacobians (a variational Jacobian counts one).
    pub strides: usize,
    /// `|S(v) − v|` at the fixed point (∞-norm).
    pub residual: f64,
    /// The stride from the fixed point.
    pub stride: StrideResult,
    /// The fixed-point search's settings that produced it.
    pub newton: NewtonSettings,
    /// The stride settings it was integrated with.
    pub stride_settings: StrideSettings,
    /// The coordinates whose values and rates make up the stride-map vectors (the fixed point,
    /// the Jacobian's rows and columns): [`Walker::map_coordinates`] of the walker it was found
    /// for. The same model has a longer map on a slope, where its heading is a state, than on
    /// level ground, where the heading is cyclic.
    pub map_coordinates: Vec<CoordIndex>,
}

impl Gait {
    /// Largest eigenvalue modulus.
    pub fn max_abs_eigenvalue(&self) -> f64 {
        self.eigenvalues
            .iter()
            .map(|z| z.norm())
            .fold(0.0, f64::max)
    }
    /// All eigenvalues strictly inside the unit circle.
    pub fn stable(&self) -> bool {
        self.max_abs_eigenvalue() < 1.0
    }
}

/// A starting guess for a gait: the state just after heel strike (stance labelling), as a
/// scene file's `guess` section gives it.
#[derive(Clone, Debug, PartialEq)]
pub struct GaitGuess {
    /// Coordinates [rad or m, by coordinate].
    pub q: DVector<f64>,
    /// Velocities [rad/s or m/s, by coordinate].
    pub qd: DVector<f64>,
}

/// A gait search: the stride map of `walker` with `settings`, and Newton's method with
/// `newton` on it.
#[derive(Clone, Copy, Debug)]
pub struct GaitSearch<'a> {
    /// The walker.
    pub walker: &'a Walker,
    /// How each stride is integrated.
    pub settings: &'a StrideSettings,
    /// The fixed-point search and the Jacobian.
    pub newton: &'a NewtonSettings,
}

impl<'a> GaitSearch<'a> {
    /// A search for `walker`'s gait with these settings.
    pub fn new(
        walker: &'a Walker,
        settings: &'a StrideSettings,
        newton: &'a NewtonSettings,
    ) -> Self {
        Self {
            walker,
            settings,
            newton,
        }
    }

    /// Finds the gait from `guess` (packed into a stride-map vector).
    ///
    /// # Errors
    /// As [`Self::find`].
    pub fn find_from_guess(&self, guess: &GaitGuess) -> Result<Gait, NewtonError> {
        self.find(&self.walker.pack(&guess.q, &guess.qd))
    }

    /// The stride function `S(v)` on packed stride-map vectors.
    pub fn stride_map(
        &self,
        v: &DVector<f64>,
    ) -> Result<(DVector<f64>, StrideResult), StrideFailure> {
        self.stride_map_in(&mut StrideWorkspace::new(self.walker), v)
    }

    /// [`Self::stride_map`] on `workspace` (of this search's walker).
    fn stride_map_in(
        &self,
        workspace: &mut StrideWorkspace<'_>,
        v: &DVector<f64>,
    ) -> Result<(DVector<f64>, StrideResult), StrideFailure> {
        let w = self.walker;
        let expected = 2 * w.map_coordinates().len();
        if v.len() != expected {
            return Err(StrideFailure::new(
                0.0,
                crate::stride::FailureCause::MapLength {
                    expected,
                    got: v.len(),
                },
            ));
        }
        let (q, qd) = w.unpack(v);
        let r = workspace.stride(&q, &qd, StrideRequest::new(self.settings))?;
        Ok((w.pack(&r.q_next, &r.qd_next), r))
    }

    /// The stride Jacobian at `v` by `newton.jacobian`, with the method actually used (the
    /// variational equations fall back to central differences where they do not apply).
    ///
    /// # Errors
    /// A stride that fails.
    pub fn stride_jacobian_by(
        &self,
        v: &DVector<f64>,
        s_v: &DVector<f64>,
    ) -> Result<(DMatrix<f64>, JacobianMethod), StrideFailure> {
        if self.newton.jacobian == JacobianMethod::Variational {
            match crate::analysis::variational::stride_jacobian(self.walker, v, self.settings) {
                Ok((j, _)) => return Ok((j, JacobianMethod::Variational)),
                Err(VariationalError::Stride(f)) => return Err(f),
                Err(_) => {}
            }
        }
        Ok((
            self.stride_jacobian(v, s_v)?,
            JacobianMethod::CentralDifferences,
        ))
    }

    /// The stride Jacobian at `v` by perturbation.
    ///
    /// # Errors
    /// A stride that fails.
    pub fn stride_jacobian(
        &self,
        v: &DVector<f64>,
        s_v: &DVector<f64>,
    ) -> Result<DMatrix<f64>, StrideFailure> {
        let (w, settings) = (self.walker, self.newton);
        let n = v.len();
        let d = settings.perturbation;
        let mut schedule = StepSchedule::default();
        let nominal = if settings.frozen_steps {
            let (q, qd) = w.unpack(v);
            let request =
                StrideRequest::new(self.settings).schedule(Schedule::Record(&mut schedule));
            let r = StrideWorkspace::new(w).stride(&q, &qd, request)?;
            Some(w.pack(&r.q_next, &r.qd_next))
        } else {
            None
        };
        let s_v = nominal.as_ref().unwrap_or(s_v);
        let map = |ws: &mut StrideWorkspace<'_>,
                   x: &DVector<f64>|
         -> Result<DVector<f64>, StrideFailure> {
            if settings.frozen_steps {
                let (q, qd) = w.unpack(x);
                let request =
                    StrideRequest::new(self.settings).schedule(Schedule::Replay(&schedule));
                let r = ws.stride(&q, &qd, request)?;
                Ok(w.pack(&r.q_next, &r.qd_next))
            } else {
                Ok(self.stride_map_in(ws, x)?.0)
            }
        };
        // The columns are independent strides: computed in parallel (rayon), each with the
        // same arithmetic as a sequential loop, so the Jacobian is bit-identical to it. The
        // first failure in column order is reported, as a sequential loop would.
        let column =
            |ws: &mut StrideWorkspace<'_>, k: usize| -> Result<DVector<f64>, StrideFailure> {
                let mut vp = v.clone();
                vp[k] += d;
                let sp = map(ws, &vp)?;
                Ok(if settings.central {
                    let mut vm = v.clone();
                    vm[k] -= d;
                    let sm = map(ws, &vm)?;
                    (sp - sm) / (2.0 * d)
                } else {
                    (sp - s_v) / d
                })
            };
        let columns: Vec<Result<DVector<f64>, StrideFailure>> = (0..n)
            .into_par_iter()
            .map_init(|| StrideWorkspace::new(w), column)
            .collect();
        let mut j = DMatrix::zeros(n, n);
        for (k, col) in columns.into_iter().enumerate() {
            j.set_column(k, &col?);
        }
        Ok(j)
    }

    /// The Jacobian that steps Newton at `v` (whose stride is `s_v`), as
    /// [`Self::stride_jacobian_by`] but by forward differences when `newton.forward_stepping`;
    /// with the method used and whether its differences were central.
    fn stepping_jacobian(
        &self,
        v: &DVector<f64>,
        s_v: &DVector<f64>,
    ) -> Result<(DMatrix<f64>, JacobianMethod, bool), StrideFailure> {
        let central = self.newton.central && !self.newton.forward_stepping;
        let newton = NewtonSettings {
            central,
            ..*self.newton
        };
        let (j, method) = GaitSearch {
            newton: &newton,
            ..*self
        }
        .stride_jacobian_by(v, s_v)?;
        Ok((j, method, central))
    }

    /// Strides one Jacobian of an `n`-vector took by `method` (`central` differences or not).
    fn jacobian_strides(&self, n: usize, method: JacobianMethod, central: bool) -> usize {
        match method {
            JacobianMethod::Variational => 1,
            JacobianMethod::CentralDifferences => {
                let nominal = usize::from(self.newton.frozen_steps);
                n * if central { 2 } else { 1 } + nominal
            }
        }
    }

    /// Finds the gait by Newton-Raphson from `v0`, eq. (26), and its eigenvalues:
    /// [`Self::converge`], then [`Self::gait_at`].
    ///
    /// # Errors
    /// [`NewtonError`]: a stride fails, the budget runs out, or `I − J` is singular.
    pub fn find(&self, v0: &DVector<f64>) -> Result<Gait, NewtonError> {
        let point = self.converge(v0, None)?;
        self.gait_at(point)
    }

    /// The gait at a converged `point` of this search: the stride Jacobian there (by
    /// `newton.jacobian`) and its eigenvalues. A study that converges several candidates and
    /// keeps one (the gait rule, a homotopy path) takes this Jacobian of the one it keeps only.
    ///
    /// # Errors
    /// A stride of the Jacobian fails ([`NewtonError::StrideFailed`] at the point's iteration).
    pub fn gait_at(&self, point: FixedPoint) -> Result<Gait, NewtonError> {
        let FixedPoint {
            fixed_point: v,
            image: s,
            iterations,
            mut strides,
            residual,
            stride,
            newton_matrix: _,
            map_coordinates: _,
        } = point;
        let fail = |failure| NewtonError::StrideFailed {
            iteration: iterations,
            failure,
        };
        let (j, jacobian_method) = self.stride_jacobian_by(&v, &s).map_err(fail)?;
        strides += self.jacobian_strides(v.len(), jacobian_method, self.newton.central);
        let eigenvalues = j.clone().complex_eigenvalues().iter().copied().collect();
        Ok(Gait {
            jacobian_method,
            fixed_point: v,
            jacobian: j,
            eigenvalues,
            iterations,
            strides,
            residual,
            stride,
            newton: *self.newton,
            stride_settings: self.settings.clone(),
            map_coordinates: self.walker.map_coordinates(),
        })
    }

    /// The fixed point by Newton-Raphson from `v0`, eq. (26), without the stride Jacobian at
    /// it ([`Self::gait_at`] takes that). `newton_matrix`: a stride Jacobian near `v0` (the
    /// last one of a nearby search, [`FixedPoint::newton_matrix`]) to step with first instead
    /// of taking one at `v0`; it is replaced as soon as the residual stops falling fourfold
    /// per iteration, as the search's own is.
    ///
    /// # Errors
    /// [`NewtonError`]: a stride fails, the budget runs out, or `I − J` is singular.
    pub fn converge(
        &self,
        v0: &DVector<f64>,
        newton_matrix: Option<DMatrix<f64>>,
    ) -> Result<FixedPoint, NewtonError> {
        self.converge_within(v0, newton_matrix, f64::INFINITY)
    }

    /// [`Self::converge`] that gives up ([`NewtonError::NotConverged`]) as soon as an iterate
    /// is farther than `max_move` (∞-norm) from `v0`: a corrector whose result would be
    /// refused as a jump to another branch when that far need not converge first.
    ///
    /// # Errors
    /// As [`Self::converge`].
    pub fn converge_within(
        &self,
        v0: &DVector<f64>,
        newton_matrix: Option<DMatrix<f64>>,
        max_move: f64,
    ) -> Result<FixedPoint, NewtonError> {
        let settings = self.newton;
        let mut v = v0.clone();
        let n = v.len();
        let mut last_step = f64::INFINITY;
        // The Newton matrix is kept while the residual falls at least fourfold per iteration
        // (a chord iteration); the eigenvalues always come from a Jacobian at the converged
        // point ([`Self::gait_at`]).
        let mut kept: Option<DMatrix<f64>> = newton_matrix.filter(|j| j.shape() == (n, n));
        let mut last_residual = f64::INFINITY;
        // The accepted trial's stride, reused as the next iteration's.
        let mut carried: Option<(DVector<f64>, StrideResult)> = None;
        let mut strides = 0;
        let mut stalled = 0;
        // One workspace for Newton's own strides (residuals and line-search trials).
        let mut workspace = StrideWorkspace::new(self.walker);
        for it in 0..=settings.max_iterations {
            let fail = |failure| NewtonError::StrideFailed {
                iteration: it,
                failure,
            };
            let (s, stride) = match carried.take() {
                Some(c) => c,
                None => {
                    strides += 1;
                    self.stride_map_in(&mut workspace, &v).map_err(fail)?
                }
            };
            let r = &s - &v;
            if last_step < settings.tolerance {
                return Ok(FixedPoint {
                    residual: r.amax(),
                    fixed_point: v,
                    image: s,
                    iterations: it,
                    strides,
                    stride,
                    // the matrix of the last step (a convergence is never at iteration 0)
                    newton_matrix: kept,
                    map_coordinates: self.walker.map_coordinates(),
                });
            }
            if it == settings.max_iterations {
                break;
            }
            let r_norm_now = r.amax();
            let j = match kept.take() {
                Some(j) if r_norm_now <= 0.25 * last_residual => j,
                _ => {
                    let (j, method, central) = self.stepping_jacobian(&v, &s).map_err(fail)?;
                    strides += self.jacobian_strides(n, method, central);
                    j
                }
            };
            last_residual = r_norm_now;
            let a = DMatrix::identity(n, n) - &j;
            let dv = a
                .lu()
                .solve(&r)
                .ok_or(NewtonError::Singular { iteration: it })?;
            // Damped step: halve while the stride from the new point fails or its residual
            // grows; keep the last trial if the budget runs out (the next iteration reports).
            let r_norm = r.amax();
            let mut lambda = 1.0;
            let mut accepted = settings.max_halvings == 0;
            let mut trial_residual = f64::INFINITY;
            for _ in 0..settings.max_halvings {
                let trial = &v + &dv * lambda;
                strides += 1;
                match self.stride_map_in(&mut workspace, &trial) {
                    Ok((st, sr)) if (&st - &trial).amax() < r_norm.max(settings.tolerance) => {
                        trial_residual = (&st - &trial).amax();
                        carried = Some((st, sr));
                        accepted = true;
                        break;
                    }
                    // the search's budget is spent: no halving can help
                    Err(f) if f.kind == FailureKind::SearchBudgetExhausted => {
                        return Err(fail(f));
                    }
                    _ => lambda *= 0.5,
                }
            }
            // A step that no halving made acceptable is not a sign of convergence, however
            // short it has become.
            last_step = if accepted {
                dv.amax() * lambda
            } else {
                f64::INFINITY
            };
            // stalled: no acceptable step, or one that took less than a tenth off the
            // residual while still longer than the tolerance (a search on a plateau, as at a
            // fold or past the branch's end, which the iteration budget only prolongs)
            // (a residual near the noise floor, where |Δv| can stay above the tolerance while
            // the residual cannot fall, is not a plateau; without halvings no trial is taken)
            let crawled = settings.max_halvings > 0
                && r_norm > CRAWL_FLOOR * settings.tolerance
                && trial_residual > STALL_FRACTION * r_norm;
            if !accepted || (crawled && last_step >= settings.tolerance) {
                stalled += 1;
            } else {
                stalled = 0;
            }
            let step = dv * lambda;
            v += &step;
            if stalled >= settings.max_stalled_iterations.max(1) || (&v - v0).amax() > max_move {
                return Err(NewtonError::NotConverged {
                    iterations: it + 1,
                    last_step,
                });
            }
            kept = Some(match &carried {
                Some((s_next, _)) if settings.broyden => {
                    broyden_update(j, &step, &(s_next - &s), CRAWL_FLOOR * settings.tolerance)
                }
                _ => j,
            });
        }
        Err(NewtonError::NotConverged {
            iterations: settings.max_iterations,
            last_step,
        })
    }
}

/// Broyden's rank-one update of the stride Jacobian `j` by a step `dv` of the stride map's
/// argument and the change `ds` of its value: `j + (ds − j dv) dvᵀ / (dvᵀ dv)`, the matrix
/// nearest `j` that maps `dv` to `ds` ([`NewtonSettings::broyden`]). `j` unchanged when the
/// step is shorter than `min_step` (∞-norm) or the update is not finite.
fn broyden_update(
    j: DMatrix<f64>,
    dv: &DVector<f64>,
    ds: &DVector<f64>,
    min_step: f64,
) -> DMatrix<f64> {
    let dv_dv = dv.dot(dv);
    if dv.amax() < min_step || dv_dv.is_nan() || dv_dv <= 0.0 {
        return j;
    }
    let miss = ds - &j * dv;
    let updated = &j + miss * (dv.transpose() / dv_dv);
    if updated.iter().all(|x| x.is_finite()) {
        updated
    } else {
        j
    }
}

/// A fixed point of the stride map found by [`GaitSearch::converge`], before its stride
/// Jacobian is taken ([`GaitSearch::gait_at`] makes it a [`Gait`]).
#[derive(Clone, Debug)]
pub struct FixedPoint {
    /// The fixed point (stride-map vector).
    pub fixed_point: DVector<f64>,
    /// `S(fixed_point)`, the stride map's image of it.
    pub image: DVector<f64>,
    /// Newton iterations.
    pub iterations: usize,
    /// Strides the search integrated (its Jacobians included).
    pub strides: usize,
    /// `|S(v) − v|` at the fixed point (∞-norm).
    pub residual: f64,
    /// The stride from the fixed point.
    pub stride: StrideResult,
    /// The last matrix Newton stepped with (a stride Jacobian near the fixed point: forward
    /// differences by default); `None` only for a search that took no step.
    pub newton_matrix: Option<DMatrix<f64>>,
    /// The stride-map coordinates of `fixed_point` ([`Gait::map_coordinates`]).
    pub map_coordinates: Vec<CoordIndex>,
}

#[cfg(test)]
mod message_tests {
    use super::*;

    /// `last |Δv| = inf` said nothing a user could act on.
    #[test]
    fn a_correction_that_is_not_finite_is_named_as_such() {
        for bad in [f64::INFINITY, f64::NAN] {
            let e = NewtonError::NotConverged {
                iterations: 3,
                last_step: bad,
            }
            .to_string();
            assert!(!e.contains("inf") && !e.contains("NaN"), "{e}");
            assert!(e.contains("not finite"), "{e}");
        }
        let e = NewtonError::NotConverged {
            iterations: 3,
            last_step: 2.5e-3,
        }
        .to_string();
        assert!(e.ends_with("(last |Δv| = 2.5e-3)"), "{e}");
    }
}

#[cfg(test)]
mod broyden_tests {
    use super::*;

    #[test]
    fn the_update_maps_the_step_onto_the_change_and_skips_noise_and_non_finite_steps() {
        let j = DMatrix::from_row_slice(2, 2, &[0.5, 0.1, -0.2, 0.3]);
        let dv = DVector::from_column_slice(&[1e-3, -2e-3]);
        let ds = DVector::from_column_slice(&[4e-4, 1e-4]);
        let updated = broyden_update(j.clone(), &dv, &ds, 1e-8);
        // the secant condition, and no change across directions orthogonal to the step
        assert!((&updated * &dv - &ds).amax() < 1e-18);
        let orthogonal = DVector::from_column_slice(&[2.0, 1.0]);
        assert!((&updated * &orthogonal - &j * &orthogonal).amax() < 1e-15);
        // a step below the noise floor, or a change that is not finite, leaves it alone
        assert_eq!(broyden_update(j.clone(), &(&dv * 1e-6), &ds, 1e-8), j);
        let nan = DVector::from_column_slice(&[f64::NAN, 0.0]);
        assert_eq!(broyden_update(j.clone(), &dv, &nan, 1e-8), j);
        assert_eq!(broyden_update(j.clone(), &nan, &ds, 1e-8), j);
    }
}
