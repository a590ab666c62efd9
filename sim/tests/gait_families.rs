//! The census, orbit diagram and stability map of the engine: their settings checks, and
//! that the parallel orbit diagram is the sequential one and does not depend on the number of
//! threads. (Their physics is pinned against the hand-written Garcia model in
//! `sim/cli/tests/gait_families.rs`.)
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use sim::analysis::census::{census, CensusSettings};
use sim::analysis::homotopy::{at_defaults, is_at_defaults, SetupFor};
use sim::analysis::limit_cycle::NewtonSettings;
use sim::analysis::orbit_diagram::{linspace, orbit_diagram, Attractor, OrbitError, OrbitSettings};
use sim::analysis::stability_map::{stability_map, Axis};
use sim::scene::{Scene, SceneError, Setup};

fn setup(s: &Scene) -> Result<Setup, SceneError> {
    s.setup()
}

#[test]
fn orbit_settings_that_cannot_classify_are_refused() {
    let ok = OrbitSettings::default();
    assert!(ok.validate().is_ok());
    for bad in [
        OrbitSettings {
            max_period: 0,
            ..ok
        },
        OrbitSettings {
            window_strides: 2 * ok.max_period - 1,
            ..ok
        },
        OrbitSettings {
            max_strides: ok.transient_strides,
            ..ok
        },
        OrbitSettings {
            chunk_points: 0,
            ..ok
        },
        OrbitSettings {
            period_tolerance: f64::NAN,
            ..ok
        },
        OrbitSettings {
            cycle_contrast: 0.0,
            ..ok
        },
        OrbitSettings {
            max_strides_converging: ok.max_strides - 1,
            ..ok
        },
        OrbitSettings {
            converging_factor: 1.5,
            ..ok
        },
    ] {
        assert!(
            matches!(bad.validate(), Err(OrbitError::Settings(_))),
            "{bad:?}"
        );
    }
    assert_eq!(linspace(1.0, 2.0, 3), vec![1.0, 1.5, 2.0]);
    assert_eq!(linspace(1.0, 2.0, 1), vec![1.0]);
}

#[test]
fn an_unknown_parameter_or_a_value_out_of_range_is_refused_before_any_work() {
    let scene = Scene::load("simplest").unwrap();
    let f: &SetupFor<'_> = &setup;
    let newton = NewtonSettings::default();
    let never = || panic!("no value may be computed");
    let e = orbit_diagram(
        &scene,
        f,
        "nope",
        &[0.01],
        &newton,
        &OrbitSettings::default(),
        &never,
    );
    assert!(matches!(
        e,
        Err(OrbitError::Scene(SceneError::UnknownParameter { .. }))
    ));
    let e = orbit_diagram(
        &scene,
        f,
        "slope",
        &[0.01, 0.9],
        &newton,
        &OrbitSettings::default(),
        &never,
    );
    assert!(matches!(
        e,
        Err(OrbitError::Scene(SceneError::OutOfRange { .. }))
    ));
    let x = Axis {
        name: "slope".into(),
        values: vec![0.01],
    };
    let y = Axis {
        name: "leg_length_m".into(),
        values: vec![-1.0],
    };
    let e = stability_map(&scene, f, &x, &y, &newton, &Default::default(), &never);
    assert!(matches!(e, Err(SceneError::OutOfRange { .. })));
}

#[test]
fn the_parallel_orbit_diagram_is_the_sequential_one_on_any_number_of_threads() {
    // The period-4 and period-8 windows of the simplest walker, where a seeded chunk start
    // must land on the same attractor as the previous value's.
    let scene = Scene::load("simplest").unwrap();
    let f: &SetupFor<'_> = &setup;
    let newton = NewtonSettings::default();
    let values = linspace(0.0176, 0.0182, 7);
    let run = |threads: usize, chunk_points: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let settings = OrbitSettings {
            chunk_points,
            ..OrbitSettings::default()
        };
        pool.install(|| orbit_diagram(&scene, f, "slope", &values, &newton, &settings, &|| {}))
            .unwrap()
    };
    let sequential = run(1, values.len());
    let chunked_1 = run(1, 2);
    let chunked_2 = run(2, 2);
    let periods = |d: &[sim::analysis::orbit_diagram::OrbitPoint]| {
        d.iter()
            .map(|p| match p.attractor {
                Attractor::Periodic { period } => period,
                _ => 0,
            })
            .collect::<Vec<_>>()
    };
    let seq = periods(&sequential);
    assert!(seq.contains(&4) && seq.contains(&8), "{seq:?}");
    assert_eq!(periods(&chunked_1), periods(&sequential));
    // The same cycles, to the period tolerance, and bit for bit across thread counts.
    for ((a, b), c) in sequential.iter().zip(&chunked_1).zip(&chunked_2) {
        assert_eq!(b.states, c.states, "threads change nothing at {}", a.value);
        let lo = |p: &sim::analysis::orbit_diagram::OrbitPoint| {
            p.states.iter().map(|v| v[0]).fold(f64::INFINITY, f64::min)
        };
        assert!(
            (lo(a) - lo(b)).abs() < 1e-6,
            "{} {} {}",
            a.value,
            lo(a),
            lo(b)
        );
    }
    assert!(chunked_1.iter().step_by(2).all(|p| p.seeded));
}

#[test]
fn census_at_the_defaults_starts_with_the_guess_gait_and_lists_each_gait_once() {
    let scene = Scene::load("compass").unwrap();
    assert!(is_at_defaults(&scene));
    let f: &SetupFor<'_> = &setup;
    let newton = NewtonSettings::default();
    let c = census(&scene, f, &newton, &CensusSettings::default()).unwrap();
    let from_guess = scene.setup().unwrap().find_gait(&newton).unwrap();
    assert!(c.guess_error.is_none());
    assert!(c
        .gaits
        .iter()
        .any(|g| (&g.fixed_point - &from_guess.fixed_point).amax() < 1e-9));
    for (i, a) in c.gaits.iter().enumerate() {
        for b in &c.gaits[i + 1..] {
            assert!((&a.fixed_point - &b.fixed_point).amax() >= 1e-6);
            assert!(a.stride.duration_s >= b.stride.duration_s);
        }
    }
    let mut moved = scene.clone();
    moved.set("slope", 0.03).unwrap();
    assert!(!is_at_defaults(&moved));
    assert!(is_at_defaults(&at_defaults(&moved).unwrap()));
}

#[test]
fn the_secant_step_refuses_a_jump_to_another_branch() {
    // The one guarded secant step (census homotopy, stability-map rows): from the short-step
    // gait of the simplest walker at slope 0.015 Newton converges back to it; recorded with a
    // step period 25 % longer (as the long-period gait's), the same result is a jump.
    let mut scene = Scene::load("simplest").unwrap();
    scene.set("slope", 0.015).unwrap();
    let setup = scene.setup().unwrap();
    let newton = NewtonSettings::default();
    let guard = sim::analysis::homotopy::HomotopySettings::default();
    let short = setup.find_gait(&newton).unwrap();
    let mut path = sim::analysis::homotopy::Secant::default();
    assert!(path.step(0.015, &setup, &newton, &guard).is_none());
    path.push(0.015, &short);
    let again = path.step(0.015, &setup, &newton, &guard).unwrap().unwrap();
    assert!((&again.fixed_point - &short.fixed_point).amax() < 1e-9);
    let mut disguised = short.clone();
    disguised.stride.duration_s *= 1.25;
    let mut path = sim::analysis::homotopy::Secant::default();
    path.push(0.015, &disguised);
    assert!(path.step(0.015, &setup, &newton, &guard).unwrap().is_err());
}
