//! A scene file that states something impossible is refused when it is loaded (exit 2 in the
//! CLI, a `SceneError` naming the key), not found later as a stride failure: two parameters
//! under one name, convention outputs named twice, unknown names, gravity pointing up, a
//! restitution above 1, a contact with no constrained direction or a direction named twice,
//! a fall height the hip never stands above.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use sim::scene::{Scene, SceneError};

const COMPASS: &str = include_str!("../scenes/compass.toml");

/// The compass scene with `from` replaced by `to` (which must occur once), built.
fn compass_with(from: &str, to: &str) -> Result<(), SceneError> {
    assert_eq!(COMPASS.matches(from).count(), 1, "{from}");
    let text = COMPASS.replace(from, to);
    Scene::parse("changed.toml", &text)?.setup().map(|_| ())
}

fn refused(from: &str, to: &str, needle: &str) {
    match compass_with(from, to) {
        Err(e) => assert!(e.to_string().contains(needle), "`{needle}` not in: {e}"),
        Ok(()) => panic!("accepted: {from} -> {to}"),
    }
}

#[test]
fn the_unchanged_scenes_load() {
    for name in ["simplest", "compass", "kneed2d", "wisse2d", "wisse3d"] {
        Scene::load(name).unwrap().setup().unwrap();
    }
    compass_with("aliases = [\"slope\"]", "aliases = [\"slope\"]").unwrap();
}

#[test]
fn impossible_statements_are_refused_at_load_naming_the_key() {
    // `--set slope=` once set `hip_mass_kg` when both claimed the alias.
    let hip = COMPASS.find("[parameters.hip_mass_kg]").unwrap();
    let text = format!(
        "{}aliases = [\"slope\"]\n{}",
        &COMPASS[..hip + "[parameters.hip_mass_kg]\n".len()],
        &COMPASS[hip + "[parameters.hip_mass_kg]\n".len()..]
    );
    let e = Scene::parse("changed.toml", &text).unwrap_err().to_string();
    assert!(e.contains("`slope` already names parameter"), "{e}");
    refused(
        "gravity_m_s2 = \"gravity_m_s2\"",
        "gravity_m_s2 = -9.81",
        "world.gravity_m_s2 must be positive",
    );
    refused(
        "constraints = [\"x\", \"y\"]",
        "constraints = []",
        "heel_strike.constraints is empty",
    );
    refused(
        "constraints = [\"x\", \"y\"]",
        "constraints = [\"x\", \"y\", \"x\"]",
        "heel_strike.constraints names `x` twice",
    );
    refused(
        "release = [\"tx\", \"ty\"]",
        "release = [\"tx\", \"ty\", \"tx\"]",
        "heel_strike.release names `tx` twice",
    );
    refused(
        "constraints = [\"x\", \"y\"]",
        "constraints = [\"x\", \"y\"]\nrestitution = 2.0",
        "heel_strike.restitution must lie in [0, 1]",
    );
    refused(
        "min_hip_height_m = \"0.5 * leg_length_m\"",
        "min_hip_height_m = 100.0",
        "fall.min_hip_height_m = 100",
    );
    // Top-level keys, before the file's first table.
    let top = |line: &str| {
        let text = format!("{line}\n{COMPASS}");
        Scene::parse("changed.toml", &text)
            .and_then(|s| s.setup().map(|_| ()))
            .unwrap_err()
            .to_string()
    };
    let e = top("three_d_freedoms = [\"no_such_coordinate\"]");
    assert!(
        e.contains("three_d_freedoms: unknown coordinate `no_such_coordinate`"),
        "{e}"
    );
    let e = top("walk_start_scene = \"compas\"");
    assert!(e.contains("walk_start_scene `compas`"), "{e}");
}

#[test]
fn a_parameter_range_upside_down_is_refused() {
    // It once said "allowed range [0.5, -0.5]" at the first `--set`.
    let from = "min = -0.5\nmax = 0.5\naliases = [\"slope\"]";
    assert_eq!(COMPASS.matches(from).count(), 1);
    let text = COMPASS.replace(from, "min = 0.5\nmax = -0.5\naliases = [\"slope\"]");
    let e = Scene::parse("changed.toml", &text).unwrap_err().to_string();
    assert!(e.contains("min 0.5 is above max -0.5"), "{e}");
}

/// A bad `[[shape]]` was found only by `--animate` (exit 1, a 0-byte page left): now the
/// scene is refused when it is built, naming the shape.
#[test]
fn a_bad_shape_is_refused_at_load_naming_it() {
    let shape = |link: &str, radius: &str| {
        format!(
            "[fall]\n\n[[shape]]\nkind = \"rod\"\nname = \"leg rod\"\nlink = \"{link}\"\n\
             from_m = [0, 0, 0]\nto_m = [0, 1, 0]\nradius_m = {radius}\n"
        )
    };
    // keep [fall]'s own keys after the shape: the shape goes before the section header
    let with = |text: String| {
        let fall = COMPASS.find("[fall]\n").unwrap();
        let changed = format!(
            "{}{}{}",
            &COMPASS[..fall],
            text.replacen("[fall]\n\n", "", 1),
            &COMPASS[fall..]
        );
        Scene::parse("changed.toml", &changed)
            .and_then(|s| s.setup().map(|_| ()))
            .map_err(|e| e.to_string())
    };
    with(shape("stance_leg", "0.02")).unwrap();
    for (link, radius, needle) in [
        (
            "thigh",
            "0.02",
            "shape `leg rod` (rod): unknown link `thigh`",
        ),
        (
            "stance_leg",
            "0",
            "shape `leg rod` (rod): radius_m = 0 is not a positive length",
        ),
        ("stance_leg", "-1", "radius_m = -1 is not a positive length"),
        ("stance_leg", "\"nope_m\"", "nope_m"),
    ] {
        let e = with(shape(link, radius)).unwrap_err();
        assert!(e.contains(needle), "`{needle}` not in: {e}");
    }
    let ring = "[[shape]]\nkind = \"ring\"\nname = \"ring\"\nlink = \"hip\"\n\
                centre_m = [0, 0, 0]\nnormal = [0, 0, 0]\nradius_m = 0.1\n";
    let e = with(ring.to_string()).unwrap_err();
    assert!(e.contains("shape `ring` (ring): the normal is zero"), "{e}");
}
