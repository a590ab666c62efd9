//! Pseudo-arclength continuation of the fixed points of `Sᵏ(·; p)`.
//!
//! A point is `x = (v, p)` with `F(x) = Sᵏ(v; p) − v = 0`. The tangent is the null vector of
//! `[S_v − I, S_p]` (`S_v` the monodromy matrix, `S_p` by central differences in `p`), of
//! unit length and oriented along the previous one. The predictor steps `h` along it; the
//! corrector is Newton's method on the augmented system `F(x) = 0, c·x = b`: with
//! `c = t, b = t·x_pred` the arclength constraint (the hyperplane through the prediction,
//! normal to the tangent), with `c = e_p, b = g` a point at the parameter value `g`. A fold is
//! regular for the augmented system, so the branch passes it.
//!
//! Step control: the step grows by 1.5 after a corrector that took at most 5 iterations (most
//! of them chord iterations, which cost one orbit each), halves after one that took more
//! than 8, and halves on a failed corrector, between
//! [`StepControl::min`] and [`StepControl::max`]; it moves the parameter by at most
//! [`StepControl::max_dp`] (the grid spacing).

use super::family::{EvalError, EventSignature, Family};
use super::settings::Detection;
use crate::analysis::limit_cycle::JacobianMethod;
use crate::scene::Setup;
use crate::stride::StrideResult;
use nalgebra::{Complex, DMatrix, DVector};

/// A converged point of a branch of period-`k` fixed points.
#[derive(Clone, Debug)]
pub struct BranchPoint {
    /// The parameter value `p`.
    pub value: f64,
    /// The cycle's states `v₀ … v_{k−1}` (stride-map vectors); `v₀` is the fixed point of `Sᵏ`.
    pub orbit: Vec<DVector<f64>>,
    /// The strides from each state.
    pub strides: Vec<StrideResult>,
    /// `∂Sᵏ/∂v` at the point.
    pub monodromy: DMatrix<f64>,
    /// Its eigenvalues: the Floquet multipliers of the cycle.
    pub multipliers: Vec<Complex<f64>>,
    /// How the stride Jacobians were taken.
    pub jacobian_method: JacobianMethod,
    /// `∂Sᵏ/∂p`.
    pub dfdp: DVector<f64>,
    /// The unit tangent `(dv/ds, dp/ds)` of the branch.
    pub tangent: DVector<f64>,
    /// `|Sᵏ(v) − v|` (∞-norm) at the last corrector iterate.
    pub residual: f64,
    /// Corrector iterations.
    pub iterations: usize,
    /// The strides' event sequence.
    pub signature: EventSignature,
}

impl BranchPoint {
    /// `x = (v₀, p)`.
    pub fn x(&self) -> DVector<f64> {
        let n = self.orbit[0].len();
        DVector::from_fn(
            n + 1,
            |i, _| if i < n { self.orbit[0][i] } else { self.value },
        )
    }

    /// Largest multiplier modulus.
    pub fn max_abs_multiplier(&self) -> f64 {
        self.multipliers
            .iter()
            .map(|z| z.norm())
            .fold(0.0, f64::max)
    }

    /// All multipliers strictly inside the unit circle.
    pub fn stable(&self) -> bool {
        self.max_abs_multiplier() < 1.0
    }

    /// Strides per cycle.
    pub fn period_strides(&self) -> usize {
        self.orbit.len()
    }
}

/// Why the corrector found no point.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CorrectorError {
    /// A scene or stride failure at an iterate.
    #[error(transparent)]
    Eval(#[from] EvalError),
    /// The iteration budget ran out.
    #[error(
        "the corrector did not converge in {iterations} iterations (last |Δx| = {last_step:e})"
    )]
    NotConverged {
        /// Iterations used.
        iterations: usize,
        /// Last correction (∞-norm).
        last_step: f64,
    },
    /// The augmented Jacobian is singular.
    #[error("the augmented Jacobian is singular")]
    Singular,
    /// A bifurcation's test function has the same sign at both ends of the step, so there is
    /// no single crossing to locate between them (two crossings, or a crossing pair that could
    /// not be followed).
    #[error("the test function has the same sign at both ends of the step: no single crossing to locate")]
    NoSignChange,
}

/// Step sizes of the continuation (arclength in `(v, p)`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepControl {
    /// First step.
    pub initial: f64,
    /// Largest step (arclength).
    pub max: f64,
    /// Largest change of the parameter in one step (the grid spacing): the step is at most
    /// `max_dp / |dp/ds|`.
    pub max_dp: f64,
    /// Smallest step: a corrector failing at this step ends the branch.
    pub min: f64,
    /// Corrector iteration budget.
    pub max_iterations: usize,
    /// Largest turn of the tangent in one accepted step \[degrees\] (60 by default); more says
    /// the step skipped over structure or jumped to another branch.
    pub max_turn_deg: f64,
}

impl StepControl {
    /// `h` capped so that the parameter moves at most `max_dp` along `tangent`.
    pub fn capped(&self, h: f64, tangent: &DVector<f64>) -> f64 {
        let tp = tangent[tangent.len() - 1].abs();
        if tp > 0.0 {
            h.min(self.max_dp / tp)
        } else {
            h
        }
    }

    /// The step after a corrector that converged in `iterations`.
    pub fn adapt(&self, h: f64, iterations: usize) -> f64 {
        if iterations <= 5 {
            (h * 1.5).min(self.max)
        } else if iterations > 8 {
            (h * 0.5).max(self.min)
        } else {
            h
        }
    }
}

/// The top rows `[S_v − I, S_p]` of the augmented Jacobian, with what was evaluated on the way.
#[derive(Clone, Debug)]
pub struct Linearisation {
    /// `[S_v − I, S_p]`.
    pub top: DMatrix<f64>,
    /// `S_v`.
    pub monodromy: DMatrix<f64>,
    /// `S_p`.
    pub dfdp: DVector<f64>,
    /// How `S_v` was taken.
    pub method: JacobianMethod,
}

/// The corrector's constraint `c·x = b`.
#[derive(Clone, Debug)]
pub struct Constraint {
    /// Its row.
    pub c: DVector<f64>,
    /// Its value.
    pub b: f64,
}

/// Period-`k` continuation on a family.
#[derive(Clone, Copy)]
pub struct Continuer<'a> {
    /// The family.
    pub family: &'a Family,
    /// Strides per cycle.
    pub period: usize,
    /// Step control.
    pub steps: StepControl,
    /// Which bifurcations are located.
    pub detect: Detection,
}

impl<'a> Continuer<'a> {
    fn linearise(
        &self,
        setup: &Setup,
        x: &DVector<f64>,
        orbit: &super::family::Orbit,
    ) -> Result<Linearisation, EvalError> {
        let n = x.len() - 1;
        let v = x.rows(0, n).into_owned();
        let (monodromy, method) = self.family.monodromy(setup, orbit)?;
        let dfdp = self.family.parameter_derivative(&v, x[n], self.period)?;
        let mut top = DMatrix::zeros(n, n + 1);
        top.view_mut((0, 0), (n, n))
            .copy_from(&(&monodromy - DMatrix::identity(n, n)));
        top.set_column(n, &dfdp);
        Ok(Linearisation {
            top,
            monodromy,
            dfdp,
            method,
        })
    }

    /// The unit tangent: the null vector of `top`, oriented along `along` (`t·along > 0`).
    pub fn tangent(top: &DMatrix<f64>, along: &DVector<f64>) -> Option<DVector<f64>> {
        let n = top.nrows();
        let mut a = DMatrix::zeros(n + 1, n + 1);
        a.view_mut((0, 0), (n, n + 1)).copy_from(top);
        a.set_row(n, &along.transpose());
        let mut rhs = DVector::zeros(n + 1);
        rhs[n] = 1.0;
        let t = a.lu().solve(&rhs)?;
        let norm = t.norm();
        (norm.is_finite() && norm > 0.0).then(|| t / norm)
    }

    /// Newton's method on `F(x) = 0, c·x = b` from `x0`; the first iterations reuse `kept`
    /// (a chord iteration) while the residual falls fourfold per iteration. With `full`, the
    /// converged point gets its monodromy matrix, multipliers and tangent (oriented along
    /// `along`); without, only its orbit and signature (the rest left empty), and the
    /// iteration stays a chord iteration on `kept` (no perturbed strides).
    ///
    /// # Errors
    /// [`CorrectorError`].
    pub fn correct(
        &self,
        x0: &DVector<f64>,
        constraint: &Constraint,
        kept: Option<&Linearisation>,
        along: &DVector<f64>,
        full: bool,
    ) -> Result<(BranchPoint, Linearisation), CorrectorError> {
        let n = x0.len() - 1;
        // Rounding in `Sᵏ` grows with `k` and with the size of its Jacobian: so does the
        // tolerance on the correction.
        let base_tol = self.family.newton.tolerance * self.period as f64;
        let mut tol = base_tol;
        let mut x = x0.clone();
        let mut lin: Option<Linearisation> = kept.cloned();
        let mut lin_at_x = false;
        let mut last_residual = f64::INFINITY;
        let mut last_step = f64::INFINITY;
        let mut setup_p = f64::NAN;
        let mut setup: Option<Setup> = None;
        // Chord iterations only (without `full`) converge linearly: a larger budget.
        let budget = if full {
            self.steps.max_iterations
        } else {
            3 * self.steps.max_iterations
        };
        for it in 0..=budget {
            if setup.is_none() || setup_p != x[n] {
                setup = Some(self.family.setup_at(x[n]).map_err(EvalError::from)?);
                setup_p = x[n];
            }
            let Some(su) = setup.as_ref() else {
                return Err(CorrectorError::Singular);
            };
            let v = x.rows(0, n).into_owned();
            let orbit = self.family.orbit(su, &v, self.period)?;
            let f = &orbit.end - &v;
            if last_step < tol {
                let residual = f.amax();
                let signature = EventSignature::of(&orbit.strides);
                let lin = match lin {
                    Some(l) if lin_at_x || !full => l,
                    _ => self.linearise(su, &x, &orbit)?,
                };
                let (multipliers, tangent) = if full {
                    let t = Self::tangent(&lin.top, along).ok_or(CorrectorError::Singular)?;
                    let m: Vec<Complex<f64>> = lin
                        .monodromy
                        .complex_eigenvalues()
                        .iter()
                        .copied()
                        .collect();
                    (m, t)
                } else {
                    (Vec::new(), DVector::zeros(0))
                };
                let point = BranchPoint {
                    value: x[n],
                    orbit: orbit.states,
                    strides: orbit.strides,
                    monodromy: lin.monodromy.clone(),
                    multipliers,
                    jacobian_method: lin.method,
                    dfdp: lin.dfdp.clone(),
                    tangent,
                    residual,
                    iterations: it,
                    signature,
                };
                return Ok((point, lin));
            }
            if it == budget {
                break;
            }
            let mut r = DVector::zeros(n + 1);
            r.rows_mut(0, n).copy_from(&f);
            r[n] = constraint.c.dot(&x) - constraint.b;
            let r_norm = r.amax();
            // Without `full` (locating a branch end) the kept matrix is never replaced: a
            // fresh one perturbs the state and the parameter, and a perturbed stride failing
            // near the end would count as the point failing.
            let l = match lin.take() {
                Some(l)
                    if !full || r_norm <= 0.25 * last_residual || (it == 0 && kept.is_some()) =>
                {
                    lin_at_x = false;
                    l
                }
                _ => {
                    lin_at_x = true;
                    self.linearise(su, &x, &orbit)?
                }
            };
            last_residual = r_norm;
            let mut a = DMatrix::zeros(n + 1, n + 1);
            a.view_mut((0, 0), (n, n + 1)).copy_from(&l.top);
            a.set_row(n, &constraint.c.transpose());
            let dx = a.lu().solve(&(-r)).ok_or(CorrectorError::Singular)?;
            if !dx.iter().all(|d| d.is_finite()) {
                return Err(CorrectorError::Singular);
            }
            last_step = dx.amax();
            x += dx;
            tol = base_tol * l.monodromy.amax().max(1.0);
            lin_at_x = lin_at_x && last_step < tol;
            lin = Some(l);
        }
        Err(CorrectorError::NotConverged {
            iterations: budget,
            last_step,
        })
    }

    /// The point at arclength `s` from `from` along its tangent (the corrector on the
    /// hyperplane `t·(x − x_from) = s`), starting from the prediction `x_from + s t`.
    ///
    /// # Errors
    /// As [`Self::correct`].
    pub fn at_arclength(
        &self,
        from: &BranchPoint,
        from_lin: &Linearisation,
        s: f64,
        full: bool,
    ) -> Result<(BranchPoint, Linearisation), CorrectorError> {
        let pred = from.x() + &from.tangent * s;
        self.at_arclength_from(from, from_lin, s, &pred, full)
    }

    /// As [`Self::at_arclength`], the corrector starting from `x0` instead of the prediction
    /// (a point found nearer, e.g. the last good point of a bisection moved onto the
    /// hyperplane).
    ///
    /// # Errors
    /// As [`Self::correct`].
    pub fn at_arclength_from(
        &self,
        from: &BranchPoint,
        from_lin: &Linearisation,
        s: f64,
        x0: &DVector<f64>,
        full: bool,
    ) -> Result<(BranchPoint, Linearisation), CorrectorError> {
        let t = &from.tangent;
        let constraint = Constraint {
            c: t.clone(),
            b: t.dot(&from.x()) + s,
        };
        self.correct(x0, &constraint, Some(from_lin), t, full)
    }

    /// The point at the parameter value `g` between `a` and `b` (linear interpolation as the
    /// first guess; the corrector with the constraint `p = g`).
    ///
    /// # Errors
    /// As [`Self::correct`].
    pub fn at_value(
        &self,
        a: &BranchPoint,
        b: &BranchPoint,
        b_lin: &Linearisation,
        g: f64,
    ) -> Result<(BranchPoint, Linearisation), CorrectorError> {
        let (xa, xb) = (a.x(), b.x());
        let n = xa.len() - 1;
        let w = if xb[n] != xa[n] {
            (g - xa[n]) / (xb[n] - xa[n])
        } else {
            0.5
        };
        let mut x0 = &xa + (&xb - &xa) * w;
        x0[n] = g;
        let mut c = DVector::zeros(n + 1);
        c[n] = 1.0;
        let along = &a.tangent * (1.0 - w) + &b.tangent * w;
        self.correct(&x0, &Constraint { c, b: g }, Some(b_lin), &along, true)
    }
}
