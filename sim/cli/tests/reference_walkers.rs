//! The `walker` command against published numbers: Garcia et al.'s simplest walker.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::process::Command;

/// Garcia, Chatterjee, Ruina & Coleman (1998), long-period gait at slope 0.009, as published
/// (to 14 digits in their code accompanying the paper).
const GARCIA_THETA: f64 = 0.20031090049483;
const GARCIA_THETA_DOT: f64 = -0.19983247291764;

#[test]
fn walker_gait_json_reproduces_garcia_fixed_point_to_1e_8() {
    let out = Command::new(env!("CARGO_BIN_EXE_walker"))
        .args(["gait", "--scene", "simplest", "--json"])
        .output()
        .expect("walker runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    assert_eq!(v["scene"], "simplest");
    assert_eq!(v["converged"], true);
    let fp = &v["fixed_point"];
    let theta = fp["theta"].as_f64().unwrap();
    let theta_dot = fp["theta_dot"].as_f64().unwrap();
    let phi = fp["phi"].as_f64().unwrap();
    let phi_dot = fp["phi_dot"].as_f64().unwrap();
    assert!((theta - GARCIA_THETA).abs() < 1e-8, "theta {theta}");
    assert!(
        (theta_dot - GARCIA_THETA_DOT).abs() < 1e-8,
        "theta_dot {theta_dot}"
    );
    // At heel strike phi = 2 theta, and the collision law gives phi_dot = (1 - cos 2θ) θ_dot.
    assert!((phi - 2.0 * GARCIA_THETA).abs() < 1e-8, "phi {phi}");
    let phi_dot_ref = (1.0 - (2.0 * GARCIA_THETA).cos()) * GARCIA_THETA_DOT;
    assert!((phi_dot - phi_dot_ref).abs() < 1e-8, "phi_dot {phi_dot}");
    for key in [
        "eigenvalues",
        "max_abs_eigenvalue",
        "stable",
        "step_period_s",
        "step_length_m",
        "speed_m_s",
        "newton_iterations",
    ] {
        assert!(!v[key].is_null(), "missing {key}");
    }
    assert_eq!(v["stable"], true);
}
