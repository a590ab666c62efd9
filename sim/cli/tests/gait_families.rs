//! `walker gaits`, `walker orbit-diagram` and `walker stability-map` on the simplest walker,
//! pinned against the hand-written Garcia model (`sim/tests/garcia`), which shares no code
//! with the engine: the two period-1 gaits, the cascade to chaos and the end of walking, and
//! the stable and no-gait regions of the map.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;
#[path = "../../tests/garcia/mod.rs"]
mod garcia;

use common::{stderr, walker};
use garcia::{Period1, State};
use serde_json::Value;

/// Garcia et al. (1998) at slope 0.009: the long-period gait and the short-period one.
const LONG: State = State {
    theta: 0.200_310_900_49,
    theta_dot: -0.199_832_472_91,
};
const SHORT: State = State {
    theta: 0.19393,
    theta_dot: -0.20386,
};

fn json(args: &[&str]) -> Value {
    let out = walker(args);
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    serde_json::from_slice(&out.stdout).expect("valid json")
}

/// The reference gait on slope `gamma`, followed from Garcia's gait at 0.009.
fn reference(gamma: f64, at_0_009: State) -> Option<Period1> {
    garcia::continued(0.009, gamma, at_0_009, 40)
}

fn assert_matches(gait: &Value, r: &Period1, what: &str) {
    let fp = &gait["fixed_point"];
    let theta = fp["stance_leg"].as_f64().unwrap();
    let theta_dot = fp["stance_leg_dot"].as_f64().unwrap();
    let swing = fp["swing_leg"].as_f64().unwrap();
    assert!(
        (theta - r.state.theta).abs() < 1e-8,
        "{what}: θ {theta} vs {r:?}"
    );
    assert!(
        (theta_dot - r.state.theta_dot).abs() < 1e-8,
        "{what}: θ̇ {theta_dot} vs {r:?}"
    );
    assert!(
        (swing + 2.0 * r.state.theta).abs() < 1e-8,
        "{what}: swing {swing}"
    );
    let period = gait["step_period_s"].as_f64().unwrap();
    assert!(
        (period - r.period).abs() < 1e-7,
        "{what}: period {period} vs {r:?}"
    );
    let m = gait["max_abs_eigenvalue"].as_f64().unwrap();
    assert!(
        (m - r.max_abs_eigenvalue()).abs() < 1e-5,
        "{what}: max|λ| {m} vs {r:?}"
    );
    assert_eq!(
        gait["stable"].as_bool().unwrap(),
        r.max_abs_eigenvalue() < 1.0,
        "{what}"
    );
}

#[test]
fn gaits_finds_both_period_one_gaits_wherever_the_reference_has_both() {
    for gamma in [0.001, 0.004, 0.009, 0.015, 0.018, 0.022] {
        let long = reference(gamma, LONG).expect("reference long-period gait");
        let short = reference(gamma, SHORT).expect("reference short-period gait");
        assert!(
            long.period > short.period + 0.5,
            "{gamma}: two distinct gaits"
        );
        let v = json(&[
            "gaits",
            "--scene",
            "simplest",
            "--set",
            &format!("slope={gamma}"),
            "--json",
        ]);
        assert_eq!(v["scene"], "simplest");
        let gaits = v["gaits"].as_array().unwrap();
        assert_eq!(gaits.len(), 2, "slope {gamma}: {gaits:#?}");
        // Longest step period first.
        assert_matches(&gaits[0], &long, &format!("long, slope {gamma}"));
        assert_matches(&gaits[1], &short, &format!("short, slope {gamma}"));
    }
}

#[test]
fn gaits_lists_each_gait_exactly_as_walker_gait_reports_it() {
    let one = json(&["gait", "--scene", "compass", "--json"]);
    let all = json(&["gaits", "--scene", "compass", "--json"]);
    let first = &all["gaits"][0];
    // The same object, but for `gait_source` (where `walker gait`'s one gait came from;
    // `walker gaits` lists every gait found).
    assert_eq!(one["gait_source"], "defaults");
    assert!(first.get("gait_source").is_none());
    assert_eq!(
        first.as_object().unwrap().keys().collect::<Vec<_>>(),
        one.as_object()
            .unwrap()
            .keys()
            .filter(|k| *k != "gait_source")
            .collect::<Vec<_>>()
    );
    for key in ["scene", "parameters", "integrator", "converged"] {
        assert_eq!(first[key], one[key], "{key}");
    }
    let (a, b) = (&first["fixed_point"], &one["fixed_point"]);
    for (k, x) in a.as_object().unwrap() {
        assert!(
            (x.as_f64().unwrap() - b[k].as_f64().unwrap()).abs() < 1e-9,
            "{k}"
        );
    }
}

#[test]
fn gait_returns_the_long_period_gait_away_from_the_guess() {
    // Newton from the scene's guess lands on the short-step gait at slope 0.015 (period 3.07,
    // max |λ| 4.8); the long-period one exists there and is stable.
    for gamma in [0.015, 0.0185] {
        let r = reference(gamma, LONG).unwrap();
        let v = json(&[
            "gait",
            "--scene",
            "simplest",
            "--set",
            &format!("slope={gamma}"),
            "--json",
        ]);
        assert_matches(&v, &r, &format!("walker gait, slope {gamma}"));
        // It says where the gait comes from: the scene's gait continued from its defaults
        // (Newton from the guess finds the short-step one).
        assert_eq!(v["gait_source"], "continued_from_defaults", "slope {gamma}");
    }
    let text = walker(&["gait", "--scene", "simplest", "--set", "slope=0.015"]);
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(
        text.contains("the scene's gait continued from its defaults")
            && text.contains("walker gaits"),
        "{text}"
    );
    // At the defaults: Newton from the guess, said so in the JSON, nothing extra in the text.
    let v = json(&["gait", "--scene", "simplest", "--json"]);
    assert_eq!(v["gait_source"], "defaults");
    let text = walker(&["gait", "--scene", "simplest"]);
    assert!(!String::from_utf8_lossy(&text.stdout).contains("walker gaits"));
}

/// The attractor of the reference map, classified as the engine documents it.
#[derive(Debug, PartialEq, Clone, Copy)]
enum Kind {
    Periodic(usize),
    Chaotic,
    Fell,
}

const TRANSIENT: usize = 200;
const WINDOW: usize = 64;
const MAX_STRIDES: usize = 2000;
const MAX_STRIDES_CONVERGING: usize = 10_000;
const CONVERGING_FACTOR: f64 = 0.95;
const MAX_PERIOD: usize = 32;
const TOLERANCE: f64 = 1e-7;
const CONTRAST: f64 = 1e-3;

/// The reference orbit diagram, one value after the other from the previous attractor (the
/// purely sequential method), after the first from the reference gait.
fn reference_diagram(values: &[f64]) -> Vec<Kind> {
    let mut out = Vec::new();
    let mut start: Option<State> = None;
    for &gamma in values {
        let s0 = match start.take() {
            Some(s) => s,
            None => match reference(gamma, LONG) {
                Some(g) => State {
                    theta: g.state.theta * (1.0 + 1e-6),
                    ..g.state
                },
                None => LONG,
            },
        };
        let mut s = s0;
        let mut window: Vec<State> = Vec::new();
        let mut kind = Kind::Chaotic;
        let mut last_best = f64::INFINITY;
        for k in 1..=MAX_STRIDES_CONVERGING {
            match garcia::stride(gamma, s) {
                Some((next, _)) => s = next,
                None => {
                    kind = Kind::Fell;
                    break;
                }
            }
            if k <= TRANSIENT {
                continue;
            }
            window.push(s);
            if window.len() > WINDOW {
                window.remove(0);
            }
            if window.len() == WINDOW && (k - TRANSIENT).is_multiple_of(WINDOW) {
                let error = |p: usize| {
                    (p..WINDOW)
                        .map(|i| {
                            let (a, b) = (window[i], window[i - p]);
                            let d = (a.theta - b.theta)
                                .abs()
                                .max((a.theta_dot - b.theta_dot).abs());
                            d / (1.0 + a.theta.abs().max(a.theta_dot.abs()))
                        })
                        .fold(0.0, f64::max)
                };
                let errors: Vec<f64> = (1..=MAX_PERIOD).map(error).collect();
                let cycle = |p: usize| {
                    let e = errors[p - 1];
                    e <= TOLERANCE
                        && (1..p)
                            .filter(|d| p.is_multiple_of(*d))
                            .all(|d| e <= CONTRAST * errors[d - 1])
                };
                if let Some(p) = (1..=MAX_PERIOD).find(|&p| cycle(p)) {
                    kind = Kind::Periodic(p);
                    break;
                }
                let best = errors.iter().copied().fold(f64::INFINITY, f64::min);
                let converging = best < CONVERGING_FACTOR * last_best;
                last_best = best;
                if k >= MAX_STRIDES && !converging {
                    break;
                }
            }
        }
        if kind != Kind::Fell {
            start = Some(s);
        }
        out.push(kind);
    }
    out
}

#[test]
fn orbit_diagram_shows_the_cascade_to_chaos_and_the_end_of_walking_as_the_reference() {
    let (from, to, n) = (0.015, 0.0195, 46);
    let v = json(&[
        "orbit-diagram",
        "--scene",
        "simplest",
        "--param",
        "slope",
        "--from",
        "0.015",
        "--to",
        "0.0195",
        "--points",
        "46",
        "--json",
    ]);
    assert_eq!(v["scene"], "simplest");
    assert_eq!(v["param"], "slope_rad");
    let points = v["points"].as_array().unwrap();
    assert_eq!(points.len(), n);
    let values: Vec<f64> = (0..n)
        .map(|i| from + (to - from) * i as f64 / (n - 1) as f64)
        .collect();
    let engine: Vec<Kind> = points
        .iter()
        .zip(&values)
        .map(|(p, value)| {
            assert!((p["value"].as_f64().unwrap() - value).abs() < 1e-15);
            for key in ["attractor", "period_strides", "samples", "failure"] {
                assert!(p.get(key).is_some(), "{key} in {p}");
            }
            match p["attractor"].as_str().unwrap() {
                "periodic" => {
                    let n = p["period_strides"].as_u64().unwrap() as usize;
                    assert_eq!(p["samples"]["theta"].as_array().unwrap().len(), n);
                    Kind::Periodic(n)
                }
                "chaotic" => Kind::Chaotic,
                "fell" => {
                    assert!(p["failure"]["kind"].as_str().unwrap().starts_with("fell"));
                    Kind::Fell
                }
                other => panic!("attractor {other}"),
            }
        })
        .collect();
    let reference = reference_diagram(&values);
    eprintln!("value      engine        reference");
    for ((x, e), r) in values.iter().zip(&engine).zip(&reference) {
        eprintln!("{x:.5}  {e:?}  {r:?}");
    }
    // The cascade: periods 1, 2, 4 and 8, then chaos, then falls, in both.
    for kinds in [&engine, &reference] {
        for k in [
            Kind::Periodic(1),
            Kind::Periodic(2),
            Kind::Periodic(4),
            Kind::Periodic(8),
            Kind::Chaotic,
            Kind::Fell,
        ] {
            assert!(kinds.contains(&k), "{k:?} missing from {kinds:?}");
        }
    }
    // Value by value the same attractor, except next to a change of the reference's (where
    // the slow transients of a bifurcation may end on either side of the budget): at most 3.
    let mismatches: Vec<usize> = (0..n).filter(|&i| engine[i] != reference[i]).collect();
    assert!(mismatches.len() <= 3, "{mismatches:?}");
    for &i in &mismatches {
        let near_change = (i > 0 && reference[i - 1] != reference[i])
            || (i + 1 < n && reference[i + 1] != reference[i]);
        assert!(
            near_change,
            "mismatch at {} away from a bifurcation",
            values[i]
        );
    }
    // The end of walking: the first slope where the walker falls, to one step of the grid.
    let first_fall = |k: &[Kind]| k.iter().position(|k| *k == Kind::Fell).unwrap();
    let (fe, fr) = (first_fall(&engine), first_fall(&reference));
    assert!(
        fe.abs_diff(fr) <= 1,
        "falls from {} vs {}",
        values[fe],
        values[fr]
    );
    // Garcia et al. (1998): chaotic walking before γ ≈ 0.019, no walking beyond.
    assert!(
        (0.0185..=0.0195).contains(&values[fe]),
        "falls from {}",
        values[fe]
    );
}

#[test]
fn stability_map_agrees_with_the_reference_on_stable_and_no_gait_cells() {
    // The simplest walker in Garcia's scaling: its multipliers depend on the slope only, so
    // every leg length gives the reference's column.
    let v = json(&[
        "stability-map",
        "--scene",
        "simplest",
        "--x",
        "slope=-0.002:0.022:9",
        "--y",
        "leg_length_m=0.5:2:2",
        "--json",
    ]);
    assert_eq!(v["x"]["name"], "slope_rad");
    assert_eq!(v["y"]["name"], "leg_length_m");
    let xs: Vec<f64> = v["x"]["values"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(xs.len(), 9);
    let (m, stable) = (&v["max_abs_eigenvalue"], &v["stable"]);
    assert_eq!(m.as_array().unwrap().len(), 2);
    let mut seen = (0, 0, 0);
    for (i, &gamma) in xs.iter().enumerate() {
        let r = reference(gamma, LONG);
        for row in 0..2 {
            match &r {
                None => {
                    assert!(m[row][i].is_null(), "slope {gamma}: {}", m[row][i]);
                    assert!(stable[row][i].is_null());
                    seen.0 += 1;
                }
                Some(r) => {
                    let e = m[row][i]
                        .as_f64()
                        .unwrap_or_else(|| panic!("gait at {gamma}"));
                    assert!(
                        (e - r.max_abs_eigenvalue()).abs() < 1e-5,
                        "{gamma}: {e} {r:?}"
                    );
                    let s = r.max_abs_eigenvalue() < 1.0;
                    assert_eq!(stable[row][i].as_bool().unwrap(), s, "{gamma}");
                    if s {
                        seen.1 += 1;
                    } else {
                        seen.2 += 1;
                    }
                }
            }
        }
    }
    // The grid spans all three regions: no gait, stable, unstable.
    assert!(seen.0 > 0 && seen.1 > 0 && seen.2 > 0, "{seen:?}");
}
