//! The TOML schema of scene files (see `sim/scenes/*.toml`; docs/scenes.md is the reference,
//! checked against these types by `sim/tests/scene_reference.rs`).

use serde::Deserialize;
use std::collections::BTreeMap;

/// A number, or an expression over the scene's parameters.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum Num {
    /// A literal.
    Value(f64),
    /// An expression such as `"leg_length_m - 0.5"`.
    Expr(String),
}

/// A whole scene file.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Name and description.
    pub scene: SceneHeader,
    /// Parameters, by name.
    #[serde(default)]
    pub parameters: BTreeMap<String, ParameterDef>,
    /// Gravity and slope.
    pub world: WorldDef,
    /// Links, parents first.
    #[serde(rename = "link")]
    pub links: Vec<LinkDef>,
    /// Marker points.
    #[serde(rename = "point", default)]
    pub points: Vec<PointDef>,
    /// Heel-strike rule.
    pub heel_strike: HeelStrikeDef,
    /// Knee stops.
    #[serde(rename = "knee", default)]
    pub knees: Vec<KneeDef>,
    /// Fall rule.
    pub fall: FallDef,
    /// Relabelling after heel strike.
    pub relabel: RelabelDef,
    /// Default integrator and limits.
    #[serde(default)]
    pub integrator: IntegratorDef,
    /// Starting guess for the gait.
    pub guess: GuessDef,
    /// The stance ankle's stretch reflex with an ideal actuator.
    #[serde(default)]
    pub ankle_reflex: Option<AnkleReflexDef>,
    /// Freedoms of the 3D model (reported in eigenvalue modes).
    #[serde(default)]
    pub three_d_freedoms: Vec<String>,
    /// Scene whose gait starts `walker walk` when this scene has no gait of its own (its
    /// coordinates are matched by name).
    #[serde(default)]
    pub walk_start_scene: Option<String>,
    /// Derived outputs in a publication's own convention.
    #[serde(default)]
    pub convention: Option<ConventionDef>,
    /// How the bodies look (`walker … --animate`); no effect on the dynamics. A scene
    /// without shapes is drawn as the skeleton of its links.
    #[serde(rename = "shape", default)]
    pub shapes: Vec<ShapeDef>,
}

/// A drawn part of the walker, fixed in a link (for animations only: masses and inertias
/// come from the links).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ShapeDef {
    /// A cylinder between two points of the link (a leg segment, an axle, a flat foot).
    Rod {
        /// What it is (`stance thigh`, `hip axle`).
        name: String,
        /// The link carrying it.
        link: String,
        /// One end in the link frame \[m\].
        from_m: [Num; 3],
        /// The other end in the link frame \[m\].
        to_m: [Num; 3],
        /// Radius \[m\].
        radius_m: Num,
    },
    /// A thin circular ring (the pelvic ring).
    Ring {
        /// What it is.
        name: String,
        /// The link carrying it.
        link: String,
        /// Centre in the link frame \[m\].
        centre_m: [Num; 3],
        /// Normal of its plane in the link frame (any length but zero).
        normal: [Num; 3],
        /// Radius \[m\].
        radius_m: Num,
    },
}

impl ShapeDef {
    /// The link that carries the shape.
    pub fn link(&self) -> &str {
        match self {
            ShapeDef::Rod { link, .. } | ShapeDef::Ring { link, .. } => link,
        }
    }
}

/// Scene header.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SceneHeader {
    /// Name used on the command line.
    pub name: String,
    /// One line.
    pub summary: String,
    /// Where the model comes from.
    #[serde(default)]
    pub reference: String,
}

/// One parameter.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ParameterDef {
    /// Default value.
    pub default: f64,
    /// Unit, e.g. `kg`, `m`, `rad`, `1`.
    pub unit: String,
    /// What it is.
    pub doc: String,
    /// Smallest allowed value (inclusive).
    #[serde(default)]
    pub min: Option<f64>,
    /// Largest allowed value (inclusive).
    #[serde(default)]
    pub max: Option<f64>,
    /// Other names accepted by `--set`.
    #[serde(default)]
    pub aliases: Vec<String>,
}

/// Gravity and slope.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct WorldDef {
    /// Gravitational acceleration [m/s²].
    pub gravity_m_s2: Num,
    /// Floor slope, downhill in +x \[rad\].
    pub slope_rad: Num,
}

/// A link: a joint and the body it carries.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LinkDef {
    /// Name (also the coordinate's name).
    pub name: String,
    /// Parent link name, or `ground`.
    pub parent: String,
    /// `revolute`, `prismatic` or `weld`.
    pub joint: String,
    /// Joint axis in the parent frame.
    #[serde(default)]
    pub axis: Option<[Num; 3]>,
    /// Joint origin in the parent frame \[m\].
    #[serde(default)]
    pub origin_m: Option<[Num; 3]>,
    /// Body mass \[kg\].
    #[serde(default)]
    pub mass_kg: Option<Num>,
    /// Centre of mass in the link frame \[m\].
    #[serde(default)]
    pub com_m: Option<[Num; 3]>,
    /// Principal moments of inertia about the c.m., link axes [kg·m²].
    #[serde(default)]
    pub inertia_diag_kg_m2: Option<[Num; 3]>,
    /// The mass tends to zero (limit equations).
    #[serde(default)]
    pub infinitesimal: bool,
    /// Joint spring stiffness [N·m/rad].
    #[serde(default)]
    pub stiffness: Option<Num>,
    /// Joint spring rest position \[rad\].
    #[serde(default)]
    pub rest: Option<Num>,
    /// Joint damping [N·m·s/rad].
    #[serde(default)]
    pub damping: Option<Num>,
}

/// A marker point.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PointDef {
    /// Name.
    pub name: String,
    /// Link.
    pub link: String,
    /// Position in the link frame \[m\].
    pub position_m: [Num; 3],
}

/// Heel strike.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct HeelStrikeDef {
    /// Swing-foot point.
    pub swing_foot: String,
    /// Old stance contact point (must lift).
    pub stance_contact: String,
    /// Minimum distance ahead of the stance contact for a crossing to count \[m\].
    #[serde(default)]
    pub min_ahead_m: Option<Num>,
    /// Ignore crossings behind that (mid-swing scuffing) instead of failing.
    #[serde(default)]
    pub ignore_scuffing: bool,
    /// Constrained directions: `x`, `y`, `z`, `yaw`.
    pub constraints: Vec<String>,
    /// Freedoms released at the old stance contact: `tx ty tz rx ry rz`.
    pub release: Vec<String>,
    /// Restitution `e`.
    #[serde(default)]
    pub restitution: Option<Num>,
}

/// A knee stop.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct KneeDef {
    /// Knee coordinate (link name).
    pub coordinate: String,
    /// Stop angle \[rad\].
    pub stop_rad: Num,
    /// `rising` or `falling`: how `q − stop` crosses zero at the stop.
    pub closing: String,
}

/// Falls.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct FallDef {
    /// Hip point.
    pub hip: String,
    /// Fallen below this hip height \[m\].
    pub min_hip_height_m: Num,
}

/// Relabelling.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RelabelDef {
    /// `[new, old]` link pairs whose orientations agree.
    pub pairs: Vec<[String; 2]>,
    /// `[new, old]` point pairs whose positions agree.
    #[serde(default)]
    pub point_pairs: Vec<[String; 2]>,
    /// Mirror about the sagittal plane.
    #[serde(default)]
    pub mirror: bool,
    /// Cyclic root coordinates.
    #[serde(default)]
    pub cyclic: Vec<String>,
}

/// Integrator defaults.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct IntegratorDef {
    /// `meijaard`, `rk4`, `dopri5` or `dop853`.
    #[serde(default = "default_kind")]
    pub kind: String,
    /// Fixed step \[s\] (meijaard, rk4).
    #[serde(default)]
    pub h_s: Option<f64>,
    /// Tolerances (dopri5).
    #[serde(default)]
    pub rtol: Option<f64>,
    /// Absolute tolerance (dopri5).
    #[serde(default)]
    pub atol: Option<f64>,
    /// Largest step (dopri5) \[s\].
    #[serde(default)]
    pub h_max_s: Option<f64>,
    /// Stride time budget \[s\].
    #[serde(default)]
    pub max_stride_time_s: Option<Num>,
}

fn default_kind() -> String {
    "dopri5".into()
}

impl Default for IntegratorDef {
    fn default() -> Self {
        Self {
            kind: default_kind(),
            h_s: None,
            rtol: None,
            atol: None,
            h_max_s: None,
            max_stride_time_s: None,
        }
    }
}

/// Gait guess, by coordinate name.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct GuessDef {
    /// Positions.
    pub q: BTreeMap<String, Num>,
    /// Velocities.
    pub qd: BTreeMap<String, Num>,
}

/// Outputs in a publication's convention: each is a linear combination of coordinates.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ConventionDef {
    /// Velocities are multiplied by this \[s\] (e.g. `sqrt(l/g)` for dimensionless time).
    pub time_scale_s: Num,
    /// Outputs.
    #[serde(rename = "output")]
    pub outputs: Vec<OutputDef>,
}

/// One derived output.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct OutputDef {
    /// Name of the position output; the rate is `<name>_dot`.
    pub name: String,
    /// Coefficient per coordinate.
    pub coefficients: BTreeMap<String, f64>,
    /// Constant offset (an expression: it may depend on parameters).
    #[serde(default)]
    pub offset: Option<Num>,
}

/// The ankle stretch reflex.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct AnkleReflexDef {
    /// Ankle coordinate.
    pub ankle: String,
    /// Toe-pitch coordinate (locked while the foot is flat).
    pub toe_pitch: String,
    /// Toe point.
    pub toe: String,
    /// Engagement angle \[rad\].
    pub engage_rad: Num,
    /// Final angle \[rad\].
    pub final_rad: Num,
    /// Extension duration \[s\].
    pub duration_s: Num,
}
