//! The frames of an animation: the walk's recorded samples resampled at a fixed rate of walk
//! time, plus each step's first and last sample (heel strike, the fall), each turned into the
//! floor-frame positions of the figure's key points by the engine's forward kinematics.
//! Stored compactly: each distinct point once (key points that coincide in every frame, such
//! as the ends of two rods meeting at a joint, share one), positions relative to a moving
//! origin (the hip), quantised to 16 bits. Every event has a frame at its instant and a heel
//! strike is two frames at the same time (before and after), so the page may interpolate
//! between two successive frames of different times and one step without blurring an impact.

use super::geometry::Figure;
use nalgebra::{DVector, Vector3};
use serde::Serialize;
use sim::engine::kinematics::Kinematics;
use sim::engine::walker::Walker;
use sim::stride::walk::{FloorFrame, PathSample};

/// Largest quantum of the stored positions \[m\]: finer wherever the figure allows.
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
    /// Stored points per frame (distinct key points).
    pub points: usize,
    /// For each key point of the figure ([`Figure::points`], as the parts index them), the
    /// stored point it is.
    pub point_of: Vec<usize>,
    /// Walk time of each frame \[s\] (float32).
    pub t_s: String,
    /// Step of each frame as people number it, from 1 ([`crate::labels::step_number`];
    /// uint16, saturates at 65,535): the page shows it as it is.
    pub step_number: String,
    /// The moving origin of each frame, the hip in the floor frame \[m\] (float32, x y z).
    pub origin_m: String,
    /// Key points relative to the origin, in quanta (int16, x y z per point).
    pub rel: String,
    /// The quantum \[m\].
    pub quantum_m: f64,
}

/// Samples `path` (a recorded walk) at `fps` frames per second of walk time, at each step's
/// first and last sample and at the walk times `instants_s` (events; sorted), and encodes the
/// figure's key points. `None` for an empty path.
pub fn sample(
    walker: &Walker,
    figure: &Figure,
    path: &[PathSample],
    fps: f64,
    instants_s: &[f64],
) -> Option<Track> {
    let frames = frames(walker, figure, path, fps, instants_s);
    if frames.is_empty() {
        return None;
    }
    Some(encode(&frames))
}

/// The frames of [`sample`], before encoding.
fn frames(
    walker: &Walker,
    figure: &Figure,
    path: &[PathSample],
    fps: f64,
    instants_s: &[f64],
) -> Vec<Frame> {
    let mut kin = Kinematics::new(walker.model());
    let hip = &walker.model().points[walker.fall().hip.0];
    let mut frames: Vec<Frame> = Vec::new();
    let mut pose = |q: &DVector<f64>, floor: &FloorFrame, t_walk_s: f64, step: usize| {
        let qd = DVector::zeros(q.len());
        kin.update(walker.model(), q, &qd);
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
    let (mut k, mut e): (u64, usize) = (0, 0);
    let grid = |k: u64| k as f64 * dt;
    let instant = |e: usize| instants_s.get(e).copied().unwrap_or(f64::INFINITY);
    for (i, s) in path.iter().enumerate() {
        let prev = i.checked_sub(1).map(|j| &path[j]);
        let first_of_step = prev.is_none_or(|p| p.step != s.step);
        let last_of_step = path.get(i + 1).is_none_or(|n| n.step != s.step);
        if let (Some(p), false) = (prev, first_of_step) {
            // The next grid time before this sample, or the next instant up to it (one at a
            // step's last sample is that sample's own frame, below).
            let until_s = |t: f64| t < s.t_walk_s || (t == s.t_walk_s && !last_of_step);
            while grid(k) < s.t_walk_s || until_s(instant(e)) {
                let t = grid(k).min(instant(e));
                let span = s.t_walk_s - p.t_walk_s;
                let w = if span > 0.0 {
                    ((t - p.t_walk_s) / span).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                let q = &p.q * (1.0 - w) + &s.q * w;
                frames.push(pose(&q, &s.floor, t, s.step));
                if grid(k) <= t {
                    k += 1;
                }
                if instant(e) <= t {
                    e += 1;
                }
            }
        }
        if first_of_step || last_of_step {
            frames.push(pose(&s.q, &s.floor, s.t_walk_s, s.step));
        }
        while grid(k) <= s.t_walk_s {
            k += 1;
        }
        while instant(e) <= s.t_walk_s {
            e += 1;
        }
    }
    frames
}

/// Largest distance between two key points that are one stored point \[m\].
const SAME_POINT_M: f64 = 1e-9;

/// For each key point the index of its stored point, and for each stored point the key point
/// it is stored as: key points within [`SAME_POINT_M`] of an earlier one in every frame are
/// that one.
fn distinct_points(frames: &[Frame]) -> (Vec<usize>, Vec<usize>) {
    let count = frames.first().map_or(0, |f| f.points_m.len());
    let mut point_of = Vec::with_capacity(count);
    let mut stored: Vec<usize> = Vec::new();
    for k in 0..count {
        let same = stored.iter().position(|&j| {
            frames
                .iter()
                .all(|f| (f.points_m[j] - f.points_m[k]).amax() <= SAME_POINT_M)
        });
        match same {
            Some(i) => point_of.push(i),
            None => {
                point_of.push(stored.len());
                stored.push(k);
            }
        }
    }
    (point_of, stored)
}

fn encode(frames: &[Frame]) -> Track {
    let (point_of, stored) = distinct_points(frames);
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
        let number = crate::labels::step_number(f.step);
        step.extend(u16::try_from(number).unwrap_or(u16::MAX).to_le_bytes());
        for x in f.origin_m.iter() {
            origin.extend((*x as f32).to_le_bytes());
        }
        for p in stored.iter().map(|&k| &f.points_m[k]) {
            for x in (p - f.origin_m).iter() {
                // Within ±i16::MAX by the choice of the quantum.
                let n = (x / quantum_m).round() as i16;
                rel.extend(n.to_le_bytes());
            }
        }
    }
    Track {
        frames: frames.len(),
        points: stored.len(),
        point_of,
        t_s: super::base64::encode(&t),
        step_number: super::base64::encode(&step),
        origin_m: super::base64::encode(&origin),
        rel: super::base64::encode(&rel),
        quantum_m,
    }
}

#[cfg(test)]
mod tests {
    use super::super::geometry::Part;
    use super::*;
    use sim::scene::Scene;
    use sim::stride::walk::{walk, WalkRequest};

    /// A recorded walk of `steps` steps of `scene` from its gait, with its figure's frames.
    fn walked(
        scene: &str,
        steps: usize,
    ) -> (Scene, Walker, sim::stride::walk::Walk, Figure, Vec<Frame>) {
        let scene = Scene::load(scene).unwrap();
        let setup = scene.setup().unwrap();
        let gait = setup.find_gait(&Default::default()).unwrap();
        let (q, qd) = setup.walker.unpack(&gait.fixed_point);
        let w = walk(
            &setup.walker,
            &q,
            &qd,
            WalkRequest::new(&setup.settings, steps).recording(true),
        );
        let figure = Figure::of(&scene, setup.walker.model()).unwrap();
        let instants: Vec<f64> = super::super::timeline::walk_events(&w)
            .iter()
            .map(|e| e.t_s)
            .collect();
        let f = frames(&setup.walker, &figure, &w.path, 30.0, &instants);
        (scene, setup.walker, w, figure, f)
    }

    fn key(figure: &Figure, walker: &Walker, point: &str) -> usize {
        let p = &walker.model().points[walker.model().point_index(point).unwrap().0];
        figure
            .points
            .iter()
            .position(|k| k.link == p.link && (k.p_link_m - p.p_link_m).norm() < 1e-12)
            .unwrap()
    }

    #[test]
    fn compass_frames_keep_the_legs_and_land_each_foot_on_the_floor() {
        let (scene, walker, w, figure, f) = walked("compass", 4);
        assert_eq!(w.steps_completed, 4);
        let leg = scene.values["leg_length_m"];
        let (stance, swing, hip) = (
            key(&figure, &walker, "stance_foot"),
            key(&figure, &walker, "swing_foot"),
            key(&figure, &walker, "hip"),
        );
        // Time runs forward at 30 frames per second at least, from 0 to the walk's end.
        assert_eq!(f[0].t_walk_s, 0.0);
        let end = w.path.last().unwrap().t_walk_s;
        assert_eq!(f.last().unwrap().t_walk_s, end);
        assert!(f.len() as f64 >= 30.0 * end);
        for pair in f.windows(2) {
            assert!(pair[1].t_walk_s >= pair[0].t_walk_s);
            assert!(pair[1].t_walk_s - pair[0].t_walk_s <= 1.0 / 30.0 + 1e-12);
        }
        for fr in &f {
            // The true leg length in every frame, interpolated ones included.
            for foot in [stance, swing] {
                let l = (fr.points_m[hip] - fr.points_m[foot]).norm();
                assert!((l - leg).abs() < 1e-9, "leg {l} m at t = {}", fr.t_walk_s);
            }
            // The stance foot stays on the floor (slope frame: y = 0).
            assert!(fr.points_m[stance].y.abs() < 1e-9);
        }
        // At each heel strike the swing foot is on the floor and becomes the next stance foot
        // at the same place: the floor frames compose.
        for pair in f.windows(2) {
            if pair[1].step == pair[0].step + 1 {
                let (a, b) = (&pair[0], &pair[1]);
                assert_eq!(a.t_walk_s, b.t_walk_s);
                assert!(a.points_m[swing].y.abs() < 1e-7, "{}", a.points_m[swing].y);
                assert!((a.points_m[swing] - b.points_m[stance]).norm() < 1e-7);
                assert!((a.points_m[hip] - b.points_m[hip]).norm() < 1e-7);
            }
        }
        // The walker walks forward, down the slope.
        assert!(f.last().unwrap().origin_m.x > 0.5);
    }

    #[test]
    fn wisse3d_parts_have_the_scene_dimensions_and_encoding_keeps_them() {
        let (scene, _walker, w, figure, f) = walked("wisse3d", 2);
        // A frame at each event (knee lock, string engagement, heel strike).
        let events = super::super::timeline::walk_events(&w);
        assert!(events.iter().any(|e| e.kind == "knee_lock"));
        for ev in &events {
            assert!(
                f.iter().any(|fr| (fr.t_walk_s - ev.t_s).abs() < 1e-12),
                "no frame at {} s ({})",
                ev.t_s,
                ev.text
            );
        }
        let v = |k: &str| scene.values[k];
        let rod = |name: &str| {
            figure
                .parts
                .iter()
                .find_map(|p| match p {
                    Part::Rod { name: n, a, b, .. } if n == name => Some((*a, *b)),
                    _ => None,
                })
                .unwrap()
        };
        let length = |name: &str, fr: &Frame| {
            let (a, b) = rod(name);
            (fr.points_m[a] - fr.points_m[b]).norm()
        };
        let track = encode(&f);
        // Shared rod ends (knees, hip, ankles) stored once.
        assert_eq!(track.point_of.len(), figure.points.len());
        assert!(
            track.points < figure.points.len(),
            "{} stored of {}",
            track.points,
            figure.points.len()
        );
        let rel = decode_i16(&track.rel);
        assert_eq!(rel.len(), 3 * f.len() * track.points);
        for (i, fr) in f.iter().enumerate() {
            assert!((length("hip axle", fr) - v("hip_width_m")).abs() < 1e-9);
            assert!((length("swing shank", fr) - v("shank_length_m")).abs() < 1e-9);
            assert!((length("stance foot", fr) - v("foot_length_m")).abs() < 1e-9);
            // Decoded positions within half a quantum (and float32 rounding of the origin).
            for (k, p) in fr.points_m.iter().enumerate() {
                for c in 0..3 {
                    let j = track.point_of[k];
                    let got = f64::from(rel[3 * (i * track.points + j) + c]) * track.quantum_m
                        + fr.origin_m[c];
                    assert!((got - p[c]).abs() <= 0.5 * track.quantum_m + 1e-6);
                }
            }
        }
        assert!(figure.parts.iter().any(|p| matches!(p,
            Part::Ring { radius_m, .. } if *radius_m == v("pelvic_ring_radius_m"))));
    }

    /// The inverse of the encoder's base64 of little-endian int16s.
    fn decode_i16(b64: &str) -> Vec<i16> {
        let alphabet = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        let mut bytes = Vec::new();
        for chunk in b64.as_bytes().chunks(4) {
            let mut n = 0u32;
            let mut valid = 0;
            for &c in chunk {
                n <<= 6;
                if c != b'=' {
                    n |= alphabet.iter().position(|&a| a == c).unwrap() as u32;
                    valid += 1;
                }
            }
            bytes.extend(&n.to_be_bytes()[1..valid]);
        }
        bytes
            .chunks(2)
            .map(|b| i16::from_le_bytes([b[0], b[1]]))
            .collect()
    }
}
