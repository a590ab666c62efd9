//! The `walker` command line: output contract and bad-input handling.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use serde_json::Value;
use std::process::Output;

mod common;
use common::walker;

fn json(out: &Output) -> Value {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("valid json")
}

/// The JSON of a run that exited with `code` (3: the walk fell).
fn json_exiting(code: i32, out: &Output) -> Value {
    assert_eq!(
        out.status.code(),
        Some(code),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("valid json")
}

#[test]
fn bad_input_is_named_and_exits_2() {
    let cases: &[(&[&str], &str)] = &[
        (&["gait", "--scene", "nosuch"], "nosuch"),
        (
            &["gait", "--scene", "compass", "--set", "leg_mass=1"],
            "leg_mass",
        ),
        (
            &["gait", "--scene", "compass", "--set", "leg_mass_kg=heavy"],
            "heavy",
        ),
        (
            &["gait", "--scene", "compass", "--set", "leg_mass_kg=-2"],
            "leg_mass_kg",
        ),
        (
            &["gait", "--scene", "compass", "--set", "hip_mass_kg=NaN"],
            "hip_mass_kg",
        ),
        (
            &["gait", "--scene", "compass", "--set", "slope_rad"],
            "slope_rad",
        ),
        (
            &[
                "walk",
                "--scene",
                "compass",
                "--steps",
                "2",
                "--perturb",
                "knee=1",
            ],
            "knee",
        ),
        (
            &[
                "sweep", "--scene", "compass", "--param", "nope", "--from", "0", "--to", "1",
                "--points", "3",
            ],
            "nope",
        ),
        (
            &["gait", "--scene", "compass", "--integrator", "euler"],
            "euler",
        ),
        (&["walk", "--scene", "compass", "--steps", "many"], "many"),
        (&["sil", "--scene", "compass", "--steps", "2"], "ankle"),
        (
            &[
                "sil",
                "--scene",
                "wisse3d",
                "--steps",
                "2",
                "--fault",
                "drop:idx=5",
            ],
            "idx",
        ),
        (
            &[
                "sil",
                "--scene",
                "wisse3d",
                "--steps",
                "2",
                "--fault",
                "busoff:node=leftt",
            ],
            "leftt",
        ),
        (
            &[
                "sil",
                "--scene",
                "wisse3d",
                "--steps",
                "2",
                "--socketcand",
                "10.0.0.1:5",
            ],
            "loopback",
        ),
    ];
    for (args, needle) in cases {
        let out = walker(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle), "{args:?}: {err}");
    }
}

/// The library's error for an assignment without `=` names no option; the command names
/// `--set`, as it always has.
#[test]
fn a_set_without_a_value_names_the_option() {
    let out = walker(&["gait", "--scene", "compass", "--set", "slope_rad"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("`--set slope_rad`: expected key=value"),
        "{err}"
    );
}

#[test]
fn walk_json_reports_steps_and_the_first_failure() {
    let ok = json(&walker(&[
        "walk", "--scene", "compass", "--steps", "4", "--json",
    ]));
    assert_eq!(ok["steps_completed"], 4);
    assert!(ok["failure"].is_null());
    assert_eq!(ok["steps"].as_array().unwrap().len(), 4);
    // At the fixed point every step repeats the first.
    for s in ok["steps"].as_array().unwrap() {
        assert!(s["state_deviation"].as_f64().unwrap() < 1e-8);
    }
    // A walk that falls exits 3 (issue #14), its report unchanged.
    let fell = walker(&[
        "walk",
        "--scene",
        "compass",
        "--steps",
        "10",
        "--perturb",
        "stance_leg_dot=0.6",
        "--json",
    ]);
    assert_eq!(fell.status.code(), Some(3));
    let bad: Value = serde_json::from_slice(&fell.stdout).expect("valid json");
    assert_eq!(bad["steps_completed"], 0);
    assert_eq!(bad["failure"]["kind"], "fell_backward");
    assert_eq!(bad["failure"]["step"], 0);
    assert!(bad["failure"]["time_s"].as_f64().unwrap() > 0.0);
}

#[test]
fn walk_writes_its_trajectory_as_csv() {
    let dir = std::env::temp_dir().join(format!("walker-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("walk.csv");
    let out = walker(&[
        "walk",
        "--scene",
        "compass",
        "--steps",
        "2",
        "--out",
        path.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "step,time_s,stance_leg,swing_leg,stance_leg_dot,swing_leg_dot,hip_x_m,hip_y_m,hip_z_m"
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert!(rows.len() > 20);
    // The hip advances down the slope over two steps.
    assert!(rows.last().unwrap()[6] > rows[0][6] + 0.8);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn sweep_json_reports_points_and_stability_boundaries() {
    let v = json(&walker(&[
        "sweep", "--scene", "simplest", "--param", "slope", "--from", "0.012", "--to", "0.0165",
        "--points", "10", "--json",
    ]));
    let points = v["points"].as_array().unwrap();
    // The period-1 branch at the 10 grid values (the period-2 branch beyond the doubling
    // follows them).
    assert_eq!(points.iter().filter(|p| p["branch"] == 0).count(), 10);
    for p in points {
        assert!(p["value"].is_f64());
        assert!(p["max_abs_eigenvalue"].is_f64());
        assert!(p["stable"].is_boolean());
        assert!(p["fixed_point"]["theta"].is_f64());
    }
    let b = v["stability_boundaries"].as_array().unwrap();
    assert_eq!(b.len(), 1, "{b:?}");
    assert!((b[0]["value"].as_f64().unwrap() - 0.0151).abs() < 3e-4);
}

#[test]
fn scenes_lists_parameters_with_units_and_defaults() {
    let v = json(&walker(&["scenes", "--json"]));
    let names: Vec<&str> = v["scenes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    for n in ["simplest", "compass", "kneed2d"] {
        assert!(names.contains(&n));
    }
    let simplest = &v["scenes"][0];
    let slope = simplest["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "slope_rad")
        .unwrap();
    assert_eq!(slope["default"], 0.009);
    assert_eq!(slope["unit"], "rad");
    assert_eq!(slope["aliases"][0], "slope");
}

#[test]
fn compass_gait_json_has_goswami_angles() {
    let v = json(&walker(&["gait", "--scene", "compass", "--json"]));
    for k in ["stance", "swing", "stance_dot", "swing_dot"] {
        assert!(v["fixed_point"][k].is_f64(), "{k}");
    }
    assert_eq!(v["converged"], true);
    assert_eq!(v["stable"], true);
}

#[test]
fn a_walk_starts_from_a_state_file_and_a_bad_file_is_named() {
    let dir = std::env::temp_dir().join(format!("walker-start-state-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // The gait's own output is a valid start state, and gives the same walk as the default.
    let gait = walker(&["gait", "--scene", "compass", "--json"]);
    assert!(gait.status.success());
    let file = dir.join("gait.json");
    std::fs::write(&file, &gait.stdout).unwrap();
    let steps = |extra: &[&str]| {
        let mut args = vec!["walk", "--scene", "compass", "--steps", "2", "--json"];
        args.extend_from_slice(extra);
        json(&walker(&args))["steps"].clone()
    };
    let from_file = steps(&["--start-state", file.to_str().unwrap()]);
    assert_eq!(from_file, steps(&[]));
    // A partial file changes only what it names.
    let partial = dir.join("partial.json");
    std::fs::write(&partial, r#"{"stance_leg_dot": -1.2}"#).unwrap();
    let w = json(&walker(&[
        "walk",
        "--scene",
        "compass",
        "--steps",
        "1",
        "--json",
        "--start-state",
        partial.to_str().unwrap(),
    ]));
    assert_ne!(w["steps"], from_file);
    // Bad files: exit 2, naming the problem.
    for (content, needle) in [
        (r#"{"nosuch": 1.0}"#, "nosuch"),
        (r#"{"stance_leg_dot": "fast"}"#, "stance_leg_dot"),
        (r#"[1, 2]"#, "object"),
        ("not json", "not JSON"),
        ("{}", "no entry"),
    ] {
        let f = dir.join("bad.json");
        std::fs::write(&f, content).unwrap();
        let out = walker(&[
            "walk",
            "--scene",
            "compass",
            "--steps",
            "1",
            "--start-state",
            f.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{content}: {err}");
        assert!(err.contains(needle), "{content}: {err}");
    }
    let missing = walker(&[
        "walk",
        "--scene",
        "compass",
        "--steps",
        "1",
        "--start-state",
        "/nonexistent/x.json",
    ]);
    assert_eq!(missing.status.code(), Some(2));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn sil_takes_encoder_faults_and_names_a_bad_one() {
    // Bad specs: exit 2, the message names the flag and the offending part.
    for (spec, needle) in [
        ("jitter:side=left,at_ms=5", "jitter"),
        ("stuck:side=middle,from_ms=5", "middle"),
        ("stuck:side=left", "from_ms"),
        ("glitch:side=left,at_ms=soon", "soon"),
        ("parity:side=left,at_ms=5,extra=1", "extra"),
    ] {
        let out = walker(&[
            "sil",
            "--scene",
            "wisse3d",
            "--steps",
            "2",
            "--sensor-fault",
            spec,
        ]);
        assert_eq!(out.status.code(), Some(2), "{spec}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("--sensor-fault") && err.contains(needle),
            "{spec}: {err}"
        );
    }
    // Two faults (the flag repeats): a glitch on the left ankle (rate fault the same tick) and
    // a parity error on the right's encoder link (comms fault, detail 2). The walker falls in
    // its second step: exit code 3 (issue #14).
    let v = json_exiting(
        3,
        &walker(&[
            "sil",
            "--scene",
            "wisse3d",
            "--steps",
            "2",
            "--sensor-fault",
            "glitch:side=left,at_ms=300,delta_rad=0.1",
            "--sensor-fault",
            "parity:side=right,at_ms=400",
            "--json",
        ]),
    );
    let faults = v["node_faults"].as_array().expect("node_faults");
    let raised = |side: &str, code: &str| {
        faults
            .iter()
            .find(|f| f["side"] == side && f["code"] == code && f["raised"] == Value::Bool(true))
    };
    let rate = raised("Left", "EncoderRate").expect("the glitch raises EncoderRate");
    let t = rate["t_s"].as_f64().unwrap();
    assert!((0.3..0.3015).contains(&t), "{t}");
    let comms = raised("Right", "EncoderComms").expect("the parity error raises EncoderComms");
    assert_eq!(comms["detail"], 2);
    let t = comms["t_s"].as_f64().unwrap();
    assert!((0.4..0.4015).contains(&t), "{t}");
}

#[test]
fn sil_keeps_only_the_last_step_summaries_when_asked() {
    let all = json(&walker(&[
        "sil", "--scene", "wisse3d", "--steps", "12", "--json",
    ]));
    let kept = json(&walker(&[
        "sil",
        "--scene",
        "wisse3d",
        "--steps",
        "12",
        "--keep-steps",
        "3",
        "--json",
    ]));
    assert_eq!(all["steps"].as_array().unwrap().len(), 12);
    assert_eq!(kept["steps_completed"], 12);
    let k = kept["steps"].as_array().unwrap();
    assert_eq!(k.len(), 3);
    // The last three summaries, and the same gait figures (averaged over the last 10 steps).
    assert_eq!(k[0]["step"], 9);
    assert_eq!(kept["gait"], all["gait"]);
}
