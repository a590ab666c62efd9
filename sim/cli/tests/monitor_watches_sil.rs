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

/// The README's live pair: `walker sil --wait-client` waits for the monitor, which then sees
/// the host's first commands (the host shown by what it sent, not as a dead node), prints no
/// "Got incomplete message" lines, and ends by itself when the walk ends (no `--duration`).
#[test]
fn the_monitor_sees_the_walk_from_its_start_and_ends_with_it() {
    let venv = PythonVenv::for_test("monitor_watches_sil").unwrap_or_else(|e| panic!("{e}"));
    let Some(venv) = venv else { return };
    let mut sim = Command::new(env!("CARGO_BIN_EXE_walker"))
        .args([
            "sil",
            "--scene",
            "wisse3d",
            "--steps",
            "3",
            "--realtime",
            "1",
        ])
        .args([
            "--socketcand",
            "127.0.0.1:0",
            "--wait-client",
            "60",
            "--json",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = BufReader::new(sim.stderr.take().unwrap());
    let addr: std::net::SocketAddr = announced_address(
        &mut err,
        "socketcand: serving the bus on ",
        Duration::from_secs(60),
    )
    .expect("the simulation announces its socketcand address")
    .parse()
    .unwrap();
    let mut monitor = venv
        .monitor()
        .args(["--interface", "socketcand", "--channel", "vcan0"])
        .args([
            "--host",
            &addr.ip().to_string(),
            "--port",
            &addr.port().to_string(),
        ])
        .arg("--json")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // A budget: the walk is about 2.4 s of real time.
    let t0 = std::time::Instant::now();
    while monitor.try_wait().unwrap().is_none() {
        if t0.elapsed() > Duration::from_secs(60) {
            let _ = monitor.kill();
            let _ = sim.kill();
            panic!("the monitor did not end with the walk");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let monitor = monitor.wait_with_output().unwrap();
    let sim_out = sim.wait_with_output().unwrap();
    let monitor_err = String::from_utf8_lossy(&monitor.stderr);
    assert!(monitor.status.success(), "monitor: {monitor_err}");
    assert!(sim_out.status.success());
    assert!(
        monitor_err.contains("closed the connection"),
        "{monitor_err}"
    );
    assert!(!monitor_err.contains("incomplete message"), "{monitor_err}");
    let m: serde_json::Value = serde_json::from_slice(&monitor.stdout).unwrap();
    let host = &m["nodes"]["HOST"];
    assert_eq!(host["sends_heartbeats"], false, "{host}");
    assert!(
        host["messages_sent"]["Command_ALL"].as_u64().unwrap_or(0) >= 1,
        "the monitor missed the host's first commands: {host}"
    );
    assert!(
        m["messages"]["HeelStrike_LEFT_ANKLE"]["count"]
            .as_u64()
            .unwrap_or(0)
            >= 1
    );
}
