//! The general engine against published numbers and hand-derived reference models.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use nalgebra::{DMatrix, Vector2};

/// Garcia et al.'s equations in their own variables (dimensionless, foot mass → 0),
/// integrated by a hand-written RK4: an independent model of the same walker.
fn garcia_stride(theta: f64, theta_dot: f64, slope: f64) -> Vector2<f64> {
    let f = |y: [f64; 4]| {
        let [th, thd, ph, phd] = y;
        let thdd = (th - slope).sin();
        [
            thd,
            thdd,
            phd,
            thdd + (thd * thd - (th - slope).cos()) * ph.sin(),
        ]
    };
    let rk4 = |y: [f64; 4], h: f64| {
        let add = |a: [f64; 4], b: [f64; 4], s: f64| {
            [
                a[0] + s * b[0],
                a[1] + s * b[1],
                a[2] + s * b[2],
                a[3] + s * b[3],
            ]
        };
        let k1 = f(y);
        let k2 = f(add(y, k1, h / 2.0));
        let k3 = f(add(y, k2, h / 2.0));
        let k4 = f(add(y, k3, h));
        let mut o = y;
        for i in 0..4 {
            o[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        o
    };
    let g = |y: [f64; 4]| y[2] - 2.0 * y[0];
    let mut y = [
        theta,
        theta_dot,
        2.0 * theta,
        (1.0 - (2.0 * theta).cos()) * theta_dot,
    ];
    let h = 1e-3;
    let mut t = 0.0;
    loop {
        let yn = rk4(y, h);
        if t > 1.0 && y[0] < 0.0 && (g(y) > 0.0) != (g(yn) > 0.0) {
            let (mut lo, mut hi) = (0.0, h);
            for _ in 0..80 {
                let m = 0.5 * (lo + hi);
                if (g(rk4(y, m)) > 0.0) == (g(y) > 0.0) {
                    lo = m;
                } else {
                    hi = m;
                }
            }
            let ye = rk4(y, 0.5 * (lo + hi));
            return Vector2::new(-ye[0], (2.0 * ye[0]).cos() * ye[1]);
        }
        y = yn;
        t += h;
    }
}

/// Garcia, Chatterjee, Ruina & Coleman (1998), long-period gait at slope 0.009, as published
/// (to 14 digits in their code accompanying the paper): θ and θ̇ after heel strike.
const GARCIA_THETA: f64 = 0.200_310_900_494_83;
const GARCIA_THETA_DOT: f64 = -0.199_832_472_917_64;

#[test]
fn simplest_fixed_point_matches_garcias_published_values_to_1e_9() {
    // Measured: 5.0e-11 (θ) and 8.7e-11 (θ̇); the bound is about ten times that (the CLI's
    // `walker_gait_json_reproduces_garcia_fixed_point_to_1e_8` checks the same through
    // `walker gait --json`).
    let (_, w) = common::walker("simplest");
    let g = common::gait(&w);
    let (theta, theta_dot) = (g.fixed_point[0], g.fixed_point[2]);
    let error = (theta - GARCIA_THETA)
        .abs()
        .max((theta_dot - GARCIA_THETA_DOT).abs());
    eprintln!(
        "θ {:e}, θ̇ {:e} from Garcia et al.'s values",
        theta - GARCIA_THETA,
        theta_dot - GARCIA_THETA_DOT
    );
    assert!(error < 1e-9, "θ {theta}, θ̇ {theta_dot}: {error:e}");
}

#[test]
fn simplest_eigenvalues_match_a_hand_written_model_of_garcias_equations() {
    let (_, w) = common::walker("simplest");
    let g = common::gait(&w);
    let v = Vector2::new(g.fixed_point[0], g.fixed_point[2]);
    let s = garcia_stride(v[0], v[1], 0.009);
    assert!(
        (s - v).amax() < 1e-9,
        "independent model maps the fixed point to {s:?}"
    );
    let d = 1e-6;
    let mut j = DMatrix::zeros(2, 2);
    for k in 0..2 {
        let mut a = v;
        a[k] += d;
        let mut b = v;
        b[k] -= d;
        j.set_column(
            k,
            &((garcia_stride(a[0], a[1], 0.009) - garcia_stride(b[0], b[1], 0.009)) / (2.0 * d)),
        );
    }
    let reference = j.complex_eigenvalues();
    let max_ref = reference.iter().map(|z| z.norm()).fold(0.0, f64::max);
    assert!(
        (g.max_abs_eigenvalue() - max_ref).abs() < 1e-6,
        "{} vs {max_ref}",
        g.max_abs_eigenvalue()
    );
    // The two nonzero eigenvalues of the 4x4 Jacobian are those of the 2x2 section map.
    for z in reference.iter() {
        assert!(
            g.eigenvalues.iter().any(|e| (e - z).norm() < 1e-6),
            "{z} not among {:?}",
            g.eigenvalues
        );
    }
}

#[test]
fn simplest_loses_stability_by_period_doubling_near_slope_0_0151() {
    // Garcia et al. (1998): the period-one gait becomes unstable at γ ≈ 0.0151.
    let (scene, _) = common::walker("simplest");
    let (points, bounds) =
        sim::analysis::continuation::sweep(&scene, "slope", 0.009, 0.0165, 16, &Default::default())
            .unwrap();
    assert!(points.iter().all(|p| p.gait.is_ok()));
    assert_eq!(bounds.len(), 1, "{bounds:?}");
    assert_eq!(bounds[0].change, "lost");
    assert!(
        (bounds[0].value - 0.0151).abs() < 2e-4,
        "{}",
        bounds[0].value
    );
    // Lost through −1: the critical eigenvalue is real and negative.
    let last = points.last().unwrap().gait.as_ref().unwrap();
    let critical = last
        .eigenvalues
        .iter()
        .max_by(|a, b| a.norm().total_cmp(&b.norm()))
        .unwrap();
    assert!(critical.re < -1.0 && critical.im.abs() < 1e-9, "{critical}");
}

#[test]
fn compass_gait_is_stable_with_goswami_leg_angles() {
    // Goswami et al. (1998), 10 kg hip, 5 kg legs at 0.5 m, slope 3°: a stable period-one gait
    // with the stance leg about 0.22 rad and the swing leg about 0.32 rad from the vertical.
    let (scene, w) = common::walker("compass");
    let g = common::gait(&w);
    let (q, qd) = common::start_state(&w, &g);
    let out: std::collections::BTreeMap<_, _> = scene
        .convention_outputs(&w.walker, &q, &qd)
        .unwrap()
        .into_iter()
        .collect();
    assert!((out["stance"] + 0.2188).abs() < 1e-3, "{out:?}");
    assert!((out["swing"] - 0.3238).abs() < 1e-3, "{out:?}");
    assert!(g.stable());
    assert!(g.max_abs_eigenvalue() > 0.5 && g.max_abs_eigenvalue() < 0.65);
}

#[test]
fn kneed_walker_has_a_stable_gait_with_knee_lock_before_heel_strike() {
    let (_, w) = common::walker("kneed2d");
    let g = common::gait(&w);
    assert!(g.stable(), "max |λ| = {}", g.max_abs_eigenvalue());
    let names: Vec<_> = g.stride.events.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(names, ["knee_lock:swing_knee", "heel_strike"]);
}
