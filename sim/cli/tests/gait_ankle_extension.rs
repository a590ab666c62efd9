//! `walker gait`'s `ankle_extension`: the push as it happens in the periodic stride, checked
//! against the same report's events and parameters and a quintic evaluated here.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::walker;
use serde_json::Value;

fn gait_json(scene: &str) -> Value {
    let out = walker(&["gait", "--scene", scene, "--json"]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    serde_json::from_slice(&out.stdout).unwrap()
}

fn event_time(v: &Value, name: &str) -> f64 {
    v["events"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["name"] == name)
        .unwrap_or_else(|| panic!("no {name} event"))["time_s"]
        .as_f64()
        .unwrap()
}

/// `s(x) = 10x³ − 15x⁴ + 6x⁵` on [0, 1].
fn quintic(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x.powi(3) * (10.0 - 15.0 * x + 6.0 * x * x)
}

#[test]
fn table_one_extension_is_cut_by_heel_strike_in_2d_and_3d() {
    for scene in ["wisse3d", "wisse2d"] {
        let v = gait_json(scene);
        let x = &v["ankle_extension"];
        let p = &v["parameters"];
        let (from, to, d) = (
            p["ankle_engage_rad"].as_f64().unwrap(),
            p["ankle_final_rad"].as_f64().unwrap(),
            p["ankle_extension_duration_s"].as_f64().unwrap(),
        );
        let (t0, t1) = (
            event_time(&v, "string_engaged"),
            event_time(&v, "heel_strike"),
        );
        assert_eq!(x["engaged_at_s"].as_f64().unwrap(), t0, "{scene}");
        assert_eq!(x["released_at_s"].as_f64().unwrap(), t1, "{scene}");
        assert_eq!(t1, v["step_period_s"].as_f64().unwrap(), "{scene}");
        assert_eq!(x["profile_duration_s"].as_f64().unwrap(), d);
        assert_eq!(x["final_angle_rad"].as_f64().unwrap(), to);
        let fraction = (t1 - t0) / d;
        assert!((x["profile_fraction_completed"].as_f64().unwrap() - fraction).abs() < 1e-12);
        let angle = x["angle_at_release_rad"].as_f64().unwrap();
        let by_hand = from + (to - from) * quintic(fraction);
        assert!(
            (angle - by_hand).abs() < 1e-9,
            "{scene}: {angle} vs {by_hand}"
        );
        // At Table I the heel strike cuts the push: the ankle stops short of its final angle.
        assert!(fraction < 1.0 && angle < to - 1e-3, "{scene}: {x}");
    }
}

#[test]
fn text_output_names_the_extension_and_walkers_without_ankles_have_none() {
    let out = walker(&["gait", "--scene", "wisse3d"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.lines()
            .any(|l| l.starts_with("ankle extension: string engaged at ")),
        "{text}"
    );
    let v = gait_json("compass");
    assert!(v.get("ankle_extension").is_none(), "{v}");
}
