//! The fixed-size stride (`sim::stride`'s `fast`) against the general stride loop, its
//! reference: which strides take it, strides from perturbed starts (heel-strike state, stride
//! time, events, next state), recorded and replayed schedules, recorded samples, a fall, and
//! whole gaits (fixed point and eigenvalues).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use nalgebra::DVector;
use sim::analysis::limit_cycle::{GaitSearch, NewtonSettings};
use sim::scene::{Scene, Setup};
use sim::stride::EvaluationPath;
use sim::stride::{
    Schedule, StepSchedule, StrideOptions, StrideRequest, StrideResult, StrideSettings,
};

/// The scenes the fixed-size stride covers.
const COVERED: [&str; 3] = ["compass", "simplest", "kneed2d"];

fn setup(name: &str) -> Setup {
    Scene::load(name).unwrap().setup().unwrap()
}

fn with_path(s: &StrideSettings, path: EvaluationPath) -> StrideSettings {
    let mut r = s.clone();
    r.evaluation = path;
    r
}

/// A deterministic pseudo-random number in [-1, 1).
fn noise(k: &mut u64) -> f64 {
    *k = k
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    ((*k >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

/// Largest difference between two strides: heel-strike state, next state, stride time, event
/// times and states, step, lift velocity, impact loss (the events' names must be the same).
fn difference(a: &StrideResult, b: &StrideResult) -> f64 {
    let names = |r: &StrideResult| r.events.iter().map(|e| e.name.clone()).collect::<Vec<_>>();
    assert_eq!(names(a), names(b));
    let mut d = (a.duration_s - b.duration_s).abs();
    d = d.max((&a.pre_impact.q - &b.pre_impact.q).amax());
    d = d.max((&a.pre_impact.qd - &b.pre_impact.qd).amax());
    d = d.max((&a.q_next - &b.q_next).amax());
    d = d.max((&a.qd_next - &b.qd_next).amax());
    for (x, y) in a.events.iter().zip(&b.events) {
        d = d.max((x.t_stride_s - y.t_stride_s).abs());
    }
    for ((x0, x1), (y0, y1)) in a.event_states.iter().zip(&b.event_states) {
        d = d.max((&x0.q - &y0.q).amax()).max((&x1.qd - &y1.qd).amax());
    }
    d = d.max((a.step_m - b.step_m).amax());
    d = d.max((a.lift_velocity_m_s - b.lift_velocity_m_s).abs());
    d = d.max((a.heading_change_rad - b.heading_change_rad).abs());
    d.max((a.impact_energy_loss_j - b.impact_energy_loss_j).abs())
}

#[test]
fn the_covered_scenes_take_it_and_the_others_do_not() {
    for name in COVERED {
        let s = setup(name);
        let w = &s.walker;
        assert!(
            w.takes_fixed_size_stride(&s.settings, StrideOptions::default()),
            "{name}"
        );
        for path in [EvaluationPath::General, EvaluationPath::GeneralLoop] {
            assert!(
                !w.takes_fixed_size_stride(&with_path(&s.settings, path), StrideOptions::default())
            );
        }
        let contact = StrideOptions {
            contact: true,
            ..Default::default()
        };
        assert!(!w.takes_fixed_size_stride(&s.settings, contact), "{name}");
        let dopri =
            s.settings
                .with_integrator(sim::engine::integrators::IntegratorChoice::Dopri5 {
                    rtol: 1e-10,
                    atol: 1e-10,
                    h_max_s: 0.05,
                });
        assert!(
            !w.takes_fixed_size_stride(&dopri, StrideOptions::default()),
            "{name}"
        );
    }
    // The ankle string (wisse2d) and the 3D walker are left to the general loop.
    for name in ["wisse2d", "wisse3d"] {
        let s = setup(name);
        assert!(
            !s.walker
                .takes_fixed_size_stride(&s.settings, StrideOptions::default()),
            "{name}"
        );
    }
}

#[test]
fn strides_from_perturbed_starts_equal_the_general_loop() {
    let mut seed = 11u64;
    for name in COVERED {
        let s = setup(name);
        let w = &s.walker;
        let (q0, qd0) = (s.guess.q.clone(), s.guess.qd.clone());
        let (mut worst_loop, mut worst_general, mut compared) = (0.0f64, 0.0f64, 0);
        for trial in 0..8 {
            // The simplest walker's gait (slope 0.004) tolerates smaller perturbations.
            let size = if name == "simplest" { 1e-3 } else { 1e-2 };
            let scale = if trial == 0 { 0.0 } else { size };
            let map = w.map_coordinates();
            let mut q = q0.clone();
            let mut qd = qd0.clone();
            for c in &map {
                q[c.0] += scale * noise(&mut seed);
                qd[c.0] += 5.0 * scale * noise(&mut seed);
            }
            for rtol in [1e-12, 1e-10, 1e-8] {
                let fast = s.settings.with_integrator(
                    s.settings
                        .integrator
                        .with_tolerance_or_step(Some(rtol), None),
                );
                let general_loop = with_path(&fast, EvaluationPath::GeneralLoop);
                let general = with_path(&fast, EvaluationPath::General);
                let a = w.stride(&q, &qd, StrideRequest::new(&fast));
                let b = w.stride(&q, &qd, StrideRequest::new(&general_loop));
                let c = w.stride(&q, &qd, StrideRequest::new(&general));
                match (a, b, c) {
                    (Ok(a), Ok(b), Ok(c)) => {
                        worst_loop = worst_loop.max(difference(&a, &b));
                        worst_general = worst_general.max(difference(&a, &c));
                        assert_eq!(
                            a.evaluations, b.evaluations,
                            "{name} trial {trial} {rtol:e}"
                        );
                        assert_eq!(a.damping_dissipation_j, b.damping_dissipation_j);
                        compared += 1;
                    }
                    (Err(a), Err(b), _) => assert_eq!(a.kind, b.kind, "{name}"),
                    (a, b, _) => panic!(
                        "{name} trial {trial}: fast {:?} against {:?}",
                        a.err(),
                        b.err()
                    ),
                }
            }
        }
        eprintln!(
            "{name}: {compared} strides, fast − general loop (planar evaluation) {worst_loop:e}, \
             fast − general engine {worst_general:e}"
        );
        assert!(compared >= 12, "{name}: {compared}");
        // The same loop and evaluation: equal but for the heel strike's rounding (measured
        // 4.2e-14, simplest); against the general engine 5.3e-14 (compass). Bounds about ten
        // times those.
        assert!(worst_loop < 4e-13, "{name}: {worst_loop:e}");
        assert!(worst_general < 5e-13, "{name}: {worst_general:e}");
    }
}

#[test]
fn schedules_and_recorded_samples_equal_the_general_loop() {
    for name in COVERED {
        let s = setup(name);
        let w = &s.walker;
        let reference = with_path(&s.settings, EvaluationPath::GeneralLoop);
        let (q, qd) = (&s.guess.q, &s.guess.qd);
        let (mut ra, mut rb) = (StepSchedule::default(), StepSchedule::default());
        let a = w
            .stride(
                q,
                qd,
                StrideRequest::new(&s.settings)
                    .schedule(Schedule::Record(&mut ra))
                    .recording(),
            )
            .unwrap();
        let b = w
            .stride(
                q,
                qd,
                StrideRequest::new(&reference)
                    .schedule(Schedule::Record(&mut rb))
                    .recording(),
            )
            .unwrap();
        assert_eq!(ra.phases.len(), rb.phases.len(), "{name}");
        for (x, y) in ra.phases.iter().zip(&rb.phases) {
            assert_eq!(x.len(), y.len(), "{name}");
            let d = x
                .iter()
                .zip(y)
                .map(|(u, v)| (u - v).abs())
                .fold(0.0, f64::max);
            assert!(d < 1e-14, "{name}: steps {d:e}");
        }
        assert_eq!(a.trajectory.len(), b.trajectory.len(), "{name}");
        assert!(a.trajectory.len() > 5);
        for (x, y) in a.trajectory.iter().zip(&b.trajectory) {
            assert!(
                (x.t_s - y.t_s).abs() < 1e-13 && (&x.q - &y.q).amax() < 1e-12,
                "{name}"
            );
        }
        // Replayed from a perturbed start, as the stride Jacobian does.
        let mut qp = q.clone();
        qp[0] += 1e-6;
        let c = w
            .stride(
                &qp,
                qd,
                StrideRequest::new(&s.settings).schedule(Schedule::Replay(&ra)),
            )
            .unwrap();
        let d = w
            .stride(
                &qp,
                qd,
                StrideRequest::new(&reference).schedule(Schedule::Replay(&ra)),
            )
            .unwrap();
        let diff = difference(&c, &d);
        assert!(diff < 1e-13, "{name}: replayed {diff:e}");
    }
}

#[test]
fn a_fall_is_handed_back_to_the_general_loop() {
    // The compass thrown backward: the fixed-size stride meets the fall (hip moving back) and
    // hands the stride to the general loop, which reports it exactly as without it.
    let s = setup("compass");
    let w = &s.walker;
    let mut qd = s.guess.qd.clone();
    qd *= -1.0;
    let reference = with_path(&s.settings, EvaluationPath::GeneralLoop);
    let a = w
        .stride(&s.guess.q, &qd, StrideRequest::new(&s.settings))
        .unwrap_err();
    let b = w
        .stride(&s.guess.q, &qd, StrideRequest::new(&reference))
        .unwrap_err();
    assert_eq!(a, b);
    // A recorded sink keeps the general loop's samples only.
    let (mut sa, mut sb) = (Vec::new(), Vec::new());
    let _ = w.stride(
        &s.guess.q,
        &qd,
        StrideRequest::new(&s.settings).recording().sink(&mut sa),
    );
    let _ = w.stride(
        &s.guess.q,
        &qd,
        StrideRequest::new(&reference).recording().sink(&mut sb),
    );
    assert_eq!(sa, sb);
    assert!(!sa.is_empty());
}

#[test]
fn gaits_equal_the_general_loop() {
    for name in COVERED {
        let s = setup(name);
        let w = &s.walker;
        let newton = NewtonSettings::default();
        let v0 = w.pack(&s.guess.q, &s.guess.qd);
        let reference = with_path(&s.settings, EvaluationPath::GeneralLoop);
        let ga = GaitSearch::new(w, &s.settings, &newton).find(&v0).unwrap();
        let gb = GaitSearch::new(w, &reference, &newton).find(&v0).unwrap();
        let fp = (&ga.fixed_point - &gb.fixed_point).amax();
        let sort = |g: &sim::analysis::limit_cycle::Gait| {
            let mut e: Vec<_> = g.eigenvalues.iter().map(|z| (z.re, z.im)).collect();
            e.sort_by(|x, y| x.partial_cmp(y).unwrap());
            e
        };
        let ev = sort(&ga)
            .iter()
            .zip(&sort(&gb))
            .map(|(x, y)| (x.0 - y.0).hypot(x.1 - y.1))
            .fold(0.0f64, f64::max);
        eprintln!("{name}: fixed point {fp:e}, eigenvalues {ev:e}");
        // Measured: fixed points 1.5e-14 (compass), eigenvalues 5.4e-9 (simplest); bounds about
        // ten times those.
        assert!(fp < 1.5e-13, "{name}: {fp:e}");
        // The fixed-size heel strike (closed-form relabelling, one KKT solve) differs from the
        // general one by rounding (1e-14): the central differences (δ = 1e-6) move the
        // eigenvalues by about 1e-14 / 1e-6 · |J|, their own noise (docs/accuracy.md).
        assert!(ev < 5e-8, "{name}: {ev:e}");
        let _ = DVector::<f64>::zeros(0);
    }
}

#[test]
fn the_closed_form_strides_and_gaits_equal_the_link_pass() {
    // The two-link chains with finite bodies (compass) evaluate by their closed form
    // (`planar/two_link.rs`); `LinkPass` runs the same fixed-size stride on the planar link
    // pass: strides from perturbed starts at three tolerances, then whole gaits.
    let mut seed = 29u64;
    for name in ["compass"] {
        let s = setup(name);
        let w = &s.walker;
        assert!(w.takes_fixed_size_stride(
            &with_path(&s.settings, EvaluationPath::LinkPass),
            StrideOptions::default()
        ));
        let (mut worst, mut compared) = (0.0f64, 0);
        for trial in 0..8 {
            let scale = if trial == 0 { 0.0 } else { 1e-2 };
            let (mut q, mut qd) = (s.guess.q.clone(), s.guess.qd.clone());
            for c in &w.map_coordinates() {
                q[c.0] += scale * noise(&mut seed);
                qd[c.0] += 5.0 * scale * noise(&mut seed);
            }
            for rtol in [1e-12, 1e-10, 1e-8] {
                let closed = s.settings.with_integrator(
                    s.settings
                        .integrator
                        .with_tolerance_or_step(Some(rtol), None),
                );
                let link_pass = with_path(&closed, EvaluationPath::LinkPass);
                match (
                    w.stride(&q, &qd, StrideRequest::new(&closed)),
                    w.stride(&q, &qd, StrideRequest::new(&link_pass)),
                ) {
                    (Ok(a), Ok(b)) => {
                        worst = worst.max(difference(&a, &b));
                        assert_eq!(a.evaluations, b.evaluations, "{name} {trial} {rtol:e}");
                        compared += 1;
                    }
                    (Err(a), Err(b)) => assert_eq!(a.kind, b.kind, "{name}"),
                    (a, b) => panic!("{name} {trial}: {:?} against {:?}", a.err(), b.err()),
                }
            }
        }
        let newton = NewtonSettings::default();
        let v0 = w.pack(&s.guess.q, &s.guess.qd);
        let link_pass = with_path(&s.settings, EvaluationPath::LinkPass);
        let ga = GaitSearch::new(w, &s.settings, &newton).find(&v0).unwrap();
        let gb = GaitSearch::new(w, &link_pass, &newton).find(&v0).unwrap();
        let fp = (&ga.fixed_point - &gb.fixed_point).amax();
        let ev = ga
            .eigenvalues
            .iter()
            .map(|x| {
                gb.eigenvalues
                    .iter()
                    .map(|y| (x - y).norm())
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0f64, f64::max);
        eprintln!(
            "{name}: {compared} strides, closed form − link pass {worst:e}; gait: fixed point \
             {fp:e}, eigenvalues {ev:e}"
        );
        assert!(compared >= 12, "{name}: {compared}");
        // Measured: strides 4.4e-14, fixed point 1.3e-15, eigenvalues 3.5e-9; bounds about ten
        // times those.
        assert!(worst < 5e-13, "{name}: {worst:e}");
        assert!(fp < 2e-14, "{name}: {fp:e}");
        // Central differences (δ = 1e-6) of strides that differ by rounding: their own noise.
        assert!(ev < 5e-8, "{name}: {ev:e}");
    }
}
