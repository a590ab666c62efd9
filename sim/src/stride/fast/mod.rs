//! The fixed-size stride: the general stride loop ([`crate::walker::Walker::stride`]'s `run`)
//! specialised to the planar fast path, for the walkers and requests it covers — states
//! `SVector<f64, N>` (positions, velocities), DOP853 and its dense output on them
//! (`dop853`), the witnesses on the planar kinematics (`witness`), event location on the
//! dense output with the general refinement ([`crate::events::refine`]), and the general
//! impacts and relabelling at knee locks and heel strike (once or twice a stride). It returns
//! the general loop's [`StrideResult`], step for step the same arithmetic; the general loop
//! stays the reference (`sim/tests/fast_path.rs` compares both).
//!
//! Selected automatically ([`covers`]): a walker on the planar fast path
//! ([`PlanarTree::of`]) without an ankle string, DOP853 with its dense output for events, no
//! controller, no contact figures, and [`EvaluationPath::Auto`] (or `LinkPass`). Whatever it meets on the way
//! that the general loop handles and it does not — a step that triggers two events, a fall, a
//! scuff the scene does not ignore, a budget used up, a failed step — hands the stride back to
//! the general loop, which runs it again from its start ([`Outcome::Fallback`]).

mod dop853;
mod heel_strike;
mod impact;
mod run;
mod witness;

use super::request::StrideOptions;
use super::schedule::Schedule;
use super::settings::StrideSettings;
use super::{StrideFailure, StrideResult};
use crate::integrators::{IntegratorChoice, Sample};
use crate::planar::{EvaluationPath, PlanarTree};
use crate::walker::Walker;
use nalgebra::DVector;

/// What the fixed-size stride made of a stride.
pub(super) enum Outcome {
    /// The stride, completed or failed as the general loop would have it.
    Done(Box<Result<StrideResult, StrideFailure>>),
    /// Not covered (from the start or on the way): the general loop runs it.
    Fallback,
}

/// Whether the fixed-size stride covers a stride of `walker` with these settings and options
/// (and no controller): the planar tree when it does.
pub(super) fn covers(
    walker: &Walker,
    settings: &StrideSettings,
    options: StrideOptions,
    controlled: bool,
) -> Option<PlanarTree> {
    let eligible = matches!(
        settings.evaluation,
        EvaluationPath::Auto | EvaluationPath::LinkPass
    ) && matches!(settings.integrator, IntegratorChoice::Dop853 { .. })
        && settings.event_tolerance.dense_output
        && !controlled
        && walker.ankle.is_none()
        && !options.contact;
    if !eligible {
        return None;
    }
    PlanarTree::for_path(&walker.model, settings.evaluation)
}

impl Walker {
    /// Whether a stride of this walker with `settings` and `options` (and no controller) takes
    /// the fixed-size stride (`stride::fast`) from its start, rather than the general loop. It
    /// may still hand the stride back to the general loop on the way (two events in one step,
    /// a fall, a budget used up).
    pub fn takes_fixed_size_stride(
        &self,
        settings: &StrideSettings,
        options: StrideOptions,
    ) -> bool {
        covers(self, settings, options, false).is_some_and(|t| (1..=6).contains(&t.dof()))
    }
}

/// Runs the stride from `q0`, `qd0` on fixed-size states, if `tree` has a size it is built for
/// (1 to 6 coordinates). Samples it records go to `trajectory`; on a fallback the caller drops
/// them.
#[allow(clippy::too_many_arguments)]
pub(super) fn stride(
    walker: &Walker,
    tree: &PlanarTree,
    settings: &StrideSettings,
    options: StrideOptions,
    schedule: Schedule<'_>,
    trajectory: &mut Vec<Sample>,
    q0: &DVector<f64>,
    qd0: &DVector<f64>,
) -> Outcome {
    let args = run::Args {
        walker,
        tree,
        settings,
        options,
        schedule,
        trajectory,
    };
    match tree.dof() {
        1 => run::stride::<1>(args, q0, qd0),
        2 => run::stride::<2>(args, q0, qd0),
        3 => run::stride::<3>(args, q0, qd0),
        4 => run::stride::<4>(args, q0, qd0),
        5 => run::stride::<5>(args, q0, qd0),
        6 => run::stride::<6>(args, q0, qd0),
        _ => Outcome::Fallback,
    }
}
