//! What the animation draws, with the scene's own dimensions: the scene's `[[shape]]`s (rods
//! and rings fixed in links), else the skeleton of its links (a rod from each link's joint to
//! its children's joints and its marker points), and every body's mass at its centre of mass.
//! Each drawn part refers to key points (a link and a point in its frame); the frames carry
//! the key points' floor-frame positions, so the page only draws.

use nalgebra::Vector3;
use serde::Serialize;
use sim::engine::model::{LinkIndex, Model};
use sim::scene::{Scene, SceneError, Shape};

/// A point fixed in a link whose floor-frame position each frame carries.
#[derive(Clone, Debug, PartialEq)]
pub struct KeyPoint {
    /// The link.
    pub link: LinkIndex,
    /// Position in the link frame \[m\].
    pub p_link_m: Vector3<f64>,
}

/// Which leg a part belongs to (its colour): the link's name says (`stance_…`, `swing_…`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Role {
    /// The stance leg (labels swap at every heel strike).
    Stance,
    /// The swing leg.
    Swing,
    /// Everything else (hip, pelvis).
    Body,
}

/// One drawn part; indices are into [`Figure::points`].
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Part {
    /// A cylinder from key point `a` to key point `b`.
    Rod {
        /// What it is.
        name: String,
        /// Its leg.
        role: Role,
        /// One end.
        a: usize,
        /// The other end.
        b: usize,
        /// Radius \[m\].
        radius_m: f64,
    },
    /// A ring about key point `centre`, in the plane normal to the direction from `centre`
    /// to `normal_tip`.
    Ring {
        /// What it is.
        name: String,
        /// Its leg.
        role: Role,
        /// The centre.
        centre: usize,
        /// Centre plus the unit normal.
        normal_tip: usize,
        /// Radius \[m\].
        radius_m: f64,
    },
    /// A body's mass at its centre of mass (drawn as a sphere whose volume grows with it).
    Mass {
        /// The link carrying it.
        name: String,
        /// Its leg.
        role: Role,
        /// The centre of mass.
        at: usize,
        /// Mass \[kg\]; 0 for a body whose mass tends to zero (Garcia's feet).
        mass_kg: f64,
    },
}

/// Everything drawn, for one walker.
#[derive(Clone, Debug, Default)]
pub struct Figure {
    /// The key points, each once.
    pub points: Vec<KeyPoint>,
    /// The parts.
    pub parts: Vec<Part>,
}

/// Drawn radius of a skeleton rod (the scenes without shapes give no thickness) \[m\].
const SKELETON_ROD_RADIUS_M: f64 = 0.012;

impl Figure {
    /// The figure of `scene`'s walker `model`: its shapes, else its skeleton, and its masses.
    pub fn of(scene: &Scene, model: &Model) -> Result<Self, SceneError> {
        let mut f = Figure::default();
        if scene.file.shapes.is_empty() {
            f.add_skeleton(model);
        }
        for s in &scene.shapes(model)? {
            f.add_shape(model, s);
        }
        for (i, l) in model.links.iter().enumerate() {
            if l.body.mass_kg > 0.0 {
                let link = LinkIndex(i);
                let at = f.point(link, l.body.p_link_com_m);
                f.parts.push(Part::Mass {
                    name: l.name.clone(),
                    role: role(&l.name),
                    at,
                    mass_kg: if l.body.infinitesimal {
                        0.0
                    } else {
                        l.body.mass_kg
                    },
                });
            }
        }
        Ok(f)
    }

    /// The index of key point (`link`, `p_link_m`), added if new.
    fn point(&mut self, link: LinkIndex, p_link_m: Vector3<f64>) -> usize {
        let k = KeyPoint { link, p_link_m };
        match self.points.iter().position(|p| *p == k) {
            Some(i) => i,
            None => {
                self.points.push(k);
                self.points.len() - 1
            }
        }
    }

    fn add_skeleton(&mut self, model: &Model) {
        for (i, l) in model.links.iter().enumerate() {
            let link = LinkIndex(i);
            let children = model
                .links
                .iter()
                .filter(|c| c.parent == Some(link))
                .map(|c| c.p_parent_joint_m);
            let markers = model
                .points
                .iter()
                .filter(|p| p.link == link)
                .map(|p| p.p_link_m);
            let mut ends: Vec<Vector3<f64>> = Vec::new();
            for e in children.chain(markers) {
                if e.norm() > 1e-9 && !ends.iter().any(|x| (x - e).norm() < 1e-9) {
                    ends.push(e);
                }
            }
            for e in ends {
                let a = self.point(link, Vector3::zeros());
                let b = self.point(link, e);
                self.parts.push(Part::Rod {
                    name: l.name.clone(),
                    role: role(&l.name),
                    a,
                    b,
                    radius_m: SKELETON_ROD_RADIUS_M,
                });
            }
        }
    }

    fn add_shape(&mut self, model: &Model, s: &Shape) {
        let link = s.link();
        let link_name = model.links.get(link.0).map_or("", |l| l.name.as_str());
        let role = shape_role(s.name(), link_name);
        match s {
            Shape::Rod {
                name,
                from_m,
                to_m,
                radius_m,
                ..
            } => {
                let (a, b) = (self.point(link, *from_m), self.point(link, *to_m));
                self.parts.push(Part::Rod {
                    name: name.clone(),
                    role,
                    a,
                    b,
                    radius_m: *radius_m,
                });
            }
            Shape::Ring {
                name,
                centre_m,
                normal,
                radius_m,
                ..
            } => {
                let (centre, normal_tip) = (
                    self.point(link, *centre_m),
                    self.point(link, centre_m + normal),
                );
                self.parts.push(Part::Ring {
                    name: name.clone(),
                    role,
                    centre,
                    normal_tip,
                    radius_m: *radius_m,
                });
            }
        }
    }
}

/// A shape's colour: a shape named after the hip or the pelvis (the hip axle, the pelvic
/// ring) is the body's, as the page's legend says ("hip, pelvis"), whichever link carries it
/// (wisse3d's hip axle rides on the stance thigh); any other shape is its link's.
fn shape_role(shape_name: &str, link_name: &str) -> Role {
    let name = shape_name.to_lowercase();
    if name.starts_with("hip") || name.starts_with("pelvi") {
        Role::Body
    } else {
        role(link_name)
    }
}

/// A link's leg, from its name.
fn role(link_name: &str) -> Role {
    if link_name.starts_with("stance") {
        Role::Stance
    } else if link_name.starts_with("swing") {
        Role::Swing
    } else {
        Role::Body
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn figure(scene: &Scene) -> Result<Figure, SceneError> {
        Figure::of(scene, scene.setup()?.walker.model())
    }

    fn names(f: &Figure) -> Vec<&str> {
        f.parts
            .iter()
            .filter_map(|p| match p {
                Part::Rod { name, .. } | Part::Ring { name, .. } => Some(name.as_str()),
                Part::Mass { .. } => None,
            })
            .collect()
    }

    #[test]
    fn a_variant_drops_the_shapes_of_the_bodies_it_removes() {
        let with = figure(&Scene::load("wisse3d").unwrap()).unwrap();
        let without = figure(&Scene::load("wisse3d-uncompensated").unwrap()).unwrap();
        assert!(names(&with).contains(&"pelvic ring"));
        assert!(!names(&without).contains(&"pelvic ring"));
        assert!(names(&without).contains(&"hip axle"));
        // Hip axle and pelvic ring in the body's colour (the legend's "hip, pelvis"), the
        // legs in theirs.
        let role_of = |name: &str| {
            with.parts.iter().find_map(|p| match p {
                Part::Rod { name: n, role, .. } | Part::Ring { name: n, role, .. } if n == name => {
                    Some(*role)
                }
                _ => None,
            })
        };
        assert_eq!(role_of("hip axle"), Some(Role::Body));
        assert_eq!(role_of("pelvic ring"), Some(Role::Body));
        assert_eq!(role_of("stance shank"), Some(Role::Stance));
        assert_eq!(role_of("swing shank"), Some(Role::Swing));
        // Welded freedoms keep their bodies (and shapes).
        let planar = figure(&Scene::load("wisse2d").unwrap()).unwrap();
        assert_eq!(names(&planar), names(&with));
    }

    #[test]
    fn a_scene_without_shapes_is_its_skeleton_and_its_masses() {
        let scene = Scene::load("compass").unwrap();
        let f = figure(&scene).unwrap();
        let rods = f
            .parts
            .iter()
            .filter(|p| matches!(p, Part::Rod { .. }))
            .count();
        // Stance leg (foot to hip) and swing leg (hip to foot).
        assert_eq!(rods, 2);
        let masses: Vec<f64> = f
            .parts
            .iter()
            .filter_map(|p| match p {
                Part::Mass { mass_kg, .. } => Some(*mass_kg),
                _ => None,
            })
            .collect();
        let v = |k: &str| scene.values[k];
        let mut expected = vec![v("leg_mass_kg"), v("hip_mass_kg"), v("leg_mass_kg")];
        expected.sort_by(f64::total_cmp);
        let mut got = masses.clone();
        got.sort_by(f64::total_cmp);
        assert_eq!(got, expected);
    }

    #[test]
    fn a_bad_shape_is_refused() {
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../scenes/compass.toml"
        ))
        .unwrap();
        for (shape, message) in [
            (
                "kind = \"rod\"\nname = \"leg\"\nlink = \"stance_leg\"\nfrom_m = [0, 0, 0]\nto_m = [0, 1, 0]\nradius_m = 0",
                "not a positive length",
            ),
            (
                "kind = \"ring\"\nname = \"r\"\nlink = \"stance_leg\"\ncentre_m = [0, 0, 0]\nnormal = [0, 0, 0]\nradius_m = 0.1",
                "normal is zero",
            ),
            (
                "kind = \"rod\"\nname = \"leg\"\nlink = \"no_such_link\"\nfrom_m = [0, 0, 0]\nto_m = [0, 1, 0]\nradius_m = 0.01",
                "unknown link",
            ),
        ] {
            let scene = Scene::parse("test", &format!("{text}\n[[shape]]\n{shape}\n")).unwrap();
            let err = figure(&scene).unwrap_err().to_string();
            assert!(err.contains(message), "{err}");
        }
        // An unknown field is a scene-file error.
        let typo = format!(
            "{text}\n[[shape]]\nkind = \"rod\"\nname = \"l\"\nlink = \"stance_leg\"\nfrom_m = [0, 0, 0]\nto_m = [0, 1, 0]\nradius = 0.01\n"
        );
        assert!(Scene::parse("test", &typo).is_err());
    }
}
