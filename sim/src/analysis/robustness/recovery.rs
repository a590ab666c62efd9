//! The one loop of the robustness measures: strides from a (disturbed) state just after heel
//! strike, each ending on the floor a closure gives, until the walker is back on its gait,
//! settles on another periodic motion, falls, or runs out of strides.
//!
//! "Back on the gait" is the rule: the stride-map state after a stride within
//! [`ReturnRule::tolerance`] of the gait's fixed point in the ∞-norm (positions and rates of
//! every map coordinate, in their own units), inside [`ReturnRule::max_strides`] strides.

use crate::analysis::limit_cycle::Gait;
use crate::engine::kinematics::Kinematics;
use crate::engine::walker::Walker;
use crate::stride::{FailureKind, StrideRequest, StrideSettings, StrideWorkspace};
use nalgebra::DVector;
use serde::Serialize;
use std::collections::VecDeque;

/// When a walker counts as back on its gait.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ReturnRule {
    /// ∞-norm distance of the stride-map state from the fixed point that counts as returned.
    pub tolerance: f64,
    /// Strides it may take.
    pub max_strides: usize,
}

impl Default for ReturnRule {
    /// The rule: within 1e-6 inside 100 strides.
    fn default() -> Self {
        Self {
            tolerance: 1e-6,
            max_strides: 100,
        }
    }
}

/// Longest period of another periodic motion recognised (strides).
pub const MAX_PERIOD: usize = 8;

/// Another periodic motion repeats within this fraction of its distance from the gait (and
/// within the tolerance): a walk still returning slowly to the gait moves more per stride.
pub const REPEAT_FRACTION: f64 = 1e-3;

/// How strides from a disturbed state ended.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "outcome", rename_all = "snake_case")]
pub enum Outcome {
    /// Back on the gait after `strides` strides.
    Gait {
        /// Strides taken.
        strides: usize,
    },
    /// Not back on the gait after every stride allowed (`strides`), but on another periodic
    /// motion of `period` strides (a period-1 one is another gait): the last state `x_K`
    /// within the tolerance of `x_{K−period}`, and within [`REPEAT_FRACTION`] of its distance
    /// from the gait; the smallest such period.
    Periodic {
        /// Its period in strides (1 to [`MAX_PERIOD`]).
        period: usize,
        /// Strides taken.
        strides: usize,
    },
    /// Stride `strides` failed (fell, or a numerical failure: the kind says which).
    Failed {
        /// How.
        kind: FailureKind,
        /// The stride that failed (counted from 1).
        strides: usize,
    },
    /// Neither within the strides allowed.
    NotSettled {
        /// Strides taken.
        strides: usize,
    },
}

impl Outcome {
    /// Whether the walker came back to its gait.
    pub fn returned(&self) -> bool {
        matches!(self, Outcome::Gait { .. })
    }

    /// Strides taken (to the return, the settling, the failing stride, or all allowed).
    pub fn strides(&self) -> usize {
        match *self {
            Outcome::Gait { strides }
            | Outcome::Periodic { strides, .. }
            | Outcome::Failed { strides, .. }
            | Outcome::NotSettled { strides } => strides,
        }
    }

    /// The outcome's name as reports give it: `gait`, `periodic`, the failure kind
    /// (`fell_forward`, `fell_backward`, ...), or `not_settled`.
    pub fn name(&self) -> String {
        match self {
            Outcome::Gait { .. } => "gait".into(),
            Outcome::Periodic { .. } => "periodic".into(),
            Outcome::NotSettled { .. } => "not_settled".into(),
            Outcome::Failed { kind, .. } => serde_json::to_value(kind)
                .ok()
                .and_then(|v| v.as_str().map(str::to_owned))
                .unwrap_or_else(|| format!("{kind:?}")),
        }
    }
}

/// Until when [`Recovery::follow`] strides.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Until {
    /// Back on the gait, or every stride taken (then judged periodic or not), or failed.
    Settled,
    /// A failure only (a Monte Carlo walk on a rough floor): every stride allowed is taken.
    Failure,
}

/// A gait and the rule for returning to it: what every robustness measure strides from.
pub struct Recovery<'a> {
    /// The walker.
    pub walker: &'a Walker,
    /// Its stride settings.
    pub settings: &'a StrideSettings,
    /// The gait's fixed point (stride-map vector, just after heel strike).
    pub fixed_point: &'a DVector<f64>,
    /// When it counts as back.
    pub rule: ReturnRule,
}

impl<'a> Recovery<'a> {
    /// Recovery to `gait` under the rule ([`ReturnRule::default`]).
    pub fn new(walker: &'a Walker, settings: &'a StrideSettings, gait: &'a Gait) -> Self {
        Self {
            walker,
            settings,
            fixed_point: &gait.fixed_point,
            rule: ReturnRule::default(),
        }
    }

    /// With `rule`.
    pub fn with_rule(self, rule: ReturnRule) -> Self {
        Self { rule, ..self }
    }

    /// Strides from `x0` (stride-map vector), stride `k` (from 1) ending on the floor
    /// `floor_step_m(k)` above its stance foot's, until `until`, at most
    /// [`ReturnRule::max_strides`] strides, on `ws` (a workspace of this walker).
    pub fn follow(
        &self,
        ws: &mut StrideWorkspace<'_>,
        x0: &DVector<f64>,
        floor_step_m: &mut dyn FnMut(usize) -> f64,
        until: Until,
    ) -> Outcome {
        let mut x = x0.clone();
        // The last states x_{k−MAX_PERIOD} ..= x_k (x_0 the start), newest last, for
        // recognising another periodic motion once every stride is taken.
        let mut recent: VecDeque<DVector<f64>> = VecDeque::with_capacity(MAX_PERIOD + 1);
        recent.push_back(x.clone());
        for k in 1..=self.rule.max_strides {
            let (q, qd) = self.walker.unpack(&x);
            let request = StrideRequest::new(self.settings).floor_step(floor_step_m(k));
            match ws.stride(&q, &qd, request) {
                Err(f) => {
                    return Outcome::Failed {
                        kind: f.kind,
                        strides: k,
                    }
                }
                Ok(r) => x = self.walker.pack(&r.q_next, &r.qd_next),
            }
            if !x.iter().all(|v| v.is_finite()) {
                return Outcome::Failed {
                    kind: FailureKind::NonFiniteState,
                    strides: k,
                };
            }
            if until == Until::Settled && distance_inf(&x, self.fixed_point) <= self.rule.tolerance
            {
                return Outcome::Gait { strides: k };
            }
            if recent.len() == MAX_PERIOD + 1 {
                recent.pop_front();
            }
            recent.push_back(x.clone());
        }
        let strides = self.rule.max_strides;
        if until == Until::Failure {
            return Outcome::NotSettled { strides };
        }
        // x_K against x_{K−p}, p = 1..: judged only after every stride (a walk that spirals
        // into the gait repeats itself closely on the way)
        let last = recent.len() - 1;
        let x_last = &recent[last];
        // ... and within a thousandth of its distance from the gait: a slow return
        // (`|λ|` near 1) moves a hundredth of that distance or more per stride
        let within = self
            .rule
            .tolerance
            .min(REPEAT_FRACTION * distance_inf(x_last, self.fixed_point));
        (1..=last.min(MAX_PERIOD))
            .find(|&p| distance_inf(x_last, &recent[last - p]) <= within)
            .map_or(Outcome::NotSettled { strides }, |period| {
                Outcome::Periodic { period, strides }
            })
    }

    /// The walker's leg length for scaling tolerances: the distance from the stance contact
    /// point to the hip point (the fall rule's) at the fixed point \[m\].
    pub fn leg_length_m(&self) -> f64 {
        let model = self.walker.model();
        let (q, qd) = self.walker.unpack(self.fixed_point);
        let mut kin = Kinematics::new(model);
        kin.update(model, &q, &qd);
        let at = |i: crate::engine::model::PointIndex| {
            let p = &model.points[i.0];
            kin.position_of(p.link, &p.p_link_m)
        };
        (at(self.walker.fall().hip) - at(self.walker.heel_strike().stance_contact)).norm()
    }

    /// The walker's natural rate `sqrt(g / L)` \[1/s\] (`g` the gravity's magnitude, `L` the
    /// leg length): the scale of rate perturbations.
    pub fn natural_rate_1_s(&self) -> f64 {
        let g = self.walker.model().gravity_floor_m_s2.norm();
        (g / self.leg_length_m()).sqrt()
    }
}

/// ∞-norm of `a − b`.
pub fn distance_inf(a: &DVector<f64>, b: &DVector<f64>) -> f64 {
    a.iter()
        .zip(b.iter())
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}
