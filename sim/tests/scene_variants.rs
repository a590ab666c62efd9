//! A `[variant]` changes parameter defaults and puts springs and dampers on joints exactly as
//! writing them in the base file would; what it names that the base lacks is an error naming it.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use sim::report::SceneEntry;
use sim::scene::variant::VariantError;
use sim::scene::{Scene, SceneError, BUILTIN};

/// The text of a built-in scene.
fn builtin(name: &str) -> &'static str {
    BUILTIN.iter().find(|(n, _)| *n == name).unwrap().1
}

/// The compass scene's text with `from` replaced by `to` (which must occur in it).
fn compass_edited(from: &str, to: &str) -> String {
    let text = builtin("compass");
    assert!(text.contains(from), "`{from}` is not in the compass scene");
    text.replacen(from, to, 1)
}

/// A variant of the compass scene: `[variant] base = "compass"` followed by `rest`.
fn compass_variant(rest: &str) -> Result<Scene, SceneError> {
    Scene::parse(
        "variant.toml",
        &format!("[variant]\nbase = \"compass\"\n{rest}"),
    )
}

/// The swing leg's joint line in compass.toml, after which a spring or damper is written.
const SWING_LEG: &str = "name = \"swing_leg\"\nparent = \"stance_leg\"\njoint = \"revolute\"\n";

#[test]
fn a_variant_adding_a_damper_gives_the_model_of_the_base_file_with_it() {
    // A damper and a spring, one of them an expression over a parameter the variant adds.
    let variant = compass_variant(
        "[parameters.hip_damping_n_m_s_rad]\ndefault = 0.3\nunit = \"N·m·s/rad\"\n\
         doc = \"Hip damper\"\nmin = 0.0\n\
         [variant.joint.swing_leg]\ndamping = \"hip_damping_n_m_s_rad\"\nstiffness = 2.0\n",
    )
    .unwrap();
    // The same written into the base file: the damper and spring in the swing leg's link,
    // the parameter appended (TOML lets a `[parameters.*]` table come last).
    let written = Scene::parse(
        "written.toml",
        &(compass_edited(
            SWING_LEG,
            &format!("{SWING_LEG}damping = \"hip_damping_n_m_s_rad\"\nstiffness = 2.0\n"),
        ) + "\n[parameters.hip_damping_n_m_s_rad]\ndefault = 0.3\nunit = \"N·m·s/rad\"\n\
             doc = \"Hip damper\"\nmin = 0.0\n"),
    );
    let written = written.unwrap();
    let (a, b) = (variant.setup().unwrap(), written.setup().unwrap());
    assert_eq!(a.walker.model(), b.walker.model());
    assert_eq!(format!("{a:?}"), format!("{b:?}"));
    let force =
        &a.walker.model().links[a.walker.model().link_index("swing_leg").unwrap().0].joint_force;
    assert_eq!((force.damping, force.stiffness), (0.3, 2.0));
    // The damper follows its parameter.
    let mut changed = variant.clone();
    changed.set("hip_damping_n_m_s_rad", 0.7).unwrap();
    let built = changed.build().unwrap();
    let model = built.model();
    assert_eq!(
        model.links[model.link_index("swing_leg").unwrap().0]
            .joint_force
            .damping,
        0.7
    );
}

#[test]
fn overriding_a_default_changes_the_default_in_the_parameter_table() {
    let base = SceneEntry::of(&Scene::load("compass").unwrap()).unwrap();
    let default = |e: &SceneEntry, name: &str| {
        e.parameters
            .iter()
            .find(|p| p.name == name)
            .unwrap()
            .clone()
    };
    assert_eq!(default(&base, "slope_rad").default, 0.0525);
    // By name, and by alias (`slope` is `slope_rad`'s).
    for key in ["slope_rad", "slope"] {
        let scene = compass_variant(&format!("[variant.defaults]\n{key} = 0.04\n")).unwrap();
        let entry = SceneEntry::of(&scene).unwrap();
        let p = default(&entry, "slope_rad");
        assert_eq!(p.default, 0.04);
        // Unit, doc and range kept.
        let q = default(&base, "slope_rad");
        assert_eq!((p.unit, p.doc, p.min, p.max), (q.unit, q.doc, q.min, q.max));
        assert_eq!(scene.values["slope_rad"], 0.04);
        assert_eq!(scene.setup().unwrap().walker.model(), {
            let mut s = Scene::load("compass").unwrap();
            s.set("slope_rad", 0.04).unwrap();
            s.build().unwrap().model()
        });
    }
}

#[test]
fn a_variant_naming_what_its_base_lacks_is_an_error_naming_it() {
    let err = compass_variant("[variant.joint.knee]\ndamping = 0.1\n").unwrap_err();
    assert!(
        matches!(&err, SceneError::Variant(VariantError::UnknownJoint { base, link, .. })
            if base == "compass" && link == "knee"),
        "{err:?}"
    );
    assert!(err.to_string().contains("no link `knee`"), "{err}");
    // The hip is welded to the stance leg: nothing for a damper to act on.
    let err = compass_variant("[variant.joint.hip]\ndamping = 0.1\n").unwrap_err();
    assert!(
        matches!(&err, SceneError::Variant(VariantError::NoJoint { link, why, .. })
            if link == "hip" && why.contains("weld")),
        "{err:?}"
    );
    // Welded or removed by the variant itself.
    let err = compass_variant("weld = [\"swing_leg\"]\n[variant.joint.swing_leg]\ndamping = 0.1\n")
        .unwrap_err();
    assert!(
        matches!(&err, SceneError::Variant(VariantError::NoJoint { .. })),
        "{err:?}"
    );
    let err =
        compass_variant("remove = [\"swing_leg\"]\n[variant.joint.swing_leg]\ndamping = 0.1\n")
            .unwrap_err();
    assert!(
        matches!(&err, SceneError::Variant(VariantError::NoJoint { why, .. }) if why.contains("removed")),
        "{err:?}"
    );
    let err = compass_variant("[variant.defaults]\nknee_stiffness = 1.0\n").unwrap_err();
    assert!(
        matches!(&err, SceneError::Variant(VariantError::UnknownParameter { name, .. })
            if name == "knee_stiffness"),
        "{err:?}"
    );
    assert!(
        err.to_string().contains("no parameter `knee_stiffness`"),
        "{err}"
    );
    // A new default outside the parameter's range, a misspelt key: named.
    let err = compass_variant("[variant.defaults]\nslope_rad = 0.9\n").unwrap_err();
    assert!(
        matches!(&err, SceneError::OutOfRange { name, .. } if name == "slope_rad"),
        "{err:?}"
    );
    let err = compass_variant("[variant.joint.swing_leg]\ndampin = 0.1\n").unwrap_err();
    assert!(err.to_string().contains("dampin"), "{err}");
    // A negative damper is refused as if written in the link.
    let err = compass_variant("[variant.joint.swing_leg]\ndamping = -0.1\n")
        .unwrap()
        .setup()
        .unwrap_err();
    assert!(err.to_string().contains("must not be negative"), "{err}");
}
