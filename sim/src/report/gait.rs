//! The `walker gait` report: the gait found (or why none was), its stability and figures.

use super::{eigenvalue_pairs, gait_numbers, FixedPoint};
use super::{eigenvectors, ComplexVector, StrideJacobian};
use super::{AnkleExtension, CostOfTransport};
use crate::analysis::limit_cycle::{Gait, JacobianMethod, NewtonError};
use crate::analysis::stability::{modes, EigenMode};
use crate::engine::integrators::IntegratorChoice;
use crate::engine::walker::Walker;
use crate::scene::{Scene, Setup};
use crate::stride::{ContactSummary, StrideEvent, StrideFailure, StrideResult};
use serde::Serialize;
use std::collections::BTreeMap;

/// The `walker gait --json` object: the scene, its parameter values and the integrator, with
/// the outcome of the gait search flattened beside them.
#[derive(Clone, Debug, Serialize)]
pub struct GaitReport {
    /// Scene name.
    pub scene: String,
    /// Parameter values the walker was built with.
    pub parameters: BTreeMap<String, f64>,
    /// The integrator the search ran with.
    pub integrator: IntegratorChoice,
    /// Where `walker gait`'s gait comes from: `defaults` (Newton from the scene's guess at its
    /// defaults), `guess` (Newton from the guess off the defaults) or
    /// `continued_from_defaults` (the scene's gait continued from its defaults); absent in
    /// `walker gaits`, which lists every gait found.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gait_source: Option<crate::analysis::homotopy::GaitSource>,
    /// The gait, or why none was found.
    #[serde(flatten)]
    pub outcome: GaitOutcome,
}

/// The outcome of a gait search.
#[derive(Clone, Debug, Serialize)]
#[serde(untagged)]
pub enum GaitOutcome {
    /// A fixed point was found (`converged: true`).
    Found(Box<FoundGait>),
    /// None was (`converged: false`).
    NotFound(Box<GaitNotFound>),
}

/// A gait that was found.
#[derive(Clone, Debug, Serialize)]
pub struct FoundGait {
    /// Always `true`.
    pub converged: bool,
    /// The fixed point just after heel strike.
    pub fixed_point: FixedPoint,
    /// Eigenvalues of the stride Jacobian, `[re, im]`.
    pub eigenvalues: Vec<[f64; 2]>,
    /// The eigenvector of each eigenvalue (in `eigenvalues`' order) as `{"re": [...], "im":
    /// [...]}`, entries in `jacobian`'s order (`jacobian.names`), unit 2-norm with its largest
    /// entry real and positive; `null` where inverse iteration found none.
    pub eigenvectors: Vec<Option<ComplexVector>>,
    /// The stride Jacobian at the fixed point: `{"names": [...], "rows": [[...]]}`, rows and
    /// columns in the order of `names`, the stride-map entries sorted as `fixed_point` lists
    /// them.
    pub jacobian: StrideJacobian,
    /// Largest eigenvalue modulus.
    pub max_abs_eigenvalue: f64,
    /// All eigenvalues strictly inside the unit circle.
    pub stable: bool,
    /// Step period \[s\].
    pub step_period_s: f64,
    /// Distance between the contacts of one step \[m\].
    pub step_length_m: f64,
    /// Distance walked forward per step \[m\].
    pub progress_m_per_step: f64,
    /// Forward speed [m/s].
    pub speed_m_s: f64,
    /// Newton iterations.
    pub newton_iterations: usize,
    /// How the stride Jacobian was taken.
    pub jacobian_method: JacobianMethod,
    /// `|S(v) − v|` at the fixed point (∞-norm).
    pub residual: f64,
    /// Events of the stride, in order.
    pub events: Vec<StrideEvent>,
    /// Mechanical energy lost in the impacts of a stride \[J\].
    pub impact_energy_loss_j: f64,
    /// Impact loss over weight times step length [-] (absent for a massless walker or a zero
    /// step).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub specific_cost_of_transport: Option<f64>,
    /// Heading change per step \[rad\].
    pub heading_change_rad_per_step: f64,
    /// Total mass \[kg\].
    pub total_mass_kg: f64,
    /// Each eigenvalue with the freedoms that dominate its eigenvector.
    pub eigenvalue_modes: Vec<EigenMode>,
    /// Actuator figures (walkers with actuated ankles only).
    #[serde(flatten)]
    pub actuator: Option<ActuatorFigures>,
    /// The stance ankle's extension as it happens in the periodic stride: engagement, release,
    /// the angle reached and how much of the profile ran (walkers with an ankle reflex only;
    /// absent otherwise). A found gait's stride always ends in a heel strike, so the record is
    /// always readable for them.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ankle_extension: Option<AnkleExtension>,
    /// Contact figures of the stride from the fixed point (when the caller could compute them).
    #[serde(flatten)]
    pub contact: Option<ContactFigures>,
}

/// Energy figures of an actuated gait, per step.
#[derive(Clone, Debug, Serialize)]
pub struct ActuatorFigures {
    /// Work done by the ankle actuator \[J\].
    pub actuator_work_j_per_step: f64,
    /// Energy dissipated by the joint dampers \[J\].
    pub damping_dissipation_j_per_step: f64,
    /// Actuator work per unit mass and forward distance, under the keys
    /// `cost_of_transport_J_per_kg_m` (original spelling, kept for compatibility) and
    /// `cost_of_transport_j_per_kg_m`.
    #[serde(flatten)]
    pub cost_of_transport: CostOfTransport,
    /// Work done by gravity over the periodic stride on a slope \[J\]: the potential energy
    /// released, `M g_floor · c` with `M` the total mass and `c` the step between the contacts
    /// (over a periodic stride the centre of mass moves by `c` along the floor and returns to
    /// its height above it). Absent on level ground, where it is 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub slope_work_j_per_step: Option<f64>,
    /// Actuator work plus the slope's work minus impact loss minus damper dissipation \[J\]:
    /// over a periodic stride the energy put in (by the actuator, and by gravity on a slope) is
    /// what the impacts and dampers take, so this checks the quadrature.
    pub energy_balance_residual_j: f64,
}

/// Contact and clearance figures of the stride from the fixed point.
#[derive(Clone, Debug, Serialize)]
pub struct ContactFigures {
    /// Largest |lateral centre of pressure| under the stance foot \[m\].
    pub max_lateral_cop_m: f64,
    /// Smallest normal force on the stance foot \[N\].
    pub min_normal_force_n: f64,
    /// Smallest swing-ankle height near mid-swing \[m\] (`null` if the swing ankle never passes).
    pub mid_swing_clearance_m: Option<f64>,
}

impl From<&ContactSummary> for ContactFigures {
    fn from(c: &ContactSummary) -> Self {
        Self {
            max_lateral_cop_m: c.max_lateral_cop_m,
            min_normal_force_n: c.min_normal_force_n,
            mid_swing_clearance_m: c.mid_swing_clearance_m,
        }
    }
}

/// A gait search that found nothing.
#[derive(Clone, Debug, Serialize)]
pub struct GaitNotFound {
    /// Always `false`.
    pub converged: bool,
    /// Why, in words.
    pub error: String,
    /// The stride that failed, when one did.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failure: Option<StrideFailure>,
    /// Newton iterations used (the failing iteration for a failed stride or a singular
    /// system).
    pub newton_iterations: usize,
    /// `null`: no fixed point.
    pub fixed_point: Option<FixedPoint>,
    /// `null`.
    pub eigenvalues: Option<Vec<[f64; 2]>>,
    /// `null`.
    pub eigenvectors: Option<Vec<Option<ComplexVector>>>,
    /// `null`.
    pub jacobian: Option<StrideJacobian>,
    /// `null`.
    pub max_abs_eigenvalue: Option<f64>,
    /// `null`.
    pub stable: Option<bool>,
    /// `null`.
    pub step_period_s: Option<f64>,
    /// `null`.
    pub step_length_m: Option<f64>,
    /// `null`.
    pub speed_m_s: Option<f64>,
}

impl GaitReport {
    /// The report of a gait search by `walker` (built from `scene`, integrating with
    /// `integrator`). `contact` is the contact summary of a stride from the fixed point, run
    /// by the caller with contact figures on; `None` leaves the contact figures out.
    pub fn new(
        scene: &Scene,
        walker: &Walker,
        integrator: &IntegratorChoice,
        result: &Result<Gait, NewtonError>,
        contact: Option<&ContactSummary>,
    ) -> Self {
        let outcome = match result {
            Ok(g) => GaitOutcome::Found(Box::new(FoundGait::new(scene, walker, g, contact))),
            Err(e) => GaitOutcome::NotFound(Box::new(GaitNotFound::new(e))),
        };
        Self {
            scene: scene.name().to_string(),
            parameters: scene.values.clone(),
            integrator: integrator.clone(),
            gait_source: None,
            outcome,
        }
    }

    /// The report of a gait search `result` at `scene`'s values (`setup` built from them),
    /// with the contact figures of [`Setup::gait_stride`] from its fixed point, as `walker gait`
    /// reports a gait; and that stride (its samples kept when `record`, for a joint-angle
    /// figure). The report's `gait_source` is left for the caller.
    pub fn of_setup(
        setup: &Setup,
        scene: &Scene,
        result: &Result<Gait, NewtonError>,
        record: bool,
    ) -> (Self, Option<StrideResult>) {
        let stride = result
            .as_ref()
            .ok()
            .and_then(|g| setup.gait_stride(g, record));
        let report = Self::new(
            scene,
            &setup.walker,
            &setup.settings.integrator,
            result,
            stride.as_ref().map(|r| &r.contact),
        );
        (report, stride)
    }
}

impl FoundGait {
    fn new(scene: &Scene, walker: &Walker, g: &Gait, contact: Option<&ContactSummary>) -> Self {
        let n = gait_numbers(walker, g);
        let mass = walker.model().total_mass_kg();
        let g_m_s2 = walker.model().gravity_floor_m_s2.norm();
        let s = &g.stride;
        let gravity = walker.model().gravity_floor_m_s2;
        let slope_work =
            (gravity.x != 0.0 || gravity.z != 0.0).then(|| mass * gravity.dot(&s.step_m));
        let actuator = walker.ankle().map(|_| {
            let cost = s.actuator_work_j / (mass * n.progress_m);
            let put_in = match slope_work {
                Some(w) => s.actuator_work_j + w,
                None => s.actuator_work_j,
            };
            ActuatorFigures {
                actuator_work_j_per_step: s.actuator_work_j,
                damping_dissipation_j_per_step: s.damping_dissipation_j,
                cost_of_transport: CostOfTransport { j_per_kg_m: cost },
                slope_work_j_per_step: slope_work,
                energy_balance_residual_j: put_in
                    - s.impact_energy_loss_j
                    - s.damping_dissipation_j,
            }
        });
        let map_names = walker.map_names();
        Self {
            converged: true,
            fixed_point: FixedPoint::of(scene, walker, g),
            eigenvalues: eigenvalue_pairs(&g.eigenvalues),
            eigenvectors: eigenvectors(&g.jacobian, &g.eigenvalues, &map_names),
            jacobian: StrideJacobian::new(&g.jacobian, &map_names),
            max_abs_eigenvalue: g.max_abs_eigenvalue(),
            stable: g.stable(),
            step_period_s: n.step_period_s,
            step_length_m: n.step_length_m,
            progress_m_per_step: n.progress_m,
            speed_m_s: n.speed_m_s,
            newton_iterations: g.iterations,
            jacobian_method: g.jacobian_method,
            residual: g.residual,
            events: s.events.clone(),
            impact_energy_loss_j: s.impact_energy_loss_j,
            specific_cost_of_transport: (mass > 0.0 && n.step_length_m > 0.0)
                .then(|| s.impact_energy_loss_j / (mass * g_m_s2 * n.step_length_m)),
            heading_change_rad_per_step: s.heading_change_rad,
            total_mass_kg: mass,
            eigenvalue_modes: modes(
                &g.jacobian,
                &g.eigenvalues,
                &map_names,
                walker.three_d_freedoms(),
            ),
            actuator,
            ankle_extension: walker
                .ankle()
                .as_ref()
                .and_then(|r| AnkleExtension::of(r, s).ok()),
            contact: contact.map(ContactFigures::from),
        }
    }
}

impl GaitNotFound {
    fn new(e: &NewtonError) -> Self {
        let (newton_iterations, failure) = match e {
            NewtonError::NotConverged { iterations, .. } => (*iterations, None),
            NewtonError::StrideFailed { iteration, failure } => (*iteration, Some(failure.clone())),
            NewtonError::Singular { iteration } => (*iteration, None),
        };
        Self {
            converged: false,
            error: e.to_string(),
            failure,
            newton_iterations,
            fixed_point: None,
            eigenvalues: None,
            eigenvectors: None,
            jacobian: None,
            max_abs_eigenvalue: None,
            stable: None,
            step_period_s: None,
            step_length_m: None,
            speed_m_s: None,
        }
    }
}
