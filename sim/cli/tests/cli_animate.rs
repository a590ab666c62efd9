//! `--animate FILE.html` on `walk`, `gait` and `sil`: a self-contained page, the commands'
//! other outputs unchanged, bad paths and step counts refused. (The page in a browser:
//! scripts/browser-tier.)
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::PathBuf;
use std::process::{Command, Output};

fn walker(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_walker"))
        .args(args)
        .output()
        .unwrap()
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("walker-animate-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// The page is self-contained: three.js, the drawing code and the data inline, no URL to
/// fetch.
fn assert_page(path: &PathBuf, title_has: &str) {
    let html = std::fs::read_to_string(path).unwrap();
    assert!(html.starts_with("<!DOCTYPE html>"));
    assert!(html.contains(title_has), "title lacks {title_has}");
    assert!(html.contains("id=\"walker-data\""));
    assert!(html.contains("WebGLRenderer"), "three.js not inlined");
    for remote in ["src=\"http", "href=\"http", "import(\"http", "from \"http"] {
        assert!(!html.contains(remote), "the page fetches {remote}");
    }
}

#[test]
fn walk_writes_a_page_and_prints_the_same_text() {
    let page = tmp("walk.html");
    let with = walker(&[
        "walk",
        "--scene",
        "compass",
        "--steps",
        "3",
        "--animate",
        page.to_str().unwrap(),
    ]);
    let without = walker(&["walk", "--scene", "compass", "--steps", "3"]);
    assert_eq!(with.status.code(), Some(0));
    assert_eq!(
        with.stdout, without.stdout,
        "--animate changed the text output"
    );
    // The walker by name, as the figures call it.
    assert_page(&page, "compass-gait walker (Goswami et al.): 3 steps");
}

#[test]
fn a_fall_is_animated_and_the_exit_code_stays_3() {
    let page = tmp("fall.html");
    let out = walker(&[
        "walk",
        "--scene",
        "wisse3d-uncompensated",
        "--steps",
        "10",
        "--animate",
        page.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(3));
    assert_page(
        &page,
        "3D walker without compensator: 1 step, then the fall",
    );
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(html.contains("\"kind\":\"fall\""));
    // Failures and events in words, numbered as the text output numbers them.
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("failure: fell forward in step 2 at t = "),
        "{text}"
    );
    assert!(html.contains("\"text\":\"step 2: fell forward: "));
    assert!(html.contains("knee lock (swing knee)"));
    for code in ["FellForward", "swing_knee)", "fell at"] {
        assert!(!html.contains(code), "the page shows `{code}`");
    }
}

#[test]
fn a_failure_that_is_not_a_fall_is_a_stop() {
    // The emergency stop at 4 s: the walk ends on a singular impact, not on a fall.
    let page = tmp("stop.html");
    let out = walker(&[
        "sil",
        "--scene",
        "wisse3d",
        "--steps",
        "12",
        "--estop-at",
        "4",
        "--animate",
        page.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(3));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("failure: simulation ended: the impact equations were singular in step 5"),
        "{text}"
    );
    assert!(
        text.contains("emergency stop sent at 4.000 s"),
        "the text names the emergency stop: {text}"
    );
    assert_page(
        &page,
        "3D walker with pelvic compensator: 4 steps, firmware in the loop, emergency stop sent at 4.000 s, then simulation ended: the impact equations were singular",
    );
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(html.contains("\"kind\":\"stop\""));
    assert!(!html.contains("\"kind\":\"fall\""));
}

#[test]
fn gait_and_sil_write_pages() {
    let gait = tmp("gait.html");
    let out = walker(&[
        "gait",
        "--scene",
        "compass",
        "--animate",
        gait.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0));
    // Steps, as the page's clock counts them.
    assert_page(&gait, "steps of its gait");
    let sil = tmp("sil.html");
    let out = walker(&[
        "sil",
        "--scene",
        "wisse3d",
        "--steps",
        "2",
        "--animate",
        sil.to_str().unwrap(),
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_page(&sil, "firmware in the loop");
    let html = std::fs::read_to_string(&sil).unwrap();
    assert!(html.contains("\"kind\":\"phase\""), "no ankle phases");
    assert!(html.contains("\"firmware\":true"));
}

#[test]
fn a_path_that_cannot_be_written_is_exit_1_naming_it() {
    let bad = "/nonexistent-folder-for-walker/page.html";
    for args in [
        vec![
            "walk",
            "--scene",
            "compass",
            "--steps",
            "2",
            "--animate",
            bad,
        ],
        vec!["gait", "--scene", "compass", "--animate", bad],
        vec![
            "sil",
            "--scene",
            "wisse3d",
            "--steps",
            "2",
            "--animate",
            bad,
        ],
    ] {
        let out = walker(&args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("--animate") && err.contains(bad), "{err}");
    }
}

#[test]
fn zero_steps_or_too_many_are_refused() {
    let page = tmp("zero.html");
    let out = walker(&[
        "walk",
        "--scene",
        "compass",
        "--steps",
        "0",
        "--animate",
        page.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--animate"));
    // Too many steps for a page: refused before the walk (which would record every sample).
    let out = walker(&[
        "walk",
        "--scene",
        "compass",
        "--steps",
        "100000",
        "--animate",
        page.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("1 to 2000 steps"));
}

#[test]
fn the_firmware_gait_averages_only_steps_before_the_emergency_stop() {
    // At 3.5 s the fifth step (begun at 3.2 s) is under way: it, and any step after the
    // stop, is not the firmware's gait.
    let out = walker(&[
        "sil",
        "--scene",
        "wisse3d",
        "--steps",
        "12",
        "--estop-at",
        "3.5",
        "--json",
    ]);
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let t_stop = r["emergency_stop_sent_s"].as_f64().unwrap();
    assert!((3.5..3.502).contains(&t_stop), "{t_stop}");
    let before = r["steps"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|s| {
            s["start_time_s"].as_f64().unwrap() + s["duration_s"].as_f64().unwrap() <= t_stop
        })
        .count();
    let completed = r["steps_completed"].as_u64().unwrap() as usize;
    assert!(
        before >= 1 && before < completed,
        "{before} of {completed} steps ended before the stop"
    );
    assert_eq!(
        r["steps_before_emergency_stop"].as_u64().unwrap() as usize,
        before
    );
    assert_eq!(
        r["gait"]["steps_averaged"].as_u64().unwrap() as usize,
        before.min(10)
    );
    let out = walker(&[
        "sil",
        "--scene",
        "wisse3d",
        "--steps",
        "12",
        "--estop-at",
        "3.5",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains(&format!(
            "firmware's gait, mean over the last {} steps before the emergency stop:",
            before.min(10)
        )),
        "{text}"
    );
    assert!(text.contains("emergency stop sent at 3.500 s"), "{text}");
}
