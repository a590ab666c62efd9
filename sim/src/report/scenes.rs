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
        let mut scenes = Vec::new();
        for (name, _) in BUILTIN {
            let s = Scene::load(name)?;
            let parameters = s
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
            scenes.push(SceneEntry {
                name: name.to_string(),
                summary: s.file.scene.summary.clone(),
                reference: s.file.scene.reference.clone(),
                parameters,
            });
        }
        Ok(Self { scenes })
    }
}
