//! Walking many strides from a state, tracking the path on the floor.
//!
//! Every stride is computed in its own stance frame (origin at the stance contact, and for 3D
//! walkers reflected at every step). [`FloorFrame`] composes those frames so that paths are
//! reported in one fixed floor frame.
//!
//! The one entry point is the free function [`walk`] with a [`WalkRequest`] (stride settings,
//! step count, recording, bounded step summaries, controller, per-step callback). Times here
//! are walk time (from the start of the walk); a stride's own times are stride time.

use crate::engine::control::AnkleController;
use crate::engine::integrators::Sample;
use crate::engine::kinematics::Kinematics;
use crate::engine::math::{rotation_about, sagittal_reflection};
use crate::engine::walker::Walker;
use crate::stride::{
    FailureKind, Floor, StrideEvent, StrideOptions, StrideRequest, StrideSettings, StrideWorkspace,
};
use nalgebra::{DVector, Matrix3, Vector3};
use serde::Serialize;

/// The pose of the current stance frame in the fixed floor frame (rotation may be improper).
#[derive(Clone, Debug, PartialEq)]
pub struct FloorFrame {
    /// Stance frame → floor frame (det = ±1).
    pub r: Matrix3<f64>,
    /// Stance-frame origin in the floor frame \[m\].
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
    /// Walk time at the start of the step \[s\] (serialised as `start_time_s`).
    #[serde(rename = "start_time_s")]
    pub start_t_walk_s: f64,
    /// Duration \[s\].
    pub duration_s: f64,
    /// The floor this step landed on, above the one it started from \[m\] (0 on one plane).
    pub floor_step_m: f64,
    /// Distance between the contacts \[m\].
    pub step_length_m: f64,
    /// Yaw of the new stance foot relative to the old one, in the step's own (mirrored) stance
    /// frame \[rad\]: for a 3D walker the world heading alternates in sign from step to step, so a
    /// constant value here is a straight zigzag, not a turn.
    pub heading_change_rad: f64,
    /// Hip position in the floor frame at the end of the step \[m\].
    pub hip_floor_m: [f64; 3],
    /// Largest deviation of the state from the start state of the walk (∞-norm).
    pub state_deviation: f64,
    /// Impact energy loss \[J\].
    pub impact_energy_loss_j: f64,
    /// Work of the ankle actuator \[J\].
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
    /// Time from the start of the walk \[s\] (walk time; serialised as `time_s`).
    #[serde(rename = "time_s")]
    pub t_walk_s: f64,
    /// Details.
    pub detail: String,
}

/// A sample along the walk, in the floor frame.
#[derive(Clone, Debug)]
pub struct PathSample {
    /// Step number.
    pub step: usize,
    /// Time from the start of the walk \[s\] (walk time).
    pub t_walk_s: f64,
    /// Coordinates (stance labelling of that step).
    pub q: DVector<f64>,
    /// Velocities.
    pub qd: DVector<f64>,
    /// Hip in the floor frame \[m\].
    pub hip_floor_m: Vector3<f64>,
    /// The stance frame of its step in the floor frame: maps the sample's link poses
    /// ([`Kinematics`] of `q`) to the floor frame.
    pub floor: FloorFrame,
}

/// What a walk keeps.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WalkOptions {
    /// Record the path in [`Walk::path`]: every integration sample, or with
    /// [`WalkOptions::path_interval_s`] fewer.
    pub record: bool,
    /// Keep in [`Walk::path`] at most one sample per this much walk time \[s\], plus every
    /// step's first and last sample (the impacts stay sharp); `None`: every integration
    /// sample. The recorded path then grows with the walk's duration, not with the
    /// integrator's step (a fixed step of 2e-5 s kept 50,000 samples a second). The samples
    /// given to [`WalkRequest::on_sample`] are never thinned.
    pub path_interval_s: Option<f64>,
    /// Keep only the summaries of the last this many steps in [`Walk::steps`] (`None`: all).
    /// A long walk (a soak) then runs in bounded memory; [`Walk::steps_completed`] still
    /// counts every step and the per-step callback of [`WalkRequest::on_step`] sees each.
    pub keep_steps: Option<usize>,
    /// Keep at most this many samples in [`Walk::path`] (`None`: no bound). Past them the path
    /// stops growing and the walk goes on; [`Walk::path_cut_t_walk_s`] says where the path
    /// stopped. With [`WalkOptions::path_interval_s`] the path still grows with the walk's
    /// duration: this bounds a long walk's memory whatever its length.
    pub max_path_samples: Option<usize>,
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
    /// The walk time of the path's last sample when it reached
    /// [`WalkOptions::max_path_samples`] before the walk ended \[s\]; `None`: the path is whole.
    pub path_cut_t_walk_s: Option<f64>,
}

/// Most steps a caller should ask of one walk (`walker walk --steps`, `walker sil --steps`,
/// `walker.walk` in Python refuse more). Each completed step keeps a summary (a few hundred
/// bytes; `walker sil --keep-steps` bounds them) and takes milliseconds to seconds: 100,000
/// steps is ten times the 10,000-step soak.
pub const MAX_WALK_STEPS: usize = 100_000;

/// Everything a walk is asked to do.
pub struct WalkRequest<'a> {
    /// How each stride is integrated.
    pub settings: &'a StrideSettings,
    /// Strides to walk at most.
    pub steps: usize,
    /// What the walk keeps (path, bounded step summaries).
    pub options: WalkOptions,
    /// The stance ankle's string moved by this controller at its control ticks (see
    /// [`crate::engine::control`]); it is told of every heel strike. `None`: the scene's ideal reflex.
    pub controller: Option<&'a mut dyn AnkleController>,
    /// Called with each step's summary as it completes.
    pub on_step: Option<&'a mut dyn FnMut(&StepSummary)>,
    /// Called with every integration sample, in the floor frame, as its stride completes
    /// (streaming: the walk keeps none of them unless recording).
    pub on_sample: Option<&'a mut dyn FnMut(&PathSample)>,
    /// The floor walked over. Default: one plane.
    pub floor: Floor,
}

impl<'a> WalkRequest<'a> {
    /// Up to `steps` strides with `settings`, keeping every step summary and no path.
    pub fn new(settings: &'a StrideSettings, steps: usize) -> Self {
        Self {
            settings,
            steps,
            options: WalkOptions::default(),
            controller: None,
            on_step: None,
            on_sample: None,
            floor: Floor::Plane,
        }
    }

    /// Recording the path (every integration sample) when `record`.
    pub fn recording(self, record: bool) -> Self {
        let options = WalkOptions {
            record,
            ..self.options
        };
        Self { options, ..self }
    }

    /// Recording at most one sample per `interval_s` of walk time (and every step's first
    /// and last): see [`WalkOptions::path_interval_s`].
    pub fn path_interval(self, interval_s: f64) -> Self {
        let options = WalkOptions {
            path_interval_s: Some(interval_s),
            ..self.options
        };
        Self { options, ..self }
    }

    /// Keeping at most `samples` samples in the path: see [`WalkOptions::max_path_samples`].
    pub fn max_path_samples(self, samples: usize) -> Self {
        let options = WalkOptions {
            max_path_samples: Some(samples),
            ..self.options
        };
        Self { options, ..self }
    }

    /// With `on_sample` called with every integration sample (see
    /// [`WalkRequest::on_sample`]).
    pub fn on_sample(self, on_sample: &'a mut dyn FnMut(&PathSample)) -> Self {
        Self {
            on_sample: Some(on_sample),
            ..self
        }
    }

    /// Over `floor`.
    pub fn floor(self, floor: Floor) -> Self {
        Self { floor, ..self }
    }

    /// With these options.
    pub fn options(self, options: WalkOptions) -> Self {
        Self { options, ..self }
    }

    /// With the stance ankle's string moved by `controller`.
    pub fn controlled(self, controller: &'a mut dyn AnkleController) -> Self {
        Self {
            controller: Some(controller),
            ..self
        }
    }

    /// With `on_step` called with each step's summary.
    pub fn on_step(self, on_step: &'a mut dyn FnMut(&StepSummary)) -> Self {
        Self {
            on_step: Some(on_step),
            ..self
        }
    }
}

/// Walks up to `request.steps` strides of `walker` from `q0`, `qd0` (just after heel strike),
/// as `request` asks. With [`WalkOptions::keep_steps`] and no recording the memory stays
/// bounded however long the walk.
pub fn walk(
    walker: &Walker,
    q0: &DVector<f64>,
    qd0: &DVector<f64>,
    request: WalkRequest<'_>,
) -> Walk {
    let WalkRequest {
        settings,
        steps,
        options,
        mut controller,
        mut on_step,
        mut on_sample,
        floor,
    } = request;
    let mut floor_heights = floor.heights();
    let (record, keep_steps) = (options.record, options.keep_steps);
    let path_interval_s = options.path_interval_s;
    let options_max_path = options.max_path_samples;
    let sampling = record || on_sample.is_some();
    let mut last_kept_s = f64::NEG_INFINITY;
    let mut frame = FloorFrame::default();
    let (mut q, mut qd) = (q0.clone(), qd0.clone());
    let v0 = walker.pack(q0, qd0);
    let names = walker.map_names();
    let mut kin = Kinematics::new(walker.model());
    let mut out = Walk {
        steps_completed: 0,
        steps: Vec::new(),
        failure: None,
        path: Vec::new(),
        path_cut_t_walk_s: None,
    };
    let mut t0 = 0.0;
    let hip = &walker.model().points[walker.fall().hip.0];
    let mut samples = Vec::new();
    let mut workspace = StrideWorkspace::new(walker);
    for step in 0..steps {
        samples.clear();
        let floor_step_m = floor_heights.next_step_m();
        let options = StrideOptions {
            record: sampling,
            contact: false,
            floor_step_m,
        };
        let mut request = StrideRequest::new(settings)
            .options(options)
            .sink(&mut samples);
        if let Some(c) = controller.as_deref_mut() {
            request = request.controlled(c, t0);
        }
        let result = workspace.stride(&q, &qd, request);
        let last = samples.len().saturating_sub(1);
        for (i, s) in samples.iter().enumerate() {
            let t_walk_s = t0 + s.t_s;
            let kept = record
                && (i == 0
                    || i == last
                    || path_interval_s.is_none_or(|dt| t_walk_s - last_kept_s >= dt));
            if !kept && on_sample.is_none() {
                continue;
            }
            let p = path_sample(walker, &mut kin, &frame, step, t0, s);
            if let Some(f) = on_sample.as_deref_mut() {
                f(&p);
            }
            if kept {
                if options_max_path.is_some_and(|m| out.path.len() >= m) {
                    if out.path_cut_t_walk_s.is_none() {
                        out.path_cut_t_walk_s = out.path.last().map(|p| p.t_walk_s);
                    }
                } else {
                    last_kept_s = t_walk_s;
                    out.path.push(p);
                }
            }
        }
        match result {
            Err(f) => {
                out.failure = Some(WalkFailure {
                    kind: f.kind,
                    step,
                    t_walk_s: t0 + f.t_stride_s,
                    detail: f.detail(),
                });
                break;
            }
            Ok(r) => {
                kin.update(walker.model(), &r.pre_impact.q, &r.pre_impact.qd);
                let p_hip = frame.apply(&kin.position_of(hip.link, &hip.p_link_m));
                let v = walker.pack(&r.q_next, &r.qd_next);
                let summary = StepSummary {
                    step,
                    start_t_walk_s: t0,
                    duration_s: r.duration_s,
                    floor_step_m,
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
                if let Some(f) = on_step.as_deref_mut() {
                    f(&summary);
                }
                out.steps_completed += 1;
                out.steps.push(summary);
                if let Some(keep) = keep_steps {
                    trim_to_kept(&mut out.steps, keep);
                }
                frame = frame.next(&r.step_m, r.heading_change_rad, walker.relabel().mirror);
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

/// A stride's sample `s` (stride time) of step `step`, which started at walk time `t0` [s],
/// in the floor frame.
fn path_sample(
    walker: &Walker,
    kin: &mut Kinematics,
    frame: &FloorFrame,
    step: usize,
    t0: f64,
    s: &Sample,
) -> PathSample {
    kin.update(walker.model(), &s.q, &s.qd);
    let hip = &walker.model().points[walker.fall().hip.0];
    PathSample {
        step,
        t_walk_s: t0 + s.t_s,
        q: s.q.clone(),
        qd: s.qd.clone(),
        hip_floor_m: frame.apply(&kin.position_of(hip.link, &hip.p_link_m)),
        floor: frame.clone(),
    }
}

/// Bounded step summaries: once twice the kept number (at least 2) accumulate, the oldest are
/// dropped down to the last `keep`. Amortised O(1) per step; any `keep`, however large, is safe.
fn trim_to_kept<T>(steps: &mut Vec<T>, keep: usize) {
    if steps.len() >= keep.max(1).saturating_mul(2) {
        let drop = steps.len().saturating_sub(keep);
        steps.drain(..drop);
    }
}

#[cfg(test)]
mod trim_tests {
    use super::trim_to_kept;

    #[test]
    fn trimming_keeps_the_last_and_survives_any_keep() {
        let mut v: Vec<u32> = (0..10).collect();
        trim_to_kept(&mut v, 3);
        assert_eq!(v, vec![7, 8, 9]);
        let mut v: Vec<u32> = (0..5).collect();
        trim_to_kept(&mut v, 3);
        assert_eq!(v.len(), 5, "under twice the kept number nothing is dropped");
        // `2 * keep` wrapped to 2 for this `keep` (also in release builds) and the drain
        // panicked; `usize::MAX` overflowed in debug builds.
        for keep in [usize::MAX / 2 + 1, usize::MAX] {
            let mut v: Vec<u32> = (0..3).collect();
            trim_to_kept(&mut v, keep);
            assert_eq!(v, vec![0, 1, 2]);
        }
    }
}
