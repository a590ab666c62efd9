//! The scene's `[[shape]]`s evaluated against its model: how the bodies look (animations
//! only). Evaluated, and so checked, when the scene is built ([`Scene::setup`]): a shape on an
//! unknown link, a number that does not evaluate, a radius that is not positive or a ring
//! without a normal is refused at load, not found only by `--animate`.

use super::{Scene, SceneError};
use crate::engine::model::{LinkIndex, Model};
use crate::scene::file::{Num, ShapeDef};
use nalgebra::Vector3;

/// A shape, in its link's frame.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A cylinder between two points.
    Rod {
        /// What it is.
        name: String,
        /// Its link.
        link: LinkIndex,
        /// One end \[m\].
        from_m: Vector3<f64>,
        /// The other end \[m\].
        to_m: Vector3<f64>,
        /// Radius \[m\], positive.
        radius_m: f64,
    },
    /// A thin ring.
    Ring {
        /// What it is.
        name: String,
        /// Its link.
        link: LinkIndex,
        /// Centre \[m\].
        centre_m: Vector3<f64>,
        /// Unit normal of its plane.
        normal: Vector3<f64>,
        /// Radius \[m\], positive.
        radius_m: f64,
    },
}

impl Shape {
    /// Its name.
    pub fn name(&self) -> &str {
        match self {
            Shape::Rod { name, .. } | Shape::Ring { name, .. } => name,
        }
    }

    /// Its link.
    pub fn link(&self) -> LinkIndex {
        match self {
            Shape::Rod { link, .. } | Shape::Ring { link, .. } => *link,
        }
    }
}

impl Scene {
    /// The scene's shapes on `model` (its built walker's), in file order.
    ///
    /// # Errors
    /// [`SceneError::Invalid`] naming the shape: an unknown link, a radius that is not
    /// positive, a ring's zero normal; a number that does not evaluate, as for any key.
    pub fn shapes(&self, model: &Model) -> Result<Vec<Shape>, SceneError> {
        self.file
            .shapes
            .iter()
            .map(|s| self.shape(model, s))
            .collect()
    }

    fn shape(&self, model: &Model, s: &ShapeDef) -> Result<Shape, SceneError> {
        let link_name = s.link();
        let (name, kind) = match s {
            ShapeDef::Rod { name, .. } => (name, "rod"),
            ShapeDef::Ring { name, .. } => (name, "ring"),
        };
        let what = format!("shape `{name}` ({kind})");
        let link = model
            .link_index(link_name)
            .ok_or_else(|| SceneError::Invalid(format!("{what}: unknown link `{link_name}`")))?;
        let vec = |v: &[Num; 3]| -> Result<Vector3<f64>, SceneError> {
            let p = Vector3::new(
                self.num(&v[0], &what)?,
                self.num(&v[1], &what)?,
                self.num(&v[2], &what)?,
            );
            if p.iter().all(|x| x.is_finite()) {
                Ok(p)
            } else {
                Err(SceneError::Invalid(format!(
                    "{what}: a point is not finite"
                )))
            }
        };
        let positive = |r: &Num| -> Result<f64, SceneError> {
            let r = self.num(r, &what)?;
            if r > 0.0 && r.is_finite() {
                Ok(r)
            } else {
                Err(SceneError::Invalid(format!(
                    "{what}: radius_m = {} is not a positive length",
                    super::short_number(r)
                )))
            }
        };
        Ok(match s {
            ShapeDef::Rod {
                from_m,
                to_m,
                radius_m,
                ..
            } => Shape::Rod {
                name: name.clone(),
                link,
                from_m: vec(from_m)?,
                to_m: vec(to_m)?,
                radius_m: positive(radius_m)?,
            },
            ShapeDef::Ring {
                centre_m,
                normal,
                radius_m,
                ..
            } => Shape::Ring {
                name: name.clone(),
                link,
                centre_m: vec(centre_m)?,
                normal: vec(normal)?
                    .try_normalize(1e-12)
                    .ok_or_else(|| SceneError::Invalid(format!("{what}: the normal is zero")))?,
                radius_m: positive(radius_m)?,
            },
        })
    }
}
