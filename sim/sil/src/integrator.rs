//! The integrator a firmware-in-the-loop walk uses, and how accurate it is.

use sim::integrators::IntegratorChoice;

/// The integrator of a firmware-in-the-loop walk: DOPRI5 at rtol = atol = 1e-6.
///
/// The control ticks cut every integration step to at most one tick (1 ms), so the tolerance
/// rarely shortens a step further. Over 12 steps of `wisse3d` with the firmware in the loop,
/// against DOPRI5 at 1e-12 (relative differences of the 12-step means): step period, speed
/// and step length agree to 5e-8, the impact loss per step to 2e-7, but the actuator work per
/// step and the cost of transport only to 9e-6 (test `hil-tests/tests/sil_integrator.rs`,
/// bounds 3 × these; docs/sil.md). It costs 6.4 right-hand-side evaluations per tick against
/// 9.6 at 1e-9 and 21.4 at 1e-12. Classical RK4 at one step per tick is cheaper
/// (4 evaluations) but its step period is 0.1 % off and its impact loss 0.7 %.
pub const SIL_INTEGRATOR: IntegratorChoice = IntegratorChoice::Dopri5 {
    rtol: 1e-6,
    atol: 1e-6,
    h_max_s: 0.01,
};
