//! `walker gait --json` lists the stride Jacobian (rows and columns named, in the fixed
//! point's order) and an eigenvector per eigenvalue; each pair satisfies J·v = λ·v.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use serde_json::Value;

fn gait_json(args: &[&str]) -> Value {
    let out = common::walker(args);
    assert!(out.status.success(), "{}", common::stderr(&out));
    serde_json::from_slice(&out.stdout).expect("json")
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect()
}

/// Checks the Jacobian's names against `fixed_point` and each eigenpair: |J v − λ v|∞ below
/// `tolerance`, v of unit 2-norm.
fn check_eigenpairs(v: &Value, tolerance: f64) {
    let names: Vec<&str> = v["jacobian"]["names"]
        .as_array()
        .expect("names")
        .iter()
        .map(|n| n.as_str().expect("name"))
        .collect();
    // In fixed_point's order: its keys are sorted, and the names are among them, sorted.
    let fixed_point = v["fixed_point"].as_object().expect("fixed_point");
    let keys: Vec<&str> = fixed_point.keys().map(String::as_str).collect();
    let in_keys_order: Vec<&str> = keys.iter().copied().filter(|k| names.contains(k)).collect();
    assert_eq!(in_keys_order, names);
    let n = names.len();
    assert!(n >= 4, "{names:?}");
    let j: Vec<Vec<f64>> = v["jacobian"]["rows"]
        .as_array()
        .expect("rows")
        .iter()
        .map(numbers)
        .collect();
    assert_eq!(j.len(), n);
    assert!(j.iter().all(|r| r.len() == n));
    let eigenvalues = v["eigenvalues"].as_array().expect("eigenvalues");
    let eigenvectors = v["eigenvectors"].as_array().expect("eigenvectors");
    assert_eq!(eigenvalues.len(), n);
    assert_eq!(eigenvectors.len(), n);
    for (lambda, vector) in eigenvalues.iter().zip(eigenvectors) {
        let [l_re, l_im] = numbers(lambda)[..] else {
            panic!("eigenvalue {lambda}")
        };
        let (re, im) = (numbers(&vector["re"]), numbers(&vector["im"]));
        assert_eq!((re.len(), im.len()), (n, n));
        let norm: f64 = re.iter().chain(&im).map(|x| x * x).sum::<f64>().sqrt();
        assert!((norm - 1.0).abs() < 1e-9, "norm {norm}");
        for (i, row) in j.iter().enumerate() {
            let jv_re: f64 = row.iter().zip(&re).map(|(a, x)| a * x).sum();
            let jv_im: f64 = row.iter().zip(&im).map(|(a, x)| a * x).sum();
            let lv_re = l_re * re[i] - l_im * im[i];
            let lv_im = l_re * im[i] + l_im * re[i];
            let residual = (jv_re - lv_re).hypot(jv_im - lv_im);
            assert!(
                residual < tolerance,
                "λ = {l_re} {l_im:+}i, row {}: |Jv − λv| = {residual:e}",
                names[i]
            );
        }
    }
}

#[test]
fn compass_gait_eigenvectors_satisfy_the_jacobian() {
    let v = gait_json(&["gait", "--scene", "compass", "--json"]);
    check_eigenpairs(&v, 1e-8);
    // The fixed point's own entries are among the Jacobian's names.
    assert!(v["jacobian"]["names"]
        .as_array()
        .unwrap()
        .iter()
        .any(|n| n == "stance_leg_dot"));
}

#[test]
fn wisse3d_gait_eigenvectors_satisfy_the_jacobian_including_complex_pairs() {
    let v = gait_json(&["gait", "--scene", "wisse3d", "--json"]);
    let complex = v["eigenvalues"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|z| z[1].as_f64().unwrap() != 0.0)
        .count();
    assert!(complex >= 2, "wisse3d has complex multipliers");
    check_eigenpairs(&v, 1e-8);
}

#[test]
fn a_gait_not_found_has_null_jacobian_and_eigenvectors() {
    let out = common::walker(&[
        "gait",
        "--scene",
        "compass",
        "--newton-max-iter",
        "1",
        "--json",
    ]);
    assert_eq!(out.status.code(), Some(1), "{}", common::stderr(&out));
    let v: Value = serde_json::from_slice(&out.stdout).expect("json");
    assert_eq!(v["converged"], false);
    assert!(v["jacobian"].is_null());
    assert!(v["eigenvectors"].is_null());
}
