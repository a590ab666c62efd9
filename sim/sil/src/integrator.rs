//! The integrator a firmware-in-the-loop walk uses, and how accurate it is.

use sim::integrators::IntegratorChoice;

/// The integrator of a firmware-in-the-loop walk: DOPRI5 at rtol = atol = 1e-6.
///
/// The control ticks cut every integration step to at most one tick (1 ms), so the tolerance
/// rarely shortens a step further. Over the first step of `wisse3d` (Table I, the chosen reading) with the
/// firmware in the loop, against DOPRI5 at 1e-12 (relative differences): step period, speed and
/// step length agree to 2e-8, the impact loss to 7e-9, the actuator work and the cost of
/// transport to 2.4e-7 (test `hil-tests/tests/sil_integrator.rs`, bounds 1.5e-7, 5e-7 and
/// 2.7e-5; docs/sil.md). Over more steps the closed loop (quantised encoder, 1 ms ticks)
/// amplifies such differences: 1.2e-4 in the 12-step mean period. It costs 6.4 right-hand-side evaluations per tick against
/// 9.6 at 1e-9 and 21.4 at 1e-12. Classical RK4 at one step per tick is cheaper
/// (4 evaluations) but its step period is 0.1 % off and its impact loss 0.7 %.
pub const SIL_INTEGRATOR: IntegratorChoice = IntegratorChoice::Dopri5 {
    rtol: 1e-6,
    atol: 1e-6,
    h_max_s: 0.01,
};
