#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]
//! The 3D walker on a slope (issue 26): its heading, cyclic on level ground, is a state of the
//! stride map on a slope, decided once by the scene builder.

use nalgebra::DVector;
use sim::analysis::homotopy::{nominal_gait, HomotopySettings};
use sim::analysis::limit_cycle::{Gait, NewtonSettings};
use sim::report::{GaitOutcome, GaitReport};
use sim::scene::{Scene, SceneError, Setup};
use sim::stride::walk::{walk, WalkRequest};

const THREE_D: [&str; 4] = [
    "wisse3d",
    "wisse3d-tuned",
    "wisse3d-uncompensated",
    "wisse3d-locked-compensator",
];
const HEADING: &str = "stance_foot_yaw";

fn scene_at(name: &str, slope: f64) -> Scene {
    let mut scene = Scene::load(name).unwrap();
    scene.set("slope_rad", slope).unwrap();
    scene
}

/// The nominal gait, found as `walker gait` finds it (from the scene's defaults).
fn nominal(scene: &Scene) -> (Setup, Gait) {
    let setup_for = |s: &Scene| -> Result<Setup, SceneError> { s.setup() };
    let (gait, _) = nominal_gait(
        scene,
        &setup_for,
        &NewtonSettings::default(),
        &HomotopySettings::default(),
    )
    .unwrap()
    .unwrap();
    (scene.setup().unwrap(), gait)
}

fn entry(setup: &Setup, v: &DVector<f64>, name: &str) -> f64 {
    let i = setup
        .walker
        .map_names()
        .iter()
        .position(|n| n == name)
        .unwrap();
    v[i]
}

#[test]
fn the_heading_is_cyclic_on_level_ground_and_a_state_on_a_slope() {
    for name in THREE_D {
        let level = scene_at(name, 0.0).setup().unwrap();
        let model = level.walker.model();
        let yaw = model.coord_index(HEADING).unwrap();
        assert_eq!(level.walker.relabel().cyclic, vec![yaw], "{name}");
        assert!(level.walker.relabel().symmetry_broken.is_empty(), "{name}");
        let level_names = level.walker.map_names();
        assert!(
            !level_names.iter().any(|n| n.starts_with(HEADING)),
            "{name}"
        );
        for slope in [0.01, -0.01, 1e-9] {
            let sloped = scene_at(name, slope).setup().unwrap();
            let r = sloped.walker.relabel();
            assert!(r.cyclic.is_empty(), "{name} {slope}");
            assert_eq!(r.symmetry_broken, vec![yaw], "{name} {slope}");
            let names = sloped.walker.map_names();
            assert_eq!(names.len(), level_names.len() + 2, "{name} {slope}");
            assert!(names.contains(&HEADING.to_owned()), "{name} {slope}");
            assert!(names.contains(&format!("{HEADING}_dot")), "{name} {slope}");
        }
    }
    // the 2D scenes declare nothing cyclic: their maps do not depend on the slope
    for name in ["simplest", "compass", "kneed2d", "wisse2d"] {
        let mut scene = Scene::load(name).unwrap();
        let before = scene.setup().unwrap().walker.map_names();
        assert!(scene.setup().unwrap().walker.relabel().cyclic.is_empty());
        if scene.values.contains_key("slope_rad") && !scene.is_unused("slope_rad") {
            scene.set("slope_rad", 0.02).unwrap();
            let w = scene.setup().unwrap().walker;
            assert_eq!(w.map_names(), before, "{name}");
            assert!(w.relabel().symmetry_broken.is_empty(), "{name}");
        }
    }
}

#[test]
fn a_declared_cyclic_coordinate_that_is_no_symmetry_is_refused() {
    let text = include_str!("../scenes/wisse3d.toml");
    for (coord, why) in [
        ("pelvis_yaw", "not a root joint"),
        ("stance_toe_pitch", "not a root joint"),
    ] {
        let bad = text.replace(
            "cyclic = [\"stance_foot_yaw\"]",
            &format!("cyclic = [\"{coord}\"]"),
        );
        assert_ne!(bad, text);
        let err = Scene::parse("bad.toml", &bad)
            .unwrap()
            .setup()
            .err()
            .unwrap()
            .to_string();
        assert!(err.contains(coord) && err.contains(why), "{err}");
    }
    let tilted = text.replace(
        "parent = \"ground\"\njoint = \"revolute\"\naxis = [0, 1, 0]",
        "parent = \"ground\"\njoint = \"revolute\"\naxis = [1, 0, 0]",
    );
    assert_ne!(tilted, text);
    let err = Scene::parse("tilted.toml", &tilted)
        .unwrap()
        .setup()
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("not about the floor's normal"), "{err}");
}

/// The gait `walker gait --scene wisse3d --set slope_rad=0.01` reports: the heading in the
/// fixed point, the heading's mode among the eigenvalues, and the energy balance closed by the
/// slope's work (the potential energy released is what the impacts and the damper take beyond
/// the actuator's work).
#[test]
fn wisse3d_gait_on_a_slope_has_its_heading_in_the_map_and_balances_energy() {
    let slope = 0.01;
    let scene = scene_at("wisse3d", slope);
    let (setup, gait) = nominal(&scene);
    let n = setup.walker.map_names().len();
    assert_eq!(n, 14);
    assert_eq!(gait.fixed_point.len(), n);
    assert_eq!(gait.eigenvalues.len(), n);
    assert!(gait.residual < 1e-9, "{}", gait.residual);
    // the heading is a state; its rate is 0 after heel strike (the landing foot cannot yaw)
    let heading = entry(&setup, &gait.fixed_point, HEADING);
    assert!(heading.abs() < 0.3, "{heading}");
    assert!(entry(&setup, &gait.fixed_point, &format!("{HEADING}_dot")).abs() < 1e-9);
    assert_eq!(gait.stride.heading_change_rad, 0.0);
    let report = GaitReport::new(
        &scene,
        &setup.walker,
        &setup.settings.integrator,
        &Ok(gait.clone()),
        None,
    );
    let GaitOutcome::Found(found) = report.outcome else {
        panic!("no gait")
    };
    // the heading's mode: an eigenvalue whose eigenvector is mostly the heading, near −1 (on
    // level ground the heading is neutral and the mirror flips it: −1 exactly)
    let heading_mode = found
        .eigenvalue_modes
        .iter()
        .find(|m| {
            m.dominant
                .first()
                .is_some_and(|(c, s)| c == HEADING && *s > 0.9)
        })
        .expect("a mode of the heading");
    assert!(
        heading_mode.eigenvalue[0] < -0.9 && heading_mode.eigenvalue[0] > -1.0,
        "{:?}",
        heading_mode.eigenvalue
    );
    // energy: M g sin(slope) × forward progress released per step
    let a = found.actuator.as_ref().unwrap();
    let mass = setup.walker.model().total_mass_kg();
    let released = mass * 9.81 * slope.sin() * found.progress_m_per_step;
    let w = a.slope_work_j_per_step.unwrap();
    assert!((w - released).abs() < 1e-6 * released, "{w} vs {released}");
    assert!(
        a.energy_balance_residual_j.abs() < 1e-4 * (found.impact_energy_loss_j),
        "residual {} J",
        a.energy_balance_residual_j
    );
    eprintln!(
        "slope {slope}: period {:.6} s, speed {:.6} m/s, max |λ| {:.6}, heading {heading:.6} rad, \
         heading mode {:?}, slope work {w:.6} J, balance residual {:.2e} J",
        found.step_period_s,
        found.speed_m_s,
        found.max_abs_eigenvalue,
        heading_mode.eigenvalue,
        a.energy_balance_residual_j
    );
    // and the walker walks 20 steps from it
    let (q, qd) = setup.walker.unpack(&gait.fixed_point);
    let walked = walk(
        &setup.walker,
        &q,
        &qd,
        WalkRequest::new(&setup.settings, 20),
    );
    assert_eq!(walked.steps.len(), 20);
    assert!(walked.failure.is_none());
}

/// Through the slope's path at a vanishing slope the level gait comes back: the same fixed
/// point (the heading aside), the heading at half the level gait's heading change per step
/// `Δ` (on level ground a stride takes the relabelled heading `ψ` to `Δ − ψ`, the mirror
/// flipping it: fixed point `Δ/2`, eigenvalue −1), and the level eigenvalues plus the
/// heading's, near −1, and its rate's, 0.
#[test]
fn a_vanishing_slope_reproduces_the_level_gait() {
    let level_scene = scene_at("wisse3d", 0.0);
    let level = level_scene.setup().unwrap();
    let level_gait = level.find_gait(&NewtonSettings::default()).unwrap();
    let slope_scene = scene_at("wisse3d", 1e-9);
    let sloped = slope_scene.setup().unwrap();
    // start at the level fixed point with heading Δ/2
    let (mut q, qd) = level.walker.unpack(&level_gait.fixed_point);
    let yaw = sloped.walker.model().coord_index(HEADING).unwrap();
    q[yaw.0] = level_gait.stride.heading_change_rad / 2.0;
    let guess = sim::analysis::limit_cycle::GaitGuess { q, qd };
    let gait = sim::analysis::limit_cycle::GaitSearch::new(
        &sloped.walker,
        &sloped.settings,
        &NewtonSettings::default(),
    )
    .find_from_guess(&guess)
    .unwrap();
    for (i, name) in level.walker.map_names().iter().enumerate() {
        let on_slope = entry(&sloped, &gait.fixed_point, name);
        assert!(
            (on_slope - level_gait.fixed_point[i]).abs() < 1e-5,
            "{name}: {on_slope} vs {}",
            level_gait.fixed_point[i]
        );
    }
    let heading = entry(&sloped, &gait.fixed_point, HEADING);
    assert!(
        (heading - level_gait.stride.heading_change_rad / 2.0).abs() < 1e-5,
        "{heading} vs {}",
        level_gait.stride.heading_change_rad / 2.0
    );
    // the level eigenvalues are among the slope's, and the extra ones are the heading's (−1)
    // and its rate's (0: the landing foot cannot yaw)
    let mut unmatched: Vec<_> = gait.eigenvalues.clone();
    for z in &level_gait.eigenvalues {
        let (k, d) = unmatched
            .iter()
            .enumerate()
            .map(|(k, w)| (k, (w - z).norm()))
            .fold((0, f64::INFINITY), |a, b| if b.1 < a.1 { b } else { a });
        assert!(d < 1e-4, "level eigenvalue {z} missing (nearest {d:e})");
        unmatched.remove(k);
    }
    assert_eq!(unmatched.len(), 2);
    let mut extra: Vec<f64> = unmatched.iter().map(|z| z.re).collect();
    extra.sort_by(f64::total_cmp);
    assert!((extra[0] + 1.0).abs() < 1e-4, "{extra:?}");
    assert!(
        extra[1].abs() < 1e-4 && unmatched.iter().all(|z| z.im.abs() < 1e-6),
        "{unmatched:?}"
    );
}

/// A state of the walker on a slope (its heading in the map) given to the walker on level
/// ground is refused with the reason, never unpacked into the wrong coordinates or a panic
/// (a sweep of the slope through 0 hit this).
#[test]
fn a_state_of_another_map_length_is_refused_not_misread() {
    let level = scene_at("wisse3d", 0.0).setup().unwrap();
    let sloped = scene_at("wisse3d", 0.01).setup().unwrap();
    let (n_level, n_sloped) = (
        2 * level.walker.map_coordinates().len(),
        2 * sloped.walker.map_coordinates().len(),
    );
    assert_eq!(n_sloped, n_level + 2);
    let newton = NewtonSettings::default();
    for (setup, len) in [(&level, n_sloped), (&sloped, n_level)] {
        let search =
            sim::analysis::limit_cycle::GaitSearch::new(&setup.walker, &setup.settings, &newton);
        let e = search.stride_map(&DVector::zeros(len)).unwrap_err();
        assert_eq!(e.kind, sim::stride::FailureKind::InvalidConfiguration);
        assert!(
            e.detail().contains(&format!("{len} entries")),
            "{}",
            e.detail()
        );
        let (q, _) = setup.walker.unpack(&DVector::zeros(len));
        assert!(q.iter().any(|v| v.is_nan()), "unpacked to NaN, not misread");
    }
}
