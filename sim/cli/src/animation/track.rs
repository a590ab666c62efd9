//! The frames of an animation: the walk's recorded samples resampled at a fixed rate of walk
//! time, plus each step's first and last sample (heel strike, the fall), each turned into the
//! floor-frame positions of the figure's key points by the engine's forward kinematics.
//! Stored compactly: positions relative to a moving origin (the hip), quantised to 16 bits.

use super::geometry::Figure;
use nalgebra::{DVector, Vector3};
use serde::Serialize;
use sim::kinematics::Kinematics;
use sim::walk::{FloorFrame, PathSample};
use sim::walker::Walker;

/// Largest quantum of the stored positions [m]: finer wherever the figure allows.
const FINEST_QUANTUM_M: f64 = 1e-4;

/// One frame before encoding.
struct Frame {
    t_walk_s: f64,
    step: usize,
    origin_m: Vector3<f64>,
    points_m: Vec<Vector3<f64>>,
}

/// The encoded frames (little-endian arrays in base64), as the page reads them.
#[derive(Serialize)]
pub struct Track {
    /// Frames.
    pub frames: usize,
    /// Key points per frame.
    pub points: usize,
    /// Walk time of each frame [s] (float32).
    pub t_s: String,
    /// Step of each frame, numbered from 0 (uint16; saturates at 65,535).
    pub step: String,
    /// The moving origin of each frame, the hip in the floor frame [m] (float32, x y z).
    pub origin_m: String,
    /// Key points relative to the origin, in quanta (int16, x y z per point).
    pub rel: String,
    /// The quantum [m].
    pub quantum_m: f64,
}

/// Samples `path` (a recorded walk) at `fps` frames per second of walk time and at each
/// step's first and last sample, and encodes the figure's key points. `None` for an empty
/// path.
pub fn sample(walker: &Walker, figure: &Figure, path: &[PathSample], fps: f64) -> Option<Track> {
    let mut kin = Kinematics::new(&walker.model);
    let hip = &walker.model.points[walker.fall.hip.0];
    let mut frames: Vec<Frame> = Vec::new();
    let mut pose = |q: &DVector<f64>, floor: &FloorFrame, t_walk_s: f64, step: usize| {
        let qd = DVector::zeros(q.len());
        kin.update(&walker.model, q, &qd);
        let points_m = figure
            .points
            .iter()
            .map(|k| floor.apply(&kin.position_of(k.link, &k.p_link_m)))
            .collect();
        Frame {
            t_walk_s,
            step,
            origin_m: floor.apply(&kin.position_of(hip.link, &hip.p_link_m)),
            points_m,
        }
    };
    let dt = 1.0 / fps;
    let mut k: u64 = 0;
    let grid = |k: u64| k as f64 * dt;
    for (i, s) in path.iter().enumerate() {
        let prev = i.checked_sub(1).map(|j| &path[j]);
        let first_of_step = prev.is_none_or(|p| p.step != s.step);
        let last_of_step = path.get(i + 1).is_none_or(|n| n.step != s.step);
        if let (Some(p), false) = (prev, first_of_step) {
            while grid(k) < s.t_walk_s {
                let t = grid(k);
                let span = s.t_walk_s - p.t_walk_s;
                let w = if span > 0.0 {
                    ((t - p.t_walk_s) / span).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                let q = &p.q * (1.0 - w) + &s.q * w;
                frames.push(pose(&q, &s.floor, t, s.step));
                k += 1;
            }
        }
        if first_of_step || last_of_step {
            frames.push(pose(&s.q, &s.floor, s.t_walk_s, s.step));
        }
        while grid(k) <= s.t_walk_s {
            k += 1;
        }
    }
    if frames.is_empty() {
        return None;
    }
    Some(encode(&frames))
}

fn encode(frames: &[Frame]) -> Track {
    let largest_m = frames
        .iter()
        .flat_map(|f| f.points_m.iter().map(move |p| (p - f.origin_m).amax()))
        .fold(0.0, f64::max);
    let quantum_m = FINEST_QUANTUM_M.max(largest_m / f64::from(i16::MAX - 1));
    let mut t = Vec::with_capacity(4 * frames.len());
    let mut step = Vec::with_capacity(2 * frames.len());
    let mut origin = Vec::with_capacity(12 * frames.len());
    let mut rel = Vec::new();
    for f in frames {
        t.extend((f.t_walk_s as f32).to_le_bytes());
        step.extend(u16::try_from(f.step).unwrap_or(u16::MAX).to_le_bytes());
        for x in f.origin_m.iter() {
            origin.extend((*x as f32).to_le_bytes());
        }
        for p in &f.points_m {
            for x in (p - f.origin_m).iter() {
                // Within ±i16::MAX by the choice of the quantum.
                let n = (x / quantum_m).round() as i16;
                rel.extend(n.to_le_bytes());
            }
        }
    }
    Track {
        frames: frames.len(),
        points: frames.first().map_or(0, |f| f.points_m.len()),
        t_s: super::base64::encode(&t),
        step: super::base64::encode(&step),
        origin_m: super::base64::encode(&origin),
        rel: super::base64::encode(&rel),
        quantum_m,
    }
}
