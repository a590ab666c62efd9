//! The Python bus monitor, a separate process over real TCP on 127.0.0.1, watches a running
//! software-in-the-loop walk (`walker sil --socketcand ... --realtime 1`) and decodes both
//! ankle nodes' heartbeats and ankle states, and the heel strikes of the walk.
//!
//! Needs the project's venv (`scripts/python-venv`, through `walker_tools::python_venv`):
//! skipped with a message when it cannot be created, unless `WALKER_REQUIRE_PYTHON=1` (set by
//! `scripts/test-all`), which makes it fail.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::io::BufReader;
use std::process::{Command, Stdio};
use std::time::Duration;
use walker_tools::announced::announced_address;

use walker_tools::python_venv::PythonVenv;

#[test]
fn python_monitor_decodes_a_running_firmware_in_the_loop_walk() {
    let venv = PythonVenv::for_test("monitor_watches_sil").unwrap_or_else(|e| panic!("{e}"));
    let Some(venv) = venv else { return };
    let mut sim = Command::new(env!("CARGO_BIN_EXE_walker"))
        .args([
            "sil",
            "--scene",
            "wisse3d",
            "--steps",
            "5",
            "--realtime",
            "1",
        ])
        .args(["--socketcand", "127.0.0.1:0", "--json"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The server's address, from the simulation's first lines on stderr.
    let mut err = BufReader::new(sim.stderr.take().unwrap());
    let addr: std::net::SocketAddr = announced_address(
        &mut err,
        "socketcand: serving the bus on ",
        Duration::from_secs(60),
    )
    .expect("the simulation announces its socketcand address")
    .parse()
    .unwrap();
    let monitor = venv
        .monitor()
        .args(["--interface", "socketcand", "--channel", "vcan0"])
        .args([
            "--host",
            &addr.ip().to_string(),
            "--port",
            &addr.port().to_string(),
        ])
        .args(["--duration", "2.5", "--json"])
        .output()
        .unwrap();
    let sim_out = sim.wait_with_output().unwrap();
    assert!(
        monitor.status.success(),
        "monitor: {}",
        String::from_utf8_lossy(&monitor.stderr)
    );
    assert!(sim_out.status.success());
    let m: serde_json::Value = serde_json::from_slice(&monitor.stdout).unwrap();
    let s: serde_json::Value = serde_json::from_slice(&sim_out.stdout).unwrap();
    assert_eq!(s["steps_completed"], 5, "{}", s["failure"]);
    assert!(m["frames"].as_u64().unwrap() > 500, "{}", m["frames"]);
    let nodes = &m["nodes"];
    for n in ["LEFT_ANKLE", "RIGHT_ANKLE"] {
        assert_eq!(nodes[n]["state"], "Enabled", "{nodes}");
        assert!(nodes[n]["heartbeats"].as_u64().unwrap() >= 20, "{nodes}");
        let r = m["messages"][format!("AnkleState_{n}")]["rate_hz"]
            .as_f64()
            .unwrap();
        assert!((r - 200.0).abs() < 20.0, "{n}: {r} Hz");
    }
    // Each ankle node announces its own heel strikes on the bus.
    let strikes: u64 = ["HeelStrike_LEFT_ANKLE", "HeelStrike_RIGHT_ANKLE"]
        .iter()
        .filter_map(|k| m["messages"][*k]["count"].as_u64())
        .sum();
    assert!(strikes >= 2, "{}", m["messages"]);
}
