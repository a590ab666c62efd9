//! Time integrators for `q̈ = f(q, q̇, t)` behind one interface.
//!
//! Every integrator advances a [`SecondOrderSystem`] by one accepted step and can take an
//! exact step of any smaller size, which the event locator uses to refine event times.
//!
//! By file: `system` (the system, samples, errors), `integrator` (the [`Integrator`] trait), `adaptive` (the
//! embedded pairs' step-size controller), `choice` ([`IntegratorChoice`]), one file per scheme,
//! `dense` (DOP853's dense output).

mod adaptive;
mod choice;
mod dense;
mod dop853;
mod dopri5;
mod embedded;
mod integrator;
mod meijaard;
mod rk4;
mod system;

pub(crate) use adaptive::{adaptive_step, StepLimits};
pub use choice::{IntegratorChoice, IntegratorError};
pub use dense::{DenseCoefficients, DenseOutput};
pub(crate) use dop853::{combined_error, component_error};
pub use dop853::{Dop853, Dop853Pair};
pub use dopri5::{Dopri5, Dopri5Pair};
pub use embedded::{EmbeddedPair, EmbeddedRk, Tolerances};
pub use integrator::{Integrator, SystemChange};
pub use meijaard::Meijaard;
pub use rk4::Rk4;
pub use system::{IntegrationError, Sample, SecondOrderSystem, StabilityLimit};
