//! The text `walker` prints for people: the main job's gait figures (each the JSON's number,
//! the speed the printed progress over the printed period), steps numbered from 1, the walk
//! table's legend, `walker scenes [NAME]`, and `walker sil --wait-client`.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::{stderr, walker};
use serde_json::Value;
use std::io::{BufReader, Read, Write};
use std::process::{Command, Stdio};
use std::time::Duration;
use walker_tools::announced::announced_address;

fn stdout(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The number after `label` on the line starting with `line_start`.
fn number_after(text: &str, line_start: &str, label: &str) -> f64 {
    let line = text
        .lines()
        .find(|l| l.trim_start().starts_with(line_start))
        .unwrap_or_else(|| panic!("no line `{line_start}` in\n{text}"));
    let rest = line
        .split_once(label)
        .unwrap_or_else(|| panic!("no `{label}` in `{line}`"))
        .1;
    rest.split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap_or_else(|e| panic!("`{line}`: {e}"))
}

#[test]
fn the_main_job_prints_speed_step_period_work_and_cost_as_the_json_has_them() {
    let text_out = walker(&["gait", "--scene", "wisse3d"]);
    assert!(text_out.status.success(), "{}", stderr(&text_out));
    let text = stdout(&text_out);
    let json: Value =
        serde_json::from_slice(&walker(&["gait", "--scene", "wisse3d", "--json"]).stdout).unwrap();
    let speed = number_after(&text, "speed", "speed");
    let progress = number_after(&text, "speed", "forward progress");
    let period = number_after(&text, "speed", "period");
    // What the issue asked: the printed progress over the printed period is the printed speed.
    assert!(
        (progress / period - speed).abs() < 2e-6,
        "{progress} / {period} != {speed}"
    );
    let close = |printed: f64, key: &str| {
        let j = json[key].as_f64().unwrap_or_else(|| panic!("{key}"));
        assert!(
            (printed - j).abs() < 1e-6,
            "{key}: text {printed}, JSON {j}"
        );
    };
    close(speed, "speed_m_s");
    close(progress, "progress_m_per_step");
    close(period, "step_period_s");
    close(
        number_after(&text, "step ", "forward progress,"),
        "step_length_m",
    );
    close(
        number_after(&text, "actuator work", "actuator work"),
        "actuator_work_j_per_step",
    );
    close(
        number_after(&text, "cost of transport", "cost of transport"),
        "cost_of_transport_j_per_kg_m",
    );
    assert!(text.contains("J/(kg·m)"), "{text}");
    // The forward progress of the 3D walker is shorter than the distance between its feet.
    assert!(progress < json["step_length_m"].as_f64().unwrap());
}

#[test]
fn a_passive_walker_says_it_has_no_actuator() {
    let out = walker(&["gait", "--scene", "simplest"]);
    assert!(out.status.success());
    let text = stdout(&out);
    assert!(
        text.contains("cost of transport  none: no actuator"),
        "{text}"
    );
    assert!(!text.contains("actuator work"), "{text}");
}

#[test]
fn steps_are_numbered_from_1_in_text_and_from_0_in_json() {
    let args = ["walk", "--scene", "wisse3d-uncompensated", "--steps", "10"];
    let out = walker(&args);
    assert_eq!(out.status.code(), Some(3));
    let text = stdout(&out);
    let json: Value =
        serde_json::from_slice(&walker(&[&args[..], &["--json"]].concat()).stdout).unwrap();
    let failed_in = json["failure"]["step"].as_u64().unwrap();
    assert!(
        text.contains(&format!("in step {} at t", failed_in + 1)),
        "JSON step {failed_in}:\n{text}"
    );
    // The table's first row is step 1, and its legend says what deviation is.
    let first_row = text
        .lines()
        .skip_while(|l| !l.trim_start().starts_with("step"))
        .nth(1)
        .unwrap();
    assert_eq!(first_row.split_whitespace().next(), Some("1"), "{text}");
    assert_eq!(json["steps"][0]["step"], 0);
    assert!(text.contains("steps are numbered from 1"), "{text}");
    assert!(text.contains("deviation: the largest difference"), "{text}");
}

#[test]
fn a_walk_shows_its_gait_and_no_progress_bar_off_a_terminal() {
    let out = walker(&["walk", "--scene", "wisse3d", "--steps", "4"]);
    assert!(out.status.success());
    let text = stdout(&out);
    assert!(text.contains("gait, mean over the last 4 steps:"), "{text}");
    let speed = number_after(&text, "speed", "speed");
    assert!((0.4..0.55).contains(&speed), "{speed}");
    // Standard error is a pipe here: no bar.
    assert!(!stderr(&out).contains("walk (steps)"), "{}", stderr(&out));
}

#[test]
fn scenes_are_listed_one_line_each() {
    let out = walker(&["scenes"]);
    assert!(out.status.success());
    let text = stdout(&out);
    let json: Value = serde_json::from_slice(&walker(&["scenes", "--json"]).stdout).unwrap();
    let scenes = json["scenes"].as_array().unwrap();
    // A header, one line per scene, a closing note.
    assert_eq!(text.lines().count(), scenes.len() + 2, "{text}");
    for s in scenes {
        let name = s["name"].as_str().unwrap();
        let dof = s["degrees_of_freedom"].as_u64().unwrap();
        let line = text
            .lines()
            .find(|l| l.split_whitespace().next() == Some(name))
            .unwrap_or_else(|| panic!("{name} not listed:\n{text}"));
        assert_eq!(line.split_whitespace().nth(1), Some(&*dof.to_string()));
        assert_eq!(s["coordinates"].as_array().unwrap().len() as u64, dof);
        // The fields the JSON always had.
        for key in ["summary", "reference", "parameters"] {
            assert!(s.get(key).is_some(), "{name}: {key}");
        }
    }
}

#[test]
fn a_scene_by_name_shows_its_parameters_in_aligned_columns() {
    let out = walker(&["scenes", "wisse3d"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    let json: Value =
        serde_json::from_slice(&walker(&["scenes", "wisse3d", "--json"]).stdout).unwrap();
    let params = json["parameters"].as_array().unwrap();
    let header = text
        .lines()
        .find(|l| l.starts_with("parameter"))
        .unwrap_or_else(|| panic!("{text}"));
    let unit_col = header.find("unit").unwrap();
    let desc_col = header.find("description").unwrap();
    for p in params {
        let name = p["name"].as_str().unwrap();
        let row = text
            .lines()
            .find(|l| l.split_whitespace().next() == Some(name))
            .unwrap_or_else(|| panic!("{name}:\n{text}"));
        let chars: Vec<char> = row.chars().collect();
        let at = |col: usize| chars[col..].iter().collect::<String>();
        assert!(
            at(unit_col).starts_with(p["unit"].as_str().unwrap()),
            "{name}: unit not under its header:\n{header}\n{row}"
        );
        assert!(
            at(desc_col).starts_with(p["doc"].as_str().unwrap()),
            "{name}: description not under its header:\n{header}\n{row}"
        );
    }
}

#[test]
fn an_unknown_scene_is_refused_with_the_list() {
    let out = walker(&["scenes", "wisse4d"]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(
        err.contains("wisse4d") && err.contains("wisse3d-uncompensated"),
        "{err}"
    );
}

#[test]
fn wait_client_is_bounded_and_needs_socketcand() {
    for bad in ["-1", "nan", "inf", "86401", "1e300"] {
        let out = walker(&[
            "sil",
            "--scene",
            "wisse3d",
            "--steps",
            "1",
            "--socketcand",
            "127.0.0.1:0",
            "--wait-client",
            bad,
        ]);
        assert_eq!(out.status.code(), Some(2), "{bad}: {}", stderr(&out));
        assert!(stderr(&out).contains("--wait-client"), "{bad}");
    }
    let out = walker(&[
        "sil",
        "--scene",
        "wisse3d",
        "--steps",
        "1",
        "--wait-client",
        "1",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("--socketcand"), "{}", stderr(&out));
}

#[test]
fn without_a_client_the_walk_starts_after_the_wait_and_says_so() {
    let t0 = std::time::Instant::now();
    let out = walker(&[
        "sil",
        "--scene",
        "wisse3d",
        "--steps",
        "2",
        "--socketcand",
        "127.0.0.1:0",
        "--wait-client",
        "0.3",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(t0.elapsed() >= Duration::from_millis(300));
    assert!(
        stderr(&out).contains("no client within 0.3 s; the walk starts without one"),
        "{}",
        stderr(&out)
    );
    assert!(stdout(&out).contains("2 of 2 steps"));
}

/// Reads from `s` until `want` arrived (or 10 s passed).
fn read_until(s: &mut std::net::TcpStream, want: &str) -> String {
    let mut got = String::new();
    let mut b = [0u8; 4096];
    let end = std::time::Instant::now() + Duration::from_secs(10);
    while !got.contains(want) && std::time::Instant::now() < end {
        if let Ok(n) = s.read(&mut b) {
            got.push_str(&String::from_utf8_lossy(&b[..n]));
        }
    }
    got
}

#[test]
fn with_a_client_the_walk_waits_for_it_and_it_sees_the_first_commands() {
    let mut sim = Command::new(env!("CARGO_BIN_EXE_walker"))
        .args(["sil", "--scene", "wisse3d", "--steps", "2"])
        .args(["--socketcand", "127.0.0.1:0", "--wait-client", "60"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = BufReader::new(sim.stderr.take().unwrap());
    let addr = announced_address(
        &mut err,
        "socketcand: serving the bus on ",
        Duration::from_secs(60),
    )
    .unwrap();
    // Wait before connecting: the walk must not start without the client.
    std::thread::sleep(Duration::from_millis(500));
    let mut c = std::net::TcpStream::connect(addr).unwrap();
    c.set_read_timeout(Some(Duration::from_millis(50))).unwrap();
    assert!(read_until(&mut c, "< hi >").contains("< hi >"));
    c.write_all(b"< open vcan0 >").unwrap();
    assert!(read_until(&mut c, "< ok >").contains("< ok >"));
    c.write_all(b"< rawmode >").unwrap();
    // Everything until the server closes at the end of the walk.
    let mut got = read_until(&mut c, "< ok >");
    let end = std::time::Instant::now() + Duration::from_secs(60);
    let mut b = [0u8; 65536];
    while std::time::Instant::now() < end {
        match c.read(&mut b) {
            Ok(0) => break,
            Ok(n) => got.push_str(&String::from_utf8_lossy(&b[..n])),
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) => {}
            Err(_) => break,
        }
    }
    let mut rest = String::new();
    err.read_to_string(&mut rest).unwrap();
    let status = sim.wait().unwrap();
    assert!(status.success(), "{rest}");
    assert!(rest.contains("client connected; the walk starts"), "{rest}");
    // The host's first commands (Command_ALL, 0x04F: setup and Enable at the first tick) reach
    // the client, which connected before the walk started.
    assert!(got.contains("< frame 04F "), "no host command seen");
}
