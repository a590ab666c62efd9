//! `walker optimize` (issue 26): CMA-ES over scene parameters, every candidate's gait by the
//! gait rule of `walker gait`. Its JSON contract, its reproducibility (the same seed gives the
//! same search, bit for bit, on one thread or two), bad input refused with code 2, and an
//! optimisation of the compass gait that improves on the scene's design, its best value
//! checked independently by `walker gait --set` at the best parameters.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use serde_json::Value;
use std::process::{Command, Output};

mod common;
use common::{stderr, walker};

/// The compass gait's hip-to-leg-mass distance, varied around its default (0.5 m).
const VARY: &str = "leg_com_from_hip_m=0.3:0.7";

fn optimize_json(extra: &[&str], threads: Option<&str>) -> (Output, Value) {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_walker"));
    cmd.args(["optimize", "--scene", "compass", "--vary", VARY, "--json"])
        .args(extra);
    if let Some(t) = threads {
        cmd.env("RAYON_NUM_THREADS", t);
    }
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "walker optimize {extra:?}: {}",
        stderr(&out)
    );
    let json = serde_json::from_slice(&out.stdout).unwrap();
    (out, json)
}

#[test]
fn the_json_names_the_scene_the_objective_the_best_design_and_every_evaluation() {
    let (_, j) = optimize_json(
        &["--objective", "max_abs_eigenvalue", "--budget", "9"],
        None,
    );
    assert_eq!(j["scene"], "compass");
    assert_eq!(j["objective"], "max_abs_eigenvalue");
    assert_eq!(j["sense"], "minimise");
    assert_eq!(j["seed"], 0);
    assert_eq!(j["budget"], 9);
    let evaluations = j["evaluations"].as_array().unwrap();
    assert_eq!(evaluations.len(), 9, "the budget is spent exactly");
    for e in evaluations {
        for key in ["parameters", "value", "feasible", "reason"] {
            assert!(e.get(key).is_some(), "evaluation without `{key}`: {e}");
        }
        assert!(e["parameters"]["leg_com_from_hip_m"].is_f64(), "{e}");
        assert_eq!(e["feasible"].as_bool().unwrap(), e["reason"].is_null());
    }
    let best = &j["best"];
    let value = best["value"].as_f64().unwrap();
    assert!(best["parameters"]["leg_com_from_hip_m"].is_f64());
    // the gait as `walker gait --json` reports it, with where it came from
    let gait = &best["gait"];
    assert_eq!(gait["converged"], true);
    assert_eq!(gait["scene"], "compass");
    assert!(gait["gait_source"].is_string(), "{gait}");
    assert_eq!(gait["max_abs_eigenvalue"].as_f64().unwrap(), value);
    // the best is the best feasible evaluation
    let feasible_best = evaluations
        .iter()
        .filter(|e| e["feasible"] == true)
        .map(|e| e["value"].as_f64().unwrap())
        .fold(f64::INFINITY, f64::min);
    assert_eq!(feasible_best, value);
    // the history: the best so far after each generation, never worse
    let generations = j["generations"].as_array().unwrap();
    let history: Vec<f64> = j["history"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(history.len(), generations.len());
    assert!(history.windows(2).all(|w| w[1] <= w[0]), "{history:?}");
    assert_eq!(*history.last().unwrap(), value);
    assert_eq!(
        generations.last().unwrap()["evaluations"].as_u64().unwrap(),
        9
    );
    // the scene's own design, to compare with
    assert_eq!(j["default"]["parameters"]["leg_com_from_hip_m"], 0.5);
    assert_eq!(j["default"]["gait_source"], "defaults");
}

#[test]
fn the_same_seed_gives_the_same_search_bit_for_bit_on_one_thread_or_two() {
    let args = ["--objective", "gsn", "--budget", "14", "--seed", "7"];
    let (one, _) = optimize_json(&args, Some("1"));
    let (two, j) = optimize_json(&args, Some("2"));
    assert_eq!(
        String::from_utf8_lossy(&one.stdout),
        String::from_utf8_lossy(&two.stdout)
    );
    assert_eq!(j["seed"], 7);
    let (other, _) = optimize_json(
        &["--objective", "gsn", "--budget", "14", "--seed", "8"],
        Some("2"),
    );
    assert_ne!(one.stdout, other.stdout, "another seed, another search");
}

#[test]
fn bad_input_is_refused_with_code_2_and_a_message_naming_it() {
    let base = ["optimize", "--scene", "compass"];
    let cases: [(&[&str], &str); 10] = [
        (&["--vary", "nope=0:1", "--objective", "gsn"], "nope"),
        (
            &["--vary", "leg_com_from_hip_m=0.7:0.3", "--objective", "gsn"],
            "must be below",
        ),
        (
            &["--vary", "leg_com_from_hip_m=-1:0.5", "--objective", "gsn"],
            "outside its allowed range",
        ),
        (
            &["--vary", "leg_com_from_hip_m=0.3", "--objective", "gsn"],
            "NAME=MIN:MAX",
        ),
        (
            &["--vary", VARY, "--objective", "gsn", "--budget", "0"],
            "--budget",
        ),
        (&["--vary", VARY, "--objective", "fastest"], "--objective"),
        (
            &[
                "--vary",
                VARY,
                "--objective",
                "gsn",
                "--constraint",
                "speed=1",
            ],
            "NAME<=V",
        ),
        (
            &[
                "--vary",
                VARY,
                "--objective",
                "gsn",
                "--constraint",
                "legs<=1",
            ],
            "unknown quantity `legs`",
        ),
        (
            &["--vary", VARY, "--objective", "mfpt"],
            "objective mfpt: mfpt needs the rough floor's standard deviation (--sigma-m)",
        ),
        (
            &["--vary", VARY, "--objective", "cost_of_transport"],
            "no actuated ankle",
        ),
    ];
    for (args, message) in cases {
        let all: Vec<&str> = base.iter().chain(args).copied().collect();
        let out = walker(&all);
        assert_eq!(out.status.code(), Some(2), "{all:?}: {}", stderr(&out));
        assert!(
            stderr(&out).contains(message),
            "{all:?}: expected `{message}` in: {}",
            stderr(&out)
        );
    }
    let out = walker(&[
        "optimize",
        "--scene",
        "compass",
        "--vary",
        VARY,
        "--vary",
        "leg_com_from_hip_m=0.4:0.6",
        "--objective",
        "gsn",
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("twice"), "{}", stderr(&out));
}

#[test]
fn the_compass_gait_is_improved_and_its_best_value_is_what_walker_gait_finds_there() {
    let (_, j) = optimize_json(
        &["--objective", "max_abs_eigenvalue", "--budget", "60"],
        None,
    );
    let best = j["best"]["value"].as_f64().unwrap();
    let default = j["default"]["value"].as_f64().unwrap();
    assert!(
        best < default - 0.01,
        "best {best} does not improve on the scene's design {default}"
    );
    // An independent check: the gait `walker gait` finds at the best parameters.
    let x = &j["best"]["parameters"]["leg_com_from_hip_m"];
    let set = format!("leg_com_from_hip_m={x}");
    let out = walker(&["gait", "--scene", "compass", "--set", &set, "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let g: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(g["max_abs_eigenvalue"].as_f64().unwrap(), best, "{set}");
    assert_eq!(g["gait_source"], j["best"]["gait"]["gait_source"]);
}

#[test]
fn a_constraint_makes_designs_infeasible_with_a_typed_reason_and_the_best_meets_it() {
    let (_, j) = optimize_json(
        &[
            "--objective",
            "max_abs_eigenvalue",
            "--constraint",
            "step_period_s<=0.77",
            "--budget",
            "24",
        ],
        None,
    );
    let evaluations = j["evaluations"].as_array().unwrap();
    assert!(
        evaluations
            .iter()
            .any(|e| e["reason"] == "constraint_violated"),
        "no design violated the constraint"
    );
    for e in evaluations.iter().filter(|e| e["feasible"] == true) {
        assert!(e["constrained"]["step_period_s"].as_f64().unwrap() <= 0.77);
    }
    let period = j["best"]["gait"]["step_period_s"].as_f64().unwrap();
    assert!(period <= 0.77, "{period}");
    assert_eq!(j["constraints"][0]["quantity"], "step_period_s");
    assert_eq!(j["constraints"][0]["relation"], "<=");
}

#[test]
fn the_text_compares_the_best_design_with_the_scenes_and_the_plot_is_written() {
    let dir = std::env::temp_dir().join(format!("walker-optimize-plot-{}", std::process::id()));
    let out = walker(&[
        "optimize",
        "--scene",
        "compass",
        "--vary",
        VARY,
        "--objective",
        "max_abs_eigenvalue",
        "--budget",
        "8",
        "--plot",
        dir.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    for needle in [
        "best max_abs_eigenvalue",
        "the scene's design",
        "leg_com_from_hip_m",
    ] {
        assert!(text.contains(needle), "`{needle}` missing: {text}");
    }
    for ext in ["svg", "png", "pdf"] {
        let f = dir.join(format!("history.{ext}"));
        assert!(std::fs::metadata(&f).unwrap().len() > 0, "{}", f.display());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn every_candidates_gait_is_the_one_walker_gait_finds_at_its_values() {
    let (_, j) = optimize_json(
        &["--objective", "gsn", "--budget", "6", "--seed", "3"],
        None,
    );
    for e in j["evaluations"].as_array().unwrap() {
        let set = format!(
            "leg_com_from_hip_m={}",
            e["parameters"]["leg_com_from_hip_m"]
        );
        let out = walker(&["gait", "--scene", "compass", "--set", &set, "--json"]);
        let g: Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(g["max_abs_eigenvalue"], e["max_abs_eigenvalue"], "{set}");
        assert_eq!(g["gait_source"], e["gait_source"], "{set}");
    }
}
