//! The `walker scenes` report: the built-in scenes and their parameters.

use crate::scene::{Scene, SceneError, BUILTIN};
use serde::Serialize;

/// The `walker scenes --json` object.
#[derive(Clone, Debug, Serialize)]
pub struct SceneCatalogue {
    /// The built-in scenes, in their listing order.
    pub scenes: Vec<SceneEntry>,
}

/// One scene.
#[derive(Clone, Debug, Serialize)]
pub struct SceneEntry {
    /// Name used on the command line.
    pub name: String,
    /// One line.
    pub summary: String,
    /// Where the model comes from.
    pub reference: String,
    /// Degrees of freedom of the walker in single support: its generalised coordinates.
    pub degrees_of_freedom: usize,
    /// The generalised coordinates, in the model's order.
    pub coordinates: Vec<String>,
    /// Its parameters, by name.
    pub parameters: Vec<ParameterEntry>,
}

/// One parameter of a scene.
#[derive(Clone, Debug, Serialize)]
pub struct ParameterEntry {
    /// Name.
    pub name: String,
    /// Default value.
    pub default: f64,
    /// Unit.
    pub unit: String,
    /// What it is.
    pub doc: String,
    /// Smallest allowed value.
    pub min: Option<f64>,
    /// Largest allowed value.
    pub max: Option<f64>,
    /// Other names it can be set by.
    pub aliases: Vec<String>,
}

impl SceneCatalogue {
    /// The built-in scenes.
    pub fn builtin() -> Result<Self, SceneError> {
        let scenes = BUILTIN
            .iter()
            .map(|(name, _)| SceneEntry::of(&Scene::load(name)?))
            .collect::<Result<_, _>>()?;
        Ok(Self { scenes })
    }
}

impl SceneEntry {
    /// The entry of `scene` (built-in or from a file), its walker built at its defaults to
    /// count the freedoms.
    pub fn of(scene: &Scene) -> Result<Self, SceneError> {
        let parameters = scene
            .file
            .parameters
            .iter()
            .map(|(k, p)| ParameterEntry {
                name: k.clone(),
                default: p.default,
                unit: p.unit.clone(),
                doc: p.doc.clone(),
                min: p.min,
                max: p.max,
                aliases: p.aliases.clone(),
            })
            .collect();
        let coordinates: Vec<String> = scene
            .setup()?
            .walker
            .model()
            .coordinates
            .iter()
            .map(|c| c.name.clone())
            .collect();
        Ok(Self {
            name: scene.name().to_string(),
            summary: scene.file.scene.summary.clone(),
            reference: scene.file.scene.reference.clone(),
            degrees_of_freedom: coordinates.len(),
            coordinates,
            parameters,
        })
    }
}
