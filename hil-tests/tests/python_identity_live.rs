//! The Python bus monitor, as a separate process over real TCP, reads the firmware nodes'
//! identity and fault history: the firmware runs in the loop (`sil::FirmwareInTheLoop`, both
//! ankles, their CAN controllers on the simulated bus, socketcand on 127.0.0.1), an encoder
//! glitch puts the left node in its safe state, the monitor connects and sends GetIdentity
//! and GetFaultHistory to the left ankle (`--send`), and its JSON shows the left node's
//! identity (firmware version, protocol, reset cause, parameter source, UID) and the fault
//! that made it go safe.
//!
//! Needs the project's venv (`scripts/python-venv`, through `walker_tools::python_venv`);
//! skipped with a message when it cannot be created, unless `WALKER_REQUIRE_PYTHON=1`.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use std::process::Stdio;
use std::time::{Duration, Instant as WallClock};

use protocol::{Command, CommandKind, Message, NodeId, Target};
use sil::{FirmwareInTheLoop, SensorFault, Side, SilConfig};
use sim::engine::control::{AnkleController, AnkleSensing};
use walker_tools::python_venv::PythonVenv;

fn cansend(kind: CommandKind) -> String {
    let f = Message::Command(Command {
        target: Target::Node(NodeId::LeftAnkle),
        kind,
    })
    .encode()
    .unwrap();
    let hex: String = f.payload().iter().map(|b| format!("{b:02X}")).collect();
    format!("{:03X}#{hex}", f.id.raw())
}

#[test]
fn python_monitor_reads_identity_and_fault_history_from_the_firmware() {
    let Some(venv) = PythonVenv::for_test("python_identity_live").unwrap_or_else(|e| panic!("{e}"))
    else {
        return;
    };
    let config = SilConfig {
        socketcand: Some("127.0.0.1:0".into()),
        // the monitor sends GetIdentity and GetFaultHistory
        socketcand_allow_send: true,
        ..SilConfig::default()
    }
    .with_sensor_fault(SensorFault::Glitch {
        side: Side::Left,
        at_s: 0.1,
        delta_rad: 0.2,
    });
    let mut c = FirmwareInTheLoop::new(config).unwrap();
    let port = c.socketcand_addr().unwrap().port().to_string();
    let mut t_ms = 0u64;
    let mut tick = |c: &mut FirmwareInTheLoop| {
        let s = AnkleSensing {
            t_walk_s: t_ms as f64 * 1e-3,
            stance_ankle_rad: 0.05,
            stance_ankle_rate_rad_s: 0.0,
            stance_foot_on_floor: true,
            swing_foot_on_floor: false,
            string_engaged: false,
            string_torque_n_m: 0.0,
        };
        c.tick(&s).unwrap();
        t_ms += 1;
    };
    // 0.2 s of walk time before anyone listens: the glitch at 0.1 s makes the left node safe.
    for _ in 0..200 {
        tick(&mut c);
    }
    let monitor = venv
        .monitor()
        .args(["--interface", "socketcand", "--channel", "vcan0"])
        .args(["--host", "127.0.0.1", "--port", &port])
        .args(["--duration", "4", "--json"])
        .args(["--send", &cansend(CommandKind::GetIdentity)])
        .args(["--send", &cansend(CommandKind::GetFaultHistory)])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Keep the firmware running, about 1 ms of walk time per 0.5 ms of wall time, while the
    // monitor listens; the monitor ends by its own --duration. The deadline only turns a hang
    // into a failure, whatever the machine's load.
    let start = WallClock::now();
    let mut monitor = monitor;
    loop {
        tick(&mut c);
        std::thread::sleep(Duration::from_micros(500));
        if let Some(_status) = monitor.try_wait().unwrap() {
            break;
        }
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "monitor did not finish"
        );
    }
    let out = monitor.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "monitor failed: {stderr}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&out.stdout)));
    let left = &v["nodes"]["LEFT_ANKLE"];
    let ident = &left["identity"];
    assert_eq!(ident["firmware"], "0.1.0", "{left}");
    assert_eq!(ident["protocol_version"], 3);
    assert_eq!(
        ident["reset_cause"], "Unknown",
        "simulation: no reset flags"
    );
    assert_eq!(ident["params_source"], "Defaults");
    assert_eq!(ident["uid"], "000000000000000000000000");
    let history = left["fault_history"].as_array().unwrap();
    assert!(!history.is_empty(), "{left}");
    let cause = history
        .iter()
        .find(|e| e["state_after"] == "Safe")
        .unwrap_or_else(|| panic!("no entry that made the node safe: {history:?}"));
    assert_eq!(cause["code"], "EncoderRate");
    assert_eq!(left["state"], "Safe");
    // The right node was not asked.
    assert!(v["nodes"]["RIGHT_ANKLE"]["fault_history"]
        .as_array()
        .unwrap()
        .is_empty());
}
