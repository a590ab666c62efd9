//! `walker walk|gait|sil … --animate FILE.html`: a self-contained HTML page that plays the
//! walk in 3D in a browser (three.js inlined; no network when viewed). The binary computes
//! every drawn point's floor-frame position per frame with the engine's forward kinematics
//! ([`track`]); the page only draws ([`page`]). docs/animation.md.

mod base64;
pub mod geometry;
mod page;
pub mod timeline;
pub mod track;

use crate::labels;
use crate::output::PathError;
use serde::Serialize;
use sim::engine::walker::Walker;
use sim::scene::{Scene, SceneError};
use sim::stride::walk::Walk;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The most steps a page animates: about 9 kB of page per step of `wisse3d`.
pub const MAX_ANIMATED_STEPS: usize = 2_000;

/// Frames per second of walk time.
pub const FRAMES_PER_S: f64 = 30.0;

/// The walk behind a page or a floor-path figure keeps at most one sample per this much walk
/// time (four per frame; every step's first and last sample besides), so its memory follows
/// the walk's duration, not the integrator's step (a 2,000-step walk at a fixed step of
/// 1e-4 s kept 20 GB of samples for a 12 MB page).
pub const PATH_SAMPLE_INTERVAL_S: f64 = 1.0 / (4.0 * FRAMES_PER_S);

/// The page's file, opened before the run so that a path that cannot be written fails at once
/// (exit code 1, naming `--animate` and the path).
pub struct AnimationFile {
    path: PathBuf,
    file: std::fs::File,
}

impl AnimationFile {
    /// Creates (truncates) `path`.
    pub fn create(path: &Path) -> Result<Self, PathError> {
        let file = std::fs::File::create(path).map_err(|e| PathError::new("--animate", path, e))?;
        Ok(Self {
            path: path.to_path_buf(),
            file,
        })
    }

    /// Removes the file (nothing to animate: no gait found); a file that cannot be removed
    /// stays, empty.
    pub fn discard(self) {
        drop(self.file);
        let _ = std::fs::remove_file(&self.path);
    }

    /// Writes the page of `animation`.
    pub fn write(self, animation: &Animation<'_>) -> anyhow::Result<()> {
        let html = animation.html()?;
        let mut w = std::io::BufWriter::new(self.file);
        w.write_all(html.as_bytes())
            .and_then(|()| w.flush())
            .map_err(|e| PathError::new("--animate", &self.path, e))?;
        Ok(())
    }
}

/// What a page shows: a recorded walk of a scene's walker, and its events.
pub struct Animation<'a> {
    /// The scene (its shapes and name).
    pub scene: &'a Scene,
    /// The walker that walked.
    pub walker: &'a Walker,
    /// The walk, recorded (`WalkRequest::recording(true)`).
    pub walk: &'a Walk,
    /// The command that made it, for the title (`walk`, `gait`, `sil`).
    pub command: &'static str,
    /// The events shown as they happen.
    pub events: Vec<timeline::Event>,
    /// The firmware was in the loop (the page shows the ankle nodes).
    pub firmware: bool,
    /// Walk time the host sent the emergency stop \[s\] (`None`: none sent).
    pub emergency_stop_sent_s: Option<f64>,
}

/// The page's data.
#[derive(Serialize)]
struct PageData<'a> {
    format: u32,
    title: &'a str,
    scene: &'a str,
    command: &'a str,
    firmware: bool,
    /// Walk time the host sent the emergency stop \[s\] (`null`: none sent).
    emergency_stop_sent_s: Option<f64>,
    /// The emergency stop in words (empty: none sent), for the banner.
    emergency_stop_text: String,
    /// Turn of the floor frame about its z axis that makes gravity point down \[rad\].
    world_rotation_z_rad: f64,
    /// Floor grid spacing \[m\].
    grid_m: f64,
    /// Radius of the sphere drawn for 1 kg \[m\].
    mass_sphere_m: f64,
    parts: &'a [geometry::Part],
    /// The floor's levels under each step where a floor steps up or down (`walker walk
    /// --floor`); absent on one plane.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    floor_levels: Vec<Terrace>,
    track: track::Track,
    events: &'a [timeline::Event],
}

impl Animation<'_> {
    /// The title: the walker by name (as the figures name it), what it did, and how the walk
    /// ended: "then the fall" for a fall, "then simulation ended: `<reason in words>`" for any
    /// other failure; an emergency stop is named with its time. A gait's page counts steps,
    /// as its clock does.
    pub fn title(&self) -> String {
        let n = self.walk.steps_completed;
        let steps = format!("{n} step{}", if n == 1 { "" } else { "s" });
        let what = match (self.command, self.firmware) {
            ("gait", _) => format!("{steps} of its gait"),
            (_, true) => format!("{steps}, firmware in the loop"),
            (_, false) => steps,
        };
        let stop = self.emergency_stop_sent_s.map_or_else(String::new, |t| {
            format!(", {}", labels::emergency_stop_label(t))
        });
        let end = match &self.walk.failure {
            None => String::new(),
            Some(f) if labels::is_fall(f.kind) => ", then the fall".into(),
            Some(f) => format!(", then {}", labels::walk_end_label(f.kind)),
        };
        format!("{}: {what}{stop}{end}", labels::walker_name(self.scene))
    }

    /// The page.
    pub fn html(&self) -> Result<String, AnimationError> {
        let figure = geometry::Figure::of(self.scene, self.walker.model())?;
        let mut instants: Vec<f64> = self.events.iter().map(|e| e.t_s).collect();
        instants.sort_by(f64::total_cmp);
        let track = track::sample(
            self.walker,
            &figure,
            &self.walk.path,
            FRAMES_PER_S,
            &instants,
        )
        .ok_or(AnimationError::NothingRecorded)?;
        let g = self.walker.model().gravity_floor_m_s2;
        let title = self.title();
        let data = PageData {
            format: 1,
            title: &title,
            scene: self.scene.name(),
            command: self.command,
            firmware: self.firmware,
            emergency_stop_sent_s: self.emergency_stop_sent_s,
            emergency_stop_text: self
                .emergency_stop_sent_s
                .map_or_else(String::new, labels::emergency_stop_label),
            // Rz(θ) g points along −y: θ = −atan2(g_x, −g_y) (−slope for a slope's gravity).
            world_rotation_z_rad: -g.x.atan2(-g.y),
            grid_m: 0.25,
            mass_sphere_m: 0.04,
            parts: &figure.parts,
            floor_levels: terraces(self.walk),
            track,
            events: &self.events,
        };
        let json = serde_json::to_string(&data).map_err(AnimationError::Json)?;
        Ok(page::html(&title, &json))
    }
}

/// The floor under one step, in the floor frame: the stance foot's level from halfway back
/// to the previous stance foot to halfway on to the next (the model meets the floor only at
/// the feet, so where between them the level changes is a drawing's choice).
#[derive(Clone, Debug, PartialEq, Serialize)]
struct Terrace {
    /// The step as people number it (from 1, as the page's frames).
    step: usize,
    /// Along the walk (floor frame's x) \[m\].
    x_from_m: f64,
    /// \[m\]
    x_to_m: f64,
    /// The level along the floor's normal (floor frame's y) \[m\].
    y_m: f64,
}

/// The terraces under a walk's steps: each step's level the sum of the floor steps landed on
/// before it, from its stance frame's origin (in the floor frame) halfway to its neighbours';
/// none when every step is on one plane.
fn terraces(walk: &sim::stride::walk::Walk) -> Vec<Terrace> {
    if walk.steps.iter().all(|s| s.floor_step_m == 0.0) {
        return Vec::new();
    }
    let mut origins: Vec<(usize, f64)> = Vec::new();
    for s in &walk.path {
        if origins.last().is_none_or(|(k, _)| *k != s.step) {
            origins.push((s.step, s.floor.p_m.x));
        }
    }
    let x: Vec<f64> = origins.iter().map(|(_, x)| *x).collect();
    // a step's length to extend the first and the last terrace by
    let reach = x
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.5f64, f64::max);
    let level = |step: usize| -> f64 {
        walk.steps
            .iter()
            .filter(|s| s.step < step)
            .map(|s| s.floor_step_m)
            .sum()
    };
    origins
        .iter()
        .enumerate()
        .map(|(i, (step, _))| Terrace {
            step: labels::step_number(*step),
            x_from_m: if i == 0 {
                x[0] - 2.0 * reach
            } else {
                0.5 * (x[i - 1] + x[i])
            },
            x_to_m: x
                .get(i + 1)
                .map_or(x[i] + 4.0 * reach, |next| 0.5 * (x[i] + next)),
            y_m: level(*step),
        })
        .collect()
}

/// Why a page could not be made.
#[derive(Debug, thiserror::Error)]
pub enum AnimationError {
    /// The scene's shapes are invalid.
    #[error("--animate: {0}")]
    Scene(#[from] SceneError),
    /// The walk recorded no sample (zero steps asked).
    #[error("--animate: the walk recorded nothing to animate (ask for at least one step)")]
    NothingRecorded,
    /// The data could not be serialised (a non-finite number).
    #[error("--animate: {0}")]
    Json(#[source] serde_json::Error),
}

/// The page file of `--animate PATH` for a run of `steps` steps, created now; `None` without
/// the option. Zero steps leave nothing to animate, more than [`MAX_ANIMATED_STEPS`] make too
/// big a page: bad input.
pub fn open(path: Option<&Path>, steps: usize) -> anyhow::Result<Option<AnimationFile>> {
    let Some(path) = path else {
        return Ok(None);
    };
    if steps == 0 || steps > MAX_ANIMATED_STEPS {
        return Err(crate::input_error::InputError::Other(format!(
            "--animate needs 1 to {MAX_ANIMATED_STEPS} steps (the page holds every frame; \
             the walk records every sample), got --steps {steps}"
        ))
        .into());
    }
    Ok(Some(AnimationFile::create(path)?))
}
