//! `walker robustness` and `walker basin` (issue 26): the JSON contracts, the thresholds
//! against walks over the same floors (`walker walk --floor`, another loop), results that do
//! not depend on the number of threads, and bad input refused.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;
use common::{stderr, walker};
use serde_json::Value;
use std::process::Command;

fn json(args: &[&str]) -> Value {
    let out = walker(args);
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{args:?}: {e}"))
}

const COMPASS: [&str; 8] = [
    "robustness",
    "--scene",
    "compass",
    "--json",
    "--sigma-m",
    "0.003",
    "--mfpt-runs",
    "20",
];

/// Whether a walk of `steps` from the gait onto a step of `height_m` at the first heel strike
/// completes (`walker walk`, its own loop).
fn walk_survives(height_m: f64, steps: usize) -> bool {
    let floor = format!("step:at=1,height_m={height_m}");
    let steps = steps.to_string();
    let out = walker(&[
        "walk", "--scene", "compass", "--steps", &steps, "--floor", &floor, "--json",
    ]);
    let r: Value = serde_json::from_slice(&out.stdout).unwrap();
    r["failure"].is_null()
}

#[test]
fn robustness_reports_every_measure_under_the_contract_and_walks_agree() {
    let r = json(&COMPASS);
    assert_eq!(r["scene"], "compass");
    assert_eq!(r["gait"]["gait_source"], "defaults");
    let gsn = &r["gait_sensitivity_norm"];
    for k in ["step_time", "step_length", "both"] {
        assert!(gsn[k].as_f64().unwrap() > 0.0, "{k}");
    }
    assert_eq!(gsn["disturbance"], "floor_step");
    let (t, l, b) = (
        gsn["step_time"].as_f64().unwrap(),
        gsn["step_length"].as_f64().unwrap(),
        gsn["both"].as_f64().unwrap(),
    );
    assert!(
        (b - t.hypot(l)).abs() <= 1e-12 * b,
        "both is the 2-norm of the two"
    );
    let down = r["step_down_max_m"].as_f64().unwrap();
    let up = r["step_up_max_m"].as_f64().unwrap();
    assert!(down > 0.0 && up > 0.0);
    assert!(r["survived_again_from_m"].get("down").is_some());
    assert!(r["survived_again_from_m"].get("up").is_some());
    let v = r["velocity_perturbation_max"].as_object().unwrap();
    assert_eq!(
        v.keys().collect::<Vec<_>>(),
        vec!["stance_leg_dot", "swing_leg_dot"]
    );
    for (_, s) in v {
        assert!(s["positive"].as_f64().unwrap() > 0.0);
        assert!(s["negative"].as_f64().unwrap() > 0.0);
    }
    let m = &r["mfpt"][0];
    for k in [
        "sigma_m",
        "steps",
        "ci_low",
        "ci_high",
        "strides_simulated",
        "censored",
    ] {
        assert!(m.get(k).is_some(), "mfpt lacks {k}");
    }
    assert_eq!(m["sigma_m"], 0.003);
    let (lo, hi) = (
        m["ci_low"].as_f64().unwrap(),
        m["ci_high"].as_f64().unwrap(),
    );
    let steps = m["steps"].as_f64().unwrap();
    assert!(lo < steps && steps < hi, "{lo} < {steps} < {hi}");
    // the walk command over the same floors: just inside the threshold it walks on (and the
    // recovery rule's 100 strides), just outside it falls; the bracket is 1e-7 m
    let bracket = r["step_thresholds"]["down"]["bracket"].as_f64().unwrap();
    assert!(bracket <= 1e-7 * 1.000_001, "{bracket}");
    assert!(walk_survives(-down, 100), "inside the step-down threshold");
    assert!(!walk_survives(-(down + 2e-7), 100), "past it");
    assert!(walk_survives(up, 100), "inside the step-up threshold");
    assert!(!walk_survives(up + 2e-7, 100), "past it");
    if let Some(again) = r["survived_again_from_m"]["down"].as_f64() {
        assert!(again > down);
        assert!(walk_survives(-(again + 1e-6), 100), "survived again");
        assert!(
            !walk_survives(-(again - 2e-7), 100),
            "not yet survived again"
        );
    }
}

#[test]
fn robustness_does_not_depend_on_the_number_of_threads() {
    let run = |threads: &str| {
        let out = Command::new(env!("CARGO_BIN_EXE_walker"))
            .args(COMPASS)
            .env("RAYON_NUM_THREADS", threads)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", stderr(&out));
        out.stdout
    };
    assert_eq!(run("1"), run("3"));
}

#[test]
fn basin_reports_its_grid_under_the_contract() {
    let r = json(&[
        "basin",
        "--scene",
        "simplest",
        "--x",
        "stance_leg=0.15:0.25:12",
        "--y",
        "stance_leg_dot=-0.3:-0.1:9",
        "--json",
    ]);
    assert_eq!(r["scene"], "simplest");
    assert_eq!(r["x"]["name"], "stance_leg");
    assert_eq!(r["y"]["values"].as_array().unwrap().len(), 9);
    let outcome = r["outcome"].as_array().unwrap();
    let strides = r["strides"].as_array().unwrap();
    assert_eq!(outcome.len(), 9, "one row per y value");
    let mut gait = 0;
    for (row, srow) in outcome.iter().zip(strides) {
        assert_eq!(row.as_array().unwrap().len(), 12);
        for (c, s) in row.as_array().unwrap().iter().zip(srow.as_array().unwrap()) {
            let c = c.as_str().unwrap();
            assert!(
                matches!(
                    c,
                    "gait" | "periodic" | "fell_forward" | "fell_backward" | "not_settled"
                ),
                "{c}"
            );
            let s = s.as_u64().unwrap();
            assert!((1..=100).contains(&s));
            gait += usize::from(c == "gait");
        }
    }
    assert!(gait > 0, "the gait's own cell neighbourhood returns");
    assert_eq!(
        r["fraction_returning"].as_f64().unwrap(),
        gait as f64 / 108.0
    );
    assert_eq!(r["solved_coordinate"], "swing_leg");
}

/// `args` are bad input: exit code 2, a message on standard error containing `needle`, nothing
/// on standard output.
fn refused(args: &[&str], needle: &str) {
    let out = walker(args);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
    assert!(stderr(&out).contains(needle), "{args:?}: {}", stderr(&out));
    assert!(out.stdout.is_empty(), "{args:?}");
}

#[test]
fn bad_input_is_refused_with_a_clear_message() {
    for (args, needle) in [
        (
            vec!["robustness", "--scene", "compass", "--sigma-m", "-1"],
            "--sigma-m -1",
        ),
        (
            vec!["robustness", "--scene", "compass", "--sigma-m", "nan"],
            "--sigma-m",
        ),
        (
            vec!["robustness", "--scene", "compass", "--mfpt-runs", "0"],
            "--mfpt-runs",
        ),
        (
            vec![
                "robustness",
                "--scene",
                "compass",
                "--mfpt-runs",
                "100000",
                "--mfpt-strides",
                "100000",
            ],
            "at most",
        ),
        (
            vec![
                "basin",
                "--scene",
                "compass",
                "--x",
                "hip=0:1:3",
                "--y",
                "stance_leg_dot=0:1:3",
            ],
            "`hip` is not a stride-map coordinate",
        ),
        (
            vec![
                "basin",
                "--scene",
                "compass",
                "--x",
                "stance_leg=0:1:3",
                "--y",
                "stance_leg=0:1:3",
            ],
            "two different",
        ),
        (
            vec![
                "basin",
                "--scene",
                "compass",
                "--x",
                "stance_leg=0:1:0",
                "--y",
                "stance_leg_dot=0:1:3",
            ],
            "--x N",
        ),
        (
            vec![
                "basin",
                "--scene",
                "compass",
                "--x",
                "stance_leg=0:1:3",
                "--y",
                "stance_leg_dot=0:1:3",
                "--strides",
                "0",
            ],
            "--strides",
        ),
    ] {
        refused(&args, needle);
    }
}

#[test]
fn a_map_of_a_measure_equals_the_measure_at_each_cell() {
    let map = json(&[
        "stability-map",
        "--scene",
        "compass",
        "--x",
        "slope_rad=0.03:0.05:2",
        "--y",
        "leg_com_from_hip_m=0.5:0.5:1",
        "--quantity",
        "step_down",
        "--json",
    ]);
    assert_eq!(map["quantity"]["name"], "step_down");
    assert_eq!(map["quantity"]["unit"], "m");
    for (i, slope) in ["0.03", "0.05"].iter().enumerate() {
        let set = format!("slope_rad={slope}");
        let r = json(&[
            "robustness",
            "--scene",
            "compass",
            "--set",
            &set,
            "--measures",
            "steps",
            "--json",
        ]);
        assert_eq!(
            map["quantity"]["values"][0][i], r["step_down_max_m"],
            "{slope}"
        );
        assert!(r["gait_sensitivity_norm"].is_null() && r["mfpt"] == serde_json::json!([]));
    }
    let out = walker(&[
        "stability-map",
        "--scene",
        "compass",
        "--x",
        "slope_rad=0.03:0.05:2",
        "--y",
        "leg_com_from_hip_m=0.5:0.5:1",
        "--sigma-m",
        "0.01",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("--quantity mfpt"), "{}", stderr(&out));
}

#[test]
fn optimize_maximises_the_step_down_and_its_best_is_the_measure_there() {
    let r = json(&[
        "optimize",
        "--scene",
        "compass",
        "--vary",
        "leg_com_from_hip_m=0.4:0.6",
        "--objective",
        "step_down",
        "--budget",
        "12",
        "--json",
    ]);
    assert_eq!(r["objective"], "step_down");
    let best = r["best"]["value"].as_f64().unwrap();
    let b = r["best"]["parameters"]["leg_com_from_hip_m"]
        .as_f64()
        .unwrap();
    // not worse than the scene's design (the search keeps the best it saw)
    assert!(best >= r["default"]["value"].as_f64().unwrap() - 1e-12);
    let set = format!("leg_com_from_hip_m={b}");
    let at = json(&[
        "robustness",
        "--scene",
        "compass",
        "--set",
        &set,
        "--measures",
        "steps",
        "--json",
    ]);
    assert_eq!(at["step_down_max_m"].as_f64().unwrap(), best);
}

#[test]
fn an_unstable_gait_has_no_robustness_measure_and_says_so() {
    let out = walker(&[
        "robustness",
        "--scene",
        "compass",
        "--set",
        "slope_rad=0.2",
        "--json",
    ]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let r: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(r["errors"]["gait"].as_str().unwrap().contains("unstable"));
    assert!(r["gait_sensitivity_norm"].is_null() && r["step_down_max_m"].is_null());
    // in a map: the cell has its gait, its measure an error saying why
    let map = json(&[
        "stability-map",
        "--scene",
        "compass",
        "--x",
        "slope_rad=0.05:0.2:2",
        "--y",
        "leg_com_from_hip_m=0.5:0.5:1",
        "--quantity",
        "gsn",
        "--json",
    ]);
    assert!(map["quantity"]["values"][0][0].as_f64().unwrap() > 0.0);
    assert!(map["quantity"]["values"][0][1].is_null());
    assert!(map["quantity"]["errors"][0][1]
        .as_str()
        .unwrap()
        .contains("unstable"));
}

#[test]
fn a_floor_that_never_trips_the_walker_scores_the_strides_simulated() {
    // σ = 0: no walk falls; the value is the strides simulated (100 walks × 200), above any
    // design that fell in the same Monte Carlo
    let map = json(&[
        "stability-map",
        "--scene",
        "compass",
        "--x",
        "slope_rad=0.05:0.05:1",
        "--y",
        "leg_com_from_hip_m=0.5:0.5:1",
        "--quantity",
        "mfpt",
        "--sigma-m",
        "0",
        "--json",
    ]);
    assert_eq!(map["quantity"]["values"][0][0].as_f64().unwrap(), 20_000.0);
    assert_eq!(map["quantity"]["sigma_m"], 0.0);
}

#[test]
fn a_basin_over_both_positions_keeps_only_cells_on_the_section() {
    let r = json(&[
        "basin",
        "--scene",
        "simplest",
        "--x",
        "stance_leg=0.15:0.25:5",
        "--y",
        "swing_leg=-0.5:-0.3:3",
        "--json",
    ]);
    assert!(r["solved_coordinate"].is_null());
    // swing_leg = −2 stance_leg puts the foot on the floor: of these cells only
    // (0.15, −0.3), (0.2, −0.4) and (0.25, −0.5)
    let on: Vec<(usize, usize)> = (0..3)
        .flat_map(|j| (0..5).map(move |i| (j, i)))
        .filter(|&(j, i)| r["outcome"][j][i] != "off_section")
        .collect();
    assert_eq!(on, vec![(0, 4), (1, 2), (2, 0)], "{}", r["outcome"]);
}

#[test]
fn options_that_would_be_ignored_or_overreach_are_refused() {
    for (args, needle) in [
        (
            vec![
                "robustness",
                "--scene",
                "compass",
                "--measures",
                "gsn",
                "--sigma-m",
                "0.01",
            ],
            "add mfpt to --measures",
        ),
        (
            vec![
                "robustness",
                "--scene",
                "compass",
                "--rate-scan-step",
                "0.3",
            ],
            "--rate-scan-step",
        ),
        (
            vec![
                "optimize",
                "--scene",
                "compass",
                "--vary",
                "leg_com_from_hip_m=0.4:0.6",
                "--objective",
                "gsn",
                "--sigma-m",
                "0.002",
            ],
            "--sigma-m is the rough floor of mfpt",
        ),
        (
            vec![
                "stability-map",
                "--scene",
                "compass",
                "--x",
                "slope_rad=0.03:0.05:2",
                "--y",
                "leg_com_from_hip_m=0.5:0.5:1",
                "--quantity",
                "mfpt",
                "--sigma-m",
                "-1",
            ],
            "--sigma-m -1",
        ),
    ] {
        refused(&args, needle);
    }
}

#[test]
fn a_sweep_measures_each_period_one_gait_as_robustness_does_there() {
    let sweep = [
        "sweep",
        "--scene",
        "compass",
        "--param",
        "slope_rad",
        "--from",
        "0.03",
        "--to",
        "0.05",
        "--points",
        "3",
        "--quantity",
    ];
    let r = json(&[&sweep[..], &["step_down", "--json"]].concat());
    let points = r["points"].as_array().unwrap();
    assert_eq!(points.len(), 3);
    for p in points {
        assert_eq!(p["quantity"]["name"], "step_down");
        let value = p["quantity"]["value"].as_f64().unwrap();
        let set = format!("slope_rad={}", p["value"]);
        let at = json(&[
            "robustness",
            "--scene",
            "compass",
            "--set",
            &set,
            "--measures",
            "steps",
            "--json",
        ]);
        // the sweep's gait is the same fixed point (its own continuation): the same threshold
        // to the bisection's resolution
        let there = at["step_down_max_m"].as_f64().unwrap();
        assert!(
            (value - there).abs() <= 2e-7,
            "{set}: {value} against {there}"
        );
    }
    // mfpt needs the floor's roughness
    refused(&[&sweep[..], &["mfpt"]].concat(), "--sigma-m");
}
