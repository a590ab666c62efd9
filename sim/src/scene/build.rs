//! The stages of [`Scene::setup`]: each reads one part of the scene file and builds what the
//! walker needs from it, naming in its errors the key that was wrong.

use super::file::{self, Num};
use super::{direction, Scene, SceneError, Setup};
use crate::analysis::limit_cycle::GaitGuess;
use crate::engine::actuator::AnkleReflex;
use crate::engine::events::EventTolerance;
use crate::engine::integrators::IntegratorChoice;
use crate::engine::kinematics::Kinematics;
use crate::engine::model::{
    BodyInertia, CoordIndex, JointForce, JointKind, LinkIndex, Model, PointIndex,
};
use crate::engine::relabel::Relabel;
use crate::engine::walker::{
    ContactConstraint, FallRule, HeelStrikeRule, KneeLock, Walker, WalkerRules,
};
use crate::stride::StrideSettings;
use nalgebra::{DVector, Matrix3, Vector3};

/// The model's points, links and coordinates by name; an unknown name is an error naming it.
pub(super) struct Names<'a>(pub(super) &'a Model);

impl Names<'_> {
    pub(super) fn point(&self, name: &str) -> Result<PointIndex, SceneError> {
        self.0
            .point_index(name)
            .ok_or_else(|| SceneError::Invalid(format!("unknown point `{name}`")))
    }

    pub(super) fn link(&self, name: &str) -> Result<LinkIndex, SceneError> {
        self.0
            .link_index(name)
            .ok_or_else(|| SceneError::Invalid(format!("unknown link `{name}`")))
    }

    pub(super) fn coord(&self, name: &str) -> Result<CoordIndex, SceneError> {
        self.0
            .coord_index(name)
            .ok_or_else(|| SceneError::Invalid(format!("unknown coordinate `{name}`")))
    }
}

impl Scene {
    /// The model (`[world]`, `[[link]]`, `[[point]]`); the floor's slope enters as the
    /// direction of gravity in the floor frame.
    pub(super) fn model(&self) -> Result<Model, SceneError> {
        let f = &self.file;
        let g = self.num(&f.world.gravity_m_s2, "world.gravity_m_s2")?;
        if g <= 0.0 {
            return Err(SceneError::Invalid(format!(
                "world.gravity_m_s2 must be positive (its direction is down the slope's normal), \
                 got {g}"
            )));
        }
        let slope = self.num(&f.world.slope_rad, "world.slope_rad")?;
        let mut model = Model::new(Model::gravity_on_slope(g, slope));
        for l in &f.links {
            self.add_link(&mut model, l)?;
        }
        for p in &f.points {
            model.add_point(
                &p.name,
                &p.link,
                self.vec3(&Some(p.position_m.clone()), &p.name)?,
            )?;
        }
        Ok(model)
    }

    /// Adds one `[[link]]`: its joint, body, spring and damper.
    fn add_link(&self, model: &mut Model, l: &file::LinkDef) -> Result<(), SceneError> {
        let what = |field: &str| format!("link `{}`.{field}", l.name);
        let axis = self.vec3(&l.axis, &what("axis"))?;
        let joint = match l.joint.as_str() {
            "revolute" => JointKind::Revolute { axis_parent: axis },
            "prismatic" => JointKind::Prismatic { axis_parent: axis },
            "weld" => JointKind::Weld,
            other => {
                return Err(SceneError::Invalid(format!(
                    "link `{}`: joint `{other}` is not revolute, prismatic or weld",
                    l.name
                )))
            }
        };
        let d = self.inertia_diag(l)?;
        let body = BodyInertia {
            mass_kg: self.opt(&l.mass_kg, &what("mass_kg"))?,
            p_link_com_m: self.vec3(&l.com_m, &what("com_m"))?,
            inertia_com_kg_m2: Matrix3::from_diagonal(&d),
            infinitesimal: l.infinitesimal,
        };
        let force = JointForce {
            stiffness: self.opt(&l.stiffness, &what("stiffness"))?,
            rest_position: self.opt(&l.rest, &what("rest"))?,
            damping: self.opt(&l.damping, &what("damping"))?,
        };
        if force.stiffness < 0.0 || force.damping < 0.0 {
            return Err(SceneError::Invalid(format!(
                "link `{}`: stiffness and damping must not be negative",
                l.name
            )));
        }
        let parent = if l.parent == "ground" {
            None
        } else {
            Some(l.parent.as_str())
        };
        model.add_link(
            &l.name,
            parent,
            self.vec3(&l.origin_m, &what("origin_m"))?,
            joint,
            force,
            body,
        )?;
        Ok(())
    }

    /// The heel-strike rule (`[heel_strike]`), with the joints its release frees.
    pub(super) fn heel_strike(&self, names: &Names) -> Result<HeelStrikeRule, SceneError> {
        let hs = &self.file.heel_strike;
        let swing_foot = names.point(&hs.swing_foot)?;
        let constraints = hs
            .constraints
            .iter()
            .map(|c| contact_constraint(c))
            .collect::<Result<Vec<_>, _>>()?;
        let release = hs
            .release
            .iter()
            .map(|r| released_joint(r))
            .collect::<Result<Vec<_>, _>>()?;
        if constraints.is_empty() {
            return Err(SceneError::Invalid(
                "heel_strike.constraints is empty: the new stance contact needs at least one \
                 constrained direction"
                    .to_owned(),
            ));
        }
        for (list, names) in [("constraints", &hs.constraints), ("release", &hs.release)] {
            if let Some(twice) = names
                .iter()
                .enumerate()
                .find(|(i, n)| names[..*i].contains(n))
                .map(|(_, n)| n)
            {
                return Err(SceneError::Invalid(format!(
                    "heel_strike.{list} names `{twice}` twice"
                )));
            }
        }
        let restitution = self.opt(&hs.restitution, "heel_strike.restitution")?;
        if !(0.0..=1.0).contains(&restitution) {
            return Err(SceneError::Invalid(format!(
                "heel_strike.restitution must lie in [0, 1] (0 plastic, 1 elastic), got {restitution}"
            )));
        }
        let rule = HeelStrikeRule {
            swing_foot,
            swing_foot_link: names.0.points[swing_foot.0].link,
            min_ahead_m: self.opt(&hs.min_ahead_m, "heel_strike.min_ahead_m")?,
            ignore_scuffing: hs.ignore_scuffing,
            constraints,
            restitution,
            release,
            stance_contact: names.point(&hs.stance_contact)?,
        };
        Ok(rule)
    }

    /// The knee stops (`[[knee]]`).
    pub(super) fn knees(&self, names: &Names) -> Result<Vec<KneeLock>, SceneError> {
        self.file
            .knees
            .iter()
            .map(|k| {
                Ok(KneeLock {
                    coordinate: names.coord(&k.coordinate)?,
                    stop_rad: self.num(&k.stop_rad, "knee.stop_rad")?,
                    closing: direction(&k.closing)?,
                })
            })
            .collect()
    }

    /// The fall rule (`[fall]`).
    pub(super) fn fall(&self, names: &Names) -> Result<FallRule, SceneError> {
        let f = &self.file.fall;
        Ok(FallRule {
            hip: names.point(&f.hip)?,
            min_hip_height_m: self.num(&f.min_hip_height_m, "fall.min_hip_height_m")?,
        })
    }

    /// The relabelling (`[relabel]`), with the declared cyclic coordinates sorted by
    /// [`cyclic_symmetry`]: those the floor and gravity are invariant to stay cyclic (left out
    /// of the stride map), those only the slope's gravity breaks (the heading on a slope) become
    /// states of the map ([`Relabel::symmetry_broken`]), any other is an error.
    pub(super) fn relabel(&self, names: &Names) -> Result<Relabel, SceneError> {
        let r = &self.file.relabel;
        let model = names.0;
        let mut cyclic = Vec::new();
        let mut symmetry_broken = Vec::new();
        for name in &r.cyclic {
            let c = names.coord(name)?;
            match cyclic_symmetry(model, c) {
                Ok(true) => cyclic.push(c),
                Ok(false) => symmetry_broken.push(c),
                Err(why) => {
                    return Err(SceneError::Invalid(format!(
                        "relabel.cyclic: `{name}` {why}"
                    )))
                }
            }
        }
        Ok(Relabel {
            pairs: r
                .pairs
                .iter()
                .map(|[a, b]| Ok((names.link(a)?, names.link(b)?)))
                .collect::<Result<Vec<_>, SceneError>>()?,
            point_pairs: r
                .point_pairs
                .iter()
                .map(|[a, b]| Ok((names.point(a)?, names.point(b)?)))
                .collect::<Result<Vec<_>, SceneError>>()?,
            mirror: r.mirror,
            cyclic,
            symmetry_broken,
            fixed: Vec::new(),
            tolerance: 1e-13,
            max_iterations: 50,
        })
    }

    /// The integrator and the stride time budget \[s\] (`[integrator]`).
    pub(super) fn integrator(&self) -> Result<(IntegratorChoice, f64), SceneError> {
        let it = &self.file.integrator;
        let integrator =
            IntegratorChoice::from_kind(&it.kind, it.h_s, it.rtol, it.atol, it.h_max_s)
                .ok_or_else(|| {
                    SceneError::Invalid(format!("integrator.kind: unknown `{}`", it.kind))
                })?;
        let max_stride_time_s = match &it.max_stride_time_s {
            Some(n) => self.num(n, "integrator.max_stride_time_s")?,
            None => StrideSettings::default().max_stride_time_s,
        };
        Ok((integrator, max_stride_time_s))
    }

    /// The gait guess's coordinates and rates (`[guess]`; those not named are 0).
    pub(super) fn guess(&self, names: &Names) -> Result<(DVector<f64>, DVector<f64>), SceneError> {
        let g = &self.file.guess;
        let mut q = DVector::zeros(names.0.dof());
        let mut qd = DVector::zeros(names.0.dof());
        for (k, v) in &g.q {
            q[names.coord(k)?.0] = self.num(v, "guess.q")?;
        }
        for (k, v) in &g.qd {
            qd[names.coord(k)?.0] = self.num(v, "guess.qd")?;
        }
        Ok((q, qd))
    }

    /// The stance ankle's stretch reflex (`[ankle_reflex]`), if the scene has one.
    pub(super) fn ankle_reflex(&self, names: &Names) -> Result<Option<AnkleReflex>, SceneError> {
        let Some(a) = &self.file.ankle_reflex else {
            return Ok(None);
        };
        let duration_s = self.num(&a.duration_s, "ankle_reflex.duration_s")?;
        if duration_s <= 0.0 {
            return Err(SceneError::Invalid(format!(
                "ankle_reflex.duration_s must be positive, got {duration_s}"
            )));
        }
        Ok(Some(AnkleReflex {
            ankle: names.coord(&a.ankle)?,
            toe_pitch: names.coord(&a.toe_pitch)?,
            toe: names.point(&a.toe)?,
            engage_rad: self.num(&a.engage_rad, "ankle_reflex.engage_rad")?,
            final_rad: self.num(&a.final_rad, "ankle_reflex.final_rad")?,
            duration_s,
        }))
    }

    /// A link's principal moments about its c.m., each checked to be non-negative: a scene
    /// that computes them from other parameters (e.g. a moment about a joint less m d²) can
    /// make one negative, and the error then names the expression and the value.
    fn inertia_diag(&self, l: &file::LinkDef) -> Result<Vector3<f64>, SceneError> {
        let what = format!("link `{}`.inertia_diag_kg_m2", l.name);
        let d = self.vec3(&l.inertia_diag_kg_m2, &what)?;
        let texts = l.inertia_diag_kg_m2.as_ref();
        for (k, &v) in d.iter().enumerate() {
            if v < 0.0 {
                let text = texts.map_or_else(String::new, |t| match &t[k] {
                    Num::Value(x) => format!("{x}"),
                    Num::Expr(e) => format!("`{e}`"),
                });
                return Err(SceneError::Invalid(format!(
                    "{what}[{k}] = {text} is {v} kg·m² with these parameter values: a moment \
                     of inertia about the centre of mass cannot be negative"
                )));
            }
        }
        Ok(d)
    }
}

/// A `heel_strike.constraints` entry.
fn contact_constraint(c: &str) -> Result<ContactConstraint, SceneError> {
    match c {
        "x" => Ok(ContactConstraint::X),
        "y" => Ok(ContactConstraint::Y),
        "z" => Ok(ContactConstraint::Z),
        "yaw" => Ok(ContactConstraint::Yaw),
        o => Err(SceneError::Invalid(format!(
            "heel_strike.constraints: unknown `{o}`"
        ))),
    }
}

/// A `heel_strike.release` entry: the joint it frees at the old stance contact.
fn released_joint(r: &str) -> Result<JointKind, SceneError> {
    let (prismatic, axis) = match r {
        "tx" => (true, Vector3::x()),
        "ty" => (true, Vector3::y()),
        "tz" => (true, Vector3::z()),
        "rx" => (false, Vector3::x()),
        "ry" => (false, Vector3::y()),
        "rz" => (false, Vector3::z()),
        _ => {
            return Err(SceneError::Invalid(format!(
                "heel_strike.release: unknown `{r}` (expected tx, ty, tz, rx, ry or rz)"
            )))
        }
    };
    Ok(if prismatic {
        JointKind::Prismatic { axis_parent: axis }
    } else {
        JointKind::Revolute { axis_parent: axis }
    })
}

/// Whether the coordinate `c`, declared cyclic, is a symmetry of the walker on this floor.
///
/// A coordinate is cyclic when the dynamics and the floor are invariant to it, so that the
/// stride map can be taken modulo it. The floor is a plane and gravity a uniform field; the
/// walker's position on the plane is already taken modulo (every stride is expressed about its
/// own stance contact), so what a scene declares cyclic is a root joint's rotation about the
/// floor's normal (y), the heading:
/// - the floor is invariant to it on any slope (a rotation about a normal maps the plane onto
///   itself), gravity only when it points along the normal (level ground). On a slope the
///   heading decides which way is downhill: it is then a state of the stride map, `Ok(false)`
///   (the gait walks straight downhill, heading 0 up to the stance foot's yaw within the stride,
///   by the sagittal mirror symmetry, which a slope keeps since gravity has no z component);
/// - anything else (a joint that is not the root, a prismatic root, a rotation about another
///   axis) moves the walker off the floor or is already taken care of: `Err(why)`.
///
/// `Ok(true)`: cyclic. Level ground is decided exactly (gravity's in-plane components are 0
/// when `slope_rad` is 0), so a level scene's stride map does not change.
fn cyclic_symmetry(model: &Model, c: CoordIndex) -> Result<bool, String> {
    let link = &model.links[model.coordinates[c.0].link.0];
    if link.parent.is_some() {
        return Err(
            "is not a root joint: only a rotation of the whole walker can be cyclic".into(),
        );
    }
    let JointKind::Revolute { axis_parent } = link.joint else {
        return Err(
            "is not a revolute joint: the position on the floor is already taken modulo (each \
             stride is expressed about its own stance contact); only the heading can be cyclic"
                .into(),
        );
    };
    let normal = Vector3::y();
    if axis_parent.cross(&normal).norm() > 1e-12 * axis_parent.norm() {
        return Err(format!(
            "turns about {:?}, not about the floor's normal [0, 1, 0]: that would tilt the walker \
             into the floor",
            axis_parent.as_slice()
        ));
    }
    let g = model.gravity_floor_m_s2;
    Ok(g.x == 0.0 && g.z == 0.0)
}

/// The fall rule can fire: the hip at the guess stands above `fall.min_hip_height_m` (a walker
/// that starts below it would never be seen to fall).
fn check_fall_height(
    model: &Model,
    fall: &FallRule,
    q: &DVector<f64>,
    qd: &DVector<f64>,
) -> Result<(), SceneError> {
    let mut kin = Kinematics::new(model);
    kin.update(model, q, qd);
    let hip_m = kin.point_position(model, fall.hip).y;
    if hip_m <= fall.min_hip_height_m {
        return Err(SceneError::Invalid(format!(
            "fall.min_hip_height_m = {} is not below the hip's height at the guess ({hip_m:.4} m): \
             no fall could be seen",
            fall.min_hip_height_m
        )));
    }
    Ok(())
}

impl Scene {
    /// Builds the walker (the physics only; [`Self::setup`] for its settings and gait guess).
    pub fn build(&self) -> Result<Walker, SceneError> {
        Ok(self.setup()?.walker)
    }

    /// Builds everything the scene file sets up: the walker, its stride settings (the
    /// `integrator` section) and its gait guess (the `guess` section), in stages (see
    /// `scene/build.rs`): the model, the heel-strike, knee, fall and relabelling rules, the
    /// integrator, the guess and the ankle reflex.
    pub fn setup(&self) -> Result<Setup, SceneError> {
        let f = &self.file;
        let model = self.model()?;
        let names = Names(&model);
        let heel_strike = self.heel_strike(&names)?;
        let knees = self.knees(&names)?;
        let fall = self.fall(&names)?;
        let relabel = self.relabel(&names)?;
        let (integrator, max_stride_time_s) = self.integrator()?;
        let (guess_q, guess_qd) = self.guess(&names)?;
        let ankle = self.ankle_reflex(&names)?;
        for c in &f.three_d_freedoms {
            names.coord(c).map_err(|_| {
                SceneError::Invalid(format!("three_d_freedoms: unknown coordinate `{c}`"))
            })?;
        }
        check_fall_height(&model, &fall, &guess_q, &guess_qd)?;
        let walker = Walker::new(
            self.name(),
            model,
            WalkerRules {
                heel_strike,
                knees,
                fall,
                relabel,
                ankle,
                three_d_freedoms: f.three_d_freedoms.clone(),
                relabel_reference_q: guess_q.clone(),
            },
        );
        let settings = StrideSettings {
            integrator,
            event_tolerance: EventTolerance::default(),
            max_stride_time_s,
            ..StrideSettings::default()
        };
        settings
            .validate()
            .map_err(|error| SceneError::Integrator {
                scene: self.name().to_string(),
                error,
            })?;
        self.check_convention(&walker)?;
        // how the bodies look: checked here, at load, not first by an animation
        self.shapes(walker.model())?;
        Ok(Setup {
            walker,
            settings,
            guess: GaitGuess {
                q: guess_q,
                qd: guess_qd,
            },
        })
    }
}
