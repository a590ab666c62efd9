//! Scenes: walkers described in TOML files with documented, unit-named parameters.
//!
//! Built-in scenes live in `sim/scenes/` and are compiled in; `--scene` also accepts a path
//! to a scene file of the same schema ([`file::SceneFile`]).

mod build;
mod error;
pub mod expr;
pub mod file;
mod shapes;
pub mod text_file;
mod usage;
pub mod variant;

pub use error::{short_number, SceneError, VariantError};
pub use shapes::Shape;

use crate::analysis::limit_cycle::{Gait, GaitGuess, GaitSearch, NewtonError, NewtonSettings};
use crate::engine::events::Direction;
use crate::engine::model::CoordIndex;
use crate::engine::walker::Walker;
use crate::stride::StrideSettings;
use file::{Num, SceneFile};
use nalgebra::{DVector, Vector3};
use std::collections::{BTreeMap, BTreeSet};

/// The built-in scenes: `(name, TOML text)`.
pub const BUILTIN: &[(&str, &str)] = &[
    ("simplest", include_str!("../../scenes/simplest.toml")),
    ("compass", include_str!("../../scenes/compass.toml")),
    ("kneed2d", include_str!("../../scenes/kneed2d.toml")),
    ("wisse3d", include_str!("../../scenes/wisse3d.toml")),
    ("wisse2d", include_str!("../../scenes/wisse2d.toml")),
    (
        "wisse3d-uncompensated",
        include_str!("../../scenes/wisse3d-uncompensated.toml"),
    ),
    (
        "wisse3d-tuned",
        include_str!("../../scenes/wisse3d-tuned.toml"),
    ),
    (
        "wisse3d-locked-compensator",
        include_str!("../../scenes/wisse3d-locked-compensator.toml"),
    ),
    (
        "wisse2d-tuned",
        include_str!("../../scenes/wisse2d-tuned.toml"),
    ),
    (
        "wisse2d-uncompensated",
        include_str!("../../scenes/wisse2d-uncompensated.toml"),
    ),
];

/// Everything a scene file sets up: the walker's physics, the solver settings of its strides,
/// and a starting guess for its gait.
#[derive(Clone, Debug)]
pub struct Setup {
    /// The walker (model, contact, impact, event and relabelling rules).
    pub walker: Walker,
    /// How its strides are integrated (the scene's `integrator` section).
    pub settings: StrideSettings,
    /// A starting guess for its gait (the scene's `guess` section).
    pub guess: GaitGuess,
}

impl Setup {
    /// Finds the gait from the scene's guess with `newton`.
    ///
    /// # Errors
    /// As [`GaitSearch::find`].
    pub fn find_gait(&self, newton: &NewtonSettings) -> Result<Gait, NewtonError> {
        GaitSearch::new(&self.walker, &self.settings, newton).find_from_guess(&self.guess)
    }

    /// One stride from `gait`'s fixed point with the contact figures on (and every sample
    /// kept when `record`): what a gait report's contact figures (and a joint-angle figure)
    /// are read from. `None` if the stride failed.
    pub fn gait_stride(&self, gait: &Gait, record: bool) -> Option<crate::stride::StrideResult> {
        let (q, qd) = self.walker.unpack(&gait.fixed_point);
        self.walker
            .stride(
                &q,
                &qd,
                crate::stride::StrideRequest::new(&self.settings).options(
                    crate::stride::StrideOptions {
                        record,
                        contact: true,
                        ..crate::stride::StrideOptions::default()
                    },
                ),
            )
            .ok()
    }
}

/// A scene file with its parameter values.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The parsed file.
    pub file: SceneFile,
    /// Current parameter values.
    pub values: BTreeMap<String, f64>,
    /// The built-in scenes this one derives from by `[variant]`, nearest first.
    bases: Vec<String>,
    /// Parameters no expression of the file uses (after its variant is applied): those of
    /// removed or welded bodies. They cannot be changed ([`Self::set`]).
    unused: BTreeSet<String>,
}

/// Largest scene file read \[bytes\] (the built-in scenes are a few kilobytes): a larger one,
/// or a path to a device or FIFO, is refused before it is read.
pub const MAX_SCENE_FILE_BYTES: u64 = 1 << 20;

impl Scene {
    /// Loads a built-in scene by name, or a scene file by path (a regular file of at most
    /// [`MAX_SCENE_FILE_BYTES`]).
    pub fn load(name_or_path: &str) -> Result<Self, SceneError> {
        if let Some((_, text)) = BUILTIN.iter().find(|(n, _)| *n == name_or_path) {
            return Self::parse(name_or_path, text);
        }
        if name_or_path.ends_with(".toml") {
            let text = text_file::read_text_file(
                std::path::Path::new(name_or_path),
                MAX_SCENE_FILE_BYTES,
                "a scene file",
            )
            .map_err(|e| SceneError::File {
                path: name_or_path.to_string(),
                message: e.to_string(),
            })?;
            return Self::parse(name_or_path, &text);
        }
        Err(SceneError::UnknownScene {
            name: name_or_path.to_string(),
            available: BUILTIN
                .iter()
                .map(|(n, _)| *n)
                .collect::<Vec<_>>()
                .join(", "),
        })
    }

    /// Parses scene text; `origin` names it in errors.
    pub fn parse(origin: &str, text: &str) -> Result<Self, SceneError> {
        let (table, bases) = Self::resolve(origin, text, 0)?;
        let file: SceneFile = table
            .try_into()
            .map_err(|e: toml::de::Error| SceneError::File {
                path: origin.to_string(),
                message: e.to_string(),
            })?;
        let values = file
            .parameters
            .iter()
            .map(|(k, p)| (k.clone(), p.default))
            .collect();
        let unused = usage::unused_parameters(&file);
        let scene = Self {
            file,
            values,
            bases,
            unused,
        };
        for (k, p) in &scene.file.parameters {
            for (bound, v) in [("min", p.min), ("max", p.max)] {
                if v.is_some_and(f64::is_nan) {
                    return Err(SceneError::Invalid(format!(
                        "parameter `{k}`: {bound} is NaN"
                    )));
                }
            }
            if let (Some(min), Some(max)) = (p.min, p.max) {
                if min > max {
                    return Err(SceneError::Invalid(format!(
                        "parameter `{k}`: min {} is above max {}",
                        error::short_number(min),
                        error::short_number(max)
                    )));
                }
            }
            scene.check_range(k, p.default)?;
        }
        scene.check_names()?;
        Ok(scene)
    }

    /// Names the file must keep apart: every parameter name and alias names one parameter;
    /// convention outputs are named once; `walk_start_scene` is a built-in scene or a `.toml`
    /// path.
    fn check_names(&self) -> Result<(), SceneError> {
        let mut owner: BTreeMap<&str, &str> = BTreeMap::new();
        for (name, p) in &self.file.parameters {
            for key in std::iter::once(name).chain(&p.aliases) {
                if let Some(other) = owner.insert(key, name) {
                    if other != name {
                        return Err(SceneError::Invalid(format!(
                            "parameter `{name}`: `{key}` already names parameter `{other}`"
                        )));
                    }
                }
            }
        }
        if let Some(conv) = &self.file.convention {
            for (i, o) in conv.outputs.iter().enumerate() {
                if conv.outputs[..i].iter().any(|e| e.name == o.name) {
                    return Err(SceneError::Invalid(format!(
                        "convention output `{}` is named twice",
                        o.name
                    )));
                }
            }
        }
        if let Some(other) = &self.file.walk_start_scene {
            if !other.ends_with(".toml") && !BUILTIN.iter().any(|(n, _)| n == other) {
                return Err(SceneError::Invalid(format!(
                    "walk_start_scene `{other}` is not a built-in scene (nor a .toml path)"
                )));
            }
        }
        Ok(())
    }

    /// Parses text to a TOML table, resolving `[variant] base = ...` (at most 4 deep).
    /// Returns the table and the chain of bases, nearest first.
    fn resolve(
        origin: &str,
        text: &str,
        depth: usize,
    ) -> Result<(toml::Table, Vec<String>), SceneError> {
        let file_err = |message: String| SceneError::File {
            path: origin.to_string(),
            message,
        };
        let table: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| file_err(e.to_string()))?;
        let Some(spec) = variant::VariantDef::of(&table).map_err(|e| file_err(e.to_string()))?
        else {
            return Ok((table, Vec::new()));
        };
        if depth > 4 {
            return Err(file_err("variant chain too deep".into()));
        }
        let base = spec.base;
        let base_text = BUILTIN
            .iter()
            .find(|(n, _)| *n == base)
            .map(|(_, t)| *t)
            .ok_or_else(|| file_err(format!("variant base `{base}` is not a built-in scene")))?;
        let (base_table, mut bases) = Self::resolve(&base, base_text, depth + 1)?;
        let table = variant::apply(&base, base_table, table)?;
        bases.insert(0, base);
        Ok((table, bases))
    }

    /// The scene's name.
    pub fn name(&self) -> &str {
        &self.file.scene.name
    }

    fn canonical(&self, key: &str) -> Option<String> {
        if self.file.parameters.contains_key(key) {
            return Some(key.to_string());
        }
        self.file
            .parameters
            .iter()
            .find(|(_, p)| p.aliases.iter().any(|a| a == key))
            .map(|(k, _)| k.clone())
    }

    fn check_range(&self, name: &str, value: f64) -> Result<(), SceneError> {
        let p = &self.file.parameters[name];
        let (min, max) = (
            p.min.unwrap_or(f64::NEG_INFINITY),
            p.max.unwrap_or(f64::INFINITY),
        );
        if !value.is_finite() {
            return Err(SceneError::NotANumber {
                name: name.into(),
                value: value.to_string(),
            });
        }
        if value < min || value > max {
            return Err(SceneError::OutOfRange {
                name: name.into(),
                value,
                unit: p.unit.clone(),
                min,
                max,
            });
        }
        Ok(())
    }

    /// The canonical name of a parameter given by name or alias.
    pub fn parameter_name(&self, key: &str) -> Result<String, SceneError> {
        self.canonical(key)
            .ok_or_else(|| SceneError::UnknownParameter {
                scene: self.name().to_string(),
                name: key.to_string(),
                available: self
                    .file
                    .parameters
                    .keys()
                    .cloned()
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    }

    /// The built-in scenes this one derives from by `[variant]`, nearest first (empty for a
    /// scene that is not a variant).
    pub fn variant_bases(&self) -> &[String] {
        &self.bases
    }

    /// Whether a parameter (canonical name) is used by no expression of the scene, i.e. acts
    /// on nothing of its walker (a body its variant removed or a joint it welded).
    pub fn is_unused(&self, name: &str) -> bool {
        self.unused.contains(name)
    }

    /// Sets a parameter (by name or alias) to a value, checking its range. A parameter that
    /// acts on nothing of this walker ([`Self::is_unused`]) cannot be changed: setting it to
    /// another value than its current one is an error naming the variant.
    pub fn set(&mut self, key: &str, value: f64) -> Result<(), SceneError> {
        let name = self.parameter_name(key)?;
        if self.unused.contains(&name) && self.values.get(&name) != Some(&value) {
            return Err(SceneError::UnusedParameter {
                scene: self.name().to_string(),
                name,
                variant_of: self.bases.first().cloned(),
            });
        }
        self.check_range(&name, value)?;
        self.values.insert(name, value);
        Ok(())
    }

    /// Sets a parameter from `key=value` text; returns its canonical name.
    pub fn set_text(&mut self, assignment: &str) -> Result<String, SceneError> {
        let (k, v) = assignment
            .split_once('=')
            .ok_or_else(|| SceneError::NotAnAssignment {
                text: assignment.to_string(),
            })?;
        let (k, v) = (k.trim(), v.trim());
        // Name first, so an unknown key is reported as such even with a bad value.
        let name = self.parameter_name(k)?;
        let value: f64 = v.parse().map_err(|_| SceneError::NotANumber {
            name: name.clone(),
            value: v.to_string(),
        })?;
        self.set(&name, value)?;
        Ok(name)
    }

    /// Evaluates a number or expression with the current parameter values.
    pub fn num(&self, n: &Num, what: &str) -> Result<f64, SceneError> {
        let v = match n {
            Num::Value(v) => *v,
            Num::Expr(e) => expr::eval(e, &self.values)?,
        };
        if !v.is_finite() {
            return Err(SceneError::NonFinite {
                what: what.to_string(),
                value: v,
            });
        }
        Ok(v)
    }

    fn vec3(&self, v: &Option<[Num; 3]>, what: &str) -> Result<Vector3<f64>, SceneError> {
        match v {
            None => Ok(Vector3::zeros()),
            Some([a, b, c]) => Ok(Vector3::new(
                self.num(a, what)?,
                self.num(b, what)?,
                self.num(c, what)?,
            )),
        }
    }

    fn opt(&self, n: &Option<Num>, what: &str) -> Result<f64, SceneError> {
        n.as_ref().map_or(Ok(0.0), |n| self.num(n, what))
    }

    /// Checks the `[convention]` section against the built walker: a positive, finite time
    /// scale, finite offsets, and finite coefficients of coordinates the walker has.
    fn check_convention(&self, walker: &Walker) -> Result<(), SceneError> {
        let Some(conv) = &self.file.convention else {
            return Ok(());
        };
        let ts = self.num(&conv.time_scale_s, "convention.time_scale_s")?;
        if ts <= 0.0 {
            return Err(SceneError::Invalid(format!(
                "convention.time_scale_s must be positive, got {ts}"
            )));
        }
        for o in &conv.outputs {
            self.opt(&o.offset, &format!("convention output `{}`.offset", o.name))?;
            for (name, c) in &o.coefficients {
                if walker.model().coord_index(name).is_none() {
                    return Err(SceneError::Invalid(format!(
                        "convention output `{}`: unknown coordinate `{name}`",
                        o.name
                    )));
                }
                if !c.is_finite() {
                    return Err(SceneError::NonFinite {
                        what: format!("convention output `{}`: coefficient of `{name}`", o.name),
                        value: *c,
                    });
                }
            }
        }
        Ok(())
    }

    /// Outputs in the publication's convention for a state (empty if the scene has none).
    pub fn convention_outputs(
        &self,
        walker: &Walker,
        q: &DVector<f64>,
        qd: &DVector<f64>,
    ) -> Result<Vec<(String, f64)>, SceneError> {
        let Some(conv) = &self.file.convention else {
            return Ok(Vec::new());
        };
        let ts = self.num(&conv.time_scale_s, "convention.time_scale_s")?;
        let mut out = Vec::new();
        for o in &conv.outputs {
            let mut v = self.opt(&o.offset, &o.name)?;
            let mut vd = 0.0;
            for (name, c) in &o.coefficients {
                let i: CoordIndex = walker.model().coord_index(name).ok_or_else(|| {
                    SceneError::Invalid(format!("convention output `{}`: unknown `{name}`", o.name))
                })?;
                v += c * q[i.0];
                vd += c * qd[i.0];
            }
            out.push((o.name.clone(), v));
            out.push((format!("{}_dot", o.name), vd * ts));
        }
        Ok(out)
    }
}

fn direction(s: &str) -> Result<Direction, SceneError> {
    match s {
        "rising" => Ok(Direction::Rising),
        "falling" => Ok(Direction::Falling),
        o => Err(SceneError::Invalid(format!(
            "direction `{o}` is not rising or falling"
        ))),
    }
}
