//! The names most programs need: `use sim::prelude::*;`.

pub use crate::analysis::continuation::{continuation, sweep, ContinuationSettings};
pub use crate::analysis::limit_cycle::{Gait, GaitSearch, NewtonSettings};
pub use crate::engine::integrators::IntegratorChoice;
pub use crate::engine::model::Model;
pub use crate::engine::walker::{Walker, WalkerRules};
pub use crate::scene::{Scene, SceneError, Setup};
pub use crate::stride::walk::{walk, WalkRequest};
pub use crate::stride::{
    FailureKind, StrideFailure, StrideRequest, StrideResult, StrideSettings, StrideWorkspace,
};
