//! The fixed-size engine of the stride loop: states `SVector<f64, N>` (positions,
//! velocities), DOP853 and its dense output on them (`dop853`), the witnesses on the planar
//! kinematics (`planar_witnesses`), the planar evaluation (closed forms or link pass) called
//! directly, and the heel-strike impact and relabelling on the planar frames (`heel_strike`,
//! `impact`; the general ones where those do not cover the walker). The loop is the one of
//! `stride::run`; the reference engine stays the reference (`sim/tests/fast_path.rs`
//! compares both).
//!
//! Selected automatically ([`covers`]): a walker on the planar fast path
//! ([`PlanarTree::of`]) without an ankle string, DOP853 with its dense output for events, no
//! controller, no contact figures, and [`EvaluationPath::Auto`] (or `LinkPass`). Whatever it
//! meets on the way that it does not cover — a step that triggers two events, a failure of any
//! kind — hands the stride back to the reference engine, which runs it again from its start.

mod dop853;
mod heel_strike;
mod impact;
mod planar_witnesses;

use super::contact_figures::ContactSummary;
use super::engine::{Engine, NoInterpolant};
use super::failure::StrideFailure;
use super::phase::Drive;
use super::request::StrideOptions;
use super::result::{StrideEvent, StrideResult};
use super::run::{Run, Start};
use super::settings::StrideSettings;
use super::state::StrideState;
use super::EvaluationPath;
use crate::engine::dynamics::{Dynamics, DynamicsError};
use crate::engine::events::{refine, root_on_dense, EventError, EventTolerance};
use crate::engine::integrators::{IntegrationError, IntegratorChoice, Sample, SystemChange};
use crate::engine::model::{CoordIndex, Model};
use crate::engine::planar::{PlanarPoints, PlanarTree};
use crate::engine::walker::Walker;
use dop853::{FixedDop853, FixedSystem, State};
use heel_strike::heel_strike;
use nalgebra::{DVector, SVector};
use planar_witnesses::PlanarWitnesses;

/// Whether the fixed-size engine covers a stride of `walker` with these settings and options
/// (and no controller), as far as they go: the walker's model must also qualify
/// (its planar points on a tree of 1 to `MAX_PLANAR_COORDINATES` coordinates, compiled
/// once per walker).
pub(super) fn covers(
    walker: &Walker,
    settings: &StrideSettings,
    options: StrideOptions,
    controlled: bool,
) -> bool {
    matches!(
        settings.evaluation,
        EvaluationPath::Auto | EvaluationPath::LinkPass
    ) && matches!(settings.integrator, IntegratorChoice::Dop853 { .. })
        && settings.event_tolerance.dense_output
        && !controlled
        && walker.ankle().is_none()
        && !options.contact
}

impl Walker {
    /// Whether a stride of this walker with `settings` and `options` (and no controller) runs
    /// on the fixed-size engine (`stride::fast`) from its start, rather than the reference
    /// engine. It may still hand the stride back to the reference on the way (two events in
    /// one step, a fall, a budget used up).
    pub fn takes_fixed_size_stride(
        &self,
        settings: &StrideSettings,
        options: StrideOptions,
    ) -> bool {
        covers(self, settings, options, false)
            && self.compiled(settings.evaluation).planar_points.is_some()
    }
}

/// Runs the stride from `q0`, `qd0` on fixed-size states, on the walker's planar `tree` and
/// `points` (compiled once per walker): the stride's result, or `None` when the stride is handed back to the reference
/// engine (samples it recorded are then dropped by the caller).
pub(super) fn stride(
    start: Start<'_, '_, '_>,
    tree: &PlanarTree,
    points: &PlanarPoints,
    q0: &DVector<f64>,
    qd0: &DVector<f64>,
) -> Option<StrideResult> {
    let wit = PlanarWitnesses {
        points,
        min_hip_height_m: start.walker.fall().min_hip_height_m,
        floor_step_m: start.options.floor_step_m,
    };
    match tree.dof() {
        1 => stride_n::<1>(start, tree, wit, q0, qd0),
        2 => stride_n::<2>(start, tree, wit, q0, qd0),
        3 => stride_n::<3>(start, tree, wit, q0, qd0),
        4 => stride_n::<4>(start, tree, wit, q0, qd0),
        5 => stride_n::<5>(start, tree, wit, q0, qd0),
        6 => stride_n::<6>(start, tree, wit, q0, qd0),
        _ => None,
    }
}

/// [`stride`] on `N`-sized states.
fn stride_n<const N: usize>(
    start: Start<'_, '_, '_>,
    tree: &PlanarTree,
    wit: PlanarWitnesses<'_>,
    q0: &DVector<f64>,
    qd0: &DVector<f64>,
) -> Option<StrideResult> {
    let walker = start.walker;
    let IntegratorChoice::Dop853 {
        rtol,
        atol,
        h_max_s,
    } = start.settings.integrator
    else {
        return None;
    };
    let cur = state::<N>(0.0, q0, qd0)?;
    let mut active = [true; N];
    for c in walker.initially_locked() {
        *active.get_mut(c.0)? = false;
    }
    let engine = FixedEngine {
        walker,
        tree,
        integrator: FixedDop853::new(rtol, atol, h_max_s),
        sys: FastPhase {
            tree,
            model: walker.model(),
            active,
            limit: None,
        },
    };
    Run::new(start, engine, wit, None, cur).ok()?.run().0.ok()
}

impl<const N: usize> StrideState for State<N> {
    #[inline]
    fn t_s(&self) -> f64 {
        self.t_s
    }
    #[inline]
    fn q(&self, c: usize) -> f64 {
        self.q[c]
    }
    #[inline]
    fn qd(&self, c: usize) -> f64 {
        self.qd[c]
    }
    #[inline]
    fn is_finite(&self) -> bool {
        self.q.iter().chain(self.qd.iter()).all(|v| v.is_finite())
    }
    fn to_sample(&self) -> Sample {
        Sample {
            t_s: self.t_s,
            q: DVector::from_column_slice(self.q.as_slice()),
            qd: DVector::from_column_slice(self.qd.as_slice()),
        }
    }
    /// `None`: another length, or not finite.
    fn from_sample(s: Sample) -> Option<Self> {
        state(s.t_s, &s.q, &s.qd)
    }
}

/// `q`, `q̇` at `t_s` as a fixed-size state (`None`: another length, or not finite).
fn state<const N: usize>(t_s: f64, q: &DVector<f64>, qd: &DVector<f64>) -> Option<State<N>> {
    let finite = q.iter().chain(qd.iter()).all(|v| v.is_finite());
    (q.len() == N && qd.len() == N && finite).then(|| State {
        t_s,
        q: SVector::from_iterator(q.iter().copied()),
        qd: SVector::from_iterator(qd.iter().copied()),
    })
}

/// The smooth dynamics of a phase on the planar fast path: free coordinates, no drive.
struct FastPhase<'a, const N: usize> {
    tree: &'a PlanarTree,
    model: &'a Model,
    active: [bool; N],
    /// The general workspace, made when a model with infinitesimal bodies has a coordinate
    /// locked (its limit solve is the general one).
    limit: Option<Dynamics>,
}

impl<const N: usize> FixedSystem<N> for FastPhase<'_, N> {
    #[inline]
    fn accelerations(
        &mut self,
        _t_s: f64,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
    ) -> Result<SVector<f64, N>, DynamicsError> {
        if self.active.iter().all(|&a| a) {
            if let Some(qdd) = self.tree.free_closed_form(q, qd) {
                return Ok(qdd);
            }
        }
        let (limit, model) = (&mut self.limit, self.model);
        self.tree.accelerations_fixed(
            || limit.get_or_insert_with(|| Dynamics::new(model)),
            &self.active,
            None,
            q,
            qd,
        )
    }
}

/// The fixed-size engine: DOP853 on `N`-sized states over the planar evaluation.
struct FixedEngine<'w, const N: usize> {
    walker: &'w Walker,
    tree: &'w PlanarTree,
    integrator: FixedDop853<N>,
    sys: FastPhase<'w, N>,
}

impl<'w, const N: usize> Engine for FixedEngine<'w, N> {
    type State = State<N>;
    type Interpolant = NoInterpolant;
    type Witness = PlanarWitnesses<'w>;
    const HANDS_BACK: bool = true;

    #[inline]
    fn advance(&mut self, cur: &State<N>, h_limit_s: f64) -> Result<State<N>, IntegrationError> {
        self.integrator.advance(&mut self.sys, cur, h_limit_s)
    }

    #[inline]
    fn step_exact(&mut self, cur: &State<N>, h_s: f64) -> Result<State<N>, IntegrationError> {
        self.integrator.step_exact(&mut self.sys, cur, h_s)
    }

    /// [`crate::engine::events::locate`] on the dense output (which this engine always has after a
    /// step).
    #[inline]
    fn locate<G: FnMut(&State<N>) -> f64>(
        &mut self,
        cur: &State<N>,
        next: &State<N>,
        mut g: G,
        tol: &EventTolerance,
    ) -> Result<State<N>, EventError> {
        let (ga, gb) = (g(cur), g(next));
        let dense = self
            .integrator
            .dense_output(&mut self.sys, cur, next)
            .ok_or(EventError::NoDenseOutput {
                from_s: cur.t_s,
                to_s: next.t_s,
            })??;
        let (guess, slope) = root_on_dense(
            |t| g(&dense.eval(t)),
            (cur.t_s, ga),
            (next.t_s, gb),
            dense.h_s,
            tol,
        );
        let (integrator, sys) = (&mut self.integrator, &mut self.sys);
        refine(
            (cur.t_s, ga),
            (next, next.t_s, gb),
            (guess, Some(slope)),
            tol,
            |t| {
                let s = integrator.step_exact(sys, cur, t - cur.t_s)?;
                Ok((s, g(&s)))
            },
        )
    }

    fn interpolates(&self) -> bool {
        false
    }

    fn interpolant(
        &mut self,
        _cur: &State<N>,
        _next: &State<N>,
    ) -> Option<Result<NoInterpolant, IntegrationError>> {
        None
    }

    #[inline]
    fn evaluations(&self) -> usize {
        self.integrator.evaluations()
    }

    fn reset(&mut self) {
        self.integrator.reset();
    }

    /// Nothing to forget: without a drive the equations change only at impacts.
    fn system_changed(&mut self, _change: SystemChange) {}

    #[inline]
    fn active(&self) -> &[bool] {
        &self.sys.active
    }

    fn set_active(&mut self, c: usize, free: bool) {
        if let Some(a) = self.sys.active.get_mut(c) {
            *a = free;
        }
    }

    /// No drive: the engine is not chosen for a walker with an ankle string.
    #[inline]
    fn prescribed(&self) -> Option<(CoordIndex, Drive)> {
        None
    }

    fn set_prescribed(&mut self, _p: Option<(CoordIndex, Drive)>) {}

    #[inline]
    fn snap(&self, _s: &mut State<N>) {}

    fn actuator_torque(
        &mut self,
        _s: &State<N>,
        _at_step_end: bool,
    ) -> Result<(f64, f64), DynamicsError> {
        Ok((0.0, 0.0))
    }

    /// Nothing: the engine is not chosen when contact figures are asked for.
    fn add_contact(
        &mut self,
        _summary: &mut ContactSummary,
        _walker: &Walker,
        _wit: &mut PlanarWitnesses<'w>,
        _s: &State<N>,
    ) -> Result<(), DynamicsError> {
        Ok(())
    }

    /// The impact and relabelling on the planar frames, or the general ones where those do
    /// not cover the walker.
    fn finish(
        &mut self,
        walker: &Walker,
        (at, at_sample): (&State<N>, Sample),
        events: Vec<StrideEvent>,
        energy_loss_j: f64,
    ) -> Result<StrideResult, StrideFailure> {
        let active = self.sys.active;
        match heel_strike::<N>(walker, self.tree, at, &active) {
            Some(h) => Ok(StrideResult {
                q_next: h.q_next,
                qd_next: h.qd_next,
                duration_s: at.t_s,
                step_m: h.step_m,
                heading_change_rad: 0.0,
                events,
                pre_impact: at_sample,
                lift_velocity_m_s: h.lift_velocity_m_s,
                impact_energy_loss_j: energy_loss_j + h.energy_loss_j,
                evaluations: 0,
                trajectory: Vec::new(),
                event_states: Vec::new(),
                actuator_work_j: 0.0,
                damping_dissipation_j: 0.0,
                contact: ContactSummary::default(),
            }),
            None => self
                .walker
                .finish_stride(at_sample, &active, events, energy_loss_j),
        }
    }
}
