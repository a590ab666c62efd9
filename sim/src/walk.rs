//! Walking many strides from a state, tracking the path on the floor.
//!
//! Every stride is computed in its own stance frame (origin at the stance contact, and for 3D
//! walkers reflected at every step). [`FloorFrame`] composes those frames so that paths are
//! reported in one fixed floor frame.

use crate::control::AnkleController;
use crate::integrators::Sample;
use crate::kinematics::Kinematics;
use crate::math::{rotation_about, sagittal_reflection};
use crate::stride::{FailureKind, StrideEvent, StrideOptions};
use crate::walker::Walker;
use nalgebra::{DVector, Matrix3, Vector3};
use serde::Serialize;

/// The pose of the current stance frame in the fixed floor frame (rotation may be improper).
#[derive(Clone, Debug, PartialEq)]
pub struct FloorFrame {
    /// Stance frame → floor frame (det = ±1).
    pub r: Matrix3<f64>,
    /// Stance-frame origin in the floor frame [m].
    pub p_m: Vector3<f64>,
}

impl Default for FloorFrame {
    fn default() -> Self {
        Self {
            r: Matrix3::identity(),
            p_m: Vector3::zeros(),
        }
    }
}

impl FloorFrame {
    /// Maps a stance-frame point to the floor frame.
    pub fn apply(&self, p_stance_m: &Vector3<f64>) -> Vector3<f64> {
        self.p_m + self.r * p_stance_m
    }

    /// The frame of the next stride. The relabelling maps old stance-frame points `p` to
    /// `R_y(−ψ) S (p − c)` (translate to the new contact `c`, reflect if mirroring, then zero the
    /// heading `ψ`), so a new-frame point `p'` is the old-frame point `c + S R_y(ψ) p'`.
    pub fn next(&self, step_m: &Vector3<f64>, heading_rad: f64, mirror: bool) -> Self {
        let turn = rotation_about(&Vector3::y(), heading_rad);
        let r = if mirror {
            self.r * sagittal_reflection() * turn
        } else {
            self.r * turn
        };
        Self {
            r,
            p_m: self.apply(step_m),
        }
    }
}

/// Summary of one completed step.
#[derive(Clone, Debug, Serialize)]
pub struct StepSummary {
    /// 0-based step number.
    pub step: usize,
    /// Time at the start of the step [s].
    pub start_time_s: f64,
    /// Duration [s].
    pub duration_s: f64,
    /// Distance between the contacts [m].
    pub step_length_m: f64,
    /// Yaw of the new stance foot relative to the old one, in the step's own (mirrored) stance
    /// frame [rad]: for a 3D walker the world heading alternates in sign from step to step, so a
    /// constant value here is a straight zigzag, not a turn.
    pub heading_change_rad: f64,
    /// Hip position in the floor frame at the end of the step [m].
    pub hip_floor_m: [f64; 3],
    /// Largest deviation of the state from the start state of the walk (∞-norm).
    pub state_deviation: f64,
    /// Impact energy loss [J].
    pub impact_energy_loss_j: f64,
    /// Work of the ankle actuator [J].
    pub actuator_work_j: f64,
    /// Right-hand-side evaluations the step cost (event location and impacts included).
    pub evaluations: usize,
    /// Events.
    pub events: Vec<StrideEvent>,
    /// Stride-map state at the end of the step, by name.
    pub state: Vec<(String, f64)>,
}

/// The first failure of a walk.
#[derive(Clone, Debug, Serialize)]
pub struct WalkFailure {
    /// Failure kind.
    pub kind: FailureKind,
    /// 0-based step in which it happened.
    pub step: usize,
    /// Time from the start of the walk [s].
    pub time_s: f64,
    /// Details.
    pub detail: String,
}

/// A sample along the walk, in the floor frame.
#[derive(Clone, Debug)]
pub struct PathSample {
    /// Step number.
    pub step: usize,
    /// Time from the start of the walk [s].
    pub time_s: f64,
    /// Coordinates (stance labelling of that step).
    pub q: DVector<f64>,
    /// Velocities.
    pub qd: DVector<f64>,
    /// Hip in the floor frame [m].
    pub hip_floor_m: Vector3<f64>,
}

/// What a walk keeps.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WalkOptions {
    /// Record the path (every integration sample).
    pub record: bool,
    /// Keep only the summaries of the last this many steps in [`Walk::steps`] (`None`: all).
    /// A long walk (a soak) then runs in bounded memory; [`Walk::steps_completed`] still
    /// counts every step and the per-step callback of [`Walker::walk_streaming`] sees each.
    pub keep_steps: Option<usize>,
}

/// The outcome of a walk.
#[derive(Clone, Debug)]
pub struct Walk {
    /// Steps completed.
    pub steps_completed: usize,
    /// Summaries of the steps completed (the last [`WalkOptions::keep_steps`] of them).
    pub steps: Vec<StepSummary>,
    /// The first failure, if any.
    pub failure: Option<WalkFailure>,
    /// Samples, when recording.
    pub path: Vec<PathSample>,
}

impl Walker {
    /// Walks up to `steps` strides from `q0`, `qd0`; records the path when `record`.
    pub fn walk(&self, q0: &DVector<f64>, qd0: &DVector<f64>, steps: usize, record: bool) -> Walk {
        let options = WalkOptions {
            record,
            keep_steps: None,
        };
        self.walk_streaming(q0, qd0, steps, options, None, &mut |_| {})
    }

    /// As [`Self::walk`], with the stance ankle's string moved by `controller` at its control
    /// ticks (see [`crate::control`]); the controller is told of every heel strike.
    pub fn walk_controlled(
        &self,
        q0: &DVector<f64>,
        qd0: &DVector<f64>,
        steps: usize,
        record: bool,
        controller: &mut dyn AnkleController,
    ) -> Walk {
        let options = WalkOptions {
            record,
            keep_steps: None,
        };
        self.walk_streaming(q0, qd0, steps, options, Some(controller), &mut |_| {})
    }

    /// Walks up to `steps` strides, handing each step's summary to `on_step` as it completes;
    /// with a controller the stance ankle's string is moved by it (as
    /// [`Self::walk_controlled`]). With [`WalkOptions::keep_steps`] and no recording the
    /// memory stays bounded however long the walk.
    pub fn walk_streaming(
        &self,
        q0: &DVector<f64>,
        qd0: &DVector<f64>,
        steps: usize,
        options: WalkOptions,
        mut controller: Option<&mut dyn AnkleController>,
        on_step: &mut dyn FnMut(&StepSummary),
    ) -> Walk {
        let (record, keep_steps) = (options.record, options.keep_steps);
        let mut frame = FloorFrame::default();
        let (mut q, mut qd) = (q0.clone(), qd0.clone());
        let v0 = self.pack(q0, qd0);
        let names = self.map_names();
        let mut kin = Kinematics::new(&self.model);
        let mut out = Walk {
            steps_completed: 0,
            steps: Vec::new(),
            failure: None,
            path: Vec::new(),
        };
        let mut t0 = 0.0;
        let hip = &self.model.points[self.fall.hip.0];
        let mut samples = Vec::new();
        for step in 0..steps {
            samples.clear();
            let options = StrideOptions {
                record,
                contact: false,
            };
            let result = match controller.as_deref_mut() {
                Some(c) => self.stride_controlled(&q, &qd, options, &mut samples, c, t0),
                None => self.stride_recording(&q, &qd, options, &mut samples),
            };
            for s in &samples {
                out.path
                    .push(self.path_sample(&mut kin, &frame, step, t0, s));
            }
            match result {
                Err(f) => {
                    out.failure = Some(WalkFailure {
                        kind: f.kind,
                        step,
                        time_s: t0 + f.time_s,
                        detail: f.detail,
                    });
                    break;
                }
                Ok(r) => {
                    kin.update(&self.model, &r.pre_impact.q, &r.pre_impact.qd);
                    let p_hip = frame.apply(&kin.position_of(hip.link, &hip.p_link_m));
                    let v = self.pack(&r.q_next, &r.qd_next);
                    let summary = StepSummary {
                        step,
                        start_time_s: t0,
                        duration_s: r.duration_s,
                        step_length_m: r.step_m.norm(),
                        heading_change_rad: r.heading_change_rad,
                        hip_floor_m: [p_hip.x, p_hip.y, p_hip.z],
                        state_deviation: (&v - &v0).amax(),
                        impact_energy_loss_j: r.impact_energy_loss_j,
                        actuator_work_j: r.actuator_work_j,
                        evaluations: r.evaluations,
                        events: r.events.clone(),
                        state: names.iter().cloned().zip(v.iter().copied()).collect(),
                    };
                    on_step(&summary);
                    out.steps_completed += 1;
                    out.steps.push(summary);
                    // Bounded: drop the oldest half once twice the kept number accumulate.
                    if let Some(keep) = keep_steps {
                        if out.steps.len() >= 2 * keep.max(1) {
                            out.steps.drain(..out.steps.len() - keep);
                        }
                    }
                    frame = frame.next(&r.step_m, r.heading_change_rad, self.relabel.mirror);
                    t0 += r.duration_s;
                    q = r.q_next;
                    qd = r.qd_next;
                }
            }
        }
        if let Some(keep) = keep_steps {
            let excess = out.steps.len().saturating_sub(keep);
            out.steps.drain(..excess);
        }
        out
    }

    fn path_sample(
        &self,
        kin: &mut Kinematics,
        frame: &FloorFrame,
        step: usize,
        t0: f64,
        s: &Sample,
    ) -> PathSample {
        kin.update(&self.model, &s.q, &s.qd);
        let hip = &self.model.points[self.fall.hip.0];
        PathSample {
            step,
            time_s: t0 + s.t_s,
            q: s.q.clone(),
            qd: s.qd.clone(),
            hip_floor_m: frame.apply(&kin.position_of(hip.link, &hip.p_link_m)),
        }
    }
}
