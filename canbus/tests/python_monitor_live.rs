//! The Python bus monitor, as a separate process over real TCP on 127.0.0.1, watches the
//! running demo bus through its socketcand server, sends an emergency stop to the right
//! ankle through it, and decodes heartbeats from both ankles with their states.
//!
//! Needs the project's venv (`scripts/python-venv`, through `walker_tools::python_venv`). When
//! it cannot be created the test is skipped with a message — unless `WALKER_REQUIRE_PYTHON=1`
//! (set by `scripts/test-all`), in which case it fails.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use std::io::{BufReader, Read};
use std::process::{Command, Stdio};
use std::time::Duration;
use walker_tools::announced::announced_address;

use canbus::candump::{read_log, LogFrame};
use walker_tools::python_venv::PythonVenv;

#[test]
fn python_monitor_decodes_the_live_demo_over_socketcand() {
    let venv = PythonVenv::for_test("python_monitor_live").unwrap_or_else(|e| panic!("{e}"));
    let Some(venv) = venv else { return };
    let dir = std::env::temp_dir().join(format!("canbus-live-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let demo_log = dir.join("demo.log");
    let rec_log = dir.join("monitor.log");

    let mut demo = Command::new(env!("CARGO_BIN_EXE_canbus-demo"))
        .args([
            "--seconds",
            "3",
            "--socketcand",
            "127.0.0.1:0",
            "--wait-client",
            "60",
            // the monitor sends an emergency stop
            "--socketcand-allow-send",
        ])
        .arg("--candump")
        .arg(&demo_log)
        .arg("--json")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = BufReader::new(demo.stderr.take().unwrap());
    let addr = announced_address(
        &mut err,
        "socketcand: listening on ",
        Duration::from_secs(30),
    )
    .unwrap_or_else(|last| {
        let _ = demo.kill();
        panic!("demo did not report its address: {last}")
    });
    let port = addr.rsplit(':').next().unwrap().to_string();

    let monitor = venv
        .monitor()
        .args([
            "--interface",
            "socketcand",
            "--channel",
            "vcan0",
            "--host",
            "127.0.0.1",
        ])
        .args([
            "--port",
            &port,
            "--duration",
            "60",
            "--idle-exit",
            "2",
            "--json",
        ])
        .args(["--send", "013#03"]) // EmergencyStop to the right ankle
        .arg("--record")
        .arg(&rec_log)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mon = monitor.wait_with_output().unwrap();
    let mut rest = String::new();
    err.read_to_string(&mut rest).unwrap();
    let demo_out = demo.wait_with_output().unwrap();
    assert!(demo_out.status.success(), "demo failed: {rest}");
    assert!(
        mon.status.success(),
        "monitor failed: {}",
        String::from_utf8_lossy(&mon.stderr)
    );
    let m: serde_json::Value = serde_json::from_slice(&mon.stdout).unwrap();
    let d: serde_json::Value = serde_json::from_slice(&demo_out.stdout).unwrap();

    // the emergency stop went from the Python client onto the bus as a host frame
    assert_eq!(d["socketcand"]["frames_received"], 1);
    assert_eq!(
        d["bus"]["per_id"]["19"]["frames"], 1,
        "0x013 delivered: {d}"
    );
    // every frame the bus delivered reached the monitor and was decoded
    let frames = d["bus"]["frames"].as_u64().unwrap();
    assert_eq!(d["socketcand"]["frames_sent"].as_u64(), Some(frames));
    assert_eq!(m["frames"].as_u64(), Some(frames));
    let nodes = &m["nodes"];
    assert_eq!(nodes["LEFT_ANKLE"]["state"], "Enabled", "{nodes}");
    assert_eq!(nodes["RIGHT_ANKLE"]["state"], "EmergencyStop", "{nodes}");
    assert_eq!(nodes["HOST"]["state"], "Enabled");
    for n in ["HOST", "LEFT_ANKLE", "RIGHT_ANKLE"] {
        let hb = nodes[n]["heartbeats"].as_u64().unwrap();
        assert!((59..=61).contains(&hb), "{n}: {hb} heartbeats in 3 s");
        assert_eq!(nodes[n]["alive"], true);
    }
    let msgs = &m["messages"];
    for n in ["AnkleState_LEFT_ANKLE", "AnkleState_RIGHT_ANKLE"] {
        let r = msgs[n]["rate_hz"].as_f64().unwrap();
        assert!((r - 200.0).abs() < 2.0, "{n}: {r} Hz");
    }
    assert_eq!(
        msgs["AnkleState_RIGHT_ANKLE"]["last"]["reflex_phase"],
        "Inactive"
    );
    assert_eq!(msgs["EmergencyStop_RIGHT_ANKLE"]["count"], 1);
    let load = m["bus_load"].as_f64().unwrap();
    let rust_load = d["bus"]["load"].as_f64().unwrap();
    assert!(
        (load - rust_load).abs() < 0.002,
        "monitor {load} vs bus {rust_load}"
    );

    // what python-can recorded (with its ` R` suffix) reads back in Rust as the demo's own log
    let (ours, e1) = read_log(BufReader::new(std::fs::File::open(&demo_log).unwrap())).unwrap();
    let (theirs, e2) = read_log(BufReader::new(std::fs::File::open(&rec_log).unwrap())).unwrap();
    assert!(e1.is_empty() && e2.is_empty(), "{e1:?} {e2:?}");
    assert_eq!(ours.len(), theirs.len());
    for (a, b) in ours.iter().zip(&theirs) {
        assert!(matches!(a.frame, LogFrame::Standard(_)));
        assert_eq!(a.frame, b.frame);
        assert!(
            a.timestamp_ns.abs_diff(b.timestamp_ns) <= 2_000,
            "{a:?} {b:?}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
