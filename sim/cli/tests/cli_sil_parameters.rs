//! `walker sil` writes no firmware parameter unless asked (`--firmware-param NAME=VALUE`),
//! and its JSON shows per node the parameters in force as the node reported them over the
//! bus: `nodes.<side>.parameters`.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use serde_json::Value;
use sil::firmware_param::PARAM_NAMES;
use sil::FirmwareParam;

mod common;
use common::{stderr, walker};

/// The firmware's default of the parameter named `name`, as the wire's decimal.
fn default_of(name: &str) -> f64 {
    let (id, _) = PARAM_NAMES.iter().find(|(_, n)| *n == name).unwrap();
    FirmwareParam::new(*id, id.default_si())
        .unwrap()
        .wire_value_f64()
}

fn sil_json(extra: &[&str]) -> Value {
    let mut args = vec!["sil", "--scene", "wisse3d", "--steps", "2", "--json"];
    args.extend_from_slice(extra);
    let out = walker(&args);
    // 0, or 3 if the walker fell: the parameters are read at start-up either way.
    assert!(
        matches!(out.status.code(), Some(0 | 3)),
        "{:?}: {}",
        out.status,
        stderr(&out)
    );
    serde_json::from_slice(&out.stdout).expect("valid json")
}

#[test]
fn without_a_write_the_nodes_report_the_firmware_defaults() {
    let v = sil_json(&[]);
    assert_eq!(v["firmware_params_written"], serde_json::json!({}));
    for side in ["Left", "Right"] {
        let p = &v["nodes"][side]["parameters"];
        for name in ["taut_angle_rad", "extended_angle_rad", "push_duration_s"] {
            assert_eq!(
                p[name].as_f64(),
                Some(default_of(name)),
                "{side} {name}: {p}"
            );
        }
        assert_eq!(
            p["push_duration_s"].as_f64(),
            Some(0.27),
            "the chosen reading"
        );
        assert_eq!(p["effective_push_duration_s"], p["push_duration_s"]);
    }
    // The firmware's defaults and the scene's profile are one: nothing to warn about.
    assert_eq!(v["warnings"], serde_json::json!([]), "{}", v["warnings"]);
}

#[test]
fn a_written_parameter_is_the_one_the_nodes_report_and_the_difference_is_warned() {
    let v = sil_json(&[
        "--firmware-param",
        "taut_angle_rad=-0.07",
        "--firmware-param",
        "push_duration_s=0.25",
    ]);
    assert_eq!(
        v["firmware_params_written"],
        serde_json::json!({"taut_angle_rad": -0.07, "push_duration_s": 0.25})
    );
    for side in ["Left", "Right"] {
        let p = &v["nodes"][side]["parameters"];
        assert_eq!(p["taut_angle_rad"].as_f64(), Some(-0.07), "{p}");
        assert_eq!(p["push_duration_s"].as_f64(), Some(0.25), "{p}");
        assert_eq!(
            p["extended_angle_rad"].as_f64(),
            Some(default_of("extended_angle_rad"))
        );
        // The scene's ideal drive engages elsewhere: said, per node.
        let warned = v["warnings"].as_array().unwrap().iter().any(|w| {
            w.as_str()
                .unwrap()
                .starts_with(&format!("{side} node's taut_angle_rad -0.07"))
        });
        assert!(warned, "{}", v["warnings"]);
    }
}

#[test]
fn a_bad_firmware_parameter_is_refused_with_a_clear_error() {
    for (spec, needle) in [
        ("taut_angle=-0.07", "no firmware parameter `taut_angle`"),
        ("taut_angle_rad", "expected NAME=VALUE"),
        ("taut_angle_rad=soon", "`soon` is not a number"),
        ("taut_angle_rad=0.1", "outside its range -0.3 to 0 rad"),
        ("push_duration_s=NaN", "outside its range"),
    ] {
        let out = walker(&[
            "sil",
            "--scene",
            "wisse3d",
            "--steps",
            "2",
            "--firmware-param",
            spec,
        ]);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{spec}: {err}");
        assert!(
            err.contains("--firmware-param") && err.contains(needle),
            "{spec}: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
    // Two writes the nodes would not take together.
    for ([first, second], needle) in [
        (
            ["push_duration_s=0.2", "push_duration_s=0.25"],
            "push_duration_s is given twice",
        ),
        (
            ["extended_angle_rad=0.0", "taut_angle_rad=-0.03"],
            "must exceed the taut angle by at least 0.05 rad",
        ),
    ] {
        let out = walker(&[
            "sil",
            "--scene",
            "wisse3d",
            "--steps",
            "2",
            "--firmware-param",
            first,
            "--firmware-param",
            second,
        ]);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains(needle), "{err}");
    }
}
