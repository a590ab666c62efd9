//! Hardware tier: flash the board binary on a B-G431B-ESC1 with probe-rs and check that the
//! node's heartbeat reaches the CAN bus. Skipped, saying why, when probe-rs is not installed
//! or no probe is attached; the bus check also needs `WALKER_CAN_IFACE` (a SocketCAN
//! interface wired to the board's CAN, e.g. `can0`) and the project's Python venv.
//!
//! Run on a bench: `cargo test --release -p hil-tests --test hardware -- --nocapture`.
//! Not exercised here: this machine has neither a probe nor a CAN adapter.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The probes probe-rs sees, or why none can be used.
fn attached_probes() -> Result<Vec<String>, String> {
    let out = Command::new("probe-rs")
        .arg("list")
        .output()
        .map_err(|e| format!("probe-rs is not installed ({e})"))?;
    if !out.status.success() {
        return Err(format!(
            "`probe-rs list` failed: {}",
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    let probes: Vec<String> = text
        .lines()
        .filter(|l| l.trim_start().starts_with('['))
        .map(str::to_string)
        .collect();
    if probes.is_empty() {
        return Err("no debug probe is attached".into());
    }
    Ok(probes)
}

#[test]
fn board_binary_flashes_and_its_heartbeat_reaches_the_bus() {
    let probes = match attached_probes() {
        Ok(p) => p,
        Err(why) => {
            eprintln!("SKIPPED hardware tier: {why}");
            return;
        }
    };
    eprintln!("probes: {probes:?}");
    // Build and flash (the board crate's runner is `probe-rs run --chip STM32G431CBUx`); run
    // for a few seconds with its defmt log.
    let board = root().join("firmware/board-g431");
    let status = Command::new("cargo")
        .args(["build", "--release"])
        .current_dir(&board)
        .status()
        .unwrap();
    assert!(status.success(), "board binary did not build");
    let mut flash = Command::new("timeout")
        .args(["20", "cargo", "run", "--release"])
        .current_dir(&board)
        .spawn()
        .unwrap();
    let Some(iface) = std::env::var_os("WALKER_CAN_IFACE") else {
        let _ = flash.wait();
        eprintln!(
            "SKIPPED bus check: set WALKER_CAN_IFACE to the SocketCAN interface on the board's bus"
        );
        return;
    };
    std::thread::sleep(std::time::Duration::from_secs(3));
    let monitor = Command::new(root().join(".venv/bin/python"))
        .arg(root().join("python/walker_monitor.py"))
        .args(["--interface", "socketcan", "--channel"])
        .arg(&iface)
        .args(["--duration", "3", "--json"])
        .current_dir(root())
        .output()
        .unwrap();
    let _ = flash.wait();
    assert!(
        monitor.status.success(),
        "{}",
        String::from_utf8_lossy(&monitor.stderr)
    );
    let m: serde_json::Value = serde_json::from_slice(&monitor.stdout).unwrap();
    let side = std::env::var("ANKLE_SIDE")
        .unwrap_or_else(|_| "left".into())
        .to_uppercase();
    let node = &m["nodes"][format!("{side}_ANKLE")];
    assert!(
        node["heartbeats"].as_u64().unwrap_or(0) >= 5,
        "no heartbeats from the board: {node}"
    );
}
