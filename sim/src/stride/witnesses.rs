//! What the stride loop watches: the witness functions of its events, evaluated from one
//! kinematics update of a sample, and which of them a step triggers.
//!
//! Each event is a [`Watch`]; [`Witnesses::value`] evaluates its witness at any sample (for
//! event location), [`Witnesses::triggered`] lists the watches whose witnesses changed sign in
//! their direction over a step, in a fixed order (heel, knees, hip low, hip back, string
//! engagement, heel drop) that breaks ties between events located at the same time.

use super::state::StrideState;
use crate::engine::control::ActuatorSegment;
use crate::engine::events::Direction;
use crate::engine::hermite::{self, Knot};
use crate::engine::integrators::Sample;
use crate::engine::kinematics::Kinematics;
use crate::engine::walker::Walker;
use nalgebra::Vector3;

/// An event the stride loop watches for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Watch {
    /// The swing foot reaches the floor (heel strike, or a scuff).
    Heel,
    /// Knee `k` of [`Walker::knees`] reaches its stop.
    Knee(usize),
    /// The hip falls below its minimum height.
    HipLow,
    /// The hip, behind the stance contact, starts moving backward.
    HipBack,
    /// The stance ankle reaches the string's limit: the string becomes taut.
    Engage,
    /// The stance heel comes back down to the floor.
    HeelDrop,
}

/// The string's limit on the stance ankle angle, which the engagement witness compares with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum StringLimit {
    /// The ideal reflex: a fixed engagement angle [rad].
    Fixed(f64),
    /// A controller's segment over the current tick (stride time).
    Moving(ActuatorSegment),
    /// No limit: the string is slack (released, or no tick yet).
    Slack,
}

impl StringLimit {
    /// The limit angle [rad] at stride time `t_stride_s`, if any.
    fn at(&self, t_stride_s: f64) -> Option<f64> {
        match self {
            StringLimit::Fixed(e) => Some(*e),
            StringLimit::Moving(seg) => Some(seg.eval(t_stride_s).0),
            StringLimit::Slack => None,
        }
    }
}

/// Everything the stride loop watches, from one kinematics evaluation of a sample.
#[derive(Clone, Copy, Debug)]
pub(super) struct WitnessValues {
    /// Stride time of the sample [s].
    pub(super) t_s: f64,
    pub(super) foot_height_m: f64,
    pub(super) foot_height_rate_m_s: f64,
    pub(super) foot_ahead_m: f64,
    /// The rate of `foot_ahead_m` [m/s].
    pub(super) foot_ahead_rate_m_s: f64,
    pub(super) hip_height_margin_m: f64,
    pub(super) hip_ahead_m: f64,
    pub(super) hip_forward_velocity_m_s: f64,
}

impl WitnessValues {
    /// Whether a crossing of the floor by the swing foot on the step `self` → `next` is a
    /// mid-swing scuff wherever it lies in the step: the foot's distance ahead of the stance
    /// contact, as the cubic Hermite of its values and rates at both ends (which follows a
    /// turning point inside the step), stays below `min_ahead_m` over the step by more than
    /// the distance changes between the ends. Such a crossing need not be located to be told
    /// from heel strike. Shared by the general and the fixed-size stride loops.
    pub(super) fn scuff_anywhere_in_step(&self, next: &WitnessValues, min_ahead_m: f64) -> bool {
        let (a, b) = (self.foot_ahead_m, next.foot_ahead_m);
        let h = next.t_s - self.t_s;
        let knot = |w: &WitnessValues| Knot {
            value: w.foot_ahead_m,
            rate: w.foot_ahead_rate_m_s,
        };
        const SAMPLES: usize = 16;
        let highest = (1..SAMPLES).fold(a.max(b), |m, k| {
            let x = k as f64 / SAMPLES as f64;
            m.max(hermite::scalar(knot(self), knot(next), h, x).0)
        });
        h.is_finite() && h > 0.0 && highest + (b - a).abs() < min_ahead_m
    }

    /// A swing foot that dips below the floor and back inside one step (both ends above
    /// it): the stride time of the first of `samples` evenly spaced points of the step
    /// `self` → `next` at which the cubic Hermite of the foot's height (values and rates at
    /// both ends) is at or below zero, or `None` when the ends are not both above the floor
    /// or no point is below it. Shared by the general and the fixed-size stride loops.
    pub(super) fn grazing_sample_time(&self, next: &WitnessValues, samples: usize) -> Option<f64> {
        if self.foot_height_m <= 0.0 || next.foot_height_m <= 0.0 {
            return None;
        }
        let h = next.t_s - self.t_s;
        let knot = |w: &WitnessValues| Knot {
            value: w.foot_height_m,
            rate: w.foot_height_rate_m_s,
        };
        let fraction = |k: usize| k as f64 / (samples + 1) as f64;
        let height_at = |x: f64| hermite::scalar(knot(self), knot(next), h, x).0;
        (1..=samples)
            .find(|&k| height_at(fraction(k)) <= 0.0)
            .map(|k| self.t_s + h * k as f64 / (samples + 1) as f64)
    }
}

/// The witnesses of the stride's events at a state.
pub(super) trait WitnessEvaluator<S> {
    /// Every witness at `s`.
    fn eval(&mut self, s: &S) -> WitnessValues;
}

impl WitnessEvaluator<Sample> for Witnesses<'_> {
    #[inline]
    fn eval(&mut self, s: &Sample) -> WitnessValues {
        Witnesses::eval(self, s)
    }
}

/// Witness values at a sample: what the stride loop watches.
pub(super) struct Witnesses<'a> {
    pub(super) walker: &'a Walker,
    pub(super) kin: Kinematics,
    /// The landing floor above the stance foot's \[m\] ([`super::StrideOptions::floor_step_m`]):
    /// the swing foot's height is measured from it.
    pub(super) floor_step_m: f64,
}

impl<'a> Witnesses<'a> {
    pub(super) fn new(walker: &'a Walker) -> Self {
        Self {
            walker,
            kin: Kinematics::new(walker.model()),
            floor_step_m: 0.0,
        }
    }

    pub(super) fn update(&mut self, s: &Sample) {
        self.kin.update(self.walker.model(), &s.q, &s.qd);
    }

    pub(super) fn eval(&mut self, s: &Sample) -> WitnessValues {
        self.update(s);
        let m = self.walker.model();
        let foot = &m.points[self.walker.heel_strike().swing_foot.0];
        let p_foot = self.kin.position_of(foot.link, &foot.p_link_m);
        let hip = &m.points[self.walker.fall().hip.0];
        let p_hip = self.kin.position_of(hip.link, &hip.p_link_m);
        let p_contact = self
            .kin
            .point_position(m, self.walker.heel_strike().stance_contact);
        let contact_link = m.points[self.walker.heel_strike().stance_contact.0].link;
        let heading = self.heading();
        WitnessValues {
            t_s: s.t_s,
            foot_height_m: p_foot.y - self.floor_step_m,
            foot_height_rate_m_s: self.kin.velocity_of(foot.link, &p_foot).y,
            foot_ahead_m: (p_foot - p_contact).dot(&heading),
            foot_ahead_rate_m_s: (self.kin.velocity_of(foot.link, &p_foot)
                - self.kin.velocity_of(contact_link, &p_contact))
            .dot(&heading),
            hip_height_margin_m: p_hip.y - self.walker.fall().min_hip_height_m,
            hip_ahead_m: (p_hip - p_contact).dot(&heading),
            hip_forward_velocity_m_s: self.kin.velocity_of(hip.link, &p_hip).dot(&heading),
        }
    }

    /// The walking direction: the stance contact link's forward axis, level with the floor.
    pub(super) fn heading(&self) -> Vector3<f64> {
        let m = self.walker.model();
        let link = m.points[self.walker.heel_strike().stance_contact.0].link;
        let mut d = self.kin.r_floor_link[link.0] * Vector3::x();
        d.y = 0.0;
        let n = d.norm();
        if n > 1e-9 {
            d / n
        } else {
            Vector3::x()
        }
    }
}

/// The witness of `watch` at `s` (its zero is the event), with the string's `limit`, on any
/// state storage.
pub(super) fn value<S: StrideState>(
    walker: &Walker,
    wit: &mut impl WitnessEvaluator<S>,
    watch: Watch,
    limit: StringLimit,
    s: &S,
) -> f64 {
    let w = walker;
    match watch {
        Watch::Heel => wit.eval(s).foot_height_m,
        Watch::Knee(k) => s.q(w.knees()[k].coordinate.0) - w.knees()[k].stop_rad,
        Watch::HipLow => wit.eval(s).hip_height_margin_m,
        Watch::HipBack => wit.eval(s).hip_forward_velocity_m_s,
        Watch::Engage => {
            let a = w.ankle().as_ref().map_or(0, |r| r.ankle.0);
            s.q(a) - limit.at(s.t_s()).unwrap_or(0.0)
        }
        Watch::HeelDrop => s.q(w.ankle().as_ref().map_or(0, |r| r.toe_pitch.0)),
    }
}

/// The watches whose witnesses changed sign in their direction over the step `cur` → `next`
/// (witness values `w_cur`, `w_next`), into `triggered`, in tie-breaking order; `active` the free
/// coordinates, `driven` whether a coordinate is driven.
pub(super) fn triggered<S: StrideState>(
    triggered: &mut Vec<Watch>,
    walker: &Walker,
    (active, driven): (&[bool], bool),
    limit: StringLimit,
    (cur, w_cur): (&S, &WitnessValues),
    (next, w_next): (&S, &WitnessValues),
) {
    let w = walker;
    triggered.clear();
    if Direction::Falling.triggered(w_cur.foot_height_m, w_next.foot_height_m) {
        triggered.push(Watch::Heel);
    }
    for (k, knee) in w.knees().iter().enumerate() {
        let c = knee.coordinate.0;
        if active[c]
            && knee
                .closing
                .triggered(cur.q(c) - knee.stop_rad, next.q(c) - knee.stop_rad)
        {
            triggered.push(Watch::Knee(k));
        }
    }
    if Direction::Falling.triggered(w_cur.hip_height_margin_m, w_next.hip_height_margin_m) {
        triggered.push(Watch::HipLow);
    }
    if w_next.hip_ahead_m < 0.0
        && Direction::Falling.triggered(
            w_cur.hip_forward_velocity_m_s,
            w_next.hip_forward_velocity_m_s,
        )
    {
        triggered.push(Watch::HipBack);
    }
    if let Some(r) = &w.ankle() {
        let (a, toe) = (r.ankle.0, r.toe_pitch.0);
        let flat = !active[toe] && !driven;
        if let (true, Some(l0), Some(l1)) = (flat, limit.at(cur.t_s()), limit.at(next.t_s())) {
            if Direction::Falling.triggered(cur.q(a) - l0, next.q(a) - l1) {
                triggered.push(Watch::Engage);
            }
        }
        if active[toe] && Direction::Rising.triggered(cur.q(toe), next.q(toe)) {
            triggered.push(Watch::HeelDrop);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::WitnessValues;

    fn at(t_s: f64, ahead_m: f64, rate_m_s: f64) -> WitnessValues {
        WitnessValues {
            t_s,
            foot_height_m: 0.0,
            foot_height_rate_m_s: 0.0,
            foot_ahead_m: ahead_m,
            foot_ahead_rate_m_s: rate_m_s,
            hip_height_margin_m: 1.0,
            hip_ahead_m: 0.0,
            hip_forward_velocity_m_s: 0.0,
        }
    }

    /// A foot far behind and moving forward (the compass's mid-swing scuff) is a scuff
    /// anywhere in the step; a foot whose distance ahead peaks above `min_ahead` inside the
    /// step (both ends below it, rates of opposite signs) is not, nor is one ending ahead.
    #[test]
    fn a_scuff_anywhere_in_the_step_follows_a_turning_point() {
        let min_ahead = 1e-3;
        assert!(at(0.0, -0.25, 1.5).scuff_anywhere_in_step(&at(0.05, -0.175, 1.5), min_ahead));
        // Ends at 0.5 mm, peak of the Hermite 0.5 mm + h·r/4 = 2.4 mm at mid-step.
        let (a, b) = (at(0.0, 0.5e-3, 0.15), at(0.05, 0.5e-3, -0.15));
        assert!(!a.scuff_anywhere_in_step(&b, min_ahead));
        assert!(!at(0.0, -0.01, 0.5).scuff_anywhere_in_step(&at(0.05, 0.015, 0.5), min_ahead));
        // A zero-length or non-finite step: never.
        assert!(!at(0.1, -0.2, 1.0).scuff_anywhere_in_step(&at(0.1, -0.2, 1.0), min_ahead));
    }
}
