//! The hybrid multibody engine: the read-only model, its kinematics and equations of motion
//! (generic over the scalar), contact and impact equations, integrators and event location;
//! and the walker built on it — its rules (heel strike, knees, fall, relabelling), the ankle
//! reflex and the controller interface.
//!
//! The fast evaluations (the planar tree with its closed forms, the 3D axis tree, the limit
//! of vanishing masses) are the crate's own: a stride picks them
//! ([`EvaluationPath`]) and the general engine stays their reference.
//! [`PlanarTree`] and [`AxisTree`] are public so that they can be checked against it.

pub mod actuator;
pub(crate) mod axis_tree;
pub(crate) mod compiled;
pub mod contact;
pub mod control;
pub mod dynamics;
mod evaluation_path;
pub mod events;
pub mod hermite;
pub(crate) mod hybrid;
pub mod impact;
pub mod integrators;
pub mod kinematics;
pub(crate) mod math;
pub mod model;
pub(crate) mod planar;
pub mod relabel;
pub(crate) mod singular_limit;
pub mod walker;

pub use axis_tree::AxisTree;
pub use evaluation_path::EvaluationPath;
pub use hybrid::phase::DriveValues;
pub use math::rotation_about;
pub use planar::PlanarTree;
