//! The string actuator as the simulator sees it: a position servo that moves the string's limit
//! (as a stance ankle angle) towards the firmware's setpoint, with a rate limit and a
//! first-order lag, integrated exactly over each control tick.
//!
//! `dp/dt = clamp((s − p)/τ, −r_max, r_max)`: far from the setpoint the limit moves at the
//! rate limit `r_max` (saturated), within `r_max·τ` of it the lag takes over and the approach
//! is exponential. The rate is continuous at the switch, so position and rate are continuous
//! across ticks: each tick becomes a C¹ cubic Hermite [`ActuatorSegment`] from the previous
//! end `(p, v)` to the new end.
//!
//! Torque limit: the simulator's string is rigid and unilateral, so it transmits whatever torque
//! keeps the ankle at the limit. The model compares that torque (the string's torque on the
//! stance ankle at the tick's start, [`sim::engine::control::AnkleSensing::string_torque_n_m`]) with
//! the servo's [`ActuatorParams::max_torque_n_m`]: over it, the servo cannot move its load and
//! *stalls* for that tick — the limit stops advancing (it comes to rest within the tick, from
//! its rate at the tick's start, C¹: `p1 = p0 + v0·h/2`, `v1 = 0`, and holds there while the
//! torque stays over the limit). The string stays rigid: a servo that is backdriven by a load
//! over its limit (the limit moving backwards) is not modelled, nor is any compliance.
//! The servo's tracking error, its rate saturation and its torque are recorded
//! (see [`ActuatorStats`]).

use serde::Serialize;

use sim::engine::control::ActuatorSegment;

/// Parameters of the actuator model.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ActuatorParams {
    /// Largest rate of the string's limit, as an ankle-angle rate [rad/s]. Default 10 rad/s:
    /// 2.5 × the firmware's own bound on its push profile (`MaxPushRate`, 4 rad/s), so a
    /// healthy servo follows the profile without saturating, while a setpoint step (the
    /// string taking up slack at engagement) is still spread over milliseconds.
    pub max_rate_rad_per_s: f64,
    /// Time constant of the servo's first-order lag \[s\]. Default 5 ms (a position loop of
    /// about 30 Hz bandwidth, typical of a small geared DC motor with an encoder).
    pub time_constant_s: f64,
    /// Slack left when a released string is taken up \[rad\]: the limit starts this far below
    /// the ankle angle. Default 0.1 mrad (a quarter of an encoder count). The simulator
    /// engages the string as an event, the ankle reaching the limit from above; a limit
    /// starting exactly at the ankle would be a grazing start that it does not detect, and
    /// one above the ankle would violate the constraint.
    pub take_up_slack_rad: f64,
    /// Largest torque the servo can drive its string against [N·m] (as a torque on the
    /// ankle). While the string's torque at a tick exceeds it, the servo stalls for that tick
    /// (see the module documentation). Default 2.5 N·m: 1.5 × the largest torque of the
    /// nominal `wisse3d` push with the firmware in the loop (1.664 N·m over 200 steps,
    /// docs/sil.md), so a healthy servo never reaches it.
    pub max_torque_n_m: f64,
}

impl Default for ActuatorParams {
    fn default() -> Self {
        ActuatorParams {
            max_rate_rad_per_s: 10.0,
            time_constant_s: 0.005,
            take_up_slack_rad: 1e-4,
            max_torque_n_m: 2.5,
        }
    }
}

/// What the actuator did over a run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct ActuatorStats {
    /// Ticks with a position setpoint.
    pub position_ticks: u64,
    /// Ticks in which the rate limit was reached.
    pub saturated_ticks: u64,
    /// First time the rate limit was reached \[s\], if ever.
    pub first_saturation_s: Option<f64>,
    /// Largest |setpoint − limit| at the end of a tick \[rad\].
    pub max_tracking_error_rad: f64,
    /// Largest |limit rate| at the end of a tick [rad/s].
    pub max_rate_rad_per_s: f64,
    /// Largest |string torque| seen at a tick with a setpoint [N·m].
    pub peak_torque_n_m: f64,
    /// Ticks with a setpoint at which |string torque| exceeded
    /// [`ActuatorParams::max_torque_n_m`] (the servo stalled).
    pub over_torque_ticks: u64,
    /// First time the torque limit was exceeded \[s\], if ever.
    pub first_over_torque_s: Option<f64>,
}

/// One ankle's actuator: the string's limit and its rate, and the run's statistics.
#[derive(Clone, Debug, PartialEq)]
pub struct ActuatorModel {
    params: ActuatorParams,
    /// Limit [rad] and its rate [rad/s] at the end of the last segment; `None` while released.
    state: Option<(f64, f64)>,
    last: Option<ActuatorSegment>,
    stats: ActuatorStats,
}

/// End of one integration step.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Step {
    p_rad: f64,
    v_rad_s: f64,
    saturated: bool,
}

fn integrate(p: &ActuatorParams, p0: f64, setpoint: f64, h: f64) -> Step {
    let tau = p.time_constant_s.max(0.0);
    let r = p.max_rate_rad_per_s.abs();
    let e0 = setpoint - p0;
    let dir = e0.signum();
    // Time spent at the rate limit, before |e| falls to r·τ.
    let t_sat = if e0.abs() > r * tau && r > 0.0 {
        (e0.abs() - r * tau) / r
    } else {
        0.0
    };
    if t_sat >= h {
        return Step {
            p_rad: p0 + dir * r * h,
            v_rad_s: dir * r,
            saturated: h > 0.0,
        };
    }
    let e_at = if t_sat > 0.0 { dir * r * tau } else { e0 };
    let rest = h - t_sat;
    if tau <= 0.0 {
        return Step {
            p_rad: setpoint,
            v_rad_s: 0.0,
            saturated: t_sat > 0.0,
        };
    }
    let e1 = e_at * (-rest / tau).exp();
    Step {
        p_rad: setpoint - e1,
        v_rad_s: e1 / tau,
        saturated: t_sat > 0.0,
    }
}

impl ActuatorModel {
    /// A released actuator.
    pub fn new(params: ActuatorParams) -> Self {
        ActuatorModel {
            params,
            state: None,
            last: None,
            stats: ActuatorStats::default(),
        }
    }

    /// Statistics so far.
    pub fn stats(&self) -> &ActuatorStats {
        &self.stats
    }

    /// Limit \[rad\] and rate [rad/s] at `t_s` on the last segment (its end when `t_s` is past
    /// it); `None` while released.
    pub fn limit_at(&self, t_s: f64) -> Option<(f64, f64)> {
        let s = self.last?;
        if s.released {
            return None;
        }
        let (p, v, _) = s.eval(t_s);
        Some((p, v))
    }

    /// One tick over `[t0_s, t1_s]` with `setpoint_rad` (`None`: released). `take_up_rad` is
    /// where the string becomes taut if it was slack (the current ankle angle): a string
    /// that was released starts at rest from `min(setpoint, take_up − slack)`, below the
    /// ankle, then tracks the setpoint. `load_n_m` is the string's torque on the ankle at
    /// `t0_s` (0 while slack): over [`ActuatorParams::max_torque_n_m`] the servo stalls for
    /// this tick (the limit comes to rest, `v1 = 0`, and does not follow the setpoint).
    pub fn tick(
        &mut self,
        t0_s: f64,
        t1_s: f64,
        setpoint_rad: Option<f64>,
        take_up_rad: f64,
        load_n_m: f64,
    ) -> ActuatorSegment {
        let Some(s) = setpoint_rad else {
            self.state = None;
            let p = self.last.map_or(take_up_rad, |l| l.eval(t0_s).0);
            let seg = ActuatorSegment {
                released: true,
                ..ActuatorSegment::hold(t0_s, t1_s, p)
            };
            self.last = Some(seg);
            return seg;
        };
        let (p0, v0) = match (self.state, self.limit_at(t0_s)) {
            (Some(_), Some(pv)) => pv,
            (Some(pv), None) => pv,
            (None, _) => (s.min(take_up_rad - self.params.take_up_slack_rad), 0.0),
        };
        let h = (t1_s - t0_s).max(0.0);
        let load = load_n_m.abs();
        // NaN compares false: an unknown load does not stall the servo.
        let stalled = load > self.params.max_torque_n_m;
        let end = if stalled {
            // Stalled: the limit stops advancing, at rest by the tick's end (constant
            // deceleration from its rate at the start, so position and rate stay continuous).
            Step {
                p_rad: p0 + 0.5 * v0 * h,
                v_rad_s: 0.0,
                saturated: false,
            }
        } else {
            integrate(&self.params, p0, s, h)
        };
        self.state = Some((end.p_rad, end.v_rad_s));
        let st = &mut self.stats;
        st.position_ticks += 1;
        if load.is_finite() {
            st.peak_torque_n_m = st.peak_torque_n_m.max(load);
        }
        if stalled {
            st.over_torque_ticks += 1;
            st.first_over_torque_s.get_or_insert(t0_s);
        }
        if end.saturated {
            st.saturated_ticks += 1;
            st.first_saturation_s.get_or_insert(t0_s);
        }
        st.max_tracking_error_rad = st.max_tracking_error_rad.max((s - end.p_rad).abs());
        st.max_rate_rad_per_s = st.max_rate_rad_per_s.max(end.v_rad_s.abs());
        let seg = ActuatorSegment {
            t0_s,
            t1_s,
            p0_rad: p0,
            v0_rad_s: v0,
            p1_rad: end.p_rad,
            v1_rad_s: end.v_rad_s,
            released: false,
        };
        self.last = Some(seg);
        seg
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn step_is_rate_limited_then_exponential() {
        let p = ActuatorParams::default();
        // 0.1 rad step: saturated for (0.1 - 10*0.005)/10 = 5 ms.
        let s = integrate(&p, 0.0, 0.1, 0.001);
        assert!(s.saturated && (s.p_rad - 0.01).abs() < 1e-15 && s.v_rad_s == 10.0);
        let s = integrate(&p, 0.0, 0.1, 0.005);
        assert!((s.p_rad - 0.05).abs() < 1e-12 && (s.v_rad_s - 10.0).abs() < 1e-9);
        let s = integrate(&p, 0.0, 0.1, 0.010);
        let e = 0.05 * (-1.0f64).exp();
        assert!((s.p_rad - (0.1 - e)).abs() < 1e-12 && (s.v_rad_s - e / 0.005).abs() < 1e-9);
        // Splitting the interval changes nothing (exact integration).
        let a = integrate(&p, 0.0, 0.1, 0.003);
        let b = integrate(&p, a.p_rad, 0.1, 0.007);
        assert!((b.p_rad - s.p_rad).abs() < 1e-12);
        // Small errors: pure lag, not saturated; downward too.
        let s = integrate(&p, 0.0, -0.01, 0.001);
        assert!(!s.saturated && s.p_rad < 0.0 && s.p_rad > -0.01 && s.v_rad_s < 0.0);
    }

    #[test]
    fn segments_are_continuous_and_start_at_the_take_up_angle() {
        let mut m = ActuatorModel::new(ActuatorParams::default());
        let r = m.tick(0.0, 0.001, None, -0.05, 0.0);
        assert!(r.released);
        // Engaging with the ankle at -0.085 below the setpoint -0.08: starts at the ankle,
        // less the slack.
        let a = m.tick(0.001, 0.002, Some(-0.08), -0.085, 0.0);
        assert_eq!((a.p0_rad, a.v0_rad_s), (-0.085 - 1e-4, 0.0));
        assert!(a.p1_rad > -0.085 && a.p1_rad < -0.08);
        let b = m.tick(0.002, 0.003, Some(0.2), 0.0, 0.0);
        assert_eq!((b.p0_rad, b.v0_rad_s), (a.p1_rad, a.v1_rad_s));
        assert!(b.v1_rad_s <= 10.0 + 1e-12);
        assert_eq!(m.stats().saturated_ticks, 1);
        assert_eq!(m.stats().first_saturation_s, Some(0.002));
        // A tick that comes early continues from where the last segment is at that time.
        let c = m.tick(0.0025, 0.0035, Some(0.2), 0.0, 0.0);
        assert_eq!(c.p0_rad, b.eval(0.0025).0);
        // Engaging with the ankle above the setpoint: starts at the setpoint.
        let mut m = ActuatorModel::new(ActuatorParams::default());
        let a = m.tick(0.0, 0.001, Some(-0.08), 0.1, 0.0);
        assert_eq!(a.p0_rad, -0.08);
    }

    #[test]
    fn over_the_torque_limit_the_servo_stalls_for_the_tick() {
        let params = ActuatorParams {
            max_torque_n_m: 1.0,
            ..ActuatorParams::default()
        };
        let mut m = ActuatorModel::new(params);
        m.tick(0.0, 0.001, Some(-0.08), -0.08, 0.0);
        let a = m.tick(0.001, 0.002, Some(0.0), -0.08, 0.9);
        assert!(a.v1_rad_s > 1.0, "moving towards the setpoint: {a:?}");
        // Over the limit (either sign): the limit comes to rest within the tick, C¹.
        let b = m.tick(0.002, 0.003, Some(0.0), -0.08, -1.5);
        assert_eq!((b.p0_rad, b.v0_rad_s), (a.p1_rad, a.v1_rad_s));
        assert_eq!(b.v1_rad_s, 0.0);
        assert!((b.p1_rad - (a.p1_rad + 0.5 * a.v1_rad_s * 0.001)).abs() < 1e-15);
        // Still over: it holds.
        let c = m.tick(0.003, 0.004, Some(0.0), -0.08, 2.0);
        assert_eq!(
            (c.p0_rad, c.v0_rad_s, c.p1_rad, c.v1_rad_s),
            (b.p1_rad, 0.0, b.p1_rad, 0.0)
        );
        // Under again: it follows the setpoint.
        let d = m.tick(0.004, 0.005, Some(0.0), -0.08, 0.5);
        assert!(d.p1_rad > c.p1_rad && d.v1_rad_s > 0.0);
        let st = m.stats();
        assert_eq!(st.over_torque_ticks, 2);
        assert_eq!(st.first_over_torque_s, Some(0.002));
        assert_eq!(st.peak_torque_n_m, 2.0);
        // A released string carries nothing and is not counted.
        m.tick(0.005, 0.006, None, -0.08, 5.0);
        assert_eq!(m.stats().over_torque_ticks, 2);
        assert_eq!(m.stats().peak_torque_n_m, 2.0);
    }
}
