//! The gait figures as `walker gait`, `walker walk` and `walker sil` print them for people:
//! speed (per metre walked forward), the step (forward progress and the distance between the
//! feet at heel strike), period, actuator work per step and cost of transport. The numbers
//! come from the engine's reports ([`sim::report`]); nothing here computes them again.

use crate::commands::shown;
use sim::report::{FoundGait, IdealGaitRecord, WalkGaitRecord};
use std::io::Write;

/// The figures of one gait, as a report gives them.
pub struct GaitFigures {
    /// Step period \[s\].
    pub period_s: f64,
    /// Distance walked forward per step \[m\].
    pub progress_m: f64,
    /// Distance between the feet at heel strike \[m\].
    pub step_length_m: f64,
    /// Forward speed, `progress_m / period_s` [m/s].
    pub speed_m_s: f64,
    /// Actuator work per step \[J\] and cost of transport [J/(kg·m)]; `None` for a walker
    /// without an actuator.
    pub actuator: Option<(f64, f64)>,
}

impl GaitFigures {
    /// The figures of a gait found by `walker gait` (passive walkers have no actuator).
    pub fn of_found(g: &FoundGait) -> Self {
        Self {
            period_s: g.step_period_s,
            progress_m: g.progress_m_per_step,
            step_length_m: g.step_length_m,
            speed_m_s: g.speed_m_s,
            actuator: g
                .actuator
                .as_ref()
                .map(|a| (a.actuator_work_j_per_step, a.cost_of_transport.j_per_kg_m)),
        }
    }

    /// The mean figures over the last steps of a walk.
    pub fn of_walk(g: &WalkGaitRecord, actuated: bool) -> Self {
        Self {
            period_s: g.step_period_s,
            progress_m: g.progress_m_per_step,
            step_length_m: g.step_length_m,
            speed_m_s: g.speed_m_s,
            actuator: actuated
                .then_some((g.actuator_work_j_per_step, g.cost_of_transport.j_per_kg_m)),
        }
    }

    /// The figures of the ideal-actuator gait of `walker sil`.
    pub fn of_ideal(g: &IdealGaitRecord) -> Self {
        Self {
            period_s: g.step_period_s,
            progress_m: g.progress_m_per_step,
            step_length_m: g.step_length_m,
            speed_m_s: g.speed_m_s,
            actuator: Some((g.actuator_work_j_per_step, g.cost_of_transport.j_per_kg_m)),
        }
    }

    /// Writes the figures, one per line, each line starting with `indent`.
    pub fn write(&self, out: &mut dyn Write, indent: &str) -> std::io::Result<()> {
        let (period, progress, length, speed) = (
            shown(self.period_s),
            shown(self.progress_m),
            shown(self.step_length_m),
            shown(self.speed_m_s),
        );
        writeln!(
            out,
            "{indent}speed              {speed:.6} m/s = forward progress {progress:.6} m per step / period {period:.6} s"
        )?;
        writeln!(
            out,
            "{indent}step               {progress:.6} m forward progress, {length:.6} m between the feet at heel strike"
        )?;
        writeln!(out, "{indent}period             {period:.6} s")?;
        match self.actuator {
            Some((work, cost)) => {
                writeln!(
                    out,
                    "{indent}actuator work      {:.6} J per step",
                    shown(work)
                )?;
                writeln!(
                    out,
                    "{indent}cost of transport  {:.6} J/(kg·m) = actuator work / (mass × forward progress)",
                    shown(cost)
                )
            }
            None => writeln!(
                out,
                "{indent}cost of transport  none: no actuator (the energy comes from the slope)"
            ),
        }
    }
}
