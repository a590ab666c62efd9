//! `walker sweep`'s output contract (issue #11): each point's `value`, `period_strides`,
//! `branch` and, for period > 1, `orbit`; `stability_boundaries` with `kind`; `branch_ends`
//! with `value`, `kind`, `detail`; a `reason` where no gait was found. The numbers are checked
//! against the hand-written Garcia model (sim/tests/garcia), not against earlier output.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use serde_json::Value;
use std::process::Output;

mod common;
#[path = "../../tests/garcia/mod.rs"]
mod garcia;
use common::walker;

fn json(out: &Output) -> Value {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("valid json")
}

const SIMPLEST: [&str; 12] = [
    "sweep",
    "--scene",
    "simplest",
    "--param",
    "slope",
    "--from",
    "0.009",
    "--to",
    "0.017",
    "--points",
    "5",
    "--max-period",
];

#[test]
fn the_simplest_sweep_reports_branches_periods_orbits_and_the_period_doubling() {
    let mut args = SIMPLEST.to_vec();
    args.extend(["2", "--json"]);
    let v = json(&walker(&args));
    let points = v["points"].as_array().unwrap();
    let grid = [0.009, 0.011, 0.013, 0.015, 0.017];
    let main: Vec<&Value> = points.iter().filter(|p| p["branch"] == 0).collect();
    assert_eq!(main.len(), 5);
    for (p, g) in main.iter().zip(grid) {
        assert!((p["value"].as_f64().unwrap() - g).abs() < 1e-12, "{p}");
        assert_eq!(p["period_strides"], 1);
        assert_eq!(p["converged"], true);
        assert!(p.get("orbit").is_none(), "{p}");
        assert!(p["fixed_point"]["theta"].is_f64());
    }
    let doubled: Vec<&Value> = points.iter().filter(|p| p["branch"] == 1).collect();
    assert!(!doubled.is_empty(), "{points:?}");
    for p in &doubled {
        assert_eq!(p["period_strides"], 2);
        let orbit = p["orbit"].as_array().unwrap();
        assert_eq!(orbit.len(), 2);
        assert_eq!(orbit[0], p["fixed_point"]);
        let (a, b) = (
            orbit[0]["theta"].as_f64().unwrap(),
            orbit[1]["theta"].as_f64().unwrap(),
        );
        assert!(
            (a - b).abs() > 1e-4,
            "a period-2 cycle has two distinct states: {orbit:?}"
        );
    }
    // The parameter as given and its canonical name; nothing left unlocated or unswitched.
    assert_eq!(v["param"], "slope");
    assert_eq!(v["param_canonical"], "slope_rad");
    assert_eq!(
        v["unlocated"].as_array().unwrap().len(),
        0,
        "{}",
        v["unlocated"]
    );
    assert_eq!(
        v["switch_failures"].as_array().unwrap().len(),
        0,
        "{}",
        v["switch_failures"]
    );
    for b in v["stability_boundaries"].as_array().unwrap() {
        assert!(b["bracket"].as_f64().unwrap() < 1e-8, "{b}");
        assert_eq!(b["budget_exhausted"], false);
    }
    let branches = v["branches"].as_array().unwrap();
    assert_eq!(branches[1]["parent"], 0);
    assert_eq!(branches[1]["period_strides"], 2);
    let b = v["stability_boundaries"].as_array().unwrap();
    let pd: Vec<&Value> = b
        .iter()
        .filter(|b| b["kind"] == "period_doubling" && b["branch"] == 0)
        .collect();
    assert_eq!(pd.len(), 1, "{b:?}");
    assert_eq!(pd[0]["change"], "lost");
    let reference = garcia::period_doubling_slope(
        0.009,
        0.017,
        garcia::State {
            theta: 0.2,
            theta_dot: -0.2,
        },
    )
    .unwrap();
    let value = pd[0]["value"].as_f64().unwrap();
    assert!((value - reference).abs() < 1e-8, "{value} vs {reference}");
    for b in b {
        let kind = b["kind"].as_str().unwrap();
        assert!(
            ["fold", "branch_point", "period_doubling", "neimark_sacker"].contains(&kind),
            "{kind}"
        );
        assert!(!b["multipliers"].as_array().unwrap().is_empty());
    }
    assert!(v["branch_ends"].as_array().unwrap().is_empty(), "{v}");
}

#[test]
fn the_simplest_sweep_says_so_in_text() {
    let mut args = SIMPLEST.to_vec();
    args.push("1");
    let out = walker(&args);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("period doubling on branch 0"), "{text}");
    assert!(text.contains("slope = 0.01508843"), "{text}");
}

#[test]
fn the_tuned_wisse2d_sweep_names_the_fold_where_its_branch_ends() {
    let v = json(&walker(&[
        "sweep",
        "--scene",
        "wisse2d-tuned",
        "--param",
        "ankle_engage_rad",
        "--from",
        "-0.055",
        "--to",
        "-0.08",
        "--points",
        "11",
        "--json",
    ]));
    let ends = v["branch_ends"].as_array().unwrap();
    assert_eq!(ends.len(), 1, "{ends:?}");
    assert_eq!(ends[0]["kind"], "fold");
    let at = ends[0]["value"].as_f64().unwrap();
    assert!(at < -0.055 && at > -0.0575, "{at}");
    assert!(ends[0]["detail"].as_str().unwrap().contains("fold"));
    let points = v["points"].as_array().unwrap();
    let failed: Vec<&Value> = points.iter().filter(|p| p["converged"] == false).collect();
    // Every grid value beyond the fold is unreached, with the reason.
    assert_eq!(failed.len(), 10, "{points:?}");
    for p in failed {
        assert!(p["reason"].as_str().unwrap().contains("fold"), "{p}");
        assert!(p["value"].as_f64().unwrap() < at);
    }
    let fold = v["stability_boundaries"]
        .as_array()
        .unwrap()
        .iter()
        .find(|b| b["kind"] == "fold")
        .expect("the fold is a stability boundary");
    assert_eq!(fold["value"], ends[0]["value"]);
}

#[test]
fn a_bad_max_period_is_named() {
    let mut args = SIMPLEST.to_vec();
    args.push("0");
    let out = walker(&args);
    assert_eq!(out.status.code(), Some(2));
    assert!(common::stderr(&out).contains("--max-period"));
}

#[test]
fn the_command_lines_integrator_applies_at_every_value() {
    // RK4 with a 0.1 s step moves the period doubling by about 1e-8 from the scene's DOP853:
    // the sweep must use it (at every rebuilt parameter value), not the scene's integrator.
    let pd = |extra: &[&str]| {
        let mut args = SIMPLEST.to_vec();
        args.extend(["1", "--json"]);
        args.extend(extra);
        let v = json(&walker(&args));
        v["stability_boundaries"][0]["value"].as_f64().unwrap()
    };
    let scene = pd(&[]);
    let rk4 = pd(&["--integrator", "rk4", "--step-s", "0.1"]);
    assert!((rk4 - scene).abs() > 1e-9, "{rk4} vs {scene}");
    assert!((rk4 - scene).abs() < 1e-6, "{rk4} vs {scene}");
}

#[test]
fn a_sweep_that_cannot_start_or_runs_out_of_budget_exits_1_naming_the_unanswered_range() {
    // No gait on steep uphill slopes: the sweep cannot start at any value it tries; it used
    // to exit 0.
    let out = walker(&[
        "sweep", "--scene", "simplest", "--param", "slope", "--from", "-0.5", "--to", "-0.4",
        "--points", "50",
    ]);
    let err = common::stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("values of slope from -0.5 to") && err.contains("unanswered: no gait"),
        "{err}"
    );
    // The compass's branch to a slope of 0.5 runs out of its point budget: said, exit 1.
    let out = walker(&[
        "sweep", "--scene", "compass", "--param", "slope", "--from", "0.01", "--to", "0.5",
        "--points", "2000",
    ]);
    let err = common::stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("unanswered") && err.contains("budget"),
        "{err}"
    );
    // The text's rows are in parameter order, whatever the branches' order.
    let text = String::from_utf8_lossy(&out.stdout);
    let values: Vec<f64> = text
        .lines()
        .skip(1)
        .map_while(|l| l.split_whitespace().next()?.parse().ok())
        .collect();
    assert!(values.len() > 10, "{text}");
    assert!(values.windows(2).all(|w| w[0] <= w[1]), "{values:?}");
    // The sweep over the whole range: its gaits lie between slopes 0 and 0.019, far
    // from its start; it tried its first 32 values only and answered none. Now its start is
    // searched across the range: the branch is found and followed both ways.
    let out = walker(&[
        "sweep", "--scene", "simplest", "--param", "slope", "--from", "-0.5", "--to", "0.5",
        "--points", "10000", "--json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let answered: Vec<f64> = v["points"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|p| p["converged"] == true)
        .filter_map(|p| p["value"].as_f64())
        .collect();
    assert!(answered.len() > 100, "{} points", answered.len());
    assert!(
        answered.iter().all(|s| (0.0..0.0195).contains(s)),
        "{answered:?}"
    );
    assert!(answered.iter().any(|s| *s < 0.001) && answered.iter().any(|s| *s > 0.01));
    // The unanswered values, named as two runs on either side of the answered ones, each
    // with its own reason: behind the start the branch's end going back, ahead the budget.
    let err = common::stderr(&out);
    let runs: Vec<&str> = err.lines().filter(|l| l.contains("unanswered")).collect();
    assert_eq!(runs.len(), 2, "{err}");
    assert!(
        runs[0].contains("values of slope from -0.5 to ") && runs[0].contains("event_change"),
        "{err}"
    );
    assert!(
        runs[1].contains("to 0.5 unanswered") && runs[1].contains("budget"),
        "{err}"
    );
    let lowest_after = answered.iter().copied().fold(f64::INFINITY, f64::min);
    let run_from: f64 = runs[1]
        .split("values of slope from ")
        .nth(1)
        .and_then(|t| t.split(' ').next())
        .and_then(|t| t.parse().ok())
        .unwrap();
    assert!(run_from > lowest_after, "{err}");
    // A sweep that answers every value exits 0.
    let out = walker(&[
        "sweep", "--scene", "simplest", "--param", "slope", "--from", "0.009", "--to", "0.012",
        "--points", "4",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
}
