//! Reports of gaits, walks, sweeps and scenes: the output contract other tools read.
//!
//! Each report is a typed record computed from results the engine already returned (a
//! [`Gait`], a [`Walk`](crate::stride::walk::Walk), sweep points); no report simulates. Whatever a
//! report needs from a further stride (e.g. the contact figures of [`GaitReport`]) the caller
//! runs through the engine and passes in.
//!
//! # JSON form
//!
//! Serialise a report with [`to_json`]: it goes through [`serde_json::Value`], whose objects
//! (without serde_json's `preserve_order` feature) are key-sorted maps, so every object of the
//! output — the reports' own and those of the engine types inside them — lists its keys in
//! sorted order, as the output always has. Floats that are not finite come out as `null`.
//!
//! # Key spelling
//!
//! Keys are lower snake case with the unit last (`step_period_s`). One older key,
//! `cost_of_transport_J_per_kg_m`, has an upper-case `J`; it is kept for compatibility, with
//! its lower-case twin `cost_of_transport_j_per_kg_m` (the same number) beside it.

mod ankle_extension;
mod basin;
mod cost_of_transport;
mod fixed_point;
mod gait;
mod gaits;
mod ideal_gait;
mod optimize;
mod orbit_diagram;
mod robustness;
mod scenes;
mod stability_map;
mod start;
mod stride_jacobian;
mod sweep;
mod walk;
mod walk_gait;

pub use ankle_extension::{AnkleExtension, AnkleExtensionError};
pub use basin::BasinReport;
pub use cost_of_transport::CostOfTransport;
pub use fixed_point::FixedPoint;
pub use gait::{ActuatorFigures, ContactFigures, FoundGait, GaitNotFound, GaitOutcome, GaitReport};
pub use gaits::GaitsReport;
pub use ideal_gait::IdealGaitRecord;
pub use optimize::{
    parse_vary, Best, Method, OptimizeOptionError, OptimizeOptions, OptimizeReport,
    OptimizeRequest, MAX_OPTIMIZE_EVALUATIONS,
};
pub use orbit_diagram::{FellRecord, OrbitDiagramReport, OrbitPointRecord};
pub use robustness::{
    Again, Measures, RobustnessOptionError, RobustnessOptions, RobustnessReport, Signs,
    MAX_MFPT_RUNS, MAX_MFPT_STRIDES, MAX_MFPT_TOTAL_STRIDES, MAX_RETURN_STRIDES, MAX_SIGMAS,
    MIN_RATE_SCAN_STEP,
};
pub use scenes::{ParameterEntry, SceneCatalogue, SceneEntry};
pub use stability_map::{AxisRecord, StabilityMapReport};
pub use start::{StartKind, StartRecord};
pub use stride_jacobian::{eigenvectors, ComplexVector, StrideJacobian};
pub use sweep::{
    BoundaryRecord, BranchEndRecord, BranchRecord, ConvergedPoint, FailedPoint, QuantityValue,
    SweepPointRecord, SweepReport, SwitchFailureRecord, UnlocatedRecord,
};
pub use walk::WalkReport;
pub use walk_gait::WalkGaitRecord;

use crate::analysis::limit_cycle::Gait;
use crate::engine::walker::Walker;
use nalgebra::Complex;
use serde::Serialize;

/// A report as JSON, every object key-sorted (see the [module docs](self)).
pub fn to_json<T: Serialize + ?Sized>(report: &T) -> serde_json::Result<serde_json::Value> {
    serde_json::to_value(report)
}

/// Gait summary numbers.
pub struct GaitNumbers {
    /// Step period \[s\].
    pub step_period_s: f64,
    /// Step length \[m\].
    pub step_length_m: f64,
    /// Distance walked per step, forward \[m\].
    pub progress_m: f64,
    /// Speed [m/s].
    pub speed_m_s: f64,
}

/// Period, step length and speed of a gait.
pub fn gait_numbers(walker: &Walker, gait: &Gait) -> GaitNumbers {
    let step_period_s = gait.stride.duration_s;
    let step_length_m = gait.stride.step_m.norm();
    let progress_m = forward_progress_m(walker, gait);
    GaitNumbers {
        step_period_s,
        step_length_m,
        progress_m,
        speed_m_s: progress_m / step_period_s,
    }
}

/// Distance walked per step \[m\]: half the displacement over two periodic steps, `|c + M c| / 2`
/// with `c` the step between contacts and `M` the map from one stance frame to the next
/// (reflection and heading). For a 3D walker this leaves out the sideways zigzag between the
/// feet, which `step_length_m` (the distance between the contacts) includes.
pub fn forward_progress_m(walker: &Walker, gait: &Gait) -> f64 {
    let c = gait.stride.step_m;
    let next = crate::stride::walk::FloorFrame::default().next(
        &c,
        gait.stride.heading_change_rad,
        walker.relabel().mirror,
    );
    (c + next.r * c).norm() / 2.0
}

/// Eigenvalues as `[re, im]` pairs, the form every report lists them in.
fn eigenvalue_pairs(eigenvalues: &[Complex<f64>]) -> Vec<[f64; 2]> {
    eigenvalues.iter().map(|z| [z.re, z.im]).collect()
}
