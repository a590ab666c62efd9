//! `walker sil --sensor-fault stuck:side=left,state=hold --json`: the fault applied is listed
//! as `sensor_faults_applied: [{side, kind, t_s}]`, and its outcome is the firmware's.
//!
//! With the Table I gait the firmware's default 0.27 s push never reaches `Hold`: the string
//! engages about 0.19 s before the other foot's heel strike releases it. The test writes a
//! 0.15 s push (`--firmware-param`), which ends in `Hold` before the release.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use serde_json::Value;

mod common;
use common::walker;

#[test]
fn sil_stuck_in_hold_lists_the_fault_applied() {
    let out = walker(&[
        "sil",
        "--scene",
        "wisse3d",
        "--steps",
        "3",
        "--sensor-fault",
        "stuck:side=left,state=hold",
        "--firmware-param",
        "push_duration_s=0.15",
        "--json",
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).expect("valid json");
    let applied = v["sensor_faults_applied"].as_array().expect("a list");
    assert_eq!(applied.len(), 1, "{applied:?}");
    let a = &applied[0];
    assert_eq!(a["side"], "Left");
    assert_eq!(a["kind"], "stuck");
    // Frozen at the first tick the left node is in Hold, after its push (0.5–1 s into the walk).
    let t = a["t_s"].as_f64().expect("t_s a number");
    assert!((0.5..1.0).contains(&t), "{t}");
    // Outcome: the servo holds still in Hold, so the frozen reading equals the held angle and
    // the stuck check (hold ticks count only while the spool turns) has no evidence: no node
    // fault, both nodes still enabled, the walk completes.
    assert_eq!(
        v["node_faults"],
        Value::Array(vec![]),
        "{}",
        v["node_faults"]
    );
    assert_eq!(v["nodes"]["Left"]["state"], "Enabled");
    assert_eq!(v["nodes"]["Left"]["fault_raises"], serde_json::json!({}));
    assert_eq!(v["steps_completed"], 3);
}
