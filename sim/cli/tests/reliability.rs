//! The `walker` command under bad input and failing output (issue #14): counts that would
//! allocate without bound, factors and times that cannot be used, outputs that cannot be
//! written, faults that could never apply, start-state files that say something twice, and
//! walks that end with the walker on the floor. Each case once panicked, aborted or passed
//! silently.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use proptest::prelude::*;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

mod common;
use common::{stderr, walker};

/// Runs `args` and asserts exit code `code` and a message on stderr containing each needle
/// (and no panic).
fn assert_refused(args: &[&str], code: i32, needles: &[&str]) {
    let out = walker(args);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(code), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    for n in needles {
        assert!(err.contains(n), "{args:?}: `{n}` not in {err}");
    }
}

/// A fresh scratch folder for one test.
fn scratch(name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("walker-reliability-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn counts_that_would_allocate_without_bound_are_refused_before_any_work() {
    // `--points 18446744073709551615` panicked (capacity overflow), `1000000000000` aborted
    // on allocation.
    for points in ["18446744073709551615", "1000000000000", "10001", "1"] {
        assert_refused(
            &[
                "sweep",
                "--scene",
                "compass",
                "--param",
                "slope_rad",
                "--from",
                "0.005",
                "--to",
                "0.01",
                "--points",
                points,
            ],
            2,
            &["--points", points],
        );
    }
    for steps in ["18446744073709551615", "1000000000000", "100001"] {
        assert_refused(
            &["walk", "--scene", "compass", "--steps", steps],
            2,
            &["--steps", steps],
        );
        assert_refused(
            &["sil", "--scene", "wisse3d", "--steps", steps],
            2,
            &["--steps", steps],
        );
    }
}

#[test]
fn keeping_more_step_summaries_than_exist_keeps_them_all() {
    // `--keep-steps 18446744073709551615` overflowed `2 * keep` in the walk (a panic in a
    // debug build).
    let out = walker(&[
        "sil",
        "--scene",
        "wisse3d",
        "--steps",
        "2",
        "--keep-steps",
        "18446744073709551615",
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["steps"].as_array().unwrap().len(), 2);
}

#[test]
fn a_realtime_factor_outside_its_range_is_refused() {
    // `--realtime 1e-300` panicked in `Duration::from_secs_f64`.
    for factor in ["1e-300", "0", "-1", "NaN", "inf", "1e9"] {
        assert_refused(
            &[
                "sil",
                "--scene",
                "wisse3d",
                "--steps",
                "1",
                &format!("--realtime={factor}"),
            ],
            2,
            &["--realtime"],
        );
    }
}

#[test]
fn an_emergency_stop_time_that_is_not_a_time_is_refused() {
    // `--estop-at NaN` and `-1` were taken and stopped the walker at once, exit 0.
    // (`--estop-at=-inf`: clap reads a bare `-inf` as an option.)
    for t in ["NaN", "-1", "inf", "-inf", "-1e-300"] {
        assert_refused(
            &[
                "sil",
                "--scene",
                "wisse3d",
                "--steps",
                "1",
                &format!("--estop-at={t}"),
            ],
            2,
            &["--estop-at"],
        );
    }
}

/// Runs `args` with standard output a pipe whose reading end is already closed: every write
/// fails with a broken pipe, deterministically.
fn with_closed_stdout(args: &[&str]) -> Output {
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    Command::new(env!("CARGO_BIN_EXE_walker"))
        .args(args)
        .stdout(Stdio::from(writer))
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
        .wait_with_output()
        .unwrap()
}

#[test]
fn a_closed_pipe_ends_quietly_with_exit_0() {
    // `walker scenes | head -1` panicked in `println!`.
    for args in [
        &["scenes"][..],
        &["scenes", "--json"],
        &["gait", "--scene", "compass"],
        &["walk", "--scene", "compass", "--steps", "2"],
        &[
            "sweep",
            "--scene",
            "compass",
            "--param",
            "slope_rad",
            "--from",
            "0.005",
            "--to",
            "0.01",
            "--points",
            "2",
        ],
    ] {
        let out = with_closed_stdout(args);
        assert_eq!(out.status.code(), Some(0), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).is_empty(), "{args:?}: {}", stderr(&out));
    }
}

#[test]
fn a_full_disk_on_standard_output_is_an_error_with_exit_1() {
    let full = Path::new("/dev/full");
    if !full.exists() {
        eprintln!("no /dev/full here: skipped");
        return;
    }
    for args in [
        &["scenes"][..],
        &["scenes", "--json"],
        &["gait", "--scene", "compass"],
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_walker"))
            .args(args)
            .stdout(Stdio::from(std::fs::File::create(full).unwrap()))
            .output()
            .unwrap();
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains("standard output") && !err.contains("panicked"),
            "{err}"
        );
    }
}

#[test]
fn tune_refuses_a_parameter_twice_and_no_evaluations_and_keeps_its_budget() {
    assert_refused(
        &[
            "tune",
            "--scene",
            "compass",
            "--vary",
            "slope_rad=0.005:0.015",
            "--vary",
            "slope_rad=0.006:0.012",
        ],
        2,
        &["slope_rad", "twice"],
    );
    // The same parameter under its alias and its name is one parameter given twice.
    assert_refused(
        &[
            "tune",
            "--scene",
            "compass",
            "--vary",
            "slope=0.005:0.015",
            "--vary",
            "slope_rad=0.006:0.012",
        ],
        2,
        &["slope_rad", "twice"],
    );
    assert_refused(
        &[
            "tune",
            "--scene",
            "compass",
            "--vary",
            "slope_rad=0.005:0.015",
            "--evaluations",
            "0",
        ],
        2,
        &["--evaluations"],
    );
    // `--evaluations 20` reported 21, `1` ran 2: a simplex step ran past the budget.
    for n in [1usize, 2, 3, 4, 7, 20] {
        let out = walker(&[
            "tune",
            "--scene",
            "compass",
            "--vary",
            "slope_rad=0.005:0.015",
            "--vary",
            "hip_mass_kg=0.5:2",
            "--evaluations",
            &n.to_string(),
            "--json",
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        let v: Value = serde_json::from_slice(&out.stdout).unwrap();
        let done = v["history"].as_array().unwrap().len();
        assert!(
            done <= n && done >= n.min(3),
            "--evaluations {n}: {done} gait searches"
        );
    }
}

#[test]
fn a_fault_on_an_identifier_no_node_sends_is_refused_naming_those_that_exist() {
    // The documented example `drop:id=0x101,count=5` did nothing, silently.
    assert_refused(
        &[
            "sil",
            "--scene",
            "wisse3d",
            "--steps",
            "1",
            "--fault",
            "drop:id=0x101,count=5",
        ],
        2,
        &["--fault", "0x101", "0x022 HeelStrike LEFT_ANKLE"],
    );
    // The example as documented now is taken (and drops the left heel strikes).
    let out = walker(&[
        "sil",
        "--scene",
        "wisse3d",
        "--steps",
        "2",
        "--fault",
        "drop:id=0x022,count=5",
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let help = walker(&["sil", "--help"]);
    let help = String::from_utf8_lossy(&help.stdout);
    assert!(
        help.contains("drop:id=0x022") && !help.contains("0x101"),
        "{help}"
    );
}

#[test]
fn a_start_state_that_sets_an_entry_twice_is_refused_naming_it() {
    let dir = scratch("duplicate");
    let f = dir.join("twice.json");
    std::fs::write(&f, r#"{"stance_leg_dot": -1.2, "stance_leg_dot": -1.1}"#).unwrap();
    assert_refused(
        &[
            "walk",
            "--scene",
            "compass",
            "--steps",
            "1",
            "--start-state",
            f.to_str().unwrap(),
        ],
        2,
        &["--start-state", "duplicate key `stance_leg_dot`"],
    );
    // A file too large to be a start state is refused without reading it all.
    let big = dir.join("big.json");
    std::fs::write(&big, vec![b' '; (1 << 20) + 10]).unwrap();
    assert_refused(
        &[
            "walk",
            "--scene",
            "compass",
            "--steps",
            "1",
            "--start-state",
            big.to_str().unwrap(),
        ],
        2,
        &["--start-state", "larger than"],
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_walk_that_falls_exits_3_with_its_report_unchanged() {
    let fall = walker(&[
        "walk",
        "--scene",
        "compass",
        "--steps",
        "10",
        "--perturb",
        "stance_leg_dot=0.6",
        "--json",
    ]);
    assert_eq!(fall.status.code(), Some(3), "{}", stderr(&fall));
    let v: Value = serde_json::from_slice(&fall.stdout).unwrap();
    assert_eq!(v["failure"]["kind"], "fell_backward");
    // Text output too; a walk that completes exits 0.
    let text = walker(&[
        "walk",
        "--scene",
        "compass",
        "--steps",
        "10",
        "--perturb",
        "stance_leg_dot=0.6",
    ]);
    assert_eq!(text.status.code(), Some(3));
    assert!(String::from_utf8_lossy(&text.stdout).contains("failure: fell backward in step "));
    assert_eq!(
        walker(&["walk", "--scene", "compass", "--steps", "2"])
            .status
            .code(),
        Some(0)
    );
    // The firmware walk stopped by an emergency stop falls.
    let sil = walker(&[
        "sil",
        "--scene",
        "wisse3d",
        "--steps",
        "6",
        "--estop-at",
        "0.3",
        "--json",
    ]);
    assert_eq!(sil.status.code(), Some(3), "{}", stderr(&sil));
    let v: Value = serde_json::from_slice(&sil.stdout).unwrap();
    assert!(v["failure"].is_object(), "{v}");
    let help = walker(&["--help"]);
    assert!(String::from_utf8_lossy(&help.stdout).contains("3 the walk"));
    for command in ["walk", "sil"] {
        let help = walker(&[command, "--help"]);
        let help = String::from_utf8_lossy(&help.stdout);
        assert!(help.contains("3 the walker fell"), "{command}: {help}");
    }
}

#[test]
fn output_paths_that_cannot_be_written_are_named() {
    let dir = scratch("paths");
    // A file where a folder is expected: nothing can be created below it.
    let file = dir.join("a-file");
    std::fs::write(&file, "x").unwrap();
    let below = file.join("walk.csv");
    let below = below.to_str().unwrap();
    let file_s = file.to_str().unwrap();
    let walk = |extra: &[&str]| {
        let mut args = vec!["walk", "--scene", "compass", "--steps", "1"];
        args.extend_from_slice(extra);
        args.iter().map(|s| s.to_string()).collect::<Vec<_>>()
    };
    for (args, flag, path) in [
        (walk(&["--out", below]), "--out", below),
        (walk(&["--plot", file_s]), "--plot", file_s),
        (
            vec!["gait", "--scene", "compass", "--plot", file_s]
                .into_iter()
                .map(String::from)
                .collect(),
            "--plot",
            file_s,
        ),
    ] {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        assert_refused(&args, 1, &[flag, path]);
    }
    assert_refused(
        &[
            "sil",
            "--scene",
            "wisse3d",
            "--steps",
            "1",
            "--candump",
            below,
        ],
        2,
        &["--candump", below],
    );
    std::fs::remove_dir_all(&dir).ok();
}

proptest! {
    // Each case runs the binary (a compass gait search and one step, tens of milliseconds).
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Whatever a start-state file holds, `walker walk` walks (0, or 3 if that start falls)
    /// or refuses it naming the option (2); never panics.
    #[test]
    fn any_start_state_file_is_walked_or_refused(
        text in prop_oneof![
            "\\PC{0,40}",
            prop::collection::vec(
                (
                    prop::sample::select(vec![
                        "stance_leg", "swing_leg", "stance_leg_dot", "swing_leg_dot", "knee",
                    ]),
                    prop_oneof![
                        (-2.0f64..2.0).prop_map(|x| x.to_string()),
                        Just("null".to_string()),
                        Just("\"x\"".to_string()),
                        Just("1e999".to_string()),
                    ],
                ),
                0..5,
            )
            .prop_map(|kv| {
                let parts: Vec<String> =
                    kv.into_iter().map(|(k, v)| format!("\"{k}\": {v}")).collect();
                format!("{{{}}}", parts.join(", "))
            }),
        ]
    ) {
        let dir = scratch("proptest");
        let f = dir.join(format!("{}.json", text.len()));
        std::fs::write(&f, &text).unwrap();
        let out = walker(&[
            "walk", "--scene", "compass", "--steps", "1", "--start-state", f.to_str().unwrap(),
        ]);
        let err = stderr(&out);
        prop_assert!(!err.contains("panicked"), "{text}: {err}");
        match out.status.code() {
            Some(0) | Some(3) => {}
            Some(2) => prop_assert!(err.contains("--start-state"), "{text}: {err}"),
            other => prop_assert!(false, "{text}: exit {other:?}: {err}"),
        }
        std::fs::remove_file(&f).ok();
    }
}

/// A fixed step too small for the stride's time budget used to integrate for ever
/// (`--integrator rk4 --step-s 1e-300`, also Meijaard, also 1e-9): refused before any stride.
#[test]
fn a_fixed_step_too_small_for_the_stride_budget_is_refused() {
    for (kind, step) in [("rk4", "1e-300"), ("meijaard", "1e-9"), ("rk4", "1e-9")] {
        assert_refused(
            &[
                "gait",
                "--scene",
                "compass",
                "--integrator",
                kind,
                "--step-s",
                step,
            ],
            2,
            &[step],
        );
    }
}

#[test]
fn scene_files_that_are_huge_devices_or_fifos_are_refused_before_they_are_read() {
    // A link to /dev/zero grew to 4 GB; a 100 MB scene took 20 s and 5.2 GB; a FIFO blocked
    // forever. Every path that reads a scene file (`--scene`, `--start-from-scene`,
    // `--plot-with`, `walker scenes PATH`) goes through the one bounded read.
    let dir = scratch("scene-files");
    let zero = dir.join("zero.toml");
    let _ = std::fs::remove_file(&zero);
    std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
    let fifo = dir.join("fifo.toml");
    let _ = std::fs::remove_file(&fifo);
    let made = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success());
    let huge = dir.join("huge.toml");
    std::fs::write(&huge, "#".repeat(2 << 20)).unwrap();
    let (zero, fifo, huge) = (
        zero.to_str().unwrap(),
        fifo.to_str().unwrap(),
        huge.to_str().unwrap(),
    );
    for (path, why) in [
        (zero, "not a regular file"),
        (fifo, "not a regular file"),
        (huge, "larger than 1048576 bytes"),
    ] {
        assert_refused(&["gait", "--scene", path], 2, &[path, why]);
        assert_refused(&["scenes", path], 2, &[why]);
        assert_refused(
            &[
                "walk",
                "--scene",
                "compass",
                "--steps",
                "1",
                "--start-from-scene",
                path,
            ],
            2,
            &[why],
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn flags_a_command_would_ignore_are_refused() {
    // Each was once accepted and ignored in silence.
    assert_refused(
        &["gait", "--scene", "compass", "--step-s", "0.001"],
        2,
        &["--step-s", "dop853"],
    );
    assert_refused(
        &[
            "gait",
            "--scene",
            "compass",
            "--integrator",
            "rk4",
            "--rtol",
            "1e-8",
        ],
        2,
        &["--rtol", "rk4"],
    );
    assert_refused(
        &[
            "walk",
            "--scene",
            "compass",
            "--steps",
            "1",
            "--plot-with",
            "simplest",
        ],
        2,
        &["--plot-with", "--plot"],
    );
    assert_refused(
        &[
            "walk",
            "--scene",
            "compass",
            "--steps",
            "1",
            "--start",
            "guess",
            "--start-from-scene",
            "simplest",
        ],
        2,
        &["--start-from-scene", "--start guess"],
    );
    assert_refused(
        &[
            "sil",
            "--scene",
            "wisse3d",
            "--steps",
            "1",
            "--socketcand-allow-send",
        ],
        2,
        &["--socketcand-allow-send", "needs --socketcand"],
    );
    assert_refused(
        &[
            "sil",
            "--scene",
            "wisse3d",
            "--steps",
            "1",
            "--fault",
            "drop:id=0x022,count=0",
        ],
        2,
        &["count", "from 1 to 4294967295"],
    );
}

#[test]
fn messages_are_clear_short_and_never_carry_terminal_escapes() {
    // A TOML error quoting a line with an escape sequence reached the terminal raw.
    let dir = scratch("messages");
    let scene = dir.join("escape.toml");
    std::fs::write(
        &scene,
        "[scene]\nname = \"x\u{1b}]0;title\u{7}\"\nbad = \u{1b}[31m\n",
    )
    .unwrap();
    let out = walker(&["gait", "--scene", scene.to_str().unwrap()]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(!err.contains('\u{1b}') && !err.contains('\u{7}'), "{err:?}");
    assert!(err.contains("\\u{1b}"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
    // A tiny value in short scientific form, not 300 digits.
    assert_refused(
        &["gait", "--scene", "compass", "--set", "leg_length_m=1e-300"],
        2,
        &["= 1e-300 m is outside its allowed range [1e-6, inf]"],
    );
    // Negative tolerances reach the check (clap once took `-1e-8` for a flag).
    assert_refused(
        &["gait", "--scene", "compass", "--rtol", "-1e-8"],
        2,
        &["--rtol must be a positive number, got -1e-8"],
    );
    assert_refused(
        &["gait", "--scene", "compass", "--newton-max-iter", "0"],
        2,
        &["--newton-max-iter must be at least 1"],
    );
    assert_refused(
        &["tune", "--scene", "compass", "--vary", "slope=0.06:0.04"],
        2,
        &["min 0.06 must be below max 0.04"],
    );
    // A firmware parameter far out of range as given, not as its f32 (`= inf`).
    assert_refused(
        &[
            "sil",
            "--scene",
            "wisse3d",
            "--steps",
            "1",
            "--firmware-param",
            "taut_angle_rad=1e300",
        ],
        2,
        &["taut_angle_rad = 1e300 is outside its range"],
    );
}

#[test]
fn a_parameter_or_a_perturbation_given_twice_is_refused() {
    // The last `--set` won and repeated `--perturb`s were added, in silence.
    assert_refused(
        &[
            "gait",
            "--scene",
            "compass",
            "--set",
            "slope=0.04",
            "--set",
            "slope_rad=0.05",
        ],
        2,
        &["parameter `slope_rad` is already set by `--set slope=0.04`"],
    );
    assert_refused(
        &[
            "walk",
            "--scene",
            "compass",
            "--steps",
            "1",
            "--perturb",
            "stance_leg=0.01",
            "--perturb",
            "stance_leg=0.01",
        ],
        2,
        &["`stance_leg` is already perturbed"],
    );
}
