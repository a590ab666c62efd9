//! A long gait search shows its progress and honours its budget (issue 25: a compass with 50
//! extra pendulum links printed nothing for 240 s). `--max-strides` bounds the strides of one
//! gait search; past them the search stops and says so; on a terminal the strides taken are
//! its progress.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::PathBuf;
use std::process::Command;

mod common;
use common::{stderr, walker};

/// The compass gait with `n` light pendulums hanging from the hip: 2 + n degrees of freedom,
/// a stride Jacobian of 2 (2 + n) strides.
fn compass_with_links(n: usize) -> PathBuf {
    let base = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenes/compass.toml"
    ))
    .unwrap();
    let links: String = (0..n)
        .map(|i| {
            format!(
                "\n[[link]]\nname = \"p{i}\"\nparent = \"stance_leg\"\njoint = \"revolute\"\n\
                 axis = [0, 0, 1]\norigin_m = [0, \"leg_length_m\", 0]\nmass_kg = 0.01\n\
                 com_m = [0, -0.1, 0]\n"
            )
        })
        .collect();
    let pairs: Vec<String> = (0..n).map(|i| format!("[\"p{i}\", \"p{i}\"]")).collect();
    let scene = base
        .replace("name = \"compass\"", &format!("name = \"compass{n}\""))
        .replacen(
            "[[point]]\nname = \"stance_foot\"",
            &format!("{links}\n[[point]]\nname = \"stance_foot\""),
            1,
        )
        .replace(
            "pairs = [[\"stance_leg\", \"swing_leg\"], [\"swing_leg\", \"stance_leg\"]]",
            &format!(
                "pairs = [[\"stance_leg\", \"swing_leg\"], [\"swing_leg\", \"stance_leg\"], {}]",
                pairs.join(", ")
            ),
        );
    assert!(
        scene.contains("\"p0\", \"p0\""),
        "the relabelling took the links"
    );
    let path = std::env::temp_dir().join(format!(
        "walker-search-budget-{n}-{}.toml",
        std::process::id()
    ));
    std::fs::write(&path, scene).unwrap();
    path
}

#[test]
fn a_gait_search_stops_at_its_budget_and_says_so() {
    for cmd in [
        &["gait", "--scene", "wisse3d", "--max-strides", "10"][..],
        &[
            "gait",
            "--scene",
            "wisse3d",
            "--max-strides",
            "10",
            "--json",
        ][..],
        &[
            "walk",
            "--scene",
            "simplest",
            "--set",
            "slope=0.015",
            "--steps",
            "2",
            "--max-strides",
            "10",
        ][..],
        &[
            "stability-map",
            "--scene",
            "compass",
            "--x",
            "slope=0.04:0.05:2",
            "--y",
            "leg_mass_kg=4:5:2",
            "--max-strides",
            "10",
            "--json",
        ][..],
    ] {
        let out = walker(cmd);
        let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), stderr(&out));
        assert!(text.contains("budget of 10 strides"), "{cmd:?}: {text}");
        if cmd[0] != "stability-map" {
            assert_eq!(out.status.code(), Some(1), "{cmd:?}: {text}");
        }
    }
    let out = walker(&[
        "gait",
        "--scene",
        "wisse3d",
        "--max-strides",
        "10",
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        v["failure"]["kind"],
        "search_budget_exhausted",
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    let out = walker(&["gait", "--scene", "compass", "--max-strides", "0"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("--max-strides must be at least 1"));
    // the default budget leaves the usual searches alone
    let out = walker(&["gait", "--scene", "wisse3d"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
}

/// On a terminal (a pty from `script`), a search that lasts over a second draws the strides
/// it has taken of its budget; in a pipe nothing is drawn. 40 pendulums: the 300 strides take
/// about 3 s on the 2-core CI machine (20 took 0.9 s, too close to the second).
#[test]
fn a_long_search_shows_its_strides_on_a_terminal_and_nothing_in_a_pipe() {
    let scene = compass_with_links(40);
    let cmd = format!(
        "'{}' gait --scene '{}' --max-strides 300",
        env!("CARGO_BIN_EXE_walker"),
        scene.display()
    );
    let out = Command::new("script")
        .args(["-qec", &cmd, "/dev/null"])
        .output()
        .expect("`script` (util-linux) runs: it gives the search a terminal");
    let shown = String::from_utf8_lossy(&out.stdout);
    assert!(
        shown.contains("gait search [") && shown.contains("strides of its budget"),
        "{shown}"
    );
    assert!(shown.contains("budget of 300 strides"), "{shown}");
    let piped = walker(&[
        "gait",
        "--scene",
        scene.to_str().unwrap(),
        "--max-strides",
        "300",
    ]);
    assert!(!stderr(&piped).contains("strides of its budget"));
    assert!(String::from_utf8_lossy(&piped.stdout).contains("budget of 300 strides"));
    std::fs::remove_file(&scene).unwrap();
}
