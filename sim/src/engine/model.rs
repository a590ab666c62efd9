//! The read-only multibody model: links (a body hung on a joint), coordinates, marker points.
//!
//! A model is a kinematic tree rooted at the ground (the stance contact). Each link owns at
//! most one coordinate (its joint's), so each joint owns its slice of `q` and `q̇`. Positions are
//! in metres, angles in radians, masses in kilograms, in the floor frame of `docs/model.md`: x forward
//! (down the slope), y normal to the floor (up), z = x × y.

use nalgebra::{Matrix3, Vector3};

/// Index of a link in [`Model::links`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct LinkIndex(pub usize);

/// Index of a generalised coordinate in `q`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct CoordIndex(pub usize);

/// Index of a marker point in [`Model::points`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PointIndex(pub usize);

/// How a link moves relative to its parent.
#[derive(Clone, Debug, PartialEq)]
pub enum JointKind {
    /// Rotation about a unit axis given in the parent link's frame, through the joint origin.
    Revolute {
        /// Unit axis in the parent frame.
        axis_parent: Vector3<f64>,
    },
    /// Translation along a unit axis given in the parent link's frame.
    Prismatic {
        /// Unit axis in the parent frame.
        axis_parent: Vector3<f64>,
    },
    /// Rigidly attached.
    Weld,
}

/// Mass properties of the body carried by a link.
#[derive(Clone, Debug, PartialEq)]
pub struct BodyInertia {
    /// Mass \[kg\].
    pub mass_kg: f64,
    /// Centre of mass in the link frame \[m\].
    pub p_link_com_m: Vector3<f64>,
    /// Inertia tensor about the centre of mass, link frame axes [kg·m²].
    pub inertia_com_kg_m2: Matrix3<f64>,
    /// The body's mass tends to zero: the equations of motion are those of the limit
    /// `mass → 0` (Garcia et al. 1998), not of a massless body. See `singular_limit`.
    pub infinitesimal: bool,
}

impl BodyInertia {
    /// A body with no mass at all.
    pub fn massless() -> Self {
        Self {
            mass_kg: 0.0,
            p_link_com_m: Vector3::zeros(),
            inertia_com_kg_m2: Matrix3::zeros(),
            infinitesimal: false,
        }
    }
}

/// A linear spring and damper acting on a joint coordinate.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct JointForce {
    /// Stiffness [N·m/rad] or [N/m].
    pub stiffness: f64,
    /// Rest position \[rad\] or \[m\].
    pub rest_position: f64,
    /// Damping [N·m·s/rad] or [N·s/m].
    pub damping: f64,
}

/// A body hung on a joint.
#[derive(Clone, Debug, PartialEq)]
pub struct Link {
    /// Unique name.
    pub name: String,
    /// Parent link, or `None` for the ground.
    pub parent: Option<LinkIndex>,
    /// Joint origin in the parent frame (or the floor frame for a root link) \[m\].
    pub p_parent_joint_m: Vector3<f64>,
    /// The joint kind.
    pub joint: JointKind,
    /// The coordinate this joint owns (`None` for a weld).
    pub coordinate: Option<CoordIndex>,
    /// Spring and damper on the joint coordinate.
    pub joint_force: JointForce,
    /// The carried body.
    pub body: BodyInertia,
}

/// A named generalised coordinate.
#[derive(Clone, Debug, PartialEq)]
pub struct Coordinate {
    /// Name, as used in scene files and reports.
    pub name: String,
    /// The link whose joint owns it.
    pub link: LinkIndex,
}

/// A marker point fixed in a link.
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    /// Name.
    pub name: String,
    /// Link carrying it.
    pub link: LinkIndex,
    /// Position in the link frame \[m\].
    pub p_link_m: Vector3<f64>,
}

/// The read-only model. Links are stored parents-first.
#[derive(Clone, Debug, PartialEq)]
pub struct Model {
    /// Links, every parent before its children.
    pub links: Vec<Link>,
    /// Coordinates in `q` order.
    pub coordinates: Vec<Coordinate>,
    /// Marker points.
    pub points: Vec<Point>,
    /// Gravity in the floor frame [m/s²] (includes the slope).
    pub gravity_floor_m_s2: Vector3<f64>,
}

/// Errors building a model.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// A name used twice.
    #[error("duplicate name `{0}`")]
    DuplicateName(String),
    /// A reference to a link that does not exist (or is not yet defined: parents come first).
    #[error("link `{child}` names parent `{parent}`, which is not defined before it")]
    UnknownParent {
        /// The referring link.
        child: String,
        /// The missing parent.
        parent: String,
    },
    /// A point on an unknown link.
    #[error("point `{point}` is on unknown link `{link}`")]
    UnknownLink {
        /// The point.
        point: String,
        /// The missing link.
        link: String,
    },
    /// A joint axis of zero length.
    #[error("joint of link `{0}` has a zero axis")]
    ZeroAxis(String),
    /// A non-physical mass or inertia.
    #[error("link `{link}`: {what}")]
    NonPhysical {
        /// The link.
        link: String,
        /// What is wrong.
        what: String,
    },
}

impl Model {
    /// An empty model with the given gravity vector.
    pub fn new(gravity_floor_m_s2: Vector3<f64>) -> Self {
        Self {
            links: Vec::new(),
            coordinates: Vec::new(),
            points: Vec::new(),
            gravity_floor_m_s2,
        }
    }

    /// Gravity for magnitude `g_m_s2` on a floor sloping down by `slope_rad` in +x.
    pub fn gravity_on_slope(g_m_s2: f64, slope_rad: f64) -> Vector3<f64> {
        Vector3::new(g_m_s2 * slope_rad.sin(), -g_m_s2 * slope_rad.cos(), 0.0)
    }

    /// Number of generalised coordinates.
    pub fn dof(&self) -> usize {
        self.coordinates.len()
    }

    /// Adds a link; `parent` is a link name or `None` for the ground.
    #[allow(clippy::too_many_arguments)]
    pub fn add_link(
        &mut self,
        name: &str,
        parent: Option<&str>,
        p_parent_joint_m: Vector3<f64>,
        joint: JointKind,
        joint_force: JointForce,
        body: BodyInertia,
    ) -> Result<LinkIndex, ModelError> {
        if self.link_index(name).is_some() {
            return Err(ModelError::DuplicateName(name.to_string()));
        }
        let parent = match parent {
            None => None,
            Some(p) => Some(
                self.link_index(p)
                    .ok_or_else(|| ModelError::UnknownParent {
                        child: name.to_string(),
                        parent: p.to_string(),
                    })?,
            ),
        };
        let joint = match joint {
            JointKind::Revolute { axis_parent } | JointKind::Prismatic { axis_parent }
                if axis_parent.norm() < 1e-12 =>
            {
                return Err(ModelError::ZeroAxis(name.to_string()));
            }
            JointKind::Revolute { axis_parent } => JointKind::Revolute {
                axis_parent: axis_parent.normalize(),
            },
            JointKind::Prismatic { axis_parent } => JointKind::Prismatic {
                axis_parent: axis_parent.normalize(),
            },
            JointKind::Weld => JointKind::Weld,
        };
        check_body(name, &body)?;
        let index = LinkIndex(self.links.len());
        let coordinate = match joint {
            JointKind::Weld => None,
            _ => {
                let c = CoordIndex(self.coordinates.len());
                self.coordinates.push(Coordinate {
                    name: name.to_string(),
                    link: index,
                });
                Some(c)
            }
        };
        self.links.push(Link {
            name: name.to_string(),
            parent,
            p_parent_joint_m,
            joint,
            coordinate,
            joint_force,
            body,
        });
        Ok(index)
    }

    /// Adds a marker point on a link.
    pub fn add_point(
        &mut self,
        name: &str,
        link: &str,
        p_link_m: Vector3<f64>,
    ) -> Result<PointIndex, ModelError> {
        if self.point_index(name).is_some() {
            return Err(ModelError::DuplicateName(name.to_string()));
        }
        let l = self
            .link_index(link)
            .ok_or_else(|| ModelError::UnknownLink {
                point: name.to_string(),
                link: link.to_string(),
            })?;
        self.points.push(Point {
            name: name.to_string(),
            link: l,
            p_link_m,
        });
        Ok(PointIndex(self.points.len() - 1))
    }

    /// Looks a link up by name.
    pub fn link_index(&self, name: &str) -> Option<LinkIndex> {
        self.links
            .iter()
            .position(|l| l.name == name)
            .map(LinkIndex)
    }

    /// Looks a coordinate up by name.
    pub fn coord_index(&self, name: &str) -> Option<CoordIndex> {
        self.coordinates
            .iter()
            .position(|c| c.name == name)
            .map(CoordIndex)
    }

    /// Looks a point up by name.
    pub fn point_index(&self, name: &str) -> Option<PointIndex> {
        self.points
            .iter()
            .position(|p| p.name == name)
            .map(PointIndex)
    }

    /// Total mass \[kg\] (infinitesimal bodies count as zero).
    pub fn total_mass_kg(&self) -> f64 {
        self.links
            .iter()
            .filter(|l| !l.body.infinitesimal)
            .map(|l| l.body.mass_kg)
            .sum()
    }

    /// Whether any body is infinitesimal (the equations are a singular limit).
    pub fn has_infinitesimal_bodies(&self) -> bool {
        self.links
            .iter()
            .any(|l| l.body.infinitesimal && l.body.mass_kg > 0.0)
    }

    /// The chain of links from `link` up to the root, `link` first.
    pub fn ancestry(&self, link: LinkIndex) -> Vec<LinkIndex> {
        let mut out = vec![link];
        let mut cur = self.links[link.0].parent;
        while let Some(p) = cur {
            out.push(p);
            cur = self.links[p.0].parent;
        }
        out
    }

    /// A copy in which the root links hang below a chain of new massless joints from the
    /// ground: used for impacts, during which the stance foot is released. Returns the model
    /// and the number of new coordinates, which come first in `q`.
    pub fn with_released_root(&self, release: &[JointKind]) -> Model {
        let mut m = Model::new(self.gravity_floor_m_s2);
        let mut parent: Option<String> = None;
        for (i, kind) in release.iter().enumerate() {
            let name = format!("__release_{i}");
            // Names are fresh and axes validated by the caller: this cannot fail.
            let _ = m.add_link(
                &name,
                parent.as_deref(),
                Vector3::zeros(),
                kind.clone(),
                JointForce::default(),
                BodyInertia::massless(),
            );
            parent = Some(name);
        }
        let offset = release.len();
        for link in &self.links {
            let index = LinkIndex(m.links.len());
            let coordinate = link.coordinate.map(|c| {
                m.coordinates.push(Coordinate {
                    name: self.coordinates[c.0].name.clone(),
                    link: index,
                });
                CoordIndex(m.coordinates.len() - 1)
            });
            let parent = match link.parent {
                Some(p) => Some(LinkIndex(p.0 + offset)),
                None if offset > 0 => Some(LinkIndex(offset - 1)),
                None => None,
            };
            m.links.push(Link {
                parent,
                coordinate,
                ..link.clone()
            });
        }
        for p in &self.points {
            m.points.push(Point {
                link: LinkIndex(p.link.0 + offset),
                ..p.clone()
            });
        }
        m
    }
}

fn check_body(name: &str, b: &BodyInertia) -> Result<(), ModelError> {
    let bad = |what: String| {
        Err(ModelError::NonPhysical {
            link: name.to_string(),
            what,
        })
    };
    if !b.mass_kg.is_finite() || b.mass_kg < 0.0 {
        return bad(format!(
            "mass {} kg is not a finite non-negative number",
            b.mass_kg
        ));
    }
    if b.p_link_com_m.iter().any(|v| !v.is_finite()) {
        return bad("centre of mass is not finite".into());
    }
    let i = &b.inertia_com_kg_m2;
    if i.iter().any(|v| !v.is_finite()) || (i - i.transpose()).norm() > 1e-12 {
        return bad("inertia tensor is not finite and symmetric".into());
    }
    let eig = i.symmetric_eigenvalues();
    let (a, bb, c) = (eig[0], eig[1], eig[2]);
    if a < -1e-12 || bb < -1e-12 || c < -1e-12 {
        return bad(format!(
            "inertia tensor has a negative principal moment ({a}, {bb}, {c})"
        ));
    }
    // Triangle inequality of principal moments, with a tolerance for rounding.
    let tol = 1e-9 * (a + bb + c).max(1e-300);
    if a + bb < c - tol || a + c < bb - tol || bb + c < a - tol {
        return bad(format!(
            "principal moments ({a}, {bb}, {c}) kg·m² violate the triangle inequality"
        ));
    }
    Ok(())
}
