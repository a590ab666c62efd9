//! One stride: integrate single stance from just after one heel strike to just after the next,
//! with knee locks and the ankle string's engagement on the way, then relabel (the stride
//! function of eq. 22). The one entry point is [`Walker::stride`] with a [`StrideRequest`].
//!
//! The folder, by concept:
//! - `settings`: [`StrideSettings`], the solver settings (integrator, event tolerances, time
//!   budget), apart from the walker's physics;
//! - `request`: [`StrideRequest`], what one stride is asked to do (settings, recording, step
//!   schedule, controller, sample sink);
//! - `phase`: the smooth dynamics of a phase ([`Phase`], [`Drive`], [`linearised_limit`]);
//! - `witnesses`: the event witnesses and which of them a step triggers;
//! - `schedule`: step schedules recorded and replayed ([`StepSchedule`], [`Schedule`]);
//! - `impacts`: every impact (coordinate locking, string engagement, heel strike) and the
//!   stride's end ([`Walker::heel_strike_impact`]);
//! - `energy`: actuator work and damper dissipation;
//! - `contact_figures`: [`ContactSummary`];
//! - [`EvaluationPath`] (from [`crate::engine`]): which evaluation a stride uses;
//! - `state`: `StrideState`, a state of a stride in one storage (dynamic or fixed-size);
//! - `engine`: what the loop needs of a state's storage and its evaluation (`Engine`), and the
//!   reference engine on `DVector` samples;
//! - `run`: the one loop, written once for every engine (its control ticks in `run/ticks`);
//! - `fast`: the fixed-size engine (`SVector<N>` states, DOP853 and the planar evaluation) for
//!   the planar walkers it covers (selected automatically, the reference engine its reference
//!   and fallback);
//! - `workspace`: [`StrideWorkspace`], the model-derived structures and scratch repeated
//!   strides reuse, and the entry points ([`Walker::stride`], [`StrideWorkspace::stride`])
//!   that pick the engine and run the loop on it;
//! - `result`: [`StrideResult`], [`StrideEvent`];
//! - `failure`: [`StrideFailure`], its [`FailureKind`] and [`FailureCause`] (with the values).
//!
//! `impl Walker` for the stride lives here (`workspace` and `impacts`); [`crate::engine::walker`] keeps the
//! model-level methods; walks are [`crate::stride::walk::walk`], gait searches
//! [`crate::analysis::limit_cycle::GaitSearch`]. Times in a stride are stride time (from its start).
//!
//! [`Walker::stride`]: crate::engine::walker::Walker::stride
//! [`Walker::heel_strike_impact`]: crate::engine::walker::Walker::heel_strike_impact

mod budget;
mod contact_figures;
mod energy;
mod engine;
mod failure;
mod fast;
mod floor;
mod impacts;
mod phase;
mod request;
mod result;
mod run;
mod schedule;
mod settings;
mod state;
pub mod walk;
mod witnesses;
mod workspace;

pub use crate::engine::EvaluationPath;
pub use budget::{SearchBudget, SharedBudget};
pub use contact_figures::ContactSummary;
pub use failure::{FailureCause, FailureKind, StrideFailure};
pub use floor::{Floor, FloorError, FloorHeights};
pub use impacts::HeelStrikeImpact;
pub use phase::{linearised_limit, Drive, Phase};
pub use request::{StrideControl, StrideOptions, StrideRequest};
pub use result::{StrideEvent, StrideResult};
pub use schedule::{Schedule, StepSchedule};
pub use settings::StrideSettings;
pub use workspace::StrideWorkspace;
